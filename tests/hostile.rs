//! Hostile and broken inputs (issue #7): every loader and writer refuses bad input with exit
//! code 2 and one line naming the file and the problem, never panics, creates no output folder
//! and leaves the inputs untouched; references never reach outside the scene folder; size limits
//! are options with their own errors; names from input files cannot inject XML or escape OUT.
//! Every input is built here, in code. The cases already in `tests/export.rs`
//! (`bad_inputs_exit_2_with_one_line_and_no_output`) are not repeated.

mod batch_data;
use batch_data::obj_text;
mod common;

use common::*;
use interact3d::mesh::{Material, Mesh, Texture, VisualMesh, VisualPart, V3};
use serde_json::{json, Value};
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::Arc;

// ---------------------------------------------------------------------------------------------
// Building inputs

fn cuboid(x: f64, y: f64, z: f64) -> Mesh {
    interact3d::shapes::cuboid(V3::new(x, y, z))
}

fn part(m: &Mesh, texture: Option<Texture>) -> VisualPart {
    let uvs = texture.as_ref().map(|_| {
        m.vertices
            .iter()
            .map(|v| [v.x.fract().abs(), v.y.fract().abs()])
            .collect()
    });
    VisualPart {
        positions: m.vertices.clone(),
        uvs,
        triangles: m.triangles.clone(),
        material: Material {
            name: "paint".into(),
            base_color: [0.5, 0.6, 0.7, 1.0],
            texture,
        },
    }
}

/// A 4x4 PNG.
fn png() -> Vec<u8> {
    let img = image::RgbImage::from_fn(4, 4, |x, y| image::Rgb([x as u8 * 60, y as u8 * 60, 99]));
    let mut out = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
        .unwrap();
    out
}

fn glb_of(m: &Mesh, textured: bool) -> Vec<u8> {
    let tex = textured.then(|| Texture {
        origin: "test.png".into(),
        bytes: Arc::new(png()),
        width: 4,
        height: 4,
    });
    interact3d::io::to_glb_bytes(&VisualMesh {
        parts: vec![part(m, tex)],
    })
    .unwrap()
}

/// A valid GLB of a 10 x 20 x 30 cm box (textured when asked).
fn box_glb(textured: bool) -> Vec<u8> {
    glb_of(&cuboid(0.1, 0.2, 0.3), textured)
}

/// Split a GLB into its JSON and BIN chunks.
fn split_glb(b: &[u8]) -> (Value, Vec<u8>) {
    let u = |o: usize| u32::from_le_bytes(b[o..o + 4].try_into().unwrap()) as usize;
    let jlen = u(12);
    let json = serde_json::from_slice(&b[20..20 + jlen]).unwrap();
    let bin = if b.len() > 20 + jlen {
        let blen = u(20 + jlen);
        b[28 + jlen..28 + jlen + blen].to_vec()
    } else {
        Vec::new()
    };
    (json, bin)
}

/// Pack JSON and BIN chunks into a GLB (no BIN chunk when `bin` is empty).
fn pack_glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut j = serde_json::to_vec(json).unwrap();
    while j.len() % 4 != 0 {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while b.len() % 4 != 0 {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + if b.is_empty() { 0 } else { 8 + b.len() };
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    if !b.is_empty() {
        out.extend_from_slice(&(b.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&b);
    }
    out
}

/// The box GLB with its JSON and BIN edited.
fn edited_glb(textured: bool, edit: impl FnOnce(&mut Value, &mut Vec<u8>)) -> Vec<u8> {
    let (mut json, mut bin) = split_glb(&box_glb(textured));
    edit(&mut json, &mut bin);
    pack_glb(&json, &bin)
}

/// A fresh case folder `<tmp>/<case>/scene`.
fn case_dir(t: &Path, case: &str) -> PathBuf {
    let d = t.join(case).join("scene");
    fs::create_dir_all(&d).unwrap();
    d
}

/// An Interact3D sample folder holding `object_a.glb` (identity transform).
fn sample(t: &Path, case: &str, glb: &[u8]) -> PathBuf {
    let d = case_dir(t, case);
    fs::write(d.join("object_a.glb"), glb).unwrap();
    fs::write(
        d.join("metadata.json"),
        serde_json::to_vec_pretty(&json!({"registration": {"transforms": {"object_a": {
            "matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}}}}))
        .unwrap(),
    )
    .unwrap();
    d
}

/// A manifest scene: `files` written into the folder, one object `box` using `mesh`.
fn manifest(t: &Path, case: &str, files: &[(&str, &[u8])], mesh: &str) -> PathBuf {
    let d = case_dir(t, case);
    for (name, bytes) in files {
        let p = d.join(name);
        fs::create_dir_all(p.parent().unwrap()).unwrap();
        fs::write(p, bytes).unwrap();
    }
    write_manifest(&d, json!([{"name": "box", "mesh": mesh}]));
    d
}

fn write_manifest(d: &Path, objects: Value) {
    fs::write(
        d.join("scene.json"),
        serde_json::to_vec_pretty(
            &json!({"format": "interact3d-scene", "version": 1, "objects": objects}),
        )
        .unwrap(),
    )
    .unwrap();
}

fn box_obj() -> String {
    obj_text(&cuboid(0.1, 0.2, 0.3))
}

/// A manifest scene with one OBJ mesh `meshes/box.obj`.
fn obj_scene(t: &Path, case: &str, obj: &str) -> PathBuf {
    manifest(
        t,
        case,
        &[("meshes/box.obj", obj.as_bytes())],
        "meshes/box.obj",
    )
}

/// Binary STL of triangle soup with a declared triangle count.
fn stl_bytes(m: &Mesh, declared: u32) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&declared.to_le_bytes());
    for t in &m.triangles {
        b.extend_from_slice(&[0u8; 12]);
        for &i in t {
            let v = m.vertices[i as usize];
            for c in [v.x, v.y, v.z] {
                b.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

/// Export without validation (fast); the output's report.json.
fn export_ok(scene: &Path, out: &Path) -> Value {
    let code = export(scene, out, &["--no-validate"]);
    assert_eq!(code, 0);
    read_json(&out.join("report.json"))
}

// ---------------------------------------------------------------------------------------------
// GLB / glTF containers

#[test]
fn glb_truncated_file() {
    let t = tempfile::tempdir().unwrap();
    let b = box_glb(false);
    let d = sample(t.path(), "cut", &b[..b.len() - 100]);
    rejects(&d, "object_a.glb", "truncated GLB: the header declares");
    let d = sample(t.path(), "header", &b[..10]);
    rejects(&d, "object_a.glb", "truncated GLB: 10 bytes");
}

#[test]
fn glb_wrong_magic() {
    let t = tempfile::tempdir().unwrap();
    let mut b = box_glb(false);
    b[..4].copy_from_slice(b"PK\x03\x04");
    let d = sample(t.path(), "magic", &b);
    rejects(&d, "object_a.glb", "not a GLB file");
    let mut b = box_glb(false);
    b[4] = 1;
    let d = sample(t.path(), "version", &b);
    rejects(&d, "object_a.glb", "unsupported GLB version 1");
}

#[test]
fn glb_chunk_lengths_past_the_end() {
    let t = tempfile::tempdir().unwrap();
    // The BIN chunk claims 1 GiB.
    let mut b = box_glb(false);
    let jlen = u32::from_le_bytes(b[12..16].try_into().unwrap()) as usize;
    b[20 + jlen..24 + jlen].copy_from_slice(&(1u32 << 30).to_le_bytes());
    let d = sample(t.path(), "bin", &b);
    rejects(
        &d,
        "object_a.glb",
        "chunk 1 (BIN) declares 1073741824 bytes",
    );
    // The JSON chunk claims more than the file.
    let mut b = box_glb(false);
    b[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
    let d = sample(t.path(), "json", &b);
    rejects(
        &d,
        "object_a.glb",
        "chunk 0 (JSON) declares 4294967295 bytes",
    );
    // A header length smaller than the header itself (the gltf crate would underflow).
    let mut b = box_glb(false);
    b[8..12].copy_from_slice(&4u32.to_le_bytes());
    let d = sample(t.path(), "tiny", &b);
    rejects(&d, "object_a.glb", "too few for a JSON chunk");
}

#[test]
fn glb_accessor_out_of_bounds() {
    let t = tempfile::tempdir().unwrap();
    let b = edited_glb(false, |j, _| {
        j["accessors"][0]["byteOffset"] = json!(1_000_000)
    });
    let d = sample(t.path(), "acc", &b);
    rejects(&d, "object_a.glb", "accessor 0");
}

#[test]
fn glb_attribute_naming_a_missing_accessor() {
    // Found by fuzzing (fuzz target glb, 31 crash files, all this one): gltf-json's validation
    // indexed the accessors with the POSITION index unchecked and panicked.
    let t = tempfile::tempdir().unwrap();
    for (case, index, n) in [("past", 5, 3), ("none", 0, 0)] {
        let b = edited_glb(false, |j, _| {
            j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(index);
            let acc = j["accessors"].as_array_mut().unwrap();
            acc.truncate(n);
        });
        let d = sample(t.path(), case, &b);
        rejects(
            &d,
            "object_a.glb",
            &format!("mesh 0 primitive 0: attribute POSITION refers to accessor {index}, but there are {n} accessors"),
        );
    }
}

#[test]
fn glb_buffer_view_out_of_bounds() {
    let t = tempfile::tempdir().unwrap();
    let b = edited_glb(false, |j, _| {
        j["bufferViews"][0]["byteOffset"] = json!(1_000_000);
    });
    let d = sample(t.path(), "view", &b);
    rejects(&d, "object_a.glb", "runs past the end of its buffer");
    // The buffer declares more bytes than the BIN chunk holds.
    let b = edited_glb(false, |j, _| {
        j["buffers"][0]["byteLength"] = json!(1u64 << 40)
    });
    let d = sample(t.path(), "buffer", &b);
    rejects(&d, "object_a.glb", "shorter than its declared length");
}

#[test]
fn glb_accessor_layouts_the_reader_cannot_take() {
    let t = tempfile::tempdir().unwrap();
    let pos = |j: &Value| {
        j["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
            .as_u64()
            .unwrap() as usize
    };
    let idx = |j: &Value| j["meshes"][0]["primitives"][0]["indices"].as_u64().unwrap() as usize;
    type Edit = fn(&mut Value, usize, usize);
    let cases: [(&str, Edit, &str); 4] = [
        (
            "stride",
            |j, p, _| {
                let v = j["accessors"][p]["bufferView"].as_u64().unwrap() as usize;
                j["bufferViews"][v]["byteStride"] = json!(4);
            },
            "has byteStride 4, smaller than one 12-byte element",
        ),
        (
            "u8_positions",
            |j, p, _| j["accessors"][p]["componentType"] = json!(5121),
            "(POSITION) is Vec3 U8; glTF requires Vec3 of [F32]",
        ),
        (
            "float_indices",
            |j, _, i| j["accessors"][i]["componentType"] = json!(5126),
            "(indices) is Scalar F32",
        ),
        (
            "zero_count",
            |j, p, _| j["accessors"][p]["count"] = json!(0),
            "count is 0",
        ),
    ];
    for (case, edit, problem) in cases {
        let b = edited_glb(false, |j, _| {
            let (p, i) = (pos(j), idx(j));
            edit(j, p, i)
        });
        let d = sample(t.path(), case, &b);
        rejects(&d, "object_a.glb", problem);
    }
}

#[test]
fn glb_index_past_vertex_count() {
    let t = tempfile::tempdir().unwrap();
    let b = edited_glb(false, |j, bin| {
        let idx = j["meshes"][0]["primitives"][0]["indices"].as_u64().unwrap() as usize;
        let view = j["accessors"][idx]["bufferView"].as_u64().unwrap() as usize;
        let off = j["bufferViews"][view]["byteOffset"].as_u64().unwrap_or(0) as usize;
        bin[off..off + 4].copy_from_slice(&999u32.to_le_bytes());
    });
    let d = sample(t.path(), "index", &b);
    rejects(&d, "object_a.glb", "index 999 past the vertex count");
}

#[test]
fn glb_declared_counts_of_gigabytes() {
    let t = tempfile::tempdir().unwrap();
    // An accessor claiming 4 billion elements in a small buffer.
    let b = edited_glb(false, |j, _| {
        j["accessors"][0]["count"] = json!(4_000_000_000u64)
    });
    let d = sample(t.path(), "count", &b);
    rejects(&d, "object_a.glb", "4000000000 elements need");
    // One small mesh instanced by 100,000 nodes: counted before anything is read.
    let b = edited_glb(false, |j, _| {
        let nodes: Vec<Value> = (0..100_000).map(|_| json!({"mesh": 0})).collect();
        j["nodes"] = Value::Array(nodes);
        j["scenes"] = json!([{"nodes": (0..100_000).collect::<Vec<u32>>()}]);
    });
    let d = sample(t.path(), "instances", &b);
    rejects_with(
        &d,
        &["--max-triangles", "100000"],
        "object_a.glb",
        "more than 100000 triangles",
    );
}

#[test]
fn glb_cyclic_node_hierarchy() {
    let t = tempfile::tempdir().unwrap();
    for (case, nodes, scene_nodes, problem) in [
        (
            "self",
            json!([{"mesh": 0, "children": [0]}]),
            json!([0]),
            "node 0 has more than one parent or is its own child",
        ),
        (
            "twice",
            json!([{"mesh": 0, "children": [1, 1]}, {"mesh": 0}]),
            json!([0]),
            "node 1 has more than one parent",
        ),
        (
            "pair",
            json!([{"mesh": 0, "children": [1]}, {"children": [0]}]),
            json!([0]),
            "scene root node 0 is also a child of node 1",
        ),
    ] {
        let b = edited_glb(false, |j, _| {
            j["nodes"] = nodes;
            j["scenes"] = json!([{"nodes": scene_nodes}]);
        });
        let d = sample(t.path(), case, &b);
        rejects(&d, "object_a.glb", problem);
    }
}

#[test]
fn glb_buffer_uri_escaping_the_scene_folder() {
    let t = tempfile::tempdir().unwrap();
    let (_, bin) = split_glb(&box_glb(false));
    fs::write(t.path().join("secret.bin"), &bin).unwrap();
    for (case, uri, problem) in [
        ("up", "../../secret.bin", "points outside the scene folder"),
        ("abs", "/etc/passwd", "is an absolute path"),
        ("file", "file:///etc/passwd", "is a URI"),
        ("http", "https://example.com/x.bin", "is a URI"),
    ] {
        let b = edited_glb(false, |j, bin| {
            j["buffers"][0]["uri"] = json!(uri);
            bin.clear();
        });
        let d = sample(t.path(), case, &b);
        rejects(&d, "object_a.glb", problem);
    }
    // Percent-encoded dots are decoded before the check; a `%` before a multi-byte character
    // (which once split the character and panicked) is kept as it is.
    for (case, uri, problem) in [
        (
            "pct",
            "%2e%2e/%2E%2E/secret.bin",
            "points outside the scene folder",
        ),
        ("utf8", "%a\u{e9}.bin", "cannot open"),
    ] {
        let b = edited_glb(false, |j, bin| {
            j["buffers"][0]["uri"] = json!(uri);
            bin.clear();
        });
        let d = sample(t.path(), case, &b);
        rejects(&d, "object_a.glb", problem);
    }
    // Through a symbolic link inside the folder that points out of it.
    let b = edited_glb(false, |j, bin| {
        j["buffers"][0]["uri"] = json!("link.bin");
        bin.clear();
    });
    let d = sample(t.path(), "link", &b);
    std::os::unix::fs::symlink(t.path().join("secret.bin"), d.join("link.bin")).unwrap();
    rejects(&d, "object_a.glb", "resolves (through a link) outside");
}

#[test]
fn glb_image_uri_escaping_the_scene_folder() {
    let t = tempfile::tempdir().unwrap();
    fs::write(t.path().join("secret.png"), png()).unwrap();
    let b = edited_glb(true, |j, _| {
        j["images"][0] = json!({"uri": "../../secret.png"});
    });
    let d = sample(t.path(), "img", &b);
    rejects(&d, "object_a.glb", "points outside the scene folder");
}

#[test]
fn gltf_huge_data_uri() {
    let t = tempfile::tempdir().unwrap();
    use base64::Engine;
    let (mut j, bin) = split_glb(&box_glb(false));
    let mut big = bin.clone();
    big.resize(600_000, 0);
    j["buffers"][0] = json!({
        "byteLength": big.len(),
        "uri": format!("data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&big)),
    });
    let text = serde_json::to_vec(&j).unwrap();
    let d = manifest(t.path(), "data", &[("box.gltf", &text)], "box.gltf");
    rejects_with(
        &d,
        &["--max-file-bytes", "500000"],
        "box.gltf",
        "over the limit of 500000 bytes (--max-file-bytes)",
    );
    // Not base64, and broken base64.
    j["buffers"][0]["uri"] = json!("data:application/octet-stream,rawbytes");
    let d = manifest(
        t.path(),
        "plain",
        &[("box.gltf", &serde_json::to_vec(&j).unwrap())],
        "box.gltf",
    );
    rejects(&d, "box.gltf", "data: URI is not base64-encoded");
    j["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,%%%%");
    let d = manifest(
        t.path(),
        "b64",
        &[("box.gltf", &serde_json::to_vec(&j).unwrap())],
        "box.gltf",
    );
    rejects(&d, "box.gltf", "data: URI is not valid base64");
}

#[test]
fn glb_missing_texture_image() {
    let t = tempfile::tempdir().unwrap();
    let b = edited_glb(true, |j, _| j["images"][0] = json!({"uri": "missing.png"}));
    let d = sample(t.path(), "missing", &b);
    rejects(&d, "object_a.glb", "\"missing.png\": cannot open");
}

#[test]
fn glb_image_without_mime_type_or_source() {
    // Found by fuzzing (fuzz target glb): "mimeType" misspelt, so an image in a buffer view had
    // none, and the gltf crate unwrapped it (a panic). Also: no source at all, and both.
    let t = tempfile::tempdir().unwrap();
    for (case, edit, problem) in [
        (
            "mime",
            json!({"bufferView": 4, "mimeVype": "image/png"}),
            "image 0 is stored in a buffer view but has no mimeType",
        ),
        (
            "none",
            json!({"name": "x"}),
            "image 0 has neither a uri nor a bufferView",
        ),
        (
            "both",
            json!({"bufferView": 4, "mimeType": "image/png", "uri": "x.png"}),
            "image 0 has both a uri and a bufferView",
        ),
    ] {
        let b = edited_glb(true, |j, _| {
            let view = j["images"][0]["bufferView"].clone();
            let mut img = edit;
            if img.get("bufferView").is_some() {
                img["bufferView"] = view;
            }
            j["images"][0] = img;
        });
        let d = sample(t.path(), case, &b);
        rejects(&d, "object_a.glb", problem);
    }
}

#[test]
fn glb_corrupt_texture_image() {
    let t = tempfile::tempdir().unwrap();
    let image_range = |j: &Value| {
        let v = j["images"][0]["bufferView"].as_u64().unwrap() as usize;
        let off = j["bufferViews"][v]["byteOffset"].as_u64().unwrap_or(0) as usize;
        let len = j["bufferViews"][v]["byteLength"].as_u64().unwrap() as usize;
        off..off + len
    };
    // Not an image at all.
    let b = edited_glb(true, |j, bin| {
        let r = image_range(j);
        bin[r].fill(b'x');
    });
    let d = sample(t.path(), "garbage", &b);
    rejects(&d, "object_a.glb#image0", "not a recognised image");
    // A PNG signature followed by garbage.
    let b = edited_glb(true, |j, bin| {
        let r = image_range(j);
        bin[r.start + 8..r.end].fill(0xAB);
    });
    let d = sample(t.path(), "header", &b);
    rejects(&d, "object_a.glb#image0", "corrupt texture image");
}

#[test]
fn glb_draco_compression_is_refused_by_name() {
    let t = tempfile::tempdir().unwrap();
    let b = edited_glb(false, |j, _| {
        j["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
        j["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    });
    let d = sample(t.path(), "draco", &b);
    rejects(&d, "object_a.glb", "Draco mesh compression");
    let b = edited_glb(false, |j, _| {
        j["extensionsUsed"] = json!(["EXT_meshopt_compression"]);
        j["extensionsRequired"] = json!(["EXT_meshopt_compression"]);
    });
    let d = sample(t.path(), "meshopt", &b);
    rejects(&d, "object_a.glb", "meshopt compression");
}

// ---------------------------------------------------------------------------------------------
// OBJ / MTL

#[test]
fn obj_index_zero() {
    let t = tempfile::tempdir().unwrap();
    let d = obj_scene(t.path(), "zero", &(box_obj() + "f 0 1 2\n"));
    rejects(&d, "box.obj", "face vertex index 0 out of range");
    // Negative but reaching before the first vertex.
    let d = obj_scene(t.path(), "neg", &(box_obj() + "f -1 -2 -9\n"));
    rejects(&d, "box.obj", "face vertex index -9 out of range");
    // The most negative 64-bit index (its negation overflowed).
    let d = obj_scene(
        t.path(),
        "min",
        &(box_obj() + "f 1 2 -9223372036854775808\n"),
    );
    rejects(
        &d,
        "box.obj",
        "face vertex index -9223372036854775808 out of range",
    );
}

#[test]
fn obj_negative_relative_indices_and_ngons_read_correctly() {
    let t = tempfile::tempdir().unwrap();
    let m = cuboid(0.1, 0.2, 0.3);
    // Relative indices: each face given after all 8 vertices, counted from the end.
    let mut neg = String::new();
    for v in &m.vertices {
        neg += &format!("v {} {} {}\n", v.x, v.y, v.z);
    }
    for tri in &m.triangles {
        let r = |i: u32| i as i64 - 8;
        neg += &format!("f {} {} {}\n", r(tri[0]), r(tri[1]), r(tri[2]));
    }
    let a = export_ok(&obj_scene(t.path(), "neg", &neg), &t.path().join("out_neg"));
    let b = export_ok(
        &obj_scene(t.path(), "pos", &box_obj()),
        &t.path().join("out_pos"),
    );
    // Quads and a hexagon-free prism: the same box written with 6 quads.
    let quads = "v -0.05 -0.1 -0.15\nv 0.05 -0.1 -0.15\nv 0.05 0.1 -0.15\nv -0.05 0.1 -0.15\n\
                 v -0.05 -0.1 0.15\nv 0.05 -0.1 0.15\nv 0.05 0.1 0.15\nv -0.05 0.1 0.15\n\
                 f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    let c = export_ok(
        &obj_scene(t.path(), "quads", quads),
        &t.path().join("out_quads"),
    );
    let mass = 1000.0 * 0.1 * 0.2 * 0.3;
    for r in [&a, &b, &c] {
        let o = &r["objects"][0];
        assert!((o["mass"].as_f64().unwrap() - mass).abs() < 1e-9, "{o}");
        assert_eq!(o["volume_source"], "closed_mesh");
        assert_eq!(o["triangles"], 12);
    }
    // An octagon fan: one n-gon face closing a prism top and bottom.
    let n = 8;
    let mut s = String::new();
    for z in [0.0, 0.1] {
        for k in 0..n {
            let a = k as f64 * std::f64::consts::TAU / n as f64;
            s += &format!("v {} {} {z}\n", 0.05 * a.cos(), 0.05 * a.sin());
        }
    }
    s += &format!(
        "f {}\n",
        (1..=n)
            .rev()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    );
    s += &format!(
        "f {}\n",
        (n + 1..=2 * n)
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    );
    for k in 0..n {
        let (a, b) = (k + 1, (k + 1) % n + 1);
        s += &format!("f {a} {b} {} {}\n", b + n, a + n);
    }
    let r = export_ok(
        &obj_scene(t.path(), "octagon", &s),
        &t.path().join("out_oct"),
    );
    let o = &r["objects"][0];
    assert_eq!(o["volume_source"], "closed_mesh", "{o}");
    let area = 0.5 * n as f64 * 0.05f64.powi(2) * (std::f64::consts::TAU / n as f64).sin();
    assert!(
        (o["volume"].as_f64().unwrap() - area * 0.1).abs() < 1e-9,
        "{o}"
    );
}

#[test]
fn obj_missing_or_escaping_mtl_and_texture() {
    let t = tempfile::tempdir().unwrap();
    let d = obj_scene(
        t.path(),
        "mtl",
        &("mtllib missing.mtl\n".to_string() + &box_obj()),
    );
    rejects(&d, "box.obj", "\"missing.mtl\": cannot open");
    fs::write(t.path().join("evil.mtl"), "newmtl m\nKd 1 0 0\n").unwrap();
    let d = obj_scene(
        t.path(),
        "mtl_up",
        &("mtllib ../../../evil.mtl\n".to_string() + &box_obj()),
    );
    rejects(&d, "box.obj", "outside the scene folder");
    let d = manifest(
        t.path(),
        "tex_abs",
        &[
            (
                "meshes/box.obj",
                ("mtllib box.mtl\nusemtl m\n".to_string() + &box_obj()).as_bytes(),
            ),
            (
                "meshes/box.mtl",
                b"newmtl m\nKd 1 1 1\nmap_Kd /etc/passwd\n",
            ),
        ],
        "meshes/box.obj",
    );
    rejects(&d, "box.obj", "is an absolute path");
    // A texture that is not an image.
    let d = manifest(
        t.path(),
        "tex_bad",
        &[
            (
                "meshes/box.obj",
                ("mtllib box.mtl\nusemtl m\n".to_string() + &box_obj()).as_bytes(),
            ),
            ("meshes/box.mtl", b"newmtl m\nKd 1 1 1\nmap_Kd skin.png\n"),
            ("meshes/skin.png", b"\x89PNG\r\n\x1a\nthis is not a png"),
        ],
        "meshes/box.obj",
    );
    rejects(&d, "skin.png", "corrupt texture image");
}

#[test]
fn obj_infinite_and_absurd_coordinates() {
    let t = tempfile::tempdir().unwrap();
    let d = obj_scene(
        t.path(),
        "inf",
        &box_obj()
            .replacen("v ", "v inf ", 1)
            .replacen("inf -0.05", "inf", 1),
    );
    rejects(&d, "box.obj", "NaN or infinite");
    let d = obj_scene(
        t.path(),
        "overflow",
        &box_obj().replacen("v -0.05", "v 1e999", 1),
    );
    rejects(&d, "box.obj", "NaN or infinite");
    let d = obj_scene(
        t.path(),
        "absurd",
        &box_obj().replacen("v -0.05", "v 1e30", 1),
    );
    rejects(&d, "box.obj", "out of range (|x| > 1e12)");
}

// ---------------------------------------------------------------------------------------------
// STL

#[test]
fn stl_triangle_count_not_matching_the_size() {
    let t = tempfile::tempdir().unwrap();
    let m = cuboid(0.1, 0.2, 0.3);
    for (case, declared, problem) in [
        (
            "more",
            11,
            "declares 11 triangles (634 bytes) but the file has 684 bytes",
        ),
        ("huge", u32::MAX, "declares 4294967295 triangles"),
    ] {
        let d = manifest(
            t.path(),
            case,
            &[("box.stl", &stl_bytes(&m, declared))],
            "box.stl",
        );
        rejects(&d, "box.stl", problem);
    }
    let d = manifest(t.path(), "short", &[("box.stl", &[7u8; 40])], "box.stl");
    rejects(&d, "box.stl", "40 bytes is too short for a binary STL");
    let ascii = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n";
    let d = manifest(
        t.path(),
        "ascii",
        &[("box.stl", ascii.as_bytes())],
        "box.stl",
    );
    rejects(&d, "box.stl", "ends inside a facet (truncated)");
}

// ---------------------------------------------------------------------------------------------
// Geometry

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

// ---------------------------------------------------------------------------------------------
// metadata.json and scene.json

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

// ---------------------------------------------------------------------------------------------
// Names in the output, limits

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

// ---------------------------------------------------------------------------------------------
// Batch and determinism

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
