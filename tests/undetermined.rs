//! The undetermined gate through the binary: a scene whose verdict flips under the nudge
//! check's 0.5° turns is `undetermined` in `validate --json` and in `export`'s report.json, and
//! `--undetermined warn` / `fail` give the exit codes a CI gate relies on (0 with a warning / 1).
//!
//! The scene is built here, independently of the validator: a 5 cm cube leaning on one bottom
//! edge, written as our manifest (`scene.json` + an OBJ cube). Falling back onto its face, its
//! centre moves √2 s sin(θ/2); the settle rule allows 10 % of the bounding-box diagonal of the
//! hull *at the composed pose*, s √(2 (cos θ + sin θ)² + 1). The two meet at the critical angle
//! θ* (16.43°, solved below): below it the scene passes, above it fails, and at it the turn that
//! tilts the cube 0.5° further (one of the four) fails while the other three pass.

mod common;
use common::*;
use std::path::Path;

const SIDE: f64 = 0.05;

/// Writes the leaning cube at `theta` degrees into `dir` (manifest + OBJ), its low edge 0.5 mm
/// above the ground (z = 0), turned about +y so the edge x = s/2, z = -s/2 is the lowest.
fn leaning_cube_scene(dir: &Path, theta: f64) {
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    let h = SIDE / 2.0;
    std::fs::write(
        dir.join("meshes/cube.obj"),
        common::box_extents_obj([SIDE; 3]),
    )
    .unwrap();
    let t = theta.to_radians();
    // R_y(θ) (h, 0, -h): the low edge's centre.
    let (ex, ez) = (h * t.cos() - h * t.sin(), -h * t.sin() - h * t.cos());
    let scene = serde_json::json!({
        "format": "interact3d-scene",
        "version": 1,
        "name": "leaning_cube",
        "units": "m",
        "up_axis": "z",
        "objects": [{
            "name": "cube",
            "mesh": "meshes/cube.obj",
            "label": "cube",
            "pose": {
                "translation": [-ex, 0.0, -ez + 5e-4],
                "quaternion_wxyz": [(t / 2.0).cos(), 0.0, (t / 2.0).sin(), 0.0],
                "scale": 1.0
            },
            "density": 1000.0
        }]
    });
    std::fs::write(
        dir.join("scene.json"),
        serde_json::to_string_pretty(&scene).unwrap(),
    )
    .unwrap();
}

/// The analytic drift of the falling cube over its limit (10 % of the composed pose's
/// bounding-box diagonal).
fn drift_ratio(theta: f64) -> f64 {
    let t = theta.to_radians();
    let drift = 2f64.sqrt() * SIDE * (t / 2.0).sin();
    let diagonal = SIDE * (2.0 * (t.cos() + t.sin()).powi(2) + 1.0).sqrt();
    drift / (0.1 * diagonal)
}

/// θ* where the drift meets the limit (bisection; the ratio grows with θ on 0..30°).
fn critical_angle() -> f64 {
    let (mut lo, mut hi) = (0.0, 30.0);
    for _ in 0..60 {
        let m = 0.5 * (lo + hi);
        if drift_ratio(m) < 1.0 {
            lo = m
        } else {
            hi = m
        }
    }
    lo
}

const FAST: [&str; 4] = ["--points", "20000", "--no-visual-metrics", "--nudge-check"];

/// `validate DIR --json --undetermined POLICY`: (exit code, validation JSON, stderr).
fn validate(dir: &Path, policy: &str) -> (i32, serde_json::Value, String) {
    let mut args = vec![
        "validate",
        dir.to_str().unwrap(),
        "--json",
        "--undetermined",
        policy,
    ];
    args.extend_from_slice(&FAST);
    let (code, out, err) = run(&args);
    let v: serde_json::Value =
        serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}\n{err}"));
    (code, v, err)
}

#[test]
fn an_undetermined_scene_warns_or_fails_the_gate_through_the_binary() {
    let star = critical_angle();
    assert!((star - 16.43).abs() < 0.01, "θ* = {star}");
    let tmp = tempfile::tempdir().unwrap();
    let scene = |theta: f64| {
        let d = tmp.path().join(format!("cube_{theta:.3}"));
        leaning_cube_scene(&d, theta);
        d
    };

    // Far from θ*: determined under either policy (the signal fires: drift ≥ 30 % of the limit,
    // so the nudged starts do run, and agree).
    for (theta, pass) in [(star - 1.5, true), (star + 1.5, false)] {
        let d = scene(theta);
        for policy in ["warn", "fail"] {
            let (code, v, err) = validate(&d, policy);
            assert_eq!(code, if pass { 0 } else { 1 }, "{theta}° {policy}: {err}");
            let expected = if pass { "pass" } else { "fail" };
            assert_eq!(v["verdict"], expected, "{theta}° {policy}");
            assert_eq!(v["passed"], pass);
            if pass {
                let n = &v["nudge"];
                assert_eq!(
                    (n["runs"].as_u64(), n["passed"].as_u64()),
                    (Some(4), Some(4))
                );
            }
        }
    }

    // Near θ*: the scan finds the undetermined band, and only near θ*.
    let split: Vec<f64> = (-4..=4)
        .map(|k| star + 0.1 * k as f64)
        .filter(|&t| validate(&scene(t), "warn").1["verdict"] == "undetermined")
        .collect();
    assert!(
        !split.is_empty(),
        "no undetermined angle within ±0.4° of θ* = {star}"
    );
    let theta = split[0];
    assert!((theta - star).abs() <= 0.4);
    let d = scene(theta);

    // `validate`: warn exits 0 with a warning, fail exits 1; both say undetermined.
    let (code, v, err) = validate(&d, "warn");
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        (v["verdict"].as_str(), v["passed"].as_bool()),
        (Some("undetermined"), Some(true))
    );
    // Of the four turns (+x, -x, +y, -y) only +y, which tilts the cube further past θ*, fails.
    assert_eq!(
        v["nudge"]["verdicts"],
        serde_json::json!([true, true, false, true])
    );
    assert!(
        err.contains("warning: undetermined verdict: 3 of 4"),
        "{err}"
    );
    let (code, v, err) = validate(&d, "fail");
    assert_eq!(code, 1, "{err}");
    assert_eq!(
        (v["verdict"].as_str(), v["passed"].as_bool()),
        (Some("undetermined"), Some(false))
    );
    assert!(err.contains("failed (--undetermined fail)"), "{err}");

    // `export`: the same verdicts in report.json; warn ships the settled pose, fail the composed.
    let composed = read_json(&d.join("scene.json"))["objects"][0]["pose"]["translation"].clone();
    for (policy, code_expected) in [("warn", 0), ("fail", 1)] {
        let out = tmp.path().join(format!("out_{policy}"));
        let mut extra = vec!["--undetermined", policy];
        extra.extend_from_slice(&FAST);
        let (code, err) = export_logged(&d, &out, &extra);
        assert_eq!(code, code_expected, "export {policy}: {err}");
        let report = read_json(&out.join("report.json"));
        let val = &report["validation"];
        assert_eq!(val["verdict"], "undetermined", "{policy}");
        assert_eq!(val["passed"], code_expected == 0, "{policy}");
        assert_eq!(
            (
                val["nudge"]["runs"].as_u64(),
                val["nudge"]["passed"].as_u64()
            ),
            (Some(4), Some(3))
        );
        let warnings: Vec<&str> = val["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .map(|w| w.as_str().unwrap())
            .collect();
        assert!(
            warnings
                .iter()
                .any(|w| w.starts_with("undetermined verdict: 3 of 4")),
            "{warnings:?}"
        );
        let shipped = &read_json(&out.join("scene.json"))["objects"][0];
        if code_expected == 0 {
            // The settled pose: the cube lies on its face, centre s/2 above the ground.
            let z = shipped["pose"]["translation"][2].as_f64().unwrap();
            assert!((z - SIDE / 2.0).abs() < 1e-4, "settled z {z}");
        } else {
            // The composed pose (the mesh is shipped turned; the reader may set the low edge
            // on the ground, at most the 0.5 mm gap lower), not the settled one.
            let at = |k: usize| shipped["pose"]["translation"][k].as_f64().unwrap();
            let c = |k: usize| composed[k].as_f64().unwrap();
            assert!((at(0) - c(0)).abs() < 1e-12 && (at(1) - c(1)).abs() < 1e-12);
            assert!(
                (at(2) - c(2)).abs() <= 5.1e-4,
                "composed z {} shipped {}",
                c(2),
                at(2)
            );
        }
    }
}
