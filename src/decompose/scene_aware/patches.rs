//! Surface patches: deterministic k-means (farthest-point seeded Lloyd) on area-weighted
//! triangle features. The position of a triangle is its centroid moved inwards to the middle
//! of the wall (half the local thickness, when the wall is thin), so both sides of a thin wall
//! fall into the same patch and a patch becomes a *wall segment*; the orientation term compares
//! the normals' outer products `n·nᵀ` (blind to the sign, so opposite sides of a wall agree,
//! while a sharp edge costs `2·lambda²`).

use super::geom::Surface;
use crate::mesh::{P3, V3};
use rayon::prelude::*;

/// Per-triangle clustering features.
pub struct Features {
    /// Mid-wall position of each triangle.
    pub pos: Vec<P3>,
    /// `n·nᵀ` of each triangle normal, its upper triangle (see [`Sym`]).
    pub orient: Vec<Sym>,
}

/// A symmetric 3×3 matrix by its upper triangle: `[m00, m01, m02, m11, m12, m22]`.
pub type Sym = [f64; 6];

impl Features {
    /// `merge_depth`: walls up to twice this thick are merged; thicker material keeps its sides
    /// apart (positions moved in by `push` only).
    pub fn new(s: &Surface, merge_depth: f64, push: f64) -> Features {
        let pos = (0..s.tri_centroid.len())
            .into_par_iter()
            .map(|t| {
                let (c, n) = (s.tri_centroid[t], s.tri_normal[t]);
                let th = s.thickness(&c, &n, 2.0 * merge_depth);
                let d = if th <= 2.0 * merge_depth {
                    0.5 * th
                } else {
                    push
                };
                c - n * d
            })
            .collect();
        let orient = s
            .tri_normal
            .iter()
            .map(|n| {
                [
                    n.x * n.x,
                    n.x * n.y,
                    n.x * n.z,
                    n.y * n.y,
                    n.y * n.z,
                    n.z * n.z,
                ]
            })
            .collect();
        Features { pos, orient }
    }
}

/// A patch triangle's features, gathered in one place for the passes of [`kmeans`].
#[derive(Clone, Copy)]
struct Feat {
    pos: [f64; 3],
    orient: Sym,
}

/// A k-means centre: mean position, mean `n·nᵀ` and its squared Frobenius norm.
#[derive(Clone, Copy)]
struct Centre {
    pos: [f64; 3],
    orient: Sym,
    norm2: f64,
}

impl Centre {
    /// The squared Frobenius norm is summed as nalgebra sums a `Matrix3`'s (column by column,
    /// each column's squares left to right), so the clustering is the same, bit for bit, as
    /// when the features were `Matrix3`s.
    fn new(pos: [f64; 3], m: Sym) -> Centre {
        let col = |a: f64, b: f64, c: f64| a * a + b * b + c * c;
        let norm2 = col(m[0], m[1], m[2]) + col(m[1], m[3], m[4]) + col(m[2], m[4], m[5]);
        Centre {
            pos,
            orient: m,
            norm2,
        }
    }
}

/// Squared feature distance between a triangle and a centre: squared distance of the
/// positions plus `lambda²·|n nᵀ − M|²_F = lambda²·(1 − 2 nᵀMn + |M|²)`, with `nᵀMn` the
/// Frobenius product `⟨n nᵀ, M⟩`, summed in the column-major order of a `Matrix3`'s
/// `component_mul(..).sum()` (each off-diagonal product twice).
#[inline]
fn dist2(x: &Feat, c: &Centre, lambda2: f64) -> f64 {
    let (o, m) = (&x.orient, &c.orient);
    let (d00, d01, d02) = (o[0] * m[0], o[1] * m[1], o[2] * m[2]);
    let (d11, d12, d22) = (o[3] * m[3], o[4] * m[4], o[5] * m[5]);
    let n_m_n = d00 + d01 + d02 + d01 + d11 + d12 + d02 + d12 + d22;
    let (dx, dy, dz) = (
        x.pos[0] - c.pos[0],
        x.pos[1] - c.pos[1],
        x.pos[2] - c.pos[2],
    );
    (dx * dx + dy * dy + dz * dz) + lambda2 * (1.0 - 2.0 * n_m_n + c.norm2)
}

/// Fewest triangles a thread takes at a time: the polishing's 2-means of a patch of a few
/// hundred triangles runs on one, where splitting it cost more than it saved.
const MIN_LEN: usize = 1024;

/// Split the triangles `tris` into at most `k` patches. Deterministic; patches ordered by their
/// first triangle, each patch's triangles ascending.
pub fn kmeans(
    s: &Surface,
    f: &Features,
    tris: &[u32],
    k: usize,
    lambda: f64,
    iters: usize,
) -> Vec<Vec<u32>> {
    if tris.is_empty() {
        return Vec::new();
    }
    let k = k.clamp(1, tris.len());
    let lambda2 = lambda * lambda;
    // The features of the patch in a row: the passes below read them in order.
    let feats: Vec<Feat> = tris
        .iter()
        .map(|&t| {
            let p = f.pos[t as usize];
            Feat {
                pos: [p.x, p.y, p.z],
                orient: f.orient[t as usize],
            }
        })
        .collect();
    let areas: Vec<f64> = tris.iter().map(|&t| s.tri_area[t as usize]).collect();
    let total_w: f64 = areas.iter().sum::<f64>().max(1e-300);
    let mean = P3::from(
        tris.iter()
            .zip(&areas)
            .fold(V3::zeros(), |a, (&t, &w)| a + f.pos[t as usize].coords * w)
            / total_w,
    );
    // Farthest-point seeding in feature space, starting from the triangle farthest from the
    // area-weighted mean (the first of equals in `total_cmp`'s order, each distance computed
    // once).
    let mut first = 0;
    let mut far = f64::NEG_INFINITY;
    for (i, x) in feats.iter().enumerate() {
        let d = (P3::from(x.pos) - mean).norm_squared();
        if i == 0 || d.total_cmp(&far).is_gt() {
            (first, far) = (i, d);
        }
    }
    let seed = |i: usize| Centre::new(feats[i].pos, feats[i].orient);
    let mut centres = vec![seed(first)];
    let mut best: Vec<f64> = feats
        .par_iter()
        .with_min_len(MIN_LEN)
        .map(|x| dist2(x, &centres[0], lambda2))
        .collect();
    // With k = 2, `best` stays each triangle's distance to the first centre (the last seed's
    // distances are not folded in: nothing reads them after the seeding), which the first
    // assignment then reads instead of computing it again.
    while centres.len() < k {
        let (i, d) = best
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(&a.0)))
            .unwrap();
        if *d <= 1e-300 {
            break;
        }
        let c = seed(i);
        if centres.len() + 1 < k {
            best.par_iter_mut()
                .zip(feats.par_iter())
                .with_min_len(MIN_LEN)
                .for_each(|(b, x)| {
                    *b = b.min(dist2(x, &c, lambda2));
                });
        }
        centres.push(c);
    }
    let first_dist = (k == 2 && centres.len() == 2).then_some(best.as_slice());
    let assign = lloyd(&feats, &areas, centres, lambda2, iters, first_dist);
    let mut out: Vec<Vec<u32>> = vec![Vec::new(); k];
    for (i, &t) in tris.iter().enumerate() {
        out[assign[i]].push(t);
    }
    out.retain(|p| !p.is_empty());
    for p in &mut out {
        p.sort_unstable();
    }
    out.sort_by_key(|p| p[0]);
    out
}

/// Relative (and, times `lambda²`, absolute) slack of [`lloyd`]'s bounds: far above the
/// rounding of [`dist2`] (about 1e-13 of `lambda²` and 1e-15 of the position term for
/// features within `[-1, 1]`), so a bound that proves a triangle's centre is also what the
/// computed distances would pick.
const SLACK: f64 = 1e-9;

/// A triangle's bounds in [`lloyd`]: its centre `a`, `u` at least its distance to it and `l`
/// at most its distance to any other centre (distances in feature space, not squared).
#[derive(Clone, Copy)]
struct Bound {
    a: usize,
    u: f64,
    l: f64,
}

/// Lloyd's iterations from `centres`: each triangle goes to the centre of least [`dist2`],
/// the first of equals, until no triangle moves or `iters` rounds; the centres are the
/// area-weighted means of their triangles, summed in the triangles' order. `first_dist`:
/// each triangle's `dist2` to the first of two centres, already computed. Returns each
/// triangle's centre.
///
/// Hamerly's bounds (issue #37): [`dist2`] is a squared Euclidean distance `D²` in the
/// feature space `(pos, lambda·n nᵀ)` plus a term of the triangle alone
/// (`lambda²·(1 − |n nᵀ|²)`, 0 but for rounding and degenerate normals), so the triangle
/// inequality bounds `D`: a triangle keeps an upper bound `u` on `D` to its centre and a lower
/// bound `l` on `D` to every other; when the centres move by `δ`, `u += δ(own)` and
/// `l −= max δ(others)`. While `l² − u²` exceeds the slack (see [`SLACK`]) its computed
/// distances would pick the same centre, strictly, so they are not computed. Otherwise they
/// are, in the same order with the same first-of-equals rule. The assignment of every round is
/// thus the plain one, and so are the sums and the centres, bit for bit. The bounds are used
/// only when every feature's `n nᵀ` entry lies in `[-1, 1]` and its position is finite (what
/// the rounding estimate assumes; unit normals give it).
fn lloyd(
    feats: &[Feat],
    areas: &[f64],
    centres: Vec<Centre>,
    lambda2: f64,
    iters: usize,
    first_dist: Option<&[f64]>,
) -> Vec<usize> {
    lloyd_counted(feats, areas, centres, lambda2, iters, first_dist).0
}

/// [`lloyd`], and how many triangle-rounds its bounds skipped (for its tests).
fn lloyd_counted(
    feats: &[Feat],
    areas: &[f64],
    mut centres: Vec<Centre>,
    lambda2: f64,
    iters: usize,
    first_dist: Option<&[f64]>,
) -> (Vec<usize>, usize) {
    let n = feats.len();
    let k = centres.len();
    let mut skipped = 0;
    let bounded = feats
        .iter()
        .all(|x| x.pos.iter().all(|v| v.is_finite()) && x.orient.iter().all(|v| v.abs() <= 1.0));
    let mut state = vec![
        Bound {
            a: usize::MAX,
            u: f64::INFINITY,
            l: 0.0,
        };
        n
    ];
    // How far each centre moved in the last update, and the most any other centre did.
    let mut drift = vec![0.0f64; k];
    let mut others = vec![0.0f64; k];
    for round in 0..iters.max(1) {
        let first = if round == 0 { first_dist } else { None };
        let (centres_now, drift_now, others_now) = (&centres, &drift, &others);
        let (changed, skips) = state
            .par_iter_mut()
            .zip(feats.par_iter())
            .enumerate()
            .with_min_len(MIN_LEN)
            .map(|(i, (b, x))| {
                if bounded && b.a != usize::MAX {
                    let u = (b.u + drift_now[b.a]) * (1.0 + SLACK);
                    let l = (b.l - others_now[b.a]) * (1.0 - SLACK);
                    let l = if l > 0.0 { l } else { 0.0 };
                    if l * l * (1.0 - SLACK) - u * u * (1.0 + SLACK) - 2.0 * SLACK * lambda2 > 0.0 {
                        (b.u, b.l) = (u, l);
                        return (false, 1);
                    }
                }
                // The plain assignment: every distance, the first of the least.
                let (mut bi, mut bd, mut second) = (0, f64::INFINITY, f64::INFINITY);
                for (ci, c) in centres_now.iter().enumerate() {
                    let d = match first {
                        Some(f) if ci == 0 => f[i],
                        _ => dist2(x, c, lambda2),
                    };
                    if d < bd {
                        second = bd;
                        bd = d;
                        bi = ci;
                    } else if d < second {
                        second = d;
                    }
                }
                // `D²` is the computed distance less the triangle's own term, within the slack.
                let o = &x.orient;
                let own = lambda2
                    * (1.0
                        - (o[0] * o[0]
                            + o[3] * o[3]
                            + o[5] * o[5]
                            + 2.0 * (o[1] * o[1] + o[2] * o[2] + o[4] * o[4])));
                let above = |d: f64| {
                    let e = d - own;
                    let e = if e > 0.0 { e } else { 0.0 };
                    (e * (1.0 + SLACK) + SLACK * lambda2).sqrt() * (1.0 + SLACK)
                };
                let below = |d: f64| {
                    let e = d - own;
                    let e = if e > 0.0 { e } else { 0.0 };
                    let e = e * (1.0 - SLACK) - SLACK * lambda2;
                    if e > 0.0 {
                        e.sqrt() * (1.0 - SLACK)
                    } else {
                        0.0
                    }
                };
                // Not a number anywhere: no bound (the next round computes again).
                let (u, l) = if !bounded || bd.is_nan() || second.is_nan() || k < 2 {
                    (f64::INFINITY, 0.0)
                } else {
                    (above(bd), below(second))
                };
                let moved = b.a != bi;
                *b = Bound { a: bi, u, l };
                (moved, 0)
            })
            .reduce(|| (false, 0), |x, y| (x.0 | y.0, x.1 + y.1));
        skipped += skips;
        if !changed {
            break;
        }
        // Update (sequential sums: a fixed order keeps the result bit-identical).
        let mut acc = vec![([0.0f64; 3], [0.0f64; 6], 0.0f64); k];
        for ((x, &w), b) in feats.iter().zip(areas).zip(&state) {
            let a = &mut acc[b.a];
            for (s, v) in a.0.iter_mut().zip(x.pos) {
                *s += v * w;
            }
            for (s, v) in a.1.iter_mut().zip(x.orient) {
                *s += v * w;
            }
            a.2 += w;
        }
        for ((c, a), d) in centres.iter_mut().zip(&acc).zip(drift.iter_mut()) {
            *d = 0.0;
            if a.2 > 0.0 {
                let new = Centre::new(a.0.map(|v| v / a.2), a.1.map(|v| v / a.2));
                let dp = (0..3).map(|j| (new.pos[j] - c.pos[j]).powi(2)).sum::<f64>();
                let dm = (0..6)
                    .map(|j| {
                        (new.orient[j] - c.orient[j]).powi(2) * [1.0, 2.0, 2.0, 1.0, 2.0, 1.0][j]
                    })
                    .sum::<f64>();
                // NaN stays NaN: the bounds then never hold.
                *d = (dp + lambda2 * dm).sqrt() * (1.0 + SLACK);
                *c = new;
            }
        }
        for (j, o) in others.iter_mut().enumerate() {
            *o = (0..k)
                .filter(|&i| i != j)
                .map(|i| drift[i])
                .fold(0.0, |m: f64, d| if d > m || d.is_nan() { d } else { m });
        }
    }
    (state.into_iter().map(|b| b.a).collect(), skipped)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plain Lloyd's iterations `lloyd` replaced (every distance every round).
    fn plain(
        feats: &[Feat],
        areas: &[f64],
        mut centres: Vec<Centre>,
        lambda2: f64,
        iters: usize,
    ) -> Vec<usize> {
        let mut assign: Vec<usize> = vec![usize::MAX; feats.len()];
        for _ in 0..iters.max(1) {
            let new: Vec<usize> = feats
                .iter()
                .map(|x| {
                    let mut bi = 0;
                    let mut bd = f64::INFINITY;
                    for (ci, c) in centres.iter().enumerate() {
                        let d = dist2(x, c, lambda2);
                        if d < bd {
                            bd = d;
                            bi = ci;
                        }
                    }
                    bi
                })
                .collect();
            if new == assign {
                break;
            }
            assign = new;
            let mut acc = vec![([0.0f64; 3], [0.0f64; 6], 0.0f64); centres.len()];
            for ((x, &w), &ci) in feats.iter().zip(areas).zip(&assign) {
                let a = &mut acc[ci];
                for (s, v) in a.0.iter_mut().zip(x.pos) {
                    *s += v * w;
                }
                for (s, v) in a.1.iter_mut().zip(x.orient) {
                    *s += v * w;
                }
                a.2 += w;
            }
            for (c, a) in centres.iter_mut().zip(&acc) {
                if a.2 > 0.0 {
                    *c = Centre::new(a.0.map(|v| v / a.2), a.1.map(|v| v / a.2));
                }
            }
        }
        assign
    }

    fn feat(p: [f64; 3], n: [f64; 3]) -> Feat {
        Feat {
            pos: p,
            orient: [
                n[0] * n[0],
                n[0] * n[1],
                n[0] * n[2],
                n[1] * n[1],
                n[1] * n[2],
                n[2] * n[2],
            ],
        }
    }

    /// The bounded iterations assign every triangle as the plain ones, on random clouds and on
    /// lattices full of ties (points equidistant from two centres, duplicates, equal areas),
    /// for k = 2 (with and without the seeding's distances), 3 and 7, with lambda from 0 to
    /// large; and the bounds do skip (else this would test nothing).
    #[test]
    fn bounded_lloyd_is_plain_lloyd() {
        let mut rng = crate::rng::Rng::new(37);
        let mut skipped = 0;
        let mut total = 0;
        let mut cases = 0;
        for case in 0..120 {
            let n = [5, 40, 300, 2000][case % 4];
            let lattice = case % 3 == 0;
            let feats: Vec<Feat> = (0..n)
                .map(|i| {
                    if lattice {
                        // Integer positions, axis normals: distances tie exactly.
                        let p = [(i % 4) as f64, (i / 4 % 3) as f64, 0.0];
                        let mut nn = [0.0; 3];
                        nn[i % 3] = if i % 2 == 0 { 1.0 } else { -1.0 };
                        feat(p, nn)
                    } else {
                        let p = [rng.next_f64(), 0.3 * rng.next_f64(), rng.next_f64() - 0.5];
                        let v = [
                            rng.next_f64() - 0.5,
                            rng.next_f64() - 0.5,
                            rng.next_f64() - 0.5,
                        ];
                        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                        feat(p, v.map(|x| x / l))
                    }
                })
                .collect();
            let areas: Vec<f64> = (0..n)
                .map(|_| if lattice { 1.0 } else { rng.next_f64() })
                .collect();
            let lambda = [0.0, 0.05, 0.3, 3.0][case / 4 % 4];
            let lambda2 = lambda * lambda;
            let k = [2, 2, 3, 7][case / 16 % 4].min(n);
            // Seeds: distinct triangles spread over the patch.
            let centres: Vec<Centre> = (0..k)
                .map(|j| {
                    let x = &feats[j * n / k];
                    Centre::new(x.pos, x.orient)
                })
                .collect();
            let want = plain(&feats, &areas, centres.clone(), lambda2, 12);
            let (got, s) = lloyd_counted(&feats, &areas, centres.clone(), lambda2, 12, None);
            assert_eq!(got, want, "case {case}: n {n}, k {k}, lambda {lambda}");
            if k == 2 {
                let d0: Vec<f64> = feats
                    .iter()
                    .map(|x| dist2(x, &centres[0], lambda2))
                    .collect();
                let (got, _) = lloyd_counted(&feats, &areas, centres, lambda2, 12, Some(&d0));
                assert_eq!(got, want, "case {case} with the seeding's distances");
            }
            skipped += s;
            total += n;
            cases += 1;
        }
        assert_eq!(cases, 120);
        assert!(
            skipped > total,
            "the bounds skipped {skipped} of the triangle-rounds"
        );
    }

    /// Out of the bounds' assumptions (entries beyond [-1, 1], a position not finite) the
    /// plain assignment runs, and agrees.
    #[test]
    fn unbounded_features_fall_back_to_plain() {
        let mut rng = crate::rng::Rng::new(3);
        for bad in 0..2 {
            let mut feats: Vec<Feat> = (0..500)
                .map(|_| feat([rng.next_f64(), rng.next_f64(), 0.0], [0.0, 0.0, 1.0]))
                .collect();
            if bad == 0 {
                feats[7].orient[0] = 4.0;
            } else {
                feats[7].pos[1] = f64::NAN;
            }
            let areas = vec![1.0; 500];
            let centres = vec![
                Centre::new(feats[0].pos, feats[0].orient),
                Centre::new(feats[250].pos, feats[250].orient),
            ];
            let want = plain(&feats, &areas, centres.clone(), 0.01, 12);
            let (got, skipped) = lloyd_counted(&feats, &areas, centres, 0.01, 12, None);
            assert_eq!(got, want);
            assert_eq!(skipped, 0);
        }
    }
}
