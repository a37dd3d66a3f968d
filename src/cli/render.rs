//! `interact3d render`: pictures of a scene or an export folder.
//!
//! Entry point: [`render`].

use super::args::RenderArgs;
use crate::Error;
use std::process::ExitCode;

/// Runs `render`.
pub fn render(a: RenderArgs) -> Result<ExitCode, Error> {
    let t = std::time::Instant::now();
    let assembly = crate::pipeline::load_any(&a.path, &a.limits.limits(), &a.build.options())?;
    let t_draw = std::time::Instant::now();
    let r = crate::render::render_to_dir(&assembly, &a.out, &a.render.options(), None, a.force)?;
    eprintln!(
        "rendered {} pictures of {} into {} in {:.2} s (loading {:.2} s)",
        r.pictures.len(),
        assembly.name,
        a.out.display(),
        t_draw.elapsed().as_secs_f64(),
        (t_draw - t).as_secs_f64()
    );
    Ok(ExitCode::SUCCESS)
}
