//! Closed primitives and the solids built from rings: box, UV sphere, cylinder, lofts and
//! surfaces of revolution, with their exact polyhedral volumes.
//!
//! Entry points: [`cuboid`], [`uv_sphere`], [`cylinder`], [`loft`], [`revolve`],
//! [`cubes_on_an_edge`]; volumes [`prism_volume`], [`loft_volume`], [`revolved_volume`].

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

// ---------------------------------------------------------------------------------------------
// Lofts and surfaces of revolution: the containers below are all built from these two.

/// A closed solid through a sequence of horizontal-ish rings of equal vertex count, each ring
/// counter-clockwise seen from +z, capped with a fan to `start` before the first ring and a fan
/// to `end` after the last one.
///
/// The rings are the cross-section of the wall traversed with the material on the left in the
/// (radial, z) half-plane: e.g. for a cup, outer bottom → outer rim → inner rim → inner floor,
/// with `start` the centre of the base and `end` the centre of the inner floor. Triangles are
/// counter-clockwise seen from outside. When corresponding edges of consecutive rings are
/// parallel (scaled copies, offset rounded rectangles, regular polygons) every quad is planar and
/// [`loft_volume`] gives the exact volume.
pub fn loft(rings: &[Vec<P3>], start: P3, end: P3) -> Mesh {
    assert!(!rings.is_empty(), "loft needs at least one ring");
    let n = rings[0].len();
    assert!(n >= 3, "a ring needs at least 3 vertices");
    assert!(
        rings.iter().all(|r| r.len() == n),
        "all rings need the same vertex count"
    );
    let m = rings.len();
    let mut vertices: Vec<P3> = rings.iter().flatten().copied().collect();
    let s = vertices.len() as u32;
    vertices.push(start);
    let e = s + 1;
    vertices.push(end);
    let v = |k: usize, j: usize| (k * n + j % n) as u32;
    let mut triangles = Vec::with_capacity(2 * n * m);
    for j in 0..n {
        triangles.push([s, v(0, j + 1), v(0, j)]);
    }
    for k in 0..m - 1 {
        for j in 0..n {
            let (a, b, c, d) = (v(k, j), v(k, j + 1), v(k + 1, j), v(k + 1, j + 1));
            triangles.push([a, b, c]);
            triangles.push([b, d, c]);
        }
    }
    for j in 0..n {
        triangles.push([v(m - 1, j), v(m - 1, j + 1), e]);
    }
    Mesh::new(vertices, triangles)
}

/// Area of a polygon's projection on the xy plane (shoelace), positive when counter-clockwise.
pub fn polygon_area_xy(ring: &[P3]) -> f64 {
    let n = ring.len();
    (0..n)
        .map(|i| {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            a.x * b.y - b.x * a.y
        })
        .sum::<f64>()
        / 2.0
}

/// Exact volume of [`loft`] when its quads are planar, by the prismatoid formula over each pair
/// of consecutive rings (caps included as rings shrunk to a point):
/// `Σ Δz · (A₀ + 4·A_mid + A₁) / 6`, with segments going down (the inside of a container)
/// counting negative. Independent of the triangle-based divergence sum of [`Mesh::signed_volume`].
pub fn loft_volume(rings: &[Vec<P3>], start: P3, end: P3) -> f64 {
    let n = rings[0].len();
    let mut all: Vec<Vec<P3>> = Vec::with_capacity(rings.len() + 2);
    all.push(vec![start; n]);
    all.extend(rings.iter().cloned());
    all.push(vec![end; n]);
    all.windows(2)
        .map(|w| {
            let (r0, r1) = (&w[0], &w[1]);
            let dz = r1[0].z - r0[0].z;
            let mid: Vec<P3> = r0
                .iter()
                .zip(r1)
                .map(|(a, b)| nalgebra::center(a, b))
                .collect();
            dz * (polygon_area_xy(r0) + 4.0 * polygon_area_xy(&mid) + polygon_area_xy(r1)) / 6.0
        })
        .sum()
}

/// The rings of a surface of revolution about z: one regular `slices`-gon (a vertex on +x) per
/// profile point `[r, z]`.
pub fn revolution_rings(profile: &[[f64; 2]], slices: usize) -> Vec<Vec<P3>> {
    assert!(slices >= 3, "slices must be at least 3");
    profile
        .iter()
        .map(|&[r, z]| {
            assert!(r > 0.0, "profile radii must be positive off the axis");
            (0..slices)
                .map(|j| {
                    let ph = 2.0 * PI * j as f64 / slices as f64;
                    P3::new(r * ph.cos(), r * ph.sin(), z)
                })
                .collect()
        })
        .collect()
}

/// Split a profile into its ring points and its two axis points: a first or last point with
/// `r == 0` is the axis point itself (a pole); otherwise the axis point is `(0, z)` of the
/// neighbouring ring (a flat cap).
fn split_profile(profile: &[[f64; 2]]) -> (&[[f64; 2]], [f64; 2], [f64; 2]) {
    let mut rings = profile;
    let start = if rings[0][0] == 0.0 {
        let s = rings[0];
        rings = &rings[1..];
        s
    } else {
        [0.0, rings[0][1]]
    };
    let end = if rings[rings.len() - 1][0] == 0.0 {
        let e = rings[rings.len() - 1];
        rings = &rings[..rings.len() - 1];
        e
    } else {
        [0.0, rings[rings.len() - 1][1]]
    };
    assert!(!rings.is_empty(), "profile needs a point off the axis");
    (rings, start, end)
}

/// A closed surface of revolution about z. `profile` lists `[r, z]` points of the wall's
/// cross-section with the material on the left (e.g. outer foot → outer rim → inner rim → inner
/// floor), from axis to axis. The first and last points may lie on the axis (`r == 0`, a pole);
/// if they do not, the profile is closed by a flat cap through `(0, z)` of the end point. All
/// other points need `r > 0`. Vertex `j` of every ring is at angle `2πj/slices` (vertex 0 on +x).
pub fn revolve(profile: &[[f64; 2]], slices: usize) -> Mesh {
    let (pts, s, e) = split_profile(profile);
    let rings = revolution_rings(pts, slices);
    loft(&rings, P3::new(0.0, 0.0, s[1]), P3::new(0.0, 0.0, e[1]))
}

/// Exact volume of [`revolve`]`(profile, slices)`: the solid of revolution of the profile polygon
/// (closed through the axis) by Pappus, times the ratio of a regular `slices`-gon's area to its
/// circumcircle's, `slices·sin(2π/slices) / (2π)` (every horizontal section of the polyhedron is
/// such a polygon, and every quad is a planar trapezoid).
pub fn revolved_volume(profile: &[[f64; 2]], slices: usize) -> f64 {
    let (pts, s, e) = split_profile(profile);
    let mut poly = vec![s];
    poly.extend_from_slice(pts);
    poly.push(e);
    let k = poly.len();
    // ∬ r dA over the (r, z) polygon (closed along the axis), positive for counter-clockwise.
    let first_moment: f64 = (0..k)
        .map(|i| {
            let ([x0, y0], [x1, y1]) = (poly[i], poly[(i + 1) % k]);
            (x0 * y1 - x1 * y0) * (x0 + x1)
        })
        .sum::<f64>()
        / 6.0;
    let n = slices as f64;
    2.0 * PI * first_moment * n * (2.0 * PI / n).sin() / (2.0 * PI)
}

/// Two cubes of side `a`, the first centred on the origin, the second on `(a, a, 0)`: they meet
/// along the edge `x = y = a/2`, whose two vertices they share. Four triangles meet on that
/// edge, as on the few non-manifold edges of scans (see [`Mesh::bounds_solid`]).
pub fn cubes_on_an_edge(a: f64) -> Mesh {
    let c = cuboid(V3::new(a, a, a));
    let mut vertices = c.vertices.clone();
    let shift = V3::new(a, a, 0.0);
    let index: Vec<u32> = c
        .vertices
        .iter()
        .map(|v| {
            let w = v + shift;
            match vertices.iter().position(|u| (u - w).norm() < 1e-12 * a) {
                Some(i) => i as u32,
                None => {
                    vertices.push(w);
                    vertices.len() as u32 - 1
                }
            }
        })
        .collect();
    let mut triangles = c.triangles.clone();
    triangles.extend(c.triangles.iter().map(|t| t.map(|i| index[i as usize])));
    Mesh::new(vertices, triangles)
}
