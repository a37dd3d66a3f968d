//! Planted defects, one a file with a clean twin: file, inertia, geometry, contact and physics
//! checks, each against MuJoCo's own verdict where it has one; primitive contact depths exact.

use super::*;

#[test]
fn file_checks_fire_with_the_line_and_their_twins_do_not() {
    let t = tempfile::tempdir().unwrap();
    let good = urdf(
        &inertial(0.5, box_inertia(0.5, [0.1, 0.1, 0.1]), [0.0; 3]),
        "<box size=\"0.1 0.1 0.1\"/>",
        "<box size=\"0.1 0.1 0.1\"/>",
    );
    let r = check(&write(t.path(), "good.urdf", &good));
    assert!(r.findings.is_empty(), "{:#?}", r.findings);
    // Broken XML: the error names the line of the tag left open.
    let bad = good.replace("</link>", "");
    let r = check(&write(t.path(), "bad.urdf", &bad));
    let f = find(&r, "file.parse_error");
    assert_eq!(f.len(), 1, "{:?}", ids(&r));
    assert!(f[0].line >= 3, "line {}: {}", f[0].line, f[0].message);
    // A missing mesh: the <mesh> line.
    let missing = urdf(
        &inertial(0.5, box_inertia(0.5, [0.1, 0.1, 0.1]), [0.0; 3]),
        "<box size=\"0.1 0.1 0.1\"/>",
        "<mesh filename=\"nowhere.obj\"/>",
    );
    let r = check(&write(t.path(), "missing.urdf", &missing));
    let f = find(&r, "file.mesh_missing");
    assert_eq!(f.len(), 1, "{:?}", ids(&r));
    assert_eq!(f[0].line, 10);
    // The twin with the mesh present (package:// through --package).
    let pkg = urdf(
        &inertial(0.068, [4.1e-5, 4.1e-5, 4.2e-5], [0.0; 3]),
        &format!("<mesh filename=\"file://{}\"/>", apple()),
        "<mesh filename=\"package://ycbpkg/textured.obj\"/>",
    );
    let p = write(t.path(), "pkg.urdf", &pkg);
    let r = check(&p);
    assert_eq!(find(&r, "file.mesh_missing").len(), 1);
    let mut o = AssetCheckOptions::default();
    o.read.packages = vec![(
        "ycbpkg".into(),
        Path::new(&apple()).parent().unwrap().to_path_buf(),
    )];
    let r = check_path(&p, "pkg.urdf", &o);
    assert!(
        find(&r, "file.mesh_missing").is_empty(),
        "{:#?}",
        r.findings
    );
}

#[test]
fn inertia_checks() {
    let t = tempfile::tempdir().unwrap();
    let e = [0.1, 0.06, 0.04];
    let geo = format!("<box size=\"{} {} {}\"/>", e[0], e[1], e[2]);
    let case = |name: &str, mass: f64, i: [f64; 3], com: [f64; 3]| {
        check(&write(
            t.path(),
            name,
            &urdf(&inertial(mass, i, com), &geo, &geo),
        ))
    };
    let exact = box_inertia(0.3, e);
    let clean = case("clean.urdf", 0.3, exact, [0.0; 3]);
    assert!(clean.findings.is_empty(), "{:#?}", clean.findings);
    // Triangle inequality broken: 1 + 1 < 3.
    let r = case("tri.urdf", 0.3, [1e-4, 1e-4, 3e-4], [0.0; 3]);
    let f = find(&r, "inertia.triangle_inequality");
    assert_eq!(f.len(), 1, "{:?}", ids(&r));
    assert!((f[0].value.unwrap() - 1e-4).abs() < 1e-12);
    assert_eq!(f[0].line, 4, "line of <inertial>");
    // Not positive definite.
    let r = case("neg.urdf", 0.3, [-1e-4, 1e-4, 1e-4], [0.0; 3]);
    assert_eq!(
        find(&r, "inertia.positive_definite").len(),
        1,
        "{:?}",
        ids(&r)
    );
    // Placeholder: 100x the exact moments; its twin at the exact ones is clean (above).
    let r = case("ph.urdf", 0.3, exact.map(|x| x * 100.0), [0.0; 3]);
    let f = find(&r, "inertia.placeholder");
    assert_eq!(f.len(), 1, "{:?}", ids(&r));
    assert!(
        (f[0].value.unwrap() - 100.0).abs() < 1e-6,
        "{:?}",
        f[0].value
    );
    // Mass in grams: 300 "kg" in 2.4e-4 m³.
    let r = case("grams.urdf", 300.0, box_inertia(300.0, e), [0.0; 3]);
    let f = find(&r, "inertia.density");
    assert_eq!(f.len(), 1, "{:?}", ids(&r));
    let density = 300.0 / (e[0] * e[1] * e[2]);
    assert!((f[0].value.unwrap() - density).abs() / density < 1e-9);
    // Centre of mass 10 cm off a 10 cm box.
    let r = case("com.urdf", 0.3, exact, [0.0, 0.0, 0.12]);
    let f = find(&r, "inertia.com_outside");
    assert_eq!(f.len(), 1, "{:?}", ids(&r));
    assert!((f[0].value.unwrap() - 0.1).abs() < 1e-9, "{:?}", f[0].value);
}

#[test]
fn geometry_checks() {
    let t = tempfile::tempdir().unwrap();
    let apple = apple();
    let ine = inertial(0.068, [4.1e-5, 4.2e-5, 4.2e-5], [0.0; 3]);
    // A mesh in millimetres (scale 1000): 75 m long.
    let mm = urdf(
        &ine,
        &format!("<mesh filename=\"{apple}\" scale=\"1000 1000 1000\"/>"),
        &format!("<mesh filename=\"{apple}\" scale=\"1000 1000 1000\"/>"),
    );
    let r = check(&write(t.path(), "mm.urdf", &mm));
    let f = find(&r, "geometry.size");
    assert_eq!(f.len(), 1, "{:?}", ids(&r));
    assert!(f[0].value.unwrap() > 50.0);
    // The twin in metres: no size finding, but the scan's hull is far over the GPU limit.
    let m = urdf(
        &ine,
        &format!("<mesh filename=\"{apple}\"/>"),
        &format!("<mesh filename=\"{apple}\"/>"),
    );
    let r = check(&write(t.path(), "m.urdf", &m));
    assert!(find(&r, "geometry.size").is_empty(), "{:#?}", r.findings);
    assert_eq!(
        find(&r, "geometry.gpu_hull_limit").len(),
        1,
        "{:?}",
        ids(&r)
    );
    // GPU twin: a box mesh of 8 vertices and 6 polygons.
    let cube = write(
        t.path(),
        "cube.obj",
        &format!("o c\n{}", box_obj([0.03; 3])),
    );
    let cm = urdf(
        &inertial(0.2, box_inertia(0.2, [0.06; 3]), [0.0; 3]),
        "<mesh filename=\"cube.obj\"/>",
        "<mesh filename=\"cube.obj\"/>",
    );
    let r = check(&write(t.path(), "cube.urdf", &cm));
    assert!(r.findings.is_empty(), "{:#?}", r.findings);
    let _ = cube;
    // Visual and collision disagree: collision box twice the visual cube.
    let vc = urdf(
        &inertial(0.2, box_inertia(0.2, [0.12; 3]), [0.0; 3]),
        "<mesh filename=\"cube.obj\"/>",
        "<box size=\"0.12 0.12 0.12\"/>",
    );
    let r = check(&write(t.path(), "vc.urdf", &vc));
    let f = find(&r, "geometry.visual_collision_mismatch");
    assert_eq!(f.len(), 1, "{:?}", ids(&r));
    // 3 cm of 6√3 = 10.39 cm diagonal.
    assert!(
        (f[0].value.unwrap() - 0.03 / (0.06 * 3f64.sqrt())).abs() < 1e-9,
        "{:?}",
        f[0].value
    );
}

#[test]
fn concave_hull_with_a_body_inside_and_mujoco_agrees() {
    let t = tempfile::tempdir().unwrap();
    let inside = mug_scene(t.path(), "inside", true);
    let r = check(&inside);
    assert_eq!(
        find(&r, "geometry.concave_collision").len(),
        1,
        "{:?}",
        ids(&r)
    );
    let f = find(&r, "geometry.hull_inside_body");
    assert_eq!(f.len(), 1, "{:?}", ids(&r));
    assert_eq!(f[0].line, 9, "line of the mug's geom");
    let pen = find(&r, "contact.penetration");
    assert_eq!(pen.len(), 1, "{:?}", ids(&r));
    // MuJoCo collides the hull: the same deep contact after mj_forward.
    let mj = python_json("check_asset_mujoco.py", &[inside.to_str().unwrap()]);
    assert_eq!(mj["loads"], true);
    let theirs = mj["body_penetration"].as_f64().unwrap();
    let ours = pen[0].value.unwrap();
    assert!(
        (ours - theirs).abs() < 1e-3 + 0.05 * theirs,
        "depth ours {ours} MuJoCo {theirs}"
    );
    // Beside the mug: the hull is still concave, nobody is inside it, and nothing penetrates.
    let beside = mug_scene(t.path(), "beside", false);
    let r = check(&beside);
    assert_eq!(
        find(&r, "geometry.concave_collision").len(),
        1,
        "{:?}",
        ids(&r)
    );
    assert!(
        find(&r, "geometry.hull_inside_body").is_empty(),
        "{:#?}",
        r.findings
    );
    assert!(
        find(&r, "contact.penetration").is_empty(),
        "{:#?}",
        r.findings
    );
    let mj = python_json("check_asset_mujoco.py", &[beside.to_str().unwrap()]);
    assert!(mj["body_penetration"].as_f64().unwrap() < 1e-3, "{mj}");
    // The ball rests beside the mug, in both.
    assert!(
        r.findings.iter().all(|f| !f.check.starts_with("physics")),
        "{:#?}",
        r.findings
    );
    assert!(
        mj["motion"]["ball"]["moved"].as_f64().unwrap() < 1e-3,
        "{mj}"
    );
}

#[test]
fn contact_and_physics_checks_agree_with_mujoco() {
    let t = tempfile::tempdir().unwrap();
    // Clean: a box on the floor, a tall bar standing upright away from it.
    let clean = boxes(t.path(), "clean", 0.01, 0.0, 0.0);
    let r = check(&clean);
    assert!(r.findings.is_empty(), "{:#?}", r.findings);
    let mj = python_json("check_asset_mujoco.py", &[clean.to_str().unwrap()]);
    for b in ["a", "b"] {
        assert!(mj["motion"][b]["moved"].as_f64().unwrap() < 1e-3, "{mj}");
    }
    // The box 4 mm through the floor: ours and MuJoCo's depth.
    let sunk = boxes(t.path(), "sunk", 0.01, 0.004, 0.0);
    let r = check(&sunk);
    let f = find(&r, "contact.floor");
    assert_eq!(f.len(), 1, "{:?}", ids(&r));
    assert!(
        (f[0].value.unwrap() - 0.004).abs() < 1e-9,
        "{:?}",
        f[0].value
    );
    assert_eq!(f[0].line, 4);
    let mj = python_json("check_asset_mujoco.py", &[sunk.to_str().unwrap()]);
    assert!(
        (mj["floor_penetration"].as_f64().unwrap() - 0.004).abs() < 2e-4,
        "{mj}"
    );
    // The bar tilted 40° on its edge falls over: settle fails here and MuJoCo moves it too.
    let tilt = boxes(t.path(), "tilt", 0.01, 0.0, 40.0);
    let r = check(&tilt);
    let f = find(&r, "physics.settle");
    assert_eq!(f.len(), 1, "{:#?}", r.findings);
    assert_eq!(f[0].subject, "b");
    let mj = python_json("check_asset_mujoco.py", &[tilt.to_str().unwrap()]);
    assert!(
        mj["motion"]["b"]["turned_deg"].as_f64().unwrap() > 30.0,
        "{mj}"
    );
    assert!(mj["motion"]["a"]["moved"].as_f64().unwrap() < 1e-3, "{mj}");
}

#[test]
fn mujoco_refuses_what_we_call_an_error() {
    let t = tempfile::tempdir().unwrap();
    let body = |inertia: &str| {
        format!(
            "<mujoco>\n  <worldbody>\n    <body name=\"b\" pos=\"0 0 0.05\">\n      <freejoint/>\n      <inertial pos=\"0 0 0\" mass=\"0.5\" diaginertia=\"{inertia}\"/>\n      <geom type=\"box\" size=\"0.05 0.05 0.05\"/>\n    </body>\n  </worldbody>\n</mujoco>\n"
        )
    };
    let good_i = 0.5 * 0.01 / 6.0;
    for (name, inertia, refused) in [
        ("ok", format!("{good_i} {good_i} {good_i}"), false),
        ("tri", "1e-4 1e-4 3e-4".to_string(), true),
    ] {
        let p = write(t.path(), &format!("{name}.xml"), &body(&inertia));
        let r = check(&p);
        let ours = !find(&r, "inertia.triangle_inequality").is_empty();
        let mj = python_json("check_asset_mujoco.py", &[p.to_str().unwrap()]);
        assert_eq!(ours, refused, "{name}: {:#?}", r.findings);
        assert_eq!(mj["loads"].as_bool().unwrap(), !refused, "{name}: {mj}");
        if refused {
            assert_eq!(find(&r, "inertia.triangle_inequality")[0].line, 5);
        }
    }
}

#[test]
fn primitive_contact_depths_are_exact_not_tessellated() {
    // A sphere turned so no tessellation vertex is lowest, its centre h = 47 mm above the floor
    // (r = 50 mm): depth r − h = 3 mm. Two spheres (30 mm, 20 mm) whose centres are
    // r1 + r2 − d apart along (1,2,2)/3, d = 2 mm: depth d. A 16×32 sphere read 2.907 and 1.678 mm.
    let t = tempfile::tempdir().unwrap();
    let (d, k) = (0.002, 0.048 / 3.0);
    let xml = format!(
        r#"<mujoco model="spheres">
  <worldbody>
    <geom name="floor" type="plane" size="1 1 0.1"/>
    <body name="sunk" pos="0.3 0 0.047">
      <freejoint/>
      <geom type="sphere" size="0.05" euler="13 7 29" density="500"/>
    </body>
    <body name="p" pos="-0.3 0 0.2">
      <freejoint/>
      <geom type="sphere" size="0.03" density="500"/>
    </body>
    <body name="q" pos="{} {} {}">
      <freejoint/>
      <geom type="sphere" size="0.02" euler="31 -11 5" density="500"/>
    </body>
  </worldbody>
</mujoco>
"#,
        -0.3 + k,
        2.0 * k,
        0.2 + 2.0 * k
    );
    let p = write(t.path(), "spheres.xml", &xml);
    let r = check(&p);
    let f = find(&r, "contact.floor");
    assert_eq!(f.len(), 1, "{:#?}", r.findings);
    assert_eq!(f[0].subject, "sunk");
    assert!(
        (f[0].value.unwrap() - 0.003).abs() < 1e-9,
        "{:?}",
        f[0].value
    );
    let f = find(&r, "contact.penetration");
    assert_eq!(f.len(), 1, "{:#?}", r.findings);
    assert_eq!(f[0].subject, "p/q");
    assert!((f[0].value.unwrap() - d).abs() < 1e-9, "{:?}", f[0].value);
}
