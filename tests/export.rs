//! Export contract: analytic masses and inertias through the whole pipeline, Z-up and ground
//! placement, units and --size, re-readable scene.json, byte-identical output (two exports, on
//! all threads and on one), and bad input rejected with exit code 2, one line naming the file, no
//! output folder and untouched inputs.

mod common;
use common::*;
use std::fs;
use std::path::Path;

/// OBJ text of an axis-aligned box with the given extents, centred at the origin.
fn box_obj(ext: [f64; 3]) -> String {
    let m = interact3d::shapes::cuboid(nalgebra::Vector3::new(ext[0], ext[1], ext[2]));
    let mut s = String::new();
    for v in &m.vertices {
        s += &format!("v {} {} {}\n", v.x, v.y, v.z);
    }
    for t in &m.triangles {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

fn write_box_scene(dir: &Path, manifest_extra: &str, pose: &str) {
    fs::create_dir_all(dir.join("meshes")).unwrap();
    fs::write(dir.join("meshes/box.obj"), box_obj([0.1, 0.2, 0.3])).unwrap();
    fs::write(
        dir.join("scene.json"),
        format!(
            r#"{{"format": "interact3d-scene", "version": 1 {manifest_extra},
  "objects": [{{"name": "box", "mesh": "meshes/box.obj", "pose": {pose}}}]}}"#
        ),
    )
    .unwrap();
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn box_mass_inertia_and_ground_through_the_whole_pipeline() {
    let t = tempfile::tempdir().unwrap();
    // 90° about x: the 0.2 (y) side becomes vertical.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    write_box_scene(
        t.path(),
        "",
        &format!(r#"{{"translation": [1, 2, 3], "quaternion_wxyz": [{h}, {h}, 0, 0]}}"#),
    );
    let out = t.path().join("out");
    export(t.path(), &out, &["--no-validate"]);
    let r = read_json(&out.join("report.json"));
    let o = &r["objects"][0];
    let mass = 1000.0 * 0.1 * 0.2 * 0.3;
    assert!(rel(o["mass"].as_f64().unwrap(), mass) < 1e-9);
    assert_eq!(o["volume_source"], "closed_mesh");
    // World axes: extents (0.1, 0.3, 0.2); Ixx = m(0.3² + 0.2²)/12 etc.
    let i = &o["inertia"];
    assert!(rel(i[0][0].as_f64().unwrap(), mass * (0.09 + 0.04) / 12.0) < 1e-9);
    assert!(rel(i[1][1].as_f64().unwrap(), mass * (0.01 + 0.04) / 12.0) < 1e-9);
    assert!(rel(i[2][2].as_f64().unwrap(), mass * (0.01 + 0.09) / 12.0) < 1e-9);
    // Resting on the ground: the COM is half the (now vertical) 0.2 side above z = 0.
    let com = &o["com"];
    assert!((com[2].as_f64().unwrap() - 0.1).abs() < 1e-9);
    assert!(
        (com[0].as_f64().unwrap() - 1.0).abs() < 1e-9
            && (com[1].as_f64().unwrap() - 2.0).abs() < 1e-9
    );
    let ext: Vec<f64> = o["extents"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!(
        (ext[0] - 0.1).abs() < 1e-9 && (ext[1] - 0.3).abs() < 1e-9 && (ext[2] - 0.2).abs() < 1e-9
    );
    assert!(o["hull_count"].as_u64().unwrap() >= 1);
    assert!(o["hull_vertex_counts"]
        .as_array()
        .unwrap()
        .iter()
        .all(|v| v.as_u64().unwrap() <= 64));

    // The MJCF carries the full tensor, the body at the COM.
    let xml = fs::read_to_string(out.join("scene.xml")).unwrap();
    assert!(xml.contains(r#"<body name="box" pos="1 2 0.1""#), "{xml}");
    assert!(xml.contains("fullinertia="));
}

#[test]
fn exported_scene_json_reads_back_to_the_same_bodies() {
    let t = tempfile::tempdir().unwrap();
    write_box_scene(
        t.path(),
        r#", "units": "cm""#,
        r#"{"translation": [10, 0, 50], "scale": 2.0}"#,
    );
    let out = t.path().join("out");
    export(t.path(), &out, &["--no-validate"]);
    let out2 = t.path().join("out2");
    export(&out.join("scene.json"), &out2, &["--no-validate"]);
    let a = read_json(&out.join("report.json"));
    let b = read_json(&out2.join("report.json"));
    // units cm and scale 2: the 0.1 x 0.2 x 0.3 box becomes 2 x 4 x 6 mm.
    let mass = 1000.0 * (0.002 * 0.004 * 0.006);
    for r in [&a, &b] {
        assert!(
            rel(r["objects"][0]["mass"].as_f64().unwrap(), mass) < 1e-6,
            "{r}"
        );
    }
    for k in 0..3 {
        let (x, y) = (
            a["objects"][0]["com"][k].as_f64().unwrap(),
            b["objects"][0]["com"][k].as_f64().unwrap(),
        );
        assert!((x - y).abs() < 1e-12, "com {x} vs {y}");
        for c in 0..3 {
            let (x, y) = (
                a["objects"][0]["inertia"][k][c].as_f64().unwrap(),
                b["objects"][0]["inertia"][k][c].as_f64().unwrap(),
            );
            assert!(
                (x - y).abs() <= 1e-6 * x.abs().max(1e-15),
                "inertia {x} vs {y}"
            );
        }
    }
}

#[test]
fn size_option_scales_the_scene_uniformly() {
    let t = tempfile::tempdir().unwrap();
    write_box_scene(t.path(), "", r#"{"translation": [0, 0, 0]}"#);
    let out = t.path().join("out");
    export(t.path(), &out, &["--size", "box=0.6"]);
    let r = read_json(&out.join("report.json"));
    let mass = 1000.0 * 0.2 * 0.4 * 0.6;
    assert!(rel(r["objects"][0]["mass"].as_f64().unwrap(), mass) < 1e-9);
    assert!((r["scale"].as_f64().unwrap() - 2.0).abs() < 1e-12);
    let (code, _, err) = run(&[
        "export",
        t.path().to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--size",
        "nothing=1",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("nothing"), "{err}");
}

#[test]
fn same_input_same_bytes() {
    // A real scan scene when ../shared is there (its textures and many triangles exercise more
    // of the writers); the first fixture either way, so the check always runs.
    let mut scenes = fixtures().into_iter().take(1).collect::<Vec<_>>();
    scenes.extend(shared_or_skip(
        "export::same_input_same_bytes (the shared lemon_bowl part)",
        "datasets/scenes/food/00001_lemon_bowl",
    ));
    for scene in scenes {
        same_bytes_twice(&scene);
    }
}

fn same_bytes_twice(scene: &Path) {
    let t = tempfile::tempdir().unwrap();
    let (a, b) = (t.path().join("a"), t.path().join("b"));
    export(scene, &a, &[]);
    // The second on one thread: the bytes may not depend on how the work was spread (#37).
    let one = std::process::Command::new(env!("CARGO_BIN_EXE_interact3d"))
        .args(["export", scene.to_str().unwrap(), "-o", b.to_str().unwrap()])
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .expect("run interact3d");
    assert!(
        b.join("report.json").is_file(),
        "export on one thread failed: {}",
        String::from_utf8_lossy(&one.stderr)
    );
    let files = |d: &Path| -> Vec<(String, Vec<u8>)> {
        let mut v = Vec::new();
        let mut stack = vec![d.to_path_buf()];
        while let Some(p) = stack.pop() {
            for e in fs::read_dir(&p).unwrap() {
                let e = e.unwrap().path();
                if e.is_dir() {
                    stack.push(e);
                } else {
                    v.push((
                        e.strip_prefix(d).unwrap().display().to_string(),
                        fs::read(&e).unwrap(),
                    ));
                }
            }
        }
        v.sort();
        v
    };
    let (fa, fb) = (files(&a), files(&b));
    assert!(fa.len() > 5);
    assert_eq!(fa.len(), fb.len());
    for (x, y) in fa.iter().zip(&fb) {
        assert_eq!(x.0, y.0);
        assert!(x.1 == y.1, "{} differs between two exports", x.0);
    }
}

#[test]
fn bad_inputs_exit_2_with_one_line_and_no_output() {
    let t = tempfile::tempdir().unwrap();
    let case = |name: &str| {
        let d = t.path().join(name).join("scene");
        write_box_scene(&d, "", r#"{"translation": [0, 0, 0]}"#);
        d
    };
    // NaN vertex.
    let d = case("nan");
    fs::write(
        d.join("meshes/box.obj"),
        box_obj([0.1, 0.2, 0.3])
            .replacen("v ", "v nan ", 1)
            .replacen("nan -0.05", "nan", 1),
    )
    .unwrap();
    rejects(&d, "box.obj", "NaN");
    // Index out of range.
    let d = case("index");
    fs::write(
        d.join("meshes/box.obj"),
        box_obj([0.1, 0.2, 0.3]) + "f 1 2 99\n",
    )
    .unwrap();
    rejects(&d, "box.obj", "out of range");
    // Empty mesh.
    let d = case("empty");
    fs::write(d.join("meshes/box.obj"), "# nothing\n").unwrap();
    rejects(&d, "box.obj", "no triangles");
    // Missing texture.
    let d = case("texture");
    fs::write(
        d.join("meshes/box.obj"),
        "mtllib box.mtl\nusemtl m\n".to_string() + &box_obj([0.1, 0.2, 0.3]),
    )
    .unwrap();
    fs::write(
        d.join("meshes/box.mtl"),
        "newmtl m\nKd 1 1 1\nmap_Kd missing.png\n",
    )
    .unwrap();
    rejects(&d, "box", "missing.png");
    // Singular matrix.
    let d = case("singular");
    write_box_scene(
        &d,
        "",
        r#"{"matrix": [[0,0,0,0],[0,0,0,0],[0,0,0,0],[0,0,0,1]]}"#,
    );
    rejects(&d, "scene.json", "singular");
    // Mesh path escaping the manifest folder.
    let d = case("escape");
    fs::write(
        d.join("scene.json"),
        r#"{"objects": [{"name": "box", "mesh": "../../box.obj"}]}"#,
    )
    .unwrap();
    rejects(&d, "scene.json", "outside");
    // Duplicate names.
    let d = case("dup");
    fs::write(d.join("scene.json"), r#"{"objects": [{"name": "box", "mesh": "meshes/box.obj"}, {"name": "box", "mesh": "meshes/box.obj"}]}"#).unwrap();
    rejects(&d, "scene.json", "duplicate");
    // Malformed JSON.
    let d = case("json");
    fs::write(d.join("scene.json"), "{ not json").unwrap();
    rejects(&d, "scene.json", "invalid scene manifest");
    // A name that would inject XML.
    let d = case("name");
    fs::write(
        d.join("scene.json"),
        r#"{"objects": [{"name": "a\"/><evil", "mesh": "meshes/box.obj"}]}"#,
    )
    .unwrap();
    rejects(&d, "scene.json", "not a valid identifier");
    // Truncated binary STL.
    let d = case("stl");
    let mut stl = vec![0u8; 80];
    stl.extend_from_slice(&10u32.to_le_bytes());
    stl.extend_from_slice(&[0u8; 50 * 3]);
    fs::write(d.join("meshes/box.stl"), stl).unwrap();
    fs::write(
        d.join("scene.json"),
        r#"{"objects": [{"name": "box", "mesh": "meshes/box.stl"}]}"#,
    )
    .unwrap();
    rejects(&d, "box.stl", "truncated");
}
