//! Step 2 for one object: the strategies' patch search, the quality loop, and the choice
//! of the closer result.
//!
//! Entry points: [`decompose_object`], [`grow_parts`], [`quality_loop`], [`distance_stats`],
//! [`hulls_of`].

use super::*;

/// Once the budget is spent: most moves kept by the rebalancing (see [`rebalance`]) and by the
/// polishing (see [`polish`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Effort {
    pub(super) rebalance: usize,
    pub(super) polish: usize,
}

impl Effort {
    /// As many moves of each as hulls in the budget.
    pub(super) fn full(budget: usize) -> Effort {
        Effort {
            rebalance: budget,
            polish: budget,
        }
    }
}

/// Decompose one object alone. `budget`: most hulls the quality loop may use.
#[cfg(test)]
pub(super) fn decompose_alone(
    mesh: &Mesh,
    opts: &DecomposeOptions,
    budget: usize,
    effort: Effort,
    strategies: &[Strategy],
) -> Obj {
    decompose_object(
        Surface::new(mesh),
        opts,
        budget,
        effort,
        &[],
        &[],
        strategies,
    )
}

/// [`decompose_alone`] on a prepared surface. `near[t]`: a lower bound on how far triangle
/// `t` is from every neighbour's collision geometry, ∞ where it may not pin its patch (see
/// [`pin_contacts`]; empty: nothing is pinned); the rebalancing, the polishing and the
/// refit leave alone the patches within reach of them.
pub(super) fn decompose_object(
    surf: Option<Surface>,
    opts: &DecomposeOptions,
    budget: usize,
    effort: Effort,
    near: &[f64],
    under: &[f64],
    strategies: &[Strategy],
) -> Obj {
    let Some(s) = surf.as_ref() else {
        return Obj {
            surf: None,
            feat: None,
            params: None,
            parts: Vec::new(),
            report: ObjectReport::default(),
        };
    };
    let p = Params::new(s, opts, Strategy::Patches);
    if let Some(parts) = shortcut(s, &p, opts, budget) {
        return Obj {
            parts,
            feat: None,
            surf,
            params: Some(p),
            report: ObjectReport {
                convex_shortcut: true,
                ..Default::default()
            },
        };
    }
    // Whole-solid candidates: star pieces (a solid seen from its centre), kept as they are
    // when within the tolerance; else, for a thick solid, V-HACD's hulls too, the closer of
    // the two kept when within the tolerance; else they compete with the patches below (ties
    // keep the earlier). V-HACD is built only when the star pieces are not enough: on the GSO
    // bottle it took 0.26 s of the 0.33 s, for p95 0.65 % where the star pieces read 0.77 %
    // (CoACD 32×64: 4.52 %).
    let mut whole: Vec<(f64, Vec<Part>, Solid)> = Vec::new();
    // What a neighbour may rest on; a candidate, when it keeps that.
    let carried = support(s, &p, opts, under);
    let candidate = |c: Option<(f64, Vec<Part>)>, kind: Solid| {
        c.filter(|(_, q)| keeps_support(s, &p, &carried, q))
            .map(|(d, q)| (d, q, kind))
    };
    // The closest whose hulls reach at most `bound` past the surface anywhere: V-HACD's hulls
    // of the YCB pear were closer than its star pieces at the 95th percentile (0.47 against
    // 0.49 % of the diagonal) but one reached 7.1 % past it. Alone within the tolerance, 5
    // tolerances (CoACD's default concavity bound); against the patches, their own reach if
    // more.
    let closest = |w: &[(f64, Vec<Part>, Solid)], bound: f64| {
        w.iter()
            .enumerate()
            .filter(|(_, (_, q, _))| q.iter().all(|x| x.dev <= bound))
            .reduce(|a, b| if b.1 .0 < a.1 .0 { b } else { a })
            .map(|(k, _)| k)
    };
    let within = |w: &[(f64, Vec<Part>, Solid)]| {
        closest(w, 5.0 * p.tol).filter(|&k| w[k].0 <= opts.tolerance)
    };
    whole.extend(candidate(
        star(s, &p, opts, budget, &carried, None, false),
        Solid::Star,
    ));
    // The patch features, built once for the slabs and the patches.
    let mut feat = None;
    if whole.is_empty() && !carried.is_empty() {
        let f = feat.insert(patches::Features::new(s, p.merge_depth, p.d_max));
        whole.extend(candidate(
            star_on_slabs(s, &p, opts, budget, &carried, f),
            Solid::StarOnSlabs,
        ));
    }
    let thick = thick_solid(s);
    if thick && within(&whole).is_none() {
        whole.extend(candidate(voxel_parts(s, opts, budget), Solid::Voxel));
    }
    // A thick solid its centre does not see whole: star pieces where it does, patches over the
    // rest.
    if thick && within(&whole).is_none() && whole.iter().all(|w| w.2 == Solid::Voxel) {
        let f = feat.get_or_insert_with(|| patches::Features::new(s, p.merge_depth, p.d_max));
        whole.extend(candidate(
            star_with_patches(s, opts, f, budget, effort, near, &carried),
            Solid::StarWithPatches,
        ));
    }
    if let Some(k) = within(&whole) {
        let (_, parts, kind) = whole.swap_remove(k);
        return kind.obj(parts, p, surf, feat);
    }
    let (fixed, rest) = convex_components(s, opts, budget);
    let feat = feat.unwrap_or_else(|| patches::Features::new(s, p.merge_depth, p.d_max));
    let run = |strategy: Strategy| {
        let p = Params::new(s, opts, strategy);
        let (parts, report) = grow_parts(s, &feat, &p, opts, &fixed, &rest, budget, effort, near);
        (parts, report, p)
    };
    let ctx = race::Ctx {
        s,
        feat: &feat,
        opts,
        fixed: &fixed,
        rest: &rest,
        budget,
        effort,
        near,
    };
    // One strategy for a set of closed convex pieces, and under a neighbour leaning on its side
    // (see `Strategy`).
    let strategies = if rest.is_empty() || (!carried.is_empty() && leaned_on(s, near, opts)) {
        &strategies[..strategies.len().min(1)]
    } else {
        strategies
    };
    // Closest at the 95th percentile; ties keep the earlier strategy.
    let measured = |st: Strategy| {
        let r = run(st);
        (distance_stats(s, &hulls_of(&r.0)), r)
    };
    let p95 = |d: &Option<(f64, f64)>| d.map_or(f64::INFINITY, |x| x.0);
    let (mut dist, (mut parts, mut report, p)) = race::race(&ctx, strategies)
        .into_iter()
        .reduce(|a, b| if p95(&b.0) < p95(&a.0) { b } else { a })
        .unwrap_or_else(|| measured(Strategy::Patches));
    report.top_down = p.strategy == Strategy::Planes;
    // Concavities the chosen patches fill, opened with the budget they have (`unfill.rs`).
    if effort.polish > 0 && parts.len() >= budget {
        let h2m = dist.map_or(f64::INFINITY, |d| d.0);
        report.unfilled = unfill::unfill(s, &feat, &p, opts, &mut parts, UNFILL_ROUNDS, near, h2m);
        if report.unfilled > 0 {
            dist = distance_stats(s, &hulls_of(&parts));
        }
    }
    // A whole-solid candidate instead when it lies closer at the 95th percentile. A solid the
    // thickness test missed shows as patches that leave it hollow: V-HACD then too.
    let (d_parts, reach) = dist.unwrap_or((0.0, 0.0));
    if !thick && d_parts > opts.tolerance && hollow(s, &parts) {
        whole.extend(candidate(voxel_parts(s, opts, budget), Solid::Voxel));
    }
    if let Some(k) = closest(&whole, (5.0 * p.tol).max(reach * s.diag)) {
        if whole[k].0 < d_parts {
            let (_, parts, kind) = whole.swap_remove(k);
            return kind.obj(parts, p, surf, Some(feat));
        }
    }
    Obj {
        parts,
        feat: Some(feat),
        surf,
        params: Some(p),
        report,
    }
}

/// 95th percentile and maximum of the sampled distance from the union boundary of `hulls` to
/// the surface, relative to the diagonal: what [`decompose_object`] chooses by (the bench's
/// measure, on fewer samples). `None` without hull surface.
pub(super) fn distance_stats(s: &Surface, hulls: &[Hull]) -> Option<(f64, f64)> {
    let d = metrics::surface_distances(s, hulls, P95_SAMPLES);
    if d.is_empty() {
        return None;
    }
    let (_, p95, max) = metrics::stats(&d);
    Some((p95, max))
}

/// The hulls of `parts`.
pub(super) fn hulls_of(parts: &[Part]) -> Vec<Hull> {
    parts.iter().map(|q| q.hull.clone()).collect()
}

pub(super) const P95_SAMPLES: usize = 4000;
/// Most moves of `unfill.rs` per object.
const UNFILL_ROUNDS: usize = 8;

/// The parts of one strategy: the closed convex components `fixed` as they are, the remaining
/// triangles `rest` as k-means patches split by the quality loop, then rebalanced and polished.
#[allow(clippy::too_many_arguments)]
pub(super) fn grow_parts(
    s: &Surface,
    feat: &patches::Features,
    p: &Params,
    opts: &DecomposeOptions,
    fixed: &[Part],
    rest: &[u32],
    budget: usize,
    effort: Effort,
    near: &[f64],
) -> (Vec<Part>, ObjectReport) {
    let c = race::Ctx {
        s,
        feat,
        opts,
        fixed,
        rest,
        budget,
        effort,
        near,
    };
    let at = grow_to_quality(&c, p);
    let at = grow_rebalanced(&c, p, at);
    grow_from_checkpoint(&c, p, at)
}

/// [`grow_parts`] up to the strategy race's first checkpoint (see `race.rs`): the k-means
/// patches and the quality loop.
pub(super) fn grow_to_quality(c: &race::Ctx, p: &Params) -> (Vec<Part>, ObjectReport) {
    let (s, feat, opts, budget) = (c.s, c.feat, c.opts, c.budget);
    let mut report = ObjectReport::default();
    let mut parts = c.fixed.to_vec();
    if !c.rest.is_empty() {
        let k0 = p
            .strategy
            .initial_patches(budget.saturating_sub(parts.len()));
        let groups = patches::kmeans(s, feat, c.rest, k0, p.lambda, 16);
        parts.extend(
            groups
                .into_par_iter()
                .filter_map(|g| build_part(s, p, opts, g, Vec::new()))
                .collect::<Vec<_>>(),
        );
    }
    report.quality_splits = quality_loop(s, feat, p, opts, &mut parts, budget, &|_| true);
    (parts, report)
}

/// [`grow_parts`] from [`grow_to_quality`] to the race's second checkpoint: the rebalancing,
/// when the budget is spent.
pub(super) fn grow_rebalanced(
    c: &race::Ctx,
    p: &Params,
    (mut parts, mut report): (Vec<Part>, ObjectReport),
) -> (Vec<Part>, ObjectReport) {
    if parts.len() >= c.budget {
        report.rebalance_rounds = rebalance::rebalance(
            c.s,
            c.feat,
            p,
            c.opts,
            &mut parts,
            c.effort.rebalance,
            c.near,
        );
    }
    (parts, report)
}

/// The rest of [`grow_parts`] after [`grow_rebalanced`]: the polishing (budget spent) and
/// the refit; the parts' memo is emptied.
pub(super) fn grow_from_checkpoint(
    c: &race::Ctx,
    p: &Params,
    (mut parts, mut report): (Vec<Part>, ObjectReport),
) -> (Vec<Part>, ObjectReport) {
    if parts.len() >= c.budget && c.effort.polish > 0 {
        (report.trimmed_patches, report.polish_rounds) =
            polish::polish(c.s, c.feat, p, c.opts, &mut parts, c.effort.polish, c.near);
    }
    report.refitted = refit::refit(c.s, p, c.opts, &mut parts, c.near);
    p.memo.clear();
    (parts, report)
}

/// The quality loop: split the worst patch (largest deviation) while it deviates more than
/// the tolerance and `parts` has fewer than `budget`. Only patches `free` takes are split, and
/// only into halves it takes. Returns the splits made.
pub(super) fn quality_loop(
    s: &Surface,
    feat: &patches::Features,
    p: &Params,
    opts: &DecomposeOptions,
    parts: &mut Vec<Part>,
    budget: usize,
    free: &dyn Fn(&Part) -> bool,
) -> usize {
    let mut unsplittable: Vec<bool> = parts.iter().map(|q| !free(q)).collect();
    let mut splits = 0;
    while parts.len() < budget {
        let worst = (0..parts.len())
            .filter(|&i| !unsplittable[i] && parts[i].dev > p.tol)
            .max_by(|&i, &j| parts[i].dev.total_cmp(&parts[j].dev).then(j.cmp(&i)));
        let Some(w) = worst else { break };
        match split(s, feat, p, opts, &parts[w], f64::INFINITY) {
            Some((a, b)) if free(&a) && free(&b) => {
                parts[w] = a;
                parts.push(b);
                unsplittable.push(false);
                splits += 1;
            }
            _ => unsplittable[w] = true,
        }
    }
    splits
}
