//! Cross-engine rest agreement over generated scenes (issue #33): random item-in/on-support,
//! item-on-item and item-on-floor scenes from `../shared/datasets/objects`, settled in Rapier and
//! exported by the library, then replayed in MuJoCo (`tests/python/agreement_mujoco.py`) and,
//! with `--physx`, in PhysX as well (`tests/python/agreement_physx.py`, on the USD export).
//! Prints one line per disagreeing scene and a summary table per engine; writes
//! OUT/scenes.jsonl and OUT/summary.json (MuJoCo), OUT/scenes_physx.jsonl and
//! OUT/summary_physx.json (PhysX).
//!
//! Run: `nice cargo run --release --example agreement -- [--seeds 0..300] [--out DIR]
//!       [--objects DIR] [--batch 10] [--keep] [--physx] [--physx-every K] [--only S1,S2]
//!       [--set KEY=VALUE] [--max-hull-polygons N] [--nudge]` (`--nudge`: for every verdict
//! disagreement, our verdict again from the composed pose nudged by 0.5 mm / 0.5°, 8 starts a
//! free body (`agreement::nudge`), written to OUT/nudges.jsonl and counted: a disagreement whose
//! engine verdict some nudged start of ours shares is within our own spread; with `--physx`, the
//! same for PhysX's disagreements, and PhysX's own verdict from the same nudged starts (the
//! file a user gets, nudged as ours is), to OUT/nudges_physx.jsonl; `--max-hull-polygons 64`: the hulls a user
//! exporting for Isaac gets, the ones PhysX should judge; `--only`: these seeds instead; `--set`: a settle option, for
//! experiments; `--physx-every K`:
//! PhysX judges one batch in K, it is about 4x slower than MuJoCo; the judges' interpreter:
//! `INTERACT3D_PYTHON`, default `python3`). Objects are decomposed once each and cached in
//! `target/agreement-cache`.

#[path = "common/seeds.rs"]
mod seeds;
use interact3d::agreement::nudge::{self, Spread};
use interact3d::agreement::{
    judge::Judge, run_scene_with, summary, Catalog, Generated, Judged, Summary,
};
use interact3d::physics::SettleOptions;
use rayon::prelude::*;
use std::io::Write;
use std::path::PathBuf;

fn main() {
    let mut seeds = 0u64..300;
    let mut out = PathBuf::from("target/agreement");
    let mut objects = PathBuf::from("../shared/datasets/objects");
    let mut batch = 10usize;
    let mut keep = false;
    let mut physx = false;
    let mut physx_every = 1usize;
    let mut only: Option<Vec<u64>> = None;
    let mut settle = SettleOptions::default();
    let mut max_polygons = usize::MAX;
    let mut nudge = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--seeds" => seeds = seeds::seed_range(&args.next().expect("--seeds A..B")),
            "--out" => out = args.next().expect("--out DIR").into(),
            "--objects" => objects = args.next().expect("--objects DIR").into(),
            "--batch" => batch = args.next().expect("--batch N").parse().expect("N"),
            "--keep" => keep = true,
            "--only" => {
                let v = args.next().expect("--only S1,S2,...");
                only = Some(v.split(',').map(|s| s.parse().expect("seed")).collect());
            }
            "--max-hull-polygons" => {
                max_polygons = match args.next().expect("--max-hull-polygons N").parse() {
                    Ok(0) => usize::MAX,
                    Ok(n) => n,
                    Err(_) => {
                        eprintln!("--max-hull-polygons N (0: no limit)");
                        std::process::exit(2)
                    }
                }
            }
            "--set" => set(&mut settle, &args.next().expect("--set KEY=VALUE")),
            "--physx" => physx = true,
            "--nudge" => nudge = true,
            "--physx-every" => {
                physx = true;
                physx_every = args.next().expect("--physx-every K").parse().expect("K");
            }
            _ => {
                eprintln!("unknown argument {a}");
                std::process::exit(2);
            }
        }
    }
    let python = std::env::var("INTERACT3D_PYTHON").unwrap_or_else(|_| "python3".into());
    let scripts = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/python");
    let script = scripts.join("agreement_mujoco.py");
    let physx_script = scripts.join("agreement_physx.py");
    std::fs::create_dir_all(&out).expect("output folder");
    let t = std::time::Instant::now();
    let catalog = Catalog::load_with(
        &objects,
        None,
        Some("target/agreement-cache".into()),
        max_polygons,
    )
    .unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    eprintln!(
        "{} objects decomposed in {:.1} s",
        catalog.objects.len(),
        t.elapsed().as_secs_f64()
    );
    let mut lines = std::fs::File::create(out.join("scenes.jsonl")).expect("scenes.jsonl");
    let mut px_lines = physx.then(|| {
        std::fs::File::create(out.join("scenes_physx.jsonl")).expect("scenes_physx.jsonl")
    });
    let mut all: Vec<Judged> = Vec::new();
    let mut nudge_lines =
        nudge.then(|| std::fs::File::create(out.join("nudges.jsonl")).expect("nudges.jsonl"));
    let mut nudged: Vec<(bool, Spread)> = Vec::new();
    let mut nudge_px_lines = (nudge && physx).then(|| {
        std::fs::File::create(out.join("nudges_physx.jsonl")).expect("nudges_physx.jsonl")
    });
    let mut nudged_px: Vec<(bool, Spread)> = Vec::new();
    let mut physx_spread: Vec<(bool, Spread)> = Vec::new();
    let mut all_px: Vec<Judged> = Vec::new();
    let seed_list: Vec<u64> = only.clone().unwrap_or_else(|| seeds.clone().collect());
    for (k, chunk) in seed_list.chunks(batch).enumerate() {
        let done: Vec<_> = chunk
            .par_iter()
            .filter_map(|&seed| {
                let g = catalog.compose(seed);
                let dir = out.join(format!("scene_{seed}"));
                match run_scene_with(&g, &dir, &settle) {
                    Ok(ours) => Some((g, ours, dir)),
                    Err(e) => {
                        eprintln!("seed {seed}: {e}");
                        None
                    }
                }
            })
            .collect();
        let judged = judged_by(
            "MuJoCo",
            &python,
            &script,
            &done,
            &mut lines,
            settle.settle_max_time,
        );
        if let Some(px) = px_lines.as_mut().filter(|_| k % physx_every == 0) {
            let judged_px = judged_by(
                "PhysX",
                &python,
                &physx_script,
                &done,
                px,
                settle.settle_max_time,
            );
            if nudge {
                let gens: Vec<_> = done.iter().map(|d| &d.0).collect();
                nudged_px.extend(nudge_disagreements(
                    &gens,
                    &judged_px,
                    &settle,
                    &mut nudge_px_lines,
                ));
                physx_spread.extend(physx_nudged(
                    &python,
                    &physx_script,
                    &done,
                    &judged_px,
                    settle.settle_max_time,
                    &mut nudge_px_lines,
                ));
            }
            all_px.extend(judged_px);
        }
        if !keep {
            for (_, _, d) in &done {
                let _ = std::fs::remove_dir_all(d);
            }
        }
        if nudge {
            let gens: Vec<_> = done.iter().map(|d| &d.0).collect();
            nudged.extend(nudge_disagreements(
                &gens,
                &judged,
                &settle,
                &mut nudge_lines,
            ));
        }
        all.extend(judged);
        eprintln!("{} scenes, {:.0} s", all.len(), t.elapsed().as_secs_f64());
    }
    let s = summary(&all);
    std::fs::write(
        out.join("summary.json"),
        serde_json::to_string_pretty(&s).unwrap(),
    )
    .unwrap();
    if let Some(o) = &only {
        println!("seeds {o:?}");
    }
    print_table("MuJoCo", &(if only.is_some() { 0..0 } else { seeds }), &s);
    if nudge {
        print_spread(&nudged);
    }
    if physx {
        let s = summary(&all_px);
        std::fs::write(
            out.join("summary_physx.json"),
            serde_json::to_string_pretty(&s).unwrap(),
        )
        .unwrap();
        let seeds: Vec<u64> = all_px.iter().map(|j| j.seed).collect();
        println!("\nPhysX judged seeds: {seeds:?}");
        print_table("PhysX", &(0..0), &s);
        if nudge {
            print_spread(&nudged_px);
            let (within, split) = spread_counts(&physx_spread);
            println!(
                "verdict disagreements where some nudged start (0.5 mm / 0.5 deg) of PhysX's \
                 gives our verdict: {within} of {} ({split} with PhysX's nudged verdicts split)",
                physx_spread.len()
            );
        }
    }
}

/// `--nudge` with `--physx`: PhysX's own verdict over the nudged composed poses of each of its
/// verdict disagreements (the same starts as ours; one line each to `lines`); returns (our
/// verdict, PhysX's spread) of each.
fn physx_nudged(
    python: &str,
    script: &std::path::Path,
    done: &[(Generated, interact3d::agreement::Ours, PathBuf)],
    judged: &[Judged],
    settle_s: f64,
    lines: &mut Option<std::fs::File>,
) -> Vec<(bool, Spread)> {
    let todo: Vec<_> = done
        .iter()
        .filter(|d| {
            judged
                .iter()
                .any(|j| j.seed == d.0.seed && !j.verdict_agrees)
        })
        .cloned()
        .collect();
    if todo.is_empty() {
        return Vec::new();
    }
    let judge = Judge {
        settle_s,
        ..Judge::new("PhysX", python, script)
    };
    let res = judge.nudged(&todo).unwrap_or_else(|e| {
        eprintln!("PhysX nudges: {e}");
        Vec::new()
    });
    res.iter()
        .map(|j| {
            let v = j.mujoco.nudged.clone().unwrap_or_default();
            let sp = Spread {
                runs: v.len(),
                passed: v.iter().filter(|&&p| p).count(),
            };
            eprintln!(
                "seed {}: we {}, PhysX {}; PhysX from its nudged starts: {} of {} pass{}",
                j.seed,
                if j.ours.passed { "pass" } else { "fail" },
                if j.mujoco.passed { "passes" } else { "fails" },
                sp.passed,
                sp.runs,
                if sp.includes(j.ours.passed) {
                    " (our verdict within PhysX's spread)"
                } else {
                    ""
                }
            );
            if let Some(f) = lines.as_mut() {
                let v = serde_json::json!({"seed": j.seed, "ours": j.ours.passed,
                    "engine": j.mujoco.passed, "engine_nudged_runs": sp.runs,
                    "engine_nudged_passed": sp.passed, "engine_nudged": v,
                    "ours_within_engine_spread": sp.includes(j.ours.passed)});
                writeln!(f, "{v}").expect("nudges_physx.jsonl");
            }
            (j.ours.passed, sp)
        })
        .collect()
}

/// Of (verdict, spread) pairs: those whose spread includes the verdict, and those whose spread
/// is split.
fn spread_counts(v: &[(bool, Spread)]) -> (usize, usize) {
    let within = v.iter().filter(|(x, sp)| sp.includes(*x)).count();
    let split = v.iter().filter(|(_, sp)| sp.undetermined()).count();
    (within, split)
}

/// `--nudge`'s count: of the verdict disagreements, those whose engine verdict some nudged
/// start of ours shares, and those whose nudged verdicts split.
fn print_spread(nudged: &[(bool, Spread)]) {
    let (within, split) = spread_counts(nudged);
    println!(
        "verdict disagreements within our own nudged spread (0.5 mm / 0.5 deg): {within} of {} \
         ({split} with our nudged verdicts split)",
        nudged.len()
    );
}

/// `--nudge`: our verdict over the nudged composed poses of each verdict disagreement of one
/// engine's judged scenes (one line each to `lines`); returns (the engine's verdict, our
/// spread) of each.
fn nudge_disagreements(
    gens: &[&Generated],
    judged: &[Judged],
    settle: &SettleOptions,
    lines: &mut Option<std::fs::File>,
) -> Vec<(bool, Spread)> {
    let todo: Vec<_> = judged
        .iter()
        .filter(|j| !j.verdict_agrees)
        .filter_map(|j| gens.iter().find(|g| g.seed == j.seed).map(|g| (*g, j)))
        .collect();
    let res: Vec<_> = todo
        .par_iter()
        .filter_map(|(g, j)| match nudge::spread(g, settle) {
            Ok(sp) => Some((j.seed, j.ours.passed, j.mujoco.passed, sp, j.engine.clone())),
            Err(e) => {
                eprintln!("seed {}: nudges: {e}", j.seed);
                None
            }
        })
        .collect();
    res.into_iter()
        .map(|(seed, ours, engine, sp, name)| {
            eprintln!(
                "seed {seed}: we {}, {name} {}; nudged: {} of {} pass{}",
                if ours { "pass" } else { "fail" },
                if engine { "passes" } else { "fails" },
                sp.passed,
                sp.runs,
                if sp.includes(engine) {
                    " (the engine's verdict within our spread)"
                } else {
                    ""
                }
            );
            if let Some(f) = lines.as_mut() {
                let v = serde_json::json!({"seed": seed, "ours": ours, "engine": engine,
                    "nudged_runs": sp.runs, "nudged_passed": sp.passed,
                    "within_spread": sp.includes(engine)});
                writeln!(f, "{v}").expect("nudges.jsonl");
            }
            (engine, sp)
        })
        .collect()
}

/// `--set KEY=VALUE`: a settle option (experiments; the defaults are the library's).
fn set(o: &mut SettleOptions, kv: &str) {
    let (k, v) = kv.split_once('=').expect("--set KEY=VALUE");
    let x: f64 = v.parse().expect("a number");
    match k {
        "dt" => o.dt = x,
        "solver_iterations" => o.solver_iterations = x as usize,
        "pgs_iterations" => o.pgs_iterations = x as usize,
        "load_ratio" => o.load_ratio = x,
        "loaded_solver_iterations" => o.loaded_solver_iterations = x as usize,
        "loaded_pgs_iterations" => o.loaded_pgs_iterations = x as usize,
        "loaded_fresh_contacts" => o.loaded_fresh_contacts = x != 0.0,
        "loaded_stiff_contacts" => o.loaded_stiff_contacts = x != 0.0,
        "stabilization_iterations" => o.stabilization_iterations = x as usize,
        "settle_max_time" => o.settle_max_time = x,
        "rest_time" => o.rest_time = x,
        "sleep_linear_threshold" => o.sleep_linear_threshold = x,
        "sleep_time" => o.sleep_time = x,
        "contact_frequency" => o.contact_frequency = x,
        "static_contact_frequency" => o.static_contact_frequency = x,
        "contact_damping_ratio" => o.contact_damping_ratio = x,
        "angular_damping" => o.angular_damping = x,
        "prediction_distance" => o.prediction_distance = x,
        "contact_reuse_max_turn_deg" => o.contact_reuse_max_turn_deg = x,
        "rolling_friction" => o.rolling_friction = x,
        "contact_recycling" => o.contact_recycling = x != 0.0,
        "coulomb_friction" => o.coulomb_friction = x != 0.0,
        "contact_clustering" => o.contact_clustering = x != 0.0,
        "friction_in_bias_pass" => o.friction_in_bias_pass = x != 0.0,
        "max_corrective_velocity" => o.max_corrective_velocity = x,
        "contact_recycle_distance" => o.contact_recycle_distance = x,
        "probe_angle_deg" => o.probe_angle_deg = x,
        "probe_time" => o.probe_time = x,
        "max_rest_motion" => o.max_rest_motion = x,
        "max_rest_rotation_deg" => o.max_rest_rotation_deg = x,
        "max_rest_penetration" => o.max_rest_penetration = x,
        "creep_max_motion" => o.creep_max_motion = x,
        "creep_max_rotation_deg" => o.creep_max_rotation_deg = x,
        "creep_contact_distance" => o.creep_contact_distance = x,
        "creep_max_imbalance" => o.creep_max_imbalance = x,
        _ => {
            eprintln!("--set: unknown settle option {k}");
            std::process::exit(2)
        }
    }
}

/// Judge a batch with one engine, write its lines, print its disagreements.
fn judged_by(
    engine: &str,
    python: &str,
    script: &std::path::Path,
    done: &[(
        interact3d::agreement::Generated,
        interact3d::agreement::Ours,
        PathBuf,
    )],
    lines: &mut std::fs::File,
    settle_s: f64,
) -> Vec<Judged> {
    let judge = Judge {
        settle_s,
        ..Judge::new(engine, python, script)
    };
    let judged = judge.run(done).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
    for j in &judged {
        writeln!(lines, "{}", serde_json::to_string(j).unwrap()).unwrap();
        if let Some(c) = interact3d::agreement::judge::cause(j) {
            eprintln!(
                "seed {} {:?}: {c}; drifts {:?}",
                j.seed, j.objects, j.rest_drifts
            );
        }
    }
    judged
}

fn print_table(engine: &str, seeds: &std::ops::Range<u64>, s: &Summary) {
    let pct = |a: usize, n: usize| 100.0 * a as f64 / n.max(1) as f64;
    if !seeds.is_empty() {
        println!("seeds {}..{}", seeds.start, seeds.end);
    }
    println!("{engine}: {} scenes", s.scenes);
    println!("{:<44} {:>8}", "", "count");
    println!("{:<44} {:>8}", "we pass", s.we_pass);
    println!("{:<44} {:>8}", format!("{engine} passes"), s.mujoco_pass);
    println!(
        "{:<44} {:>8}  ({:.1} %)",
        "verdict agrees",
        s.verdict_agree,
        pct(s.verdict_agree, s.scenes)
    );
    println!(
        "{:<44} {:>8}  ({:.1} % of {} determined; {} undetermined)",
        "verdict agrees on determined scenes",
        s.determined_agree,
        pct(s.determined_agree, s.scenes - s.undetermined),
        s.scenes - s.undetermined,
        s.undetermined
    );
    println!(
        "{:<44} {:>8}  ({:.1} % of {} we pass)",
        "rest agrees (<= 1 mm, <= 1 deg for 2 s)",
        s.rest_agree,
        pct(s.rest_agree, s.rest_judged),
        s.rest_judged
    );
    println!("{:<44} {:>8}", "scenes with a marginal body", s.marginal);
    println!(
        "{:<44} {:>8}  (of {} marginal bodies; {} of {} other bodies)",
        format!("marginal bodies {engine} moves"),
        s.marginal_bodies_moved,
        s.marginal_bodies,
        s.stable_bodies_moved,
        s.stable_bodies
    );
    for (c, n) in &s.causes {
        println!("  {c:<70} {n:>4}");
    }
    println!(
        "{engine} drift of bodies at rest: mean {:.3} mm / {:.3} deg, worst {:.3} mm / {:.3} deg",
        s.drift_mean_mm, s.drift_mean_deg, s.drift_worst_mm, s.drift_worst_deg
    );
    println!(
        "settle (validation) per scene: mean {:.2} s, worst {:.2} s",
        s.settle_mean_s, s.settle_worst_s
    );
}
