//! Hostile inputs: Batch and determinism.

use super::*;

#[test]
fn batch_records_hostile_scenes_and_converts_the_good_ones() {
    let t = tempfile::tempdir().unwrap();
    let root = t.path().join("data");
    let made = batch_data::make_dataset(
        &root,
        batch_data::Spec {
            good: 2,
            failing: 0,
            broken: false,
        },
    );
    let hostile = root.join("outputs/toys");
    // Each hostile scene: (folder, text its error row must contain).
    let mut bad: Vec<(String, &str)> = Vec::new();
    let b = edited_glb(false, |j, _| {
        j["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
        j["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    });
    let d = sample(&hostile, "00101_draco", &b);
    bad.push((
        d.strip_prefix(&root).unwrap().display().to_string(),
        "Draco",
    ));
    let d = obj_scene(&hostile, "00102_escape", &box_obj());
    write_manifest(
        &d,
        json!([{"name": "box", "mesh": "../../../../../etc/passwd"}]),
    );
    bad.push((
        d.strip_prefix(&root).unwrap().display().to_string(),
        "outside the scene folder",
    ));
    let d = obj_scene(&hostile, "00103_loop", &box_obj());
    std::os::unix::fs::symlink("loop.obj", d.join("meshes/loop.obj")).unwrap();
    write_manifest(&d, json!([{"name": "box", "mesh": "meshes/loop.obj"}]));
    bad.push((
        d.strip_prefix(&root).unwrap().display().to_string(),
        "symbolic links",
    ));
    let mut glb = box_glb(false);
    glb.truncate(50);
    let d = sample(&hostile, "00104_truncated", &glb);
    bad.push((
        d.strip_prefix(&root).unwrap().display().to_string(),
        "truncated GLB",
    ));
    let d = obj_scene(&hostile, "00105_name", &box_obj());
    write_manifest(&d, json!([{"name": "</mujoco>", "mesh": "meshes/box.obj"}]));
    bad.push((
        d.strip_prefix(&root).unwrap().display().to_string(),
        "not a valid identifier",
    ));
    // Folder links back up: neither discovery nor the input hash may loop; the scene converts.
    std::os::unix::fs::symlink("..", root.join("outputs/toys/loop")).unwrap();
    let d = obj_scene(&hostile, "00106_dirloop", &box_obj());
    std::os::unix::fs::symlink("..", d.join("meshes/up")).unwrap();
    let good_extra = d.clone();
    let before = snapshot(&root);

    let out = t.path().join("out");
    let (code, _, err) = run(&[
        "batch",
        root.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--progress",
        "quiet",
        "--points",
        "20000",
        "--jobs",
        "2",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let s = read_json(&out.join("summary.json"));
    assert_eq!(s["counts"]["pass"], made.len() + 1, "{s}");
    assert_eq!(s["counts"]["error"], bad.len(), "{s}");
    let rows = s["scenes"].as_array().unwrap();
    for (rel, problem) in &bad {
        let row = rows
            .iter()
            .find(|r| r["path"] == rel.as_str())
            .unwrap_or_else(|| panic!("{rel} not in {s}"));
        assert_eq!(row["verdict"], "error", "{row}");
        let e = row["error"].as_str().unwrap();
        assert!(e.contains(problem) && !e.contains('\n'), "{rel}: {e}");
        assert!(!out.join(rel).exists(), "no output for {rel}");
    }
    for m in &made {
        assert!(out.join(&m.rel).join("scene.xml").is_file(), "{}", m.rel);
    }
    let rel = good_extra.strip_prefix(&root).unwrap();
    assert!(
        out.join(rel).join("scene.xml").is_file(),
        "{}",
        rel.display()
    );
    assert_eq!(before, snapshot(&root), "inputs untouched");
}

#[test]
fn textured_glb_scene_exports_byte_identically_twice() {
    let t = tempfile::tempdir().unwrap();
    let d = sample(t.path(), "tex", &box_glb(true));
    let (a, b) = (t.path().join("a"), t.path().join("b"));
    export(&d, &a, &["--points", "20000"]);
    export(&d, &b, &["--points", "20000"]);
    let (sa, sb) = (snapshot(&a), snapshot(&b));
    assert!(
        sa.iter().any(|(p, _)| p.ends_with(".png")),
        "texture written"
    );
    assert_eq!(sa.len(), sb.len());
    for (x, y) in sa.iter().zip(&sb) {
        assert_eq!(x.0, y.0);
        assert!(x.1 == y.1, "{} differs between two exports", x.0);
    }
}
