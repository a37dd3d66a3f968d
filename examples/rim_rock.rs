//! A bare cylinder released tilted on the floor (issue #33, seed 313's rocking bottle): prints
//! the largest tilt and mechanical energy (above upright, from finite differences of the poses)
//! per 0.25 s; neither may grow. The default body is 313's stand-in: 32 sides, r 3 cm, 25 cm
//! tall, 0.5 kg, μ 0.6, the library's settle options with sleeping and the start kick off.
//!
//! Run: `cargo run --release --example rim_rock -- [TILT_DEG] [SECONDS] [--set KEY=VALUE]...`
//! (keys: the settle options below, and `friction`, `r`, `h`, `n` for the body; `RIM_TRACE=1`
//! also prints every step: time, tilt about y and x (deg), COM x (mm), energy and kinetic
//! energy (mJ)). docs/agreement.md, "Twelfth stop", has the table it gives.

use interact3d::mesh::P3;
use interact3d::physics::{simulate, SettleOptions, SimBody};
use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

fn main() {
    let mut args = std::env::args().skip(1);
    let mut pos = Vec::new();
    let mut opts = SettleOptions::default();
    let (mut r, mut h, mut n, mut mu) = (0.03, 0.25, 32usize, 0.6);
    while let Some(a) = args.next() {
        if a == "--set" {
            let kv = args.next().unwrap();
            let (k, v) = kv.split_once('=').unwrap();
            let x: f64 = v.parse().unwrap();
            match k {
                "solver_iterations" => opts.solver_iterations = x as usize,
                "pgs_iterations" => opts.pgs_iterations = x as usize,
                "stabilization_iterations" => opts.stabilization_iterations = x as usize,
                "coulomb_friction" => opts.coulomb_friction = x != 0.0,
                "contact_clustering" => opts.contact_clustering = x != 0.0,
                "contact_recycling" => opts.contact_recycling = x != 0.0,
                "friction_in_bias_pass" => opts.friction_in_bias_pass = x != 0.0,
                "prediction_distance" => opts.prediction_distance = x,
                "contact_reuse_max_turn_deg" => opts.contact_reuse_max_turn_deg = x,
                "rolling_friction" => opts.rolling_friction = x,
                "contact_frequency" => opts.contact_frequency = x,
                "static_contact_frequency" => opts.static_contact_frequency = x,
                "contact_damping_ratio" => opts.contact_damping_ratio = x,
                "max_corrective_velocity" => opts.max_corrective_velocity = x,
                "dt" => opts.dt = x,
                "floor_friction" => opts.floor_friction = x,
                "friction" => mu = x,
                "r" => r = x,
                "h" => h = x,
                "n" => n = x as usize,
                _ => panic!("unknown {k}"),
            }
        } else {
            pos.push(a);
        }
    }
    let tilt: f64 = pos.first().map_or(4.0, |s| s.parse().unwrap());
    let seconds: f64 = pos.get(1).map_or(4.0, |s| s.parse().unwrap());
    opts.sleep_linear_threshold = 0.0;
    opts.perturbation_speed = 0.0;
    let m = 0.5;
    let (ixx, izz) = (m * (3.0 * r * r + h * h) / 12.0, m * r * r / 2.0);
    let t = tilt.to_radians();
    // The rim vertex at +x goes down: a turn about y.
    let rot = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), t);
    let low = rot * Vector3::new(r, 0.0, -h / 2.0);
    let body = SimBody {
        name: "cyl".into(),
        pose: Isometry3::from_parts(Translation3::new(0.0, 0.0, -low.z + 1e-5), rot),
        hulls: vec![interact3d::shapes::cylinder(r, h, n)],
        mass: m,
        com: P3::origin(),
        inertia: Matrix3::from_diagonal(&Vector3::new(ixx, ixx, izz)),
        friction: mu,
        fixed: false,
    };
    let traj = simulate(std::slice::from_ref(&body), &opts, seconds, 1).unwrap();
    let g = opts.gravity;
    let z0 = h / 2.0; // upright COM height
    let win = (0.25 / opts.dt).round() as usize;
    let mut max_tilt: f64 = 0.0;
    let mut max_e: f64 = 0.0;
    println!("window_end_s max_tilt_deg max_energy_mJ (potential+kinetic above upright)");
    let fr = &traj.frames;
    for k in 1..fr.len() {
        let p = &fr[k][0];
        let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            p.quaternion_wxyz[0],
            p.quaternion_wxyz[1],
            p.quaternion_wxyz[2],
            p.quaternion_wxyz[3],
        ));
        let axis = q * Vector3::z();
        let tl = axis.z.clamp(-1.0, 1.0).acos().to_degrees();
        let pp = &fr[k - 1][0];
        let qp = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            pp.quaternion_wxyz[0],
            pp.quaternion_wxyz[1],
            pp.quaternion_wxyz[2],
            pp.quaternion_wxyz[3],
        ));
        let v = (Vector3::from(p.translation) - Vector3::from(pp.translation)) / opts.dt;
        let w = (q * qp.inverse()).scaled_axis() / opts.dt;
        let wb = q.inverse() * w;
        let ke = 0.5 * m * v.norm_squared()
            + 0.5 * (ixx * wb.x * wb.x + ixx * wb.y * wb.y + izz * wb.z * wb.z);
        let e = m * g * (p.translation[2] - z0) + ke;
        max_tilt = max_tilt.max(tl);
        max_e = max_e.max(e);
        if std::env::var("RIM_TRACE").is_ok() {
            println!(
                "T {:.5} {:+.4} {:+.4} {:.5} {:.4} {:.4}",
                k as f64 * opts.dt,
                axis.x.asin().to_degrees(),
                axis.y.asin().to_degrees(),
                p.translation[0] * 1e3,
                e * 1e3,
                ke * 1e3
            );
        }
        if k % win == 0 {
            println!(
                "{:>6.2} {:>7.3} {:>9.4}",
                k as f64 * opts.dt,
                max_tilt,
                max_e * 1e3
            );
            max_tilt = 0.0;
            max_e = 0.0;
        }
    }
}
