//! Validation speed (issue 3 targets): R_volume at N = 10^6 and R_surface for two ~16k-triangle
//! scans, the settle of a two-object scene, and a whole `validate`, on one core.
//!
//! `cargo run --release --example bench_validate [-- SCENE]` (default: the shared lemon-in-bowl
//! scene, else the ball_bowl fixture). Prints a markdown table.

use interact3d::body::BuildOptions;
use interact3d::metrics::{r_surface, r_volume, MetricsOptions, Prepared, Solid};
use interact3d::pipeline::load_assembly;
use interact3d::validate::{sim_bodies, validate, ValidateOptions};
use std::path::PathBuf;

#[path = "common/timing.rs"]
mod timing;
use timing::best_of;

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let scene = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            let s = root.join("../shared/datasets/scenes/food/00001_lemon_bowl");
            if s.exists() {
                s
            } else {
                root.join("fixtures/ball_bowl")
            }
        });
    // One core, as the targets are stated.
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global()
        .unwrap();
    let (t_build, a) = best_of(1, || {
        load_assembly(&scene, &Default::default(), &BuildOptions::default()).unwrap()
    });
    let world: Vec<_> = a.bodies.iter().map(|b| b.world_geometry()).collect();
    let tris: Vec<usize> = world.iter().map(|m| m.triangles.len()).collect();
    let hulls: Vec<usize> = a.bodies.iter().map(|b| b.hulls.len()).collect();
    let (t_prep, prepared) = best_of(3, || {
        world
            .iter()
            .map(|m| Prepared::new(Solid::Mesh(m)))
            .collect::<Vec<_>>()
    });
    let opts = MetricsOptions::default();
    let (t_rvol, rv) = best_of(3, || r_volume(&prepared[0], &prepared[1], &opts));
    let (t_rsurf, rs) = best_of(3, || r_surface(&prepared[0], &prepared[1]));
    let vopts = ValidateOptions::default();
    let bodies = sim_bodies(&a);
    let mut two_s = vopts.settle.clone();
    two_s.settle_max_time = 2.0;
    let (t_sim, _) = best_of(3, || {
        interact3d::physics::simulate(&bodies, &two_s, 2.0, 0).unwrap()
    });
    let (t_settle, rep) = best_of(3, || {
        interact3d::physics::settle(&bodies, &vopts.settle).unwrap()
    });
    let (t_val, v) = best_of(3, || validate(&a, &vopts).unwrap());
    println!(
        "scene: {} ({} objects, triangles {:?}, hulls {:?})\n",
        scene.display(),
        a.bodies.len(),
        tris,
        hulls
    );
    println!("| step (1 core) | time | result |");
    println!("|---|---:|---|");
    println!(
        "| load + prepare + decompose (default engine) + inertia | {:.0} ms | |",
        t_build * 1e3
    );
    println!(
        "| metrics: prepare both meshes | {:.1} ms | |",
        t_prep * 1e3
    );
    println!(
        "| R_volume, N = 10^6 | {:.1} ms | {:.3e} ({} points) |",
        t_rvol * 1e3,
        rv.r_volume,
        rv.points
    );
    println!("| R_surface | {:.1} ms | {:.3e} |", t_rsurf * 1e3, rs);
    println!("| Rapier: 2 s simulated | {:.1} ms | |", t_sim * 1e3);
    println!(
        "| Rapier: settle (to sleep, cap 3 s) + 1 s rest | {:.1} ms | asleep at {:?} s |",
        t_settle * 1e3,
        rep.time_to_sleep
    );
    println!(
        "| whole validate (visual + hull metrics, settle, rest) | {:.0} ms | {} |",
        t_val * 1e3,
        if v.passed { "pass" } else { "fail" }
    );
}
