//! Quality metrics of a decomposition, the same for every engine (used by the tests and by
//! `examples/bench_decompose.rs`).
//!
//! * **Surface distance**: points sampled uniformly (by area) on the boundary of the union of
//!   the hulls — points on a hull's surface that lie inside another hull of the same set are
//!   skipped, since they are not collision surface — and their unsigned distance to the mesh
//!   surface, divided by the mesh's bounding-box diagonal.
//! * **Volume ratio**: volume of the union of the hulls (grid sampling, exact face-plane tests)
//!   over the mesh's enclosed volume.
//! * **Uncovered**: fraction of the mesh surface (sampled) farther than 0.1 % of the diagonal
//!   outside every hull.
//! * **Cavity kept**: for containers (see [`cavity_probe`]), whether the probe point in the
//!   cavity is outside every hull.

use super::geom::{sample_hull, Surface};
use crate::decompose::Hull;
use crate::mesh::{Aabb, Mesh, P3, V3};
use rayon::prelude::*;

/// Measured quality of a set of hulls for one mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Quality {
    pub hulls: usize,
    pub max_vertices: usize,
    pub min_thickness: f64,
    pub volume_ratio: f64,
    pub dist_mean: f64,
    pub dist_p95: f64,
    pub dist_max: f64,
    pub uncovered: f64,
    /// `None` when the mesh is not a container.
    pub cavity_kept: Option<bool>,
}

/// Measure `hulls` against `mesh`.
pub fn measure(mesh: &Mesh, hulls: &[Hull]) -> Quality {
    let Some(s) = Surface::new(mesh) else {
        return Quality::default();
    };
    let d = surface_distances(&s, hulls, 20_000);
    let (mean, p95, max) = stats(&d);
    let vol = s.mesh.signed_volume().abs();
    Quality {
        hulls: hulls.len(),
        max_vertices: hulls.iter().map(|h| h.vertices.len()).max().unwrap_or(0),
        min_thickness: hulls
            .iter()
            .map(|h| h.thickness())
            .fold(f64::INFINITY, f64::min),
        volume_ratio: if vol > 0.0 {
            union_volume(hulls, 96) / vol
        } else {
            f64::NAN
        },
        dist_mean: mean,
        dist_p95: p95,
        dist_max: max,
        uncovered: uncovered(&s, hulls, 8_000),
        cavity_kept: cavity_probe(&s).map(|p| !hulls.iter().any(|h| h.contains(&p))),
    }
}

/// Mean, 95th percentile and maximum (0s for an empty set).
pub fn stats(d: &[f64]) -> (f64, f64, f64) {
    if d.is_empty() {
        return (0.0, 0.0, 0.0);
    }
    let mut v = d.to_vec();
    v.sort_by(f64::total_cmp);
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    (
        mean,
        v[(v.len() * 95 / 100).min(v.len() - 1)],
        v[v.len() - 1],
    )
}

/// Distances (relative to the diagonal) from about `n` points on the boundary of the union of
/// the hulls to the mesh surface. A point within 1e-6 of the diagonal of another hull is on a
/// seam between two hulls, inside the union: CoACD cuts a solid into pieces that meet on their
/// cut planes, and with 1e-9 rounding left its YCB pear's inner cut faces on the boundary
/// (p95 5.87 % of the diagonal, 1.80 % as seams).
pub fn surface_distances(s: &Surface, hulls: &[Hull], n: usize) -> Vec<f64> {
    let areas: Vec<f64> = hulls.iter().map(|h| h.mesh().area()).collect();
    let total: f64 = areas.iter().sum();
    if !(total > 0.0) {
        return Vec::new();
    }
    let eps = 1e-6 * s.diag;
    hulls
        .par_iter()
        .enumerate()
        .flat_map_iter(|(i, h)| {
            let k = ((areas[i] / total) * n as f64).ceil() as usize;
            sample_hull(h, k, 0xd15 + i as u64)
                .into_iter()
                .filter(|p| {
                    !hulls
                        .iter()
                        .enumerate()
                        .any(|(j, g)| j != i && g.within_planes(p, eps))
                })
                .map(|p| s.distance(&p) / s.diag)
                .collect::<Vec<_>>()
        })
        .collect()
}

/// Volume of the union of the hulls by sampling cell centres of a grid with `res` cells along
/// the longest side of their bounding box.
pub fn union_volume(hulls: &[Hull], res: usize) -> f64 {
    let Some(b) = hulls.iter().map(|h| h.aabb).reduce(|a, b| a.union(&b)) else {
        return 0.0;
    };
    let e = b.extents();
    let cell = e.max() / res as f64;
    if !(cell > 0.0) {
        return 0.0;
    }
    let dims = [0, 1, 2].map(|k| ((e[k] / cell).ceil() as usize).max(1));
    let count: usize = (0..dims[2])
        .into_par_iter()
        .map(|k| {
            let mut c = 0usize;
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let p = P3::new(
                        b.min.x + (i as f64 + 0.5) * cell,
                        b.min.y + (j as f64 + 0.5) * cell,
                        b.min.z + (k as f64 + 0.5) * cell,
                    );
                    if hulls
                        .iter()
                        .any(|h| h.aabb.intersects(&Aabb { min: p, max: p }, 0.0) && h.contains(&p))
                    {
                        c += 1;
                    }
                }
            }
            c
        })
        .sum();
    count as f64 * cell * cell * cell
}

/// Fraction of the mesh surface (sampled) not within 0.1 % of the diagonal of some hull.
pub fn uncovered(s: &Surface, hulls: &[Hull], n: usize) -> f64 {
    let pts = s.samples(n, 0xc0e);
    if pts.is_empty() {
        return 0.0;
    }
    let tol = 1e-3 * s.diag;
    let bad = pts
        .par_iter()
        .filter(|p| !hulls.iter().any(|h| h.within_planes(p, tol)))
        .count();
    bad as f64 / pts.len() as f64
}

/// A point in the cavity of a container standing upright (Z up): on the vertical line through
/// the bounding-box centre, half-way between the first surface hit from above (the floor) and
/// the top, provided that point is outside the material, the floor lies at least 20 % of the
/// height below the top, and horizontal rays from the point in 8 directions all hit the mesh
/// (walls all around). `None` for anything else.
pub fn cavity_probe(s: &Surface) -> Option<P3> {
    let b = s.aabb;
    let c = b.center();
    let h = b.extents().z;
    let top = P3::new(c.x, c.y, b.max.z + 0.01 * s.diag);
    let t = s.ray(&top, &V3::new(0.0, 0.0, -1.0), 2.0 * s.diag)?;
    let floor = top.z - t;
    if b.max.z - floor < 0.2 * h {
        return None;
    }
    let p = P3::new(c.x, c.y, 0.5 * (floor + b.max.z));
    if s.contains(&p) {
        return None;
    }
    for k in 0..8 {
        let a = std::f64::consts::PI * k as f64 / 4.0;
        s.ray(&p, &V3::new(a.cos(), a.sin(), 0.0), 2.0 * s.diag)?;
    }
    Some(p)
}
