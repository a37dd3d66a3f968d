//! Trace one generated agreement scene (issue #33) in Rapier over a long run: for each window
//! of simulated time, how far each dynamic body's centre of mass moved and how much it turned,
//! and whether it sleeps. It tells a body that creeps (a steady speed that does not decay) from
//! one that is still coming to rest when the settle test's cap ends (a decaying speed).
//!
//! Run: `cargo run --release --example agreement_trace -- SEED [SECONDS] [WINDOW_S]
//!       [--set solver_iterations=N|pgs_iterations=N|load_ratio=K|coulomb_friction=0/1|contact_clustering=0/1|
//!        friction_in_bias_pass=0/1|sleep=0/1]` (defaults 20 s, 1 s windows, the library's
//! settle options; `sleep=0` keeps every body awake as the rest check does).

use interact3d::agreement::Catalog;
use interact3d::physics::{simulate, SettleOptions};
use std::path::PathBuf;

fn main() {
    let mut args = std::env::args().skip(1);
    let usage = || -> ! {
        eprintln!("usage: agreement_trace SEED [SECONDS] [WINDOW_S] [--set KEY=VALUE]...");
        std::process::exit(2)
    };
    let mut pos = Vec::new();
    let mut opts = SettleOptions::default();
    while let Some(a) = args.next() {
        if a == "--set" {
            let kv = args.next().unwrap_or_else(|| usage());
            let (k, v) = kv.split_once('=').unwrap_or_else(|| usage());
            let x: f64 = v.parse().unwrap_or_else(|_| usage());
            match k {
                "solver_iterations" => opts.solver_iterations = x as usize,
                "pgs_iterations" => opts.pgs_iterations = x as usize,
                "load_ratio" => opts.load_ratio = x,
                "loaded_solver_iterations" => opts.loaded_solver_iterations = x as usize,
                "loaded_pgs_iterations" => opts.loaded_pgs_iterations = x as usize,
                "loaded_fresh_contacts" => opts.loaded_fresh_contacts = x != 0.0,
                "loaded_stiff_contacts" => opts.loaded_stiff_contacts = x != 0.0,
                "coulomb_friction" => opts.coulomb_friction = x != 0.0,
                "contact_reuse_max_turn_deg" => opts.contact_reuse_max_turn_deg = x,
                "rolling_friction" => opts.rolling_friction = x,
                "contact_clustering" => opts.contact_clustering = x != 0.0,
                "friction_in_bias_pass" => opts.friction_in_bias_pass = x != 0.0,
                "sleep" if x == 0.0 => opts.sleep_linear_threshold = 0.0,
                "sleep" => {}
                _ => usage(),
            }
        } else {
            pos.push(a);
        }
    }
    let seed: u64 = pos
        .first()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| usage());
    let seconds: f64 = pos
        .get(1)
        .map_or(20.0, |s| s.parse().unwrap_or_else(|_| usage()));
    let window: f64 = pos
        .get(2)
        .map_or(1.0, |s| s.parse().unwrap_or_else(|_| usage()));
    let catalog = Catalog::load(
        &PathBuf::from("../shared/datasets/objects"),
        None,
        Some("target/agreement-cache".into()),
    )
    .unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    let g = catalog.compose(seed);
    let bodies = interact3d::validate::sim_bodies(&g.assembly);
    let every = ((window / opts.dt).round() as usize).max(1);
    let traj = simulate(&bodies, &opts, seconds, every).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    println!(
        "seed {seed} ({:?}): {} solver iterations x {} PGS sweeps; per {window} s window: \
         centre-of-mass motion (mm) and turn (deg)",
        g.kind, opts.solver_iterations, opts.pgs_iterations
    );
    print!("{:>7}", "t (s)");
    for n in &traj.names {
        print!(" {:>34}", n);
    }
    println!();
    for k in 1..traj.frames.len() {
        print!("{:>7.2}", traj.times[k]);
        for (i, b) in bodies.iter().enumerate() {
            let (a, c) = (
                traj.frames[k - 1][i].isometry(),
                traj.frames[k][i].isometry(),
            );
            let pa = a * b.com;
            let pc = c * b.com;
            let turn = (c.rotation * a.rotation.inverse()).angle().to_degrees();
            print!(
                " {:>34}",
                format!("{:.4} mm {:.4}°", (pc - pa).norm() * 1e3, turn)
            );
        }
        println!();
    }
}
