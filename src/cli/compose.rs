//! `interact3d compose`: register a sample folder's objects onto their guidance, optionally
//! with the agentic loop (`--agent`).
//!
//! Entry point: [`compose`].

use super::args::ComposeArgs;
use crate::Error;
use std::process::ExitCode;

/// Runs `compose`: exit 1 when the agentic loop ends above its threshold.
pub fn compose(a: ComposeArgs) -> Result<ExitCode, Error> {
    let t = std::time::Instant::now();
    let opts = crate::compose::ComposeOptions {
        method: a.method,
        seed: a.seed,
        anchor: a.anchor,
        ..Default::default()
    };
    if let Some(cmd) = &a.agent {
        let mut ao = crate::compose::agent::AgentOptions::new(cmd.clone());
        ao.max_iterations = a.max_iterations;
        let r = crate::compose::agent::compose_with_agent(
            &a.sample,
            &a.out,
            &opts,
            &Default::default(),
            a.force,
            &ao,
        )?;
        eprintln!(
            "composed into {} with {} agent call(s) in {:.2} s: penetration ratio {:.2e} ({})",
            a.out.display(),
            r.iterations,
            t.elapsed().as_secs_f64(),
            r.ratio,
            if r.success {
                "success"
            } else {
                "still above the threshold"
            }
        );
        return Ok(if r.success {
            ExitCode::SUCCESS
        } else {
            ExitCode::from(1)
        });
    }
    let (comp, check) = crate::compose::folder::compose_folder(
        &a.sample,
        &a.out,
        &opts,
        &Default::default(),
        a.force,
    )?;
    for o in &comp.objects {
        eprintln!(
            "{:<16} scale {:>9.5}  score {:.3}  rms {:.3e}  {}",
            o.name, o.transform.scale, o.score, o.icp_rms, o.method
        );
    }
    eprintln!(
        "composed {} objects (anchor {}) into {} in {:.2} s; max R_volume {:.2e}, max penetration {:.2e}",
        comp.objects.len(),
        comp.anchor,
        a.out.display(),
        t.elapsed().as_secs_f64(),
        check["max_r_volume"].as_f64().unwrap_or(f64::NAN),
        check["max_penetration_depth"].as_f64().unwrap_or(f64::NAN),
    );
    Ok(ExitCode::SUCCESS)
}
