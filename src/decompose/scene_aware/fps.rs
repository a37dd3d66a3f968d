//! Farthest-point sampling ([`farthest_points`], [`farthest_of`]) and its passes, compiled
//! twice: for the baseline x86-64 (two f64 a vector) and, chosen at run time when the processor
//! has it, for AVX2 (four). The same IEEE operations on the same values in the same order per
//! point (no fused multiply-add: AVX2 does not bring FMA, and Rust never contracts), so both
//! give the same picks to the bit; the wider one runs half the vector instructions (issue
//! #37: `farthest_points` was the largest single function of a decomposition, 11.5 % of the
//! plate's instructions).
//!
//! The points are taken in blocks of [`BLOCK`] consecutive ones, each with its box and its
//! largest distance to the kept set: a block whose box lies at least that far from the point
//! just kept cannot change (every point in it is at least as far from the new point as from
//! the kept set), so its pass is skipped and its largest kept as it was. The distances, hence
//! the picks, are those of the full passes to the bit (see [`picks`]).
//!
//! Entry points: [`farthest_points`], [`farthest_of`], [`picks`].

use crate::mesh::{P3, V3};

/// Points a lane group holds: each lane keeps its own farthest, so one pass updates the
/// distances and finds the farthest at once.
pub(super) const LANES: usize = 8;

/// Points a block holds (whole lanes): the unit a pass skips.
pub(super) const BLOCK: usize = 4 * LANES;

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
    let (mut xs, mut ys, mut zs) = (
        Vec::with_capacity(padded),
        Vec::with_capacity(padded),
        Vec::with_capacity(padded),
    );
    let mut sum = V3::zeros();
    for i in 0..n {
        let p = at(i);
        sum += p.coords;
        xs.push(p.x);
        ys.push(p.y);
        zs.push(p.z);
    }
    let c = sum / n as f64;
    let far2 = |i: usize| (V3::new(xs[i], ys[i], zs[i]) - c).norm_squared();
    let first = (0..n)
        .max_by(|&i, &j| far2(i).total_cmp(&far2(j)).then(j.cmp(&i)))
        .expect("n > k >= 0 points");
    for v in [&mut xs, &mut ys, &mut zs] {
        v.resize(padded, 0.0);
    }
    // The padding is at distance 0: never the farthest.
    let mut dist = vec![f64::INFINITY; padded];
    dist[n..].fill(0.0);
    picks(&xs, &ys, &zs, &mut dist, n, first, k)
}

/// Farthest-point sampling from `first` until `k` points are kept or no point is farther than
/// 0 from the kept ones: `xs`, `ys`, `zs` the coordinates of `n` points padded to whole lanes,
/// `dist` the squared distances to the kept set (`f64::INFINITY` for the points, 0 for the
/// padding, which is then never the farthest). Each pick is the point farthest from those
/// kept, the first of equals.
///
/// A block is skipped when the squared distance from the new point to its box, computed as a
/// point's is (`(dx·dx + dy·dy) + dz·dz`, each `d` a difference to the box's nearer face or
/// 0), is at least the block's largest distance: rounding is monotone, so every point's own
/// squared distance is at least the box's, hence at least its distance so far, and the
/// update `e < d` would have changed nothing. Blocks are consecutive indices, so the first
/// block holding the largest holds the first of equals.
pub(super) fn picks(
    xs: &[f64],
    ys: &[f64],
    zs: &[f64],
    dist: &mut [f64],
    n: usize,
    first: usize,
    k: usize,
) -> Vec<usize> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor has AVX2 (checked just above).
        return unsafe { picks_avx2(xs, ys, zs, dist, n, first, k) };
    }
    picks_body(xs, ys, zs, dist, n, first, k)
}

/// [`picks`] compiled for AVX2: [`picks_body`] inlined here is vectorised four f64 wide.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn picks_avx2(
    xs: &[f64],
    ys: &[f64],
    zs: &[f64],
    dist: &mut [f64],
    n: usize,
    first: usize,
    k: usize,
) -> Vec<usize> {
    picks_body(xs, ys, zs, dist, n, first, k)
}

/// One block: its points' box (padding left out) and its largest distance, with the first
/// index holding it.
#[derive(Clone, Copy)]
struct Block {
    lo: [f64; 3],
    hi: [f64; 3],
    max: f64,
    at: usize,
}

/// The squared distance from `l` to a box, rounded as a point's distance is (see [`picks`]).
#[inline(always)]
fn box_dist2(b: &Block, l: [f64; 3]) -> f64 {
    let gap = |a: usize| {
        if l[a] < b.lo[a] {
            b.lo[a] - l[a]
        } else if l[a] > b.hi[a] {
            l[a] - b.hi[a]
        } else {
            0.0
        }
    };
    let (dx, dy, dz) = (gap(0), gap(1), gap(2));
    dx * dx + dy * dy + dz * dz
}

#[cfg(test)]
thread_local! {
    /// Blocks skipped on this thread (the tests' proof that some were).
    static SKIPPED: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// The passes themselves (see [`picks`]).
#[inline(always)]
fn picks_body(
    xs: &[f64],
    ys: &[f64],
    zs: &[f64],
    dist: &mut [f64],
    n: usize,
    first: usize,
    k: usize,
) -> Vec<usize> {
    let padded = dist.len();
    let mut blocks: Vec<Block> = (0..padded.div_ceil(BLOCK))
        .map(|b| {
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for i in b * BLOCK..((b + 1) * BLOCK).min(n) {
                for (a, c) in [xs[i], ys[i], zs[i]].into_iter().enumerate() {
                    lo[a] = lo[a].min(c);
                    hi[a] = hi[a].max(c);
                }
            }
            // Not yet passed: never skipped (no box distance is at least ∞ but ∞'s own).
            Block {
                lo,
                hi,
                max: f64::INFINITY,
                at: b * BLOCK,
            }
        })
        .collect();
    let mut kept = vec![first];
    let mut last = first;
    while kept.len() < k {
        let (lx, ly, lz) = (xs[last], ys[last], zs[last]);
        for (b, blk) in blocks.iter_mut().enumerate() {
            // `>=` false for a NaN distance: the block is passed, as before.
            if blk.max.is_finite() && box_dist2(blk, [lx, ly, lz]) >= blk.max {
                #[cfg(test)]
                SKIPPED.with(|s| s.set(s.get() + 1));
                continue;
            }
            let r = b * BLOCK..((b + 1) * BLOCK).min(padded);
            // Each lane's largest and the chunk of its first occurrence: the first of equals
            // in the block is then the lowest index among the lanes holding the largest, with
            // no second pass over the distances to find it.
            let mut lanes = [0.0f64; LANES];
            let mut at = [0usize; LANES];
            for (c, (((d, x), y), z)) in dist[r.clone()]
                .chunks_exact_mut(LANES)
                .zip(xs[r.clone()].chunks_exact(LANES))
                .zip(ys[r.clone()].chunks_exact(LANES))
                .zip(zs[r.clone()].chunks_exact(LANES))
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
            let m = lanes
                .iter()
                .fold(0.0, |m: f64, &d| if d > m { d } else { m });
            blk.max = m;
            blk.at = (0..LANES)
                .filter(|&l| lanes[l] == m)
                .map(|l| r.start + at[l] * LANES + l)
                .min()
                .expect("m is a lane's largest");
        }
        let far = blocks
            .iter()
            .fold(0.0, |m: f64, b| if b.max > m { b.max } else { m });
        if far <= 0.0 {
            break;
        }
        last = blocks
            .iter()
            .find(|b| b.max == far)
            .expect("far is a block's largest")
            .at;
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
                    let base = picks_body(&c[0], &c[1], &c[2], &mut d1, n, first, k);
                    // SAFETY: AVX2 checked above.
                    let wide = unsafe { picks_avx2(&c[0], &c[1], &c[2], &mut d2, n, first, k) };
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

    /// The passes without blocks: every point updated each pass, the farthest the first of
    /// equals (the code before blocks were skipped).
    fn full_passes(pts: &[[f64; 3]], first: usize, k: usize) -> (Vec<usize>, Vec<f64>) {
        let mut dist = vec![f64::INFINITY; pts.len()];
        let mut kept = vec![first];
        let mut last = first;
        while kept.len() < k {
            let l = pts[last];
            let mut far = (0.0, 0);
            for (i, p) in pts.iter().enumerate() {
                let (dx, dy, dz) = (p[0] - l[0], p[1] - l[1], p[2] - l[2]);
                let e = dx * dx + dy * dy + dz * dz;
                if e < dist[i] {
                    dist[i] = e;
                }
                if dist[i] > far.0 {
                    far = (dist[i], i);
                }
            }
            if far.0 <= 0.0 {
                break;
            }
            last = far.1;
            kept.push(last);
        }
        (kept, dist)
    }

    /// Skipping the blocks whose box lies beyond their largest distance changes nothing: the
    /// picks and every distance are the full passes', to the bit, on clouds in index order
    /// along a curve (most blocks skipped), shuffled (few), with duplicates, points on a
    /// block's box faces, a lattice (ties everywhere) and coordinates far from the origin
    /// (rounding in the differences). Checked on the baseline build and, where the
    /// processor has it, the AVX2 one.
    #[test]
    fn skipped_blocks_change_nothing() {
        let mut rng = crate::rng::Rng::new(37);
        let mut clouds: Vec<Vec<[f64; 3]>> = Vec::new();
        for &n in &[9usize, 33, 64, 200, 1001, 3000] {
            // Along a helix, in index order: consecutive points are close.
            let helix: Vec<[f64; 3]> = (0..n)
                .map(|i| {
                    let t = i as f64 * 0.05;
                    [t.cos(), t.sin(), 0.01 * t + 1e-4 * rng.next_f64()]
                })
                .collect();
            let mut shuffled = helix.clone();
            for i in (1..n).rev() {
                shuffled.swap(i, rng.below(i as u64 + 1) as usize);
            }
            let far: Vec<[f64; 3]> = helix
                .iter()
                .map(|p| [1e6 + p[0], -3e5 + p[1], 7e4 + 1e-3 * p[2]])
                .collect();
            let dup: Vec<[f64; 3]> = helix.iter().map(|p| [p[0], p[1], 0.0]).collect();
            let dup: Vec<[f64; 3]> = dup.iter().chain(&dup).copied().collect();
            clouds.extend([helix, shuffled, far, dup]);
        }
        clouds.push(
            (0..10 * 10 * 10)
                .map(|i| [(i % 10) as f64, (i / 10 % 10) as f64, (i / 100) as f64])
                .collect(),
        );
        SKIPPED.with(|s| s.set(0));
        for pts in &clouds {
            let n = pts.len();
            let padded = n.div_ceil(LANES) * LANES;
            let mut c = [vec![0.0; padded], vec![0.0; padded], vec![0.0; padded]];
            for (i, p) in pts.iter().enumerate() {
                for a in 0..3 {
                    c[a][i] = p[a];
                }
            }
            for k in [2, 7, 32, 100] {
                for first in [0, n / 2, n - 1] {
                    let (want, want_d) = full_passes(pts, first, k);
                    let mut d = vec![f64::INFINITY; padded];
                    d[n..].fill(0.0);
                    let got = picks_body(&c[0], &c[1], &c[2], &mut d, n, first, k);
                    assert_eq!(got, want, "{n} points, k = {k}, first {first}");
                    let bits = |d: &[f64]| d.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&d[..n]), bits(&want_d), "{n} points, k = {k}");
                    #[cfg(target_arch = "x86_64")]
                    if std::arch::is_x86_feature_detected!("avx2") {
                        let mut d2 = vec![f64::INFINITY; padded];
                        d2[n..].fill(0.0);
                        // SAFETY: AVX2 checked just above.
                        let wide = unsafe { picks_avx2(&c[0], &c[1], &c[2], &mut d2, n, first, k) };
                        assert_eq!(wide, want);
                        assert_eq!(bits(&d2[..n]), bits(&want_d));
                    }
                }
            }
        }
        // The skip was taken (on the helices most blocks are skipped after a few picks).
        assert!(SKIPPED.with(|s| s.get()) > 1000);
    }
}
