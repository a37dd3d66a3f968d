//! The settle's Rapier world against closed-form rigid-body statics and impacts (issue #33: the
//! creep of an item leaning on an inclined contact, and the bottle that rocks itself over on its
//! rim). Every scene is simulated with the library's settle options through `physics::simulate`
//! (sleeping and the start kick off, so nothing hides motion), and judged against Coulomb's law
//! or Housner's rocking impacts, not against another run.
//!
//! - a block on a fixed incline is held exactly (no creep) below tan⁻¹ μ and slides above;
//! - a box leaning against a wall (a ladder, friction μ at both ends) is held below
//!   tan θ = 2μ / (1 − μ²) and falls above, leaning on the wall's face or on its top edge,
//!   the wall fixed or a dynamic box;
//! - a slender block rocking on its edges loses energy at every impact (Housner);
//! - a 32-sided cylinder rocking on its rim never tilts past the angle it was released at once
//!   contact normals are not kept while they turn (`contact_reuse_max_turn_deg` 0.01°, with or
//!   without a rolling friction), and does with parry's 1° (the default: seed 313's bottle);
//! - a cylinder on an incline stays while tan θ ≤ μ_r / r and rolls above, decelerated by the
//!   rolling friction's μ_r g cos θ / (1.5 r) (`rolling_friction`);
//! - and it is held exactly (no creep) where MuJoCo's condim 6 holds it, with the export's
//!   contact settings (`tests/python/incline_mujoco.py`), and rolls where MuJoCo's rolls.

use interact3d::mesh::{P3, V3};
use interact3d::physics::{cylinder_inertia, simulate, PoseRecord, SettleOptions, SimBody};
use interact3d::shapes::{cuboid, cylinder};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

mod common;

/// The library's settle options with sleeping and the start kick off.
fn awake() -> SettleOptions {
    SettleOptions {
        sleep_linear_threshold: 0.0,
        perturbation_speed: 0.0,
        ..SettleOptions::default()
    }
}

fn dynamic_box(name: &str, e: V3, mass: f64, pose: Isometry3<f64>, mu: f64) -> SimBody {
    SimBody::cuboid(name, e, mass, pose, mu)
}

fn fixed_box(name: &str, e: V3, pose: Isometry3<f64>, mu: f64) -> SimBody {
    SimBody {
        fixed: true,
        ..dynamic_box(name, e, 1.0, pose, mu)
    }
}

fn rotation(p: &PoseRecord) -> UnitQuaternion<f64> {
    let q = p.quaternion_wxyz;
    UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]))
}

/// How far body `i` moves (m) and turns (degrees) from `from` s to the end of a run of
/// `seconds`, recorded every 0.5 s.
fn motion(
    bodies: &[SimBody],
    opts: &SettleOptions,
    i: usize,
    from: f64,
    seconds: f64,
) -> (f64, f64) {
    let every = (0.5 / opts.dt).round() as usize;
    let t = simulate(bodies, opts, seconds, every).unwrap();
    let k = t.times.iter().position(|&x| x >= from - 1e-9).unwrap();
    let (a, b) = (&t.frames[k][i], t.frames.last().unwrap()[i]);
    let d = (Vector3::from(b.translation) - Vector3::from(a.translation)).norm();
    (d, rotation(a).angle_to(&rotation(&b)).to_degrees())
}

/// A 4 cm, 0.2 kg cube on a fixed plate turned by `deg` about y, friction `mu` on both.
fn block_on_incline(deg: f64, mu: f64) -> Vec<SimBody> {
    let rot = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), deg.to_radians());
    let up = rot * Vector3::z();
    let top = Vector3::new(0.0, 0.0, 0.1);
    let plate = fixed_box(
        "plate",
        V3::new(0.4, 0.4, 0.02),
        Isometry3::from_parts(Translation3::from(top - up * 0.01), rot),
        mu,
    );
    let cube = V3::new(0.04, 0.04, 0.04);
    let block = dynamic_box(
        "block",
        cube,
        0.2,
        Isometry3::from_parts(Translation3::from(top + up * (0.02 + 1e-5)), rot),
        mu,
    );
    vec![plate, block]
}

#[test]
fn a_block_on_an_incline_is_held_below_atan_mu_and_slides_above() {
    let mut opts = awake();
    for mu in [0.3, 0.6] {
        opts.floor_friction = mu;
        let limit = mu.atan().to_degrees();
        // Held: after the first second (the 10 µm drop onto the plate), nothing moves at all.
        for deg in [0.5 * limit, limit - 1.5] {
            let (d, a) = motion(&block_on_incline(deg, mu), &opts, 1, 1.0, 3.0);
            assert!(
                d < 1e-6 && a < 1e-3,
                "μ {mu}, {deg:.2}°: crept {d:.2e} m, {a:.2e}°"
            );
        }
        // Slides: gone down the slope by centimetres within the next second.
        let (d, _) = motion(&block_on_incline(limit + 1.5, mu), &opts, 1, 0.5, 1.5);
        assert!(d > 0.02, "μ {mu}, {:.2}°: slid only {d:.4} m", limit + 1.5);
    }
}

/// A 2 × 4 × 20 cm, 0.2 kg box leaning at `deg` from the vertical against a wall whose face is at
/// x = 0: its bottom edge 10 µm above the floor, its top edge 10 µm from the wall (`edge`: the
/// wall is only 70 % as high as the box reaches, which then leans on the wall's top edge). The
/// wall is fixed, or a dynamic 40 × 40 cm box of 1 kg on the floor.
fn ladder(deg: f64, mu: f64, edge: bool, dynamic_wall: bool) -> Vec<SimBody> {
    let e = V3::new(0.02, 0.04, 0.20);
    let rot = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), deg.to_radians());
    let verts: Vec<Vector3<f64>> = cuboid(e).vertices.iter().map(|v| rot * v.coords).collect();
    let min_z = verts.iter().map(|v| v.z).fold(f64::INFINITY, f64::min);
    let max_x = verts.iter().map(|v| v.x).fold(f64::NEG_INFINITY, f64::max);
    let centre = Vector3::new(-max_x - 1e-5, 0.0, -min_z + 1e-5);
    let (face_x, height) = if edge {
        // The wall's top edge on the box's wall-side face, at 70 % of the box's reach.
        let h = 0.7 * e.z * deg.to_radians().cos();
        let n = rot * Vector3::x();
        ((0.5 * e.x + n.dot(&centre) - n.z * h) / n.x + 1e-5, h)
    } else {
        (0.0, 0.4)
    };
    let wall_e = V3::new(0.4, 0.4, height);
    let wall_pose = Isometry3::translation(face_x + 0.2, 0.0, 0.5 * height + 1e-5);
    let wall = if dynamic_wall {
        dynamic_box("wall", wall_e, 1.0, wall_pose, mu)
    } else {
        fixed_box("wall", wall_e, wall_pose, mu)
    };
    let leaning = Isometry3::from_parts(Translation3::from(centre), rot);
    vec![dynamic_box("ladder", e, 0.2, leaning, mu), wall]
}

#[test]
fn a_leaning_box_is_held_below_its_coulomb_limit_and_falls_above() {
    let mu: f64 = 0.6;
    let mut opts = awake();
    opts.floor_friction = mu;
    // A uniform ladder with friction μ at both ends holds while tan θ ≤ 2μ / (1 − μ²).
    let limit = (2.0 * mu / (1.0 - mu * mu)).atan().to_degrees(); // 61.93°
    for (edge, dynamic_wall) in [(false, false), (false, true), (true, false), (true, true)] {
        for deg in [10.0, 25.0, 40.0] {
            let (d, a) = motion(&ladder(deg, mu, edge, dynamic_wall), &opts, 0, 1.0, 3.0);
            assert!(
                d < 1e-6 && a < 1e-3,
                "edge {edge}, dynamic wall {dynamic_wall}, {deg}°: crept {d:.2e} m, {a:.2e}°"
            );
        }
    }
    // On the fixed wall's face: held 4° inside the limit, down 3° past it.
    let (d, a) = motion(&ladder(limit - 4.0, mu, false, false), &opts, 0, 1.0, 3.0);
    assert!(d < 1e-6 && a < 1e-3, "{:.2}°: crept {d:.2e} m", limit - 4.0);
    let (d, _) = motion(&ladder(limit + 3.0, mu, false, false), &opts, 0, 0.0, 2.0);
    assert!(d > 0.02, "{:.2}°: moved only {d:.4} m", limit + 3.0);
}

/// Tilt (degrees) of the body's z axis from the vertical, every step of a run of `seconds`,
/// released at rest with its lowest point 10 µm above the floor.
fn tilts(body: SimBody, opts: &SettleOptions, seconds: f64) -> Vec<f64> {
    let t = simulate(std::slice::from_ref(&body), opts, seconds, 1).unwrap();
    t.frames
        .iter()
        .map(|f| {
            let axis = rotation(&f[0]) * Vector3::z();
            axis.z.clamp(-1.0, 1.0).acos().to_degrees()
        })
        .collect()
}

/// Largest tilt of each swing: the maxima between consecutive passes through upright (the
/// frames where the tilt reaches a local minimum under `upright` degrees).
fn swing_peaks(tilt: &[f64], upright: f64) -> Vec<f64> {
    let mut peaks = vec![];
    let mut peak: f64 = 0.0;
    for k in 1..tilt.len() - 1 {
        peak = peak.max(tilt[k]);
        if tilt[k] < upright && tilt[k] <= tilt[k - 1] && tilt[k] <= tilt[k + 1] {
            peaks.push(peak);
            peak = 0.0;
        }
    }
    peaks.push(peak.max(tilt[tilt.len() - 1]));
    peaks
}

/// `hulls` released tilted by `deg` about y, resting on its lowest point.
fn released(name: &str, mut body: SimBody, deg: f64) -> SimBody {
    let rot = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), deg.to_radians());
    let min_z = body.hulls[0]
        .vertices
        .iter()
        .map(|v| (rot * v.coords).z)
        .fold(f64::INFINITY, f64::min);
    body.name = name.into();
    body.pose = Isometry3::from_parts(Translation3::new(0.0, 0.0, -min_z + 1e-5), rot);
    body
}

#[test]
fn a_slender_block_rocking_on_its_edges_loses_energy_at_every_impact() {
    // Housner (1963): a block of half-width b and half-height h rocking on its edges keeps a
    // fraction r = (1 − 3/2 sin² α)² of its energy at each impact, α = atan(b / h); released
    // at θ0 it first rebounds to θ1 with cos(α − θ1) = cos α + r (cos(α − θ0) − cos α).
    let (b, h) = (0.015, 0.1);
    let e = V3::new(2.0 * b, 0.04, 2.0 * h);
    let block = released(
        "block",
        dynamic_box("b", e, 0.5, Isometry3::identity(), 0.6),
        4.0,
    );
    let alpha = (b / h).atan();
    let r = (1.0 - 1.5 * alpha.sin().powi(2)).powi(2);
    let theta0 = 4f64.to_radians();
    let c1 = alpha.cos() + r * ((alpha - theta0).cos() - alpha.cos());
    let theta1 = (alpha - c1.acos()).to_degrees(); // 3.64°
    let peaks = swing_peaks(&tilts(block, &awake(), 3.0), 0.5);
    assert!(peaks.len() >= 3, "{peaks:?}");
    assert!((peaks[0] - 4.0).abs() < 0.01, "{peaks:?}");
    // The solver's impacts may dissipate more than Housner's (soft contacts), never less.
    assert!(
        peaks[1] <= theta1 + 0.05,
        "first rebound {:.3}° > {theta1:.3}°",
        peaks[1]
    );
    for w in peaks.windows(2) {
        assert!(w[1] <= w[0] + 0.01, "a swing grew: {peaks:?}");
    }
}

#[test]
fn a_cylinder_rocking_on_its_rim_never_tilts_past_its_release_angle() {
    // 313's bottle: a 32-sided cylinder, r 3 cm, 25 cm tall, 0.5 kg, released at rest tilted
    // 4°. Its energy can only fall, and its potential energy at a tilt θ on any rim point is
    // at least that on the inscribed circle (radius r cos(π/32)): no swing may pass 4.2°.
    let (r, h, m) = (0.03, 0.25, 0.5);
    let body = SimBody {
        name: "c".into(),
        pose: Isometry3::identity(),
        hulls: vec![cylinder(r, h, 32)],
        mass: m,
        com: P3::origin(),
        inertia: cylinder_inertia(m, r, h),
        friction: 0.6,
        fixed: false,
    };
    let body = released("cylinder", body, 4.0);
    // Largest tilt per 0.25 s (60 steps).
    let quarters = |opts: &SettleOptions| -> Vec<f64> {
        tilts(body.clone(), opts, 4.0)
            .chunks(60)
            .map(|c| c.iter().copied().fold(0.0, f64::max))
            .collect()
    };
    let fresh = quarters(&SettleOptions {
        contact_reuse_max_turn_deg: 0.01,
        rolling_friction: 0.0,
        ..awake()
    });
    assert!(
        fresh[1..].iter().all(|&t| t <= 4.2) && fresh[fresh.len() - 2] < 2.0,
        "normals recomputed once turned 0.01°: {fresh:.2?}"
    );
    // With MuJoCo's rolling friction (0.1 mm) as well it comes to rest no later.
    let rolling = quarters(&SettleOptions {
        contact_reuse_max_turn_deg: 0.01,
        rolling_friction: 0.0001,
        ..awake()
    });
    assert!(
        rolling[1..].iter().all(|&t| t <= 4.2) && rolling[rolling.len() - 2] < 2.0,
        "0.01° and μ_r 0.1 mm: {rolling:.2?}"
    );
    // The cause: parry keeps a manifold's normal (in the body's frame) while it turns < 1°.
    let kept = quarters(&SettleOptions {
        contact_reuse_max_turn_deg: 1.0,
        rolling_friction: 0.0,
        ..awake()
    });
    assert!(
        kept.iter().copied().fold(0.0, f64::max) > 5.0,
        "parry's 1°: {kept:.2?}"
    );
}

/// A cylinder of `sides` sides (r 2 cm, 10 cm long, 0.2 kg, axis along y) lying on a fixed
/// plate turned by `deg` about y, friction 0.6 on both: it can only roll down the slope (along x).
fn cylinder_on_incline(deg: f64, sides: usize) -> Vec<SimBody> {
    cylinder_on_incline_mu(deg, sides, 0.6)
}

/// [`cylinder_on_incline`] with sliding friction `mu` on both.
fn cylinder_on_incline_mu(deg: f64, sides: usize, mu: f64) -> Vec<SimBody> {
    let mut v = block_on_incline(deg, mu);
    let (r, l, m) = (0.02, 0.1, 0.2);
    let rot = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), deg.to_radians());
    let up = rot * Vector3::z();
    // A 4 m plate: it rolls up to 0.6 m in the time measured.
    v[0] = fixed_box(
        "plate",
        V3::new(4.0, 0.4, 0.02),
        Isometry3::from_parts(
            Translation3::from(Vector3::new(0.0, 0.0, 0.1) - up * 0.01),
            rot,
        ),
        mu,
    );
    // The cylinder's axis (its z) along y; a face, not a vertex, down: slices at ±π/sides.
    let half = std::f64::consts::PI / sides as f64;
    let lie = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), -std::f64::consts::FRAC_PI_2)
        * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), half);
    let apothem = r * half.cos();
    let top = Vector3::new(0.0, 0.0, 0.1);
    v[1] = SimBody {
        name: "roller".into(),
        pose: Isometry3::from_parts(Translation3::from(top + up * (apothem + 1e-5)), rot * lie),
        hulls: vec![cylinder(r, l, sides)],
        mass: m,
        com: P3::origin(),
        inertia: cylinder_inertia(m, r, l),
        friction: mu,
        fixed: false,
    };
    v
}

#[test]
fn a_cylinder_on_an_incline_rolls_iff_tan_theta_exceeds_rolling_friction_over_radius() {
    // Rolling friction μ_r (m) bounds the torque opposing rolling by μ_r·N: a cylinder of
    // radius r stays on an incline while tan θ ≤ μ_r / r and otherwise rolls down with
    // a = g (sin θ − μ_r cos θ / r) / (1 + I / (m r²)), I / (m r²) = 1/2. r 2 cm and μ_r 2 mm:
    // θ_c = atan 0.1 = 5.71°. The 128 facets alone hold it only below π/128 = 1.41°.
    let (r, mu_r, g) = (0.02, 0.002, 9.81);
    let opts = SettleOptions {
        rolling_friction: mu_r,
        ..awake()
    };
    // Held at 0.8 θ_c, after the first second: nothing rolls.
    let (d, a) = motion(&cylinder_on_incline(4.5, 128), &opts, 1, 1.0, 3.0);
    assert!(
        d < 1e-4 && a < 0.3,
        "4.5° with μ_r: moved {d:.2e} m, {a:.3}°"
    );
    // Without it the same cylinder rolls away (what the settle did before).
    let none = SettleOptions {
        rolling_friction: 0.0,
        ..awake()
    };
    let (d, _) = motion(&cylinder_on_incline(4.5, 128), &none, 1, 1.0, 3.0);
    assert!(d > 0.05, "4.5° without μ_r: moved only {d:.4} m");
    // Above θ_c it rolls away too.
    let (d, _) = motion(&cylinder_on_incline(12.0, 128), &opts, 1, 1.0, 2.0);
    assert!(d > 0.05, "12° with μ_r: rolled only {d:.4} m");
    // μ_r takes μ_r g cos θ / (1.5 r) off the acceleration g sin θ / 1.5: the distance from
    // 0.5 s to 1 s from rest at 0 s is a (1² − 0.5²) / 2. A 512-gon, whose facets take only
    // 1–5 % off the free roll (a 128-gon's take 13–15 %, more the faster it rolls, which biased
    // a comparison of runs with and without μ_r by 10 %); with parry's kept normals (1°) and
    // with contacts recomputed every step (0.01°, the default). `N` counts only the points the
    // solver used: the manifold's stale extra point made it 1.4–1.5× the weight at 0.01° and
    // stopped the cylinder at 8° (docs/agreement.md "Fourteenth stop").
    for turn in [1.0, 0.01] {
        let kept = |mu_r: f64| SettleOptions {
            rolling_friction: mu_r,
            contact_reuse_max_turn_deg: turn,
            ..awake()
        };
        for deg in [8.0f64, 12.0] {
            let th = deg.to_radians();
            let free = g * th.sin() / 1.5 * 0.375;
            let want = g * mu_r * th.cos() / (1.5 * r) * 0.375;
            let (without, _) = motion(&cylinder_on_incline(deg, 512), &kept(0.0), 1, 0.5, 1.0);
            assert!(
                (without - free).abs() < 0.1 * free,
                "{turn}°, {deg}° without μ_r: rolled {without:.4} m in 0.5–1 s, free {free:.4} m"
            );
            let (with, _) = motion(&cylinder_on_incline(deg, 512), &kept(mu_r), 1, 0.5, 1.0);
            assert!(
                (free - with - want).abs() < 0.1 * want,
                "{turn}°, {deg}°: rolled {with:.4} m in 0.5–1 s, {:.4} m less than free, \
                 predicted {want:.4} m less",
                free - with
            );
        }
    }
}

#[test]
fn a_cylinder_on_an_incline_is_held_where_mujoco_holds_it_and_rolls_where_it_rolls() {
    // The hold is solved within the step (the `rolling` module): below θ_c = atan(μ_r / r)
    // nothing moves at all once settled, as in MuJoCo (condim 6, the export's contact
    // settings), where the torque kept from the previous step alone crept 2–7 µm in 2 s and,
    // with parry's kept normals, rolled off at 0.95 θ_c (docs/agreement.md "Fifteenth stop").
    // A 512-gon (its facets alone hold it only below 0.35°), r 2 cm, μ_r 2 mm: θ_c = 5.71°.
    let (r, mu_r): (f64, f64) = (0.02, 0.002);
    let theta_c = (mu_r / r).atan().to_degrees();
    let fractions = [0.8, 0.95, 1.05, 1.2];
    let degs: Vec<f64> = fractions.iter().map(|f| f * theta_c).collect();
    let engine = common::python_or_skip("incline against MuJoCo").then(|| {
        let args: Vec<String> = ["512".to_string(), mu_r.to_string()]
            .into_iter()
            .chain(degs.iter().map(|d| d.to_string()))
            .collect();
        let args: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
        let v = common::python_json("incline_mujoco.py", &args);
        v["moved"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect::<Vec<f64>>()
    });
    for turn in [1.0, 0.01] {
        let opts = SettleOptions {
            rolling_friction: mu_r,
            contact_reuse_max_turn_deg: turn,
            ..awake()
        };
        for (k, (&f, &deg)) in fractions.iter().zip(&degs).enumerate() {
            let (d, _) = motion(&cylinder_on_incline(deg, 512), &opts, 1, 1.0, 3.0);
            let held = f < 1.0;
            if held {
                assert!(
                    d < 1e-6,
                    "{turn}°, {f} θ_c ({deg:.3}°): crept {d:.2e} m in 1–3 s"
                );
            } else {
                assert!(
                    d > 0.05,
                    "{turn}°, {f} θ_c ({deg:.3}°): rolled only {d:.4} m"
                );
            }
            if let Some(mj) = &engine {
                assert_eq!(
                    mj[k] < 1e-6,
                    held,
                    "MuJoCo at {f} θ_c ({deg:.3}°) moved {:.2e} m in 1–3 s",
                    mj[k]
                );
            }
        }
    }
}

#[test]
fn a_cylinder_carrying_friction_has_less_rolling_left_as_in_mujocos_elliptic_cone() {
    // MuJoCo's elliptic cone (`cone="elliptic"`, the export's) is one bound over every friction
    // dimension of a contact: (f_t / μ)² + (τ_r / μ_r)² ≤ N² (torsion aside). A cylinder held
    // on an incline carries f_t = N tan θ and τ_r = N r tan θ, so it stays while
    // (tan θ / μ)² + (r tan θ / μ_r)² ≤ 1: below θ_c = atan(μ_r / r) when μ is small. The
    // 512-gon, r 2 cm, μ_r 2 mm (θ_c 5.71°): with μ 0.1 it holds only to 4.04°, with μ 0.15 to
    // 4.76°; a bound of μ_r N alone (session 19's) held all four angles below θ_c.
    let (r, mu_r): (f64, f64) = (0.02, 0.002);
    let theta_c = (mu_r / r).atan().to_degrees();
    // (sliding friction, fraction of θ_c)
    let cases = [(0.1, 0.6), (0.1, 0.8), (0.15, 0.8), (0.15, 0.9)];
    for (mu, f) in cases {
        let deg = f * theta_c;
        let t = deg.to_radians().tan();
        let held = (t / mu).powi(2) + (r * t / mu_r).powi(2) <= 1.0;
        if common::python_or_skip("shared cone against MuJoCo") {
            let args = [
                "--mu".to_string(),
                mu.to_string(),
                "512".into(),
                mu_r.to_string(),
                deg.to_string(),
            ];
            let args: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
            let v = common::python_json("incline_mujoco.py", &args);
            let mj = v["moved"][0].as_f64().unwrap();
            assert_eq!(
                mj < 1e-6,
                held,
                "MuJoCo, μ {mu}, {f} θ_c ({deg:.3}°): moved {mj:.2e} m in 1–3 s"
            );
        }
        for turn in [1.0, 0.01] {
            let opts = SettleOptions {
                rolling_friction: mu_r,
                contact_reuse_max_turn_deg: turn,
                ..awake()
            };
            let (d, _) = motion(&cylinder_on_incline_mu(deg, 512, mu), &opts, 1, 1.0, 3.0);
            if held {
                assert!(
                    d < 1e-6,
                    "{turn}°, μ {mu}, {f} θ_c ({deg:.3}°): crept {d:.2e} m"
                );
            } else {
                assert!(
                    d > 0.05,
                    "{turn}°, μ {mu}, {f} θ_c ({deg:.3}°): moved only {d:.4} m"
                );
            }
        }
    }
}
