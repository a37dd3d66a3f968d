//! Generates the small test scenes in `fixtures/` (run from the repository root):
//!
//! ```text
//! cargo run --example make_fixtures            # writes fixtures/
//! cargo run --example make_fixtures -- OUT_DIR # writes elsewhere
//! ```
//!
//! Every pose is computed analytically from the shapes' own dimensions (the one exception is the
//! horizontal spacing of the fruits, found by bisection on the exact mesh distance), then checked
//! here on the files as written: each GLB is read back with the `gltf` crate, its matrix applied,
//! and the exact minimum distance between all pairs of triangle meshes measured (vertex-triangle
//! and edge-edge distances plus an edge-through-triangle test). The run panics if a passing scene
//! has a contact gap outside [0.5, 1.0] mm, a pair closer than 0.5 mm, or an item that cannot
//! rest. Output is deterministic: running twice gives identical bytes.

use interact3d::fsutil::write_atomically as write_atomic;
use interact3d::io::{write_glb_with, GlbOptions};
use interact3d::mesh::{Mesh, VisualMesh, P3, V3};
use interact3d::pose::Similarity;
use interact3d::shapes::{self, UvProjection};
use nalgebra::{Matrix3, Matrix4, UnitQuaternion, Vector3};
use serde_json::{json, Value};
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Target gap at every resting contact (metres).
const GAP: f64 = 0.00075;
/// Density for the masses quoted in the READMEs (kg/m³).
const DENSITY: f64 = 1000.0;
const TEX: u32 = 64;

// ---------------------------------------------------------------------------------------------
// Exact geometry checks.

/// Distance between two triangles (0 when they intersect), by the library's exact test, the one
/// the validation's metrics use.
fn triangle_distance(a: &[P3; 3], b: &[P3; 3]) -> f64 {
    let v = |t: &[P3; 3]| t.map(|p| [p.x, p.y, p.z]);
    interact3d::metrics::tri_tri_dist2(&v(a), &v(b)).sqrt()
}

struct TriSet {
    tris: Vec<[P3; 3]>,
    boxes: Vec<(P3, P3)>,
}

impl TriSet {
    fn of(m: &Mesh, keep: impl Fn(&[P3; 3]) -> bool) -> TriSet {
        let tris: Vec<[P3; 3]> = (0..m.triangles.len())
            .map(|i| m.triangle(i))
            .filter(|t| keep(t))
            .collect();
        let boxes = tris
            .iter()
            .map(|t| (t[0].inf(&t[1]).inf(&t[2]), t[0].sup(&t[1]).sup(&t[2])))
            .collect();
        TriSet { tris, boxes }
    }
    fn all(m: &Mesh) -> TriSet {
        TriSet::of(m, |_| true)
    }
}

fn box_gap(a: &(P3, P3), b: &(P3, P3)) -> f64 {
    let mut s = 0.0;
    for i in 0..3 {
        let d = (a.0[i] - b.1[i]).max(b.0[i] - a.1[i]).max(0.0);
        s += d * d;
    }
    s.sqrt()
}

/// Exact minimum distance between two triangle sets (0 when their surfaces intersect).
fn set_distance(a: &TriSet, b: &TriSet) -> f64 {
    let mut best = f64::INFINITY;
    for (ta, ba) in a.tris.iter().zip(&a.boxes) {
        for (tb, bb) in b.tris.iter().zip(&b.boxes) {
            if box_gap(ba, bb) < best {
                best = best.min(triangle_distance(ta, tb));
            }
        }
    }
    best
}

fn mesh_distance(a: &Mesh, b: &Mesh) -> f64 {
    set_distance(&TriSet::all(a), &TriSet::all(b))
}

/// Volume and centre of mass of a closed mesh.
fn mass_props(m: &Mesh) -> (f64, P3) {
    let mut v = 0.0;
    let mut c = V3::zeros();
    for i in 0..m.triangles.len() {
        let [a, b, cc] = m.triangle(i);
        let dv = a.coords.dot(&b.coords.cross(&cc.coords)) / 6.0;
        v += dv;
        c += (a.coords + b.coords + cc.coords) * (dv / 4.0);
    }
    (v, P3::from(c / v))
}

/// Signed distance from 2D point `p` to the boundary of the convex hull of `pts` (positive
/// inside). The hull is built by gift wrapping; fine for the few points of a contact face.
fn inside_margin_2d(pts: &[[f64; 2]], p: [f64; 2]) -> f64 {
    let mut hull: Vec<[f64; 2]> = Vec::new();
    let start = (0..pts.len())
        .min_by(|&i, &j| pts[i].partial_cmp(&pts[j]).unwrap())
        .unwrap();
    let mut cur = start;
    loop {
        hull.push(pts[cur]);
        let mut next = (cur + 1) % pts.len();
        for k in 0..pts.len() {
            let (a, b, c) = (pts[cur], pts[next], pts[k]);
            let cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            if cross < 0.0 {
                next = k;
            }
        }
        cur = next;
        if cur == start || hull.len() > pts.len() {
            break;
        }
    }
    let n = hull.len();
    (0..n)
        .map(|i| {
            let (a, b) = (hull[i], hull[(i + 1) % n]);
            let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
            (ex * (p[1] - a[1]) - ey * (p[0] - a[0])) / ex.hypot(ey)
        })
        .fold(f64::INFINITY, f64::min)
}

/// For an item resting on a flat face (Z-up world mesh): the face's vertices are the lowest
/// ones; returns how far inside that face the centre of mass projects (m, positive = stable).
fn face_rest_margin(world: &Mesh) -> f64 {
    let zmin = world.aabb().unwrap().min.z;
    let low: Vec<[f64; 2]> = world
        .vertices
        .iter()
        .filter(|p| p.z - zmin < 1e-9)
        .map(|p| [p.x, p.y])
        .collect();
    assert!(low.len() >= 3, "item does not rest on a face");
    let (_, com) = mass_props(world);
    inside_margin_2d(&low, [com.x, com.y])
}

// ---------------------------------------------------------------------------------------------
// Scene model.

/// One object: its mesh in its own frame (Z-up, metres), the textured visual of the same mesh,
/// and its pose in the Z-up world (scale 1).
struct Obj {
    key: String,
    label: String,
    description: String,
    mesh: Mesh,
    visual: VisualMesh,
    pose: Similarity,
}

impl Obj {
    fn new(
        key: &str,
        label: &str,
        description: String,
        mesh: Mesh,
        proj: UvProjection,
        texture: interact3d::mesh::Texture,
        pose: Similarity,
    ) -> Obj {
        let visual = shapes::visual(&mesh, proj, shapes::textured_material(label, texture));
        Obj {
            key: key.into(),
            label: label.into(),
            description,
            mesh,
            visual,
            pose,
        }
    }
    fn world_z(&self) -> Mesh {
        self.mesh.transformed(&self.pose.matrix())
    }
}

fn pose(t: V3, q: UnitQuaternion<f64>) -> Similarity {
    Similarity {
        scale: 1.0,
        rotation: q,
        translation: t,
    }
}

fn yaw(deg: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), deg.to_radians())
}

/// Rotation taking the Z-up frame to the Y-up frame: (x, y, z) ↦ (x, z, −y).
fn z_to_y() -> Matrix3<f64> {
    Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0)
}

fn r6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

fn mm(x: f64) -> String {
    format!("{:.3}", x * 1000.0)
}

fn rows3(m: &Matrix3<f64>) -> Value {
    json!((0..3)
        .map(|i| (0..3).map(|j| m[(i, j)]).collect::<Vec<_>>())
        .collect::<Vec<_>>())
}

fn rows4(m: &Matrix4<f64>) -> Value {
    json!((0..4)
        .map(|i| (0..4).map(|j| m[(i, j)]).collect::<Vec<_>>())
        .collect::<Vec<_>>())
}

fn write_text(path: &Path, text: &str) {
    write_atomic(path, text.as_bytes()).unwrap_or_else(|e| panic!("{e}"));
}

fn write_json(path: &Path, v: &Value) {
    let mut s = serde_json::to_string_pretty(v).unwrap();
    s.push('\n');
    write_text(path, &s);
}

/// A contact the scene is built around: objects `a` and `b` (indices), the triangles of `b`
/// that make it (a filter on the Y-up world triangle), and what it is.
struct Contact {
    a: usize,
    b: usize,
    what: &'static str,
    filter: TriFilter,
}

type TriFilter = Box<dyn Fn(&[P3; 3]) -> bool>;

/// A triangle filter on Y-up world triangles that tests each vertex in the own (Z-up) frame of
/// the object posed by `pose_z` in the Z-up world.
fn local_filter(pose_z: &Similarity, f: impl Fn(&P3) -> bool + 'static) -> TriFilter {
    let mut a4 = Matrix4::identity();
    a4.fixed_view_mut::<3, 3>(0, 0).copy_from(&z_to_y());
    let inv = (a4 * pose_z.matrix()).try_inverse().unwrap();
    Box::new(move |t: &[P3; 3]| t.iter().all(|p| f(&inv.transform_point(p))))
}

/// What a written scene measured.
struct Measured {
    /// Per pair (i, j): exact minimum distance between the world meshes as written.
    pairs: Vec<(usize, usize, f64)>,
    /// Per designed contact: exact gap.
    contacts: Vec<(String, f64)>,
}

// ---------------------------------------------------------------------------------------------
// Sample-folder scenes (Interact3D layout, Y-up GLBs normalised to a unit cube).

#[allow(clippy::too_many_arguments)]
fn write_sample_folder(
    dir: &Path,
    category: &str,
    prompt: &str,
    slug: &str,
    objs: &[Obj],
    contacts: &[Contact],
    notes: &str,
    facts: &str,
) -> Measured {
    std::fs::create_dir_all(dir).unwrap();
    let a = z_to_y();
    let mut transforms = serde_json::Map::new();
    let mut gt_objects = serde_json::Map::new();
    let mut world_y: Vec<Mesh> = Vec::new();
    let mut rows = String::new();
    for (i, o) in objs.iter().enumerate() {
        // GLB frame: Y-up, centred on the bounding-box centre, longest extent 1.
        let mut vis = o.visual.clone();
        let mut rot = Matrix4::identity();
        rot.fixed_view_mut::<3, 3>(0, 0).copy_from(&a);
        vis.transform(&rot);
        let bb = vis.geometry().aabb().unwrap();
        let c = bb.center();
        let ext = bb.extents();
        let s = ext.max();
        let norm = Matrix4::new_scaling(1.0 / s) * Matrix4::new_translation(&(-c.coords));
        vis.transform(&norm);
        let path = dir.join(format!("{}.glb", o.key));
        let (vol, com_local) = mass_props(&o.mesh);
        write_glb_with(
            &vis,
            &path,
            &GlbOptions {
                name: Some(o.key.clone()),
                copyright: Some(
                    "Procedural test fixture generated by interact3d (examples/make_fixtures.rs); CC0-1.0"
                        .into(),
                ),
                extras: Some(json!({
                    "label": o.label,
                    "source": "procedural",
                    "normalisation": {
                        "centre_m": [c.x, c.y, c.z],
                        "scale_m": s,
                        "frame": "+Y up; the shape's Z-up frame rotated by (x, y, z) -> (x, z, -y), then centred and divided by scale_m"
                    }
                })),
            },
        )
        .unwrap_or_else(|e| panic!("{e}"));
        // p_world(Y-up) = s · R_y · p_glb + t with R_y = A R_z Aᵀ, t = R_y c + A t_z.
        let rz = o.pose.rotation.to_rotation_matrix().into_inner();
        let ry = a * rz * a.transpose();
        let t = ry * c.coords + a * o.pose.translation;
        let mut m = Matrix4::identity();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&(ry * s));
        m.fixed_view_mut::<3, 1>(0, 3).copy_from(&t);
        let method = if i == 0 {
            "analytic_support_rest"
        } else {
            "analytic_rest_pose"
        };
        transforms.insert(
            o.key.clone(),
            json!({
                "method": method,
                "scale": s,
                "rotation": rows3(&ry),
                "translation": [t.x, t.y, t.z],
                "matrix": rows4(&m),
            }),
        );
        let split = Similarity::from_matrix(&m).unwrap();
        assert!((split.scale - s).abs() < 1e-12 && (split.matrix() - m).abs().max() < 1e-12);
        // Read back what was written and pose it.
        let bytes = std::fs::read(&path).unwrap();
        let (doc, buffers, images) = gltf::import_slice(&bytes).unwrap();
        assert_eq!(images.len(), 1);
        assert!(images[0].width <= 128 && images[0].height <= 128);
        let mut back = Mesh::default();
        for prim in doc.meshes().next().unwrap().primitives() {
            let r = prim.reader(|b| Some(&buffers[b.index()]));
            let pos: Vec<P3> = r
                .read_positions()
                .unwrap()
                .map(|p| P3::new(p[0] as f64, p[1] as f64, p[2] as f64))
                .collect();
            assert!(r.read_tex_coords(0).is_some());
            let idx: Vec<u32> = r.read_indices().unwrap().into_u32().collect();
            let tris = idx.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
            back.append(&Mesh::new(pos, tris));
        }
        let back = back.welded(0.0);
        assert!(back.is_closed(), "{}: GLB geometry is not closed", o.key);
        let gbb = back.aabb().unwrap();
        assert!((gbb.extents().max() - 1.0).abs() < 1e-6);
        assert!(gbb.center().coords.norm() < 1e-6);
        let w = back.transformed(&m);
        let wbb = w.aabb().unwrap();
        let com_world = o.pose.matrix().transform_point(&com_local);
        let com_y = a * com_world.coords;
        gt_objects.insert(
            o.key.clone(),
            json!({
                "label": o.label,
                "role": if i == 0 { "support" } else { "item" },
                "shape": o.description,
                "triangles": o.mesh.triangles.len(),
                "extents_m": [r6(ext.x), r6(ext.y), r6(ext.z)],
                "world_aabb_m": [[r6(wbb.min.x), r6(wbb.min.y), r6(wbb.min.z)], [r6(wbb.max.x), r6(wbb.max.y), r6(wbb.max.z)]],
                "volume_m3": vol,
                "mass_kg_at_1000": vol * DENSITY,
                "centre_of_mass_world_m": [r6(com_y.x), r6(com_y.y), r6(com_y.z)],
            }),
        );
        let _ = writeln!(
            rows,
            "| `{}` | {} | {} | {} | {} × {} × {} | {:.1} | {:.1} | ({}, {}, {}) |",
            o.key,
            o.label,
            o.description,
            o.mesh.triangles.len(),
            mm(ext.x),
            mm(ext.y),
            mm(ext.z),
            vol * 1e6,
            vol * DENSITY * 1000.0,
            mm(com_y.x),
            mm(com_y.y),
            mm(com_y.z),
        );
        if i == 0 {
            assert!(wbb.min.y.abs() < 1e-6, "support not on the ground");
        } else {
            assert!(wbb.min.y > 0.003, "{} not off the ground", o.key);
        }
        world_y.push(w);
    }
    let measured = measure(&world_y, contacts, true);
    let n = objs.len();
    let mut analysis = serde_json::Map::new();
    analysis.insert("category".into(), json!(category));
    for o in objs {
        analysis.insert(o.key.clone(), json!(o.label));
    }
    analysis.insert("scene_slug".into(), json!(slug));
    analysis.insert("category_folder".into(), json!(category));
    analysis.insert("category_source".into(), json!("provided"));
    let mut reg = serde_json::Map::new();
    reg.insert("anchor_object".into(), json!(objs[0].key));
    if n == 2 {
        reg.insert("remaining_object".into(), json!(objs[1].key));
    } else {
        reg.insert(
            "remaining_objects".into(),
            json!(objs[1..].iter().map(|o| o.key.clone()).collect::<Vec<_>>()),
        );
    }
    reg.insert("status".into(), json!("success"));
    reg.insert("clearance".into(), json!(GAP));
    reg.insert("transforms".into(), Value::Object(transforms));
    let metadata = json!({
        "category": category,
        "input": { "scene_prompt": prompt, "category": category },
        "analysis": Value::Object(analysis),
        "prompt": prompt,
        "registration": Value::Object(reg),
    });
    write_json(&dir.join("metadata.json"), &metadata);
    let gt = json!({
        "scene": dir.file_name().unwrap().to_string_lossy(),
        "category": category,
        "prompt": prompt,
        "conventions": {
            "up": "+Y",
            "units": "m",
            "gravity": [0, -9.81, 0],
            "ground_plane_y": 0.0,
            "pose": "p_world = scale * rotation @ p_glb + translation (row-major 4x4 'matrix')",
            "glb_frame": "+Y up, bbox centred at the origin, longest extent 1",
            "target_clearance_m": GAP,
            "density_kg_m3": DENSITY,
        },
        "objects": Value::Object(gt_objects),
        "contacts": measured.contacts.iter().map(|(w, d)| json!({"contact": w, "gap_m": r6(*d * 1e3) / 1e3})).collect::<Vec<_>>(),
        "pairs": measured.pairs.iter().map(|(i, j, d)| json!({"a": objs[*i].key, "b": objs[*j].key, "min_distance_m": r6(*d * 1e3) / 1e3})).collect::<Vec<_>>(),
    });
    write_json(&dir.join("ground_truth.json"), &gt);
    let mut readme = String::new();
    let _ = writeln!(
        readme,
        "# {}\n\n{}\n\n**Expected outcome: passes** (every item at rest, no interpenetration).\n",
        dir.file_name().unwrap().to_string_lossy(),
        prompt
    );
    let _ = writeln!(readme, "Interact3D sample-folder layout (as `shared/datasets/scenes/`): `object_*.glb` (Y-up, centred on the bounding-box centre, longest extent 1, embedded {TEX}x{TEX} PNG texture), `metadata.json` (`p_world = scale · R · p_glb + t`, world +Y up, metres, ground y = 0), `ground_truth.json` (extents, masses, contacts). Generated by `cargo run --example make_fixtures`; do not edit by hand.\n");
    let _ = writeln!(readme, "| object | label | shape (own frame, Z-up, metres) | triangles | extents in GLB frame (mm) | volume (cm³) | mass at {DENSITY} kg/m³ (g) | centre of mass, world (mm) |\n|---|---|---|---:|---|---:|---:|---|");
    readme.push_str(&rows);
    let _ = writeln!(readme, "\n{facts}");
    append_measured(&mut readme, objs, &measured);
    if !notes.is_empty() {
        let _ = writeln!(readme, "\n{notes}");
    }
    write_text(&dir.join("README.md"), &readme);
    measured
}

fn append_measured(readme: &mut String, objs: &[Obj], m: &Measured) {
    let _ = writeln!(readme, "\nExact gaps measured on the files as written (minimum distance between the triangle meshes, vertex-triangle and edge-edge):\n\n| contact | gap (mm) |\n|---|---:|");
    for (w, d) in &m.contacts {
        let _ = writeln!(readme, "| {w} | {} |", mm(*d));
    }
    let _ = writeln!(readme, "\n| pair | minimum distance (mm) |\n|---|---:|");
    for (i, j, d) in &m.pairs {
        let _ = writeln!(
            readme,
            "| {}–{} | {} |",
            objs[*i].label,
            objs[*j].label,
            mm(*d)
        );
    }
}

/// Pairwise exact distances and designed-contact gaps; with `strict`, panic when a contact gap
/// is outside [0.5, 1.0] mm or any pair is closer than 0.5 mm.
fn measure(world: &[Mesh], contacts: &[Contact], strict: bool) -> Measured {
    let mut pairs = Vec::new();
    for i in 0..world.len() {
        for j in i + 1..world.len() {
            let d = mesh_distance(&world[i], &world[j]);
            if strict {
                assert!(d >= 0.0005, "pair {i}-{j} only {d} m apart");
            }
            pairs.push((i, j, d));
        }
    }
    let mut out = Vec::new();
    for c in contacts {
        let d = set_distance(
            &TriSet::all(&world[c.a]),
            &TriSet::of(&world[c.b], |t| (c.filter)(t)),
        );
        if strict {
            assert!(
                (0.0005..=0.001).contains(&d),
                "contact {}: gap {d} m outside [0.5, 1] mm",
                c.what
            );
        }
        out.push((c.what.to_string(), d));
    }
    Measured {
        pairs,
        contacts: out,
    }
}

// ---------------------------------------------------------------------------------------------
// Manifest scenes (our scene.json, Z-up, OBJ + MTL + PNG).

fn fmt_num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x}")
    }
}

/// Write `visual` (one part) as `meshes/<name>.obj` + `.mtl` (+ `.png` when textured).
fn write_obj(dir: &Path, name: &str, visual: &VisualMesh) {
    let mdir = dir.join("meshes");
    std::fs::create_dir_all(&mdir).unwrap();
    let part = &visual.parts[0];
    let mut obj = String::new();
    let _ = writeln!(
        obj,
        "# interact3d fixture mesh '{name}': metres, the object's own frame (Z-up)\nmtllib {name}.mtl\no {name}"
    );
    for p in &part.positions {
        let _ = writeln!(obj, "v {} {} {}", fmt_num(p.x), fmt_num(p.y), fmt_num(p.z));
    }
    if let Some(uvs) = &part.uvs {
        // OBJ texture v grows upwards: v_obj = 1 − v_glTF.
        for uv in uvs {
            let _ = writeln!(obj, "vt {} {}", fmt_num(uv[0]), fmt_num(1.0 - uv[1]));
        }
    }
    let _ = writeln!(obj, "usemtl {name}");
    for t in &part.triangles {
        let [a, b, c] = t.map(|i| i + 1);
        if part.uvs.is_some() {
            let _ = writeln!(obj, "f {a}/{a} {b}/{b} {c}/{c}");
        } else {
            let _ = writeln!(obj, "f {a} {b} {c}");
        }
    }
    write_text(&mdir.join(format!("{name}.obj")), &obj);
    let m = &part.material;
    let mut mtl = format!(
        "# interact3d fixture material\nnewmtl {name}\nKa 0 0 0\nKd {} {} {}\nKs 0 0 0\nd {}\nillum 1\n",
        fmt_num(m.base_color[0]),
        fmt_num(m.base_color[1]),
        fmt_num(m.base_color[2]),
        fmt_num(m.base_color[3])
    );
    if let Some(tex) = &m.texture {
        let _ = writeln!(mtl, "map_Kd {name}.png");
        write_atomic(&mdir.join(format!("{name}.png")), &tex.bytes).unwrap();
    }
    write_text(&mdir.join(format!("{name}.mtl")), &mtl);
    // Read it back: same closed geometry, UVs and texture file.
    let (models, mats) = tobj::load_obj(
        mdir.join(format!("{name}.obj")),
        &tobj::LoadOptions {
            single_index: true,
            triangulate: true,
            ..Default::default()
        },
    )
    .unwrap();
    let mats = mats.unwrap();
    assert_eq!(models.len(), 1);
    let tm = &models[0].mesh;
    let pos: Vec<P3> = tm
        .positions
        .chunks(3)
        .map(|c| P3::new(c[0], c[1], c[2]))
        .collect();
    let tris = tm.indices.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    let back = Mesh::new(pos, tris).welded(0.0);
    assert!(back.is_closed(), "{name}.obj is not closed");
    let want = visual.geometry().signed_volume();
    assert!((back.signed_volume() - want).abs() < 1e-6 * want.abs());
    assert_eq!(tm.texcoords.len() / 2, tm.positions.len() / 3);
    if m.texture.is_some() {
        assert_eq!(
            mats[0].diffuse_texture.as_deref(),
            Some(format!("{name}.png").as_str())
        );
    }
}

#[derive(Clone, Copy)]
enum PoseForm {
    Parts,
    Matrix,
}

fn write_manifest(
    dir: &Path,
    name: &str,
    objs: &[(&Obj, PoseForm, Value)],
    readme_head: &str,
    facts: &str,
) -> Vec<(usize, usize, f64)> {
    std::fs::create_dir_all(dir).unwrap();
    let mut list = Vec::new();
    let mut rows = String::new();
    let mut world = Vec::new();
    for (o, form, extra) in objs {
        write_obj(dir, &o.key, &o.visual);
        let p = &o.pose;
        let pose = match form {
            PoseForm::Parts => {
                let q = p.rotation.quaternion();
                json!({
                    "translation": [p.translation.x, p.translation.y, p.translation.z],
                    "quaternion_wxyz": [q.w, q.i, q.j, q.k],
                    "scale": p.scale,
                })
            }
            PoseForm::Matrix => json!({ "matrix": rows4(&p.matrix()) }),
        };
        let mut e = serde_json::Map::new();
        e.insert("name".into(), json!(o.key));
        e.insert("mesh".into(), json!(format!("meshes/{}.obj", o.key)));
        e.insert("label".into(), json!(o.label));
        e.insert("pose".into(), pose);
        e.insert("density".into(), json!(DENSITY));
        if let Value::Object(x) = extra {
            for (k, v) in x {
                e.insert(k.clone(), v.clone());
            }
        }
        list.push(Value::Object(e));
        let w = o.world_z();
        let bb = w.aabb().unwrap();
        let (vol, com) = mass_props(&w);
        let _ = writeln!(
            rows,
            "| `{}` | {} | {} | {:.1} | {:.1} | ({}, {}, {}) | z {} … {} |",
            o.key,
            o.description,
            o.mesh.triangles.len(),
            vol * 1e6,
            vol * DENSITY * 1000.0,
            mm(com.x),
            mm(com.y),
            mm(com.z),
            mm(bb.min.z),
            mm(bb.max.z)
        );
        world.push(w);
    }
    let manifest = json!({
        "format": "interact3d-scene",
        "version": 1,
        "name": name,
        "units": "m",
        "up_axis": "z",
        "objects": list,
    });
    write_json(&dir.join("scene.json"), &manifest);
    let measured = measure(&world, &[], false);
    let mut readme = format!("# {name}\n\n{readme_head}\n\nOur manifest `scene.json` (Z-up, metres, ground z = 0) with OBJ + MTL meshes in `meshes/` (vertices in metres in each object's own Z-up frame; OBJ `vt` is v-up). Generated by `cargo run --example make_fixtures`; do not edit by hand.\n\n| object | shape (own frame) | triangles | volume (cm³) | mass at {DENSITY} kg/m³ (g) | centre of mass, world (mm) | world height range (mm) |\n|---|---|---:|---:|---:|---|---|\n");
    readme.push_str(&rows);
    let _ = writeln!(readme, "\n{facts}");
    if !measured.pairs.is_empty() {
        let _ = writeln!(
            readme,
            "\n| pair | exact minimum distance between the meshes (mm) |\n|---|---:|"
        );
    }
    for (i, j, d) in &measured.pairs {
        let _ = writeln!(
            readme,
            "| {}–{} | {} |",
            objs[*i].0.key,
            objs[*j].0.key,
            mm(*d)
        );
    }
    write_text(&dir.join("README.md"), &readme);
    measured.pairs
}

// ---------------------------------------------------------------------------------------------
// The scenes.

fn ball_bowl(root: &Path) {
    let (r, h, w) = (0.08, 0.055, 0.004);
    let bowl = shapes::bowl(r, h, w, 64, 12);
    let dims = shapes::bowl_dims(r, h, w);
    let rho = 0.033;
    let ball = shapes::uv_sphere(rho, 16, 32);
    // Rest the ball on one of its planar quads just below the equator (a near-square trapezoid
    // about 6.5 mm wide: a stable 4-point rest): rotate that quad's outward normal onto −z.
    // Triangle 32 + 2·(7·32) is the first triangle of ring 8 (the equator) → ring 9, slice 0.
    let [p0, p1, p2] = ball.triangle(32 + 2 * 7 * 32);
    let normal = (p1 - p0).cross(&(p2 - p0)).normalize();
    let face_down = UnitQuaternion::rotation_between(&normal, &-V3::z()).unwrap();
    let q = yaw(40.0) * face_down;
    let lowest = ball
        .vertices
        .iter()
        .map(|p| (q * p.coords).z)
        .fold(f64::INFINITY, f64::min);
    let face_depth = -lowest; // distance from the centre down to the resting face
    let cz = dims.floor_z + GAP - lowest;
    let objs = vec![
        Obj::new(
            "object_a",
            "bowl",
            format!("shapes::bowl(R {r}, H {h}, wall {w}, 64 slices, 12 rings)"),
            bowl,
            UvProjection::Cylindrical { repeat: 4.0 },
            shapes::checker_texture(TEX, 8, [196, 38, 38], [236, 200, 170], "bowl checker"),
            pose(V3::zeros(), yaw(30.0)),
        ),
        Obj::new(
            "object_b",
            "ball",
            format!("shapes::uv_sphere(r {rho}, 16 stacks, 32 slices)"),
            ball,
            UvProjection::Spherical { repeat: 1.0 },
            shapes::stripes_texture(TEX, 8, [220, 220, 40], [40, 90, 200], "ball stripes"),
            pose(V3::new(0.0, 0.0, cz), q),
        ),
    ];
    let margin = face_rest_margin(&objs[1].world_z());
    assert!(margin > 0.001);
    let floor_y = dims.floor_z;
    let contacts = vec![Contact {
        a: 1,
        b: 0,
        what: "ball resting face on the bowl's flat inner floor",
        filter: Box::new(move |t: &[P3; 3]| t.iter().all(|p| (p.y - floor_y).abs() < 1e-6)),
    }];
    let facts = format!(
        "Analytic facts (world +Y up): the bowl stands on its flat foot (radius {} mm) at y = 0; its flat inner floor (radius {} mm) is at y = {} mm, its rim at y = {} mm (inner rim radius {} mm). The ball (circumradius {} mm, a 32×16 UV sphere) is turned so one of its planar quads (between the equator and the next ring) faces straight down; that face is {} mm below the ball's centre, so the centre is at y = floor {} + gap {} + {} = **{} mm** on the bowl axis. The centre of mass projects {} mm inside the resting face: a stable 4-point rest.",
        mm(dims.flat_radius),
        mm(dims.flat_radius),
        mm(dims.floor_z),
        mm(h),
        mm(dims.inner_rim_radius),
        mm(rho),
        mm(face_depth),
        mm(dims.floor_z),
        mm(GAP),
        mm(face_depth),
        mm(cz),
        mm(margin),
    );
    write_sample_folder(
        &root.join("ball_bowl"),
        "toys",
        "A yellow and blue striped ball resting at the bottom of a red bowl.",
        "ball_bowl",
        &objs,
        &contacts,
        "",
        &facts,
    );
}

fn pen_mug(root: &Path) {
    let (rm, hm, wm, bm, nm) = (0.04, 0.095, 0.004, 0.006, 64);
    let ri = rm - wm;
    let (rho, len, np) = (0.0055, 0.14, 24);
    let mug = shapes::mug(rm, hm, wm, bm, nm);
    let pen = shapes::pen(rho, len, np);
    // The pen leans in the x-z plane towards +x, tilted by α from vertical, axis u = (sin α, 0,
    // cos α), e1 = (cos α, 0, −sin α). Its bottom-cap vertex at +e1 is the lowest point (gap to
    // the floor), the one at −e1 the leftmost (gap to the wall's vertex line at φ = π), and its
    // lateral edge at +e1 passes the inner rim vertex Q = (rᵢ, 0, H):
    //   x_B = −rᵢ + g_w + ρ cos α,  z_B = b + g + ρ sin α,  (Q − B)·e1 − ρ = g_r.
    // The mug is a 64-gon: the exact gap to the wall faces beside the vertex line is
    // g_w·cos(π/64), and to the rim chords beside Q it is g_r / sqrt(1 + cos²α·tan²(π/64)), so
    // g_w and g_r are chosen to make both exactly `GAP`.
    let t = (PI / nm as f64).tan();
    let g_w = GAP / (PI / nm as f64).cos();
    let g_r = |c: f64| GAP * (1.0 + c * c * t * t).sqrt();
    let f = |al: f64| {
        let (s, c) = al.sin_cos();
        (2.0 * ri - g_w - rho * c) * c - (hm - bm - GAP - rho * s) * s - rho - g_r(c)
    };
    let (mut lo, mut hi) = (0.0, PI / 2.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let al = 0.5 * (lo + hi);
    let (s, c) = al.sin_cos();
    let u = V3::new(s, 0.0, c);
    let e1 = V3::new(c, 0.0, -s);
    let b = P3::new(-ri + g_w + rho * c, 0.0, bm + GAP + rho * s);
    let q_rim = P3::new(ri, 0.0, hm);
    let s_rim = (q_rim - b).dot(&u);
    let tip = (3.0 * rho).min(len / 4.0);
    assert!(
        s_rim > 0.0 && s_rim < len - tip,
        "rim contact off the pen's body"
    );
    assert!(((q_rim - b).dot(&e1) - rho - g_r(c)).abs() < 1e-12);
    let rot = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), al);
    let centre = b + u * (len / 2.0);
    let scene_yaw = yaw(25.0);
    let pen_pose = pose(scene_yaw * centre.coords, scene_yaw * rot);
    let mug_pose = pose(V3::zeros(), scene_yaw);
    let objs = vec![
        Obj::new(
            "object_a",
            "mug",
            format!("shapes::mug(R {rm}, H {hm}, wall {wm}, bottom {bm}, {nm} slices)"),
            mug,
            UvProjection::Cylindrical { repeat: 3.0 },
            shapes::checker_texture(TEX, 8, [245, 245, 235], [235, 190, 30], "mug checker"),
            mug_pose,
        ),
        Obj::new(
            "object_b",
            "pen",
            format!("shapes::pen(r {rho}, length {len}, {np} slices)"),
            pen,
            UvProjection::Cylindrical { repeat: 1.0 },
            shapes::stripes_texture(TEX, 4, [20, 20, 20], [200, 30, 30], "pen stripes"),
            pen_pose,
        ),
    ];
    // Frictionless equilibrium in the lean plane: wall (+x), floor (+z) and rim (−e1) forces.
    let (_, com_local) = mass_props(&objs[1].mesh);
    let com = b + rot * (com_local.coords + V3::new(0.0, 0.0, len / 2.0));
    let (vol, _) = mass_props(&objs[1].mesh);
    let mg = vol * DENSITY * 9.81;
    let p_floor = b + e1 * rho;
    let rq = q_rim - p_floor;
    let rc = com - p_floor;
    let n_rim = rc.x * mg / (rq.x * s + rq.z * c - 2.0 * rho * s * c);
    let n_wall = n_rim * c;
    let n_floor = mg - n_rim * s;
    assert!(
        n_rim > 0.0 && n_wall > 0.0 && n_floor > 0.0,
        "pen cannot rest"
    );
    let top = b + u * len;
    let rim_side = move |p: &P3| p.z > hm - 0.01 && p.x > 0.0;
    let floor = move |p: &P3| (p.z - bm).abs() < 1e-6;
    let far_wall = move |p: &P3| (p.x.hypot(p.y) - ri).abs() < 1e-6 && p.x < 0.0;
    let contacts = vec![
        Contact {
            a: 1,
            b: 0,
            what: "pen side on the mug's inner rim edge (near side)",
            filter: local_filter(&mug_pose, rim_side),
        },
        Contact {
            a: 1,
            b: 0,
            what: "pen bottom edge on the mug's inner floor",
            filter: local_filter(&mug_pose, floor),
        },
        Contact {
            a: 1,
            b: 0,
            what: "pen bottom edge against the mug's inner wall (far side)",
            filter: local_filter(&mug_pose, far_wall),
        },
    ];
    let (g_w_text, g_r_text) = (
        format!("{:.4}", g_w * 1000.0),
        format!("{:.4}", g_r(c) * 1000.0),
    );
    let facts = format!(
        "Analytic facts (computed in a Z-up frame, then the whole scene turned 25° about the vertical and converted to +Y up): mug inner radius rᵢ = {} mm, inner floor at {} mm, rim at {} mm. The pen (a 24-gon prism, circumradius ρ = {} mm, length {} mm with a conical tip) leans across the mug: its bottom cap sits in the far corner, {} mm above the floor and {} mm (horizontally, from the wall's vertex line; {} mm from its faces) from the wall, and its side passes {} mm from the inner rim vertex on the near side ({} mm from the rim chords beside it). Solving these three conditions gives a tilt of **{:.3}°** from vertical; bottom-cap centre at {} mm from the axis, height {} mm; the rim touches the pen {} mm up its axis; the top end is at height {} mm ({} mm above the rim). Frictionless equilibrium (weight {:.4} N): rim force {:.4} N, wall {:.4} N, floor {:.4} N, all positive, so the pen rests even without friction.",
        mm(ri),
        mm(bm),
        mm(hm),
        mm(rho),
        mm(len),
        mm(GAP),
        g_w_text,
        mm(GAP),
        g_r_text,
        mm(GAP),
        al.to_degrees(),
        mm(-b.x),
        mm(b.z),
        mm(s_rim),
        mm(top.z),
        mm(top.z - hm),
        mg,
        n_rim,
        n_wall,
        n_floor
    );
    write_sample_folder(
        &root.join("pen_mug"),
        "stationery",
        "A black and red pen leaning inside a white and yellow mug, like a pen in a pen holder.",
        "pen_mug",
        &objs,
        &contacts,
        "",
        &facts,
    );
}

fn fruit_basket(root: &Path) {
    let (ext, h, w, inset, rc, seg) = ([0.30, 0.22], 0.08, 0.005, 0.02, 0.05, 8);
    let basket = shapes::basket(ext, h, w, inset, rc, seg);
    // (key, label, radius, half height, flat radius, yaw°, y offset, texture colours)
    type FruitSpec = (
        &'static str,
        &'static str,
        f64,
        f64,
        f64,
        f64,
        f64,
        [u8; 3],
        [u8; 3],
    );
    let specs: [FruitSpec; 3] = [
        (
            "object_b",
            "apple",
            0.040,
            0.036,
            0.020,
            10.0,
            0.02,
            [200, 40, 40],
            [230, 200, 60],
        ),
        (
            "object_c",
            "orange",
            0.036,
            0.035,
            0.018,
            50.0,
            -0.015,
            [240, 140, 20],
            [250, 170, 60],
        ),
        (
            "object_d",
            "plum",
            0.024,
            0.026,
            0.012,
            80.0,
            0.01,
            [110, 40, 120],
            [80, 20, 90],
        ),
    ];
    let floor = w;
    let meshes: Vec<Mesh> = specs
        .iter()
        .map(|s| shapes::fruit(s.2, s.3, s.4, 32, 16))
        .collect();
    // Each fruit stands on its flat spot at floor + gap; neighbours are spaced along x by
    // bisection on the exact mesh distance to 1.0 mm.
    let placed = |k: usize, x: f64| {
        meshes[k].transformed(&pose(V3::new(x, specs[k].6, floor + GAP), yaw(specs[k].5)).matrix())
    };
    let mut xs = vec![0.0];
    for k in 1..specs.len() {
        let prev = placed(k - 1, xs[k - 1]);
        let (mut lo, mut hi) = (xs[k - 1], xs[k - 1] + 0.2);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if mesh_distance(&prev, &placed(k, mid)) < 0.001 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        xs.push(hi);
    }
    let left = xs[0] - specs[0].2;
    let right = xs[2] + specs[2].2;
    let shift = -(left + right) / 2.0;
    let mut objs = vec![Obj::new(
        "object_a",
        "basket",
        format!("shapes::basket(top {} x {}, H {h}, wall {w}, inset {inset}, corner radius {rc}, {seg} segments)", ext[0], ext[1]),
        basket,
        UvProjection::Box { tile: 0.05 },
        shapes::checker_texture(TEX, 8, [150, 100, 50], [200, 160, 100], "basket weave"),
        pose(V3::zeros(), yaw(-15.0)),
    )];
    let turn = yaw(-15.0);
    let mut fact_rows = String::new();
    for (k, s) in specs.iter().enumerate() {
        let local = V3::new(xs[k] + shift, s.6, floor + GAP);
        objs.push(Obj::new(
            s.0,
            s.1,
            format!(
                "shapes::fruit(r {}, half height {}, flat radius {}, 32 slices, 16 rings)",
                s.2, s.3, s.4
            ),
            meshes[k].clone(),
            UvProjection::Spherical { repeat: 2.0 },
            shapes::stripes_texture(TEX, 8, s.7, s.8, s.1),
            pose(turn * local, turn * yaw(s.5)),
        ));
        let margin = face_rest_margin(&objs[k + 1].world_z());
        assert!(margin > 0.003);
        let _ = writeln!(
            fact_rows,
            "- {}: flat spot (radius {} mm) on the floor, bottom at height {} mm (floor {} + gap {}), centre of mass {} mm inside the flat; top at {} mm.",
            s.1,
            mm(s.4),
            mm(floor + GAP),
            mm(floor),
            mm(GAP),
            mm(margin),
            mm(floor + GAP + objs[k + 1].mesh.aabb().unwrap().max.z)
        );
    }
    let floor_y = floor;
    let mut contacts = Vec::new();
    for (k, what) in [
        "apple on the basket floor",
        "orange on the basket floor",
        "plum on the basket floor",
    ]
    .into_iter()
    .enumerate()
    {
        contacts.push(Contact {
            a: k + 1,
            b: 0,
            what,
            filter: Box::new(move |t: &[P3; 3]| t.iter().all(|p| (p.y - floor_y).abs() < 1e-6)),
        });
    }
    let facts = format!(
        "Analytic facts (computed Z-up, the scene turned −15° about the vertical, then converted to +Y up): the basket stands on its flat bottom at y = 0, flat inner floor at y = {} mm, rim at {} mm; walls lean outwards (bottom inset {} mm per side). The three fruits are spheroids cut flat at the bottom so each rests on its own flat spot on the floor (they do not lean on each other or on the walls):\n\n{}\nAlong the row, neighbours are spaced so the exact mesh distance is 1.0 mm (bisection; apple–orange and orange–plum), so they are \"touching\" in the Interact3D sense without any force between them.",
        mm(floor),
        mm(h),
        mm(inset),
        fact_rows
    );
    write_sample_folder(
        &root.join("fruit_basket"),
        "food",
        "A wicker basket holding an apple, an orange and a plum.",
        "fruit_basket",
        &objs,
        &contacts,
        "",
        &facts,
    );
}

fn box_tray(root: &Path) {
    let (ext, w, rim) = ([0.30, 0.20], 0.006, 0.018);
    let tray = shapes::tray(ext, w, rim);
    let bx = V3::new(0.12, 0.08, 0.05);
    let cube = shapes::cuboid(bx);
    let cz = w + GAP + bx.z / 2.0;
    let objs = [
        Obj::new(
            "tray",
            "tray",
            format!(
                "shapes::tray({} x {}, wall {w}, rim height {rim})",
                ext[0], ext[1]
            ),
            tray,
            UvProjection::Box { tile: 0.1 },
            shapes::checker_texture(TEX, 8, [120, 130, 140], [170, 180, 190], "tray checker"),
            pose(V3::zeros(), yaw(0.0)),
        ),
        Obj::new(
            "box",
            "box",
            format!("shapes::cuboid({} x {} x {})", bx.x, bx.y, bx.z),
            cube,
            UvProjection::Box { tile: 0.12 },
            shapes::checker_texture(TEX, 4, [190, 150, 100], [160, 120, 75], "cardboard"),
            pose(V3::new(0.02, -0.01, cz), yaw(15.0)),
        ),
    ];
    let margin = face_rest_margin(&objs[1].world_z());
    assert!(margin > 0.01);
    let facts = format!(
        "Expected outcome: **passes**. The tray stands on the ground (z = 0); its flat inner floor is at z = {} mm, rim top at {} mm. The box ({} × {} × {} mm, turned 15° about z) rests flat on the floor with a {} mm gap: centre at z = {} + {} + {} = **{} mm**, (x, y) = (20, −10) mm; its centre of mass projects {} mm inside its bottom face. Poses: the tray uses translation + quaternion, the box a 4×4 matrix.",
        mm(w),
        mm(w + rim),
        mm(bx.x),
        mm(bx.y),
        mm(bx.z),
        mm(GAP),
        mm(w),
        mm(GAP),
        mm(bx.z / 2.0),
        mm(cz),
        mm(margin)
    );
    let pairs = write_manifest(
        &root.join("box_tray"),
        "box_tray",
        &[
            (&objs[0], PoseForm::Parts, json!({ "friction": 0.8 })),
            (&objs[1], PoseForm::Matrix, json!({ "friction": 0.8 })),
        ],
        "A cardboard box resting on a flat tray with a raised rim. Each OBJ has a PNG texture (`map_Kd`).",
        &facts,
    );
    assert!(
        (pairs[0].2 - GAP).abs() < 1e-9,
        "box-tray gap {}",
        pairs[0].2
    );
}

fn shelf_item(root: &Path) {
    let (w, d, h, t) = (0.40, 0.25, 0.60, 0.018);
    let levels = [0.05, 0.30, 0.55];
    let shelf = shapes::shelf(w, d, h, t, &levels);
    let bx = V3::new(0.12, 0.08, 0.10);
    let cube = shapes::cuboid(bx);
    let (cx, cy) = (0.03, 0.01);
    let cz = levels[1] + GAP + bx.z / 2.0;
    let objs = [
        Obj::new(
            "shelf",
            "shelf",
            format!(
                "shapes::shelf({w} x {d} x {h}, boards {t} thick, board tops at z = {} / {} / {})",
                levels[0], levels[1], levels[2]
            ),
            shelf,
            UvProjection::Box { tile: 0.2 },
            shapes::stripes_texture(TEX, 8, [150, 105, 60], [175, 130, 80], "wood grain"),
            pose(V3::zeros(), yaw(0.0)),
        ),
        Obj::new(
            "box",
            "box",
            format!("shapes::cuboid({} x {} x {})", bx.x, bx.y, bx.z),
            cube,
            UvProjection::Box { tile: 0.12 },
            shapes::checker_texture(TEX, 4, [60, 110, 170], [40, 80, 130], "blue box"),
            pose(V3::new(cx, cy, cz), yaw(20.0)),
        ),
    ];
    let margin = face_rest_margin(&objs[1].world_z());
    assert!(margin > 0.01);
    let facts = format!(
        "Expected outcome: **passes**. The shelf ({} × {} × {} mm, open front and back) stands on its two side panels on the ground (z = 0). Its boards are {} mm thick with their top faces at z = {}, {} and {} mm; the cavity between the middle and the top board is {} mm high and {} mm wide. The box ({} × {} × {} mm, turned 20° about z) rests flat on the middle board with a {} mm gap: centre at z = {} + {} + {} = **{} mm**, (x, y) = ({}, {}) mm; its centre of mass projects {} mm inside its bottom face. A single convex hull of the shelf would fill the cavity and swallow the box.",
        mm(w),
        mm(d),
        mm(h),
        mm(t),
        mm(levels[0]),
        mm(levels[1]),
        mm(levels[2]),
        mm(levels[2] - t - levels[1]),
        mm(w - 2.0 * t),
        mm(bx.x),
        mm(bx.y),
        mm(bx.z),
        mm(GAP),
        mm(levels[1]),
        mm(GAP),
        mm(bx.z / 2.0),
        mm(cz),
        mm(cx),
        mm(cy),
        mm(margin)
    );
    let pairs = write_manifest(
        &root.join("shelf_item"),
        "shelf_item",
        &[
            (&objs[0], PoseForm::Parts, json!({ "friction": 0.8 })),
            (&objs[1], PoseForm::Parts, json!({ "friction": 0.8 })),
        ],
        "A blue box standing on the middle board of an open wooden shelf. Each OBJ has a PNG texture (`map_Kd`).",
        &facts,
    );
    assert!(
        (pairs[0].2 - GAP).abs() < 1e-9,
        "box-shelf gap {}",
        pairs[0].2
    );
}

fn plain_box(key: &str, label: &str, ext: V3, color: [f64; 4], p: Similarity) -> Obj {
    let m = shapes::cuboid(ext);
    let mut visual = shapes::visual(&m, UvProjection::Box { tile: 0.1 }, Default::default());
    visual.parts[0].material = interact3d::mesh::Material {
        name: label.into(),
        base_color: color,
        texture: None,
    };
    Obj {
        key: key.into(),
        label: label.into(),
        description: format!("shapes::cuboid({} x {} x {})", ext.x, ext.y, ext.z),
        mesh: m,
        visual,
        pose: p,
    }
}

fn fail_interpenetrating(root: &Path) {
    let big = V3::new(0.2, 0.2, 0.1);
    let small = V3::new(0.1, 0.1, 0.1);
    let sink = 0.003;
    let objs = [
        plain_box(
            "base",
            "box",
            big,
            [0.3, 0.5, 0.8, 1.0],
            pose(V3::new(0.0, 0.0, big.z / 2.0), yaw(0.0)),
        ),
        plain_box(
            "top",
            "box",
            small,
            [0.8, 0.4, 0.2, 1.0],
            pose(V3::new(0.02, 0.01, big.z - sink + small.z / 2.0), yaw(0.0)),
        ),
    ];
    let facts = format!(
        "Expected outcome: **fails** (interpenetration). The base box ({} × {} × {} mm) rests on the ground (z = 0 … {} mm). The top box ({} mm cube, centre at (20, 10, {}) mm) has its bottom at z = {} mm, i.e. **sunk {} mm** into the base: penetration depth 3 mm, overlap volume {} × {} × {} mm = **{:.1} cm³** (of {:.1} cm³ for the top box: {:.1} %).",
        mm(big.x),
        mm(big.y),
        mm(big.z),
        mm(big.z),
        mm(small.x),
        mm(big.z - sink + small.z / 2.0),
        mm(big.z - sink),
        mm(sink),
        mm(small.x),
        mm(small.y),
        mm(sink),
        small.x * small.y * sink * 1e6,
        small.x * small.y * small.z * 1e6,
        100.0 * sink / small.z
    );
    let pairs = write_manifest(
        &root.join("fail_interpenetrating"),
        "fail_interpenetrating",
        &[
            (&objs[0], PoseForm::Parts, json!({})),
            (&objs[1], PoseForm::Parts, json!({})),
        ],
        "A box sunk 3 mm into another box that rests on the ground. Untextured (MTL `Kd` colours only).",
        &facts,
    );
    assert_eq!(pairs[0].2, 0.0);
}

fn fail_unstable(root: &Path) {
    let ext = V3::new(0.1, 0.1, 0.06);
    let tilt = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), PI / 4.0);
    let low = shapes::cuboid(ext)
        .vertices
        .iter()
        .map(|p| (tilt * p.coords).z)
        .fold(f64::INFINITY, f64::min);
    let cz = -low + 0.0005;
    let obj = plain_box(
        "box",
        "box",
        ext,
        [0.9, 0.8, 0.2, 1.0],
        pose(V3::new(0.0, 0.0, cz), tilt),
    );
    let w = obj.world_z();
    let zmin = w.aabb().unwrap().min.z;
    let edge: Vec<&P3> = w.vertices.iter().filter(|p| p.z - zmin < 1e-9).collect();
    assert_eq!(edge.len(), 2, "rests on one edge");
    let offset = edge[0].y; // COM (y = 0) minus the edge's y
    let facts = format!(
        "Expected outcome: **fails** (not at rest: it topples). A box of {} × {} × {} mm rotated 45° about the horizontal x axis stands on one edge (parallel to x) {} mm above the ground; centre at z = {} mm. The support is a line, so the static support polygon has zero area. Because the box's cross-section is not square ({} × {} mm), its centre of mass is not over the edge but **{} mm beside it** (the edge is at y = {} mm, the centre at y = 0): gravity tips it about the edge by 45° onto its {} × {} mm face (centre of mass falls from {} mm to {} mm). A cube would be balanced exactly over its edge, an unstable equilibrium that a deterministic simulator may hold; this one falls for any solver.",
        mm(ext.x),
        mm(ext.y),
        mm(ext.z),
        mm(0.0005),
        mm(cz),
        mm(ext.y),
        mm(ext.z),
        mm(-offset),
        mm(offset),
        mm(ext.x),
        mm(ext.y),
        mm(cz),
        mm(ext.z / 2.0)
    );
    write_manifest(
        &root.join("fail_unstable"),
        "fail_unstable",
        &[(&obj, PoseForm::Parts, json!({}))],
        "A box standing on one edge on the ground. Untextured (MTL `Kd` colour only).",
        &facts,
    );
}

/// Seed of the guidance generator for `compose/ball_bowl` (tests/compose.rs regenerates it).
/// With seed 7 the striped ball came out 165° off its stripe-axis symmetry; seed 8 composes.
const COMPOSE_SEED: u64 = 8;

/// `compose/ball_bowl/`: the ball_bowl sample as `compose` takes it — the object GLBs, a
/// guidance part for each (`guidance_object_*.glb`: what segmenting a generated, fused scene
/// gives, from `interact3d::compose::synth` at [`COMPOSE_SEED`]), the descriptive metadata
/// without the registration, and the truth compose should find (`ground_truth_compose.json`).
/// A folder under `compose/`, so the scene fixtures' loops (every folder with a metadata.json)
/// do not take this registration-less sample for a scene.
fn compose_sample(root: &Path) {
    use interact3d::compose::synth;
    let src = root.join("ball_bowl");
    let dir = root.join("compose").join("ball_bowl");
    let _ = std::fs::remove_dir_all(&dir);
    let truth = synth::load_truth(&src).unwrap();
    let s = synth::make(&truth, COMPOSE_SEED, &synth::SynthOptions::default());
    synth::write_sample(&s, Some(&src), &dir).unwrap();
    write_text(
        &dir.join("README.md"),
        &format!(
            "# compose/ball_bowl\n\nThe `ball_bowl` fixture as `interact3d compose` takes it: `object_a.glb` (bowl) and `object_b.glb` (ball) as in `../../ball_bowl/`, and a guidance part for each, `guidance_object_*.glb`, made by `interact3d::compose::synth` (seed {COMPOSE_SEED}): each object placed by its true pose, the scene moved by a random similarity, {:.0} % and {:.0} % of the surfaces cut away as ragged holes, a strip of the neighbour fused in, noise, decimation and a tint. `metadata.json` is the sample's without its registration (what compose finds); `ground_truth_compose.json` gives the true object → guidance transforms. Generated by `cargo run --example make_fixtures`; do not edit by hand.\n\n```sh\ninteract3d compose fixtures/compose/ball_bowl -o out/composed\ninteract3d export out/composed -o out/composed_export --size bowl=0.16   # compose keeps the guidance scale\n```\n",
            100.0 * s.removed[0],
            100.0 * s.removed[1]
        ),
    );
}

fn main() {
    let root: PathBuf = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("fixtures"));
    std::fs::create_dir_all(&root).unwrap();
    ball_bowl(&root);
    eprintln!("ball_bowl done");
    compose_sample(&root);
    eprintln!("compose/ball_bowl done");
    pen_mug(&root);
    eprintln!("pen_mug done");
    box_tray(&root);
    eprintln!("box_tray done");
    shelf_item(&root);
    eprintln!("shelf_item done");
    fruit_basket(&root);
    eprintln!("fruit_basket done");
    fail_interpenetrating(&root);
    fail_unstable(&root);
    let readme = "# Test fixtures\n\nSmall procedural scenes generated by `cargo run --example make_fixtures` (deterministic: running it twice gives identical bytes). Every pose is computed analytically from the shapes' dimensions and checked by the generator on the files as written (exact triangle-mesh distances). Target gap at every resting contact: 0.75 mm. Masses are quoted at 1000 kg/m³.\n\n| folder | layout | expected outcome |\n|---|---|---|\n| `ball_bowl/` | Interact3D sample folder (`object_a.glb`, `object_b.glb`, `metadata.json`) | passes: ball resting on the bowl's flat floor |\n| `pen_mug/` | sample folder | passes: pen leaning on the rim, bottom in the far corner |\n| `fruit_basket/` | sample folder with `object_a` … `object_d`, `remaining_objects` | passes: three fruits each resting on the basket floor, 1 mm apart |\n| `box_tray/` | our manifest `scene.json` + OBJ/MTL/PNG | passes: box resting on a tray |\n| `shelf_item/` | manifest | passes: box standing on the middle board of an open shelf |\n| `fail_interpenetrating/` | manifest | fails: a box sunk 3 mm into another |\n| `fail_unstable/` | manifest | fails: a box standing on one edge topples |\n| `compose/ball_bowl/` | `compose` input: `object_*.glb` + `guidance_object_*.glb` (generated guidance, seed 8), no registration | `compose` recovers the poses of `ground_truth_compose.json` |\n\nEach folder's README gives the analytic facts (sizes, volumes, masses, rest positions, gaps).\n";
    write_text(&root.join("README.md"), readme);
}
