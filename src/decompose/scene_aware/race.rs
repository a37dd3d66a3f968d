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
/// there is more than one to compare.
fn p95s(s: &Surface, at: &[((Vec<Part>, ObjectReport), Params)]) -> Vec<f64> {
    at.par_iter()
        .map(|(r, _)| {
            if at.len() > 1 {
                distance_stats(s, &hulls_of(&r.0)).map_or(f64::INFINITY, |x| x.0)
            } else {
                f64::INFINITY
            }
        })
        .collect()
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
            let r = grow_to_quality(s, c.feat, &p, c.opts, c.fixed, c.rest, c.budget);
            (r, p)
        })
        .collect();
    let d1 = p95s(s, &at);
    let lead1 = d1.iter().copied().fold(f64::INFINITY, f64::min);
    let at: Vec<_> = at
        .into_par_iter()
        .zip(d1)
        .filter(|(_, d)| !behind(*d, lead1, MARGIN1))
        .map(|((r, p), _)| {
            let r = grow_rebalanced(s, c.feat, &p, c.opts, r, c.budget, c.effort, c.near);
            (r, p)
        })
        .collect();
    let d2 = p95s(s, &at);
    let lead2 = d2.iter().copied().fold(f64::INFINITY, f64::min);
    at.into_par_iter()
        .zip(d2)
        .filter(|(_, d)| !behind(*d, lead2, MARGIN))
        .map(|((r, p), _)| {
            let r = grow_from_checkpoint(s, c.feat, &p, c.opts, r, c.budget, c.effort, c.near);
            let fin = distance_stats(s, &hulls_of(&r.0));
            (fin, (r.0, r.1, p))
        })
        .collect()
}
