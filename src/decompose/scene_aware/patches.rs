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
    // area-weighted mean.
    let first = (0..tris.len())
        .max_by(|&i, &j| {
            let di = (f.pos[tris[i] as usize] - mean).norm_squared();
            let dj = (f.pos[tris[j] as usize] - mean).norm_squared();
            di.total_cmp(&dj).then(j.cmp(&i))
        })
        .unwrap();
    let seed = |i: usize| Centre::new(feats[i].pos, feats[i].orient);
    let mut centres = vec![seed(first)];
    let mut best: Vec<f64> = feats
        .par_iter()
        .with_min_len(MIN_LEN)
        .map(|x| dist2(x, &centres[0], lambda2))
        .collect();
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
        best.par_iter_mut()
            .zip(feats.par_iter())
            .with_min_len(MIN_LEN)
            .for_each(|(b, x)| {
                *b = b.min(dist2(x, &c, lambda2));
            });
        centres.push(c);
    }
    let mut assign: Vec<usize> = vec![usize::MAX; tris.len()];
    for _ in 0..iters.max(1) {
        let new: Vec<usize> = feats
            .par_iter()
            .with_min_len(MIN_LEN)
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
        // Update (sequential sums: a fixed order keeps the result bit-identical).
        let mut acc = vec![([0.0f64; 3], [0.0f64; 6], 0.0f64); centres.len()];
        for ((x, &w), &ci) in feats.iter().zip(&areas).zip(&assign) {
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
    let mut out: Vec<Vec<u32>> = vec![Vec::new(); centres.len()];
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
