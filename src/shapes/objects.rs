//! Everyday objects for the fixtures, each with its exact volume: bowl, mug, shelf, tray,
//! basket, pen and fruit.
//!
//! Entry points: [`bowl`], [`mug`], [`shelf`], [`tray`], [`basket`], [`pen`], [`fruit`] and
//! their `*_profile`, `*_rings` and `*_volume` companions.

use super::solids::cuboid;
use super::solids::{loft, revolve};
use crate::mesh::{Mesh, P3, V3};
use std::f64::consts::PI;

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
