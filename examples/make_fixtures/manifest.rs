//! Manifest scenes (our scene.json, Z-up, OBJ + MTL + PNG).

use super::*;

pub(crate) fn fmt_num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x}")
    }
}

/// Write `visual` (one part) as `meshes/<name>.obj` + `.mtl` (+ `.png` when textured).
pub(crate) fn write_obj(dir: &Path, name: &str, visual: &VisualMesh) {
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
pub(crate) enum PoseForm {
    Parts,
    Matrix,
}

pub(crate) fn write_manifest(
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
