//! Run-time signals of an undetermined verdict (issue #33, session 14): for each generated scene
//! our validation as the agreement run does it (one settle), and what that one settle shows
//! about how near the verdict is to flipping: each free body's drift against the 10 % limit,
//! its settle turn, whether the scene slept, the marginal probe, the creep rule, the loaded
//! solver. With `--nudge-seeds FILE` (lines `seed body...`), instead our verdict from each nudged
//! composed pose of the named bodies (`validate::nudge::nudged_verdicts`, the four 0.5° turns a
//! body, settle and rest checks), as
//! one pass bit a start. No other engine runs here: MuJoCo's verdicts are the agreement run's
//! (deterministic, same seeds, same code), joined afterwards.
//!
//! Run: `nice cargo run --release --example verdict_signals -- [--seeds 0..700] [--out FILE]
//!       [--nudge-seeds FILE]` (one JSON line a scene, in seed order per batch).

#[path = "common/seeds.rs"]
mod seeds;
use interact3d::agreement::Catalog;
use interact3d::physics::SettleOptions;
use interact3d::validate::nudge::{nudged_verdicts, Starts};
use rayon::prelude::*;
use std::io::Write;
use std::path::PathBuf;

fn main() {
    let mut seeds = 0u64..700;
    let mut out = PathBuf::from("target/verdict_signals.jsonl");
    let mut nudge_seeds: Option<Vec<(u64, Vec<String>)>> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--seeds" => seeds = seeds::seed_range(&args.next().expect("--seeds A..B")),
            "--out" => out = args.next().expect("--out FILE").into(),
            "--nudge-seeds" => {
                let f = args.next().expect("--nudge-seeds FILE");
                let text = std::fs::read_to_string(&f).expect("seed file");
                nudge_seeds = Some(
                    text.lines()
                        .filter(|l| !l.trim().is_empty())
                        .map(|l| {
                            let mut w = l.split_whitespace();
                            let seed = w.next().unwrap().parse().expect("seed");
                            (seed, w.map(String::from).collect())
                        })
                        .collect(),
                );
            }
            _ => {
                eprintln!("unknown argument {a}");
                std::process::exit(2);
            }
        }
    }
    let catalog = Catalog::load_with(
        std::path::Path::new("../shared/datasets/objects"),
        None,
        Some("target/agreement-cache".into()),
        usize::MAX,
    )
    .unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    let list: Vec<(u64, Vec<String>)> = nudge_seeds
        .clone()
        .unwrap_or_else(|| seeds.map(|s| (s, Vec::new())).collect());
    let mut f = std::fs::File::create(&out).expect("output file");
    let t = std::time::Instant::now();
    for chunk in list.chunks(20) {
        let lines: Vec<String> = chunk
            .par_iter()
            .map(|(seed, bodies)| {
                let g = catalog.compose(*seed);
                if nudge_seeds.is_some() {
                    nudged(&g, bodies)
                } else {
                    signals(&g)
                }
            })
            .collect();
        for l in lines {
            writeln!(f, "{l}").unwrap();
        }
        eprintln!("{} scenes, {:.0} s", chunk[0].0, t.elapsed().as_secs_f64());
    }
}

fn signals(g: &interact3d::agreement::Generated) -> String {
    let mut opts = interact3d::validate::ValidateOptions {
        visual_metrics: false,
        ..Default::default()
    };
    opts.nudge.enabled = false;
    let t = std::time::Instant::now();
    let v = interact3d::validate::validate(&g.assembly, &opts).expect("validate");
    let seconds = t.elapsed().as_secs_f64();
    let s = &opts.settle;
    let bodies: Vec<_> = v
        .settle
        .bodies
        .iter()
        .filter(|b| !b.fixed)
        .map(|b| {
            serde_json::json!({
                "name": b.name,
                "diag": b.bbox_diagonal,
                "drift_ratio": b.relative_drift / s.max_relative_drift,
                "settle_mm": b.settle_displacement * 1e3,
                "settle_deg": b.settle_rotation_deg,
                "shape_shift_mm": b.settle_shape_shift.map(|x| x * 1e3),
                "rest_mm": b.rest_displacement * 1e3,
                "rest_deg": b.rest_rotation_deg,
                "rest_pen_mm": b.rest_max_penetration * 1e3,
                "marginal": b.marginal,
                "probe_mm": b.probe_displacement * 1e3,
                "probe_deg": b.probe_rotation_deg,
                "creep": b.creep_imbalance,
                "left": b.left_supports || b.ended_on_floor,
                "passed": b.passed,
                "loaded": v.settle.heavily_loaded.contains(&b.name),
            })
        })
        .collect();
    serde_json::json!({
        "seed": g.seed,
        "kind": g.kind,
        "objects": g.objects,
        "passed": v.passed,
        "seconds": seconds,
        "time_to_sleep": v.settle.time_to_sleep,
        "steps": v.settle.steps,
        "bodies": bodies,
    })
    .to_string()
}

fn nudged(g: &interact3d::agreement::Generated, names: &[String]) -> String {
    let t = std::time::Instant::now();
    let sims = interact3d::validate::sim_bodies(&g.assembly);
    let which: Vec<bool> = sims.iter().map(|b| names.contains(&b.name)).collect();
    let bits = nudged_verdicts(&sims, &which, &SettleOptions::default(), Starts::Turns);
    serde_json::json!({
        "seed": g.seed,
        "bodies": names,
        "nudged": bits,
        "seconds": t.elapsed().as_secs_f64(),
    })
    .to_string()
}
