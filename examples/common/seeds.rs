//! The `--seeds A..B` argument of the agreement examples (`agreement`, `verdict_signals`): a
//! half-open range of generator seeds.

/// `A..B` as a range of seeds; panics naming the argument's form on anything else (the
/// examples are measurement tools, run by hand).
pub fn seed_range(v: &str) -> std::ops::Range<u64> {
    let (a, b) = v.split_once("..").expect("--seeds A..B");
    a.parse().expect("--seeds A..B: A a seed")..b.parse().expect("--seeds A..B: B a seed")
}
