//! Splitting a patch in two: 2-means and area-median cuts across its PCA axes (and, for
//! `Strategy::Planes`, the scene axes); the candidates are ranked by their worse half.
//!
//! Entry points: [`split`], [`closest_splits`], [`split_ways`]; [`sorted_along`].

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
            // Ordered along the axis, ties by triangle.
            let sorted = sorted_along(&by);
            let key = along;
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
                // (the keys distinct, `cut` of them order before it).
                let first = sorted[cut];
                let (mut a, mut b) = (Vec::with_capacity(cut), Vec::with_capacity(by.len() - cut));
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

/// The order of [`sorted_along`]: by the key (`total_cmp`), then by the triangle.
fn along(a: &(f64, u32), b: &(f64, u32)) -> std::cmp::Ordering {
    a.0.total_cmp(&b.0).then(a.1.cmp(&b.1))
}

/// Fewest keys [`sorted_along`] buckets; below, a comparison sort.
const BUCKET_FROM: usize = 64;

/// `by` (a key along an axis and a triangle, the pairs distinct) ordered by [`along`], as a
/// comparison sort orders them, but by buckets (issue #37: the two sorts of `split_ways` took
/// 3.4 G instructions of `00005`): each key goes to one of `n / 2` buckets evenly spaced
/// between the least and the largest key, `⌊(x − lo)·scale⌋`, which never decreases as `x`
/// grows (each rounded step is monotone), so every key of a bucket orders before every key of
/// a later one; each bucket, a few pairs, is then sorted by [`along`] itself. Keys not all
/// finite, or all equal, take the comparison sort.
pub(super) fn sorted_along(by: &[(f64, u32)]) -> Vec<(f64, u32)> {
    let n = by.len();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &(x, _) in by {
        lo = lo.min(x);
        hi = hi.max(x);
    }
    let nb = n / 2;
    let scale = nb as f64 / (hi - lo);
    let finite = by.iter().all(|(x, _)| x.is_finite());
    if n < BUCKET_FROM || !finite || !(hi > lo) || !scale.is_finite() {
        let mut v = by.to_vec();
        v.sort_unstable_by(along);
        return v;
    }
    let bucket = |x: f64| (((x - lo) * scale) as usize).min(nb - 1);
    let mut start = vec![0u32; nb + 1];
    for &(x, _) in by {
        start[bucket(x) + 1] += 1;
    }
    for b in 0..nb {
        start[b + 1] += start[b];
    }
    let mut next = start.clone();
    let mut out = vec![(0.0, 0u32); n];
    for &p in by {
        let b = bucket(p.0);
        out[next[b] as usize] = p;
        next[b] += 1;
    }
    for b in 0..nb {
        let part = &mut out[start[b] as usize..start[b + 1] as usize];
        if part.len() <= 16 {
            // Insertion sort: a bucket holds two pairs on average.
            for i in 1..part.len() {
                let mut j = i;
                while j > 0 && along(&part[j - 1], &part[j]).is_gt() {
                    part.swap(j - 1, j);
                    j -= 1;
                }
            }
        } else {
            part.sort_unstable_by(along);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The buckets order every set as the comparison sort does: uniform and clustered keys,
    /// ties (keys repeated, +0 and -0), a few far outliers, keys not finite, all keys equal,
    /// sets below and above the bucketing size.
    #[test]
    fn sorted_along_is_the_comparison_sort() {
        let mut rng = crate::rng::Rng::new(11);
        let mut checked = 0;
        for case in 0..400 {
            let n = [3, 63, 64, 65, 200, 1000, 5000][case % 7];
            let kind = case / 7 % 6;
            let mut by: Vec<(f64, u32)> = (0..n as u32)
                .map(|t| {
                    let r = rng.next_f64();
                    let x = match kind {
                        0 => r * 2.0 - 1.0,
                        // Clustered: most keys in a hundredth of the range.
                        1 => {
                            if r < 0.9 {
                                1e-2 * r
                            } else {
                                50.0 * r
                            }
                        }
                        // Few distinct values (ties broken by triangle), with both zeros.
                        2 => [(-0.0), 0.0, 1.5, -3.25][(r * 4.0) as usize],
                        3 => (r * 10.0).round() * 1e-300,
                        4 => {
                            if t % 97 == 5 {
                                [f64::NAN, f64::INFINITY, -f64::NAN][t as usize % 3]
                            } else {
                                r
                            }
                        }
                        _ => 0.25,
                    };
                    (x, t * 3 + 1)
                })
                .collect();
            if case % 2 == 1 {
                // Triangles ascending, as split_ways gives them, or not.
                by.reverse();
            }
            let mut want = by.clone();
            want.sort_unstable_by(along);
            let got = sorted_along(&by);
            let bits =
                |v: &[(f64, u32)]| v.iter().map(|p| (p.0.to_bits(), p.1)).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&want), "case {case}: n {n}, kind {kind}");
            checked += 1;
        }
        assert_eq!(checked, 400);
    }
}
