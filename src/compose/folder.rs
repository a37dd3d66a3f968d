//! Sample folders in and out: read `object_*.glb` + `guidance_object_*.glb` (+ `metadata.json`),
//! write `OUT/metadata.json` (the reference code's `registration` section), `OUT/scene.json`
//! (a manifest `export` takes) and copies of the object GLBs, atomically.

use super::{compose, ComposeOptions, Composition, ObjectInput};
use crate::error::{Error, Result};
use crate::io::Limits;
use crate::metrics::{pair_metrics, MetricsOptions, Prepared, Solid};
use crate::scene::manifest::{Manifest, ManifestObject, PoseSpec, Units};
use crate::scene::UpAxis;
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};

/// A sample folder as read.
pub struct Sample {
    pub dir: PathBuf,
    pub inputs: Vec<ObjectInput>,
    /// The input `metadata.json` (an empty object when absent).
    pub metadata: Map<String, Value>,
}

/// Read a sample folder: every `object_*.glb` needs its `guidance_object_*.glb` and vice versa.
pub fn read_sample(dir: &Path, limits: &Limits) -> Result<Sample> {
    if !dir.is_dir() {
        return Err(Error::input(
            dir,
            "not a folder (expected a sample folder with object_*.glb and guidance_object_*.glb)",
        ));
    }
    let mut objects = Vec::new();
    let mut guides = Vec::new();
    for e in std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))? {
        let e = e.map_err(|e| Error::io(dir, e))?;
        let f = e.file_name().to_string_lossy().into_owned();
        if let Some(stem) = f.strip_suffix(".glb") {
            if stem.starts_with("object_") {
                objects.push(stem.to_string());
            } else if let Some(s) = stem.strip_prefix("guidance_") {
                if s.starts_with("object_") {
                    guides.push(s.to_string());
                }
            }
        }
    }
    objects.sort();
    guides.sort();
    if objects.is_empty() {
        return Err(Error::input(dir, "sample folder has no object_*.glb files"));
    }
    for g in &guides {
        if !objects.contains(g) {
            return Err(Error::input(
                dir.join(format!("guidance_{g}.glb")),
                format!("guidance part without its object: {g}.glb is missing"),
            ));
        }
    }
    let mut inputs = Vec::new();
    for name in &objects {
        let gpath = dir.join(format!("guidance_{name}.glb"));
        if !gpath.is_file() {
            return Err(Error::input(
                &gpath,
                format!("missing guidance part for {name} (every object_*.glb needs a guidance_object_*.glb)"),
            ));
        }
        let visual = crate::io::load_visual(&dir.join(format!("{name}.glb")), limits)?;
        let guidance = crate::io::load_visual(&gpath, limits)?;
        if guidance.triangle_count() == 0 {
            return Err(Error::input(&gpath, "guidance part has no triangles"));
        }
        inputs.push(ObjectInput {
            name: name.clone(),
            visual,
            guidance,
        });
    }
    let mpath = dir.join("metadata.json");
    let metadata = if mpath.is_file() {
        let text = std::fs::read_to_string(&mpath).map_err(|e| Error::io(&mpath, e))?;
        match serde_json::from_str::<Value>(&text)
            .map_err(|e| Error::input(&mpath, format!("malformed JSON: {e}")))?
        {
            Value::Object(m) => m,
            _ => return Err(Error::input(&mpath, "metadata.json must be a JSON object")),
        }
    } else {
        Map::new()
    };
    Ok(Sample {
        dir: dir.to_path_buf(),
        inputs,
        metadata,
    })
}

/// Pairwise R_volume, R_surface, penetration depth and clearance of the composed objects.
pub fn penetration_check(sample: &Sample, comp: &Composition, points: usize) -> Value {
    let placed: Vec<(String, crate::mesh::Mesh)> = sample
        .inputs
        .iter()
        .filter_map(|i| {
            let t = comp.get(&i.name)?.transform;
            Some((i.name.clone(), i.visual.geometry().transformed(&t.matrix())))
        })
        .collect();
    let prepared: Vec<Prepared> = placed
        .iter()
        .map(|(_, m)| Prepared::new(Solid::Mesh(m)))
        .collect();
    let opts = MetricsOptions {
        points,
        ..Default::default()
    };
    let mut pairs = Vec::new();
    let (mut max_rv, mut max_pen) = (0.0f64, 0.0f64);
    for a in 0..placed.len() {
        for b in a + 1..placed.len() {
            let m = pair_metrics(&prepared[a], &prepared[b], &opts);
            max_rv = max_rv.max(m.r_volume);
            max_pen = max_pen.max(m.max_penetration_depth);
            pairs.push(json!({
                "a": placed[a].0, "b": placed[b].0,
                "r_volume": m.r_volume, "r_surface": m.r_surface,
                "max_penetration_depth": m.max_penetration_depth,
                "min_clearance": m.min_clearance,
            }));
        }
    }
    json!({
        "method": "interact3d metrics on the visual meshes at the composed poses (guidance units)",
        "points": points,
        "max_r_volume": max_rv,
        "max_penetration_depth": max_pen,
        "passed": max_rv <= 1e-4,
        "pairs": pairs,
    })
}

fn rows(m: &nalgebra::Matrix4<f64>) -> Vec<Vec<f64>> {
    (0..4)
        .map(|i| (0..4).map(|j| m[(i, j)]).collect())
        .collect()
}

/// The `registration` section in the reference code's shape.
pub fn registration_json(
    sample: &Sample,
    comp: &Composition,
    check: &Value,
    o: &ComposeOptions,
) -> Value {
    let mut transforms = Map::new();
    for i in &sample.inputs {
        let Some(r) = comp.get(&i.name) else { continue };
        let t = &r.transform;
        let rot = t.rotation.to_rotation_matrix();
        let rm = rot.matrix();
        transforms.insert(
            i.name.clone(),
            json!({
                "method": r.method,
                "pose_stage": r.pose_stage,
                "scale": t.scale,
                "rotation": (0..3).map(|a| (0..3).map(|b| rm[(a, b)]).collect::<Vec<f64>>()).collect::<Vec<_>>(),
                "translation": [t.translation.x, t.translation.y, t.translation.z],
                "matrix": rows(&t.matrix()),
            }),
        );
    }
    let remaining: Vec<&str> = comp
        .objects
        .iter()
        .skip(1)
        .map(|r| r.name.as_str())
        .collect();
    let confident = comp.objects.iter().all(|r| r.score >= 0.6);
    let passed = check
        .get("passed")
        .and_then(Value::as_bool)
        .unwrap_or(false);
    let mut reg = Map::new();
    reg.insert("anchor_object".into(), json!(comp.anchor));
    if remaining.len() == 1 {
        reg.insert("remaining_object".into(), json!(remaining[0]));
    } else {
        reg.insert("remaining_objects".into(), json!(remaining));
    }
    reg.insert(
        "status".into(),
        json!(if confident && passed {
            "success"
        } else {
            "needs_review"
        }),
    );
    reg.insert("transforms".into(), Value::Object(transforms));
    reg.insert("penetration_check".into(), check.clone());
    reg.insert(
        "compose".into(),
        json!({
            "tool": "interact3d",
            "version": env!("CARGO_PKG_VERSION"),
            "method": o.method,
            "seed": o.seed,
            "scene_diagonal": comp.scene_diagonal,
            "objects": comp.objects,
        }),
    );
    Value::Object(reg)
}

/// `interact3d compose SAMPLE -o OUT`: compose, then write OUT atomically. Returns the
/// composition and its penetration check.
pub fn compose_folder(
    sample_dir: &Path,
    out: &Path,
    o: &ComposeOptions,
    limits: &Limits,
    force: bool,
) -> Result<(Composition, Value)> {
    if let (Ok(a), Ok(b)) = (sample_dir.canonicalize(), out.canonicalize()) {
        if a == b {
            return Err(Error::Usage(
                "OUT must differ from SAMPLE (the input folder is never modified)".into(),
            ));
        }
    }
    let sample = read_sample(sample_dir, limits)?;
    let comp = compose(&sample.inputs, o)?;
    let check = penetration_check(&sample, &comp, 200_000);
    let mut meta = sample.metadata.clone();
    meta.insert(
        "registration".into(),
        registration_json(&sample, &comp, &check, o),
    );
    let labels = meta.get("analysis").cloned();
    // The same names `export` gives the sample folder itself (labels, ids as aliases).
    let ids: Vec<String> = sample.inputs.iter().map(|i| i.name.clone()).collect();
    let shown = crate::scene::sample::object_names(&Value::Object(meta.clone()), &ids);
    let manifest = Manifest {
        format: crate::scene::manifest::FORMAT.into(),
        version: 1,
        name: sample_dir
            .canonicalize()
            .ok()
            .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned())),
        units: Units::Named("m".into()),
        up_axis: UpAxis::Y,
        objects: sample
            .inputs
            .iter()
            .zip(&shown)
            .filter_map(|(i, shown)| {
                let r = comp.get(&i.name)?;
                Some(ManifestObject {
                    name: shown.clone(),
                    mesh: format!("{}.glb", i.name),
                    label: labels
                        .as_ref()
                        .and_then(|a| a.get(&i.name))
                        .and_then(Value::as_str)
                        .map(str::to_string),
                    pose: Some(PoseSpec::Matrix {
                        matrix: rows(&r.transform.matrix()),
                    }),
                    composed_pose: None,
                    density: None,
                    mass: None,
                    friction: None,
                    fixed: false,
                    collision: Vec::new(),
                    inertial: None,
                })
            })
            .collect(),
    };
    crate::fsutil::write_dir_atomically(out, force, |tmp| {
        for i in &sample.inputs {
            let f = format!("{}.glb", i.name);
            std::fs::copy(sample.dir.join(&f), tmp.join(&f))
                .map_err(|e| Error::io(sample.dir.join(&f), e))?;
        }
        crate::fsutil::write(
            &tmp.join("metadata.json"),
            &crate::fsutil::json_bytes(&Value::Object(meta.clone()))?,
        )?;
        crate::fsutil::write(
            &tmp.join("scene.json"),
            &crate::fsutil::json_bytes(&manifest)?,
        )?;
        Ok(())
    })?;
    Ok((comp, check))
}
