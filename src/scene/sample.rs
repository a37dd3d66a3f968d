//! The Interact3D sample folder: `object_*.glb` + `metadata.json` whose
//! `registration.transforms.<name>.matrix` (row-major 4x4) maps each object's GLB frame into the
//! scene: `p_world = s·R·p_glb + t`. glTF is Y-up; units are whatever the generator used.
//!
//! Entry points: [`load`], [`object_names`] (what each `object_*` is called: its label from
//! `analysis`), [`parse_metadata`], [`transforms_from_bytes`], [`parse_transform`].

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

    let display = object_names(&meta, &names);
    let mut objects = Vec::new();
    for (name, shown) in names.iter().zip(display) {
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
            aliases: if &shown == name {
                Vec::new()
            } else {
                vec![name.clone()]
            },
            name: shown,
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

/// Windows device names: never a file name, whatever the extension.
const RESERVED: [&str; 22] = [
    "con", "prn", "aux", "nul", "com1", "com2", "com3", "com4", "com5", "com6", "com7", "com8",
    "com9", "lpt1", "lpt2", "lpt3", "lpt4", "lpt5", "lpt6", "lpt7", "lpt8", "lpt9",
];

/// A label as an object name: lower case, each run of other characters than `a-z`, `0-9`, `-`
/// turned into one `_` ("avocado half" → `avocado_half`), at most 48 characters; `None` when
/// nothing usable is left (no letter first, or a Windows device name).
fn name_of_label(label: &str) -> Option<String> {
    let mut out = String::new();
    for c in label.trim().chars().flat_map(char::to_lowercase) {
        if c.is_ascii_alphanumeric() || c == '-' {
            out.push(c);
        } else if !out.is_empty() && !out.ends_with('_') {
            out.push('_');
        }
    }
    let out: String = out.trim_end_matches('_').chars().take(48).collect();
    let out = out.trim_end_matches('_').to_string();
    (out.starts_with(|c: char| c.is_ascii_alphabetic()) && !RESERVED.contains(&out.as_str()))
        .then_some(out)
}

/// The name of each object of `ids` (`object_a`, …): its label in `metadata.json`'s `analysis`
/// (`"object_b": "lemon"` → `lemon`), so tables, MJCF bodies, URDF links and export file names
/// say what the object is. Deterministic: it depends on the metadata alone, never on the order
/// files are listed in. A label several objects share gets the id's letter (three `sneaker`s:
/// `sneaker_b`, `sneaker_c`, `sneaker_d`); an object without a usable label keeps its id. If the
/// names would still clash with each other or with another object's id, every object keeps its
/// id. The id stays an alias ([`super::SceneObject::aliases`]) for `--size` and the like.
pub fn object_names(meta: &Value, ids: &[String]) -> Vec<String> {
    let bases: Vec<Option<String>> = ids
        .iter()
        .map(|id| {
            meta.pointer(&format!("/analysis/{id}"))
                .and_then(Value::as_str)
                .and_then(name_of_label)
        })
        .collect();
    let names: Vec<String> = ids
        .iter()
        .zip(&bases)
        .map(|(id, base)| match base {
            None => id.clone(),
            Some(b) if bases.iter().filter(|x| x.as_ref() == Some(b)).count() > 1 => {
                format!("{b}_{}", id.strip_prefix("object_").unwrap_or(id))
            }
            Some(b) => b.clone(),
        })
        .collect();
    let clash = names.iter().enumerate().any(|(i, n)| {
        !super::is_valid_name(n)
            || names[..i].contains(n)
            || ids.iter().enumerate().any(|(j, id)| j != i && id == n)
    });
    if clash {
        ids.to_vec()
    } else {
        names
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn ids(n: &[&str]) -> Vec<String> {
        n.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn names_come_from_the_labels() {
        let meta = json!({"analysis": {"object_a": "bowl", "object_b": "Avocado  half!"}});
        assert_eq!(
            object_names(&meta, &ids(&["object_a", "object_b"])),
            ["bowl", "avocado_half"]
        );
    }

    #[test]
    fn shared_labels_take_the_id_letter_and_missing_ones_keep_the_id() {
        let meta = json!({"analysis": {"object_a": "tray", "object_b": "sneaker",
            "object_c": "sneaker", "object_d": "sneaker", "object_e": "  ", "object_f": "NUL"}});
        let ids = ids(&[
            "object_a", "object_b", "object_c", "object_d", "object_e", "object_f", "object_g",
        ]);
        assert_eq!(
            object_names(&meta, &ids),
            [
                "tray",
                "sneaker_b",
                "sneaker_c",
                "sneaker_d",
                "object_e",
                "object_f",
                "object_g"
            ]
        );
    }

    #[test]
    fn a_clash_with_an_id_keeps_every_id() {
        // object_a labelled "object_b" would take object_b's alias: ids throughout.
        let meta = json!({"analysis": {"object_a": "object_b", "object_b": "lemon"}});
        let ids = ids(&["object_a", "object_b"]);
        assert_eq!(object_names(&meta, &ids), ids);
        // Labels "lemon" and "lemon_b" with another "lemon": lemon_b twice, ids throughout.
        let meta =
            json!({"analysis": {"object_a": "lemon_b", "object_b": "lemon", "object_c": "lemon"}});
        let ids3 = self::ids(&["object_a", "object_b", "object_c"]);
        assert_eq!(object_names(&meta, &ids3), ids3);
    }
}
