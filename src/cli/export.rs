//! `interact3d export`: one scene to MJCF, URDF and USD, validated; a line per object and the
//! validation table on stderr.
//!
//! Entry point: [`export`].

use super::args::ExportArgs;
use super::print_warnings_and_summary;
use crate::Error;
use std::process::ExitCode;

/// Runs `export`: exit 0 when the export passes validation (or is not validated), 1 when it fails.
pub fn export(a: ExportArgs) -> Result<ExitCode, Error> {
    let job = crate::pipeline::ExportJob {
        limits: a.limits.limits(),
        build: a.build.options(),
        export: crate::export::ExportOptions {
            templates: a.templates,
            force: a.force,
        },
        validate: (!a.no_validate).then(|| a.check.options()),
        keep_composed_pose: a.keep_composed_pose,
        fix_penetration: a.fix_penetration,
        render: a.render.then(|| a.render_opts.options()),
    };
    let t = std::time::Instant::now();
    let done = crate::pipeline::export_scene(&a.scene, &a.out, &job)?;
    let report = &done.report;
    for o in &report.objects {
        // Collision fit, % of the bbox diagonal: two-sided p95 (hulls→mesh,
        // mesh→hulls) and the mesh's outside depth at p99.
        let fit = o.collision_fit.map_or(String::new(), |f| {
            format!(
                "fit p95 {:>5.2} % ({:.2}/{:.2})  outside p99 {:>4.2} %  ",
                f.p95 * 100.0,
                f.hull_to_mesh_p95 * 100.0,
                f.mesh_to_hull_p95 * 100.0,
                f.outside_p99 * 100.0
            )
        });
        eprintln!(
            "{:<16} mass {:>9.4} kg  hulls {:>3}  max verts {:>3}  {fit}{}",
            o.name,
            o.mass,
            o.hull_count,
            o.hull_vertex_counts.iter().max().unwrap_or(&0),
            if o.closed {
                "closed"
            } else {
                "open: hull-union inertia"
            }
        );
    }
    let mut summary = format!(
        "exported {} to {} in {:.2} s: ",
        report.scene,
        a.out.display(),
        t.elapsed().as_secs_f64()
    );
    let code = match &done.validation {
        Some(v) => {
            eprint!("{}", crate::validate::table(v));
            if let Some(f) = &a.junit {
                crate::fsutil::write_atomically(
                    f,
                    crate::validate::junit(&report.scene, v).as_bytes(),
                )?;
            }
            summary += &crate::validate::verdict_line(v);
            if v.passed {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }
        None => {
            summary += "not validated";
            ExitCode::SUCCESS
        }
    };
    print_warnings_and_summary(&report.warning_lines(done.validation.as_ref()), &summary);
    Ok(code)
}
