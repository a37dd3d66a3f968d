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
/// passes' arrays (a patch's vertices by their mesh indices, with no list of points between).
pub fn farthest_of(n: usize, at: impl Fn(usize) -> P3, k: usize) -> Vec<usize> {
    if n <= k {
        return (0..n).collect();
    }
    // Coordinates apart, padded to whole lanes of `LANES` points, each lane keeping its own
    // farthest: the update and the maximum then run several points at a time in one pass
    // (2× quicker than one pass for each on 500 points, 3× on 10,000). The farthest is then
    // found by value, the first of equals (`picks`, AVX2 where the processor has it).
    let padded = n.div_ceil(LANES) * LANES;
    // The points in a row (an exact-size collect: no capacity check a point), then each
    // coordinate copied out and padded (issue #37: zeroed arrays written again, or a `push` a
    // coordinate, cost more than these copies: `alloc_zeroed` read 5.8 k instructions an
    // array on `00005`).
    let pts: Vec<P3> = (0..n).map(at).collect();
    let coordinate = |a: usize| {
        let mut v = Vec::with_capacity(padded);
        v.extend(pts.iter().map(|p| p[a]));
        v.resize(padded, 0.0);
        v
    };
    let (xs, ys, zs) = (coordinate(0), coordinate(1), coordinate(2));
    // The centroid: the points' sum in their order, as a fold over them gives it.
    let sum = pts.iter().fold(V3::zeros(), |s, p| s + p.coords);
    let c = sum / n as f64;
    let first = farthest_from(&xs[..n], &ys[..n], &zs[..n], &c);
    // The padding is at distance 0: never the farthest.
    let mut dist = vec![f64::INFINITY; padded];
    dist[n..].fill(0.0);
    picks(&xs, &ys, &zs, &mut dist, first, k)
}

/// The point farthest from `c`, the first of equals in `total_cmp`'s order (as `max_by` with
/// ties to the lower index found it, each distance computed once).
///
/// When `c` is finite every coordinate is (it is their sum over `n`): each squared distance
/// is then a sum of squares, never a not-a-number nor −0, and `total_cmp` orders such values
/// as `>` does. The distances then go by lanes as in [`picks`], each lane its largest and the
/// chunk of its first occurrence, the first of equals the lowest index among the lanes holding
/// the largest, and the points past the last whole lane after them (a later index wins only
/// strictly). Otherwise one distance at a time by `total_cmp`.
fn farthest_from(xs: &[f64], ys: &[f64], zs: &[f64], c: &V3) -> usize {
    let n = xs.len();
    let d = |i: usize| (V3::new(xs[i], ys[i], zs[i]) - c).norm_squared();
    if !c.iter().all(|v| v.is_finite()) {
        let mut first = 0;
        let mut far = f64::NEG_INFINITY;
        for i in 0..n {
            let e = d(i);
            if i == 0 || e.total_cmp(&far).is_gt() {
                (first, far) = (i, e);
            }
        }
        return first;
    }
    let whole = n / LANES * LANES;
    let mut lanes = [f64::NEG_INFINITY; LANES];
    let mut at = [0usize; LANES];
    for (ch, ((x, y), z)) in xs[..whole]
        .chunks_exact(LANES)
        .zip(ys[..whole].chunks_exact(LANES))
        .zip(zs[..whole].chunks_exact(LANES))
        .enumerate()
    {
        for l in 0..LANES {
            let e = (V3::new(x[l], y[l], z[l]) - c).norm_squared();
            let up = e > lanes[l];
            lanes[l] = if up { e } else { lanes[l] };
            at[l] = if up { ch } else { at[l] };
        }
    }
    let mut far = lanes
        .iter()
        .fold(f64::NEG_INFINITY, |m: f64, &e| if e > m { e } else { m });
    let mut first = (0..LANES)
        .filter(|&l| whole > 0 && lanes[l] == far)
        .map(|l| at[l] * LANES + l)
        .min()
        .unwrap_or(0);
    for i in whole..n {
        let e = d(i);
        if i == 0 || e > far {
            (first, far) = (i, e);
        }
    }
    first
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

    /// `farthest_of` before issue #37's session 20 (pushes, the first point by `total_cmp`
    /// one distance at a time): the reference the lane-wise first point is checked against.
    fn farthest_of_plain(pts: &[P3], k: usize) -> Vec<usize> {
        let n = pts.len();
        if n <= k {
            return (0..n).collect();
        }
        let padded = n.div_ceil(LANES) * LANES;
        let (mut xs, mut ys, mut zs) = (Vec::new(), Vec::new(), Vec::new());
        let mut sum = V3::zeros();
        for p in pts {
            sum += p.coords;
            xs.push(p.x);
            ys.push(p.y);
            zs.push(p.z);
        }
        let c = sum / n as f64;
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
        let mut dist = vec![f64::INFINITY; padded];
        dist[n..].fill(0.0);
        picks_body(&xs, &ys, &zs, &mut dist, first, k)
    }

    /// The first point by lanes (and the slots written in place of pushes) picks what the
    /// plain loop picked, on clouds of 1–300 points (whole lanes and not) where the farthest
    /// from the centroid is tied (symmetric lattices, duplicates of the extremes, the tied
    /// point in the tail past the last whole lane), on overflowing distances (±1e200) and on
    /// not-finite coordinates (NaN, ±∞), where the plain loop is kept.
    #[test]
    fn lane_wise_first_point_is_the_plain_one() {
        let mut rng = crate::rng::Rng::new(37);
        let mut clouds: Vec<Vec<P3>> = Vec::new();
        for n in [1usize, 2, 7, 8, 9, 15, 16, 17, 33, 64, 101, 300] {
            // Random, a lattice of small integers (ties everywhere), and the two mixed.
            clouds.push(
                (0..n)
                    .map(|_| P3::new(rng.next_f64(), rng.next_f64() - 0.5, 1e-3 * rng.next_f64()))
                    .collect(),
            );
            let lattice: Vec<P3> = (0..n)
                .map(|i| P3::new((i % 3) as f64, (i / 3 % 3) as f64, (i / 9 % 2) as f64))
                .collect();
            clouds.push(lattice.clone());
            // The extremes duplicated at the end (ties only in the tail or across it).
            let mut tail = lattice;
            tail.extend_from_within(..n.min(5));
            clouds.push(tail);
        }
        // Symmetric: ±1 on each axis, every extreme tied with its mirror.
        clouds.push(
            (0..40)
                .map(|i| {
                    let s = if i % 2 == 0 { 1.0 } else { -1.0 };
                    P3::new(s * (i % 3) as f64, -s * (i % 5) as f64, s)
                })
                .collect(),
        );
        let mut big: Vec<P3> = (0..20).map(|i| P3::new(i as f64, 0.0, 0.0)).collect();
        big[3] = P3::new(1e200, 0.0, 0.0);
        big[17] = P3::new(-1e200, 5.0, 0.0);
        clouds.push(big.clone());
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut b = big.clone();
            b[3] = P3::new(1.0, bad, 0.0);
            b[5] = P3::new(2.0, 0.0, bad);
            clouds.push(b);
        }
        let mut checked = 0;
        for pts in &clouds {
            for k in [1, 2, 5, 32] {
                let fresh = farthest_of(pts.len(), |i| pts[i], k);
                assert_eq!(
                    fresh,
                    farthest_of_plain(pts, k),
                    "{} points, k = {k}",
                    pts.len()
                );
                // The first point itself, whatever `k`.
                if pts.len() > 1 {
                    let c = pts.iter().fold(V3::zeros(), |a, p| a + p.coords) / pts.len() as f64;
                    let (xs, ys, zs): (Vec<f64>, Vec<f64>, Vec<f64>) = (
                        pts.iter().map(|p| p.x).collect(),
                        pts.iter().map(|p| p.y).collect(),
                        pts.iter().map(|p| p.z).collect(),
                    );
                    assert_eq!(
                        farthest_from(&xs, &ys, &zs, &c),
                        farthest_of_plain(pts, 1.max(pts.len() - 1))[0]
                    );
                }
                checked += 1;
            }
        }
        assert_eq!(checked, 4 * clouds.len());
    }

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
