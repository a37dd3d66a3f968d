//! Wavefront OBJ + MTL reader (through `tobj`): n-gons triangulated, every group and object
//! kept, `Kd` and `map_Kd` as the base colour and texture, UVs kept.

use crate::error::{Error, Result};
use crate::io::{resolve_inside, texture, Limits};
use crate::mesh::{Material, VisualMesh, VisualPart, P3};
use std::collections::BTreeMap;
use std::path::Path;

/// Load an OBJ file with its MTL library and textures. The MTL and textures must lie inside the
/// OBJ's own folder (or below it); a missing MTL or texture is an error naming it.
/// How tobj reads every OBJ here: triangles with one index per corner, points and lines left out.
const LOAD_OPTIONS: tobj::LoadOptions = tobj::LoadOptions {
    triangulate: true,
    single_index: true,
    ignore_points: true,
    ignore_lines: true,
};

pub fn load(path: &Path, limits: &Limits) -> Result<VisualMesh> {
    let root = path.parent().unwrap_or(Path::new("."));
    load_in(path, root, limits)
}

/// Load an OBJ whose references must stay inside `root`.
pub fn load_in(path: &Path, root: &Path, limits: &Limits) -> Result<VisualMesh> {
    let bytes = crate::io::read_file(path, limits)?;
    load_bytes(path, &bytes, root, limits)
}

/// Parse OBJ bytes; `path` names the file in errors and is where the MTL path starts from; no
/// reference may leave `root`.
pub fn load_bytes(path: &Path, bytes: &[u8], root: &Path, limits: &Limits) -> Result<VisualMesh> {
    let text = String::from_utf8_lossy(bytes);
    // tobj silently drops out-of-range indices and treats 0 as valid; check indices ourselves.
    check_indices(path, &text)?;
    let opts = LOAD_OPTIONS;
    let mtl_error: std::cell::RefCell<Option<Error>> = std::cell::RefCell::new(None);
    let (models, materials) = tobj::load_obj_buf(&mut &bytes[..], &opts, |mtl| {
        let name = mtl.to_string_lossy();
        match resolve_inside(root, path, &name) {
            Ok(file) => match crate::io::read_file(&file, limits) {
                Ok(b) => tobj::load_mtl_buf(&mut b.as_slice()),
                Err(e) => {
                    *mtl_error.borrow_mut() = Some(e);
                    Err(tobj::LoadError::OpenFileFailed)
                }
            },
            Err(e) => {
                *mtl_error.borrow_mut() = Some(e);
                Err(tobj::LoadError::OpenFileFailed)
            }
        }
    })
    .map_err(|e| Error::input(path, format!("cannot parse OBJ: {e}")))?;
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let materials =
        materials.map_err(|e| Error::input(path, format!("cannot parse material library: {e}")))?;

    let mtl_dir_file = path; // map_Kd paths are relative to the MTL, which we required next to the OBJ
    let mut textures = BTreeMap::new();
    let mut mats: Vec<Material> = Vec::with_capacity(materials.len());
    for m in &materials {
        let kd = m.diffuse.unwrap_or([0.8, 0.8, 0.8]);
        let alpha = m.dissolve.unwrap_or(1.0);
        let texture = match m.diffuse_texture.as_deref().map(str::trim) {
            Some(t) if !t.is_empty() => {
                let file = resolve_inside(root, mtl_dir_file, t)?;
                let tex = match textures.get(&file) {
                    Some(x) => x,
                    None => {
                        let x = texture::from_file(&file, limits)?;
                        textures.insert(file.clone(), x);
                        &textures[&file]
                    }
                };
                Some(tex.clone())
            }
            _ => None,
        };
        mats.push(Material {
            name: m.name.clone(),
            // A texture in MTL multiplies with Kd; most exporters write Kd 1 with a texture.
            base_color: [kd[0], kd[1], kd[2], alpha],
            texture,
        });
    }

    let mut parts = Vec::new();
    for model in &models {
        let m = &model.mesh;
        if m.indices.is_empty() {
            continue;
        }
        let positions: Vec<P3> = m
            .positions
            .chunks_exact(3)
            .map(|c| P3::new(c[0], c[1], c[2]))
            .collect();
        let triangles: Vec<[u32; 3]> = m
            .indices
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        let material = m
            .material_id
            .and_then(|i| mats.get(i).cloned())
            .unwrap_or_default();
        let uvs = if !m.texcoords.is_empty() && m.texcoords.len() / 2 == positions.len() {
            // OBJ's v grows upwards; our model uses glTF's (v down).
            Some(
                m.texcoords
                    .chunks_exact(2)
                    .map(|c| [c[0], 1.0 - c[1]])
                    .collect(),
            )
        } else {
            None
        };
        let uvs = if material.texture.is_some() {
            uvs
        } else {
            None
        };
        parts.push(VisualPart {
            positions,
            uvs,
            triangles,
            material,
        });
    }
    Ok(VisualMesh { parts })
}

/// Check every face index: 1-based positive up to the count so far, or negative (relative) not
/// before the first vertex; 0 is invalid.
fn check_indices(path: &Path, text: &str) -> Result<()> {
    let (mut nv, mut nvt, mut nvn) = (0i64, 0i64, 0i64);
    for (lineno, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => nv += 1,
            Some("vt") => nvt += 1,
            Some("vn") => nvn += 1,
            Some("f") => {
                let mut corners = 0;
                for corner in it {
                    corners += 1;
                    for (k, field) in corner.split('/').enumerate() {
                        if field.is_empty() {
                            continue;
                        }
                        let count = [nv, nvt, nvn][k.min(2)];
                        let what = ["vertex", "texture coordinate", "normal"][k.min(2)];
                        let i: i64 = field.parse().map_err(|_| {
                            Error::input(
                                path,
                                format!("line {}: bad face index {field:?}", lineno + 1),
                            )
                        })?;
                        // unsigned_abs: -i64::MIN would overflow.
                        let ok = i != 0 && i.unsigned_abs() <= count as u64;
                        if !ok {
                            return Err(Error::input(
                                path,
                                format!(
                                    "line {}: face {what} index {i} out of range (1..={count}, or negative relative)",
                                    lineno + 1
                                ),
                            ));
                        }
                    }
                }
                if corners < 3 {
                    return Err(Error::input(
                        path,
                        format!("line {}: face with fewer than 3 corners", lineno + 1),
                    ));
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Geometry only: one part per OBJ object or group (`o`/`g`), materials and textures ignored
/// (what a physics engine reads; PyBullet makes each part of a V-HACD file its own convex
/// shape). Indices are checked as in [`load_bytes`].
pub fn load_geometry_bytes(path: &Path, bytes: &[u8], limits: &Limits) -> Result<VisualMesh> {
    let text = String::from_utf8_lossy(bytes);
    check_indices(path, &text)?;
    let opts = LOAD_OPTIONS;
    let (models, _) = tobj::load_obj_buf(&mut &bytes[..], &opts, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| Error::input(path, format!("cannot parse OBJ: {e}")))?;
    let parts: Vec<VisualPart> = models
        .iter()
        .filter(|m| !m.mesh.indices.is_empty())
        .map(|model| VisualPart {
            positions: model
                .mesh
                .positions
                .chunks_exact(3)
                .map(|c| P3::new(c[0], c[1], c[2]))
                .collect(),
            uvs: None,
            triangles: model
                .mesh
                .indices
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
            material: Material::default(),
        })
        .collect();
    let mesh = VisualMesh { parts };
    crate::io::check_visual(path, &mesh, limits)?;
    Ok(mesh)
}
