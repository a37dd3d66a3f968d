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
    /// The input's up axis (`--up`), overriding a lone OBJ/STL mesh's Z-up default or a
    /// manifest's `up_axis`; refused for glTF, which is Y-up by its specification.
    pub up: Option<UpAxis>,
    /// Object name (or alias) → density in kg/m³ (`--density NAME=KG_M3`), over the scene's own.
    pub densities: BTreeMap<String, f64>,
    /// Object name (or alias) → mass in kg (`--mass NAME=KG`), over the scene's own and over any
    /// density.
    pub masses: BTreeMap<String, f64>,
}

/// A lone object whose longest extent is outside these bounds (metres) gets a warning naming
/// `--size`: a mesh file carries no unit, and one in millimetres or centimetres read as metres
/// becomes a 1,000 kg duck.
pub const LONE_OBJECT_METRES: (f64, f64) = (0.005, 2.0);

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
    let up_axis = match (opts.up, scene.up_axis_fixed()) {
        (Some(UpAxis::Z), Some(why)) => {
            return Err(Error::Usage(format!(
                "--up z does not apply to {}: {why}",
                scene.source.display()
            )))
        }
        (Some(u), _) => u,
        (None, _) => scene.up_axis,
    };
    let find = |flag: &str, name: &str| {
        scene.find(name).ok_or_else(|| {
            Error::Usage(format!(
                "{flag} names {name:?}, which is not an object of {} (objects: {})",
                scene.source.display(),
                scene.names_listed()
            ))
        })
    };
    let mut physical: BTreeMap<&str, Physical> = scene
        .objects
        .iter()
        .map(|o| (o.name.as_str(), o.physical.clone()))
        .collect();
    for (flag, values, unit) in [
        ("--density", &opts.densities, "kg/m³"),
        ("--mass", &opts.masses, "kg"),
    ] {
        for (name, &v) in values {
            let o = find(flag, name)?;
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::Usage(format!(
                    "{flag} {name}={v}: must be a positive number of {unit}"
                )));
            }
            let p = physical
                .get_mut(o.name.as_str())
                .expect("every object has an entry");
            if flag == "--mass" {
                p.mass = Some(v);
            } else {
                // A density from the command line replaces a mass the scene gave too (a
                // `--mass` for the same object, applied next, wins over both).
                p.density = Some(v);
                p.mass = None;
            }
        }
    }
    let up: UnitQuaternion<f64> = match up_axis {
        UpAxis::Y => y_up_to_z_up(),
        UpAxis::Z => UnitQuaternion::identity(),
    };
    // Scale: units, then the size override.
    let mut scale = scene.meters_per_unit;
    let mut size_scale: Option<f64> = None;
    for (name, &metres) in &opts.sizes {
        let obj = find("--size", name)?;
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
            physical: physical[o.name.as_str()].clone(),
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
    if let ([o], None) = (objects.as_slice(), size_scale) {
        let (lo, hi) = LONE_OBJECT_METRES;
        let long = o.geometry.aabb().map(|b| b.extents().max()).unwrap_or(0.0);
        if !(lo..=hi).contains(&long) {
            warnings.push(format!(
                "{} is {} long, read as metres: if that is not its real size, pass --size {}=METRES (its longest extent)",
                o.name,
                if long >= 0.1 {
                    format!("{long:.3} m")
                } else {
                    format!("{:.3} mm", long * 1e3)
                },
                o.name
            ));
        }
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
