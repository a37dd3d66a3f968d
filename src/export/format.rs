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
pub fn f(x: f64) -> String {
    let r = round(x);
    let s = format!("{r}");
    if s.len() > 16 && r != 0.0 && r.abs() < 1e-4 {
        format!("{r:e}")
    } else {
        s
    }
}

/// Three numbers separated by spaces.
pub fn vec3(v: &nalgebra::Vector3<f64>) -> String {
    format!("{} {} {}", f(v.x), f(v.y), f(v.z))
}

#[cfg(test)]
mod tests {
    use super::*;

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
