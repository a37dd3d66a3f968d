//! Mass, centre of mass and the full inertia tensor from geometry and density.
//!
//! Closed meshes: exact, by signed tetrahedra (parry's `MassProperties::from_trimesh`).
//! Open meshes: the union of the collision hulls, integrated on a regular grid (hulls overlap,
//! so summing their individual mass properties would count the overlap twice).

use crate::decompose::Hull;
use crate::mesh::{Mesh, P3, V3};
use nalgebra::Matrix3;
use serde::Serialize;

/// Default density, kg/m³ (water).
pub const DEFAULT_DENSITY: f64 = 1000.0;

/// Where an object's volume came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum VolumeSource {
    /// The closed visual mesh itself (exact).
    ClosedMesh,
    /// The union of the convex collision hulls (the mesh is not closed).
    HullUnion,
}

/// Mass properties of a rigid body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertial {
    pub mass: f64,
    /// Centre of mass.
    pub com: P3,
    /// Inertia tensor about the centre of mass, in the frame's axes (kg·m²).
    pub inertia: Matrix3<f64>,
    /// Volume (m³) the mass was computed from.
    pub volume: f64,
    pub source: VolumeSource,
}

impl Inertial {
    /// Rescale to a given total mass (a given mass overrides density).
    pub fn with_mass(mut self, mass: f64) -> Inertial {
        let k = mass / self.mass;
        self.mass = mass;
        self.inertia *= k;
        self
    }

    /// Principal moments must be positive and satisfy the triangle inequality (what MuJoCo and
    /// PhysX check); returns why not.
    pub fn check(&self) -> std::result::Result<(), String> {
        if !(self.mass.is_finite() && self.mass > 0.0) {
            return Err(format!("mass {} is not positive", self.mass));
        }
        let eig = self.inertia.symmetric_eigenvalues();
        let (a, b, c) = (eig[0], eig[1], eig[2]);
        if !(a > 0.0 && b > 0.0 && c > 0.0) {
            return Err(format!(
                "inertia has a non-positive principal moment ({a:.3e}, {b:.3e}, {c:.3e})"
            ));
        }
        let tol = 1e-9 * (a + b + c);
        if a + b + tol < c || a + c + tol < b || b + c + tol < a {
            return Err(format!(
                "principal moments ({a:.3e}, {b:.3e}, {c:.3e}) break the triangle inequality"
            ));
        }
        Ok(())
    }
}

/// Exact mass properties of a closed, outward-oriented mesh of uniform `density`.
pub fn of_closed_mesh(mesh: &Mesh, density: f64) -> Inertial {
    let (v, t) = mesh.to_parry();
    let mp = parry3d_f64::mass_properties::MassProperties::from_trimesh(density, &v, &t);
    let i = mp.reconstruct_inertia_matrix();
    let inertia = Matrix3::from_fn(|r, c| i.col(c)[r]);
    let com = crate::mesh::from_dvec(mp.local_com);
    Inertial {
        mass: mp.mass(),
        com,
        inertia: (inertia + inertia.transpose()) / 2.0,
        volume: mp.mass() / density,
        source: VolumeSource::ClosedMesh,
    }
}

/// Mass properties of the union of convex hulls, integrated on a grid of about `resolution`
/// cells along the longest axis (each cell a small box, its own inertia included).
pub fn of_hull_union(hulls: &[Hull], density: f64, resolution: usize) -> Option<Inertial> {
    let bounds = hulls.iter().map(|h| h.aabb).reduce(|a, b| a.union(&b))?;
    let ext = bounds.extents();
    let h = ext.max() / resolution.max(4) as f64;
    let n = [0, 1, 2].map(|i| ((ext[i] / h).ceil() as usize).max(1));
    let cell = V3::new(
        ext.x / n[0] as f64,
        ext.y / n[1] as f64,
        ext.z / n[2] as f64,
    );
    let dv = cell.x * cell.y * cell.z;
    let (mut m0, mut m1, mut m2) = (0.0f64, V3::zeros(), Matrix3::<f64>::zeros());
    for i in 0..n[0] {
        for j in 0..n[1] {
            for k in 0..n[2] {
                let p = bounds.min
                    + V3::new(
                        (i as f64 + 0.5) * cell.x,
                        (j as f64 + 0.5) * cell.y,
                        (k as f64 + 0.5) * cell.z,
                    );
                if hulls.iter().any(|hl| hl.contains(&p)) {
                    m0 += dv;
                    m1 += p.coords * dv;
                    m2 += p.coords * p.coords.transpose() * dv;
                }
            }
        }
    }
    if m0 <= 0.0 {
        return None;
    }
    let com = m1 / m0;
    // Second moment about the COM, plus each cell's own (box) second moment.
    let own = Matrix3::from_diagonal(&V3::new(cell.x * cell.x, cell.y * cell.y, cell.z * cell.z))
        * (m0 / 12.0);
    let c = m2 - com * com.transpose() * m0 + own;
    let inertia = (Matrix3::identity() * c.trace() - c) * density;
    Some(Inertial {
        mass: m0 * density,
        com: P3::from(com),
        inertia,
        volume: m0,
        source: VolumeSource::HullUnion,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;
    use std::f64::consts::PI;

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    #[test]
    fn box_mass_and_inertia_are_analytic() {
        let (a, b, c) = (0.1, 0.2, 0.3);
        let m = of_closed_mesh(&shapes::cuboid(V3::new(a, b, c)), 1000.0);
        let mass = 1000.0 * a * b * c;
        assert!(rel(m.mass, mass) < 1e-9);
        assert!(rel(m.inertia[(0, 0)], mass * (b * b + c * c) / 12.0) < 1e-9);
        assert!(rel(m.inertia[(1, 1)], mass * (a * a + c * c) / 12.0) < 1e-9);
        assert!(rel(m.inertia[(2, 2)], mass * (a * a + b * b) / 12.0) < 1e-9);
        assert!(m.inertia[(0, 1)].abs() < 1e-12 * mass);
        assert!(m.com.coords.norm() < 1e-12);
    }

    #[test]
    fn rotated_box_has_the_off_diagonal_terms() {
        let (a, b, c) = (0.1, 0.2, 0.3);
        let rot = nalgebra::Rotation3::from_euler_angles(0.4, -0.7, 1.1);
        let t =
            nalgebra::Isometry3::from_parts(nalgebra::Translation3::new(1.0, 2.0, 3.0), rot.into());
        let m = of_closed_mesh(
            &shapes::cuboid(V3::new(a, b, c)).transformed(&t.to_homogeneous()),
            1000.0,
        );
        let mass = 1000.0 * a * b * c;
        let local = Matrix3::from_diagonal(&V3::new(b * b + c * c, a * a + c * c, a * a + b * b))
            * (mass / 12.0);
        let expected = rot.matrix() * local * rot.matrix().transpose();
        assert!((m.inertia - expected).abs().max() < 1e-9 * expected.abs().max());
        assert!(expected[(0, 1)].abs() > 1e-3 * expected.abs().max());
        assert!((m.com - P3::new(1.0, 2.0, 3.0)).norm() < 1e-12);
    }

    #[test]
    fn cylinder_mass_and_inertia_within_half_a_percent() {
        let (r, h) = (0.04, 0.12);
        let m = of_closed_mesh(&shapes::cylinder(r, h, 256), 1000.0);
        let mass = 1000.0 * PI * r * r * h;
        assert!(rel(m.mass, mass) < 5e-3);
        assert!(rel(m.inertia[(2, 2)], mass * r * r / 2.0) < 5e-3);
        assert!(rel(m.inertia[(0, 0)], mass * (3.0 * r * r + h * h) / 12.0) < 5e-3);
    }

    #[test]
    fn sphere_mass_and_inertia_within_half_a_percent() {
        let r = 0.05;
        let m = of_closed_mesh(&shapes::uv_sphere(r, 64, 128), 1000.0);
        let mass = 1000.0 * 4.0 / 3.0 * PI * r.powi(3);
        assert!(rel(m.mass, mass) < 5e-3, "{} {}", m.mass, mass);
        for i in 0..3 {
            assert!(rel(m.inertia[(i, i)], 0.4 * mass * r * r) < 5e-3);
        }
    }

    #[test]
    fn hull_union_of_two_overlapping_boxes_counts_overlap_once() {
        // Two unit boxes overlapping by half: union volume 1.5, not 2.
        let a = Hull::from_points(&shapes::cuboid(V3::new(1.0, 1.0, 1.0)).vertices).unwrap();
        let moved: Vec<P3> = shapes::cuboid(V3::new(1.0, 1.0, 1.0))
            .vertices
            .iter()
            .map(|p| p + V3::new(0.5, 0.0, 0.0))
            .collect();
        let b = Hull::from_points(&moved).unwrap();
        let m = of_hull_union(&[a, b], 1.0, 64).unwrap();
        assert!(rel(m.volume, 1.5) < 1e-9, "{}", m.volume);
        assert!((m.com.x - 0.25).abs() < 1e-9);
        // Box 1.5 x 1 x 1: Ixx = m (1 + 1) / 12.
        assert!(rel(m.inertia[(0, 0)], 1.5 * 2.0 / 12.0) < 1e-6);
        assert!(rel(m.inertia[(1, 1)], 1.5 * (1.5 * 1.5 + 1.0) / 12.0) < 1e-3);
    }

    #[test]
    fn a_given_mass_rescales_inertia() {
        let m = of_closed_mesh(&shapes::cuboid(V3::new(0.1, 0.1, 0.1)), 1000.0).with_mass(2.0);
        assert_eq!(m.mass, 2.0);
        assert!(rel(m.inertia[(0, 0)], 2.0 * 0.02 / 12.0) < 1e-9);
        assert!(m.check().is_ok());
    }
}
