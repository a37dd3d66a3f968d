//! Quality metrics of a decomposition, the same for every engine (used by the tests and by
//! `examples/bench_decompose.rs`).
//!
//! * **Surface distance**: points sampled uniformly (by area) on the boundary of the union of
//!   the hulls — points on a hull's surface that lie inside another hull of the same set are
//!   skipped, since they are not collision surface — and their unsigned distance to the mesh
//!   surface, divided by the mesh's bounding-box diagonal.
//! * **Mesh → hulls** ([`two_sided`]): points sampled uniformly on the *mesh* surface and their
//!   distance to the boundary of the union of the hulls ([`union_boundary`]), relative to the
//!   diagonal. This is what the first figure misses: a dent spanned by a flat hull face (the
//!   face's nearest mesh point is on the rim) and a protrusion no hull reaches.
//! * **Two-sided p95**: the larger of the two 95th percentiles, the headline figure the
//!   report's tolerance warning reads.
//! * **Outside depth**: for the same mesh samples, how far they lie outside every hull (0
//!   inside one), 99th percentile and maximum, relative to the diagonal.
//! * **Volume ratio**: volume of the union of the hulls (grid sampling, exact face-plane tests)
//!   over the mesh's enclosed volume.
//! * **Uncovered**: fraction of the mesh surface (sampled) farther than 0.1 % of the diagonal
//!   outside every hull.
//! * **Cavity kept**: for containers (see [`cavity_probe`]), whether the probe point in the
//!   cavity is outside every hull.

use super::geom::{components, sample_hull, Surface};
use crate::decompose::Hull;
use crate::mesh::{Aabb, Mesh, P3, V3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Collision fidelity measured both ways, every figure relative to the mesh's bounding-box
/// diagonal (see the module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TwoSided {
    /// The headline: `max(hull_to_mesh_p95, mesh_to_hull_p95)`.
    pub p95: f64,
    /// Boundary of the union of hulls → mesh surface, 95th percentile.
    pub hull_to_mesh_p95: f64,
    /// Mesh surface → boundary of the union of hulls, 95th percentile.
    pub mesh_to_hull_p95: f64,
    /// Depth of the mesh surface outside every hull, 99th percentile and maximum.
    pub outside_p99: f64,
    pub outside_max: f64,
}

/// Samples on each side for the figures written to `report.json`.
pub const TWO_SIDED_SAMPLES: usize = 6000;

/// Both directions with about `n` samples on each side; `None` without mesh or hull surface.
pub fn two_sided(s: &Surface, hulls: &[Hull], n: usize) -> Option<TwoSided> {
    let fwd = surface_distances(s, hulls, n);
    let boundary = UnionFaces::new(hulls, s.diag);
    if boundary.is_empty() {
        return None;
    }
    let pts = seen_samples(s, n);
    if fwd.is_empty() || pts.is_empty() {
        return None;
    }
    let eps = 1e-9 * s.diag;
    let (back, out): (Vec<f64>, Vec<f64>) = pts
        .par_iter()
        .map(|p| {
            let d = boundary.distance(p) / s.diag;
            let inside = hulls.iter().any(|h| h.holds(p, eps));
            (d, if inside { 0.0 } else { d })
        })
        .unzip();
    let h2m = stats(&fwd).1;
    let m2h = stats(&back).1;
    Some(TwoSided {
        p95: h2m.max(m2h),
        hull_to_mesh_p95: h2m,
        mesh_to_hull_p95: m2h,
        outside_p99: percentile(&out, 0.99),
        outside_max: out.iter().copied().fold(0.0, f64::max),
    })
}

/// Distances (relative to the diagonal) from about `n` points on the mesh surface to the
/// boundary of the union of the hulls; `None` without hull surface.
pub fn mesh_to_hull_distances(s: &Surface, hulls: &[Hull], n: usize) -> Option<Vec<f64>> {
    let boundary = UnionFaces::new(hulls, s.diag);
    if boundary.is_empty() {
        return None;
    }
    Some(
        seen_samples(s, n)
            .par_iter()
            .map(|p| boundary.distance(p) / s.diag)
            .collect(),
    )
}

/// Most closed pieces a mesh is looked at for faces buried in its own material.
const MAX_PIECES: usize = 64;

/// About `n` points sampled uniformly on the mesh surface, but for those buried in its own
/// material: a mesh of overlapping closed pieces (the PyBullet tray: six boxes) has faces
/// inside another of its pieces, which no simulator ever touches, and which lie far from the
/// boundary of any hulls that fill the material (the tray's exact box hulls read 3.4 % of the
/// diagonal mesh → hulls at the 95th percentile from those faces alone). A point counts as
/// buried when strictly inside (by more than 1e-6 of the diagonal) a closed connected piece
/// of the mesh other than its own. Meshes of one piece, or more than [`MAX_PIECES`], keep
/// every sample.
pub fn seen_samples(s: &Surface, n: usize) -> Vec<P3> {
    let pts = s.samples(n, 0x5eed);
    let comps = components(&s.mesh);
    if comps.len() < 2 || comps.len() > MAX_PIECES {
        return pts;
    }
    let pieces: Vec<Surface> = comps
        .par_iter()
        .filter_map(|tris| {
            let vs = s.vertices_of(tris);
            let local = |v: u32| vs.binary_search(&v).unwrap_or(0) as u32;
            let m = Mesh::new(
                vs.iter().map(|&v| s.mesh.vertices[v as usize]).collect(),
                tris.iter()
                    .map(|&t| s.mesh.triangles[t as usize].map(local))
                    .collect(),
            );
            Surface::new(&m).filter(|c| c.closed)
        })
        .collect();
    let eps = 1e-6 * s.diag;
    pts.into_par_iter()
        .filter(|p| !pieces.iter().any(|c| c.contains(p) && c.distance(p) > eps))
        .collect()
}

/// A quick lower estimate of [`mesh_to_hull_distances`] for the engine's choices, without
/// building the union boundary: a point inside hulls by its depth in the one it is deepest in
/// (exact unless the nearest face of that hull is buried in another), a point outside all by
/// its largest face-plane distance to the nearest (within √3 of the distance).
pub fn mesh_to_hull_planes(s: &Surface, hulls: &[Hull], n: usize) -> Vec<f64> {
    s.samples(n, 0x5eed)
        .par_iter()
        .map(|p| {
            let (mut depth, mut out) = (0.0f64, f64::INFINITY);
            let mut inside = false;
            for h in hulls {
                let b = &h.aabb;
                let gap = (0..3)
                    .map(|a| (b.min[a] - p[a]).max(p[a] - b.max[a]).max(0.0))
                    .fold(0.0, f64::max);
                if gap > 0.0 && gap >= out {
                    continue;
                }
                let d = h.plane_distance(p);
                if d <= 0.0 {
                    inside = true;
                    depth = depth.max(-d);
                } else {
                    out = out.min(d);
                }
            }
            (if inside { depth } else { out }) / s.diag
        })
        .collect()
}

/// Two-sided figures of `hulls` against `mesh` with [`TWO_SIDED_SAMPLES`] a side.
pub fn two_sided_of(mesh: &Mesh, hulls: &[Hull]) -> Option<TwoSided> {
    two_sided(&Surface::new(mesh)?, hulls, TWO_SIDED_SAMPLES)
}

/// The warning for hulls farther from the mesh than `tolerance` (relative to the diagonal) by
/// the headline two-sided figure, with both directions and the outside depth; `None` within
/// it. `hulls` of at most `max_hulls`.
pub fn tolerance_warning(
    f: &TwoSided,
    tolerance: f64,
    hulls: usize,
    max_hulls: usize,
) -> Option<String> {
    // `!(p95 <= tolerance)`: a NaN figure warns too.
    (!(f.p95 <= tolerance)).then(|| {
        format!(
            "collision hulls: 95th percentile of their distance to the mesh {:.2} % of its \
             bounding-box diagonal (hulls → mesh {:.2} %, mesh → hulls {:.2} %; mesh surface \
             outside every hull by {:.2} % at the 99th percentile, {:.2} % at most), above the \
             {:.2} % tolerance ({hulls} of at most {max_hulls} hulls; a larger --max-hulls \
             usually brings them closer)",
            f.p95 * 100.0,
            f.hull_to_mesh_p95 * 100.0,
            f.mesh_to_hull_p95 * 100.0,
            f.outside_p99 * 100.0,
            f.outside_max * 100.0,
            tolerance * 100.0,
        )
    })
}

/// The `q`-quantile of `d` (nearest rank; 0 for an empty set).
pub fn percentile(d: &[f64], q: f64) -> f64 {
    if d.is_empty() {
        return 0.0;
    }
    let mut v = d.to_vec();
    v.sort_by(f64::total_cmp);
    v[((v.len() as f64 * q) as usize).min(v.len() - 1)]
}

/// The boundary of the union of `hulls` as a triangle surface: the hulls' faces less the
/// parts inside another hull, cut exactly. Each face triangle is clipped against every other
/// hull whose box it reaches, grown by 1e-6 of the diagonal (so that a face on a cut plane
/// two hulls share counts as inside where the neighbour's face covers it): what lies beyond
/// one of the neighbour's face planes is kept as convex polygons, the rest goes. The pieces
/// are fanned into triangles. Distances to it are exact up to that 1e-6.
///
/// Faces of two hulls in the same plane and facing the same way (two overlapping pieces of
/// one box, a wall and a wedge of it) are outer surface where they coincide: the hull of the
/// lower index keeps it (see [`shared_face_plane`]). Growing both would remove it from both,
/// and open a hole in the boundary: the PyBullet tray's 19 hulls, 13 of them overlapping
/// pieces of its six boxes, read 3.6 % of the diagonal mesh → hulls at the 95th percentile
/// (8.6 % at most) from such holes alone, where they fill every box exactly.
pub fn union_boundary(hulls: &[Hull], diag: f64) -> Option<Surface> {
    Surface::new(&UnionFaces::new(hulls, diag).mesh())
}

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
    /// Both directions (see [`two_sided`]).
    pub two_sided: TwoSided,
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
        two_sided: two_sided(&s, hulls, 20_000).unwrap_or_default(),
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
/// (p95 5.87 % of the diagonal, 1.80 % as seams). Where two hulls share an outer face (in
/// one plane, facing the same way), the one of the lower index keeps it.
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
                    !hulls.iter().enumerate().any(|(j, g)| {
                        j != i
                            && g.within_planes(p, eps)
                            && !(j > i && on_shared_face(p, h, g, eps))
                    })
                })
                .map(|p| s.distance(&p) / s.diag)
                .collect::<Vec<_>>()
        })
        .collect()
}

/// Whether `p`, on the surface of hull `h`, lies on a face of `g` in the same plane as one of
/// `h`'s and facing the same way: outer surface of both, which the hull of the lower index
/// keeps (as [`union_boundary`] does).
fn on_shared_face(p: &P3, h: &Hull, g: &Hull, eps: f64) -> bool {
    g.planes.iter().any(|(m, d)| {
        (m.dot(&p.coords) - d).abs() <= eps
            && h.planes
                .iter()
                .any(|(n, e)| n.dot(m) > 1.0 - 1e-9 && (n.dot(&p.coords) - e).abs() <= eps)
    })
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

mod pieces;
mod union;
pub use union::UnionFaces;
#[cfg(test)]
mod tests;
