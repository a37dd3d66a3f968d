//! The Interact3D sample folder: `object_*.glb` + `metadata.json` whose
//! `registration.transforms.<name>.matrix` (row-major 4x4) maps each object's GLB frame into the
//! scene: `p_world = s·R·p_glb + t`. glTF is Y-up; units are whatever the generator used.

use super::{check_names, Physical, Scene, SceneObject, UpAxis};
use crate::error::{Error, Result};
use crate::io::Limits;
use crate::pose::Similarity;
use serde_json::Value;
use std::path::Path;

/// Load a sample folder.
pub fn load(dir: &Path, limits: &Limits) -> Result<Scene> {
    let meta_path = dir.join("metadata.json");
    let meta = parse_metadata(&meta_path, &crate::io::read_file(&meta_path, limits)?)?;
    let transforms = transforms_of(&meta_path, &meta)?;

    // The objects are the object_*.glb files; each needs a transform.
    let mut names: Vec<String> = Vec::new();
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| Error::io(dir, e))?;
        let file = entry.file_name().to_string_lossy().into_owned();
        if let Some(stem) = file.strip_suffix(".glb") {
            if stem.starts_with("object_") {
                names.push(stem.to_string());
            }
        }
    }
    names.sort();
    if names.is_empty() {
        return Err(Error::input(dir, "sample folder has no object_*.glb files"));
    }
    // Names come from file names: checked before any mesh is read.
    check_names(&meta_path, names.iter().map(String::as_str))?;
    for key in transforms.keys() {
        if !names.contains(key) {
            return Err(Error::input(
                &meta_path,
                format!("registration.transforms names {key:?} but {key}.glb is missing"),
            ));
        }
    }

    let mut objects = Vec::new();
    for name in &names {
        let t = transforms.get(name).ok_or_else(|| {
            Error::input(
                &meta_path,
                format!("no registration.transforms entry for {name}"),
            )
        })?;
        let pose = parse_transform(t).map_err(|m| {
            Error::input(&meta_path, format!("registration.transforms.{name}: {m}"))
        })?;
        let mesh_path = dir.join(format!("{name}.glb"));
        let visual = crate::io::load_visual(&mesh_path, limits)?;
        let label = meta
            .pointer(&format!("/analysis/{name}"))
            .and_then(Value::as_str)
            .map(str::to_string);
        objects.push(SceneObject {
            name: name.clone(),
            label,
            mesh_path,
            visual,
            pose,
            physical: Physical::default(),
        });
    }
    let name = dir
        .canonicalize()
        .ok()
        .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "scene".into());
    Ok(Scene {
        name,
        source: dir.to_path_buf(),
        meters_per_unit: 1.0,
        up_axis: UpAxis::Y,
        objects,
        warnings: Vec::new(),
    })
}

/// Parse `metadata.json` bytes (`meta_path` names the file in errors).
pub fn parse_metadata(meta_path: &Path, bytes: &[u8]) -> Result<Value> {
    serde_json::from_slice(bytes)
        .map_err(|e| Error::input(meta_path, format!("malformed JSON: {e}")))
}

fn transforms_of<'a>(
    meta_path: &Path,
    meta: &'a Value,
) -> Result<&'a serde_json::Map<String, Value>> {
    meta.pointer("/registration/transforms")
        .and_then(Value::as_object)
        .ok_or_else(|| Error::input(meta_path, "missing registration.transforms"))
}

/// Every transform of `metadata.json` bytes, checked (the byte-level entry point the fuzz
/// target calls; [`load`] reads the same way, then matches the names to the GLB files).
pub fn transforms_from_bytes(meta_path: &Path, bytes: &[u8]) -> Result<Vec<(String, Similarity)>> {
    let meta = parse_metadata(meta_path, bytes)?;
    transforms_of(meta_path, &meta)?
        .iter()
        .map(|(name, t)| {
            parse_transform(t).map(|s| (name.clone(), s)).map_err(|m| {
                Error::input(meta_path, format!("registration.transforms.{name}: {m}"))
            })
        })
        .collect()
}

/// A transform entry: its `matrix` (preferred), else `scale` + `rotation` + `translation`.
pub fn parse_transform(t: &Value) -> std::result::Result<Similarity, String> {
    if let Some(m) = t.get("matrix") {
        let rows: Vec<Vec<f64>> = serde_json::from_value(m.clone())
            .map_err(|_| "matrix must be a 4x4 list of numbers".to_string())?;
        let s = Similarity::from_rows(&rows)?;
        if let Some(given) = t.get("scale").and_then(Value::as_f64) {
            if given <= 0.0 || ((given - s.scale) / s.scale).abs() > 1e-3 {
                return Err(format!(
                    "scale {given} disagrees with the matrix's scale {}",
                    s.scale
                ));
            }
        }
        return Ok(s);
    }
    let scale = t
        .get("scale")
        .and_then(Value::as_f64)
        .ok_or("no matrix and no scale")?;
    let r: Vec<Vec<f64>> = serde_json::from_value(t.get("rotation").cloned().ok_or("no rotation")?)
        .map_err(|_| "rotation must be a 3x3 list of numbers".to_string())?;
    let tr: Vec<f64> =
        serde_json::from_value(t.get("translation").cloned().ok_or("no translation")?)
            .map_err(|_| "translation must be 3 numbers".to_string())?;
    if r.len() != 3 || r.iter().any(|x| x.len() != 3) || tr.len() != 3 {
        return Err("rotation must be 3x3 and translation 3 numbers".into());
    }
    let rows: Vec<Vec<f64>> = (0..4)
        .map(|i| {
            if i == 3 {
                vec![0.0, 0.0, 0.0, 1.0]
            } else {
                vec![scale * r[i][0], scale * r[i][1], scale * r[i][2], tr[i]]
            }
        })
        .collect();
    Similarity::from_rows(&rows)
}
