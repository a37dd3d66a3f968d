//! How close can 32 convex hulls that cover a bowl come to its surface? An estimate from the
//! curvature of the bowl fixture's inner wall, beside what the scene-aware engine achieves.
//!
//! ```text
//! cargo run --release --example tiling_bound                 # budgets 32, 40, 48, 64
//! cargo run --release --example tiling_bound -- 24 32 96
//! ```
//!
//! A convex hull that covers a patch of a surface curving away from it (the inside of a bowl)
//! spans the patch with a lid that bulges into the cavity. For a patch small against the radii
//! of curvature (principal curvatures κ₁, κ₂), the shallowest lid over a patch of area A is a
//! plane over an ellipse with κ₁a² = κ₂b², whose depth at the centre is s = A·√K / 2π
//! (K = κ₁κ₂), falling as s·(1 − ρ²) towards the rim (ρ the elliptic radius), so a fraction
//! 1 − t/s of it lies farther than t from the surface. Patches must tile the wall: hexagons
//! tile best, and the ellipse around a hexagon is 2π/(3√3) = 1.209 times its area. So keeping
//! every point of the wall within t takes N(t) = c·∫√K dA / (2π·t) patches: c = 1 for discs
//! (a lower bound: discs do not tile), 1.209 for a perfect hexagonal tiling. The 95th
//! percentile lets 5 % of the surface lie farther: spending that on the wall where √K is
//! largest saves the most patches (free, in this count, so that bound is lower still). The
//! flat floor takes one hull; the outer wall is convex, its chords lie inside the 4 mm wall.
//! Solving N(t) = budget − 1 for t gives the closest a covering decomposition can come, in % of
//! the bounding-box diagonal, to compare with the engine's p95 on the same mesh.

use interact3d::decompose::scene_aware::{decompose_scene, geom::Surface, metrics};
use interact3d::decompose::DecomposeOptions;
use std::f64::consts::PI;

/// The fixture bowl (`fixtures/ball_bowl`, object_a): `shapes::bowl(R, H, wall, 64, 12)`.
const R: f64 = 0.08;
const H: f64 = 0.055;
const WALL: f64 = 0.004;

/// Samples along the inner wall's quarter ellipse: (√K, area) of each band, largest √K first.
fn inner_wall(steps: usize) -> Vec<(f64, f64)> {
    // Inner wall: ρ = R/2 + a·sin θ, z = H − c·cos θ, θ ∈ [0, π/2] (see `shapes::bowl_profile`).
    let (rf, a, c) = (R / 2.0, R / 2.0 - WALL, H - WALL);
    let dth = PI / 2.0 / steps as f64;
    let mut wall: Vec<(f64, f64)> = (0..steps)
        .map(|i| {
            let th = (i as f64 + 0.5) * dth;
            let rho = rf + a * th.sin();
            let (r1, z1) = (a * th.cos(), c * th.sin());
            let (r2, z2) = (-a * th.sin(), c * th.cos());
            let speed = (r1 * r1 + z1 * z1).sqrt();
            let k_meridian = (r1 * z2 - z1 * r2).abs() / speed.powi(3);
            let k_hoop = z1 / (rho * speed);
            ((k_meridian * k_hoop).sqrt(), 2.0 * PI * rho * speed * dth)
        })
        .collect();
    wall.sort_by(|x, y| y.0.total_cmp(&x.0));
    wall
}

/// Patches needed to keep the wall (from [`inner_wall`]) within `t` (m), tiling factor `c`,
/// leaving out the area `give_up` where √K is largest.
fn patches(wall: &[(f64, f64)], t: f64, c: f64, give_up: f64) -> f64 {
    let mut left = give_up;
    let mut integral = 0.0;
    for &(k, a) in wall {
        let skip = left.min(a);
        left -= skip;
        integral += k * (a - skip);
    }
    c * integral / (2.0 * PI * t)
}

/// The `t` at which `patches` equals `n` (bisection; `patches` falls as 1/t).
fn reach(wall: &[(f64, f64)], n: f64, c: f64, give_up: f64) -> f64 {
    let (mut lo, mut hi) = (1e-7f64, 1.0f64);
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        if patches(wall, mid, c, give_up) > n {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

fn main() {
    let budgets: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("budgets are whole numbers"))
        .collect();
    let budgets = if budgets.is_empty() {
        vec![32, 40, 48, 64]
    } else {
        budgets
    };
    // The bowl as the bench and the export see it: loaded from the fixture and prepared (metres,
    // Z-up, on the ground), decomposed alone.
    let fixture = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/ball_bowl");
    let scene = interact3d::scene::load(&fixture, &interact3d::io::Limits::default())
        .expect("fixtures/ball_bowl loads");
    let prepared = interact3d::prepare::prepare(&scene, &Default::default()).expect("it prepares");
    let mesh = prepared.objects[0].geometry.clone();
    let extents = mesh.aabb().expect("the bowl has vertices").extents();
    assert!(
        (extents.x - 2.0 * R).abs() < 1e-3 && (extents.z - H).abs() < 1e-6,
        "object_a of fixtures/ball_bowl is not shapes::bowl({R}, {H}, {WALL}, ..): {extents:?}"
    );
    let surface = Surface::new(&mesh).expect("the bowl has triangles");
    let diag = surface.diag;
    let wall = inner_wall(20_000);
    let wall_area: f64 = wall.iter().map(|w| w.1).sum();
    let area = mesh.area();
    let give_up = 0.05 * area;
    let integral: f64 = wall.iter().map(|w| w.0 * w.1).sum();
    // The ellipse around a regular hexagon, per unit of the hexagon's area.
    let hex = 2.0 * PI / (3.0 * 3f64.sqrt());
    println!(
        "bowl fixture: diagonal {:.1} mm, surface {:.1} cm², inner wall {:.1} cm² (∫√K dA = {:.3}; a hemisphere's is 2π)",
        diag * 1e3,
        area * 1e4,
        wall_area * 1e4,
        integral
    );
    println!("every patch within t, t in % of the diagonal; p95 lets the 5 % of the surface where √K is largest go");
    println!(
        "| hulls | discs, p95 | hexagons, p95 | hexagons, all | engine p95 |\n|---:|---:|---:|---:|---:|"
    );
    for b in budgets {
        let n = b.saturating_sub(1).max(1) as f64;
        let pct = |t: f64| t / diag * 100.0;
        let opts = DecomposeOptions {
            max_hulls: b,
            ..DecomposeOptions::default()
        };
        let (hulls, _) = decompose_scene(&[&mesh], &opts);
        let (_, p95, _) = metrics::stats(&metrics::surface_distances(&surface, &hulls[0], 20_000));
        println!(
            "| {b} | {:.2} % | {:.2} % | {:.2} % | {:.2} % |",
            pct(reach(&wall, n, 1.0, give_up)),
            pct(reach(&wall, n, hex, give_up)),
            pct(reach(&wall, n, hex, 0.0)),
            p95 * 100.0
        );
    }
}
