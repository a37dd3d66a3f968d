//! Closest-point queries on a [`Surface`] that give parry's answer, to the bit, for less
//! (issue #37). Entry points: [`Surface::project`] (parry's `project_point`),
//! [`Surface::project_within`] (its `project_point_with_max_dist`) and
//! [`Surface::project_until`], used by [`Surface::max_distance_until`].

use super::geom::{Surface, WITHIN_MARGIN};
use parry3d_f64::math::{Real, Vector};
use parry3d_f64::query::{PointProjection, PointQuery, PointQueryWithLocation};
use parry3d_f64::shape::TrianglePointLocation;

/// How much farther than the best so far, relatively, a triangle's plane must be before
/// parry's own projection of the triangle is skipped. The distance to the plane is a lower
/// bound on the distance to the triangle; the plane's distance as computed here and parry's
/// cost agree with the exact values within rounding (about 1e-15 of the distances); the
/// margin leaves a million times that.
const SKIP_MARGIN: f64 = 1e-6;

/// Slack of the plane test, as a fraction of the diagonal: the distance to a triangle's plane
/// by its unit normal (rounded, a relative error about 1e-16 of each coordinate) is a lower
/// bound on the distance to the triangle within far less.
const PLANE_SLACK: f64 = 1e-12;

impl Surface {
    /// parry's projection of `q` onto the surface (`TriMesh::project_point`, not solid), to
    /// the bit: see [`Surface::project_within`].
    pub(super) fn project(&self, q: Vector) -> PointProjection {
        self.project_local(q, Real::MAX)
            .unwrap_or(PointProjection::new(false, q))
    }

    /// parry's `project_point_with_max_dist(identity, q, false, max_dist)`, to the bit: the
    /// same best-first search of the same BVH (`Bvh::find_best`, the same box costs), the
    /// same triangle projection and cost for every triangle that can still win, and the same
    /// inside test by the pseudo-normal of the winner's feature. What changes: a triangle
    /// whose plane (its unit normal `tri_normal`, one dot product) lies beyond the best so far
    /// by more than [`SKIP_MARGIN`] is not projected by parry's triangle projection (which
    /// reports its feature too, and costs some 300 instructions). parry would have found it
    /// no better than the best (its cost is at least the plane's distance, and a cost not
    /// below the best is not taken), so the search keeps the same best at every step and
    /// walks the same boxes: the answer is the same triangle, point and flag. A degenerate
    /// triangle (a zero normal) is never skipped.
    pub(super) fn project_within(&self, q: Vector, max_dist: Real) -> Option<PointProjection> {
        self.project_local(q, max_dist)
    }

    /// parry's `TriMesh::project_local_point_and_get_location_with_max_dist` (3D, not
    /// solid), with the skip of [`Surface::project_within`].
    fn project_local(&self, point: Vector, max_dist: Real) -> Option<PointProjection> {
        let tri = &self.tri;
        let (part_id, (_, (mut proj, location))) = tri.bvh().find_best(
            max_dist,
            |node, _| node.aabb().distance_to_local_point(point, true),
            |i, best| {
                if best < Real::MAX {
                    let a = self.corners[i as usize][0];
                    let lim = best * (1.0 + SKIP_MARGIN);
                    let n = self.tri_normal[i as usize];
                    let ap = point - a;
                    let plane = (n.x * ap.x + n.y * ap.y + n.z * ap.z).abs();
                    // False for NaN: parry's projection decides then.
                    if plane > lim + PLANE_SLACK * self.diag {
                        return None;
                    }
                }
                let proj = tri
                    .triangle(i)
                    .project_local_point_and_get_location(point, false);
                let cost = (proj.0.point - point).length();
                Some((cost, proj))
            },
        )?;
        proj.subshape = part_id;
        if let Some(pseudo_normals) = tri.pseudo_normals_if_oriented() {
            let pseudo_normal = match location {
                TrianglePointLocation::OnFace(..) | TrianglePointLocation::OnSolid => {
                    Some(tri.triangle(part_id).scaled_normal())
                }
                TrianglePointLocation::OnEdge(i, _) => pseudo_normals
                    .edges_pseudo_normal
                    .get(part_id as usize)
                    .map(|pn| pn[i as usize]),
                TrianglePointLocation::OnVertex(i) => {
                    let idx = tri.indices()[part_id as usize];
                    pseudo_normals
                        .vertices_pseudo_normal
                        .get(idx[i as usize] as usize)
                        .copied()
                }
            };
            if let Some(pseudo_normal) = pseudo_normal {
                let dpt = point - proj.point;
                proj.is_inside = dpt.dot(pseudo_normal) <= 0.0;
            }
        }
        Some(proj)
    }

    /// parry's projection of `q` onto the surface, searched first only within `reach` plus a
    /// margin (`project_point_with_max_dist`, as [`Surface::farther`] does): parry's
    /// `find_best` then starts with that bound as its best cost and prunes every box beyond
    /// it, otherwise walking the same boxes in the same order, so a projection found within
    /// it is the unbounded search's, to the bit. None found: the unbounded search, as before.
    /// [`Surface::max_distance_until`] needs exact distances only up to `max(stop, seam)`,
    /// and beyond it only for the first point found there, where it stops.
    pub(super) fn project_until(&self, q: Vector, reach: f64) -> PointProjection {
        if reach > 0.0 && reach.is_finite() && q.is_finite() {
            let bound = reach * (1.0 + WITHIN_MARGIN);
            if let Some(proj) = self.project_within(q, bound) {
                return proj;
            }
        }
        self.project(q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Mesh, P3, V3};
    use crate::shapes::solids::{cuboid, uv_sphere};

    /// Every answer of [`Surface::project`] and [`Surface::project_within`] against parry's
    /// own `project_point` and `project_point_with_max_dist` on the same `TriMesh`: the same
    /// point to the bit, the same triangle and the same inside flag. On a sphere (curved), a
    /// box of two coplanar triangles a face (ties between triangles at the same distance, axis
    /// aligned planes), and a box with a sliver triangle and a degenerate one (zero normal)
    /// added; at random points from inside to well outside, points on the shared edges and
    /// corners, and bounds from below the distance to beyond it.
    #[test]
    fn projections_are_parrys_to_the_bit() {
        let mut sliver = cuboid(V3::new(1.0, 0.5, 0.25));
        let k = sliver.vertices.len() as u32;
        sliver.vertices.extend([
            P3::new(0.0, 0.0, 0.9),
            P3::new(1e-9, 0.0, 0.9),
            P3::new(0.3, 0.2, 0.9),
        ]);
        sliver.triangles.push([k, k + 1, k + 2]);
        sliver.triangles.push([k, k, k + 2]); // degenerate: two corners at one point
        let meshes: [Mesh; 3] = [
            uv_sphere(0.5, 12, 24),
            cuboid(V3::new(1.0, 0.5, 0.25)),
            sliver,
        ];
        let id = parry3d_f64::math::Pose::identity();
        let mut rng = crate::rng::Rng::new(37);
        let mut checked = 0usize;
        for mesh in &meshes {
            let s = Surface::new(mesh).expect("surface");
            let (lo, hi) = (s.aabb.min, s.aabb.max);
            let mut pts: Vec<Vector> = (0..3000)
                .map(|_| {
                    let f = |a: f64, b: f64, u: f64| a + (b - a) * (1.6 * u - 0.3);
                    Vector::new(
                        f(lo.x, hi.x, rng.range(0.0, 1.0)),
                        f(lo.y, hi.y, rng.range(0.0, 1.0)),
                        f(lo.z, hi.z, rng.range(0.0, 1.0)),
                    )
                })
                .collect();
            // Ties: the corners and edge midpoints of the mesh, pushed out along each axis.
            for t in &mesh.triangles {
                for (i, j) in [(0, 1), (1, 2), (2, 0)] {
                    let (a, b) = (mesh.vertices[t[i] as usize], mesh.vertices[t[j] as usize]);
                    for p in [a, P3::from((a.coords + b.coords) * 0.5)] {
                        for d in [V3::x(), V3::y(), V3::z(), V3::new(0.3, -0.2, 0.1)] {
                            let q = p + d * 0.05;
                            pts.push(Vector::new(q.x, q.y, q.z));
                        }
                    }
                }
            }
            for q in pts {
                let want = s.tri.project_point(&id, q, false);
                let got = s.project(q);
                assert_eq!(
                    got.point.to_array().map(f64::to_bits),
                    want.point.to_array().map(f64::to_bits),
                    "{q:?}"
                );
                assert_eq!(
                    (got.is_inside, got.subshape),
                    (want.is_inside, want.subshape),
                    "{q:?}"
                );
                let d = (want.point - q).length();
                for bound in [0.5 * d, d, d * (1.0 + 1e-12), 2.0 * d + 1e-3] {
                    let want = s.tri.project_point_with_max_dist(&id, q, false, bound);
                    let got = s.project_within(q, bound);
                    assert_eq!(got.is_some(), want.is_some(), "{q:?} within {bound}");
                    if let (Some(g), Some(w)) = (got, want) {
                        assert_eq!(
                            g.point.to_array().map(f64::to_bits),
                            w.point.to_array().map(f64::to_bits)
                        );
                        assert_eq!((g.is_inside, g.subshape), (w.is_inside, w.subshape));
                    }
                }
                checked += 1;
            }
        }
        assert!(checked > 9000, "{checked}");
    }
}
