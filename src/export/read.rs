//! Reading an export folder back: the bodies exactly as written (visual OBJ in body frames,
//! collision hull OBJs, inertials and initial poses from `scene.json`), so `validate OUT` checks
//! what a simulator will load, not a recomputation. Static checks run at the recorded composed
//! pose; the settle starts from the initial (shipped) pose.

use crate::body::{Assembly, Body};
use crate::decompose::Hull;
use crate::error::{Error, Result};
use crate::inertia::{Inertial, VolumeSource};
use crate::io::{resolve_inside, Limits};
use crate::pose::Similarity;
use crate::scene::manifest;
use nalgebra::{Isometry3, Matrix3};
use std::path::Path;

/// Whether `path` is an interact3d export folder (a `scene.json` with hulls and inertials).
pub fn is_export(path: &Path) -> bool {
    let m = if path.is_dir() {
        path.join("scene.json")
    } else {
        path.to_path_buf()
    };
    manifest::read(&m)
        .map(|m| {
            !m.objects.is_empty()
                && m.objects
                    .iter()
                    .all(|o| !o.collision.is_empty() && o.inertial.is_some())
        })
        .unwrap_or(false)
}

/// Load an export folder (or its `scene.json`).
pub fn load(path: &Path, limits: &Limits) -> Result<Assembly> {
    let mpath = if path.is_dir() {
        path.join("scene.json")
    } else {
        path.to_path_buf()
    };
    let root = mpath.parent().unwrap_or(Path::new(".")).to_path_buf();
    let m = manifest::read_with(&mpath, limits)?;
    let mut bodies = Vec::new();
    for o in &m.objects {
        let err = |msg: String| Error::input(&mpath, format!("object {:?}: {msg}", o.name));
        let pose = o
            .pose
            .as_ref()
            .map(|p| p.to_similarity())
            .transpose()
            .map_err(err)?
            .unwrap_or_default();
        if (pose.scale - 1.0).abs() > 1e-9 {
            return Err(err("an export's poses are rigid (scale 1)".into()));
        }
        let composed = match &o.composed_pose {
            Some(p) => p.to_similarity().map_err(err)?,
            None => pose,
        };
        let visual = crate::io::load_visual(&resolve_inside(&root, &mpath, &o.mesh)?, limits)?;
        let geometry = visual.geometry();
        let mut hulls = Vec::new();
        for (k, c) in o.collision.iter().enumerate() {
            let file = resolve_inside(&root, &mpath, c)?;
            let mesh = crate::io::load_visual(&file, limits)?.geometry();
            hulls.push(
                Hull::from_points(&mesh.vertices)
                    .ok_or_else(|| err(format!("collision hull {k} ({c}) is degenerate")))?,
            );
        }
        let i = o
            .inertial
            .as_ref()
            .ok_or_else(|| err("no inertial".into()))?;
        let inertial = Inertial {
            mass: i.mass,
            com: crate::mesh::P3::from(i.com),
            inertia: Matrix3::from_fn(|r, c| i.inertia[r][c]),
            volume: 0.0,
            source: VolumeSource::ClosedMesh,
        };
        inertial.check().map_err(err)?;
        let iso = |s: &Similarity| Isometry3::from_parts(s.translation.into(), s.rotation);
        bodies.push(Body {
            name: o.name.clone(),
            label: o.label.clone(),
            pose: iso(&pose),
            composed_pose: iso(&composed),
            mesh_to_body: Similarity::identity(),
            closed: geometry.is_closed(),
            visual,
            geometry,
            hulls,
            inertial,
            friction: o.friction.unwrap_or(crate::body::DEFAULT_FRICTION),
            fixed: o.fixed,
            warnings: Vec::new(),
            fidelity: None,
        });
    }
    Ok(Assembly {
        name: m.name.clone().unwrap_or_else(|| "scene".into()),
        bodies,
        decomposer: "as exported".into(),
        scene_to_world: Similarity::identity(),
        warnings: Vec::new(),
    })
}
