//! Splitting a patch in two: 2-means and area-median cuts across its PCA axes (and, for
//! `Strategy::Planes`, the scene axes); the candidates are ranked by their worse half.
//!
//! Entry points: [`split`], [`closest_splits`], [`split_ways`].

use super::*;

/// Split a part's patch in two; `None` when it cannot be split, or no split keeps both halves
/// below `bound` (∞: any split). Of the ways to split (see [`split_ways`]) the one whose worse
/// half deviates least is kept: a concave patch is thus cut across its most curved direction,
/// which halves its sagitta fastest.
pub(super) fn split(
    s: &Surface,
    f: &patches::Features,
    p: &Params,
    opts: &DecomposeOptions,
    part: &Part,
    bound: f64,
) -> Option<(Part, Part)> {
    let ways = split_ways(s, f, p, part, false);
    let mut best = closest_splits(s, p, opts, part, ways, bound, 1, &|_, _| true);
    best.pop().map(|(_, x)| x)
}

/// Of the ways of splitting `part` in two (see [`split_ways`]) whose halves both deviate less
/// than `bound` and that `admit` takes, the `keep` whose worse half deviates least, closest
/// first (ties: the earlier way), each with its index among the ways.
///
/// A way is built below the bound and, once `keep` admitted ways are built, below the `keep`-th
/// least deviation found so far (strictly above it, so that ties still go to the earlier way):
/// a half that deviates more is measured only until it passes that (see [`deviation_until`]),
/// and the other half is not built. The result is that of building every way in full. The
/// rebalancing keeps a split only below the deviation it replaces, and most of the ways it
/// tries fail (on the sneaker, 4,800 of the top-down strategy's 5,500 builds were the
/// rebalancing's before that bound; the sneaker took 2.15 → 1.93 s with it); the quality
/// loop's splits (`keep` 1) and the polishing's shortlists (see `polish.rs`) then need only
/// the closest.
#[allow(clippy::too_many_arguments)]
pub(super) fn closest_splits(
    s: &Surface,
    p: &Params,
    opts: &DecomposeOptions,
    part: &Part,
    ways: Vec<(Vec<u32>, Vec<u32>)>,
    bound: f64,
    keep: usize,
    admit: &(dyn Fn(&Part, &Part) -> bool + Sync),
) -> Vec<(usize, (Part, Part))> {
    // The worse halves' deviations of the admitted ways built so far.
    let found = Mutex::new(Vec::<f64>::new());
    let below = || {
        let mut v = found.lock().expect("no panic holding it").clone();
        if keep == 0 || v.len() < keep {
            return bound;
        }
        let (_, kth, _) = v.select_nth_unstable_by(keep - 1, f64::total_cmp);
        bound.min(kth.next_up())
    };
    let mut built: Vec<(usize, (Part, Part))> = ways
        .into_par_iter()
        .enumerate()
        .filter_map(|(k, (a, b))| {
            let half = |t| build_part_below(s, p, opts, t, part.cuts.clone(), below());
            let pa = half(a)?;
            let pb = half(b)?;
            if !admit(&pa, &pb) {
                return None;
            }
            found
                .lock()
                .expect("no panic holding it")
                .push(pa.dev.max(pb.dev));
            Some((k, (pa, pb)))
        })
        .collect();
    built.sort_by(closer_split);
    built.truncate(keep);
    built
}

/// The order of [`closest_splits`]: by the worse half's deviation, then by the way's index.
pub(super) fn closer_split(
    x: &(usize, (Part, Part)),
    y: &(usize, (Part, Part)),
) -> std::cmp::Ordering {
    let worse = |(_, (a, b)): &(usize, (Part, Part))| a.dev.max(b.dev);
    worse(x).total_cmp(&worse(y)).then(x.0.cmp(&y.0))
}

/// The ways of splitting a part's patch in two, in a fixed order: 2-means in feature space,
/// area-median cuts across the two main axes of the patch (PCA of the mid-wall positions), and
/// for [`Strategy::Planes`] cuts by planes normal to the scene axes. `fine` (the polishing)
/// adds cuts at a quarter and three quarters of the area along the principal axes, and the
/// plane cuts whatever the strategy.
pub(super) fn split_ways(
    s: &Surface,
    f: &patches::Features,
    p: &Params,
    part: &Part,
    fine: bool,
) -> Vec<(Vec<u32>, Vec<u32>)> {
    if part.tris.len() < 2 {
        return Vec::new();
    }
    debug_assert!(part.tris.is_sorted(), "a patch's triangles are ascending");
    let mut cands: Vec<(Vec<u32>, Vec<u32>)> = Vec::new();
    let halves = p.memo.halves(&part.tris, || {
        patches::kmeans(s, f, &part.tris, 2, p.lambda, 12)
    });
    // The memo hands back its own copy: the halves move into the candidates.
    if let Ok([a, b]) = <[Vec<u32>; 2]>::try_from(halves) {
        cands.push((a, b));
    }
    // PCA of the area-weighted mid-wall positions.
    let w: f64 = part.tris.iter().map(|&t| s.tri_area[t as usize]).sum();
    let mid_wall = part
        .tris
        .iter()
        .map(|&t| (f.pos[t as usize], s.tri_area[t as usize]));
    if let Some(eig) = geom::principal_axes(mid_wall) {
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| {
            eig.eigenvalues[b]
                .total_cmp(&eig.eigenvalues[a])
                .then(a.cmp(&b))
        });
        for &k in &order[..2] {
            let axis = eig.eigenvectors.column(k).into_owned();
            let by: Vec<(f64, u32)> = part
                .tris
                .iter()
                .map(|&t| (axis.dot(&f.pos[t as usize].coords), t))
                .collect();
            // Ordered along the axis, ties by triangle: every key differs, so an unstable
            // sort orders them as a stable one would.
            let mut sorted = by.clone();
            let key = |a: &(f64, u32), b: &(f64, u32)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
            sorted.sort_unstable_by(key);
            let fracs: &[f64] = if fine { &PLANE_FRACTIONS } else { &[0.5] };
            for &frac in fracs {
                let mut acc = 0.0;
                let mut cut = sorted.len() / 2;
                for (i, &(_, t)) in sorted.iter().enumerate() {
                    acc += s.tri_area[t as usize];
                    if acc >= frac * w {
                        cut = (i + 1).clamp(1, sorted.len() - 1);
                        break;
                    }
                }
                // The halves in the patch's (ascending) order: those before the first of the
                // second half along the axis, and the others.
                let first = sorted[cut];
                let (mut a, mut b) = (Vec::new(), Vec::new());
                for x in &by {
                    if key(x, &first).is_lt() {
                        a.push(x.1);
                    } else {
                        b.push(x.1);
                    }
                }
                cands.push((a, b));
            }
        }
    }
    if p.strategy == Strategy::Planes || fine {
        for axis in [V3::x(), V3::y(), V3::z()] {
            let x: Vec<f64> = part
                .tris
                .iter()
                .map(|&t| axis.dot(&s.tri_centroid[t as usize].coords))
                .collect();
            let lo = x.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            for frac in PLANE_FRACTIONS {
                let c = lo + frac * (hi - lo);
                let (mut a, mut b) = (Vec::new(), Vec::new());
                for (&t, &v) in part.tris.iter().zip(&x) {
                    if v < c {
                        a.push(t);
                    } else {
                        b.push(t);
                    }
                }
                if !a.is_empty() && !b.is_empty() && !cands.iter().any(|c| c.0 == a) {
                    cands.push((a, b));
                }
            }
        }
    }
    cands
}
