//! `interact3d batch`: a whole dataset, parallel, resumable, shardable; or merging shards'
//! summaries.
//!
//! Entry point: [`batch`].

use super::args::{BatchArgs, ProgressArg};
use crate::Error;
use std::process::ExitCode;

/// Runs `batch`: the summary's exit code (2 when merged shards are incomplete).
pub fn batch(a: BatchArgs) -> Result<ExitCode, Error> {
    use crate::batch;
    if a.merge_reports {
        let m = batch::merge_reports(&a.out, &a.inputs)?;
        for w in &m.warnings {
            eprintln!("warning: {w}");
        }
        eprintln!(
            "merged {} summaries: {} scenes: {} pass, {} fail, {} error -> {}",
            m.summary.run.merged_from.len(),
            m.summary.counts.scenes,
            m.summary.counts.pass,
            m.summary.counts.fail,
            m.summary.counts.error,
            a.out.join("summary.json").display()
        );
        return Ok(ExitCode::from(if m.incomplete {
            2
        } else {
            m.summary.exit_code
        }));
    }
    let [root] = a.inputs.as_slice() else {
        return Err(Error::Usage(
            "batch takes one ROOT folder (several only with --merge-reports)".into(),
        ));
    };
    let job = crate::pipeline::ExportJob {
        limits: a.limits.limits(),
        build: a.build.options(),
        export: crate::export::ExportOptions {
            templates: a.templates,
            force: false,
        },
        validate: Some(a.check.options()),
        keep_composed_pose: a.keep_composed_pose,
        render: a.render.then(|| a.render_opts.options()),
        ..Default::default()
    };
    let mut opts = batch::BatchOptions::new(root, &a.out, job);
    opts.include = a.include;
    opts.exclude = a.exclude;
    opts.jobs = a.jobs;
    if let Some(arg) = a.shard {
        let d = arg.resolve(a.shards)?;
        if matches!(arg, batch::ShardArg::Auto) {
            eprintln!("shard {} from {}", d.shard, d.source);
        }
        opts.shard = Some(d.shard);
    }
    opts.resume = a.resume;
    opts.force = a.force;
    opts.progress = match a.progress {
        ProgressArg::Auto => batch::Progress::Auto,
        ProgressArg::Bar => batch::Progress::Bar,
        ProgressArg::Lines => batch::Progress::Lines,
        ProgressArg::Quiet => batch::Progress::Quiet,
    };
    if a.list {
        for e in batch::scenes(&opts)? {
            println!("{}", e.rel);
        }
        return Ok(ExitCode::SUCCESS);
    }
    let s = batch::run(&opts)?;
    eprintln!("{}", batch::counts_line(&s));
    eprintln!(
        "summary: {}",
        a.out.join(batch::Summary::file_name(s.shard)).display()
    );
    Ok(ExitCode::from(s.exit_code))
}
