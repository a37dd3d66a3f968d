//! Experiment (issue #33): settle one generated scene from its composed pose nudged by 0.5 mm or
//! 0.5° (each body, ±x, ±y), and print each run's verdict and the bodies' settle motion.
//! Run: `cargo run --release --example agreement_perturb -- SEED`
use interact3d::agreement::Catalog;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
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
    for i in 0..g.assembly.bodies.len() {
        for (k, axis) in [Vector3::x(), -Vector3::x(), Vector3::y(), -Vector3::y()]
            .iter()
            .enumerate()
        {
            for kind in 0..2 {
                let mut a = g.assembly.clone();
                let b = &mut a.bodies[i];
                let com = (b.pose * b.inertial.com).coords;
                let d = if kind == 0 {
                    let r = UnitQuaternion::from_axis_angle(
                        &nalgebra::Unit::new_normalize(*axis),
                        0.5f64.to_radians(),
                    );
                    Isometry3::from_parts(Translation3::from(com), r)
                        * Isometry3::translation(-com.x, -com.y, -com.z)
                } else {
                    Isometry3::from_parts(
                        Translation3::from(axis * 5e-4),
                        UnitQuaternion::identity(),
                    )
                };
                b.pose = d * b.pose;
                b.composed_pose = d * b.composed_pose;
                run(&format!("b{i} {} {k}", ["turn", "shift"][kind]), &a);
            }
        }
    }
}
