//! Export: a folder of simulation assets from an [`Assembly`].
//!
//! ```text
//! OUT/scene.xml                MJCF scene (floor, light, one body per object)
//! OUT/<object>.xml             MJCF of one object (includable)
//! OUT/<object>.urdf            URDF of one object
//! OUT/meshes/<object>/visual.obj, visual.mtl, texture_NN.png, collision_NN.obj
//! OUT/scene.usda               USD scene (PhysicsScene, ground, each object referenced)
//! OUT/<object>.usda            USD of one object (one rigid body on the default prim)
//! OUT/scene.json               the prepared scene as a manifest (re-readable)
//! OUT/report.json              per-object mass, inertia, hulls, warnings (+ validation)
//! ```
//! Everything is written into a temporary folder beside OUT and renamed into place at the end,
//! so an error never leaves a partial OUT.

mod files;
pub mod format;
pub mod read;
pub mod rest_offset;
mod templates;
pub mod usd;

pub use templates::Templates;

use crate::body::{Assembly, Body};
use crate::error::Result;
use crate::report::Report;
use crate::scene::manifest::{InertialSpec, Manifest, ManifestObject, PoseSpec, Units};
use crate::scene::UpAxis;
use format::{f, vec3};
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;

/// What a tool version writes into generated files.
pub const GENERATOR: &str = concat!("interact3d ", env!("CARGO_PKG_VERSION"));

/// Friction of the floor in the MJCF (MuJoCo combines by the maximum; the USD's floor has the
/// settle test's friction, combined by averaging as Rapier does: [`usd::PhysxCtx`]).
const FLOOR_FRICTION: f64 = 1.0;

/// The MJCF's contact dimension and torsional and rolling friction, from the settle test's
/// options (the file says what the settle assumed): `condim="6"` with the settle's
/// [`rolling_friction`](crate::physics::SettleOptions::rolling_friction) as the geoms' third
/// `friction` value when it has one, else `condim="4"` (sliding and torsional friction) and
/// MuJoCo's default rolling coefficient, which condim 4 ignores. PhysX has no rolling friction:
/// the USD cannot state it.
fn mjcf_contact() -> minijinja::Value {
    let rolling = crate::physics::SettleOptions::default().rolling_friction;
    let (condim, rolling) = if rolling > 0.0 {
        (6, rolling)
    } else {
        (4, 0.0001)
    };
    minijinja::context! { condim => condim, torsion => f(0.005), rolling => f(rolling) }
}

/// Options of the export stage.
#[derive(Clone, Debug, Default)]
pub struct ExportOptions {
    /// A folder with `scene.xml.j2`, `object.xml.j2`, `object.urdf.j2` overriding the built-in ones
    /// (any missing file falls back to the built-in template).
    pub templates: Option<std::path::PathBuf>,
    /// Replace OUT even when it does not look like an earlier interact3d export.
    pub force: bool,
}

/// Write the assets of `assembly` to `out`, atomically.
pub fn export(
    assembly: &Assembly,
    report: &Report,
    out: &Path,
    opts: &ExportOptions,
) -> Result<()> {
    let templates = Templates::load(opts.templates.as_deref())?;
    crate::fsutil::write_dir_atomically(out, opts.force, |tmp| {
        write_all(assembly, report, tmp, &templates)
    })
}

fn write_all(
    assembly: &Assembly,
    report: &Report,
    dir: &Path,
    templates: &Templates,
) -> Result<()> {
    // Each body's mesh files go to their own folder: written side by side, gathered in order
    // (the first error in body order is the one reported, as when written one by one).
    let meshes = dir.join("meshes");
    let written: Vec<Result<files::BodyFiles>> = assembly
        .bodies
        .par_iter()
        .map(|b| files::write_body_meshes(b, &meshes))
        .collect();
    let body_files = written.into_iter().collect::<Result<Vec<_>>>()?;
    let ctx_bodies: Vec<BodyCtx> = assembly
        .bodies
        .iter()
        .zip(&body_files)
        .map(|(b, files)| body_context(b, files))
        .collect();
    // The USD files and the MJCF/URDF/JSON ones share nothing but their inputs.
    let (usd, rest) = rayon::join(
        || {
            // The USD says what the settle test assumed (export follows validation with the
            // default options); the MJCF keeps its own floor (MuJoCo takes the larger friction).
            let physx = usd::PhysxCtx::from_settle(&crate::physics::SettleOptions::default());
            usd::write_usd(
                assembly,
                &body_files,
                dir,
                templates,
                &physx,
                &heavily_loaded(report),
            )
        },
        || write_mjcf_urdf_json(assembly, report, dir, templates, &ctx_bodies),
    );
    usd?;
    rest
}

/// The bodies the validation's settle marked heavily loaded (`validation.settle.heavily_loaded`
/// of the report); none when the scene was not validated.
fn heavily_loaded(report: &Report) -> Vec<String> {
    report
        .validation
        .as_ref()
        .and_then(|v| v["settle"]["heavily_loaded"].as_array())
        .map(|a| {
            a.iter()
                .filter_map(|n| n.as_str().map(String::from))
                .collect()
        })
        .unwrap_or_default()
}

/// `scene.xml`, each body's `.xml` and `.urdf`, `scene.json` and `report.json`.
fn write_mjcf_urdf_json(
    assembly: &Assembly,
    report: &Report,
    dir: &Path,
    templates: &Templates,
    ctx_bodies: &[BodyCtx],
) -> Result<()> {
    let keyframes = keyframes(assembly);
    let scene_ctx = minijinja::context! {
        generator => GENERATOR,
        scene => minijinja::context! { name => assembly.name.clone() },
        bodies => ctx_bodies.to_vec(),
        keyframes => keyframes,
        floor_friction => f(FLOOR_FRICTION),
        contact => mjcf_contact(),
    };
    crate::fsutil::write(
        &dir.join("scene.xml"),
        templates.render("scene.xml.j2", scene_ctx)?.as_bytes(),
    )?;
    for b in ctx_bodies {
        let ctx = minijinja::context! {
            generator => GENERATOR,
            b => b.clone(),
            contact => mjcf_contact(),
        };
        crate::fsutil::write(
            &dir.join(format!("{}.xml", b.name)),
            templates.render("object.xml.j2", ctx.clone())?.as_bytes(),
        )?;
        crate::fsutil::write(
            &dir.join(format!("{}.urdf", b.name)),
            templates.render("object.urdf.j2", ctx)?.as_bytes(),
        )?;
    }
    let manifest = manifest(assembly);
    crate::fsutil::write(
        &dir.join("scene.json"),
        &crate::fsutil::json_bytes(&manifest)?,
    )?;
    crate::fsutil::write(
        &dir.join("report.json"),
        &crate::fsutil::json_bytes(report)?,
    )?;
    Ok(())
}

#[derive(Clone, Serialize)]
struct MaterialCtx {
    name: String,
    rgba: String,
    texture: Option<String>,
    texture_name: String,
}

#[derive(Clone, Serialize)]
struct MeshCtx {
    mesh: String,
    file: String,
    material: String,
}

#[derive(Clone, Serialize)]
struct InertiaCtx {
    ixx: String,
    iyy: String,
    izz: String,
    ixy: String,
    ixz: String,
    iyz: String,
}

#[derive(Clone, Serialize)]
struct BodyCtx {
    name: String,
    pos: String,
    quat: String,
    fixed: bool,
    mass: String,
    fullinertia: String,
    inertia: InertiaCtx,
    friction: String,
    materials: Vec<MaterialCtx>,
    visuals: Vec<MeshCtx>,
    hulls: Vec<MeshCtx>,
    urdf_visual: String,
    urdf_rgba: String,
    /// The body's initial world pose (as in scene.json), for the URDF's comment: position,
    /// quaternion scalar last, and URDF's roll-pitch-yaw.
    pose_xyz: String,
    quat_xyzw: String,
    pose_rpy: String,
}

fn body_context(b: &Body, files: &files::BodyFiles) -> BodyCtx {
    let i = &b.inertial.inertia;
    let q = b.pose.rotation.quaternion();
    let inertia = InertiaCtx {
        ixx: f(i[(0, 0)]),
        iyy: f(i[(1, 1)]),
        izz: f(i[(2, 2)]),
        ixy: f(i[(0, 1)]),
        ixz: f(i[(0, 2)]),
        iyz: f(i[(1, 2)]),
    };
    let materials: Vec<MaterialCtx> = files
        .materials
        .iter()
        .map(|m| MaterialCtx {
            name: m.name.clone(),
            rgba: m.rgba.iter().map(|x| f(*x)).collect::<Vec<_>>().join(" "),
            texture: m.texture.clone(),
            texture_name: format!("{}_texture", m.name),
        })
        .collect();
    let urdf_rgba = match files.materials.first() {
        Some(m) if m.texture.is_none() && files.materials.len() == 1 => {
            m.rgba.iter().map(|x| f(*x)).collect::<Vec<_>>().join(" ")
        }
        _ => "1 1 1 1".into(),
    };
    BodyCtx {
        name: b.name.clone(),
        pos: vec3(&b.pose.translation.vector),
        quat: format!("{} {} {} {}", f(q.w), f(q.i), f(q.j), f(q.k)),
        fixed: b.fixed,
        mass: f(b.inertial.mass),
        fullinertia: format!(
            "{} {} {} {} {} {}",
            inertia.ixx, inertia.iyy, inertia.izz, inertia.ixy, inertia.ixz, inertia.iyz
        ),
        inertia,
        friction: f(b.friction),
        materials,
        visuals: files
            .visual_parts
            .iter()
            .enumerate()
            .map(|(k, (file, mat))| MeshCtx {
                mesh: format!("{}_visual_{k:02}", b.name),
                file: file.clone(),
                material: mat.clone(),
            })
            .collect(),
        hulls: files
            .hulls
            .iter()
            .enumerate()
            .map(|(k, file)| MeshCtx {
                mesh: format!("{}_collision_{k:02}", b.name),
                file: file.clone(),
                material: String::new(),
            })
            .collect(),
        urdf_visual: format!("meshes/{}", files.visual_all),
        urdf_rgba,
        pose_xyz: vec3(&b.pose.translation.vector),
        quat_xyzw: format!("{} {} {} {}", f(q.i), f(q.j), f(q.k), f(q.w)),
        pose_rpy: {
            let (r, p, y) = b.pose.rotation.euler_angles();
            format!("{} {} {}", f(r), f(p), f(y))
        },
    }
}

#[derive(Clone, Serialize)]
struct KeyCtx {
    name: String,
    qpos: String,
}

/// `composed` always; `initial` too when the bodies start elsewhere (settled poses).
fn keyframes(a: &Assembly) -> Vec<KeyCtx> {
    let qpos = |settled: bool| -> String {
        a.bodies
            .iter()
            .filter(|b| !b.fixed)
            .map(|b| {
                let p = if settled { b.pose } else { b.composed_pose };
                let q = p.rotation.quaternion();
                format!(
                    "{} {} {} {} {}",
                    vec3(&p.translation.vector),
                    f(q.w),
                    f(q.i),
                    f(q.j),
                    f(q.k)
                )
            })
            .collect::<Vec<_>>()
            .join("  ")
    };
    if a.bodies.iter().all(|b| b.fixed) {
        return Vec::new();
    }
    let mut keys = vec![KeyCtx {
        name: "composed".into(),
        qpos: qpos(false),
    }];
    if a.bodies.iter().any(|b| b.pose != b.composed_pose) {
        keys.push(KeyCtx {
            name: "settled".into(),
            qpos: qpos(true),
        });
    }
    keys
}

fn pose_spec(p: &nalgebra::Isometry3<f64>) -> PoseSpec {
    PoseSpec::from_similarity(&crate::pose::Similarity {
        scale: 1.0,
        rotation: p.rotation,
        translation: p.translation.vector,
    })
}

/// The prepared scene as a manifest: Z-up metres, visual OBJs in body frames, hulls, inertials.
fn manifest(a: &Assembly) -> Manifest {
    Manifest {
        format: crate::scene::manifest::FORMAT.into(),
        version: 1,
        name: Some(a.name.clone()),
        units: Units::Named("m".into()),
        up_axis: UpAxis::Z,
        objects: a
            .bodies
            .iter()
            .map(|b| ManifestObject {
                name: b.name.clone(),
                mesh: format!("meshes/{}/visual.obj", b.name),
                label: b.label.clone(),
                pose: Some(pose_spec(&b.pose)),
                composed_pose: (b.pose != b.composed_pose).then(|| pose_spec(&b.composed_pose)),
                density: None,
                mass: Some(format::round(b.inertial.mass)),
                friction: Some(b.friction),
                fixed: b.fixed,
                collision: (0..b.hulls.len())
                    .map(|k| format!("meshes/{}/collision_{k:02}.obj", b.name))
                    .collect(),
                inertial: Some(InertialSpec {
                    mass: format::round(b.inertial.mass),
                    com: [0.0; 3],
                    inertia: std::array::from_fn(|r| {
                        std::array::from_fn(|c| format::round(b.inertial.inertia[(r, c)]))
                    }),
                }),
            })
            .collect(),
    }
}
