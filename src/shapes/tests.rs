use super::*;
use crate::mesh::{Material, Mesh, P3, V3};
use std::f64::consts::PI;

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
    let slab =
        |r0: f64, r1: f64, dz: f64| dz * (area(r0) + 4.0 * area((r0 + r1) / 2.0) + area(r1)) / 6.0;
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
