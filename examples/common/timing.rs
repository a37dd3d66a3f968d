//! The best of several timed runs, for the benches that time one call (`bench_settle`,
//! `bench_validate`): each includes this file with `#[path = "common/timing.rs"] mod timing;`.

use std::time::Instant;

/// Runs `f` `runs` times (at least once) and returns the shortest wall time in seconds with
/// the last run's result: on a shared machine the shortest run is the one least disturbed.
pub fn best_of<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        let r = f();
        best = best.min(t.elapsed().as_secs_f64());
        out = Some(r);
    }
    (best, out.expect("at least one run"))
}
