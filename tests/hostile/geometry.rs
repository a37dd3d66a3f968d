//! Hostile inputs: Geometry.

use super::*;

#[test]
fn only_degenerate_triangles() {
    let t = tempfile::tempdir().unwrap();
    let d = obj_scene(
        t.path(),
        "flat",
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 0 0\nf 1 2 3\nf 1 4 2\n",
    );
    rejects(&d, "box.obj", "only degenerate (zero-area) triangles");
}

/// An open or non-manifold mesh is exported with a warning, its inertia from the hull union.
fn assert_falls_back(r: &Value) {
    let o = &r["objects"][0];
    assert_eq!(o["closed"], false, "{o}");
    assert_eq!(o["volume_source"], "hull_union", "{o}");
    assert!(o["mass"].as_f64().unwrap() > 0.0);
    assert!(
        o["warnings"]
            .to_string()
            .contains("mesh is not closed (a hole, a fin or a flipped triangle)"),
        "{o}"
    );
}

#[test]
fn open_mesh_warns_and_falls_back_to_the_hull_union() {
    let t = tempfile::tempdir().unwrap();
    // A sphere with one triangle missing.
    let mut m = interact3d::shapes::uv_sphere(0.05, 12, 24);
    m.triangles.remove(40);
    let d = obj_scene(t.path(), "hole", &obj_text(&m));
    let r = export_ok(&d, &t.path().join("out"));
    assert_falls_back(&r);
    let mass = r["objects"][0]["mass"].as_f64().unwrap();
    let closed = 1000.0
        * interact3d::shapes::uv_sphere(0.05, 12, 24)
            .signed_volume()
            .abs();
    // The scene-aware hulls of an open surface are shells along it, so the mass comes out low
    // (about a quarter of the closed sphere's): positive and below the closed mass is what holds.
    assert!(mass > 0.0 && mass < closed, "{mass} vs {closed}");
    // A box without its top face is a tray: walls only, far lighter than the full box.
    let mut m = cuboid(0.1, 0.2, 0.3);
    m.triangles.truncate(10);
    let d = obj_scene(t.path(), "tray", &obj_text(&m));
    let r = export_ok(&d, &t.path().join("out_tray"));
    assert_falls_back(&r);
    let mass = r["objects"][0]["mass"].as_f64().unwrap();
    assert!(mass > 0.0 && mass < 6.0, "{mass}");
}

#[test]
fn non_manifold_mesh_warns_and_falls_back_to_the_hull_union() {
    let t = tempfile::tempdir().unwrap();
    let m = cuboid(0.1, 0.2, 0.3);
    // A fin: a third triangle on an edge of the box (three faces share it).
    let mut s = obj_text(&m);
    let (a, b) = (m.triangles[0][0] + 1, m.triangles[0][1] + 1);
    s += &format!("v 0.3 0.3 0.3\nf {a} {b} 9\n");
    let d = obj_scene(t.path(), "fin", &s);
    let r = export_ok(&d, &t.path().join("out"));
    assert_falls_back(&r);
}

/// Scans carry a few edges where four triangles meet (the YCB bowl, mug and soup can, the GSO
/// teapot): closed all the same, so their mass properties come from the mesh, not from the
/// hull union (which held 3.5 times the YCB bowl's volume). Two 10 cm cubes meeting along an
/// edge: 2 kg at 1000 kg/m³, and about their centre of mass (by the parallel-axis theorem,
/// each cube's centre a/√2 from the edge's axis) I_zz = 4/3·m·a², I_xx = I_yy = 5/6·m·a²,
/// |I_xy| = m·a²/2 for m = 1 kg per cube.
#[test]
fn closed_mesh_with_edges_shared_by_four_triangles_has_exact_mass_properties() {
    let t = tempfile::tempdir().unwrap();
    let a = 0.1;
    let d = obj_scene(
        t.path(),
        "cubes",
        &obj_text(&interact3d::shapes::cubes_on_an_edge(a)),
    );
    let r = export_ok(&d, &t.path().join("out"));
    let o = &r["objects"][0];
    assert_eq!(o["closed"], true, "{o}");
    assert_eq!(o["volume_source"], "closed_mesh", "{o}");
    assert!(!o["warnings"].to_string().contains("not closed"), "{o}");
    let close =
        |x: &Value, want: f64| (x.as_f64().unwrap() - want).abs() <= 1e-9 * want.abs().max(1e-3);
    assert!(close(&o["mass"], 2.0), "{o}");
    let i = &o["inertia"];
    assert!(close(&i[2][2], 4.0 / 3.0 * a * a), "{i}");
    assert!(close(&i[0][0], 5.0 / 6.0 * a * a), "{i}");
    assert!(close(&i[1][1], 5.0 / 6.0 * a * a), "{i}");
    assert!(
        (i[0][1].as_f64().unwrap().abs() - 0.5 * a * a).abs() <= 1e-11,
        "{i}"
    );
    assert!(i[0][2].as_f64().unwrap().abs() <= 1e-11, "{i}");
}

#[test]
fn tiny_object_is_refused_with_a_clear_message() {
    let t = tempfile::tempdir().unwrap();
    // A 0.1 mm cube: thinner than the thinnest collision hull kept.
    let d = obj_scene(t.path(), "tiny", &obj_text(&cuboid(1e-4, 1e-4, 1e-4)));
    rejects(
        &d,
        "scene.json",
        "object box is too small or too thin to simulate: its smallest extent is 1.000e-4 m",
    );
    // A 0.4 mm cube has hulls, but MuJoCo refuses its inertia (eigenvalues under 1e-14).
    let d = obj_scene(t.path(), "light", &obj_text(&cuboid(4e-4, 4e-4, 4e-4)));
    rejects(
        &d,
        "scene.json",
        "object box is too small or too light to simulate: mass 6.400e-8 kg",
    );
}

#[test]
fn small_object_above_the_limits_loads_in_mujoco() {
    let t = tempfile::tempdir().unwrap();
    // 0.7 mm and 1 mm cubes: exported, and MuJoCo compiles and steps them.
    for (case, s) in [("c07", 7e-4), ("c10", 1e-3)] {
        let d = obj_scene(t.path(), case, &obj_text(&cuboid(s, s, s)));
        let out = t.path().join(case).join("out");
        export_ok(&d, &out);
        if !python_or_skip("hostile::small_object_above_the_limits_loads_in_mujoco (MuJoCo part)") {
            continue;
        }
        let mj = python_json("check_mujoco.py", &[out.to_str().unwrap()]);
        assert_eq!(mj["nbody"], 2, "{mj}");
        assert_eq!(mj["finite"], true, "{mj}");
    }
}

#[test]
fn huge_object_exports_with_a_warning() {
    let t = tempfile::tempdir().unwrap();
    let d = obj_scene(t.path(), "huge", &obj_text(&cuboid(500.0, 400.0, 300.0)));
    let r = export_ok(&d, &t.path().join("out"));
    assert!(r["warnings"].to_string().contains("scene is huge"), "{r}");
    let mass = r["objects"][0]["mass"].as_f64().unwrap();
    assert!((mass / (1000.0 * 500.0 * 400.0 * 300.0) - 1.0).abs() < 1e-9);
}
