//! Preparation: every object into one world frame in metres, Z up, the scene resting on z = 0,
//! optionally scaled so one named object has a given size (generated scenes have no real scale).

use crate::error::{Error, Result};
use crate::mesh::{Mesh, VisualMesh, V3};
use crate::pose::{y_up_to_z_up, Similarity};
use crate::scene::{Physical, Scene, UpAxis};
use nalgebra::UnitQuaternion;
use std::collections::BTreeMap;

/// Options of the preparation stage.
#[derive(Clone, Debug, Default)]
pub struct PrepareOptions {
    /// Object name → metres: scale the whole scene uniformly so that object's longest extent
    /// (in its own frame) has this length. At most one entry is used for the scale; several
    /// must agree within 1%.
    pub sizes: BTreeMap<String, f64>,
    /// Leave the scene where it is instead of putting its lowest point on z = 0.
    pub keep_height: bool,
}

/// One object in the world frame (metres, Z-up).
#[derive(Clone, Debug)]
pub struct PreparedObject {
    pub name: String,
    pub label: Option<String>,
    /// Visual mesh in world coordinates.
    pub visual: VisualMesh,
    /// Welded geometry in world coordinates.
    pub geometry: Mesh,
    /// Mesh frame → world.
    pub to_world: Similarity,
    pub physical: Physical,
    /// The geometry bounds a solid: watertight and consistently oriented, though more than two
    /// triangles may meet on an edge ([`Mesh::bounds_solid`]); its mass properties are then
    /// exact.
    pub closed: bool,
    pub warnings: Vec<String>,
}

/// A scene in the world frame.
#[derive(Clone, Debug)]
pub struct PreparedScene {
    pub name: String,
    pub objects: Vec<PreparedObject>,
    /// Scene-unit → world similarity applied (units, up axis, size, ground).
    pub scene_to_world: Similarity,
    pub warnings: Vec<String>,
}

/// Longest extent of a mesh's own-frame bounding box.
fn longest_extent(v: &VisualMesh) -> f64 {
    v.geometry()
        .aabb()
        .map(|b| b.extents().max())
        .unwrap_or(0.0)
}

/// Prepare a loaded scene.
pub fn prepare(scene: &Scene, opts: &PrepareOptions) -> Result<PreparedScene> {
    let mut warnings = scene.warnings.clone();
    let up: UnitQuaternion<f64> = match scene.up_axis {
        UpAxis::Y => y_up_to_z_up(),
        UpAxis::Z => UnitQuaternion::identity(),
    };
    // Scale: units, then the size override.
    let mut scale = scene.meters_per_unit;
    let mut size_scale: Option<f64> = None;
    for (name, &metres) in &opts.sizes {
        let obj = scene
            .objects
            .iter()
            .find(|o| &o.name == name)
            .ok_or_else(|| {
                Error::Usage(format!(
                    "--size names {name:?}, which is not an object of {} (objects: {})",
                    scene.source.display(),
                    scene
                        .objects
                        .iter()
                        .map(|o| o.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })?;
        if !(metres.is_finite() && metres > 0.0) {
            return Err(Error::Usage(format!(
                "--size {name}={metres}: size must be positive"
            )));
        }
        let current = longest_extent(&obj.visual) * obj.pose.scale * scale;
        let s = metres / current;
        if let Some(prev) = size_scale {
            if (prev - s).abs() > 0.01 * prev {
                return Err(Error::Usage(format!(
                    "--size values disagree: {name}={metres} implies a scale {s:.6} but another implies {prev:.6}"
                )));
            }
        }
        size_scale = Some(s);
    }
    if let Some(s) = size_scale {
        scale *= s;
    }
    let mut scene_to_world = Similarity {
        scale,
        rotation: up,
        translation: V3::zeros(),
    };

    let mut objects = Vec::with_capacity(scene.objects.len());
    for o in &scene.objects {
        let to_world = scene_to_world.then_after(&o.pose);
        let mut visual = o.visual.clone();
        visual.transform(&to_world.matrix());
        let geometry = visual.geometry();
        let closed = geometry.bounds_solid();
        let mut w = Vec::new();
        if !closed {
            w.push("mesh is not closed (a hole, a fin or a flipped triangle): inertia falls back to the union of the collision hulls".to_string());
        }
        objects.push(PreparedObject {
            name: o.name.clone(),
            label: o.label.clone(),
            visual,
            geometry,
            to_world,
            physical: o.physical.clone(),
            closed,
            warnings: w,
        });
    }
    let bounds = objects
        .iter()
        .filter_map(|o| o.geometry.aabb())
        .reduce(|a, b| a.union(&b))
        .ok_or_else(|| Error::input(&scene.source, "scene has no geometry"))?;
    let diag = bounds.diagonal();
    if diag < 1e-4 {
        warnings.push(format!(
            "scene is tiny ({diag:.3e} m across): check its units or pass --size"
        ));
    }
    if diag > 100.0 {
        warnings.push(format!(
            "scene is huge ({diag:.3e} m across): check its units or pass --size"
        ));
    }
    if !opts.keep_height {
        let shift = V3::new(0.0, 0.0, -bounds.min.z);
        let m = nalgebra::Translation3::from(shift).to_homogeneous();
        for o in &mut objects {
            o.visual.transform(&m);
            for v in &mut o.geometry.vertices {
                *v += shift;
            }
            o.to_world.translation += shift;
        }
        scene_to_world.translation += shift;
    }
    Ok(PreparedScene {
        name: scene.name.clone(),
        objects,
        scene_to_world,
        warnings,
    })
}
