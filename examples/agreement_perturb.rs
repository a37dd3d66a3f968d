//! Experiment (issue #33): settle one generated scene from its composed pose nudged by 0.5 mm or
//! 0.5° (each free body, ±x, ±y: `agreement::nudge::nudged_poses`), and print each run's
//! verdict and the bodies' settle motion.
//! Run: `cargo run --release --example agreement_perturb -- SEED`
use interact3d::agreement::{nudge::nudged_poses, Catalog};
use std::path::PathBuf;

fn main() {
    let seed: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .expect("SEED");
    let catalog = Catalog::load(
        &PathBuf::from("../shared/datasets/objects"),
        None,
        Some("target/agreement-cache".into()),
    )
    .expect("catalog");
    let g = catalog.compose(seed);
    let opts = interact3d::validate::ValidateOptions {
        visual_metrics: false,
        ..Default::default()
    };
    let run = |label: &str, a: &interact3d::body::Assembly| {
        let v = interact3d::validate::validate(a, &opts).expect("validate");
        let s: Vec<String> = v
            .settle
            .bodies
            .iter()
            .map(|b| {
                format!(
                    "{} {:.1} mm {:.1}° rest {:.2} mm {:.2}°",
                    &b.name[..b.name.len().min(12)],
                    b.settle_displacement * 1e3,
                    b.settle_rotation_deg,
                    b.rest_displacement * 1e3,
                    b.rest_rotation_deg
                )
            })
            .collect();
        println!("{label:>16} passed={} {}", v.passed, s.join(" | "));
    };
    run("none", &g.assembly);
    // The nudged starts of `agreement::nudge` (the ones `agreement --nudge` counts): each free
    // body in turn, turned 0.5° about ±x, ±y through its centre of mass, then shifted 0.5 mm.
    let a = &g.assembly;
    let poses: Vec<_> = a.bodies.iter().map(|b| b.composed_pose).collect();
    let coms: Vec<_> = a.bodies.iter().map(|b| b.inertial.com).collect();
    let fixed: Vec<_> = a.bodies.iter().map(|b| b.fixed).collect();
    let free: Vec<usize> = (0..a.bodies.len()).filter(|&i| !fixed[i]).collect();
    for (k, p) in nudged_poses(&poses, &coms, &fixed).into_iter().enumerate() {
        let mut n = a.clone();
        for (b, q) in n.bodies.iter_mut().zip(p) {
            b.pose = q;
            b.composed_pose = q;
        }
        let (body, kind, dir) = (free[k / 8], ["turn", "shift"][k % 8 / 4], k % 4);
        run(&format!("b{body} {kind} {dir}"), &n);
    }
}
