//! Files written by others: pybullet_data's URDFs, an articulated URDF, xacro, and MJCF
//! features (defaults, frames, mesh references) read as MuJoCo reads them.

use super::*;

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
