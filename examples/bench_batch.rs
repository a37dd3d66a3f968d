//! Throughput and peak memory of `interact3d batch` on generated two-object scenes, and how the
//! time grows with the number of scenes.
//!
//! ```text
//! cargo run --release --example bench_batch                      # 50, 100, 200 scenes, 2 jobs
//! cargo run --release --example bench_batch -- --sizes 50,200 --jobs 2
//! cargo run --release --example bench_batch -- --gen DIR N       # only write a dataset
//! ```
//!
//! Each size runs in a fresh child process (this executable again), so its peak resident set
//! (`VmHWM` from /proc/self/status) is its own. Validation uses the command's defaults
//! (R_volume on 10^6 points). After the largest size, the same batch is run again to time a
//! rerun where every scene is reused.

#[path = "../tests/batch_data/mod.rs"]
mod batch_data;

use interact3d::batch::{BatchOptions, Progress};
use interact3d::pipeline::ExportJob;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

#[path = "common/procstat.rs"]
mod procstat;
use procstat::peak_rss_mib;

/// In the child: run one batch, print "scenes elapsed_s peak_rss_mib converted".
fn child(root: &Path, out: &Path, jobs: usize) {
    let job = ExportJob {
        validate: Some(Default::default()),
        ..Default::default()
    };
    let mut opts = BatchOptions::new(root, out, job);
    opts.jobs = Some(jobs);
    opts.progress = Progress::Quiet;
    let t = Instant::now();
    let s = interact3d::batch::run(&opts).expect("batch");
    println!(
        "{} {} {} {} {} {}",
        s.counts.scenes,
        t.elapsed().as_secs_f64(),
        peak_rss_mib(),
        s.run.converted,
        s.counts.pass,
        s.counts.fail + s.counts.error
    );
}

struct Measured {
    scenes: usize,
    secs: f64,
    rss: f64,
    converted: usize,
    pass: usize,
    not_pass: usize,
}

fn measure(root: &Path, out: &Path, jobs: usize) -> Measured {
    let o = Command::new(std::env::current_exe().unwrap())
        .args(["--child", root.to_str().unwrap(), out.to_str().unwrap()])
        .arg(jobs.to_string())
        .output()
        .expect("run child");
    assert!(
        o.status.success(),
        "child failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let text = String::from_utf8_lossy(&o.stdout);
    let v: Vec<f64> = text
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    Measured {
        scenes: v[0] as usize,
        secs: v[1],
        rss: v[2],
        converted: v[3] as usize,
        pass: v[4] as usize,
        not_pass: v[5] as usize,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--child") {
        child(
            Path::new(&args[1]),
            Path::new(&args[2]),
            args[3].parse().unwrap(),
        );
        return;
    }
    if args.first().map(String::as_str) == Some("--gen") {
        let n: usize = args[2].parse().unwrap();
        let made = batch_data::make_dataset(
            Path::new(&args[1]),
            batch_data::Spec {
                good: n,
                ..Default::default()
            },
        );
        println!("{} scenes in {}", made.len(), args[1]);
        return;
    }
    let mut sizes = vec![50usize, 100, 200];
    let mut jobs = 2usize;
    let mut work: Option<PathBuf> = None;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--sizes" => {
                sizes = it
                    .next()
                    .unwrap()
                    .split(',')
                    .map(|s| s.parse().unwrap())
                    .collect()
            }
            "--jobs" => jobs = it.next().unwrap().parse().unwrap(),
            "--work" => work = Some(PathBuf::from(it.next().unwrap())),
            other => panic!("unknown argument {other}"),
        }
    }
    let tmp = tempfile::tempdir().unwrap();
    let work = work.unwrap_or_else(|| tmp.path().to_path_buf());
    println!(
        "bench_batch: generated two-object scenes, {jobs} jobs, default validation (10^6 points)"
    );
    println!(
        "{:>7} {:>10} {:>12} {:>10} {:>12} {:>6}",
        "scenes", "time s", "scenes/min", "s/scene", "peak RSS MiB", "pass"
    );
    let mut results = Vec::new();
    for &n in &sizes {
        let root = work.join(format!("data{n}"));
        let out = work.join(format!("out{n}"));
        let _ = std::fs::remove_dir_all(&root);
        let _ = std::fs::remove_dir_all(&out);
        batch_data::make_dataset(
            &root,
            batch_data::Spec {
                good: n,
                ..Default::default()
            },
        );
        let m = measure(&root, &out, jobs);
        assert_eq!(m.scenes, n);
        assert_eq!(m.converted, n);
        println!(
            "{:>7} {:>10.1} {:>12.1} {:>10.3} {:>12.1} {:>6}",
            n,
            m.secs,
            60.0 * n as f64 / m.secs,
            m.secs / n as f64,
            m.rss,
            format!("{}/{}", m.pass, m.pass + m.not_pass)
        );
        results.push((n, m));
    }
    if let (Some((n0, a)), Some((n1, b))) = (results.first(), results.last()) {
        if n1 > n0 {
            println!(
                "scaling {n0} -> {n1} scenes: time x{:.2} for x{:.2} scenes (linear: equal), per-scene time {:.3} -> {:.3} s, peak RSS {:.1} -> {:.1} MiB",
                b.secs / a.secs,
                *n1 as f64 / *n0 as f64,
                a.secs / *n0 as f64,
                b.secs / *n1 as f64,
                a.rss,
                b.rss
            );
        }
    }
    if let Some(&(n, _)) = results.last() {
        let root = work.join(format!("data{n}"));
        let out = work.join(format!("out{n}"));
        let m = measure(&root, &out, jobs);
        println!(
            "rerun of {n} scenes, all reused: {:.2} s ({} converted), peak RSS {:.1} MiB",
            m.secs, m.converted, m.rss
        );
    }
}
