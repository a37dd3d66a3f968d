//! The stages chained for the commands: load → prepare → decompose → inertia → (validate) →
//! export. Each stage is usable on its own; this is the shortest path through all of them.

use crate::body::{build, Assembly, BuildOptions};
use crate::error::Result;
use crate::export::{export, ExportOptions};
use crate::io::Limits;
use crate::report::Report;
use crate::validate::{apply_settled_poses, validate, ValidateOptions, Validation};
use std::path::Path;

/// Everything `export` needs.
#[derive(Clone, Debug, Default)]
pub struct ExportJob {
    pub limits: Limits,
    pub build: BuildOptions,
    pub export: ExportOptions,
    /// Validate before writing (`None`: skip, `--no-validate`).
    pub validate: Option<ValidateOptions>,
    /// Keep the composed poses as the bodies' initial poses even when validation passes
    /// (by default a passing scene starts from its settled poses).
    pub keep_composed_pose: bool,
    /// Remove slight interpenetration of the given poses first (`--fix-penetration`: the
    /// collision-aware refinement of `compose`, moving each object as little as possible).
    pub fix_penetration: bool,
    /// Draw the scene into `OUT/render/` (`--render`; see [`crate::render`]).
    pub render: Option<crate::render::RenderOptions>,
}

/// Load a scene (sample folder or manifest) and build its bodies.
pub fn load_assembly(scene: &Path, limits: &Limits, opts: &BuildOptions) -> Result<Assembly> {
    let scene = crate::scene::load(scene, limits)?;
    build(&scene, opts)
}

/// The result of an export.
pub struct Exported {
    pub report: Report,
    pub validation: Option<Validation>,
    /// Pictures drawn into `OUT/render/` (with `ExportJob::render`).
    pub rendered: bool,
}

/// Export a scene to `out`, validating it first unless told not to; returns what was written.
/// A scene that fails validation is still exported (its report says why), from its composed poses.
pub fn export_scene(scene: &Path, out: &Path, job: &ExportJob) -> Result<Exported> {
    let (mut assembly, fixes) = if job.fix_penetration {
        let mut s = crate::scene::load(scene, &job.limits)?;
        let fixes = crate::compose::fix_penetration(&mut s, &Default::default());
        (build(&s, &job.build)?, fixes)
    } else {
        (load_assembly(scene, &job.limits, &job.build)?, Vec::new())
    };
    let mut report = Report::new(&assembly);
    for f in fixes.iter().filter(|f| f.penetration_before > 0.0) {
        report.warnings.push(format!(
            "--fix-penetration moved {} by at most {:.3e} scene units: penetration {:.3e} -> {:.3e}",
            f.name, f.moved, f.penetration_before, f.penetration_after
        ));
    }
    let validation = match &job.validate {
        Some(opts) => {
            let v = validate(&assembly, opts)?;
            if v.passed && !job.keep_composed_pose {
                apply_settled_poses(&mut assembly, &v);
            }
            report.validation =
                Some(serde_json::to_value(&v).map_err(|e| crate::Error::Internal(e.to_string()))?);
            Some(v)
        }
        None => None,
    };
    export(&assembly, &report, out, &job.export)?;
    if let Some(ro) = &job.render {
        crate::render::render_to_dir(
            &assembly,
            &out.join("render"),
            ro,
            report.validation.as_ref(),
            true,
        )?;
    }
    Ok(Exported {
        report,
        validation,
        rendered: job.render.is_some(),
    })
}

/// Validate a scene, or an export folder (its hulls and inertials as written, from its initial
/// poses).
pub fn validate_path(
    path: &Path,
    limits: &Limits,
    build: &BuildOptions,
    opts: &ValidateOptions,
) -> Result<(Assembly, Validation)> {
    let assembly = load_any(path, limits, build)?;
    let v = validate(&assembly, opts)?;
    Ok((assembly, v))
}

/// An export folder's bodies as written, or a scene's bodies built afresh.
pub fn load_any(path: &Path, limits: &Limits, build: &BuildOptions) -> Result<Assembly> {
    if crate::export::read::is_export(path) {
        crate::export::read::load(path, limits)
    } else {
        load_assembly(path, limits, build)
    }
}
