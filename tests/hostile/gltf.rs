//! Hostile inputs: GLB / glTF containers.

use super::*;

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
