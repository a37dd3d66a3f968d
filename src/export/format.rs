//! Stable number formatting for generated files: the same value always prints the same way.

/// Round to 10 significant digits (what every writer prints), and turn −0 into 0.
pub fn round(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return if x.is_finite() { 0.0 } else { x };
    }
    let r: f64 = format!("{x:.9e}").parse().unwrap_or(x);
    if r == 0.0 {
        0.0
    } else {
        r
    }
}

/// A number as text: 10 significant digits, shortest form, no `-0`.
///
/// The text is [`f_direct`]'s, byte for byte; most numbers take a quicker path that finds the
/// same ten digits with integer arithmetic ([`ten_digits`]) and spells them as `{}` or `{:e}`
/// would spell their rounded value (see there why that is the same text).
pub fn f(x: f64) -> String {
    match ten_digits(x) {
        Some((negative, n, e)) => spell(negative, n, e),
        None => f_direct(x),
    }
}

/// [`f`] by its definition: round through `{:.9e}` and `parse`, print the result with `{}`
/// (with `{:e}` when that is long and the number small). Every writer's number once went
/// through this; it is the reference [`f`]'s quick path is tested against.
pub fn f_direct(x: f64) -> String {
    let r = round(x);
    let s = format!("{r}");
    if s.len() > 16 && r != 0.0 && r.abs() < 1e-4 {
        format!("{r:e}")
    } else {
        s
    }
}

/// `x` rounded to 10 significant digits as `(negative, n, e)`, the value `±n·10^(e−9)` with
/// `10⁹ ≤ n < 10¹⁰`: the digits `{:.9e}` prints, found exactly. `x = m·2^q` with integers
/// `m < 2⁵³` and `−127 ≤ q < 0`; `x·10^(9−e) = m·10^(9−e) / 2^(−q)` is a u128 product (below
/// 2¹²⁷ for `9 − e ≤ 22`) shifted right: the quotient is its integer part, the bits shifted out
/// are its exact fraction, so the rounding to nearest is exact. `e` is the one with the quotient
/// in `[10⁹, 10¹⁰)`, i.e. `10^e ≤ |x| < 10^(e+1)`. `None` outside that range (`|x|` below
/// about 10⁻¹³ or from 2⁵² up, subnormal, zero, not finite) and on an exact tie, whose rounding
/// direction is left to the formatter: [`f_direct`] answers those.
fn ten_digits(x: f64) -> Option<(bool, u64, i32)> {
    if !x.is_normal() {
        return None;
    }
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i32;
    let m = (bits & ((1u64 << 52) - 1)) | (1u64 << 52);
    let q = exponent - 1075;
    if !(-127..0).contains(&q) {
        return None;
    }
    let shift = (-q) as u32;
    let mut e = x.abs().log10().floor() as i32;
    for _ in 0..4 {
        let k = 9 - e;
        if !(0..=22).contains(&k) {
            return None;
        }
        let p = m as u128 * 10u128.pow(k as u32);
        let whole = p >> shift;
        if whole < 1_000_000_000 {
            e -= 1;
            continue;
        }
        if whole >= 10_000_000_000 {
            e += 1;
            continue;
        }
        let fraction = p & ((1u128 << shift) - 1);
        let half = 1u128 << (shift - 1);
        let mut n = whole as u64;
        if fraction == half {
            return None;
        }
        if fraction > half {
            n += 1;
        }
        return Some(if n == 10_000_000_000 {
            (x < 0.0, 1_000_000_000, e + 1)
        } else {
            (x < 0.0, n, e)
        });
    }
    None
}

/// The text [`f_direct`] gives for `x` whose ten digits are `(negative, n, e)`. `r`, the parsed
/// `{:.9e}` text, is the double nearest `D = ±n·10^(e−9)`; `{}` prints the shortest decimal that
/// parses back to `r`, and that is `D` without its trailing zeros: two different decimals of at
/// most ten significant digits differ by more than 10⁻¹⁰ of their size, far more than the
/// 2⁻⁵² between neighbouring doubles, so no other decimal of at most ten digits (and none
/// shorter) parses to `r`. `{}` never uses an exponent; `|r| < 10⁻⁴` exactly when `e ≤ −5`
/// (parsing is monotone and `10⁻⁴` is itself such a decimal).
fn spell(negative: bool, n: u64, e: i32) -> String {
    let mut n = n;
    let mut len = 10i32;
    while n % 10 == 0 {
        n /= 10;
        len -= 1;
    }
    let digits = n.to_string();
    let mut s = String::with_capacity(24);
    if negative {
        s.push('-');
    }
    if e >= len - 1 {
        s.push_str(&digits);
        s.extend(std::iter::repeat_n('0', (e - (len - 1)) as usize));
    } else if e >= 0 {
        let (a, b) = digits.split_at(e as usize + 1);
        s.push_str(a);
        s.push('.');
        s.push_str(b);
    } else {
        s.push_str("0.");
        s.extend(std::iter::repeat_n('0', (-e - 1) as usize));
        s.push_str(&digits);
    }
    if s.len() > 16 && e <= -5 {
        s.clear();
        if negative {
            s.push('-');
        }
        let (a, b) = digits.split_at(1);
        s.push_str(a);
        if !b.is_empty() {
            s.push('.');
            s.push_str(b);
        }
        s.push('e');
        s.push_str(&e.to_string());
    }
    s
}

/// Three numbers separated by spaces.
pub fn vec3(v: &nalgebra::Vector3<f64>) -> String {
    format!("{} {} {}", f(v.x), f(v.y), f(v.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quick path against the definition, on numbers of every size the writers see and
    /// on the cases where text and rounding turn: exact ties at the tenth digit, nines that
    /// carry into a new digit, powers of ten and their neighbours, the `{:e}` switch.
    #[test]
    fn quick_path_is_the_definition_to_the_byte() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut xs = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            0.3,
            1e-4,
            -1e-4,
            1e-5,
            9.9999999995e-5,
            1.00000000005,
            0.12345678905,
            2.5,
            0.5,
            1e-13,
            1e-14,
            4503599627370495.5,
            4503599627370496.0,
            9.999999999e8,
            999999999.95,
            1e9,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            f64::INFINITY,
            f64::NAN,
            1.234567890123e-7,
            123456.78901234,
        ];
        for p in -16..=17 {
            let t = 10f64.powi(p);
            xs.extend([
                t,
                -t,
                t.next_up(),
                t.next_down(),
                9.9999999995 * t,
                1.00000000005 * t,
            ]);
        }
        let mut tested = 0;
        for _ in 0..1_000_000 {
            let r = next();
            // Uniform mantissa bits over decades 1e-16..1e17, both signs.
            let decade = (r % 34) as i32 - 16;
            let unit = (next() >> 11) as f64 / (1u64 << 53) as f64;
            let x = (1.0 + 9.0 * unit) * 10f64.powi(decade);
            xs.push(if r & (1 << 40) != 0 { -x } else { x });
            // Raw bit patterns, and values with few binary digits (exact ties happen there).
            xs.push(f64::from_bits(next()));
            xs.push((next() % 20_000_000) as f64 / 1024.0 - 9765.625);
        }
        for x in xs {
            assert_eq!(f(x), f_direct(x), "{x:e} ({:#x})", x.to_bits());
            tested += ten_digits(x).is_some() as usize;
        }
        assert!(tested > 1_500_000, "the quick path answered only {tested}");
    }

    #[test]
    fn stable_and_compact() {
        assert_eq!(f(-0.0), "0");
        assert_eq!(f(0.1 + 0.2), "0.3");
        assert_eq!(f(1.0), "1");
        assert_eq!(f(-2.5), "-2.5");
        assert_eq!(f(1.234567890123e-7), "1.23456789e-7");
        assert_eq!(f(123456.78901234), "123456.789");
    }
}
