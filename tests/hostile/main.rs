//! Hostile and broken inputs (issue #7): every loader and writer refuses bad input with exit
//! code 2 and one line naming the file and the problem, never panics, creates no output folder
//! and leaves the inputs untouched; references never reach outside the scene folder; size limits
//! are options with their own errors; names from input files cannot inject XML or escape OUT.
//! Every input is built here, in code. The cases already in `tests/export.rs`
//! (`bad_inputs_exit_2_with_one_line_and_no_output`) are not repeated.
//!
//! One file per kind of input: `gltf` (GLB and glTF containers), `obj` (OBJ and MTL), `stl`,
//! `geometry` (degenerate, open, non-manifold, tiny and huge meshes), `metadata`
//! (metadata.json, scene.json, manifests, paths and symlinks), `names` (names written into the
//! output, size limits), `batch` (hostile scenes inside a dataset). The builders of inputs they
//! share are below.

#[path = "../batch_data/mod.rs"]
mod batch_data;
use batch_data::obj_text;
#[path = "../common/mod.rs"]
mod common;

use common::*;
use interact3d::mesh::{Material, Mesh, Texture, VisualMesh, VisualPart, V3};
use serde_json::{json, Value};
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::Arc;

mod batch;
mod geometry;
mod gltf;
mod metadata;
mod names;
mod obj;
mod stl;

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
