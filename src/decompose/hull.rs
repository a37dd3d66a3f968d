//! Convex hulls ([`Hull`]): `Hull::from_points` (parry's quickhull, [`quickhull`]),
//! `Hull::from_mesh`, point tests, and the PhysX-limit simplifications (`simplified`,
//! `significant`, `within`).

mod quickhull;

use crate::mesh::{from_dvec, to_dvec, Aabb, Mesh, P3, V3};

/// A convex hull: its vertices, triangles (outward), face planes and volume, in `f64`.
/// Point tests use the face planes exactly (parry's point queries on small polyhedra are not
/// reliable; see the crate notes).
#[derive(Clone, Debug, PartialEq)]
pub struct Hull {
    pub vertices: Vec<P3>,
    pub triangles: Vec<[u32; 3]>,
    /// Outward unit normal and offset of every face: inside when `n·p ≤ d`.
    pub planes: Vec<(V3, f64)>,
    pub volume: f64,
    pub aabb: Aabb,
}

/// What PhysX cooks a convex mesh as written, and keeps on the GPU: at most 64 vertices, 64
/// polygons (coplanar triangles merged) and 32 vertices on one polygon, and not a sliver. A hull
/// over these is re-cooked silently into another shape (measured with ovphysx 0.7: a 64-vertex
/// round hull, about 124 triangles, came back as 34 of its vertices, some 8 mm inside).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhysxLimits {
    pub max_vertices: usize,
    pub max_polygons: usize,
    pub max_polygon_vertices: usize,
    /// Every vertex bulges out of the hull of the others by more than this (m), so PhysX's
    /// plane tolerance drops none (see [`Hull::significant`]); `None`: no such step.
    pub plane_tolerance: Option<f64>,
}

/// The margin [`PhysxLimits`] keeps over PhysX's cooking plane tolerance (0.0007 of the length
/// scale, 0.7 mm in metres): 1 mm. The USD export writes hull points in decimetres (see
/// `export::usd::HULL_POINTS_PER_METRE`), where PhysX's tolerance is 0.07 mm (0.07 % of the
/// hull's size above 10 cm of half perimeter), so this is now more than needed (a tolerance relative to the hull's size keeps
/// more of a small round hull; tried, not landed: docs/usd.md).
pub const PHYSX_PLANE_TOLERANCE: f64 = 1e-3;

impl Default for PhysxLimits {
    fn default() -> Self {
        PhysxLimits {
            max_vertices: 64,
            max_polygons: 64,
            max_polygon_vertices: 32,
            plane_tolerance: Some(PHYSX_PLANE_TOLERANCE),
        }
    }
}

impl Hull {
    /// The convex hull of a point set; `None` when degenerate (fewer than 4 points in general
    /// position, or zero volume).
    pub fn from_points(points: &[P3]) -> Option<Hull> {
        if points.len() < 4 || points.iter().any(|p| !p.iter().all(|c| c.is_finite())) {
            return None;
        }
        let pts: Vec<_> = points.iter().map(to_dvec).collect();
        // parry's quickhull with its buffers kept (see `quickhull`), its output to the bit.
        let got = std::panic::catch_unwind(|| quickhull::convex_hull(&pts))
            .ok()
            .and_then(|r| r.ok());
        #[cfg(test)]
        quickhull::assert_parry_agrees(&pts, got.as_ref());
        let (v, t) = got?;
        let mesh = Mesh::new(v.into_iter().map(from_dvec).collect(), t);
        Hull::from_mesh(mesh)
    }

    /// A hull from a convex closed mesh (trusted to be convex).
    pub fn from_mesh(mesh: Mesh) -> Option<Hull> {
        let volume = mesh.signed_volume();
        let aabb = mesh.aabb()?;
        let scale = aabb.diagonal();
        if !(volume > 1e-12 * scale * scale * scale) || mesh.triangles.len() < 4 {
            return None;
        }
        let mut planes: Vec<(V3, f64)> = Vec::with_capacity(mesh.triangles.len());
        for i in 0..mesh.triangles.len() {
            let [a, b, c] = mesh.triangle(i);
            let n = (b - a).cross(&(c - a));
            let len = n.norm();
            if len <= 1e-300 {
                continue;
            }
            let n = n / len;
            planes.push((n, n.dot(&a.coords)));
        }
        Some(Hull {
            vertices: mesh.vertices,
            triangles: mesh.triangles,
            planes,
            volume,
            aabb,
        })
    }

    /// Whether `p` is inside or on the hull.
    pub fn contains(&self, p: &P3) -> bool {
        self.planes.iter().all(|(n, d)| n.dot(&p.coords) <= *d)
    }

    /// Whether `p` is inside the hull grown by `eps` along every face normal (a box test
    /// first): the same as `plane_distance(p) <= eps` but for points within a few `eps` of a
    /// sharp corner, and quicker.
    pub fn holds(&self, p: &P3, eps: f64) -> bool {
        (0..3).all(|a| p[a] >= self.aabb.min[a] - eps && p[a] <= self.aabb.max[a] + eps)
            && self.within_planes(p, eps)
    }

    /// Signed distance to the closest face plane: negative inside (a lower bound on the depth
    /// for inside points), an approximation outside.
    pub fn plane_distance(&self, p: &P3) -> f64 {
        self.planes
            .iter()
            .map(|(n, d)| n.dot(&p.coords) - d)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// `plane_distance(p) <= eps` (for a number `eps`), stopped at the first face plane `p`
    /// is farther than `eps` from: a point far from the hull is mostly beyond one of the first
    /// faces tried, where `plane_distance` tries them all.
    pub fn within_planes(&self, p: &P3, eps: f64) -> bool {
        !self.planes.iter().any(|(n, d)| n.dot(&p.coords) - d > eps)
    }

    /// The smallest width over face normals: how thin the hull is.
    pub fn thickness(&self) -> f64 {
        self.planes
            .iter()
            .map(|(n, d)| {
                self.vertices
                    .iter()
                    .map(|v| d - n.dot(&v.coords))
                    .fold(0.0f64, f64::max)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// At most `max_vertices` vertices: keep extreme points by farthest-point sampling (the
    /// result lies inside the original, so it never grows into a neighbour).
    pub fn simplified(self, max_vertices: usize) -> Option<Hull> {
        if self.vertices.len() <= max_vertices {
            return Some(self);
        }
        let max_vertices = max_vertices.max(4);
        let pts = &self.vertices;
        // Large flat faces are what objects rest on (a cut fruit, a box bottom): keep up to 8
        // well-spread vertices of each facet covering at least 2% of the area, largest first,
        // using at most half of the budget, so farthest-point sampling cannot drop them.
        let mut kept: Vec<usize> = Vec::new();
        for facet in self.large_facets(0.02) {
            if kept.len() + 3 > max_vertices / 2 {
                break;
            }
            let take = 8.min(max_vertices / 2 - kept.len());
            for i in farthest_points(pts, &facet, &[], take) {
                if !kept.contains(&i) {
                    kept.push(i);
                }
            }
        }
        if kept.is_empty() {
            // Seed with the vertex farthest from the centre.
            let c = self.aabb.center();
            kept.push(
                (0..pts.len())
                    .max_by(|&i, &j| {
                        (pts[i] - c)
                            .norm_squared()
                            .total_cmp(&(pts[j] - c).norm_squared())
                            .then(j.cmp(&i))
                    })
                    .unwrap(),
            );
        }
        let all: Vec<usize> = (0..pts.len()).collect();
        let more = max_vertices - kept.len();
        let extra = farthest_points(pts, &all, &kept, more);
        kept.extend(extra);
        kept.sort_unstable();
        kept.dedup();
        let sub: Vec<P3> = kept.iter().map(|&i| pts[i]).collect();
        Hull::from_points(&sub)
    }

    /// The hull's polygons: its triangles merged by plane (normals within 1e-6 rad², offsets
    /// within 1e-7 of the diagonal), each as its distinct vertex indices. This is the face count
    /// PhysX's cooking limits (64 for the GPU), and it errs high: PhysX merges near-coplanar
    /// triangles with a looser tolerance, never a stricter one.
    pub fn polygons(&self) -> Vec<Vec<usize>> {
        self.facets().into_iter().map(|f| f.3).collect()
    }

    /// `(polygons, most vertices on one polygon)`.
    pub fn polygon_stats(&self) -> (usize, usize) {
        let p = self.polygons();
        (p.len(), p.iter().map(Vec::len).max().unwrap_or(0))
    }

    /// How much of a sliver the hull is: the largest half-extent of its box over its inner
    /// radius (the distance from its vertex centroid to the nearest face plane). PhysX keeps a
    /// convex mesh off the GPU when its extent/radius ratio is too large (it checks its own
    /// internal box, which is smaller than this one, so this errs high).
    pub fn sliver_ratio(&self) -> f64 {
        let n = self.vertices.len().max(1) as f64;
        let c = self.vertices.iter().fold(V3::zeros(), |a, v| a + v.coords) / n;
        let r = self
            .planes
            .iter()
            .map(|(nrm, d)| d - nrm.dot(&c))
            .fold(f64::INFINITY, f64::min);
        let half = 0.5 * self.aabb.extents().max();
        if r > 0.0 {
            half / r
        } else {
            f64::INFINITY
        }
    }

    /// The hull with only the vertices PhysX's cooking keeps: PhysX builds its hull
    /// incrementally and skips every point within its plane tolerance (0.0007 of its length
    /// scale: 0.7 mm for hull points in metres) of the hull so far, so a vertex that barely bulges
    /// out of the others is dropped and the cooked hull differs from the written one (measured:
    /// up to 0.72 mm on bowl wall segments). Here vertices are added farthest first while they
    /// stand more than `tol` out, then any vertex within `tol` of the hull of the others is
    /// dropped, so every vertex left bulges out by more than `tol`. The result is a subset of
    /// the input: it lies inside it, within `tol` of it.
    pub fn significant(self, tol: f64) -> Option<Hull> {
        self.significant_pinned(tol, &|_| false)
    }

    /// [`Hull::significant`] that never drops a vertex `pinned` holds for (see
    /// [`Hull::within_pinned`]).
    pub fn significant_pinned(self, tol: f64, pinned: &dyn Fn(&P3) -> bool) -> Option<Hull> {
        let pts = &self.vertices;
        if pts.len() <= 4 {
            return Some(self);
        }
        let all: Vec<usize> = (0..pts.len()).collect();
        let mut kept = farthest_points(pts, &all, &[], 4);
        for i in all.iter().copied().filter(|&i| pinned(&pts[i])) {
            if !kept.contains(&i) {
                kept.push(i);
            }
        }
        let mut hull = Hull::from_points(&kept.iter().map(|&i| pts[i]).collect::<Vec<_>>())?;
        loop {
            let far = all
                .iter()
                .filter(|i| !kept.contains(i))
                .map(|&i| (i, hull.plane_distance(&pts[i])))
                .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)));
            match far {
                Some((i, d)) if d > tol => {
                    kept.push(i);
                    hull = Hull::from_points(&kept.iter().map(|&i| pts[i]).collect::<Vec<_>>())?;
                }
                _ => break,
            }
        }
        // A vertex added early may sit within `tol` of the hull the later ones made.
        loop {
            let weakest = kept
                .iter()
                .enumerate()
                .filter(|&(_, &i)| !pinned(&pts[i]))
                .filter_map(|(k, &i)| {
                    let others: Vec<P3> =
                        kept.iter().filter(|&&j| j != i).map(|&j| pts[j]).collect();
                    Hull::from_points(&others).map(|h| (k, h.plane_distance(&pts[i])))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
            match weakest {
                Some((k, d)) if d <= tol && kept.len() > 4 => {
                    kept.remove(k);
                }
                _ => break,
            }
        }
        kept.sort_unstable();
        Hull::from_points(&kept.iter().map(|&i| pts[i]).collect::<Vec<_>>())
    }

    /// The hull brought within PhysX's cooking limits (see [`PhysxLimits`]): at most
    /// `max_vertices` vertices, `max_polygons` polygons and `max_polygon_vertices` vertices on one
    /// polygon. It drops vertices the way [`Hull::simplified`] does (farthest-point sampling
    /// from the original's extreme points, large flat faces kept), fewer each round until the
    /// polygons fit, so the result lies inside the original and never grows into a neighbour.
    /// `None` when no hull of 4 or more vertices fits.
    pub fn within(self, limits: &PhysxLimits) -> Option<Hull> {
        self.within_pinned(limits, &|_| false)
    }

    /// [`Hull::within`], but the plane-tolerance step keeps the vertices `pinned` holds for:
    /// the vertices a hull shares with another hull of its object (a seam). Pieces that meet
    /// on a seam (cones from one centre) each drop their own barely-bulging seam vertices
    /// otherwise, differently, and open gaps between them down to the centre: the YCB golf
    /// ball's star pieces went from a two-sided p95 of 0.2 % of its diagonal to 13 % (the gaps'
    /// walls are exposed surface), though no vertex moved more than 1.4 mm. A pinned vertex
    /// within PhysX's 0.7 mm (hull points in metres) used to be skipped by its cooking; with
    /// the decimetre points of the USD export it is not (tests/usd.rs: within 0.1 mm).
    pub fn within_pinned(self, limits: &PhysxLimits, pinned: &dyn Fn(&P3) -> bool) -> Option<Hull> {
        let fits = |h: &Hull| {
            let (p, pv) = h.polygon_stats();
            h.vertices.len() <= limits.max_vertices
                && p <= limits.max_polygons
                && pv <= limits.max_polygon_vertices
        };
        let orig = self;
        let this = match limits.plane_tolerance {
            Some(tol) => orig.clone().significant_pinned(tol, pinned).unwrap_or(orig),
            None => orig,
        };
        if fits(&this) {
            return Some(this);
        }
        let mut k = this.vertices.len().min(limits.max_vertices);
        loop {
            let h = this.clone().simplified(k)?;
            let (p, pv) = h.polygon_stats();
            if h.vertices.len() <= limits.max_vertices
                && p <= limits.max_polygons
                && pv <= limits.max_polygon_vertices
            {
                return Some(h);
            }
            // A round hull has about 2V - 4 faces: each vertex dropped removes about two.
            let step = if p > limits.max_polygons {
                ((p - limits.max_polygons) / 2).max(1)
            } else {
                1
            };
            k = k.min(h.vertices.len()).checked_sub(step)?;
            if k < 4 {
                return None;
            }
        }
    }

    /// Vertex sets of the planar facets (coplanar triangles merged) whose area is at least
    /// `min_fraction` of the hull's area, largest first.
    fn large_facets(&self, min_fraction: f64) -> Vec<Vec<usize>> {
        let mut facets = self.facets();
        let total: f64 = facets.iter().map(|f| f.2).sum();
        facets.retain(|f| f.2 >= min_fraction * total && f.3.len() >= 3);
        facets.sort_by(|a, b| b.2.total_cmp(&a.2));
        facets.into_iter().map(|f| f.3).collect()
    }

    /// Triangles merged by plane: (normal, offset, area, distinct vertices), in triangle order.
    fn facets(&self) -> Vec<(V3, f64, f64, Vec<usize>)> {
        let scale = self.aabb.diagonal().max(1e-300);
        let mut facets: Vec<(V3, f64, f64, Vec<usize>)> = Vec::new();
        for i in 0..self.triangles.len() {
            let t = self.triangles[i];
            let [a, b, c] = [t[0], t[1], t[2]].map(|k| self.vertices[k as usize]);
            let n = (b - a).cross(&(c - a));
            let area = 0.5 * n.norm();
            if area <= 0.0 {
                continue;
            }
            let n = n.normalize();
            let d = n.dot(&a.coords);
            let f = facets
                .iter_mut()
                .find(|f| f.0.dot(&n) > 1.0 - 1e-6 && (f.1 - d).abs() < 1e-7 * scale);
            let f = match f {
                Some(f) => f,
                None => {
                    facets.push((n, d, 0.0, Vec::new()));
                    facets.last_mut().unwrap()
                }
            };
            f.2 += area;
            for k in t {
                if !f.3.contains(&(k as usize)) {
                    f.3.push(k as usize);
                }
            }
        }
        facets
    }

    /// The hull as a mesh.
    pub fn mesh(&self) -> Mesh {
        Mesh::new(self.vertices.clone(), self.triangles.clone())
    }

    /// The hull moved by an isometry (planes and box recomputed).
    pub fn transformed(&self, iso: &nalgebra::Isometry3<f64>) -> Hull {
        Hull::from_mesh(self.mesh().transformed(&iso.to_homogeneous()))
            .expect("rigid motion keeps a hull valid")
    }
}

/// Up to `count` indices of `candidates` chosen by farthest-point sampling, starting from the
/// already chosen `seed` (or from the first candidate). Deterministic.
fn farthest_points(pts: &[P3], candidates: &[usize], seed: &[usize], count: usize) -> Vec<usize> {
    let mut out = Vec::with_capacity(count);
    if candidates.is_empty() || count == 0 {
        return out;
    }
    let mut dist: Vec<f64> = candidates
        .iter()
        .map(|&i| {
            seed.iter()
                .map(|&s| (pts[i] - pts[s]).norm_squared())
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    if seed.is_empty() {
        out.push(candidates[0]);
        for (k, &i) in candidates.iter().enumerate() {
            dist[k] = (pts[i] - pts[candidates[0]]).norm_squared();
        }
    }
    while out.len() < count {
        let (k, &d) = dist
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(&a.0)))
            .unwrap();
        if d <= 0.0 {
            break;
        }
        let j = candidates[k];
        out.push(j);
        for (m, &i) in candidates.iter().enumerate() {
            dist[m] = dist[m].min((pts[i] - pts[j]).norm_squared());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;

    #[test]
    fn cube_hull_contains_and_measures() {
        let h = Hull::from_points(&shapes::cuboid(V3::new(0.01, 0.02, 0.03)).vertices).unwrap();
        assert!((h.volume - 6e-6).abs() < 1e-15);
        assert!(h.contains(&P3::new(0.0049, 0.0099, 0.0149)));
        assert!(!h.contains(&P3::new(0.0051, 0.0, 0.0)));
        assert!((h.thickness() - 0.01).abs() < 1e-12);
    }

    #[test]
    fn within_planes_is_the_plane_distance_test() {
        // A sharp wedge and a sphere, at points from inside to well outside, with tolerances
        // of 0 to a tenth of the size: near the wedge's edge the offset planes meet far out.
        let wedge = Hull::from_points(&[
            P3::new(0.0, 0.0, 0.0),
            P3::new(1.0, 0.0, 0.0),
            P3::new(0.0, 0.02, 0.0),
            P3::new(0.0, 0.0, 1.0),
            P3::new(1.0, 0.0, 1.0),
            P3::new(0.0, 0.02, 1.0),
        ])
        .unwrap();
        let ball = Hull::from_points(&shapes::uv_sphere(0.5, 8, 16).vertices).unwrap();
        let mut rng = crate::rng::Rng::new(11);
        let (mut inside, mut outside) = (0, 0);
        for h in [&wedge, &ball] {
            for _ in 0..4000 {
                // In the hull's box grown by 30 % each way.
                let (lo, hi) = (h.aabb.min, h.aabb.max);
                let f = |a: f64, b: f64, u: f64| a + (b - a) * (1.6 * u - 0.3);
                let p = P3::new(
                    f(lo.x, hi.x, rng.next_f64()),
                    f(lo.y, hi.y, rng.next_f64()),
                    f(lo.z, hi.z, rng.next_f64()),
                );
                for eps in [0.0, 1e-3, 0.1] {
                    let want = h.plane_distance(&p) <= eps;
                    assert_eq!(h.within_planes(&p, eps), want, "{p:?} {eps}");
                    if want {
                        inside += 1;
                    } else {
                        outside += 1;
                    }
                }
            }
        }
        assert!(inside > 500 && outside > 500, "{inside} {outside}");
    }

    #[test]
    fn flat_points_make_no_hull() {
        let pts: Vec<P3> = (0..10)
            .map(|i| P3::new(i as f64, (i * i) as f64, 0.0))
            .collect();
        assert!(Hull::from_points(&pts).is_none());
    }

    #[test]
    fn simplification_keeps_the_flat_face_an_object_rests_on() {
        // A fruit cut flat at the bottom: the simplified hull must still stand on that flat spot,
        // with its support polygon around the centre of mass.
        let m = shapes::fruit(0.04, 0.036, 0.02, 32, 16);
        let zmin = m.vertices.iter().map(|v| v.z).fold(f64::INFINITY, f64::min);
        let h = Hull::from_points(&m.vertices)
            .unwrap()
            .simplified(64)
            .unwrap();
        assert!(h.vertices.len() <= 64);
        let bottom: Vec<&P3> = h.vertices.iter().filter(|v| v.z < zmin + 1e-9).collect();
        assert!(
            bottom.len() >= 6,
            "flat face kept: {} vertices",
            bottom.len()
        );
        let com = crate::inertia::of_closed_mesh(&m, 1000.0).com;
        let r = bottom
            .iter()
            .map(|v| ((v.x - com.x).powi(2) + (v.y - com.y).powi(2)).sqrt())
            .fold(f64::INFINITY, f64::min);
        assert!(
            r > 0.015,
            "support polygon reaches {r} m from the centre of mass"
        );
    }

    #[test]
    fn simplification_bounds_vertices_and_stays_inside() {
        let s = shapes::uv_sphere(0.05, 24, 48);
        let h = Hull::from_points(&s.vertices).unwrap();
        assert!(h.vertices.len() > 64);
        let small = h.clone().simplified(64).unwrap();
        assert!(small.vertices.len() <= 64);
        assert!(small.vertices.iter().all(|v| h.plane_distance(v) <= 1e-12));
        // Farthest-point sampling keeps most of the volume of a round hull.
        assert!(
            small.volume > 0.85 * h.volume,
            "{} vs {}",
            small.volume,
            h.volume
        );
    }

    #[test]
    fn significant_drops_vertices_within_the_plane_tolerance_only() {
        // A 5 cm cube with one point 0.5 mm above the centre of its top face and one 2 mm
        // above a bottom corner region: PhysX would skip the first (within 0.7 mm), not the
        // second.
        let mut pts = shapes::cuboid(V3::new(0.05, 0.05, 0.05)).vertices;
        pts.push(P3::new(0.0, 0.0, 0.0255));
        pts.push(P3::new(0.01, 0.01, -0.027));
        let h = Hull::from_points(&pts).unwrap();
        assert_eq!(h.vertices.len(), 10);
        let s = h.clone().significant(1e-3).unwrap();
        assert_eq!(s.vertices.len(), 9);
        assert!(!s.vertices.iter().any(|v| v.z > 0.0251));
        assert!(s.vertices.iter().any(|v| v.z < -0.0269));
        assert!(s.vertices.iter().all(|v| h.vertices.contains(v)));
    }

    #[test]
    fn within_physx_limits_bounds_polygons_and_keeps_inside() {
        // A 64-vertex round hull has ~124 triangles: PhysX re-cooks it. Brought within 64
        // polygons it stays inside the original and keeps most of its volume.
        let h = Hull::from_points(&shapes::uv_sphere(0.05, 24, 48).vertices)
            .unwrap()
            .simplified(64)
            .unwrap();
        assert!(h.polygon_stats().0 > 100, "{:?}", h.polygon_stats());
        let l = h.clone().within(&PhysxLimits::default()).unwrap();
        let (p, pv) = l.polygon_stats();
        assert!(p <= 64 && pv <= 32 && l.vertices.len() <= 64, "{p} {pv}");
        assert!(l.vertices.iter().all(|v| h.vertices.contains(v)));
        assert!(l.volume > 0.8 * h.volume, "{} vs {}", l.volume, h.volume);
        // A cube is left alone.
        let c = Hull::from_points(&shapes::cuboid(V3::new(0.01, 0.02, 0.03)).vertices).unwrap();
        assert_eq!(c.clone().within(&PhysxLimits::default()), Some(c.clone()));
        assert_eq!(c.polygon_stats(), (6, 4));
        assert!(
            (c.sliver_ratio() - 3.0).abs() < 1e-9,
            "{}",
            c.sliver_ratio()
        );
    }
}
