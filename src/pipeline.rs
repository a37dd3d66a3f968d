//! The stages chained for the commands: load → prepare → decompose → inertia → (validate) →
//! export. Each stage is usable on its own; this is the shortest path through all of them.

use crate::body::{build, Assembly, BuildOptions};
use crate::error::Result;
use crate::export::{export, ExportOptions};
use crate::io::Limits;
use crate::report::Report;
use std::path::Path;

/// Everything `export` needs.
#[derive(Clone, Debug, Default)]
pub struct ExportJob {
    pub limits: Limits,
    pub build: BuildOptions,
    pub export: ExportOptions,
}

/// Load a scene (sample folder or manifest) and build its bodies.
pub fn load_assembly(scene: &Path, limits: &Limits, opts: &BuildOptions) -> Result<Assembly> {
    let scene = crate::scene::load(scene, limits)?;
    build(&scene, opts)
}

/// Export a scene to `out`; returns the report written.
pub fn export_scene(scene: &Path, out: &Path, job: &ExportJob) -> Result<Report> {
    let assembly = load_assembly(scene, &job.limits, &job.build)?;
    let report = Report::new(&assembly);
    export(&assembly, &report, out, &job.export)?;
    Ok(report)
}
