//! Farthest-point sampling ([`farthest_points`], [`farthest_of`]) and its passes, compiled
//! twice: for the baseline x86-64 (two f64 a vector) and, chosen at run time when the processor
//! has it, for AVX2 (four). The same IEEE operations on the same values in the same order per
//! point (no fused multiply-add: AVX2 does not bring FMA, and Rust never contracts), so both
//! give the same picks to the bit; the wider one runs half the vector instructions (issue
//! #37: `farthest_points` was the largest single function of a decomposition, 11.5 % of the
//! plate's instructions).
//!
//! Entry points: [`farthest_points`], [`farthest_of`], [`picks`].

use crate::mesh::{P3, V3};

/// Points a lane group holds: each lane keeps its own farthest, so one pass updates the
/// distances and finds the farthest at once.
pub(super) const LANES: usize = 8;

/// Farthest-point sampling: indices of at most `k` points of `pts`, the first the point
/// farthest from their centroid (ties to the lower index). Deterministic.
pub fn farthest_points(pts: &[P3], k: usize) -> Vec<usize> {
    farthest_of(pts.len(), |i| pts[i], k)
}

/// [`farthest_points`] of the `n` points `at(0)`, …, `at(n - 1)`, read straight into the
/// passes' arrays (a patch's vertices by their mesh indices, with no list of points between
/// and no zeroed arrays).
pub fn farthest_of(n: usize, at: impl Fn(usize) -> P3, k: usize) -> Vec<usize> {
    if n <= k {
        return (0..n).collect();
    }
    // Coordinates apart, padded to whole lanes of `LANES` points, each lane keeping its own
    // farthest: the update and the maximum then run several points at a time in one pass
    // (2× quicker than one pass for each on 500 points, 3× on 10,000). The farthest is then
    // found by value, the first of equals (`picks`, AVX2 where the processor has it).
    let padded = n.div_ceil(LANES) * LANES;
    let (mut xs, mut ys, mut zs) = (
        Vec::with_capacity(padded),
        Vec::with_capacity(padded),
        Vec::with_capacity(padded),
    );
    // The centroid: the points' sum in their order, as a fold over them gives it.
    let mut sum = V3::zeros();
    for i in 0..n {
        let p = at(i);
        sum += p.coords;
        xs.push(p.x);
        ys.push(p.y);
        zs.push(p.z);
    }
    let c = sum / n as f64;
    // The farthest from it, the first of equals (in `total_cmp`'s order, as `max_by` with
    // ties to the lower index found it, each distance computed once).
    let mut first = 0;
    let mut far = f64::NEG_INFINITY;
    for i in 0..n {
        let d = (V3::new(xs[i], ys[i], zs[i]) - c).norm_squared();
        if i == 0 || d.total_cmp(&far).is_gt() {
            (first, far) = (i, d);
        }
    }
    for v in [&mut xs, &mut ys, &mut zs] {
        v.resize(padded, 0.0);
    }
    // The padding is at distance 0: never the farthest.
    let mut dist = vec![f64::INFINITY; padded];
    dist[n..].fill(0.0);
    picks(&xs, &ys, &zs, &mut dist, first, k)
}

/// Farthest-point sampling from `first` until `k` points are kept or no point is farther than
/// 0 from the kept ones: `xs`, `ys`, `zs` the coordinates padded to whole lanes, `dist` the
/// squared distances to the kept set (`f64::INFINITY` for the points, 0 for the padding,
/// which is then never the farthest). Each pick is the point farthest from those kept, the
/// first of equals.
pub(super) fn picks(
    xs: &[f64],
    ys: &[f64],
    zs: &[f64],
    dist: &mut [f64],
    first: usize,
    k: usize,
) -> Vec<usize> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor has AVX2 (checked just above).
        return unsafe { picks_avx2(xs, ys, zs, dist, first, k) };
    }
    picks_body(xs, ys, zs, dist, first, k)
}

/// [`picks`] compiled for AVX2: [`picks_body`] inlined here is vectorised four f64 wide.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn picks_avx2(
    xs: &[f64],
    ys: &[f64],
    zs: &[f64],
    dist: &mut [f64],
    first: usize,
    k: usize,
) -> Vec<usize> {
    picks_body(xs, ys, zs, dist, first, k)
}

/// The passes themselves (see [`picks`]).
#[inline(always)]
fn picks_body(
    xs: &[f64],
    ys: &[f64],
    zs: &[f64],
    dist: &mut [f64],
    first: usize,
    k: usize,
) -> Vec<usize> {
    let mut kept = vec![first];
    let mut last = first;
    while kept.len() < k {
        let (lx, ly, lz) = (xs[last], ys[last], zs[last]);
        // Each lane's largest and the chunk of its first occurrence: the first of equals
        // overall is then the lowest index among the lanes holding the largest, with no
        // second pass over the distances to find it.
        let mut lanes = [0.0f64; LANES];
        let mut at = [0usize; LANES];
        for (c, (((d, x), y), z)) in dist
            .chunks_exact_mut(LANES)
            .zip(xs.chunks_exact(LANES))
            .zip(ys.chunks_exact(LANES))
            .zip(zs.chunks_exact(LANES))
            .enumerate()
        {
            for l in 0..LANES {
                let (dx, dy, dz) = (x[l] - lx, y[l] - ly, z[l] - lz);
                let e = dx * dx + dy * dy + dz * dz;
                let v = if e < d[l] { e } else { d[l] };
                d[l] = v;
                let up = v > lanes[l];
                lanes[l] = if up { v } else { lanes[l] };
                at[l] = if up { c } else { at[l] };
            }
        }
        let far = lanes
            .iter()
            .fold(0.0, |m: f64, &d| if d > m { d } else { m });
        if far <= 0.0 {
            break;
        }
        last = (0..LANES)
            .filter(|&l| lanes[l] == far)
            .map(|l| at[l] * LANES + l)
            .min()
            .expect("far is a lane's largest");
        kept.push(last);
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX2 build and the baseline build pick the same points, and leave the same
    /// distances to the bit, on clouds of several sizes (whole lanes and not) with duplicates
    /// and ties (a lattice). Skipped where the processor has no AVX2.
    #[test]
    fn avx2_and_baseline_agree_bit_for_bit() {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            let mut rng = crate::rng::Rng::new(5);
            let mut clouds: Vec<Vec<[f64; 3]>> = [3usize, 8, 61, 500, 2049]
                .iter()
                .map(|&n| {
                    (0..n)
                        .map(|_| {
                            [
                                rng.next_f64() * 0.3 - 0.1,
                                rng.next_f64(),
                                1e-3 * rng.next_f64(),
                            ]
                        })
                        .collect()
                })
                .collect();
            clouds.push(
                (0..6 * 6 * 6)
                    .map(|i| [(i % 6) as f64, (i / 6 % 6) as f64, (i / 36) as f64])
                    .chain((0..40).map(|_| [1.0, 2.0, 3.0]))
                    .collect(),
            );
            let mut checked = 0;
            for pts in &clouds {
                let n = pts.len();
                let padded = n.div_ceil(LANES) * LANES;
                let mut c = [vec![0.0; padded], vec![0.0; padded], vec![0.0; padded]];
                for (i, p) in pts.iter().enumerate() {
                    for a in 0..3 {
                        c[a][i] = p[a];
                    }
                }
                for k in [1, 5, 32, 300] {
                    let first = n / 3;
                    let fresh = || {
                        let mut d = vec![f64::INFINITY; padded];
                        d[n..].fill(0.0);
                        d
                    };
                    let (mut d1, mut d2) = (fresh(), fresh());
                    let base = picks_body(&c[0], &c[1], &c[2], &mut d1, first, k);
                    // SAFETY: AVX2 checked above.
                    let wide = unsafe { picks_avx2(&c[0], &c[1], &c[2], &mut d2, first, k) };
                    assert_eq!(base, wide, "{n} points, k = {k}");
                    let bits = |d: &[f64]| d.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&d1), bits(&d2), "{n} points, k = {k}");
                    // The lattice holds 216 distinct points (its 40 extra copy one of them).
                    assert_eq!(base.len(), k.min(if n == 256 { 216 } else { n }));
                    checked += 1;
                }
            }
            assert_eq!(checked, 24);
        }
    }
}
