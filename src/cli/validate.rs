//! `interact3d validate`: one scene's report, or the CI gate over many assets (JSON, JUnit,
//! SARIF, GitHub annotations, baselines).
//!
//! Entry point: [`validate`].

use super::args::ValidateArgs;
use super::print_warnings_and_summary;
use crate::Error;
use std::process::ExitCode;

/// Runs `validate`: exit 0 pass, 1 findings or a failed scene, 2 nothing readable.
pub fn validate(a: ValidateArgs) -> Result<ExitCode, Error> {
    use crate::validate::ci;
    let t = std::time::Instant::now();
    let mut entries = ci::discover(&a.paths)?;
    if let Some(r) = &a.changed_since {
        let read = crate::io::asset::ReadOptions {
            limits: a.limits.limits(),
            packages: a.packages.clone(),
            keep_welded: a.keep_welded,
        };
        entries = ci::changed_since(entries, &a.paths[0], r, &read)?;
    }
    let ci_flags = a.changed_since.is_some()
        || a.sarif.is_some()
        || a.github
        || a.baseline.is_some()
        || a.write_baseline.is_some()
        || a.fail_on.is_some();
    if let ([e], false) = (entries.as_slice(), ci_flags) {
        if e.kind == ci::Kind::Scene {
            // One scene or export folder: the scene report as before.
            let (assembly, v) = crate::pipeline::validate_path(
                &e.path,
                &a.limits.limits(),
                &a.build.options(),
                &a.check.options(),
            )?;
            eprint!("{}", crate::validate::table(&v));
            print_warnings_and_summary(
                &crate::report::Report::new(&assembly).warning_lines(Some(&v)),
                &format!(
                    "validated {} in {:.2} s: {}",
                    assembly.name,
                    t.elapsed().as_secs_f64(),
                    crate::validate::verdict_line(&v)
                ),
            );
            if a.json {
                let json =
                    serde_json::to_string_pretty(&v).map_err(|e| Error::Internal(e.to_string()))?;
                println!("{json}");
            }
            if let Some(f) = &a.junit {
                crate::fsutil::write_atomically(
                    f,
                    crate::validate::junit(&assembly.name, &v).as_bytes(),
                )?;
            }
            if let Some(dir) = &a.render {
                let json = serde_json::to_value(&v).map_err(|e| Error::Internal(e.to_string()))?;
                crate::render::render_to_dir(
                    &assembly,
                    dir,
                    &a.render_opts.options(),
                    Some(&json),
                    false,
                )?;
                eprintln!("pictures: {}", dir.join("index.html").display());
            }
            return Ok(if v.passed {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            });
        }
    }
    let mut opts = ci::RunOptions {
        scene_build: a.build.options(),
        scene_validate: a.check.options(),
        fail_on: a.fail_on,
        ..Default::default()
    };
    opts.asset.read.limits = a.limits.limits();
    opts.asset.read.packages = a.packages.clone();
    opts.asset.read.keep_welded = a.keep_welded;
    opts.asset.physics = !a.no_physics;
    opts.asset.settle = crate::physics::SettleOptions {
        perturbation_speed: opts.asset.settle.perturbation_speed,
        settle_max_time: opts.asset.settle.settle_max_time,
        ..a.check.options().settle
    };
    if let Some(b) = &a.baseline {
        opts.baseline = ci::read_baseline(b)?;
    }
    let run = ci::run(&entries, &opts);
    eprint!("{}", ci::table(&run));
    eprintln!(
        "validated {} assets in {:.2} s",
        run.reports.len(),
        t.elapsed().as_secs_f64()
    );
    let pretty = |v: &serde_json::Value| {
        serde_json::to_string_pretty(v).map_err(|e| Error::Internal(e.to_string()))
    };
    if a.json {
        println!("{}", pretty(&ci::json(&run))?);
    }
    if a.github {
        print!("{}", ci::github(&run));
    }
    if let Some(f) = &a.sarif {
        crate::fsutil::write_atomically(f, (pretty(&ci::sarif(&run))? + "\n").as_bytes())?;
    }
    if let Some(f) = &a.junit {
        crate::fsutil::write_atomically(f, ci::junit(&run).as_bytes())?;
    }
    if let Some(f) = &a.write_baseline {
        crate::fsutil::write_atomically(f, (pretty(&ci::baseline_json(&run))? + "\n").as_bytes())?;
    }
    Ok(ExitCode::from(ci::exit_code(&run)))
}
