//! Interoperability: every export loads in MuJoCo and PyBullet as it is, with the bodies, geoms,
//! masses and inertias the report promises, and 1 s of simulation stays finite.
//! Needs Python with `mujoco` and `pybullet` (tests/python/requirements.txt; .ci/run installs
//! them).

mod common;
use common::*;
use std::path::Path;

fn eigen_sorted(m: &serde_json::Value) -> Vec<f64> {
    let a = nalgebra::Matrix3::from_fn(|r, c| m[r][c].as_f64().unwrap());
    let mut e: Vec<f64> = a.symmetric_eigenvalues().iter().copied().collect();
    e.sort_by(f64::total_cmp);
    e
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

/// Export `scene`, load it in both engines and compare with the report.
fn check_engines(scene: &Path, extra: &[&str]) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    export(scene, &out, extra);
    let report = read_json(&out.join("report.json"));
    let objects = report["objects"].as_array().unwrap();
    let outs = out.to_str().unwrap();

    let mj = python_json("check_mujoco.py", &[outs]);
    assert_eq!(
        mj["nbody"].as_u64().unwrap() as usize,
        objects.len() + 1,
        "{}",
        scene.display()
    );
    assert_eq!(
        mj["include_nbody"], mj["nbody"],
        "objects included together"
    );
    assert_eq!(
        mj["finite"],
        true,
        "MuJoCo state finite for {}",
        scene.display()
    );
    for o in objects {
        let name = o["name"].as_str().unwrap();
        let b = &mj["bodies"][name];
        assert_eq!(b["collision_geoms"], o["hull_count"], "{name}");
        assert!(b["visual_geoms"].as_u64().unwrap() >= 1, "{name}");
        assert_eq!(b["free"], !o["fixed"].as_bool().unwrap(), "{name}");
        let mass = o["mass"].as_f64().unwrap();
        assert!(
            rel(b["mass"].as_f64().unwrap(), mass) < 1e-6,
            "{name}: MuJoCo mass {} vs report {mass}",
            b["mass"]
        );
        assert!(rel(mj["objects"][name]["mass"].as_f64().unwrap(), mass) < 1e-6);
        // Sliding, torsional and rolling friction (docs/export.md, Contacts): with condim 3
        // MuJoCo ignores the torsional coefficient the geoms carry, and a leaning item spins on
        // its contact; condim 6 when the settle test assumed a rolling friction.
        let condim = if interact3d::physics::SettleOptions::default().rolling_friction > 0.0 {
            6
        } else {
            4
        };
        if o["hull_count"].as_u64().unwrap() > 0 {
            for got in [
                &b["collision_condim"],
                &mj["objects"][name]["collision_condim"],
            ] {
                assert_eq!(
                    got,
                    &serde_json::json!([condim]),
                    "{name}: collision geoms' condim"
                );
            }
        }
        let mut principal: Vec<f64> = b["inertia_principal"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        principal.sort_by(f64::total_cmp);
        for (p, e) in principal.iter().zip(eigen_sorted(&o["inertia"])) {
            assert!(
                rel(*p, e) < 1e-5,
                "{name}: MuJoCo principal inertia {p} vs report {e}"
            );
        }
    }

    // Every URDF parses with urdf-rs and, where installed (CI installs it), ROS's check_urdf.
    let have_check_urdf = std::process::Command::new("check_urdf")
        .arg("--help")
        .output()
        .is_ok();
    assert!(
        have_check_urdf || std::env::var("CI").is_err(),
        "CI must have check_urdf (liburdfdom-tools)"
    );
    for o in objects {
        let urdf = out.join(format!("{}.urdf", o["name"].as_str().unwrap()));
        let robot = urdf_rs::read_file(&urdf).unwrap_or_else(|e| panic!("{}: {e}", urdf.display()));
        assert_eq!(robot.links.len(), 1);
        assert_eq!(
            robot.links[0].collision.len() as u64,
            o["hull_count"].as_u64().unwrap()
        );
        assert!(
            rel(
                robot.links[0].inertial.mass.value,
                o["mass"].as_f64().unwrap()
            ) < 1e-6
        );
        if have_check_urdf {
            let r = std::process::Command::new("check_urdf")
                .arg(&urdf)
                .output()
                .unwrap();
            assert!(
                r.status.success()
                    && String::from_utf8_lossy(&r.stdout).contains("Successfully Parsed"),
                "check_urdf {}",
                urdf.display()
            );
        }
    }

    let pb = python_json("check_pybullet.py", &[outs]);
    assert_eq!(
        pb["finite"],
        true,
        "PyBullet state finite for {}",
        scene.display()
    );
    for o in objects {
        let name = o["name"].as_str().unwrap();
        let b = &pb["bodies"][name];
        if !o["fixed"].as_bool().unwrap() {
            assert!(
                rel(b["mass"].as_f64().unwrap(), o["mass"].as_f64().unwrap()) < 1e-6,
                "{name}: PyBullet mass"
            );
        }
        assert_eq!(
            b["collision_shapes"], o["hull_count"],
            "{name}: PyBullet collision shapes"
        );
    }
}

#[test]
fn fixtures_load_in_mujoco_and_pybullet() {
    if !python_or_skip("interop::fixtures_load_in_mujoco_and_pybullet") {
        return;
    }
    let fx = fixtures();
    assert!(fx.len() >= 4, "fixtures/ must hold the generated scenes");
    for f in fx {
        check_engines(&f, &[]);
    }
}

#[test]
fn shared_scenes_load_in_mujoco_and_pybullet() {
    const TEST: &str = "interop::shared_scenes_load_in_mujoco_and_pybullet";
    if shared_or_skip(TEST, "datasets/scenes").is_none() || !python_or_skip(TEST) {
        return;
    }
    let scenes = shared_scenes();
    assert!(scenes.len() >= 10);
    for s in scenes {
        check_engines(&s, &[]);
    }
}

#[test]
fn real_scans_load_in_mujoco_and_pybullet() {
    const TEST: &str = "interop::real_scans_load_in_mujoco_and_pybullet";
    let Some(base) = shared_or_skip(TEST, "datasets/objects") else {
        return;
    };
    if !python_or_skip(TEST) {
        return;
    }
    for (mesh, extra) in [
        ("gso/Room_Essentials_Mug_White_Yellow/model.obj", &[][..]),
        ("gso/Threshold_Porcelain_Teapot_White/model.obj", &[]),
        ("ycb/024_bowl/textured.obj", &[]),
        ("ycb/005_tomato_soup_can/textured.obj", &[]),
        ("khronos_gltf/Avocado/Avocado.glb", &[]),
        ("khronos_gltf/WaterBottle/WaterBottle.gltf", &[]),
        (
            "pybullet_data/tray/tray_textured4.obj",
            &["--size", "tray_textured4=0.615"],
        ),
    ] {
        check_engines(&base.join(mesh), extra);
    }
}

/// A JSON array of numbers.
fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// A quaternion from four JSON numbers in the order given (`wxyz` true: scalar first).
fn quat(v: &serde_json::Value, wxyz: bool) -> nalgebra::UnitQuaternion<f64> {
    let a = numbers(v);
    let q = if wxyz {
        nalgebra::Quaternion::new(a[0], a[1], a[2], a[3])
    } else {
        nalgebra::Quaternion::new(a[3], a[0], a[1], a[2])
    };
    nalgebra::UnitQuaternion::from_quaternion(q)
}

fn vec3(v: &serde_json::Value) -> nalgebra::Vector3<f64> {
    let a = numbers(v);
    nalgebra::Vector3::new(a[0], a[1], a[2])
}

/// docs/viewing.md's PyBullet recipe (each URDF loaded at scene.json's `translation` and
/// `quaternion_xyzw`, passed as they are) puts every body exactly where MuJoCo puts it from
/// scene.xml; the pose comment in each URDF says the same pose (its rpy too, by URDF's
/// fixed-axis convention); scene.json's two quaternion orders are the same rotation. Settled
/// poses, so the rotations are not all the identity. Reading wxyz as xyzw would be off by far
/// more than the tolerance (checked too, so the comparison can fail). PyBullet's link frame is
/// compared (its base pose is at the inertia's principal axes; check_view.py undoes that).
#[test]
fn viewing_recipes_place_every_body_where_mujoco_does() {
    if !python_or_skip("interop::viewing_recipes_place_every_body_where_mujoco_does") {
        return;
    }
    let (mut worst_pos, mut worst_angle, mut bodies) = (0.0f64, 0.0f64, 0);
    for fixture in ["ball_bowl", "pen_mug", "fruit_basket"] {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("out");
        export(&root().join("fixtures").join(fixture), &out, &[]);
        let view = python_json("check_view.py", &[out.to_str().unwrap()]);
        for (name, v) in view.as_object().unwrap() {
            bodies += 1;
            let mj_pos = vec3(&v["mujoco"]["xpos"]);
            let mj_q = quat(&v["mujoco"]["xquat_wxyz"], true);
            let pb_pos = vec3(&v["pybullet"]["position"]);
            let pb_q = quat(&v["pybullet"]["orientation_xyzw"], false);
            worst_pos = worst_pos.max((mj_pos - pb_pos).norm());
            worst_angle = worst_angle.max(mj_q.angle_to(&pb_q));
            // The wrong order is detected: scene.json's wxyz read as xyzw.
            let wrong = quat(&v["scene_json"]["quaternion_wxyz"], false);
            assert!(
                mj_q.angle_to(&wrong) > 0.1,
                "{fixture}/{name}: the order test cannot fail"
            );
            // scene.json: both orders the same rotation, the same as MuJoCo's.
            let sj_wxyz = quat(&v["scene_json"]["quaternion_wxyz"], true);
            let sj_xyzw = quat(&v["scene_json"]["quaternion_xyzw"], false);
            assert!(sj_wxyz.angle_to(&sj_xyzw) < 1e-12, "{fixture}/{name}");
            assert!(sj_wxyz.angle_to(&mj_q) < 1e-8, "{fixture}/{name}");
            // The URDF's comment: the same pose, rpy included.
            let c = &v["urdf_comment"];
            assert!(
                c.is_object(),
                "{fixture}/{name}: no pose comment in the URDF"
            );
            assert!(
                (vec3(&c["xyz"]) - mj_pos).norm() < 1e-8,
                "{fixture}/{name}: {c}"
            );
            assert!(
                quat(&c["quaternion_xyzw"], false).angle_to(&mj_q) < 1e-8,
                "{fixture}/{name}: {c}"
            );
            let rpy = vec3(&c["rpy"]);
            let from_rpy = nalgebra::UnitQuaternion::from_euler_angles(rpy.x, rpy.y, rpy.z);
            assert!(from_rpy.angle_to(&mj_q) < 1e-8, "{fixture}/{name}: {c}");
        }
    }
    eprintln!(
        "{bodies} bodies: PyBullet vs MuJoCo worst position {worst_pos:.2e} m, worst angle {worst_angle:.2e} rad"
    );
    assert!(bodies >= 8);
    // PyBullet's own round trip through the inertia's principal axes (it diagonalises the
    // tensor iteratively) costs ~1e-7 rad; the wrong quaternion order is 0.1 rad and more off.
    assert!(worst_pos < 1e-7, "{worst_pos}");
    assert!(worst_angle < 1e-5, "{worst_angle}");
}
