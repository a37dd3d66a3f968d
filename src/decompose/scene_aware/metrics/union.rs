//! The boundary of the union of hulls kept hull by hull, so that a change of a few hulls
//! recomputes only the faces they reach (issue #37): `unfill` measures the mesh → union side of
//! every move it checks against the union of all the object's hulls, where a move replaces
//! three hulls of about 32 and leaves the rest of the boundary as it was.
//!
//! Entry points: [`UnionFaces::new`] (every hull's faces less the other hulls, as
//! [`super::union_boundary`] cuts them), [`UnionFaces::moved`] (the same for a changed set of
//! hulls, reusing the faces no changed hull reaches), [`UnionFaces::distance`] and
//! [`UnionFaces::mesh`].
//!
//! Exact: [`UnionFaces::moved`] gives the triangles [`UnionFaces::new`] gives on the new hulls,
//! to the bit and in the same order, and [`UnionFaces::distance`] the distance to the nearest
//! of them that `Surface::distance` gives on their mesh (parry's triangle projection; the
//! nearest triangle's distance does not depend on how the triangles are grouped). Both are
//! checked in `metrics/tests.rs` on a real object.

use super::pieces::Pieces;
use crate::decompose::Hull;
use crate::mesh::{from_dvec, to_dvec, Aabb, Mesh, P3, V3};
use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::TriMesh;
use rayon::prelude::*;
use std::sync::Arc;

/// One hull's part of the boundary.
struct Faces {
    /// The triangles kept, face after face of the hull.
    tris: Vec<[P3; 3]>,
    /// `tris[ends[f - 1]..ends[f]]` come from the hull's face `f`.
    ends: Vec<usize>,
    /// The box of `tris` and their BVH; `None` when the hull lies inside the others.
    query: Option<(Aabb, TriMesh)>,
    /// The unit normal of each of `tris` (by index, the BVH's leaf index), for the plane skip
    /// of [`UnionFaces::distance`].
    normals: Vec<V3>,
}

/// The boundary of the union of a set of hulls, by hull (see the module's doc).
pub struct UnionFaces {
    eps: f64,
    /// The object's diagonal (`eps` is 1e-6 of it): the scale of the plane skip's slack.
    diag: f64,
    /// The hulls' boxes, by index.
    boxes: Vec<Aabb>,
    faces: Vec<Arc<Faces>>,
}

/// Relative margin by which a hull's box must lie farther than the best distance so far for
/// its triangles to be skipped: the box's distance is a lower bound on theirs, computed within
/// about 1e-16 of it.
const BOX_MARGIN: f64 = 1e-9;

impl UnionFaces {
    /// The faces of `hulls` outside the other hulls grown by 1e-6 of `diag` (see
    /// [`super::union_boundary`]).
    pub fn new(hulls: &[Hull], diag: f64) -> UnionFaces {
        let eps = 1e-6 * diag;
        let faces = hulls
            .par_iter()
            .enumerate()
            .map(|(i, _)| Arc::new(faces_of(hulls, i, eps, None)))
            .collect();
        UnionFaces {
            eps,
            diag,
            boxes: hulls.iter().map(|h| h.aabb).collect(),
            faces,
        }
    }

    /// The faces of `hulls`, where `from[k]` is the index in `self` of the same hull `k` (the
    /// same vertices and faces), `None` for a new one; the hulls kept must stay in the same
    /// order. What no new or dropped hull reaches is taken from `self`: a hull whose box none
    /// of theirs meets keeps its faces whole; otherwise its face triangles whose box none of
    /// theirs meets (within twice the growth) keep their pieces, and only the others are cut
    /// again. A hull that did not reach a face (by its box) left its pieces as they were (see
    /// `Pieces::outside`), so the result is [`UnionFaces::new`]'s on `hulls`, to the bit.
    pub fn moved(&self, hulls: &[Hull], from: &[Option<usize>]) -> UnionFaces {
        assert_eq!(hulls.len(), from.len(), "one origin per hull");
        let kept: Vec<usize> = from.iter().flatten().copied().collect();
        assert!(
            kept.windows(2).all(|w| w[0] < w[1])
                && kept.last().is_none_or(|&k| k < self.faces.len()),
            "the hulls kept keep their order"
        );
        let eps = self.eps;
        let mut changed: Vec<Aabb> = (0..self.boxes.len())
            .filter(|o| kept.binary_search(o).is_err())
            .map(|o| self.boxes[o])
            .collect();
        changed.extend(
            hulls
                .iter()
                .zip(from)
                .filter(|(_, f)| f.is_none())
                .map(|(h, _)| h.aabb),
        );
        let faces = hulls
            .par_iter()
            .enumerate()
            .map(|(i, h)| match from[i] {
                Some(o) if !changed.iter().any(|c| c.intersects(&h.aabb, eps)) => {
                    Arc::clone(&self.faces[o])
                }
                Some(o) => Arc::new(faces_of(hulls, i, eps, Some((&self.faces[o], &changed)))),
                None => Arc::new(faces_of(hulls, i, eps, None)),
            })
            .collect();
        UnionFaces {
            eps,
            diag: self.diag,
            boxes: hulls.iter().map(|h| h.aabb).collect(),
            faces,
        }
    }

    /// No triangle: every hull lies inside the others (or there is none).
    pub fn is_empty(&self) -> bool {
        self.faces.iter().all(|f| f.tris.is_empty())
    }

    /// The triangles, hull after hull, as one mesh (three vertices a triangle): the mesh
    /// [`super::union_boundary`] makes its surface of.
    pub fn mesh(&self) -> Mesh {
        let mut mesh = Mesh::default();
        for t in self.faces.iter().flat_map(|f| &f.tris) {
            let k = mesh.vertices.len() as u32;
            mesh.vertices.extend(t);
            mesh.triangles.push([k, k + 1, k + 2]);
        }
        mesh
    }

    /// Distance from `p` to the nearest triangle (infinite without any): the hulls' boxes
    /// nearest first, each hull's triangles searched by parry's projection within the best
    /// distance so far. The same number as `Surface::distance` on [`UnionFaces::mesh`]: the
    /// distance to parry's projection on the triangle of least cost, and a triangle's cost and
    /// that distance are the same sum of squares' root.
    pub fn distance(&self, p: &P3) -> f64 {
        let mut near: Vec<(f64, &Faces)> = self
            .faces
            .iter()
            .filter_map(|f| Some((box_distance(&f.query.as_ref()?.0, p), &**f)))
            .collect();
        near.sort_by(|a, b| a.0.total_cmp(&b.0));
        let q = to_dvec(p);
        let mut best = f64::INFINITY;
        for (lower, f) in near {
            if lower > best * (1.0 + BOX_MARGIN) {
                break;
            }
            if let Some(proj) = f.project(q, best.min(f64::MAX), self.diag) {
                best = best.min((from_dvec(proj) - p).norm());
            }
        }
        best
    }
}

/// How much farther than the best so far, relatively, a triangle's plane must lie for parry's
/// projection of the triangle to be skipped, and the slack of the plane test as a fraction of
/// the diagonal: `Surface::project_local`'s `SKIP_MARGIN` and `PLANE_SLACK`, by the same
/// argument (the distance to the plane by a unit normal is a lower bound on the distance to the
/// triangle, within rounding far below both).
const SKIP_MARGIN: f64 = 1e-6;
const PLANE_SLACK: f64 = 1e-12;

impl Faces {
    /// The point parry's `project_local_point_with_max_dist(q, false, max_dist)` finds on this
    /// hull's triangles, to the bit: the same best-first search of the same BVH, the same
    /// triangle projections and costs, but for triangles whose plane lies beyond the best so
    /// far by more than [`SKIP_MARGIN`], which parry would not have taken (their cost is at
    /// least the plane's distance), so the search keeps the same best at every step.
    fn project(&self, q: Vector, max_dist: f64, diag: f64) -> Option<Vector> {
        let (_, mesh) = self.query.as_ref()?;
        let (_, (_, point)) = mesh.bvh().find_best(
            max_dist,
            |node, _| node.aabb().distance_to_local_point(q, true),
            |i, best| {
                let t = mesh.triangle(i);
                if best < f64::MAX {
                    let lim = best * (1.0 + SKIP_MARGIN);
                    let n = self.normals[i as usize];
                    let ap = q - t.a;
                    let plane = (n.x * ap.x + n.y * ap.y + n.z * ap.z).abs();
                    // False for NaN: parry's projection decides then.
                    if plane > lim + PLANE_SLACK * diag {
                        return None;
                    }
                }
                let proj = t.project_local_point(q, false);
                Some(((proj.point - q).length(), proj.point))
            },
        )?;
        Some(point)
    }
}

/// Distance from `p` to the box `b` (0 inside).
fn box_distance(b: &Aabb, p: &P3) -> f64 {
    let d = |a: usize| (b.min[a] - p[a]).max(p[a] - b.max[a]).max(0.0);
    (d(0) * d(0) + d(1) * d(1) + d(2) * d(2)).sqrt()
}

/// The faces of hull `i` outside the other hulls of `hulls` whose box meets its own (grown by
/// `eps`), cut by [`Pieces::outside`] and fanned into triangles (degenerate ones dropped).
/// With `reuse: Some((old, changed))`, a face whose box no box of `changed` meets within
/// `2·eps` keeps its pieces of `old` (see [`UnionFaces::moved`]).
fn faces_of(hulls: &[Hull], i: usize, eps: f64, reuse: Option<(&Faces, &[Aabb])>) -> Faces {
    let h = &hulls[i];
    let others: Vec<(usize, &Hull)> = hulls
        .iter()
        .enumerate()
        .filter(|&(j, g)| j != i && g.aabb.intersects(&h.aabb, eps))
        .collect();
    let mut tris: Vec<[P3; 3]> = Vec::new();
    let mut ends = Vec::with_capacity(h.triangles.len());
    let mut pieces = Pieces::default();
    for (f, t) in h.triangles.iter().enumerate() {
        let tri = t.map(|k| h.vertices[k as usize]);
        if let Some((old, changed)) = reuse {
            let b = Aabb::of_points(&tri).expect("three corners");
            if !changed.iter().any(|c| c.intersects(&b, 2.0 * eps)) {
                let start = if f == 0 { 0 } else { old.ends[f - 1] };
                tris.extend_from_slice(&old.tris[start..old.ends[f]]);
                ends.push(tris.len());
                continue;
            }
        }
        pieces.outside(tri, &others, i, eps, |poly| {
            for k in 1..poly.len() - 1 {
                let tri = [poly[0], poly[k], poly[k + 1]];
                if (tri[1] - tri[0]).cross(&(tri[2] - tri[0])).norm() > 0.0 {
                    tris.push(tri);
                }
            }
        });
        ends.push(tris.len());
    }
    let query = Aabb::of_points(tris.iter().flatten()).map(|b| {
        let v = tris.iter().flatten().map(to_dvec).collect();
        let t = (0..tris.len() as u32)
            .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
            .collect();
        (b, TriMesh::new(v, t).expect("triangles"))
    });
    let normals = tris
        .iter()
        .map(|[a, b, c]| {
            let cr = (b - a).cross(&(c - a));
            let len = cr.norm();
            if len > 0.0 {
                cr / len
            } else {
                V3::zeros()
            }
        })
        .collect();
    Faces {
        tris,
        ends,
        query,
        normals,
    }
}

#[cfg(test)]
mod tests;
