//! Settle-test scenes with analytic expectations. Test-only shapes live here.

use super::*;
use crate::mesh::V3;
use crate::shapes::{cuboid, uv_sphere};
use nalgebra::{Matrix4, Vector3};
use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_4, PI};

fn at(x: f64, y: f64, z: f64) -> Isometry3<f64> {
    Isometry3::translation(x, y, z)
}

fn box_body(name: &str, e: V3, mass: f64, pose: Isometry3<f64>) -> SimBody {
    SimBody::cuboid(name, e, mass, pose, 0.6)
}

fn sphere_body(name: &str, r: f64, mass: f64, pose: Isometry3<f64>) -> SimBody {
    SimBody {
        name: name.into(),
        pose,
        hulls: vec![uv_sphere(r, 16, 32)],
        mass,
        com: P3::origin(),
        inertia: Matrix3::identity() * (0.4 * mass * r * r),
        friction: 0.6,
        fixed: false,
    }
}

const PLATE_TOP: f64 = 0.01;
const WALL_RADIUS: f64 = 0.06;
const WALL_THICKNESS: f64 = 0.01;

/// A bowl of `walls + 1` convex hulls in its body frame (origin at the bottom centre): a square
/// bottom plate 14 x 14 x 1 cm and a ring of `walls` boxes 5 cm tall standing on it, inner
/// faces at 5.5 cm from the axis.
fn bowl_hulls(walls: usize) -> Vec<Mesh> {
    let mut hulls =
        vec![
            cuboid(V3::new(0.14, 0.14, PLATE_TOP)).transformed(&Matrix4::new_translation(
                &V3::new(0.0, 0.0, PLATE_TOP / 2.0),
            )),
        ];
    let width = 2.0 * PI * WALL_RADIUS / walls as f64 * 1.05;
    for k in 0..walls {
        let phi = 2.0 * PI * k as f64 / walls as f64;
        let m = Isometry3::new(
            V3::new(
                WALL_RADIUS * phi.cos(),
                WALL_RADIUS * phi.sin(),
                PLATE_TOP + 0.025,
            ),
            V3::z() * phi,
        )
        .to_homogeneous();
        hulls.push(cuboid(V3::new(WALL_THICKNESS, width, 0.05)).transformed(&m));
    }
    hulls
}

fn bowl_body(name: &str, walls: usize, pose: Isometry3<f64>) -> SimBody {
    let mass = 0.4;
    SimBody {
        name: name.into(),
        pose,
        hulls: bowl_hulls(walls),
        mass,
        com: P3::new(0.0, 0.0, 0.015),
        inertia: box_inertia(mass, V3::new(0.14, 0.14, 0.04)),
        friction: 0.6,
        fixed: false,
    }
}

fn body<'r>(r: &'r SettleReport, name: &str) -> &'r BodyReport {
    r.bodies.iter().find(|b| b.name == name).unwrap()
}

fn run(bodies: &[SimBody]) -> SettleReport {
    let r = settle(bodies, &SettleOptions::default()).unwrap();
    eprintln!("{}", serde_json::to_string_pretty(&r).unwrap());
    r
}

#[test]
fn box_on_floor_passes_and_sleeps() {
    let e = V3::new(0.08, 0.06, 0.04);
    let r = run(&[box_body("box", e, 0.2, at(0.0, 0.0, 0.02 + 0.0005))]);
    let b = body(&r, "box");
    assert!(r.passed, "{:?}", b.reasons);
    assert!(
        r.time_to_sleep.is_some(),
        "a box resting on the floor must sleep"
    );
    assert!(b.settle_displacement < 0.001, "{}", b.settle_displacement);
    assert!(b.settle_rotation_deg < 0.1);
    assert!(b.rest_displacement < 1e-4, "{}", b.rest_displacement);
    assert!(b.rest_rotation_deg < 0.01);
    assert!(b.rest_max_penetration < 0.001);
    assert_eq!(b.supports_at_start, vec!["floor"]);
    // Settled on the floor: centre at half the height, within the solver's penetration.
    let z = b.settled_pose.translation[2];
    assert!((z - 0.02).abs() < 0.0005, "{z}");
}

#[test]
fn box_on_its_edge_topples() {
    let s = 0.05;
    let pose = Isometry3::from_parts(
        Translation3::new(0.0, 0.0, s / 2f64.sqrt() + 0.0005),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), FRAC_PI_4),
    );
    let r = run(&[box_body("cube", V3::new(s, s, s), 0.2, pose)]);
    let b = body(&r, "cube");
    assert!(!r.passed);
    assert!(b.settle_rotation_deg > 30.0, "{}", b.settle_rotation_deg);
    assert!(
        b.reasons.iter().any(|s| s.contains("turned")),
        "{:?}",
        b.reasons
    );
    // Onto a face: a quarter of the cube's own symmetry turn. Its corners then stand out of the
    // unturned cube by s (1/√2 − 1/2), 12 % of the diagonal.
    let shift = b.settle_shape_shift.expect("measured past the limit");
    assert!((b.settle_rotation_deg - 45.0).abs() < 1.0);
    let expected = s * (FRAC_1_SQRT_2 - 0.5);
    assert!(
        (shift - expected).abs() < 0.01 * expected,
        "{shift} vs {expected}"
    );
    assert!(shift > 0.1 * b.bbox_diagonal, "{shift}");
}

/// `Sim::shape_shift` of a 16-sided prism (a pen: radius 5 mm, 140 mm long) turned by 40°.
#[test]
fn a_turn_about_an_axis_of_symmetry_barely_moves_the_shape() {
    let (r, h, n) = (0.005, 0.14, 16);
    let pen = SimBody {
        name: "pen".into(),
        pose: at(0.0, 0.0, 0.1),
        hulls: vec![crate::shapes::cylinder(r, h, n)],
        mass: 0.01,
        com: P3::origin(),
        inertia: Matrix3::identity() * 1e-6,
        friction: 0.6,
        fixed: false,
    };
    let opts = SettleOptions::default();
    let sim = Sim::new(std::slice::from_ref(&pen), &opts).unwrap();
    let turned = |axis: &nalgebra::Unit<Vector3<f64>>| {
        Isometry3::from_parts(
            pen.pose.translation,
            UnitQuaternion::from_axis_angle(axis, 40f64.to_radians()),
        )
    };
    // About its own axis: every rim vertex lands 17.5° past a vertex of the 22.5° polygon, out
    // of the edge there (its normal 11.25° from the vertex, its line r cos 11.25° from the axis).
    let half = PI / n as f64;
    let expected = r * ((17.5f64.to_radians() - half).cos() - half.cos());
    let spin = sim.shape_shift(0, &pen.pose, &turned(&Vector3::z_axis()));
    assert!((spin - expected).abs() < 1e-9, "{spin} vs {expected}");
    // About a transverse axis: the rim vertex at (0, −r, h/2) swings out to
    // y = −(r cos 40° + h/2 sin 40°), that far minus r from the prism's side.
    let (c, s) = (40f64.to_radians().cos(), 40f64.to_radians().sin());
    let tilt = sim.shape_shift(0, &pen.pose, &turned(&Vector3::x_axis()));
    let swing = r * c + h / 2.0 * s - r;
    assert!((tilt - swing).abs() < 0.02 * swing, "{tilt} vs {swing}");
    let diag = (8.0 * r * r + h * h).sqrt();
    assert!(spin < 0.001 * diag && tilt > 0.25 * diag);
}

#[test]
fn sphere_settles_at_the_bottom_of_a_bowl() {
    // A generic attitude, and the pole vertex down: 32 fan facets within ~1.1° of each other
    // form a nearly flat cone. With contact recycling off Rapier keeps the ball creeping around
    // that cone (measured 0.4–4 mm and 1–11° during the 1 s rest check, depending chaotically
    // on solver settings); with the default 0.5 mm recycling it rests.
    for rotation in [
        UnitQuaternion::from_euler_angles(0.9, 0.2, 0.1),
        UnitQuaternion::identity(),
    ] {
        let r = sphere_in_bowl(rotation);
        assert!(r.passed, "{:?}", body(&r, "ball").reasons);
        assert!(r.time_to_sleep.is_some());
    }
}

fn sphere_in_bowl(rotation: UnitQuaternion<f64>) -> SettleReport {
    let r_ball = 0.02;
    let bowl = bowl_body("bowl", 12, at(0.0, 0.0, 0.0005));
    let mut ball = sphere_body(
        "ball",
        r_ball,
        0.1,
        at(0.01, 0.005, 0.0005 + PLATE_TOP + r_ball + 0.001),
    );
    ball.pose.rotation = rotation;
    let r = run(&[bowl, ball]);
    let (bw, bl) = (body(&r, "bowl"), body(&r, "ball"));
    assert!(bw.passed, "{:?}", bw.reasons);
    assert_eq!(bl.supports_at_start, vec!["bowl"]);
    assert_eq!(bw.supports_at_start, vec!["floor"]);
    assert!(bl.touching_after_settle.contains(&"bowl".to_string()));
    // Analytic rest: ball centre at the plate top + radius (the polyhedral sphere rests on a
    // facet slightly inside the radius), inside the ring of walls.
    let bowl_pose = bw.settled_pose.isometry();
    let c = bowl_pose.inverse() * P3::from(bl.settled_pose.translation);
    assert!((c.z - (PLATE_TOP + r_ball)).abs() < 0.001, "{}", c.z);
    assert!(c.xy().coords.norm() < WALL_RADIUS - WALL_THICKNESS / 2.0 - r_ball);
    assert!(bl.rest_max_penetration < 0.001);
    r
}

fn lower_again() -> SimBody {
    box_body("lower", V3::new(0.1, 0.1, 0.1), 0.5, at(0.0, 0.0, 0.0505))
}

#[test]
fn stacked_boxes_pass_and_a_floating_box_falls() {
    let lower = lower_again();
    let upper = box_body(
        "upper",
        V3::new(0.06, 0.06, 0.06),
        0.2,
        at(0.0, 0.0, 0.101 + 0.03),
    );
    let r = run(&[lower, upper.clone()]);
    let (lo, up) = (body(&r, "lower"), body(&r, "upper"));
    assert!(r.passed, "{:?} {:?}", lo.reasons, up.reasons);
    assert_eq!(up.supports_at_start, vec!["lower"]);
    assert_eq!(lo.supports_at_start, vec!["floor"]);
    assert!(!up.left_supports);

    // Overhanging by more than half its width: it tips off the lower box onto the floor.
    let overhang = SimBody {
        pose: at(0.065, 0.0, 0.101 + 0.03),
        ..upper.clone()
    };
    let r = run(&[lower_again(), overhang]);
    let up = body(&r, "upper");
    assert!(!r.passed);
    assert_eq!(up.supports_at_start, vec!["lower"]);
    assert!(up.left_supports && up.ended_on_floor, "{:?}", up.reasons);
    assert!(up.reasons.iter().any(|s| s.contains("ended on the floor")));

    // Without the lower box the upper one starts 5 cm above the floor and falls.
    let alone = SimBody {
        pose: at(0.0, 0.0, 0.05 + 0.03),
        ..upper
    };
    let r = run(&[alone]);
    let up = body(&r, "upper");
    assert!(!r.passed);
    assert!(
        (up.settle_displacement - 0.05).abs() < 0.002,
        "{}",
        up.settle_displacement
    );
    assert!(
        up.reasons.iter().any(|s| s.contains("drifted")),
        "{:?}",
        up.reasons
    );
    assert!(up.supports_at_start.is_empty());
}

#[test]
fn interpenetrating_boxes_are_flagged() {
    let s = 0.05;
    let a = box_body("a", V3::new(s, s, s), 0.2, at(0.0, 0.0, s / 2.0 + 0.0005));
    let b = box_body(
        "b",
        V3::new(s, s, s),
        0.2,
        at(s - 0.005, 0.0, s / 2.0 + 0.0005),
    );
    let r = run(&[a, b]);
    assert!(!r.passed);
    for name in ["a", "b"] {
        let x = body(&r, name);
        assert!(
            (x.initial_penetration - 0.005).abs() < 1e-6,
            "{}",
            x.initial_penetration
        );
        assert!(
            x.reasons.iter().any(|s| s.contains("interpenetrating")),
            "{:?}",
            x.reasons
        );
    }
}

#[test]
fn deterministic() {
    let scene = [
        bowl_body("bowl", 12, at(0.0, 0.0, 0.0005)),
        sphere_body("ball", 0.02, 0.1, at(0.01, 0.005, 0.0325)),
    ];
    let a = settle(&scene, &SettleOptions::default()).unwrap();
    let b = settle(&scene, &SettleOptions::default()).unwrap();
    assert_eq!(a, b);
    assert_eq!(
        serde_json::to_string(&a).unwrap(),
        serde_json::to_string(&b).unwrap()
    );
}

#[test]
fn off_diagonal_inertia_is_kept() {
    let e = V3::new(0.08, 0.04, 0.02);
    let m = 0.3;
    let rot = Rotation3::from_euler_angles(0.3, -0.7, 1.1);
    let inertia = rot.matrix() * box_inertia(m, e) * rot.matrix().transpose();
    assert!(inertia[(0, 1)].abs() > 1e-6 && inertia[(1, 2)].abs() > 1e-6);
    let com = P3::new(0.01, -0.002, 0.005);
    let iso = Isometry3::from_parts(Translation3::from(com.coords), rot.into());
    let b = SimBody {
        name: "tilted".into(),
        pose: at(0.0, 0.0, 0.1),
        hulls: vec![cuboid(e).transformed(&iso.to_homogeneous())],
        mass: m,
        com,
        inertia,
        friction: 0.5,
        fixed: false,
    };
    let (mass, c, i) = rapier_mass_properties(&b).unwrap();
    assert!((mass - m).abs() < 1e-12);
    assert!((c - com).norm() < 1e-15);
    let err = (i - inertia).abs().max() / inertia.abs().max();
    assert!(err < 1e-9, "{err:e}\n{i}\n{inertia}");
}

#[test]
fn degenerate_hull_is_an_error_naming_the_body() {
    let flat = Mesh::new(
        vec![
            P3::new(0.0, 0.0, 0.0),
            P3::new(0.01, 0.0, 0.0),
            P3::new(0.0, 0.01, 0.0),
            P3::new(0.01, 0.01, 0.0),
        ],
        vec![],
    );
    let mut b = box_body("sheet", V3::new(0.01, 0.01, 0.01), 0.1, at(0.0, 0.0, 0.1));
    b.hulls.push(flat);
    let err = settle(&[b], &SettleOptions::default()).unwrap_err();
    let msg = err.to_string();
    assert!(msg.contains("sheet") && msg.contains("hull 1"), "{msg}");
}

/// A round floor plate of pie-slice hulls (a basket's floor, as the decomposition cuts it),
/// its lowest vertices a few 1e-17 m above z = 0: what f64 rounding leaves of "resting on the
/// ground" once a pose is applied. parry's contact query gives such a slice, touching the
/// floor at its apex, a normal pointing *up* out of the floor in about half the cases (356 of
/// 2,000 random slices), and Rapier then slid the fixture basket 2.4 mm and rolled its three
/// fruits 32–84 mm out of it. The floor's top face is therefore `FLOOR_GAP` below z = 0; the
/// plate must stay where it is.
#[test]
fn a_plate_of_pie_slices_resting_on_the_floor_stays_put() {
    let (z0, z1) = (1.3877787807814457e-17, 2.7755575615628914e-17);
    let (r, t, n) = (0.1, 0.005, 8);
    let hulls: Vec<Mesh> = (0..n)
        .map(|k| {
            let mut pts = vec![P3::new(0.0, 0.0, z0), P3::new(0.0, 0.0, t)];
            for j in 0..=4 {
                let a = (k as f64 + j as f64 / 4.0) * 2.0 * PI / n as f64;
                pts.push(P3::new(r * a.cos(), r * a.sin(), z1));
                pts.push(P3::new(r * a.cos(), r * a.sin(), t));
            }
            crate::decompose::Hull::from_points(&pts).unwrap().mesh()
        })
        .collect();
    let mass = 0.5;
    let plate = SimBody {
        name: "plate".into(),
        pose: Isometry3::identity(),
        hulls,
        mass,
        com: P3::new(0.0, 0.0, t / 2.0),
        inertia: cylinder_inertia(mass, r, t),
        friction: 0.6,
        fixed: false,
    };
    let r = run(&[plate]);
    let b = body(&r, "plate");
    assert!(r.passed, "{:?}", b.reasons);
    assert!(b.settle_displacement < 1e-5, "{}", b.settle_displacement);
    assert!(b.settle_rotation_deg < 0.01, "{}", b.settle_rotation_deg);
}

/// Scanned objects rest on the floor, and on a box, instead of sinking into it: a flat package
/// (GSO) as one 64-vertex hull whose bottom is many nearly coplanar small faces (what the engine
/// gave it before issue #35's two-sided one-hull check; now it gets a few dozen hulls, also
/// tested) and a fork (YCB, 10 thin hulls, 20 g). With parry's reuse of last step's contact points against the box floor,
/// the package sank 1–3.7 mm (rest check failed at 7.5 mm; MuJoCo holds it within 1.2 mm and
/// 0.6°); on a half-space floor, whose manifold takes the hull face closest to facing straight
/// down rather than the lowest point, the fork jittered up to 2.4 mm into it.
#[test]
fn scanned_objects_rest_on_the_floor_and_on_a_box_without_sinking() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let Some(objects) = [root.join("../shared"), root.join("../../shared")]
        .into_iter()
        .map(|p| p.join("datasets/objects"))
        .find(|p| p.is_dir())
    else {
        // Loud, never a silent pass: written past the harness's capture; a failure under CI.
        let line = "physics::tests::scanned_objects_rest_on_the_floor_and_on_a_box_without_sinking: ../shared/datasets/objects not found";
        let ci = std::env::var("CI").is_ok_and(|v| v == "true")
            || std::env::var("INTERACT3D_REQUIRE").is_ok_and(|v| v.contains("shared"));
        assert!(!ci, "{line} (required under CI)");
        use std::io::Write;
        let _ = writeln!(std::io::stderr().lock(), "SKIPPED {line}");
        if let Ok(log) = std::env::var("INTERACT3D_SKIP_LOG") {
            if let Ok(mut f) = std::fs::OpenOptions::new()
                .create(true)
                .append(true)
                .open(log)
            {
                let _ = writeln!(f, "{line}");
            }
        }
        return;
    };
    let package = "gso/Google_Cardboard_Original_package/model.obj";
    for (file, one_hull) in [
        (package, true),
        (package, false),
        ("ycb/030_fork/textured.obj", false),
    ] {
        let scene = crate::scene::load(&objects.join(file), &Default::default()).unwrap();
        let a = crate::body::build(&scene, &Default::default()).unwrap();
        let mut bodies = crate::validate::sim_bodies(&a);
        if one_hull {
            // The hull of every hull vertex, cut down to 64 vertices: the old one-hull shape.
            let points: Vec<P3> = bodies[0]
                .hulls
                .iter()
                .flat_map(|h| h.vertices.clone())
                .collect();
            let h = crate::decompose::Hull::from_points(&points)
                .and_then(|h| h.simplified(64))
                .unwrap();
            assert!(h.vertices.len() <= 64 && h.triangles.len() > 64, "{file}");
            bodies[0].hulls = vec![crate::mesh::Mesh::new(h.vertices, h.triangles)];
        }
        assert!(!bodies[0].hulls.is_empty(), "{file}");
        eprintln!("{file}: {} hulls", bodies[0].hulls.len());
        let r = settle(&bodies, &SettleOptions::default()).unwrap();
        let b = &r.bodies[0];
        assert!(r.passed, "{file}: {:?}", b.reasons);
        assert!(
            b.rest_max_penetration < 5e-5,
            "{file}: {}",
            b.rest_max_penetration
        );
        // At most a few hundredths of a millimetre into the floor at the end.
        let pose = b.final_pose.isometry();
        let lowest = bodies[0]
            .hulls
            .iter()
            .flat_map(|h| h.vertices.iter())
            .map(|v| (pose * v).z)
            .fold(f64::INFINITY, f64::min);
        eprintln!(
            "{file}: rest penetration {:.4} mm, lowest vertex {:.4} mm",
            b.rest_max_penetration * 1e3,
            lowest * 1e3
        );
        assert!(lowest > -5e-5, "{file}: {lowest}");
        // The same on a fixed box hull 2 cm thick: hull–hull contacts (1–4 mm deep before).
        let mut on_tray = bodies.clone();
        on_tray[0].pose = at(0.0, 0.0, 0.02) * on_tray[0].pose;
        let mut tray = box_body("tray", V3::new(0.5, 0.5, 0.02), 1.0, at(0.0, 0.0, 0.01));
        tray.fixed = true;
        on_tray.push(tray);
        let r = settle(&on_tray, &SettleOptions::default()).unwrap();
        let b = &r.bodies[0];
        assert!(r.passed, "{file} on the tray: {:?}", b.reasons);
        assert_eq!(b.rest_max_penetration_with.as_deref(), Some("tray"));
        assert!(
            b.rest_max_penetration < 5e-5,
            "{file}: {}",
            b.rest_max_penetration
        );
    }
}

/// A 8 x 6 x 4 cm box on its face whose centre of mass sits `d` inside its +x bottom edge, 2 cm
/// up: its stability margin towards +x is atan(d / 2 cm).
fn lopsided_box(d: f64) -> SimBody {
    let e = V3::new(0.08, 0.06, 0.04);
    SimBody {
        com: P3::new(0.04 - d, 0.0, 0.0),
        ..box_body("box", e, 0.2, at(0.0, 0.0, 0.02))
    }
}

/// Settle with the start kick off: the lopsided boxes rest exactly as placed.
fn run_unkicked(bodies: &[SimBody]) -> SettleReport {
    let opts = SettleOptions {
        perturbation_speed: 0.0,
        ..SettleOptions::default()
    };
    settle(bodies, &opts).unwrap()
}

#[test]
fn probe_calls_a_box_on_its_face_stable() {
    let e = V3::new(0.08, 0.06, 0.04);
    let r = run(&[box_body("box", e, 0.2, at(0.0, 0.0, 0.02 + 0.0005))]);
    let b = body(&r, "box");
    assert!(r.passed, "{:?}", b.reasons);
    // Rolled 0.5° about an edge of its bottom face, a box falls back flat.
    assert!(!b.marginal, "{b:?}");
    assert!(b.probe_rotation_deg < 0.1, "{}", b.probe_rotation_deg);
    assert!(r.marginal.is_empty());
}

#[test]
fn probe_calls_a_pose_marginal_when_its_margin_is_under_the_nudge() {
    // d = 0.15 mm: margin atan(0.15 / 20) = 0.43° < the 0.5° nudge. It rests (nothing pushes
    // it), but rolled 0.5° onto its +x edge its centre of mass is past the edge: it topples.
    let r = run_unkicked(&[lopsided_box(1.5e-4)]);
    let b = body(&r, "box");
    assert!(r.passed, "{:?}", b.reasons);
    assert!(b.marginal, "{b:?}");
    assert!(b.probe_rotation_deg > 0.25, "{}", b.probe_rotation_deg);
    assert_eq!(r.marginal, vec!["box".to_string()]);
    // d = 2 mm: margin 5.7°, far above the nudge: it falls back onto its face.
    let r = run_unkicked(&[lopsided_box(2e-3)]);
    let b = body(&r, "box");
    assert!(r.passed, "{:?}", b.reasons);
    assert!(!b.marginal, "{b:?}");
    assert!(b.probe_rotation_deg < 0.25, "{}", b.probe_rotation_deg);
}

#[test]
fn probe_off_reports_nothing() {
    let opts = SettleOptions {
        probe_angle_deg: 0.0,
        ..SettleOptions::default()
    };
    let r = settle(&[lopsided_box(1.5e-4)], &opts).unwrap();
    assert!(!r.bodies[0].marginal);
    assert_eq!(r.bodies[0].probe_rotation_deg, 0.0);
}

/// Depth of the floor contact of a faceted ball resting on its pole vertex (one contact point
/// whose lever arm is zero, so the constraint's effective mass is the ball's mass), and after
/// `steps` steps from `start_depth` into the floor.
fn ball_floor_depth(opts: &SettleOptions, start_depth: f64, steps: usize) -> f64 {
    let r = 0.03;
    let ball = sphere_body("ball", r, 0.1, at(0.0, 0.0, r - start_depth));
    let sim_opts = SettleOptions {
        perturbation_speed: 0.0,
        ..opts.clone()
    };
    let mut sim = Sim::new(std::slice::from_ref(&ball), &sim_opts).unwrap();
    for _ in 0..steps {
        sim.step();
    }
    sim.penetrations()[0].0
}

#[test]
fn contact_rest_depth_scales_as_a_springs_and_damping_sets_the_push_out() {
    // A soft contact of natural frequency f holds a body's weight at a depth proportional to
    // g / (2πf)², whatever its damping ratio ζ (a spring's static deflection; Rapier scales the
    // spring by the constraint's effective mass). Measured: half of g/ω² (2.2 µm at 240 Hz, the
    // floor's contacts), so micrometres: not the 1 mm of `allowed_linear_error`, which in
    // Rapier 0.36 is no solver deadzone (issue #33).
    let depth = |f: f64, zeta: f64| {
        let opts = SettleOptions {
            static_contact_frequency: f,
            contact_damping_ratio: zeta,
            ..SettleOptions::default()
        };
        let d = ball_floor_depth(&opts, 0.0, 240);
        let w = 2.0 * PI * f;
        eprintln!(
            "f {f} Hz, ζ {zeta}: rest depth {d:.3e} m, g/ω² {:.3e} m",
            9.81 / (w * w)
        );
        assert!(d > 0.0 && d <= 9.81 / (w * w), "f {f}, ζ {zeta}: {d:.3e}");
        d
    };
    let (stiff, undamped, soft) = (depth(240.0, 10.0), depth(240.0, 1.0), depth(120.0, 10.0));
    assert!(
        (undamped / stiff - 1.0).abs() < 0.1,
        "{undamped} vs {stiff}"
    );
    assert!((soft / stiff / 4.0 - 1.0).abs() < 0.15, "{soft} vs {stiff}");
    // The damping ratio sets how fast a penetration is pushed out: Rapier corrects a depth d
    // at ω / (hω + 2ζ) · d per second (h = dt / solver_iterations): 70 /s at ζ = 10 (the
    // default, 240 Hz), 422 /s at ζ = 1. From 0.3 mm, after two steps (8.3 ms): e^(−0.58) ≈
    // 0.56 of it left at ζ = 10, e^(−3.5) ≈ 0.03 at ζ = 1.
    let left = |zeta: f64| {
        let opts = SettleOptions {
            contact_damping_ratio: zeta,
            ..SettleOptions::default()
        };
        ball_floor_depth(&opts, 3e-4, 2)
    };
    let (slow, fast) = (left(10.0), left(1.0));
    eprintln!("0.3 mm after 2 steps: ζ 10 {slow:.3e} m, ζ 1 {fast:.3e} m");
    assert!(slow > 0.1e-3, "{slow}");
    assert!(slow > 5.0 * fast, "{slow} vs {fast}");
}

#[test]
fn zero_pgs_sweeps_is_a_clear_options_error() {
    // Rapier would run no velocity solve at all with 0 PGS sweeps (bodies fall through the
    // floor); the options are refused up front, naming the field.
    let b = [box_body(
        "b",
        V3::new(0.05, 0.05, 0.05),
        0.1,
        at(0.0, 0.0, 0.025),
    )];
    let opts = SettleOptions {
        pgs_iterations: 0,
        ..SettleOptions::default()
    };
    match settle(&b, &opts) {
        Err(PhysicsError::InvalidOptions(m)) => assert!(m.contains("pgs_iterations"), "{m}"),
        other => panic!("expected an options error, got {other:?}"),
    }
}
