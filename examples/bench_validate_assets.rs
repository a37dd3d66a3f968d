//! Time per asset of `validate` on third-party URDF/MJCF files, against simcheck (PyPI) on the
//! same files. A table on stdout.
//!
//! usage: cargo run --release --example bench_validate_assets -- [--n 100] [--simcheck BIN]
//!        [--simcheck-n K]
//!
//! The assets: pybullet_data's duck_vhacd, teddy_vhacd, cube_small, sphere2 and tray/traybox
//! (found through `python3 -c "import pybullet_data"`), every YCB URDF and every Google Scanned
//! Objects model.xml under ../shared/datasets/objects, cycled to N. Each asset is timed alone
//! on one thread (all checks, physics included), then the N together in parallel. simcheck
//! (`simcheck check --no-cache FILE`, its engines MuJoCo and PyBullet: pip `simcheck`, pinned
//! in tests/python/requirements-simcheck.txt) runs on the same N assets, one at a time (its cache
//! off, so a repeated file costs what it costs the first time); `--simcheck-n K` stops it after
//! the first K. A second table gives each distinct file's mean and worst for both tools.

use interact3d::validate::asset::{check_path, AssetCheckOptions};
use interact3d::validate::ci::{run, Entry, Kind, RunOptions};
use std::path::PathBuf;
use std::time::Instant;

fn stats(t: &[f64]) -> (f64, f64) {
    let mean = t.iter().sum::<f64>() / t.len().max(1) as f64;
    (mean, t.iter().copied().fold(0.0, f64::max))
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |k: &str| {
        args.iter()
            .position(|a| a == k)
            .map(|i| args[i + 1].clone())
    };
    let n: usize = arg("--n").map(|s| s.parse().unwrap()).unwrap_or(100);
    let simcheck = arg("--simcheck");
    // simcheck takes seconds a file: time it on the first K distinct files only.
    let simcheck_n: usize = arg("--simcheck-n")
        .map(|s| s.parse().unwrap())
        .unwrap_or(usize::MAX);
    let py = std::env::var("INTERACT3D_PYTHON").unwrap_or_else(|_| "python3".into());
    let out = std::process::Command::new(&py)
        .args([
            "-c",
            "import pybullet_data;print(pybullet_data.getDataPath())",
        ])
        .output()
        .expect("python3 with pybullet");
    let pb = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    let mut files: Vec<PathBuf> = [
        "duck_vhacd.urdf",
        "teddy_vhacd.urdf",
        "cube_small.urdf",
        "sphere2.urdf",
        "tray/traybox.urdf",
    ]
    .iter()
    .map(|f| pb.join(f))
    .collect();
    let objects = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/datasets/objects");
    for (set, pick) in [("ycb", "urdf"), ("gso", "model.xml")] {
        let mut dirs: Vec<PathBuf> = std::fs::read_dir(objects.join(set))
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.is_dir())
            .collect();
        dirs.sort();
        for d in dirs {
            let mut fs: Vec<PathBuf> = std::fs::read_dir(&d)
                .unwrap()
                .flatten()
                .map(|e| e.path())
                .filter(|p| p.to_string_lossy().ends_with(pick))
                .collect();
            fs.sort();
            files.extend(fs.into_iter().take(1));
        }
    }
    let opts = AssetCheckOptions::default();
    let mut per_file: std::collections::BTreeMap<usize, (Vec<f64>, Vec<f64>)> = Default::default();
    let mut times = Vec::new();
    let mut findings = 0;
    for k in 0..n {
        let f = &files[k % files.len()];
        let t = Instant::now();
        let r = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| check_path(f, &f.display().to_string(), &opts));
        times.push(t.elapsed().as_secs_f64());
        per_file
            .entry(k % files.len())
            .or_default()
            .0
            .push(t.elapsed().as_secs_f64());
        findings += r.findings.len();
    }
    let entries: Vec<Entry> = (0..n)
        .map(|k| {
            let f = files[k % files.len()].clone();
            Entry {
                shown: f.display().to_string(),
                path: f,
                kind: Kind::Asset,
            }
        })
        .collect();
    let t = Instant::now();
    let all = run(&entries, &RunOptions::default());
    let wall = t.elapsed().as_secs_f64();
    let (mean, worst) = stats(&times);
    println!(
        "| tool | assets | distinct files | mean s/asset | worst s/asset | wall s ({} threads) |",
        rayon::current_num_threads()
    );
    println!("|---|---|---|---|---|---|");
    println!(
        "| interact3d validate | {n} | {} | {mean:.3} | {worst:.3} | {wall:.2} |",
        files.len()
    );
    eprintln!(
        "{findings} findings over {n} assets ({} in the parallel run)",
        all.reports.iter().map(|r| r.findings.len()).sum::<usize>()
    );
    if let Some(bin) = simcheck {
        let mut st = Vec::new();
        let mut codes = std::collections::BTreeMap::new();
        for k in 0..n.min(simcheck_n) {
            let f = &files[k % files.len()];
            let t = Instant::now();
            let o = std::process::Command::new(&bin)
                .args(["check", "--no-cache"])
                .arg(f)
                .output()
                .expect("simcheck");
            st.push(t.elapsed().as_secs_f64());
            per_file
                .entry(k % files.len())
                .or_default()
                .1
                .push(t.elapsed().as_secs_f64());
            *codes.entry(o.status.code().unwrap_or(-1)).or_insert(0) += 1;
        }
        let (m, w) = stats(&st);
        println!(
            "| simcheck check --no-cache | {} | {} | {m:.3} | {w:.3} | {:.2} (sequential) |",
            st.len(),
            files.len().min(st.len()),
            st.iter().sum::<f64>()
        );
        eprintln!("simcheck exit codes: {codes:?}");
    }
    println!();
    println!("| file | runs | ours mean s | ours worst s | simcheck mean s | simcheck worst s |");
    println!("|---|---|---|---|---|---|");
    for (k, (ours, theirs)) in &per_file {
        let (om, ow) = stats(ours);
        let name = files[*k]
            .strip_prefix(&objects)
            .or_else(|_| files[*k].strip_prefix(&pb))
            .unwrap_or(&files[*k])
            .display()
            .to_string();
        let sc = if theirs.is_empty() {
            "| – | – |".to_string()
        } else {
            let (sm, sw) = stats(theirs);
            format!("| {sm:.2} | {sw:.2} |")
        };
        println!("| {name} | {} | {om:.3} | {ow:.3} {sc}", ours.len());
    }
}
