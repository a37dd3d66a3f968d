//! Procedural meshes with known volume, area and inertia: test cases for every stage and the
//! building blocks of the generated fixtures. All are closed and outward oriented unless said.

use crate::mesh::{Mesh, P3, V3};
use std::f64::consts::PI;

/// An axis-aligned box centred at the origin with the given full extents.
pub fn cuboid(extents: V3) -> Mesh {
    let h = extents / 2.0;
    let vertices = (0..8)
        .map(|i| {
            P3::new(
                if i & 1 == 0 { -h.x } else { h.x },
                if i & 2 == 0 { -h.y } else { h.y },
                if i & 4 == 0 { -h.z } else { h.z },
            )
        })
        .collect();
    let triangles = vec![
        [0, 2, 1],
        [1, 2, 3], // -z
        [4, 5, 6],
        [5, 7, 6], // +z
        [0, 1, 4],
        [1, 5, 4], // -y
        [2, 6, 3],
        [3, 6, 7], // +y
        [0, 4, 2],
        [2, 4, 6], // -x
        [1, 3, 5],
        [3, 7, 5], // +x
    ];
    Mesh::new(vertices, triangles)
}

/// A UV sphere of radius `r` centred at the origin, `stacks` >= 2 rings, `slices` >= 3.
/// Its volume is below the true sphere's by the usual polyhedral deficit.
pub fn uv_sphere(r: f64, stacks: usize, slices: usize) -> Mesh {
    let mut vertices = vec![P3::new(0.0, 0.0, r)];
    for i in 1..stacks {
        let th = PI * i as f64 / stacks as f64;
        for j in 0..slices {
            let ph = 2.0 * PI * j as f64 / slices as f64;
            vertices.push(P3::new(
                r * th.sin() * ph.cos(),
                r * th.sin() * ph.sin(),
                r * th.cos(),
            ));
        }
    }
    vertices.push(P3::new(0.0, 0.0, -r));
    let bottom = (vertices.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * slices + j % slices) as u32;
    let mut triangles = Vec::new();
    for j in 0..slices {
        triangles.push([0, ring(1, j), ring(1, j + 1)]);
    }
    for i in 1..stacks - 1 {
        for j in 0..slices {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j),
                ring(i + 1, j + 1),
            );
            triangles.push([a, c, b]);
            triangles.push([b, c, d]);
        }
    }
    for j in 0..slices {
        triangles.push([bottom, ring(stacks - 1, j + 1), ring(stacks - 1, j)]);
    }
    Mesh::new(vertices, triangles)
}

/// A closed cylinder along z, radius `r`, height `h`, centred at the origin.
pub fn cylinder(r: f64, h: f64, slices: usize) -> Mesh {
    let mut vertices = vec![P3::new(0.0, 0.0, -h / 2.0), P3::new(0.0, 0.0, h / 2.0)];
    for j in 0..slices {
        let ph = 2.0 * PI * j as f64 / slices as f64;
        vertices.push(P3::new(r * ph.cos(), r * ph.sin(), -h / 2.0));
        vertices.push(P3::new(r * ph.cos(), r * ph.sin(), h / 2.0));
    }
    let lo = |j: usize| (2 + 2 * (j % slices)) as u32;
    let hi = |j: usize| (3 + 2 * (j % slices)) as u32;
    let mut triangles = Vec::new();
    for j in 0..slices {
        triangles.push([0, lo(j + 1), lo(j)]);
        triangles.push([1, hi(j), hi(j + 1)]);
        triangles.push([lo(j), lo(j + 1), hi(j)]);
        triangles.push([hi(j), lo(j + 1), hi(j + 1)]);
    }
    Mesh::new(vertices, triangles)
}

/// Exact volume of the inscribed polyhedral UV sphere is awkward; tests use this helper for the
/// volume of a regular `slices`-gon prism (the cylinder above).
pub fn prism_volume(r: f64, h: f64, slices: usize) -> f64 {
    0.5 * slices as f64 * r * r * (2.0 * PI / slices as f64).sin() * h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuboid_volume_area_closed() {
        let m = cuboid(V3::new(1.0, 2.0, 3.0));
        assert!((m.signed_volume() - 6.0).abs() < 1e-12);
        assert!((m.area() - 22.0).abs() < 1e-12);
        assert!(m.is_closed());
    }

    #[test]
    fn sphere_converges_to_analytic_volume() {
        let m = uv_sphere(1.0, 64, 128);
        assert!(m.is_closed());
        let v = m.signed_volume();
        let exact = 4.0 / 3.0 * PI;
        assert!(v < exact && (exact - v) / exact < 2e-3, "{v}");
    }

    #[test]
    fn cylinder_matches_prism_volume() {
        let m = cylinder(0.5, 2.0, 32);
        assert!(m.is_closed());
        assert!((m.signed_volume() - prism_volume(0.5, 2.0, 32)).abs() < 1e-12);
    }
}
