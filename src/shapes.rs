//! Procedural meshes with known volume, area and inertia: test cases for every stage and the
//! building blocks of the generated fixtures. All are closed and outward oriented unless said.

use crate::mesh::{Material, Mesh, Texture, VisualMesh, VisualPart, P3, V3};
use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::Arc;

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

/// Dimensions of [`bowl`] that placements need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BowlDims {
    /// Radius of the flat foot (z = 0) and of the flat inner floor.
    pub flat_radius: f64,
    /// Height of the flat inner floor (= `wall`).
    pub floor_z: f64,
    /// Inner radius at the rim (`outer_radius − wall`).
    pub inner_rim_radius: f64,
    pub height: f64,
}

/// The profile of [`bowl`]: outer wall a quarter ellipse from the foot `(R/2, 0)` to the rim
/// `(R, H)` (centre `(R/2, H)`, semi-axes `R/2` and `H`), a flat rim of width `wall`, inner wall
/// the nested quarter ellipse (semi-axes `R/2 − wall`, `H − wall`) down to the flat inner floor
/// at `z = wall`. `rings` points per quarter ellipse.
pub fn bowl_profile(outer_radius: f64, height: f64, wall: f64, rings: usize) -> Vec<[f64; 2]> {
    let (r, h, w) = (outer_radius, height, wall);
    assert!(
        w > 0.0 && w < r / 2.0 && w < h,
        "bowl wall must be in (0, min(R/2, H))"
    );
    assert!(rings >= 1);
    let rf = r / 2.0;
    let (ao, co, ai, ci) = (r - rf, h, r - w - rf, h - w);
    let mut p = Vec::with_capacity(2 * rings + 2);
    for k in 0..=rings {
        let th = PI / 2.0 * k as f64 / rings as f64;
        p.push([rf + ao * th.sin(), h - co * th.cos()]);
    }
    for k in (0..=rings).rev() {
        let th = PI / 2.0 * k as f64 / rings as f64;
        p.push([rf + ai * th.sin(), h - ci * th.cos()]);
    }
    // Exact ends (no rounding from sin/cos).
    p[0] = [rf, 0.0];
    p[rings] = [r, h];
    p[rings + 1] = [r - w, h];
    p[2 * rings + 1] = [rf, w];
    p
}

/// A bowl standing on z = 0, axis z: flat foot and flat inner floor of radius `outer_radius/2`,
/// elliptic walls rising to a flat rim at `z = height` (outer radius `outer_radius`, inner
/// `outer_radius − wall`), floor thickness `wall`. `slices` around, `rings` per quarter ellipse.
/// Triangles: `slices · (4·rings + 4)`.
pub fn bowl(outer_radius: f64, height: f64, wall: f64, slices: usize, rings: usize) -> Mesh {
    revolve(&bowl_profile(outer_radius, height, wall, rings), slices)
}

/// Key dimensions of [`bowl`].
pub fn bowl_dims(outer_radius: f64, height: f64, wall: f64) -> BowlDims {
    BowlDims {
        flat_radius: outer_radius / 2.0,
        floor_z: wall,
        inner_rim_radius: outer_radius - wall,
        height,
    }
}

/// Volume of the smooth bowl that [`bowl`] approximates (the limit of fine resolution).
pub fn bowl_smooth_volume(outer_radius: f64, height: f64, wall: f64) -> f64 {
    let (r, h, w) = (outer_radius, height, wall);
    let rf = r / 2.0;
    let (ao, ai, ci) = (r - rf, r - w - rf, h - w);
    // ∫ π (rf + a·sqrt(1 − u²))² c du over u ∈ [0, 1].
    let solid = |a: f64, c: f64| PI * c * (rf * rf + rf * a * PI / 2.0 + 2.0 * a * a / 3.0);
    solid(ao, h) - solid(ai, ci)
}

/// The profile of [`mug`].
pub fn mug_profile(outer_radius: f64, height: f64, wall: f64, bottom: f64) -> Vec<[f64; 2]> {
    assert!(wall > 0.0 && wall < outer_radius && bottom > 0.0 && bottom < height);
    let ri = outer_radius - wall;
    vec![
        [outer_radius, 0.0],
        [outer_radius, height],
        [ri, height],
        [ri, bottom],
    ]
}

/// An open-top cylindrical cup (no handle) standing on z = 0, axis z: outer radius
/// `outer_radius`, inner radius `outer_radius − wall`, flat inner floor at `z = bottom`, rim at
/// `z = height`. A vertex of every ring lies on +x (so the inner rim has a vertex at
/// `(outer_radius − wall, 0, height)`). Volume: `A·(R²·H − rᵢ²·(H − bottom))` with `A` the
/// `slices`-gon area factor `slices·sin(2π/slices)/2`. Triangles: `8·slices`.
pub fn mug(outer_radius: f64, height: f64, wall: f64, bottom: f64, slices: usize) -> Mesh {
    revolve(&mug_profile(outer_radius, height, wall, bottom), slices)
}

/// A counter-clockwise rounded rectangle at height `z`: core half-extents `hx`, `hy` (the corner
/// centres), corner radius `r > 0`, `segments` arc segments per corner (`4·(segments+1)` points).
/// Rounded rectangles with the same `segments` have parallel corresponding edges, so lofts of
/// them have planar quads.
pub fn rounded_rect(hx: f64, hy: f64, r: f64, segments: usize, z: f64) -> Vec<P3> {
    assert!(r > 0.0 && hx >= 0.0 && hy >= 0.0 && segments >= 1);
    let corners = [(hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy)];
    let mut pts = Vec::with_capacity(4 * (segments + 1));
    for (q, &(cx, cy)) in corners.iter().enumerate() {
        for s in 0..=segments {
            let a = PI / 2.0 * (q as f64 + s as f64 / segments as f64);
            pts.push(P3::new(cx + r * a.cos(), cy + r * a.sin(), z));
        }
    }
    pts
}

/// An open shelf (an étagère) standing on z = 0, centred on the z axis: two side panels
/// `board` thick, `depth` deep (along y) and `height` tall at x = ±(width/2 − board/2), and one
/// horizontal board per entry of `levels` (the z of its top face) spanning the inner width
/// `width − 2·board`, `board` thick, set back 5 mm from the front and the back edges. Every
/// piece is its own closed box; the boards' ends touch the panels' inner faces, where no
/// vertices are shared (the boards' corners lie inside the panels' faces), so the mesh is
/// closed and its volume is the sum of the boxes'.
pub fn shelf(width: f64, depth: f64, height: f64, board: f64, levels: &[f64]) -> Mesh {
    let inset = SHELF_INSET;
    assert!(width > 2.0 * board && depth > 2.0 * inset);
    let mut m = Mesh::new(Vec::new(), Vec::new());
    let mut put = |ext: V3, c: V3| {
        let b = cuboid(ext).transformed(&nalgebra::Translation3::from(c).to_homogeneous());
        m.append(&b);
    };
    for sx in [-1.0, 1.0] {
        put(
            V3::new(board, depth, height),
            V3::new(sx * (width - board) / 2.0, 0.0, height / 2.0),
        );
    }
    for &top in levels {
        assert!(top - board > 0.0 && top < height, "board inside the panels");
        put(
            V3::new(width - 2.0 * board, depth - 2.0 * inset, board),
            V3::new(0.0, 0.0, top - board / 2.0),
        );
    }
    m
}

/// How far [`shelf`]'s boards are set back from the panels' front and back edges.
const SHELF_INSET: f64 = 0.005;

/// Volume of [`shelf`].
pub fn shelf_volume(width: f64, depth: f64, height: f64, board: f64, levels: usize) -> f64 {
    let board_depth = depth - 2.0 * SHELF_INSET;
    2.0 * board * depth * height + levels as f64 * (width - 2.0 * board) * board_depth * board
}

/// A flat tray standing on z = 0, centred on the z axis: outer footprint `extents[0] × extents[1]`
/// with corners rounded at radius `2·wall` (4 segments each), floor plate and vertical rim walls
/// `wall` thick, rim rising `rim_height` above the floor's top (total height `wall + rim_height`).
/// The inner floor is the plane `z = wall`.
pub fn tray(extents: [f64; 2], wall: f64, rim_height: f64) -> Mesh {
    let (rings, s, e) = tray_rings(extents, wall, rim_height);
    loft(&rings, s, e)
}

/// The rings and cap centres of [`tray`] (for [`loft_volume`]).
pub fn tray_rings(extents: [f64; 2], wall: f64, rim_height: f64) -> (Vec<Vec<P3>>, P3, P3) {
    let r = 2.0 * wall;
    let (hx, hy) = (extents[0] / 2.0 - r, extents[1] / 2.0 - r);
    assert!(
        hx >= 0.0 && hy >= 0.0 && rim_height > 0.0,
        "tray too small for its wall"
    );
    let top = wall + rim_height;
    let seg = 4;
    let rings = vec![
        rounded_rect(hx, hy, r, seg, 0.0),
        rounded_rect(hx, hy, r, seg, top),
        rounded_rect(hx, hy, r - wall, seg, top),
        rounded_rect(hx, hy, r - wall, seg, wall),
    ];
    (rings, P3::new(0.0, 0.0, 0.0), P3::new(0.0, 0.0, wall))
}

/// A wide, shallow basket with slanted walls, standing on z = 0, centred on the z axis: outer
/// top footprint `extents[0] × extents[1]` with corner radius `corner_radius`, the walls leaning
/// outwards so the outer bottom is inset by `inset` on every side, walls `wall` thick (normal to
/// the wall), flat inner floor at `z = wall`, rim at `z = height`. `corner_segments` per corner.
pub fn basket(
    extents: [f64; 2],
    height: f64,
    wall: f64,
    inset: f64,
    corner_radius: f64,
    corner_segments: usize,
) -> Mesh {
    let (rings, s, e) = basket_rings(extents, height, wall, inset, corner_radius, corner_segments);
    loft(&rings, s, e)
}

/// Horizontal wall thickness of [`basket`] (`wall / cos(slant)`).
pub fn basket_wall_horizontal(height: f64, wall: f64, inset: f64) -> f64 {
    wall * (height * height + inset * inset).sqrt() / height
}

/// The rings and cap centres of [`basket`].
pub fn basket_rings(
    extents: [f64; 2],
    height: f64,
    wall: f64,
    inset: f64,
    corner_radius: f64,
    corner_segments: usize,
) -> (Vec<Vec<P3>>, P3, P3) {
    let (hx, hy) = (
        extents[0] / 2.0 - corner_radius,
        extents[1] / 2.0 - corner_radius,
    );
    let wh = basket_wall_horizontal(height, wall, inset);
    let floor_offset = wh + inset * (1.0 - wall / height);
    assert!(
        hx >= 0.0 && hy >= 0.0 && corner_radius > floor_offset.max(inset) && wall < height,
        "basket corner radius must exceed the inner floor's offset from the rim"
    );
    let seg = corner_segments;
    let rings = vec![
        rounded_rect(hx, hy, corner_radius - inset, seg, 0.0),
        rounded_rect(hx, hy, corner_radius, seg, height),
        rounded_rect(hx, hy, corner_radius - wh, seg, height),
        rounded_rect(hx, hy, corner_radius - floor_offset, seg, wall),
    ];
    (rings, P3::new(0.0, 0.0, 0.0), P3::new(0.0, 0.0, wall))
}

/// The profile of [`pen`].
pub fn pen_profile(radius: f64, length: f64) -> Vec<[f64; 2]> {
    let tip = (3.0 * radius).min(length / 4.0);
    let h = length / 2.0;
    vec![[radius, -h], [radius, h - tip], [0.35 * radius, h]]
}

/// A pen along z centred at the origin: a `slices`-gon prism of circumradius `radius` with a flat
/// bottom cap at `z = −length/2` and a conical tip (length `min(3·radius, length/4)`) ending in a
/// small flat at `z = +length/2`. Vertex 0 of every ring on +x.
pub fn pen(radius: f64, length: f64, slices: usize) -> Mesh {
    revolve(&pen_profile(radius, length), slices)
}

/// The profile of [`fruit`].
pub fn fruit_profile(
    radius: f64,
    half_height: f64,
    flat_radius: f64,
    rings: usize,
) -> Vec<[f64; 2]> {
    assert!(flat_radius > 0.0 && flat_radius < radius && rings >= 2);
    let th0 = (flat_radius / radius).asin();
    let c0 = th0.cos();
    let mut p: Vec<[f64; 2]> = (0..rings)
        .map(|k| {
            let th = th0 + (PI - th0) * k as f64 / rings as f64;
            [radius * th.sin(), half_height * (c0 - th.cos())]
        })
        .collect();
    p[0] = [flat_radius, 0.0];
    p.push([0.0, half_height * (c0 + 1.0)]);
    p
}

/// A spheroidal "fruit" standing on a small flat spot: the spheroid with horizontal semi-axis
/// `radius` and vertical `half_height`, cut at the bottom where its radius is `flat_radius`, so it
/// rests stably on a flat face at z = 0. `rings` profile steps from the flat to the top pole.
pub fn fruit(radius: f64, half_height: f64, flat_radius: f64, slices: usize, rings: usize) -> Mesh {
    revolve(
        &fruit_profile(radius, half_height, flat_radius, rings),
        slices,
    )
}

/// Volume of the smooth truncated spheroid that [`fruit`] approximates.
pub fn fruit_smooth_volume(radius: f64, half_height: f64, flat_radius: f64) -> f64 {
    let (a, c) = (radius, half_height);
    let h = c * (1.0 - (1.0 - (flat_radius / a).powi(2)).sqrt()); // height of the cut-off cap
    4.0 / 3.0 * PI * a * a * c - PI * (a / c).powi(2) * h * h * (3.0 * c - h) / 3.0
}

// ---------------------------------------------------------------------------------------------
// Texture coordinates, materials and procedural textures.

/// How [`with_uvs`] maps positions to texture coordinates (glTF convention: v grows downwards, so
/// the top of the image is at the top of the object). Ranges come from the mesh's bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum UvProjection {
    /// Seen from above: u along x, v along −y, both scaled by the larger xy extent.
    PlanarZ,
    /// Around the z axis: u = angle / 2π (`repeat` times), v from the top (max z) down.
    Cylindrical { repeat: f64 },
    /// Around the z axis: u = angle / 2π (`repeat` times), v = polar angle / π from +z.
    Spherical { repeat: f64 },
    /// Per triangle, the axis its normal points most along chooses the plane to project on;
    /// `tile` metres per texture repeat.
    Box { tile: f64 },
}

/// Give a welded mesh UVs by `projection`: vertices are split where the UVs of their triangles
/// disagree (the seam of the cylindrical map, the edges of the box map), otherwise shared.
/// Returns positions, UVs and triangles of one [`VisualPart`]. Deterministic.
pub fn with_uvs(mesh: &Mesh, projection: UvProjection) -> (Vec<P3>, Vec<[f64; 2]>, Vec<[u32; 3]>) {
    let bb = mesh.aabb().expect("with_uvs needs a non-empty mesh");
    let ext = bb.extents();
    let centre = bb.center();
    let span = |d: f64| if d > 0.0 { d } else { 1.0 };
    let angle_u = |p: &P3| -> Option<f64> {
        let (x, y) = (p.x - centre.x, p.y - centre.y);
        if x.hypot(y) <= 1e-12 * (1.0 + ext.x.max(ext.y)) {
            None
        } else {
            Some(y.atan2(x).rem_euclid(2.0 * PI) / (2.0 * PI))
        }
    };
    let mut positions = Vec::new();
    let mut uvs: Vec<[f64; 2]> = Vec::new();
    let mut triangles = Vec::with_capacity(mesh.triangles.len());
    let mut seen: HashMap<(u32, u64, u64), u32> = HashMap::new();
    for t in &mesh.triangles {
        let ps = [
            mesh.vertices[t[0] as usize],
            mesh.vertices[t[1] as usize],
            mesh.vertices[t[2] as usize],
        ];
        let mut uv = [[0.0f64; 2]; 3];
        match projection {
            UvProjection::PlanarZ => {
                let s = span(ext.x.max(ext.y));
                for k in 0..3 {
                    uv[k] = [(ps[k].x - bb.min.x) / s, (bb.max.y - ps[k].y) / s];
                }
            }
            UvProjection::Cylindrical { repeat } | UvProjection::Spherical { repeat } => {
                let mut us: [Option<f64>; 3] = [angle_u(&ps[0]), angle_u(&ps[1]), angle_u(&ps[2])];
                // Unwrap across the seam at angle 0.
                let known: Vec<f64> = us.iter().flatten().copied().collect();
                if let (Some(lo), Some(hi)) = (
                    known.iter().copied().reduce(f64::min),
                    known.iter().copied().reduce(f64::max),
                ) {
                    if hi - lo > 0.5 {
                        for u in us.iter_mut().flatten() {
                            if *u < 0.5 {
                                *u += 1.0;
                            }
                        }
                    }
                }
                let mean = {
                    let k: Vec<f64> = us.iter().flatten().copied().collect();
                    if k.is_empty() {
                        0.0
                    } else {
                        k.iter().sum::<f64>() / k.len() as f64
                    }
                };
                for k in 0..3 {
                    let u = us[k].unwrap_or(mean) * repeat;
                    let v = match projection {
                        UvProjection::Spherical { .. } => {
                            let d = ps[k] - centre;
                            let r = d.norm();
                            if r > 0.0 {
                                (d.z / r).clamp(-1.0, 1.0).acos() / PI
                            } else {
                                0.5
                            }
                        }
                        _ => (bb.max.z - ps[k].z) / span(ext.z),
                    };
                    uv[k] = [u, v];
                }
            }
            UvProjection::Box { tile } => {
                let n = (ps[1] - ps[0]).cross(&(ps[2] - ps[0]));
                let axis = n.iamax();
                for k in 0..3 {
                    let d = ps[k] - bb.min;
                    let (a, b) = match axis {
                        0 => (d.y, ext.z - d.z),
                        1 => (d.x, ext.z - d.z),
                        _ => (d.x, ext.y - d.y),
                    };
                    uv[k] = [a / tile, b / tile];
                }
            }
        }
        let mut tri = [0u32; 3];
        for k in 0..3 {
            let key = (t[k], uv[k][0].to_bits(), uv[k][1].to_bits());
            tri[k] = *seen.entry(key).or_insert_with(|| {
                positions.push(ps[k]);
                uvs.push(uv[k]);
                (positions.len() - 1) as u32
            });
        }
        triangles.push(tri);
    }
    (positions, uvs, triangles)
}

/// A one-part [`VisualMesh`] of `mesh` with UVs by `projection` and `material`.
pub fn visual(mesh: &Mesh, projection: UvProjection, material: Material) -> VisualMesh {
    let (positions, uvs, triangles) = with_uvs(mesh, projection);
    VisualMesh {
        parts: vec![VisualPart {
            positions,
            uvs: Some(uvs),
            triangles,
            material,
        }],
    }
}

/// Encode an RGB image as PNG (deterministic bytes for the same pixels) and wrap it as a
/// [`Texture`] named `origin`.
pub fn png_texture(img: &image::RgbImage, origin: &str) -> Texture {
    use image::ImageEncoder;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgb8,
        )
        .expect("PNG encoding into memory cannot fail");
    Texture {
        origin: origin.to_string(),
        bytes: Arc::new(bytes),
        width: img.width(),
        height: img.height(),
    }
}

/// A `size`×`size` checkerboard of `cells`×`cells` squares in colours `a` and `b`, with a thin
/// darker line along the top row so orientation mistakes (v flipped) show.
pub fn checker_texture(size: u32, cells: u32, a: [u8; 3], b: [u8; 3], origin: &str) -> Texture {
    let cell = (size / cells.max(1)).max(1);
    let img = image::RgbImage::from_fn(size, size, |x, y| {
        if y < (size / 32).max(1) {
            return image::Rgb([a[0] / 3, a[1] / 3, a[2] / 3]);
        }
        if ((x / cell) + (y / cell)) % 2 == 0 {
            image::Rgb(a)
        } else {
            image::Rgb(b)
        }
    });
    png_texture(&img, origin)
}

/// A `size`×`size` image of `stripes` vertical stripes (constant along v, so a cylindrical or
/// spherical map gives meridian bands) alternating `a` and `b`.
pub fn stripes_texture(size: u32, stripes: u32, a: [u8; 3], b: [u8; 3], origin: &str) -> Texture {
    let w = (size / stripes.max(1)).max(1);
    let img = image::RgbImage::from_fn(size, size, |x, _| {
        if (x / w) % 2 == 0 {
            image::Rgb(a)
        } else {
            image::Rgb(b)
        }
    });
    png_texture(&img, origin)
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

/// A material showing `texture` unmodified (base colour factor white).
pub fn textured_material(name: &str, texture: Texture) -> Material {
    Material {
        name: name.to_string(),
        base_color: [1.0, 1.0, 1.0, 1.0],
        texture: Some(texture),
    }
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
    fn edge_defects_count_holes_and_doubled_edges() {
        let mut m = cuboid(V3::new(1.0, 2.0, 3.0));
        assert_eq!(m.edge_defects(), (0, 0));
        // A triangle removed: a hole rimmed by its 3 edges.
        let t = m.triangles.pop().unwrap();
        assert_eq!(m.edge_defects(), (0, 3));
        // Put back twice: its 3 edges run twice the same way, and no hole.
        m.triangles.extend([t, t]);
        assert_eq!(m.edge_defects(), (3, 0));
    }

    /// Two cubes meeting along an edge, welded there: four triangles meet on it, each of its
    /// directed edges is run twice. Not [`Mesh::is_closed`], but it bounds a solid whose
    /// signed volume is the two cubes'. A hole, a fin on an edge or a flipped triangle does not.
    #[test]
    fn two_cubes_on_a_shared_edge_bound_a_solid() {
        let m = cubes_on_an_edge(1.0);
        assert_eq!(m.edge_defects(), (2, 0));
        assert!(!m.is_closed() && m.bounds_solid());
        assert!((m.signed_volume() - 2.0).abs() < 1e-12);
        let mut hole = m.clone();
        hole.triangles.pop();
        assert!(!hole.bounds_solid());
        let mut flipped = m.clone();
        flipped.triangles[3].swap(0, 1);
        assert!(!flipped.bounds_solid());
        let mut fin = m.clone();
        let [a, b, _] = fin.triangles[0];
        fin.vertices.push(P3::new(3.0, 3.0, 3.0));
        fin.triangles.push([a, b, fin.vertices.len() as u32 - 1]);
        assert!(!fin.bounds_solid());
        assert!(cuboid(V3::new(1.0, 2.0, 3.0)).bounds_solid());
        assert!(!Mesh::new(Vec::new(), Vec::new()).bounds_solid());
    }

    #[test]
    fn shelf_is_closed_with_the_boxes_volume() {
        let (w, d, h, t) = (0.4, 0.25, 0.6, 0.018);
        let m = shelf(w, d, h, t, &[0.05, 0.3, 0.55]);
        assert!(m.is_closed());
        // By hand: two panels 0.018 x 0.25 x 0.6, three boards 0.364 x 0.24 x 0.018.
        let by_hand = 2.0 * 0.018 * 0.25 * 0.6 + 3.0 * 0.364 * 0.24 * 0.018;
        assert!((m.signed_volume() - by_hand).abs() < 1e-12);
        assert!((shelf_volume(w, d, h, t, 3) - by_hand).abs() < 1e-12);
        let b = m.aabb().unwrap();
        assert!((b.min.z).abs() < 1e-12 && (b.max.z - h).abs() < 1e-12);
        assert!((b.extents().x - w).abs() < 1e-12 && (b.extents().y - d).abs() < 1e-12);
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

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn revolve_exact_volume_and_closed() {
        // A hollow cylinder cup with a pole at the top of the cavity? Use a lens: poles on both
        // ends.
        let profile = [[0.0, 0.0], [1.0, 0.5], [1.0, 1.5], [0.0, 2.0]];
        let m = revolve(&profile, 24);
        assert!(m.is_closed());
        assert!((m.signed_volume() - revolved_volume(&profile, 24)).abs() < 1e-12);
        // Cone + cylinder + cone of radius 1 as a 24-gon: (1/3 + 1 + 1/3)·A
        let a = 12.0 * (2.0 * PI / 24.0).sin();
        assert!((m.signed_volume() - a * (0.5 / 3.0 + 1.0 + 0.5 / 3.0)).abs() < 1e-12);
    }

    #[test]
    fn bowl_volume_exact_and_converges() {
        let (r, h, w) = (0.08, 0.055, 0.004);
        let m = bowl(r, h, w, 48, 10);
        assert!(m.is_closed());
        assert_eq!(m.triangles.len(), 48 * (4 * 10 + 4));
        let exact = revolved_volume(&bowl_profile(r, h, w, 10), 48);
        assert!(
            rel(m.signed_volume(), exact) < 1e-12,
            "{} {exact}",
            m.signed_volume()
        );
        // Same polyhedron by the prismatoid formula over its rings.
        let rings = revolution_rings(&bowl_profile(r, h, w, 10), 48);
        let lv = loft_volume(&rings, P3::new(0.0, 0.0, 0.0), P3::new(0.0, 0.0, w));
        assert!(rel(lv, exact) < 1e-12);
        // Fine resolution → the smooth bowl.
        let smooth = bowl_smooth_volume(r, h, w);
        let fine = bowl(r, h, w, 512, 128).signed_volume();
        assert!(fine < smooth && rel(fine, smooth) < 2e-4, "{fine} {smooth}");
        let aabb = m.aabb().unwrap();
        assert!((aabb.min.z).abs() < 1e-15 && (aabb.max.z - h).abs() < 1e-15);
        assert!((aabb.max.x - r).abs() < 1e-15);
        let d = bowl_dims(r, h, w);
        assert_eq!(d.floor_z, w);
        assert_eq!(d.flat_radius, r / 2.0);
    }

    #[test]
    fn mug_volume_exact() {
        let (r, h, w, b, n) = (0.04, 0.095, 0.004, 0.006, 64);
        let m = mug(r, h, w, b, n);
        assert!(m.is_closed());
        assert_eq!(m.triangles.len(), 8 * n);
        let a = n as f64 / 2.0 * (2.0 * PI / n as f64).sin();
        let exact = a * (r * r * h - (r - w) * (r - w) * (h - b));
        assert!(rel(m.signed_volume(), exact) < 1e-12);
        assert!(rel(revolved_volume(&mug_profile(r, h, w, b), n), exact) < 1e-12);
        // The inner rim has a vertex on +x.
        assert!(m
            .vertices
            .iter()
            .any(|p| (p - P3::new(r - w, 0.0, h)).norm() < 1e-15));
    }

    #[test]
    fn tray_volume_exact() {
        let (ext, w, rim) = ([0.30, 0.20], 0.006, 0.02);
        let m = tray(ext, w, rim);
        assert!(m.is_closed());
        // Rounded rectangle with a 16-gon inscribed in the corner circle: core + sides + corners.
        let rr_area = |hx: f64, hy: f64, r: f64| {
            4.0 * hx * hy + 4.0 * r * (hx + hy) + 8.0 * r * r * (2.0 * PI / 16.0).sin()
        };
        let rc = 2.0 * w;
        let (hx, hy) = (ext[0] / 2.0 - rc, ext[1] / 2.0 - rc);
        let exact = rr_area(hx, hy, rc) * (w + rim) - rr_area(hx, hy, rc - w) * rim;
        assert!(
            rel(m.signed_volume(), exact) < 1e-12,
            "{} {exact}",
            m.signed_volume()
        );
        let (rings, s, e) = tray_rings(ext, w, rim);
        assert!(rel(loft_volume(&rings, s, e), exact) < 1e-12);
        let bb = m.aabb().unwrap();
        assert!((bb.extents() - V3::new(0.30, 0.20, w + rim)).norm() < 1e-15);
    }

    #[test]
    fn basket_volume_exact() {
        let (ext, h, w, inset, rc, seg) = ([0.30, 0.22], 0.08, 0.005, 0.02, 0.05, 8);
        let m = basket(ext, h, w, inset, rc, seg);
        assert!(m.is_closed());
        let (rings, s, e) = basket_rings(ext, h, w, inset, rc, seg);
        let v = loft_volume(&rings, s, e);
        assert!(rel(m.signed_volume(), v) < 1e-12);
        // Analytic: frustum-like prismatoids with a rounded-rectangle section whose corner radius
        // varies linearly: A(ρ) = 4·hx·hy + 4ρ(hx + hy) + k·ρ², k = polygon area factor.
        let (hx, hy) = (ext[0] / 2.0 - rc, ext[1] / 2.0 - rc);
        let k = 2.0 * seg as f64 * (PI / (2.0 * seg as f64)).sin();
        let area = |r: f64| 4.0 * hx * hy + 4.0 * r * (hx + hy) + k * r * r;
        // Exact integral of a quadratic in z over a linear radius: Simpson is exact.
        let slab = |r0: f64, r1: f64, dz: f64| {
            dz * (area(r0) + 4.0 * area((r0 + r1) / 2.0) + area(r1)) / 6.0
        };
        let wh = basket_wall_horizontal(h, w, inset);
        let fo = wh + inset * (1.0 - w / h);
        let exact = slab(rc - inset, rc, h) - slab(rc - fo, rc - wh, h - w);
        assert!(
            rel(m.signed_volume(), exact) < 1e-12,
            "{} {exact}",
            m.signed_volume()
        );
        // Normal wall thickness is `wall`: inner and outer wall lines are `w` apart.
        let slant = (inset / h).atan();
        assert!((wh * slant.cos() - w).abs() < 1e-15);
    }

    #[test]
    fn pen_and_fruit_volumes() {
        let p = pen(0.005, 0.14, 16);
        assert!(p.is_closed());
        let a = 8.0 * (2.0 * PI / 16.0).sin();
        let (r, tip) = (0.005, 0.015);
        let rt = 0.35 * r;
        let exact = a * (r * r * (0.14 - tip) + tip * (r * r + r * rt + rt * rt) / 3.0);
        assert!(
            rel(p.signed_volume(), exact) < 1e-12,
            "{} {exact}",
            p.signed_volume()
        );
        let f = fruit(0.04, 0.035, 0.01, 24, 12);
        assert!(f.is_closed());
        assert!(
            rel(
                f.signed_volume(),
                revolved_volume(&fruit_profile(0.04, 0.035, 0.01, 12), 24)
            ) < 1e-12
        );
        let bb = f.aabb().unwrap();
        assert_eq!(bb.min.z, 0.0);
        let fine = fruit(0.04, 0.035, 0.01, 512, 256).signed_volume();
        let smooth = fruit_smooth_volume(0.04, 0.035, 0.01);
        assert!(fine < smooth && rel(fine, smooth) < 1e-4, "{fine} {smooth}");
    }

    #[test]
    fn uvs_split_seams_and_textures_encode() {
        let m = mug(0.04, 0.1, 0.004, 0.006, 16);
        let (pos, uv, tri) = with_uvs(&m, UvProjection::Cylindrical { repeat: 1.0 });
        assert_eq!(tri.len(), m.triangles.len());
        assert_eq!(pos.len(), uv.len());
        // Seam vertices are duplicated, nothing else: 4 rings on the seam + poles stay single.
        assert!(pos.len() > m.vertices.len() && pos.len() < m.vertices.len() + 40);
        // Same geometry after welding; no triangle spans more than half the texture.
        let back = Mesh::new(pos.clone(), tri.clone()).welded(0.0);
        assert!(back.is_closed());
        assert!((back.signed_volume() - m.signed_volume()).abs() < 1e-15);
        for t in &tri {
            let us: Vec<f64> = t.iter().map(|&i| uv[i as usize][0]).collect();
            let span = us.iter().cloned().fold(f64::MIN, f64::max)
                - us.iter().cloned().fold(f64::MAX, f64::min);
            assert!(span <= 1.0 / 16.0 + 1e-12, "{span}");
        }
        let b = visual(
            &cuboid(V3::new(0.1, 0.2, 0.3)),
            UvProjection::Box { tile: 0.1 },
            Material::default(),
        );
        // Corners whose projections agree stay shared; every face keeps a non-degenerate map.
        let part = &b.parts[0];
        assert!(part.positions.len() > 8 && part.positions.len() <= 24);
        let uvb = part.uvs.as_ref().unwrap();
        for t in &part.triangles {
            let [a, b2, c] = t.map(|i| uvb[i as usize]);
            let area = (b2[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b2[1] - a[1]);
            assert!(area.abs() > 1e-6);
        }
        let t1 = checker_texture(64, 8, [200, 30, 30], [240, 240, 240], "checker");
        let t2 = checker_texture(64, 8, [200, 30, 30], [240, 240, 240], "checker");
        assert_eq!(t1, t2);
        assert!(t1.bytes.starts_with(b"\x89PNG\r\n\x1a\n"));
        let img = image::load_from_memory(&t1.bytes).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (64, 64));
        assert_eq!(img.get_pixel(0, 20).0, [200, 30, 30]);
        assert_eq!(img.get_pixel(8, 20).0, [240, 240, 240]);
    }
}
