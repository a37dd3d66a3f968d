//! The benchmark's true resting pose: an item lowered along gravity until its mesh is an exact,
//! small clearance above the mesh of whatever is below it (the support, or the floor y = 0).
//!
//! The drop of [`super::realistic::pair_scene`] onto the support's column height field is
//! conservative (it clears 8 neighbouring columns), so it left true items floating up to 4 % of
//! their diagonal above the support; a real composed scene has them touching. This settles them.
//!
//! Entry points:
//! - [`lower_to_clearance`]: how far to lower (or raise) an item so that its exact distance to
//!   the support mesh and the floor is the clearance, found by conservative advancement (the
//!   distance between two meshes changes by at most the length of a translation, so lowering by
//!   `distance − clearance` never passes into penetration);
//! - [`mesh_gap`]: the exact minimum distance between two triangle meshes (parry).

use crate::mesh::Mesh;
use parry3d_f64::math::Pose;
use parry3d_f64::shape::TriMesh;

/// A mesh as parry's triangle mesh (`None` without triangles).
fn trimesh(m: &Mesh) -> Option<TriMesh> {
    if m.triangles.is_empty() {
        return None;
    }
    let (v, t) = m.to_parry();
    TriMesh::new(v, t).ok()
}

/// Exact minimum distance between the surfaces of `a` and `b` (0 where they cross; infinite
/// when either has no triangles).
pub fn mesh_gap(a: &Mesh, b: &Mesh) -> f64 {
    match (trimesh(a), trimesh(b)) {
        (Some(a), Some(b)) => surface_distance(&a, &b, 0.0),
        _ => f64::INFINITY,
    }
}

/// Distance between `support` and `item` translated by −`drop` along y.
fn surface_distance(support: &TriMesh, item: &TriMesh, drop: f64) -> f64 {
    let id = Pose::identity();
    let down = Pose::translation(0.0, -drop, 0.0);
    parry3d_f64::query::distance(&id, support, &down, item).map_or(f64::INFINITY, |d| d.distance)
}

/// How far to lower `item` (both meshes in the world frame, y up; negative: raise) so that the
/// smaller of its exact distance to `support` and its height above the floor y = 0 is
/// `clearance`, within 1 % of it: the first such height on the way down. The returned gap
/// is the exact one at that height. An item that starts closer than the clearance is first
/// raised (by doubling steps) until it is clear.
pub fn lower_to_clearance(support: &Mesh, item: &Mesh, clearance: f64) -> (f64, f64) {
    let floor = item
        .vertices
        .iter()
        .map(|p| p.y)
        .fold(f64::INFINITY, f64::min);
    let (Some(s), Some(i)) = (trimesh(support), trimesh(item)) else {
        return (floor - clearance, clearance);
    };
    let gap = |drop: f64| surface_distance(&s, &i, drop).min(floor - drop);
    let mut drop = 0.0;
    let mut g = gap(drop);
    let mut step = clearance;
    while g < clearance && step < 1e6 * clearance {
        drop -= step;
        step *= 2.0;
        g = gap(drop);
    }
    for _ in 0..500 {
        if g - clearance <= 0.01 * clearance {
            break;
        }
        drop += g - clearance;
        g = gap(drop);
    }
    (drop, g)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::cuboid;
    use nalgebra::{Matrix4, Rotation3, Vector3};

    fn moved(m: &Mesh, t: Matrix4<f64>) -> Mesh {
        Mesh::new(
            m.vertices.iter().map(|p| t.transform_point(p)).collect(),
            m.triangles.clone(),
        )
    }

    #[test]
    fn a_cube_settles_on_a_slab_and_on_a_ridge() {
        // A 2 × 1 × 2 slab with its top at y = 1; a unit cube whose bottom starts at y = 1.7.
        let slab = moved(
            &cuboid(Vector3::new(2.0, 1.0, 2.0)),
            Matrix4::new_translation(&Vector3::new(0.0, 0.5, 0.0)),
        );
        let cube = moved(
            &cuboid(Vector3::new(1.0, 1.0, 1.0)),
            Matrix4::new_translation(&Vector3::new(0.3, 2.2, 0.1)),
        );
        let (drop, gap) = lower_to_clearance(&slab, &cube, 1e-3);
        assert!((drop - (0.7 - 1e-3)).abs() <= 1e-5, "{drop}");
        assert!((0.999_999e-3..=1.01e-3).contains(&gap), "{gap}");
        // A ridge: the slab's cube turned 45° about z has its top edge at y = √2/2 + 0.5;
        // the cube, offset along the ridge, settles with its flat bottom on that edge.
        let ridge = moved(
            &cuboid(Vector3::new(1.0, 1.0, 1.0)),
            Matrix4::new_translation(&Vector3::new(0.0, 0.5, 0.0))
                * Rotation3::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_4)
                    .to_homogeneous(),
        );
        let top = 0.5 + std::f64::consts::FRAC_1_SQRT_2;
        let (drop, gap) = lower_to_clearance(&ridge, &cube, 2e-3);
        assert!((drop - (1.7 - top - 2e-3)).abs() <= 2e-5, "{drop}");
        assert!((1.999_999e-3..=2.02e-3).contains(&gap), "{gap}");
        // Starting inside (penetrating by 0.2) the cube is raised, then settles the same.
        let low = moved(
            &cube,
            Matrix4::new_translation(&Vector3::new(0.0, -0.9, 0.0)),
        );
        let (drop, _) = lower_to_clearance(&slab, &low, 1e-3);
        assert!((drop - (-0.2 - 1e-3)).abs() <= 1e-5, "{drop}");
        // Beside the slab it falls to the floor.
        let beside = moved(
            &cube,
            Matrix4::new_translation(&Vector3::new(3.0, 0.0, 0.0)),
        );
        let (drop, gap) = lower_to_clearance(&slab, &beside, 1e-3);
        assert!(
            (drop - (1.7 - 1e-3)).abs() <= 1e-9 && (gap - 1e-3).abs() < 1e-9,
            "{drop} {gap}"
        );
        assert!((mesh_gap(&slab, &cube) - 0.7).abs() < 1e-12);
    }
}
