//! Hostile inputs: Names in the output, limits.

use super::*;

#[test]
fn free_text_from_inputs_is_escaped_in_xml() {
    let t = tempfile::tempdir().unwrap();
    let d = obj_scene(t.path(), "xml", &box_obj());
    let evil = r#"x"/><include file="/etc/passwd"/><!-- & '"#;
    fs::write(
        d.join("scene.json"),
        serde_json::to_vec(&json!({"name": evil, "objects": [{"name": "box", "label": evil, "mesh": "meshes/box.obj"}]})).unwrap(),
    )
    .unwrap();
    let out = t.path().join("xml/out");
    export_ok(&d, &out);
    let xml = fs::read_to_string(out.join("scene.xml")).unwrap();
    assert!(!xml.contains("<include"), "{xml}");
    // Well-formed, and the model name reads back exactly.
    let mut reader = quick_xml::Reader::from_str(&xml);
    let mut model = None;
    loop {
        match reader.read_event().unwrap() {
            quick_xml::events::Event::Start(e) if e.name().as_ref() == b"mujoco" => {
                let a = e.try_get_attribute("model").unwrap().unwrap();
                model = Some(a.unescape_value().unwrap().into_owned());
            }
            quick_xml::events::Event::Eof => break,
            _ => {}
        }
    }
    assert_eq!(model.as_deref(), Some(evil));
    // Only the expected files, all inside OUT.
    let mut names: Vec<String> = fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "box.urdf",
            "box.usda",
            "box.xml",
            "meshes",
            "report.json",
            "scene.json",
            "scene.usda",
            "scene.xml"
        ]
    );
    // The scene.json written reads back with the same name and label.
    let m = read_json(&out.join("scene.json"));
    assert_eq!(m["name"], evil);
    assert_eq!(m["objects"][0]["label"], evil);
}

#[test]
fn hostile_mesh_file_names_are_sanitised() {
    let t = tempfile::tempdir().unwrap();
    let d = case_dir(t.path(), "file");
    let mesh = d.join("a b\"<&>'x.obj");
    fs::write(&mesh, box_obj()).unwrap();
    let out = t.path().join("file/out");
    export_ok(&mesh, &out);
    let r = read_json(&out.join("report.json"));
    assert_eq!(r["objects"][0]["name"], "a_b_____x");
    assert!(out.join("a_b_____x.xml").is_file());
    assert!(out.join("meshes/a_b_____x/visual.obj").is_file());
}

#[test]
fn size_limits_are_options_with_their_own_errors() {
    let t = tempfile::tempdir().unwrap();
    let d = obj_scene(t.path(), "tris", &box_obj());
    rejects_with(
        &d,
        &["--max-triangles", "5"],
        "box.obj",
        "mesh has 12 triangles, over the limit of 5 (--max-triangles)",
    );
    let padded = format!("# {}\n{}", "-".repeat(3000), box_obj());
    let d = obj_scene(t.path(), "bytes", &padded);
    rejects_with(
        &d,
        &["--max-file-bytes", "2000"],
        "box.obj",
        "over the limit of 2000 bytes (--max-file-bytes)",
    );
    let d = obj_scene(t.path(), "manifest_bytes", &box_obj());
    rejects_with(
        &d,
        &["--max-file-bytes", "20"],
        "scene.json",
        "over the limit of 20 bytes (--max-file-bytes)",
    );
    let d = sample(t.path(), "pixels", &box_glb(true));
    rejects_with(
        &d,
        &["--max-texture-pixels", "15"],
        "object_a.glb#image0",
        "texture is 4x4 pixels, over the limit of 15 pixels (--max-texture-pixels)",
    );
    let d = manifest(
        t.path(),
        "stl",
        &[("box.stl", &stl_bytes(&cuboid(0.1, 0.2, 0.3), 12))],
        "box.stl",
    );
    rejects_with(
        &d,
        &["--max-triangles", "11"],
        "box.stl",
        "STL has 12 triangles, over the limit of 11 (--max-triangles)",
    );
    // The defaults are printed in --help.
    let (code, help, _) = run(&["export", "--help"]);
    assert_eq!(code, 0);
    for flag in [
        "--max-file-bytes",
        "--max-triangles",
        "--max-texture-pixels",
    ] {
        assert!(help.contains(flag), "{flag} in {help}");
    }
}
