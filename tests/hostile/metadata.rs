//! Hostile inputs: metadata.json and scene.json.

use super::*;

fn with_metadata(t: &Path, case: &str, meta: &str) -> PathBuf {
    let d = sample(t, case, &box_glb(false));
    fs::write(d.join("metadata.json"), meta).unwrap();
    d
}

#[test]
fn metadata_malformed_or_incomplete() {
    let t = tempfile::tempdir().unwrap();
    let d = with_metadata(t.path(), "json", "{\"registration\": ");
    rejects(&d, "metadata.json", "malformed JSON");
    let d = with_metadata(t.path(), "none", "{}");
    rejects(&d, "metadata.json", "missing registration.transforms");
    let d = with_metadata(t.path(), "other", r#"{"registration": {"transforms": {}}}"#);
    rejects(
        &d,
        "metadata.json",
        "no registration.transforms entry for object_a",
    );
    let id = "[[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]";
    let d = with_metadata(
        t.path(),
        "extra",
        &format!(
            r#"{{"registration": {{"transforms": {{"object_a": {{"matrix": {id}}}, "object_b": {{"matrix": {id}}}}}}}}}"#
        ),
    );
    rejects(&d, "metadata.json", "object_b.glb is missing");
    let d = with_metadata(
        t.path(),
        "nan",
        r#"{"registration": {"transforms": {"object_a": {"matrix": [["NaN",0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}}}}"#,
    );
    rejects(&d, "metadata.json", "matrix must be a 4x4 list of numbers");
    let d = case_dir(t.path(), "no_objects");
    fs::write(
        d.join("metadata.json"),
        r#"{"registration": {"transforms": {}}}"#,
    )
    .unwrap();
    rejects(&d, "scene", "sample folder has no object_*.glb files");
}

#[test]
fn transforms_singular_shear_mirror_zero_negative_nan() {
    let t = tempfile::tempdir().unwrap();
    let meta = |m: &str| format!(r#"{{"registration": {{"transforms": {{"object_a": {m}}}}}}}"#);
    for (case, m, problem) in [
        (
            "shear",
            r#"{"matrix": [[1,0.5,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}"#,
            "not a similarity (shear or non-uniform scale",
        ),
        (
            "stretch",
            r#"{"matrix": [[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}"#,
            "not a similarity",
        ),
        (
            "mirror",
            r#"{"matrix": [[-1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}"#,
            "mirrors (determinant",
        ),
        (
            "projective",
            r#"{"matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0.1,0,1]]}"#,
            "last row must be [0, 0, 0, 1]",
        ),
        (
            "zero_scale",
            r#"{"scale": 0, "rotation": [[1,0,0],[0,1,0],[0,0,1]], "translation": [0,0,0]}"#,
            "singular (zero scale)",
        ),
        (
            "neg_scale",
            r#"{"scale": -2, "rotation": [[1,0,0],[0,1,0],[0,0,1]], "translation": [0,0,0]}"#,
            "mirrors",
        ),
        (
            "disagree",
            r#"{"matrix": [[2,0,0,0],[0,2,0,0],[0,0,2,0],[0,0,0,1]], "scale": 3}"#,
            "scale 3 disagrees with the matrix's scale 2",
        ),
    ] {
        let d = with_metadata(t.path(), case, &meta(m));
        rejects(&d, "metadata.json", problem);
    }
    // The same in a manifest: parts with zero or negative scale, NaN via an out-of-range number.
    for (case, pose, problem) in [
        (
            "m_zero",
            json!({"scale": 0.0}),
            "scale must be positive, got 0",
        ),
        (
            "m_neg",
            json!({"scale": -1.0}),
            "scale must be positive, got -1",
        ),
        (
            "m_quat",
            json!({"quaternion_wxyz": [0, 0, 0, 0]}),
            "quaternion has zero length",
        ),
        (
            "m_shear",
            json!({"matrix": [[1,0.5,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}),
            "not a similarity",
        ),
    ] {
        let d = obj_scene(t.path(), case, &box_obj());
        write_manifest(
            &d,
            json!([{"name": "box", "mesh": "meshes/box.obj", "pose": pose}]),
        );
        rejects(&d, "scene.json", problem);
    }
    let d = obj_scene(t.path(), "m_nan", &box_obj());
    fs::write(
        d.join("scene.json"),
        r#"{"objects": [{"name": "box", "mesh": "meshes/box.obj", "pose": {"translation": [1e999, 0, 0]}}]}"#,
    )
    .unwrap();
    rejects(&d, "scene.json", "invalid scene manifest");
    let d = obj_scene(t.path(), "m_nan_literal", &box_obj());
    fs::write(
        d.join("scene.json"),
        r#"{"objects": [{"name": "box", "mesh": "meshes/box.obj", "pose": {"scale": NaN}}]}"#,
    )
    .unwrap();
    rejects(&d, "scene.json", "invalid scene manifest");
}

#[test]
fn manifest_missing_objects_and_bad_values() {
    let t = tempfile::tempdir().unwrap();
    let cases: [(&str, &str, &str); 6] = [
        (
            "none",
            r#"{"format": "interact3d-scene"}"#,
            "missing field `objects`",
        ),
        ("empty", r#"{"objects": []}"#, "scene has no objects"),
        (
            "unknown",
            r#"{"objects": [{"name": "box", "mesh": "meshes/box.obj", "colour": 1}]}"#,
            "unknown field `colour`",
        ),
        (
            "units",
            r#"{"units": -1, "objects": [{"name": "box", "mesh": "meshes/box.obj"}]}"#,
            "units must be a positive number of metres, got -1",
        ),
        (
            "mass",
            r#"{"objects": [{"name": "box", "mesh": "meshes/box.obj", "mass": -3}]}"#,
            "mass must be a positive number, got -3",
        ),
        (
            "missing",
            r#"{"objects": [{"name": "box", "mesh": "meshes/nothing.obj"}]}"#,
            "\"meshes/nothing.obj\": cannot open",
        ),
    ];
    for (case, text, problem) in cases {
        let d = obj_scene(t.path(), case, &box_obj());
        fs::write(d.join("scene.json"), text).unwrap();
        rejects(&d, "scene.json", problem);
    }
}

#[test]
fn object_names_that_are_not_identifiers_or_file_names() {
    let t = tempfile::tempdir().unwrap();
    for (case, name) in [
        ("slash", "../../outside"),
        ("abs", "/tmp/x"),
        ("nul", "a\u{0}b"),
        ("space", "two words"),
        ("amp", "a&b"),
        ("digit", "1box"),
        ("empty", ""),
        ("long", &"x".repeat(65)),
    ] {
        let d = obj_scene(t.path(), case, &box_obj());
        write_manifest(&d, json!([{"name": name, "mesh": "meshes/box.obj"}]));
        rejects(&d, "scene.json", "is not a valid identifier");
    }
    // From a sample folder's file names.
    let d = sample(t.path(), "file", &box_glb(false));
    fs::rename(d.join("object_a.glb"), d.join("object_a&b.glb")).unwrap();
    fs::write(
        d.join("metadata.json"),
        r#"{"registration": {"transforms": {"object_a&b": {"matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}}}}"#,
    )
    .unwrap();
    rejects(
        &d,
        "metadata.json",
        "\"object_a&b\" is not a valid identifier",
    );
}

#[test]
fn mesh_paths_escaping_the_manifest_folder() {
    let t = tempfile::tempdir().unwrap();
    fs::write(t.path().join("outside.obj"), box_obj()).unwrap();
    let outside = t.path().join("outside.obj");
    for (case, mesh, problem) in [
        (
            "abs",
            outside.to_str().unwrap().to_string(),
            "is an absolute path",
        ),
        ("file", format!("file://{}", outside.display()), "is a URI"),
        (
            "dots",
            "meshes/../../../outside.obj".to_string(),
            "points outside the scene folder",
        ),
    ] {
        let d = obj_scene(t.path(), case, &box_obj());
        write_manifest(&d, json!([{"name": "box", "mesh": mesh}]));
        rejects(&d, "scene.json", problem);
    }
    // A link inside the folder that leads out of it.
    let d = obj_scene(t.path(), "link", &box_obj());
    std::os::unix::fs::symlink(&outside, d.join("meshes/link.obj")).unwrap();
    write_manifest(&d, json!([{"name": "box", "mesh": "meshes/link.obj"}]));
    rejects(
        &d,
        "scene.json",
        "resolves (through a link) outside the scene folder",
    );
}

#[test]
fn export_folder_with_escaping_collision_paths() {
    let t = tempfile::tempdir().unwrap();
    fs::write(t.path().join("outside.obj"), box_obj()).unwrap();
    let d = obj_scene(t.path(), "exp", &box_obj());
    let out = t.path().join("exp/out");
    export_ok(&d, &out);
    let mut m = read_json(&out.join("scene.json"));
    m["objects"][0]["collision"][0] = json!("../../../outside.obj");
    fs::write(out.join("scene.json"), serde_json::to_vec(&m).unwrap()).unwrap();
    let before = snapshot(&out);
    let (code, stdout, stderr) = run(&["validate", out.to_str().unwrap()]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stdout.is_empty());
    let line = stderr.trim();
    assert_eq!(line.lines().count(), 1, "{line}");
    assert!(
        line.contains("scene.json") && line.contains("points outside the scene folder"),
        "{line}"
    );
    assert_eq!(before, snapshot(&out));
}

#[test]
fn symlink_loops() {
    let t = tempfile::tempdir().unwrap();
    let d = obj_scene(t.path(), "self", &box_obj());
    std::os::unix::fs::symlink("loop.obj", d.join("meshes/loop.obj")).unwrap();
    write_manifest(&d, json!([{"name": "box", "mesh": "meshes/loop.obj"}]));
    rejects(&d, "scene.json", "symbolic links");
    let d = obj_scene(t.path(), "pair", &box_obj());
    std::os::unix::fs::symlink("b.obj", d.join("meshes/a.obj")).unwrap();
    std::os::unix::fs::symlink("a.obj", d.join("meshes/b.obj")).unwrap();
    write_manifest(&d, json!([{"name": "box", "mesh": "meshes/a.obj"}]));
    rejects(&d, "scene.json", "symbolic links");
    // A folder link to its own parent on the way to the mesh still stays inside: accepted.
    let d = obj_scene(t.path(), "dirloop", &box_obj());
    std::os::unix::fs::symlink("..", d.join("meshes/up")).unwrap();
    write_manifest(
        &d,
        json!([{"name": "box", "mesh": "meshes/up/meshes/up/meshes/box.obj"}]),
    );
    export_ok(&d, &t.path().join("dirloop/out"));
}
