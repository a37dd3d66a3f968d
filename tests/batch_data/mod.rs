//! Generated datasets in the Interact3D layout `outputs/<category>/<id>_<slug>/`, for the batch
//! tests (`tests/batch.rs`) and the benchmark (`examples/bench_batch.rs`, which includes this
//! file by path).
//!
//! Every good scene is two objects: a box lying on the ground and a flat or a tall box
//! resting on it with a 0.75 mm gap, sizes and yaw varying with the scene number. Even-numbered
//! scenes are sample folders (`object_a.glb`, `object_b.glb`, `metadata.json`, Y-up), odd ones
//! `scene.json` manifests with OBJ meshes (Z-up). Output is deterministic.
#![allow(dead_code)]

use interact3d::mesh::{Material, Mesh, VisualMesh, VisualPart, V3};
use nalgebra::{Matrix3, Matrix4, Vector3};
use serde_json::json;
use std::fs;
use std::path::Path;

/// The nine categories of the Interact3D dataset's layout.
pub const CATEGORIES: [&str; 9] = [
    "apparel",
    "electronics",
    "food",
    "household",
    "kitchenware",
    "office",
    "sports",
    "stationery",
    "toys",
];

/// What to generate.
#[derive(Clone, Copy, Debug, Default)]
pub struct Spec {
    /// Scenes that pass validation.
    pub good: usize,
    /// Scenes whose collision hulls interpenetrate by 5 mm (validation fails).
    pub failing: usize,
    /// Add two unreadable scenes: malformed metadata.json, and a corrupt GLB.
    pub broken: bool,
}

/// One generated scene.
#[derive(Clone, Debug)]
pub struct Made {
    /// Relative path under the dataset root.
    pub rel: String,
    /// "pass", "fail" or "error".
    pub verdict: &'static str,
}

const GAP: f64 = 0.00075;

/// Generate `spec` under `root` (the folder that will be given as ROOT; scenes go into
/// `root/outputs/...`). Returns the scenes sorted by relative path.
pub fn make_dataset(root: &Path, spec: Spec) -> Vec<Made> {
    let mut made = Vec::new();
    let n = spec.good + spec.failing;
    for i in 0..n {
        let failing = i >= spec.good;
        let cat = CATEGORIES[i % CATEGORIES.len()];
        let top_is_tall = i % 3 == 2;
        let slug = match (failing, top_is_tall) {
            (true, _) => "overlap_boxes",
            (false, true) => "tower_on_box",
            (false, false) => "box_on_box",
        };
        let rel = format!("outputs/{cat}/{:05}_{slug}", i + 1);
        let dir = root.join(&rel);
        fs::create_dir_all(&dir).unwrap();
        let scene = two_objects(i, failing, top_is_tall);
        if i % 2 == 0 {
            write_sample(&dir, cat, &scene);
        } else {
            write_manifest(&dir, &rel, &scene);
        }
        made.push(Made {
            rel,
            verdict: if failing { "fail" } else { "pass" },
        });
    }
    if spec.broken {
        // Malformed metadata.json.
        let rel = format!("outputs/{}/{:05}_broken_metadata", CATEGORIES[0], n + 1);
        let dir = root.join(&rel);
        fs::create_dir_all(&dir).unwrap();
        let scene = two_objects(0, false, false);
        write_sample(&dir, CATEGORIES[0], &scene);
        fs::write(
            dir.join("metadata.json"),
            b"{\"registration\": {\"transforms\": ",
        )
        .unwrap();
        made.push(Made {
            rel,
            verdict: "error",
        });
        // A GLB that is not one.
        let rel = format!("outputs/{}/{:05}_corrupt_glb", CATEGORIES[4], n + 2);
        let dir = root.join(&rel);
        fs::create_dir_all(&dir).unwrap();
        write_sample(&dir, CATEGORIES[4], &scene);
        fs::write(dir.join("object_b.glb"), b"glTF\x02\x00\x00\x00 truncated").unwrap();
        made.push(Made {
            rel,
            verdict: "error",
        });
    }
    made.sort_by(|a, b| a.rel.cmp(&b.rel));
    made
}

/// Two objects in a Z-up world (metres): meshes in their own frames and their poses.
struct TwoObjects {
    meshes: [Mesh; 2],
    labels: [&'static str; 2],
    poses: [Matrix4<f64>; 2],
}

fn two_objects(i: usize, failing: bool, tall: bool) -> TwoObjects {
    let k = i as f64;
    let base = V3::new(
        0.20 + 0.01 * (k % 5.0),
        0.15 + 0.01 * (k % 3.0),
        0.03 + 0.002 * (k % 4.0),
    );
    let (top, top_h) = if tall {
        let e = V3::new(
            0.03 + 0.002 * (k % 4.0),
            0.035 + 0.002 * (k % 3.0),
            0.08 + 0.005 * (k % 3.0),
        );
        (interact3d::shapes::cuboid(e), e.z)
    } else {
        let e = V3::new(
            0.06 + 0.004 * (k % 4.0),
            0.04 + 0.003 * (k % 5.0),
            0.05 + 0.004 * (k % 3.0),
        );
        (interact3d::shapes::cuboid(e), e.z)
    };
    let gap = if failing { -0.005 } else { GAP };
    let yaw = (k * 23.0 % 90.0).to_radians();
    let base_pose = Matrix4::new_translation(&Vector3::new(0.0, 0.0, base.z / 2.0));
    let top_pose = Matrix4::new_translation(&Vector3::new(
        0.01 * (k % 3.0 - 1.0),
        0.01 * (k % 2.0),
        base.z + gap + top_h / 2.0,
    )) * Matrix4::from_axis_angle(&Vector3::z_axis(), yaw);
    TwoObjects {
        meshes: [interact3d::shapes::cuboid(base), top],
        labels: ["base", if tall { "tower" } else { "box" }],
        poses: [base_pose, top_pose],
    }
}

/// Z-up → Y-up (−90° about x): (x, y, z) → (x, z, −y).
fn z_to_y() -> Matrix3<f64> {
    Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0)
}

fn rows(m: &Matrix4<f64>) -> serde_json::Value {
    json!((0..4)
        .map(|r| (0..4).map(|c| m[(r, c)]).collect::<Vec<_>>())
        .collect::<Vec<_>>())
}

fn visual(mesh: &Mesh, rgb: [f64; 3]) -> VisualMesh {
    VisualMesh {
        parts: vec![VisualPart {
            positions: mesh.vertices.clone(),
            uvs: None,
            triangles: mesh.triangles.clone(),
            material: Material {
                name: "paint".into(),
                base_color: [rgb[0], rgb[1], rgb[2], 1.0],
                texture: None,
            },
        }],
    }
}

fn write_sample(dir: &Path, category: &str, s: &TwoObjects) {
    let c = z_to_y();
    let mut c4 = Matrix4::identity();
    c4.fixed_view_mut::<3, 3>(0, 0).copy_from(&c);
    let mut transforms = serde_json::Map::new();
    let mut analysis = serde_json::Map::new();
    for (k, name) in ["object_a", "object_b"].iter().enumerate() {
        let m = s.meshes[k].transformed(&c4);
        let colour = if k == 0 {
            [0.6, 0.4, 0.2]
        } else {
            [0.2, 0.5, 0.8]
        };
        interact3d::io::write_glb(&visual(&m, colour), &dir.join(format!("{name}.glb"))).unwrap();
        // Pose in the Y-up scene: C · M · C⁻¹ (the mesh is already C · v).
        let pose = c4 * s.poses[k] * c4.transpose();
        transforms.insert(name.to_string(), json!({ "matrix": rows(&pose) }));
        analysis.insert(name.to_string(), json!(s.labels[k]));
    }
    analysis.insert("category".into(), json!(category));
    let meta = json!({
        "category": category,
        "analysis": analysis,
        "registration": { "status": "success", "transforms": transforms },
    });
    fs::write(
        dir.join("metadata.json"),
        serde_json::to_vec_pretty(&meta).unwrap(),
    )
    .unwrap();
}

/// OBJ text of a mesh (1-based indices).
pub fn obj_text(m: &Mesh) -> String {
    let mut s = String::new();
    for v in &m.vertices {
        s += &format!("v {} {} {}\n", v.x, v.y, v.z);
    }
    for t in &m.triangles {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

fn write_manifest(dir: &Path, rel: &str, s: &TwoObjects) {
    fs::create_dir_all(dir.join("meshes")).unwrap();
    let mut objects = Vec::new();
    for k in 0..2 {
        let name = s.labels[k];
        fs::write(
            dir.join(format!("meshes/{name}.obj")),
            obj_text(&s.meshes[k]),
        )
        .unwrap();
        objects.push(json!({
            "name": name,
            "mesh": format!("meshes/{name}.obj"),
            "label": name,
            "pose": { "matrix": rows(&s.poses[k]) },
        }));
    }
    let name = rel.rsplit('/').next().unwrap();
    let manifest = json!({
        "format": "interact3d-scene",
        "version": 1,
        "name": name,
        "units": "m",
        "up_axis": "z",
        "objects": objects,
    });
    fs::write(
        dir.join("scene.json"),
        serde_json::to_vec_pretty(&manifest).unwrap(),
    )
    .unwrap();
}
