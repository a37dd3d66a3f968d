//! Surface patches: deterministic k-means (farthest-point seeded Lloyd) on area-weighted
//! triangle features. The position of a triangle is its centroid moved inwards to the middle
//! of the wall (half the local thickness, when the wall is thin), so both sides of a thin wall
//! fall into the same patch and a patch becomes a *wall segment*; the orientation term compares
//! the normals' outer products `n·nᵀ` (blind to the sign, so opposite sides of a wall agree,
//! while a sharp edge costs `2·lambda²`).

use super::geom::Surface;
use crate::mesh::{P3, V3};
use nalgebra::Matrix3;
use rayon::prelude::*;

/// Per-triangle clustering features.
pub struct Features {
    /// Mid-wall position of each triangle.
    pub pos: Vec<P3>,
    /// `n·nᵀ` of each triangle normal.
    pub orient: Vec<Matrix3<f64>>,
}

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
        let orient = s.tri_normal.iter().map(|n| n * n.transpose()).collect();
        Features { pos, orient }
    }
}

/// Squared feature distance between triangle `t` and a centre `(c, m, |m|²)`.
#[inline]
fn dist2(f: &Features, t: usize, c: &(P3, Matrix3<f64>, f64), lambda2: f64) -> f64 {
    let n_m_n = {
        let o = &f.orient[t];
        // nᵀ M n = ⟨n nᵀ, M⟩ (Frobenius)
        o.component_mul(&c.1).sum()
    };
    (f.pos[t] - c.0).norm_squared() + lambda2 * (1.0 - 2.0 * n_m_n + c.2)
}

/// Fewest triangles a thread takes at a time: the polishing's 2-means of a patch of a few
/// hundred triangles runs on one, where splitting it cost more than it saved.
const MIN_LEN: usize = 1024;

fn centre(p: P3, m: Matrix3<f64>) -> (P3, Matrix3<f64>, f64) {
    (p, m, m.norm_squared())
}

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
    let total_w: f64 = tris
        .iter()
        .map(|&t| s.tri_area[t as usize])
        .sum::<f64>()
        .max(1e-300);
    let mean = P3::from(
        tris.iter().fold(V3::zeros(), |a, &t| {
            a + f.pos[t as usize].coords * s.tri_area[t as usize]
        }) / total_w,
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
    let seed = |t: usize| centre(f.pos[t], f.orient[t]);
    let mut centres = vec![seed(tris[first] as usize)];
    let mut best: Vec<f64> = tris
        .par_iter()
        .with_min_len(MIN_LEN)
        .map(|&t| dist2(f, t as usize, &centres[0], lambda2))
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
        let c = seed(tris[i] as usize);
        best.par_iter_mut()
            .zip(tris.par_iter())
            .with_min_len(MIN_LEN)
            .for_each(|(b, &u)| {
                *b = b.min(dist2(f, u as usize, &c, lambda2));
            });
        centres.push(c);
    }
    let mut assign: Vec<usize> = vec![usize::MAX; tris.len()];
    for _ in 0..iters.max(1) {
        let new: Vec<usize> = tris
            .par_iter()
            .with_min_len(MIN_LEN)
            .map(|&t| {
                let mut bi = 0;
                let mut bd = f64::INFINITY;
                for (ci, c) in centres.iter().enumerate() {
                    let d = dist2(f, t as usize, c, lambda2);
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
        let mut acc = vec![(V3::zeros(), Matrix3::zeros(), 0.0f64); centres.len()];
        for (i, &t) in tris.iter().enumerate() {
            let w = s.tri_area[t as usize];
            let a = &mut acc[assign[i]];
            a.0 += f.pos[t as usize].coords * w;
            a.1 += f.orient[t as usize] * w;
            a.2 += w;
        }
        for (c, a) in centres.iter_mut().zip(&acc) {
            if a.2 > 0.0 {
                *c = centre(P3::from(a.0 / a.2), a.1 / a.2);
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
