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

impl Hull {
    /// The convex hull of a point set; `None` when degenerate (fewer than 4 points in general
    /// position, or zero volume).
    pub fn from_points(points: &[P3]) -> Option<Hull> {
        if points.len() < 4 || points.iter().any(|p| !p.iter().all(|c| c.is_finite())) {
            return None;
        }
        let pts: Vec<_> = points.iter().map(to_dvec).collect();
        let (v, t) =
            std::panic::catch_unwind(|| parry3d_f64::transformation::try_convex_hull(&pts))
                .ok()?
                .ok()?;
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

    /// Signed distance to the closest face plane: negative inside (a lower bound on the depth
    /// for inside points), an approximation outside.
    pub fn plane_distance(&self, p: &P3) -> f64 {
        self.planes
            .iter()
            .map(|(n, d)| n.dot(&p.coords) - d)
            .fold(f64::NEG_INFINITY, f64::max)
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
        let c = self.aabb.center();
        // Seed with the vertex farthest from the centre, then farthest from the kept set.
        let mut kept = vec![(0..pts.len())
            .max_by(|&i, &j| {
                (pts[i] - c)
                    .norm_squared()
                    .total_cmp(&(pts[j] - c).norm_squared())
                    .then(j.cmp(&i))
            })
            .unwrap()];
        let mut dist: Vec<f64> = pts
            .iter()
            .map(|p| (p - pts[kept[0]]).norm_squared())
            .collect();
        while kept.len() < max_vertices {
            let (k, _) = dist
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(&a.0)))
                .unwrap();
            kept.push(k);
            for (i, p) in pts.iter().enumerate() {
                dist[i] = dist[i].min((p - pts[k]).norm_squared());
            }
        }
        kept.sort_unstable();
        let sub: Vec<P3> = kept.iter().map(|&i| pts[i]).collect();
        Hull::from_points(&sub)
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
    fn flat_points_make_no_hull() {
        let pts: Vec<P3> = (0..10)
            .map(|i| P3::new(i as f64, (i * i) as f64, 0.0))
            .collect();
        assert!(Hull::from_points(&pts).is_none());
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
}
