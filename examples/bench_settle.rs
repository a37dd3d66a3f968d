//! Benchmark of the Rapier settle test: a bowl of 32 convex hulls (bottom plate + 31 wall
//! segments) and an object made of 32 small hulls (a 4 x 4 x 2 block of 1 cm cubes) dropped
//! 3 mm into it. Prints a table: a plain 2 s simulation (`physics::simulate`, sleeping allowed)
//! and the full check (`physics::settle`: settle until asleep, then a 1 s awake rest phase with
//! exact penetration queries every step).
//!
//! Run: `cargo run --release --example bench_settle [solver_iterations=N] [pgs_iterations=N]`

use interact3d::mesh::{Mesh, P3, V3};
use interact3d::physics::{box_inertia, settle, simulate, SettleOptions, SimBody};
use interact3d::shapes::cuboid;
use nalgebra::{Isometry3, Matrix4};
use std::f64::consts::PI;

#[path = "common/timing.rs"]
mod timing;
use timing::best_of;

fn bowl() -> SimBody {
    let walls = 31;
    let (radius, plate) = (0.06, 0.01);
    let mut hulls = vec![cuboid(V3::new(0.14, 0.14, plate))
        .transformed(&Matrix4::new_translation(&V3::new(0.0, 0.0, plate / 2.0)))];
    let width = 2.0 * PI * radius / walls as f64 * 1.05;
    for k in 0..walls {
        let phi = 2.0 * PI * k as f64 / walls as f64;
        let m = Isometry3::new(
            V3::new(radius * phi.cos(), radius * phi.sin(), plate + 0.025),
            V3::z() * phi,
        )
        .to_homogeneous();
        hulls.push(cuboid(V3::new(0.01, width, 0.05)).transformed(&m));
    }
    let m = 0.4;
    SimBody {
        name: "bowl".into(),
        pose: Isometry3::translation(0.0, 0.0, 0.0005),
        hulls,
        mass: m,
        com: P3::new(0.0, 0.0, 0.015),
        inertia: box_inertia(m, V3::new(0.14, 0.14, 0.04)),
        friction: 0.6,
        fixed: false,
    }
}

fn block() -> SimBody {
    let c = 0.01;
    let hulls: Vec<Mesh> = (0..32)
        .map(|k| {
            let (i, j, l) = (k % 4, (k / 4) % 4, k / 16);
            let centre = V3::new(
                (i as f64 - 1.5) * c,
                (j as f64 - 1.5) * c,
                (l as f64 - 0.5) * c,
            );
            cuboid(V3::new(c, c, c)).transformed(&Matrix4::new_translation(&centre))
        })
        .collect();
    let m = 0.1;
    SimBody {
        name: "block".into(),
        pose: Isometry3::new(V3::new(0.005, 0.0, 0.0105 + 0.01 + 0.003), V3::z() * 0.3),
        hulls,
        mass: m,
        com: P3::origin(),
        inertia: box_inertia(m, V3::new(0.04, 0.04, 0.02)),
        friction: 0.6,
        fixed: false,
    }
}

fn main() {
    let scene = [bowl(), block()];
    // `solver_iterations=N` / `pgs_iterations=N`: measure another solver setting.
    let mut opts = SettleOptions::default();
    for a in std::env::args().skip(1) {
        match a.split_once('=') {
            Some(("solver_iterations", v)) => opts.solver_iterations = v.parse().expect("N"),
            Some(("pgs_iterations", v)) => opts.pgs_iterations = v.parse().expect("N"),
            _ => {
                eprintln!("usage: bench_settle [solver_iterations=N] [pgs_iterations=N]");
                std::process::exit(2)
            }
        }
    }
    let hulls: usize = scene.iter().map(|b| b.hulls.len()).sum();
    println!(
        "scene: bowl ({} hulls) + block ({} hulls), dt = 1/{:.0} s, {} solver iterations, {} PGS sweeps each",
        scene[0].hulls.len(),
        scene[1].hulls.len(),
        1.0 / opts.dt,
        opts.solver_iterations,
        opts.pgs_iterations
    );
    println!(
        "{:<36} {:>7} {:>10} {:>12}",
        "run (best of 5)", "steps", "ms", "steps/s"
    );
    let (t, traj) = best_of(5, || simulate(&scene, &opts, 2.0, 0).unwrap());
    println!(
        "{:<36} {:>7} {:>10.2} {:>12.0}",
        "simulate 2 s",
        traj.steps,
        t * 1e3,
        traj.steps as f64 / t
    );
    let awake = SettleOptions {
        sleep_linear_threshold: 0.0,
        ..opts.clone()
    };
    let (t, traj) = best_of(5, || simulate(&scene, &awake, 2.0, 0).unwrap());
    println!(
        "{:<36} {:>7} {:>10.2} {:>12.0}",
        "simulate 2 s, never sleeping",
        traj.steps,
        t * 1e3,
        traj.steps as f64 / t
    );
    let no_recycling = SettleOptions {
        contact_recycling: false,
        ..opts.clone()
    };
    let (t, traj) = best_of(5, || simulate(&scene, &no_recycling, 2.0, 0).unwrap());
    println!(
        "{:<36} {:>7} {:>10.2} {:>12.0}",
        "simulate 2 s, contact recycling off",
        traj.steps,
        t * 1e3,
        traj.steps as f64 / t
    );
    let (t, rep) = best_of(5, || settle(&scene, &opts).unwrap());
    println!(
        "{:<36} {:>7} {:>10.2} {:>12.0}",
        format!(
            "settle ({:.2} s) + 1 s rest check",
            rep.time_to_sleep.unwrap_or(f64::NAN)
        ),
        rep.steps,
        t * 1e3,
        rep.steps as f64 / t
    );
    let no_probe = SettleOptions {
        probe_angle_deg: 0.0,
        ..opts.clone()
    };
    let (t, rep0) = best_of(5, || settle(&scene, &no_probe).unwrap());
    println!(
        "{:<36} {:>7} {:>10.2} {:>12.0}",
        "the same, marginal probe off",
        rep0.steps,
        t * 1e3,
        rep0.steps as f64 / t
    );
    println!(
        "{hulls} hulls; verdict: {}",
        if rep.passed { "pass" } else { "fail" }
    );
    for b in &rep.bodies {
        println!(
            "  {:<6} drift {:.2} mm {:.2}°, rest {:.4} mm {:.3}°, max penetration {:.3} mm, supports {:?}, {}",
            b.name,
            b.settle_displacement * 1e3,
            b.settle_rotation_deg,
            b.rest_displacement * 1e3,
            b.rest_rotation_deg,
            b.rest_max_penetration * 1e3,
            b.supports_at_start,
            if b.passed { "pass".to_string() } else { b.reasons.join("; ") }
        );
    }
}
