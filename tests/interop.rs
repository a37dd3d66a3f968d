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
        // Sliding and torsional friction (README, Contacts): with condim 3 MuJoCo ignores the
        // torsional coefficient the geoms carry, and a leaning item spins on its contact.
        if o["hull_count"].as_u64().unwrap() > 0 {
            for condim in [
                &b["collision_condim"],
                &mj["objects"][name]["collision_condim"],
            ] {
                assert_eq!(
                    condim,
                    &serde_json::json!([4]),
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
