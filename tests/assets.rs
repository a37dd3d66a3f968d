//! `validate` on URDF and MJCF assets written by others: real pybullet_data files, planted
//! defects (one defect per file, each with a clean twin) around ../shared meshes, MuJoCo's own
//! verdict on the MJCF cases, our own exports read back, and the CI outputs.
//! Needs Python with `pybullet` (for pybullet_data) and `mujoco` (tests/python/requirements.txt).

#[path = "asset_cases/mod.rs"]
mod cases;
mod common;
use cases::*;
use common::*;
use interact3d::validate::asset::{check_path, AssetCheckOptions};
use std::path::Path;

#[test]
fn pybullet_data_real_files() {
    let d = pybullet_data();
    // The duck, the teddy and the small cube: 0.1 kg with I = 1 kg·m² (a placeholder).
    for f in ["duck_vhacd.urdf", "teddy_vhacd.urdf", "cube_small.urdf"] {
        let r = check(&d.join(f));
        let p = find(&r, "inertia.placeholder");
        assert_eq!(p.len(), 1, "{f}: {:?}", ids(&r));
        assert!(p[0].value.unwrap() > 1e3, "{f}: ratio {:?}", p[0].value);
        assert_eq!(
            p[0].line,
            10.min(p[0].line.max(8)),
            "{f}: line of <inertial>"
        );
        // Errors: only the duck's settle. Its mesh is Y-up and the URDF does not turn it, so it
        // lies on its side; with the inertia its shape implies it rolls over by 90° (so does
        // PyBullet with the same moments: tests/asset_judges.rs).
        assert!(
            r.findings.iter().all(
                |x| x.severity < interact3d::validate::finding::Severity::Error
                    || (f == "duck_vhacd.urdf" && x.check == "physics.settle")
            ),
            "{f}: {:#?}",
            r.findings
        );
    }
    // cube_small: the implied moment is the analytic one of a 5 cm, 0.1 kg cube, m a²/6.
    let r = check(&d.join("cube_small.urdf"));
    let ratio = find(&r, "inertia.placeholder")[0].value.unwrap();
    let exact = 0.1 * 0.05 * 0.05 / 6.0;
    assert!(
        (ratio - 1.0 / exact).abs() / (1.0 / exact) < 1e-6,
        "ratio {ratio} vs {}",
        1.0 / exact
    );
    // sphere2: 10 kg, r 0.5 m, I = 1 = 2/5 m r²: the same number is right here (clean twin).
    let r = check(&d.join("sphere2.urdf"));
    assert!(find(&r, "inertia.placeholder").is_empty(), "{:?}", ids(&r));
    assert!(r.findings.is_empty(), "{:#?}", r.findings);
    // The tray: mass 0, static; five boxes; nothing wrong.
    let r = check(&d.join("tray/traybox.urdf"));
    assert_eq!(r.bodies, 1);
    assert!(
        r.findings.iter().all(|f| f.check == "physics.skipped"),
        "{:#?}",
        r.findings
    );
    // The duck's V-HACD OBJ has its hulls as separate objects: each is its own convex piece.
    let a = interact3d::io::asset::load(&d.join("duck_vhacd.urdf"), &Default::default()).unwrap();
    let coll = a.bodies[0].geoms.iter().find(|g| g.collision).unwrap();
    let pieces = coll.shape.meshes().len();
    let objects = std::fs::read_to_string(d.join("duck_vhacd.obj"))
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("o ") || l.starts_with("g "))
        .count();
    assert!(
        pieces > 1 && pieces <= objects,
        "{pieces} pieces, {objects} o/g lines"
    );
}

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
fn mjcf_reader_features() {
    let t = tempfile::tempdir().unwrap();
    // Defaults with childclass, degrees, eulerseq, include, keyframe, a welded child.
    write(t.path(), "part.xml", "<mujocoinclude>\n  <body name=\"inc\" pos=\"0.3 0 0.02\">\n    <freejoint/>\n    <geom type=\"sphere\" size=\"0.02\"/>\n  </body>\n</mujocoinclude>\n");
    let xml = r#"<mujoco>
  <compiler eulerseq="zyx"/>
  <default>
    <default class="big">
      <geom type="box" size="0.05 0.05 0.05" density="200"/>
    </default>
  </default>
  <worldbody>
    <body name="a" pos="0 0 0.05" euler="90 0 0" childclass="big">
      <freejoint/>
      <geom/>
      <body name="welded" pos="0 0 0.1">
        <geom type="capsule" fromto="0 0 0 0 0 0.1" size="0.01"/>
      </body>
    </body>
    <include file="part.xml"/>
  </worldbody>
  <keyframe>
    <key qpos="0 0 0.05 1 0 0 0  0.3 0.1 0.02 1 0 0 0"/>
  </keyframe>
</mujoco>
"#;
    let p = write(t.path(), "m.xml", xml);
    let a = interact3d::io::asset::load(&p, &Default::default()).unwrap();
    assert_eq!(a.bodies.len(), 2);
    let b = &a.bodies[0];
    assert_eq!(b.merged, vec!["welded".to_string()]);
    // Box from the class, 0.1 m side at 200 kg/m³ = 0.2 kg; capsule r 1 cm, 10 cm long.
    let i = b.effective_inertial().unwrap();
    let cap = 200.0 * (std::f64::consts::PI * 1e-4 * 0.1 + 4.0 / 3.0 * std::f64::consts::PI * 1e-6);
    let tess = 0.01; // tessellated primitives: within 1%
    assert!(
        (i.mass - (0.2 + cap)).abs() / (0.2 + cap) < tess,
        "mass {}",
        i.mass
    );
    // The key frame moved the included body.
    assert!((a.bodies[1].pose.translation.y - 0.1).abs() < 1e-12);
    assert_eq!(a.bodies[1].src.line, 2, "line in the included file");
    assert!(a.bodies[1].src.file.ends_with("part.xml"));
    // euler 90° about z (first of zyx) in degrees, as MuJoCo reads it: the keyframe resets it.
    let a2 = interact3d::io::asset::load(&write(t.path(), "n.xml", &xml.replace("<keyframe>\n    <key qpos=\"0 0 0.05 1 0 0 0  0.3 0.1 0.02 1 0 0 0\"/>\n  </keyframe>\n", "")), &Default::default()).unwrap();
    let ang = a2.bodies[0].pose.rotation.angle().to_degrees();
    let axis = a2.bodies[0].pose.rotation.axis().unwrap();
    assert!(
        (ang - 90.0).abs() < 1e-9 && (axis.z - 1.0).abs() < 1e-9,
        "{ang} {axis:?}"
    );
}

#[test]
fn articulated_urdf_is_one_finding_fixed_joints_merge() {
    let t = tempfile::tempdir().unwrap();
    let robot = |ty: &str| {
        format!(
            "<robot name=\"r\">\n  <link name=\"base\">\n    <inertial><mass value=\"1\"/><inertia ixx=\"1.6667e-3\" iyy=\"1.6667e-3\" izz=\"1.6667e-3\"/></inertial>\n    <collision><geometry><box size=\"0.1 0.1 0.1\"/></geometry></collision>\n  </link>\n  <link name=\"top\">\n    <inertial><mass value=\"1\"/><inertia ixx=\"1.6667e-3\" iyy=\"1.6667e-3\" izz=\"1.6667e-3\"/></inertial>\n    <collision><geometry><box size=\"0.1 0.1 0.1\"/></geometry></collision>\n  </link>\n  <joint name=\"j\" type=\"{ty}\">\n    <parent link=\"base\"/><child link=\"top\"/><origin xyz=\"0 0 0.1\"/>\n    <axis xyz=\"0 0 1\"/>\n  </joint>\n</robot>\n"
        )
    };
    let r = check(&write(t.path(), "rev.urdf", &robot("revolute")));
    let f = find(&r, "asset.articulated");
    assert_eq!(f.len(), 1, "{:?}", ids(&r));
    assert_eq!(f[0].line, 10);
    let p = write(t.path(), "fix.urdf", &robot("fixed"));
    let r = check(&p);
    assert!(r.findings.is_empty(), "{:#?}", r.findings);
    // Merged: 2 kg, centre of mass 5 cm up, Ixx = 2 (1/6 of 0.01) + 2 (0.05²) by parallel axes.
    let a = interact3d::io::asset::load(&p, &Default::default()).unwrap();
    let i = a.bodies[0].inertial.as_ref().unwrap();
    assert!((i.mass - 2.0).abs() < 1e-12 && (i.com.z - 0.05).abs() < 1e-12);
    assert!((i.inertia[(0, 0)] - (2.0 * 1.6667e-3 + 2.0 * 0.0025)).abs() < 1e-12);
}

#[test]
fn our_export_reads_back_as_the_same_bodies() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out");
    export(&root().join("fixtures/ball_bowl"), &out, &["--no-validate"]);
    let folder = interact3d::export::read::load(&out, &Default::default()).unwrap();
    let mj = interact3d::io::asset::load(&out.join("scene.xml"), &Default::default()).unwrap();
    assert_eq!(mj.bodies.len(), folder.bodies.len());
    assert!(mj.floor.is_some());
    for fb in &folder.bodies {
        let b = mj.bodies.iter().find(|b| b.name == fb.name).unwrap();
        let urdf = interact3d::io::asset::load(
            &out.join(format!("{}.urdf", fb.name)),
            &Default::default(),
        )
        .unwrap();
        let ub = &urdf.bodies[0];
        let i = b.inertial.as_ref().unwrap();
        let ui = ub.inertial.as_ref().unwrap();
        for x in [i, ui] {
            assert!(
                (x.mass - fb.inertial.mass).abs() / fb.inertial.mass < 1e-9,
                "{}",
                fb.name
            );
            assert!(
                (x.inertia - fb.inertial.inertia).norm() / fb.inertial.inertia.norm() < 1e-8,
                "{}",
                fb.name
            );
        }
        // Same pose (the MJCF's; the URDF is placed by scene.json).
        assert!((b.pose.translation.vector - fb.pose.translation.vector).norm() < 1e-9);
        // The same hulls: count and volume.
        for hulls in [b.hulls(), ub.hulls()] {
            assert_eq!(hulls.len(), fb.hulls.len(), "{}", fb.name);
            let v: f64 = hulls.iter().map(|h| h.volume).sum();
            let w: f64 = fb.hulls.iter().map(|h| h.volume).sum();
            assert!((v - w).abs() / w < 1e-6, "{}: {v} vs {w}", fb.name);
        }
    }
}

#[test]
fn cli_outputs_and_exit_codes() {
    let t = tempfile::tempdir().unwrap();
    let d = pybullet_data();
    let duck = d.join("duck_vhacd.urdf");
    let duck = duck.to_str().unwrap();
    let bad = write(t.path(), "bad.urdf", "<robot><link name=\"a\">\n</robot>\n");
    let sarif = t.path().join("out.sarif");
    let junit = t.path().join("out.xml");
    let (code, out, err) = run(&[
        "validate",
        duck,
        bad.to_str().unwrap(),
        "--json",
        "--sarif",
        sarif.to_str().unwrap(),
        "--junit",
        junit.to_str().unwrap(),
        "--no-physics",
    ]);
    // The unreadable file is an error finding among readable assets: exit 1, not 2.
    assert_eq!(code, 1, "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["assets"].as_array().unwrap().len(), 2);
    let f = &j["assets"][0]["findings"][0];
    for k in [
        "check", "severity", "subject", "file", "line", "message", "value", "limit",
    ] {
        assert!(f.get(k).is_some(), "{k} missing in {f}");
    }
    assert_eq!(j["assets"][1]["findings"][0]["check"], "file.parse_error");
    assert_eq!(
        j["assets"][1]["findings"][0]["line"], 2,
        "the mismatched end tag"
    );
    let s: serde_json::Value = serde_json::from_slice(&std::fs::read(&sarif).unwrap()).unwrap();
    assert_eq!(s["version"], "2.1.0");
    let rules = s["runs"][0]["tool"]["driver"]["rules"].as_array().unwrap();
    assert_eq!(rules.len(), interact3d::validate::finding::CHECKS.len());
    for r in s["runs"][0]["results"].as_array().unwrap() {
        let idx = r["ruleIndex"].as_u64().unwrap() as usize;
        assert_eq!(rules[idx]["id"], r["ruleId"]);
        assert!(
            r["locations"][0]["physicalLocation"]["region"]["startLine"]
                .as_u64()
                .unwrap()
                >= 1
        );
    }
    let x = std::fs::read_to_string(&junit).unwrap();
    let cases = x.matches("<testcase").count();
    let expected: usize = j["assets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["checks"].as_array().unwrap().len())
        .sum();
    assert_eq!(cases, expected);
    // Only warnings on the duck: exit 0 at the default --fail-on error, 1 at warning.
    assert_eq!(run(&["validate", duck, "--no-physics"]).0, 0);
    let (code, out, _) = run(&[
        "validate",
        duck,
        "--no-physics",
        "--fail-on",
        "warning",
        "--github",
    ]);
    assert_eq!(code, 1);
    assert!(
        out.lines().any(|l| l.starts_with("::warning file=")
            && l.contains(",line=10,")
            && l.contains("inertia.placeholder")),
        "{out}"
    );
    // A baseline of today's findings passes tomorrow's run.
    let base = t.path().join("base.json");
    assert_eq!(
        run(&[
            "validate",
            duck,
            "--no-physics",
            "--write-baseline",
            base.to_str().unwrap()
        ])
        .0,
        0
    );
    assert_eq!(
        run(&[
            "validate",
            duck,
            "--no-physics",
            "--fail-on",
            "warning",
            "--baseline",
            base.to_str().unwrap()
        ])
        .0,
        0
    );
    // Nothing readable: 2. Nothing there: 2.
    assert_eq!(run(&["validate", bad.to_str().unwrap()]).0, 2);
    assert_eq!(
        run(&["validate", t.path().join("none.urdf").to_str().unwrap()]).0,
        2
    );
    // A folder and a glob find the same files; the same run gives the same bytes.
    let glob = format!("{}/*_vhacd.urdf", d.display());
    let (c1, o1, _) = run(&["validate", &glob, "--json", "--no-physics"]);
    let (c2, o2, _) = run(&["validate", &glob, "--json", "--no-physics"]);
    assert_eq!((c1, &o1), (c2, &o2));
    let j: serde_json::Value = serde_json::from_str(&o1).unwrap();
    assert!(j["assets"].as_array().unwrap().len() >= 2);
}

#[test]
fn frames_replicate_and_mesh_reference_agree_with_mujoco() {
    let t = tempfile::tempdir().unwrap();
    write(t.path(), "cube.obj", &box_obj([0.02, 0.01, 0.03]));
    let xml = r#"<mujoco>
  <asset>
    <mesh name="m" file="cube.obj" scale="1 2 1" refpos="0.01 0 -0.02" refquat="0.9238795 0 0 0.3826834"/>
  </asset>
  <worldbody>
    <geom type="plane" size="1 1 0.1"/>
    <frame pos="0.1 0 0" euler="0 0 30">
      <body name="a" pos="0.2 0 0.1">
        <freejoint/>
        <frame pos="0 0.05 0" euler="90 0 0">
          <geom name="ga" type="box" size="0.01 0.02 0.03"/>
          <geom name="gm" type="mesh" mesh="m" pos="0 0 0.04"/>
        </frame>
        <geom name="gc" type="capsule" fromto="0 0 0 0 0.1 0" size="0.01"/>
      </body>
    </frame>
    <replicate count="3" offset="0.1 0 0" euler="0 0 20" sep="-">
      <body name="r" pos="0 0.3 0.05">
        <freejoint/>
        <geom name="gr" type="sphere" size="0.02"/>
      </body>
    </replicate>
  </worldbody>
</mujoco>
"#;
    let p = write(t.path(), "frames.xml", xml);
    let a = interact3d::io::asset::load(&p, &Default::default()).unwrap();
    let mj = python_json(
        "check_asset_mujoco.py",
        &[p.to_str().unwrap(), "--seconds", "0"],
    );
    let geoms = mj["geoms"].as_object().unwrap();
    assert_eq!(geoms.len(), 6, "{mj}");
    for (name, g) in geoms {
        let (b, geom) = a
            .bodies
            .iter()
            .flat_map(|b| b.geoms.iter().map(move |g| (b, g)))
            .find(|(_, g)| &g.name == name)
            .unwrap_or_else(|| panic!("geom {name} not read"));
        let at = |k: usize, v: &serde_json::Value| v[k].as_f64().unwrap();
        if let Some(bb) = g.get("aabb") {
            // A mesh: MuJoCo recentres it, so compare where its vertices are in the world.
            let w: Vec<_> = geom
                .shape
                .meshes()
                .iter()
                .flat_map(|m| m.vertices.clone())
                .map(|v| b.pose * geom.pose * v)
                .collect();
            let ours = interact3d::mesh::Aabb::of_points(w.iter()).unwrap();
            for k in 0..3 {
                assert!(
                    (ours.min[k] - at(k, &bb[0])).abs() < 1e-6,
                    "{name} min {ours:?} {bb}"
                );
                assert!(
                    (ours.max[k] - at(k, &bb[1])).abs() < 1e-6,
                    "{name} max {ours:?} {bb}"
                );
            }
        } else {
            let c = b.pose * nalgebra::Point3::from(geom.pose.translation.vector);
            for k in 0..3 {
                assert!(
                    (c[k] - at(k, &g["pos"])).abs() < 1e-9,
                    "{name}: {c} vs {}",
                    g["pos"]
                );
            }
        }
    }
    // What is not read is said, at its line: <attach>, an hfield geom.
    let p = write(t.path(), "attach.xml", "<mujoco>\n  <asset><hfield name=\"h\" size=\"1 1 0.1 0.1\" nrow=\"2\" ncol=\"2\"/></asset>\n  <worldbody>\n    <body name=\"a\" pos=\"0 0 0.02\">\n      <freejoint/>\n      <geom type=\"sphere\" size=\"0.02\"/>\n      <geom type=\"hfield\" hfield=\"h\"/>\n      <attach model=\"gripper\" body=\"palm\" prefix=\"g_\"/>\n    </body>\n  </worldbody>\n</mujoco>\n");
    let r = check(&p);
    let f = find(&r, "file.unsupported");
    assert_eq!(
        f.iter().map(|f| f.line).collect::<Vec<_>>(),
        vec![7, 8],
        "{:#?}",
        r.findings
    );
    assert!(f[0].message.contains("hfield") && f[1].message.contains("attach"));
}

#[test]
fn xacro_is_one_clear_finding_at_its_line() {
    let t = tempfile::tempdir().unwrap();
    let p = write(t.path(), "arm.urdf.xacro", "<?xml version=\"1.0\"?>\n<robot name=\"arm\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n  <xacro:property name=\"r\" value=\"0.05\"/>\n  <link name=\"base\"/>\n</robot>\n");
    let (code, out, _) = run(&["validate", p.to_str().unwrap(), "--json"]);
    assert_eq!(code, 2, "nothing readable: {out}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    let f = &j["assets"][0]["findings"][0];
    assert_eq!(f["check"], "file.parse_error");
    assert_eq!(f["line"], 2, "{f}");
    assert!(f["message"].as_str().unwrap().contains("run `xacro"), "{f}");
}

#[test]
fn changed_since_checks_only_assets_whose_file_or_mesh_changed() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path();
    let git = |args: &[&str]| {
        let o = std::process::Command::new("git")
            .arg("-C")
            .arg(d)
            .args(args)
            .output()
            .expect("git");
        assert!(
            o.status.success(),
            "git {args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    };
    let commit = |msg: &str| {
        git(&[
            "-c",
            "user.name=t",
            "-c",
            "user.email=t@t",
            "commit",
            "-qm",
            msg,
        ])
    };
    let cube = |s: f64| box_obj([s; 3]);
    for n in ["a", "b", "c"] {
        write(d, &format!("{n}.obj"), &cube(0.03));
        write(
            d,
            &format!("{n}.urdf"),
            &urdf(
                &inertial(0.2, box_inertia(0.2, [0.06; 3]), [0.0; 3]),
                &format!("<mesh filename=\"{n}.obj\"/>"),
                &format!("<mesh filename=\"{n}.obj\"/>"),
            ),
        );
    }
    git(&["init", "-q"]);
    git(&["add", "."]);
    commit("assets");
    // b's mesh changes (uncommitted), c's URDF is untouched, d is new and untracked.
    write(d, "b.obj", &cube(0.031));
    write(
        d,
        "d.urdf",
        &std::fs::read_to_string(d.join("a.urdf")).unwrap(),
    );
    let dir = d.to_str().unwrap();
    let (code, out, err) = run(&[
        "validate",
        dir,
        "--changed-since",
        "HEAD",
        "--json",
        "--no-physics",
    ]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    let files: Vec<String> = j["assets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| {
            Path::new(a["file"].as_str().unwrap())
                .file_name()
                .unwrap()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    assert_eq!(files, vec!["b.urdf", "d.urdf"], "{err}");
    // Nothing changed since the working tree: nothing to check, exit 0; a bad revision: 2.
    git(&["add", "."]);
    commit("more");
    let (code, out, _) = run(&["validate", dir, "--changed-since", "HEAD", "--json"]);
    assert_eq!(code, 0);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["assets"].as_array().unwrap().len(), 0);
    assert_eq!(
        run(&["validate", dir, "--changed-since", "no-such-ref"]).0,
        2
    );
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
