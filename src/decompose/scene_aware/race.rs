//! The strategy race: an object's two strategies (see `Strategy`) run side by side to a
//! checkpoint, and one whose 95th percentile there (see [`distance_stats`], 4,000 samples) lies
//! far behind the leader's is not taken further. Checkpoints: after the quality loop (the
//! rebalancing, the polishing and the refit are saved) and after the rebalancing (the
//! polishing and the refit). Which strategy wins changes during the rebalancing and the
//! polishing (docs/speed.md, "Predicting which strategy wins"), so a strategy is dropped
//! only when it is behind by more than the most the final winner was ever behind there on
//! the 43 shared objects, with a margin ([`MARGIN1`], [`MARGIN`]): on those the kept
//! strategy, hence the hulls, are bit for bit those of running both to the end. What is
//! saved: on the 20 of them that run both, the loser's polishing on 8 (the GSO ZIGLITE
//! sneaker 5.3 → 3.3 CPU-s).
//!
//! With `DecomposeOptions::race` false every strategy runs to the end (the margins are
//! infinite): the check of the margins on objects they were not derived from.
//! On 75 held-out scene objects (10 scenes at 32, 16 and 8 hulls, docs/speed.md) the hulls
//! were the full run's on 74; the other (a sneaker at 8 hulls) kept the strategy the full
//! run does not: 0.115 points closer two-sided, 0.172 further one-sided (hulls → mesh).
//!
//! Entry point: [`race`].

use super::*;

/// What the strategies share: the object and its settings.
pub(super) struct Ctx<'a> {
    pub(super) s: &'a Surface,
    pub(super) feat: &'a patches::Features,
    pub(super) opts: &'a DecomposeOptions,
    pub(super) fixed: &'a [Part],
    pub(super) rest: &'a [u32],
    pub(super) budget: usize,
    pub(super) effort: Effort,
    pub(super) near: &'a [f64],
}

/// One finished strategy: the 95th percentile and maximum of its hulls' distance (see
/// [`distance_stats`]), its parts, its report and its parameters.
pub(super) type Run = (Option<(f64, f64)>, (Vec<Part>, ObjectReport, Params));

/// How far behind the leader at the first checkpoint (after the quality loop), relative to
/// the leader's p95 there, a strategy is still rebalanced. On the 43 shared objects alone
/// (`bench_objects`, 20 of them run both strategies) the strategy kept in the end was up to
/// 40.0 % behind there (the GSO Room Essentials mug: 2.346 against 1.675 % of the
/// diagonal); 0.6 is 1.5
/// times that.
const MARGIN1: f64 = 0.60;

/// How far behind the leader at the second checkpoint (after the rebalancing), relative to
/// the leader's p95 there, a strategy is still polished and refitted. On the same objects the
/// strategy kept in the end was up to 12.7 % behind there (the YCB lego duplo: 3.735 against
/// 3.313 %); 0.2 is
/// about 1.6 times that. Dropped at 0.2: the loser on 8 of the 20 (17.5–286 % behind).
const MARGIN: f64 = 0.20;

/// Each strategy's 95th percentile (see [`distance_stats`]; ∞ without hull surface), when
/// there is more than one to compare and the race is on.
fn p95s(c: &Ctx, at: &[((Vec<Part>, ObjectReport), Params)]) -> Vec<f64> {
    let s = c.s;
    at.par_iter()
        .map(|(r, _)| {
            if at.len() > 1 && c.opts.race {
                distance_stats(s, &hulls_of(&r.0)).map_or(f64::INFINITY, |x| x.0)
            } else {
                f64::INFINITY
            }
        })
        .collect()
}

#[cfg(test)]
thread_local! {
    /// Strategies the race dropped on this thread (the test's proof that one was).
    static DROPPED: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// How many of `d` are more than `margin` behind `lead`, counted in [`DROPPED`] under test.
fn count_dropped(d: &[f64], lead: f64, margin: f64) {
    let _n = d.iter().filter(|&&x| behind(x, lead, margin)).count();
    #[cfg(test)]
    DROPPED.with(|c| c.set(c.get() + _n));
}

/// Whether a strategy whose p95 is `d` is more than `margin` behind the least, `lead`.
fn behind(d: f64, lead: f64, margin: f64) -> bool {
    d.is_finite() && d > lead * (1.0 + margin)
}

/// The strategies, in order, that the race finishes, each finished: those whose p95 at each
/// checkpoint is within the margin of the least (all when there is one).
pub(super) fn race(c: &Ctx, strategies: &[Strategy]) -> Vec<Run> {
    let s = c.s;
    let at: Vec<_> = strategies
        .par_iter()
        .map(|&st| {
            let p = Params::new(s, c.opts, st);
            let r = grow_to_quality(c, &p);
            (r, p)
        })
        .collect();
    // Without the race no strategy is ever behind by more than the margins.
    let (m1, m2) = if c.opts.race {
        (MARGIN1, MARGIN)
    } else {
        (f64::INFINITY, f64::INFINITY)
    };
    let d1 = p95s(c, &at);
    let lead1 = d1.iter().copied().fold(f64::INFINITY, f64::min);
    count_dropped(&d1, lead1, m1);
    let at: Vec<_> = at
        .into_par_iter()
        .zip(d1)
        .filter(|(_, d)| !behind(*d, lead1, m1))
        .map(|((r, p), _)| {
            let r = grow_rebalanced(c, &p, r);
            (r, p)
        })
        .collect();
    let d2 = p95s(c, &at);
    let lead2 = d2.iter().copied().fold(f64::INFINITY, f64::min);
    count_dropped(&d2, lead2, m2);
    at.into_par_iter()
        .zip(d2)
        .filter(|(_, d)| !behind(*d, lead2, m2))
        .map(|((r, p), _)| {
            let r = grow_from_checkpoint(c, &p, r);
            let fin = distance_stats(s, &hulls_of(&r.0));
            (fin, (r.0, r.1, p))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// The race on an object where it drops a strategy (the GSO Cole Hardware mug: Patches,
    /// 25 % behind after the rebalancing, docs/speed.md) keeps the hulls of running both
    /// strategies to the end and taking the closer: the full run is the expectation.
    #[test]
    fn race_keeps_the_full_runs_hulls_where_it_drops_a_strategy() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let Some(sh) = [root.join("../shared"), root.join("../../shared")]
            .into_iter()
            .find(|p| p.join("datasets/objects").is_dir())
        else {
            eprintln!("shared datasets not present: skipped");
            return;
        };
        let p = sh.join("datasets/objects/gso/Cole_Hardware_Mug_Classic_Blue/model.obj");
        let mesh = crate::io::load_visual(&p, &crate::io::Limits::default())
            .unwrap()
            .geometry();
        let on = DecomposeOptions::default();
        let off = DecomposeOptions {
            race: false,
            ..DecomposeOptions::default()
        };
        let b = on.max_hulls;
        let run = |o: &DecomposeOptions| {
            DROPPED.with(|c| c.set(0));
            let obj = decompose_alone(&mesh, o, b, Effort::full(b), &Strategy::ALL);
            let hulls: Vec<Hull> = obj.parts.iter().map(|q| q.hull.clone()).collect();
            (hulls, obj.report.top_down, DROPPED.with(|c| c.get()))
        };
        let (h_off, top_off, dropped_off) = run(&off);
        let (h_on, top_on, dropped_on) = run(&on);
        assert_eq!(dropped_off, 0, "the full run drops nothing");
        assert_eq!(dropped_on, 1, "the race drops one strategy here");
        assert_eq!(top_on, top_off, "the same strategy wins");
        assert!(!h_on.is_empty());
        assert_eq!(h_on.len(), h_off.len());
        for (a, b) in h_on.iter().zip(&h_off) {
            assert_eq!(a.vertices, b.vertices, "the same hulls, bit for bit");
            assert_eq!(a.triangles, b.triangles);
        }
    }
}
