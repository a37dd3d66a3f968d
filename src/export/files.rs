//! Mesh files of one body: `visual.obj` (+ `visual.mtl`, PNG textures), per-material visual
//! parts when there are several materials (MuJoCo takes one material per geom), and one OBJ per
//! collision hull.

use super::format::f;
use crate::body::Body;
use crate::error::Result;
use crate::mesh::{Mesh, Texture, VisualPart};
use std::fmt::Write as _;
use std::path::Path;

pub struct MaterialFile {
    pub name: String,
    pub rgba: [f64; 4],
    /// Texture path relative to `meshes/`.
    pub texture: Option<String>,
}

pub struct BodyFiles {
    pub materials: Vec<MaterialFile>,
    /// (mesh file relative to `meshes/`, material name) per MJCF visual geom.
    pub visual_parts: Vec<(String, String)>,
    /// The all-in-one visual OBJ relative to `meshes/`.
    pub visual_all: String,
    /// Collision OBJ files relative to `meshes/`.
    pub hulls: Vec<String>,
}

/// Write all mesh files of `b` under `meshes/<name>/`.
pub fn write_body_meshes(b: &Body, meshes: &Path) -> Result<BodyFiles> {
    let dir = meshes.join(&b.name);
    crate::fsutil::create_dir(&dir)?;
    let groups = material_groups(b);
    let mut textures: Vec<Texture> = Vec::new();
    let mut materials = Vec::new();
    let mut mtl = format!("# {}\n", super::GENERATOR);
    for (k, (m, _)) in groups.iter().enumerate() {
        let name = format!("{}_material_{k:02}", b.name);
        let texture = match &m.texture {
            Some(t) => {
                let idx = match textures.iter().position(|x| x.bytes == t.bytes) {
                    Some(i) => i,
                    None => {
                        let file = format!("texture_{:02}.png", textures.len());
                        crate::fsutil::write(&dir.join(&file), &crate::io::texture::to_png(t)?)?;
                        textures.push(t.clone());
                        textures.len() - 1
                    }
                };
                Some(format!("texture_{idx:02}.png"))
            }
            None => None,
        };
        let c = m.base_color;
        writeln!(
            mtl,
            "\nnewmtl {name}\nKa 0 0 0\nKd {} {} {}\nKs 0 0 0\nd {}\nillum 1",
            f(c[0]),
            f(c[1]),
            f(c[2]),
            f(c[3])
        )
        .unwrap();
        if let Some(t) = &texture {
            writeln!(mtl, "map_Kd {t}").unwrap();
        }
        materials.push(MaterialFile {
            name,
            rgba: if texture.is_some() {
                [1.0, 1.0, 1.0, c[3]]
            } else {
                c
            },
            texture: texture.map(|t| format!("{}/{t}", b.name)),
        });
    }
    crate::fsutil::write(&dir.join("visual.mtl"), mtl.as_bytes())?;

    let all: Vec<(usize, &VisualPart)> = groups
        .iter()
        .enumerate()
        .flat_map(|(k, (_, ps))| ps.iter().map(move |p| (k, *p)))
        .collect();
    crate::fsutil::write(
        &dir.join("visual.obj"),
        visual_obj(&all, &materials, true).as_bytes(),
    )?;
    let mut visual_parts = Vec::new();
    if groups.len() == 1 {
        visual_parts.push((format!("{}/visual.obj", b.name), materials[0].name.clone()));
    } else {
        for (k, (_, ps)) in groups.iter().enumerate() {
            let file = format!("visual_{k:02}.obj");
            let parts: Vec<(usize, &VisualPart)> = ps.iter().map(|p| (k, *p)).collect();
            crate::fsutil::write(
                &dir.join(&file),
                visual_obj(&parts, &materials, false).as_bytes(),
            )?;
            visual_parts.push((format!("{}/{file}", b.name), materials[k].name.clone()));
        }
    }
    let mut hulls = Vec::new();
    for (k, h) in b.hulls.iter().enumerate() {
        let file = format!("collision_{k:02}.obj");
        crate::fsutil::write(&dir.join(&file), plain_obj(&h.mesh()).as_bytes())?;
        hulls.push(format!("{}/{file}", b.name));
    }
    Ok(BodyFiles {
        materials,
        visual_parts,
        visual_all: format!("{}/visual.obj", b.name),
        hulls,
    })
}

/// The body's visual parts grouped by material (same colour and texture bytes), in first-seen
/// order: one MJCF geom, and one entry of [`BodyFiles::materials`], per group.
pub fn material_groups(b: &Body) -> Vec<(crate::mesh::Material, Vec<&VisualPart>)> {
    let mut groups: Vec<(crate::mesh::Material, Vec<&VisualPart>)> = Vec::new();
    for p in &b.visual.parts {
        match groups
            .iter_mut()
            .find(|(m, _)| same_material(m, &p.material))
        {
            Some((_, v)) => v.push(p),
            None => groups.push((p.material.clone(), vec![p])),
        }
    }
    groups
}

fn same_material(a: &crate::mesh::Material, b: &crate::mesh::Material) -> bool {
    a.base_color == b.base_color
        && match (&a.texture, &b.texture) {
            (None, None) => true,
            (Some(x), Some(y)) => x.bytes == y.bytes,
            _ => false,
        }
}

/// OBJ text of visual parts; with `mtllib` when `with_mtl`. UVs are written OBJ-style (v up).
fn visual_obj(
    parts: &[(usize, &VisualPart)],
    materials: &[MaterialFile],
    with_mtl: bool,
) -> String {
    let mut s = format!("# {}\n", super::GENERATOR);
    if with_mtl {
        s.push_str("mtllib visual.mtl\n");
    }
    let (mut base_v, mut base_t) = (1usize, 1usize);
    for (k, p) in parts {
        for v in &p.positions {
            writeln!(s, "v {} {} {}", f(v.x), f(v.y), f(v.z)).unwrap();
        }
        if let Some(uv) = &p.uvs {
            for t in uv {
                writeln!(s, "vt {} {}", f(t[0]), f(1.0 - t[1])).unwrap();
            }
        }
        if with_mtl {
            writeln!(s, "usemtl {}", materials[*k].name).unwrap();
        }
        for t in &p.triangles {
            let (a, b, c) = (
                t[0] as usize + base_v,
                t[1] as usize + base_v,
                t[2] as usize + base_v,
            );
            if p.uvs.is_some() {
                let (ta, tb, tc) = (
                    t[0] as usize + base_t,
                    t[1] as usize + base_t,
                    t[2] as usize + base_t,
                );
                writeln!(s, "f {a}/{ta} {b}/{tb} {c}/{tc}").unwrap();
            } else {
                writeln!(s, "f {a} {b} {c}").unwrap();
            }
        }
        base_v += p.positions.len();
        if let Some(uv) = &p.uvs {
            base_t += uv.len();
        }
    }
    s
}

/// OBJ text of a plain mesh.
pub fn plain_obj(m: &Mesh) -> String {
    let mut s = format!("# {}\n", super::GENERATOR);
    for v in &m.vertices {
        writeln!(s, "v {} {} {}", f(v.x), f(v.y), f(v.z)).unwrap();
    }
    for t in &m.triangles {
        writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
    }
    s
}
