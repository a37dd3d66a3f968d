//! The validation verdict means something: it agrees with MuJoCo and PyBullet on every fixture,
//! the must-fail fixtures fail for the right reason, and the outputs (exit code, JSON, JUnit) are
//! what CI systems expect.

mod common;
use common::*;
use std::path::Path;

const MM: f64 = 1e-3;

struct Outcome {
    code: i32,
    report: serde_json::Value,
    out: tempfile::TempDir,
}

fn export_validated(scene: &Path) -> Outcome {
    export_validated_with(scene, &[])
}

/// [`export_validated`] with more `export` arguments.
fn export_validated_with(scene: &Path, args: &[&str]) -> Outcome {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("out");
    let mut all = vec![
        "export",
        scene.to_str().unwrap(),
        "-o",
        dir.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    let (code, _, err) = run(&all);
    assert!(code == 0 || code == 1, "export {}: {err}", scene.display());
    let report = read_json(&dir.join("report.json"));
    assert_eq!(
        report["validation"]["passed"].as_bool().unwrap(),
        code == 0,
        "exit code follows the verdict"
    );
    Outcome { code, report, out }
}

/// Objects Rapier failed dynamically (a failed settle or rest check names them).
fn rapier_failed(report: &serde_json::Value) -> Vec<String> {
    let mut v: Vec<String> = report["validation"]["checks"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| {
            !c["passed"].as_bool().unwrap() && (c["name"] == "settle" || c["name"] == "rest")
        })
        .flat_map(|c| {
            c["subject"]
                .as_str()
                .unwrap()
                .split('/')
                .map(str::to_string)
                .collect::<Vec<_>>()
        })
        .collect();
    v.sort();
    v.dedup();
    v
}

/// Objects an engine flags: moved > 1 mm or turned > 1° in 1 s.
fn engine_flagged(result: &serde_json::Value) -> Vec<String> {
    moved_beyond(&result["motion"], MM, 1.0)
}

/// Objects PyBullet flags: moved > 1 mm or turned > 1° in 1 s once at its own rest, or, while
/// coming to that rest, moved > 5 mm or turned > 5° (more than its collision margins lift a
/// body: a topple or a slide).
fn pybullet_flagged(result: &serde_json::Value) -> Vec<String> {
    let mut v = engine_flagged(result);
    v.extend(moved_beyond(&result["warmup_motion"], 5.0 * MM, 5.0));
    v.sort();
    v.dedup();
    v
}

fn moved_beyond(motion: &serde_json::Value, metres: f64, degrees: f64) -> Vec<String> {
    let mut v: Vec<String> = motion
        .as_object()
        .unwrap()
        .iter()
        .filter(|(_, m)| {
            m["moved_m"].as_f64().unwrap() > metres || m["turned_deg"].as_f64().unwrap() > degrees
        })
        .map(|(k, _)| k.clone())
        .collect();
    v.sort();
    v
}

#[test]
fn mujoco_and_pybullet_agree_with_the_rapier_verdict_on_every_fixture() {
    if !python_or_skip(
        "validate::mujoco_and_pybullet_agree_with_the_rapier_verdict_on_every_fixture",
    ) {
        return;
    }
    for scene in fixtures() {
        let o = export_validated(&scene);
        let dir = o.out.path().join("out");
        let mj = python_json("check_mujoco.py", &[dir.to_str().unwrap()]);
        let pb = python_json("check_pybullet.py", &[dir.to_str().unwrap()]);
        let name = scene.file_name().unwrap().to_string_lossy().to_string();
        // fixtures/README.md: the fail_* scenes are built to fail, every other one to pass.
        assert_eq!(
            o.code == 0,
            !name.starts_with("fail_"),
            "{name}: exit {} against its designed outcome: {}",
            o.code,
            o.report["validation"]["checks"]
        );
        let failed = rapier_failed(&o.report);
        if failed.is_empty() {
            // Dynamic pass: nothing moves and nothing overlaps in the other engines either.
            assert!(
                engine_flagged(&mj).is_empty(),
                "{name}: Rapier passed but MuJoCo moved {:?}: {}",
                engine_flagged(&mj),
                mj["motion"]
            );
            assert!(
                mj["initial_penetration"].as_f64().unwrap() <= MM,
                "{name}: MuJoCo initial penetration {}",
                mj["initial_penetration"]
            );
            assert!(
                pybullet_flagged(&pb).is_empty(),
                "{name}: Rapier passed but PyBullet moved {:?}: {} (warm-up {})",
                pybullet_flagged(&pb),
                pb["motion"],
                pb["warmup_motion"]
            );
        } else {
            // Fail: every object Rapier flags, MuJoCo flags too (moves, or starts overlapping).
            let mut mj_flags = engine_flagged(&mj);
            if mj["initial_penetration"].as_f64().unwrap() > MM {
                mj_flags.extend(
                    mj["initial_penetration_pair"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .map(|x| x.as_str().unwrap().to_string()),
                );
            }
            let pb_flags = pybullet_flagged(&pb);
            let some_flag = failed.iter().any(|f| mj_flags.contains(f));
            assert!(
                some_flag,
                "{name}: Rapier failed {failed:?}, MuJoCo flagged {mj_flags:?}"
            );
            let moved_in_rapier: Vec<&String> = failed
                .iter()
                .filter(|f| {
                    o.report["validation"]["checks"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .any(|c| {
                            c["subject"] == f.as_str()
                                && c["name"] == "settle"
                                && !c["passed"].as_bool().unwrap()
                                && c["message"].as_str().unwrap().contains("drifted")
                        })
                })
                .collect();
            for f in moved_in_rapier {
                assert!(
                    mj_flags.contains(f),
                    "{name}: Rapier saw {f} drift, MuJoCo did not: {}",
                    mj["motion"]
                );
                assert!(
                    pb_flags.contains(f),
                    "{name}: Rapier saw {f} drift, PyBullet did not: {}",
                    pb["motion"]
                );
            }
        }
    }
}

#[test]
fn interpenetrating_fixture_fails_on_the_measured_depth() {
    let o = export_validated(&root().join("fixtures/fail_interpenetrating"));
    assert_eq!(o.code, 1);
    // The top box is sunk 3 mm into the base (fixtures/fail_interpenetrating/README.md): the
    // meshes say so; the scene-aware hulls are cut apart, so they overlap by at most 0.1 mm.
    let checks = o.report["validation"]["checks"].as_array().unwrap();
    let c = checks
        .iter()
        .find(|c| c["name"] == "visual_penetration")
        .unwrap()
        .clone();
    assert_eq!(c["passed"], false);
    assert!((c["value"].as_f64().unwrap() - 0.003).abs() < 1e-4, "{c}");
    let h = checks
        .iter()
        .find(|c| c["name"] == "static_penetration")
        .unwrap();
    assert!(h["value"].as_f64().unwrap() <= 1e-4, "hulls cut apart: {h}");
    let pair = &o.report["validation"]["pairs"][0];
    assert!(
        (pair["visual"]["max_penetration_depth"].as_f64().unwrap() - 0.003).abs() < 1e-4,
        "{pair}"
    );
    assert!(pair["visual"]["r_volume"].as_f64().unwrap() > 0.0);
    // Bodies start where they were composed when the scene fails.
    let scene = read_json(&o.out.path().join("out/scene.json"));
    assert!(scene["objects"][0].get("composed_pose").is_none());
}

#[test]
fn unstable_fixture_fails_by_toppling() {
    let o = export_validated(&root().join("fixtures/fail_unstable"));
    assert_eq!(o.code, 1);
    let b = &o.report["validation"]["settle"]["bodies"][0];
    assert!(b["settle_rotation_deg"].as_f64().unwrap() > 30.0, "{b}");
    assert_eq!(b["passed"], false);
}

/// At 64 hulls Rapier rolls the pen of the pen-in-mug fixture 30.3° about its own axis while it
/// settles against the rim, past the 30° limit. That turn leaves the pen's shape where it was
/// (a 16-sided prism: within 0.3 mm), so it is noted, not failed; MuJoCo keeps the pen there.
#[test]
fn pen_rolling_about_its_own_axis_in_the_mug_passes() {
    let o = export_validated_with(&root().join("fixtures/pen_mug"), &["--max-hulls", "64"]);
    assert_eq!(o.code, 0, "{}", o.report["validation"]["checks"]);
    let pen = &o.report["validation"]["settle"]["bodies"][1];
    assert_eq!(pen["name"], "pen");
    if pen["settle_rotation_deg"].as_f64().unwrap() > 30.0 {
        let shift = pen["settle_shape_shift"].as_f64().unwrap();
        assert!(shift < 0.3 * MM, "{pen}");
        let notes = pen["notes"].as_array().unwrap();
        assert!(notes
            .iter()
            .any(|n| n.as_str().unwrap().contains("not counted")));
    }
    if !python_or_skip("validate::pen_rolling_about_its_own_axis_in_the_mug_passes (MuJoCo part)") {
        return;
    }
    let dir = o.out.path().join("out");
    let mj = python_json(
        "check_mujoco.py",
        &[dir.to_str().unwrap(), "--seconds", "2"],
    );
    assert!(
        moved_beyond(&mj["motion"], 2.0 * MM, 5.0).is_empty(),
        "MuJoCo: {}",
        mj["motion"]
    );
}

#[test]
fn validate_command_json_junit_and_exit_codes() {
    let t = tempfile::tempdir().unwrap();
    let junit = t.path().join("junit.xml");
    let scene = root().join("fixtures/fail_interpenetrating");
    let (code, stdout, stderr) = run(&[
        "validate",
        scene.to_str().unwrap(),
        "--json",
        "--junit",
        junit.to_str().unwrap(),
        "--points",
        "100000",
    ]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("verdict: FAIL"));
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("JSON on stdout");
    assert_eq!(v["passed"], false);
    let p = &v["pairs"][0]["collision"];
    for k in [
        "r_volume",
        "r_surface",
        "max_penetration_depth",
        "min_clearance",
    ] {
        assert!(p[k].is_number(), "{k} in {p}");
    }
    let xml = std::fs::read_to_string(&junit).unwrap();
    assert!(
        xml.contains("<testsuite") && xml.contains("<failure"),
        "{xml}"
    );
    let cases = xml.matches("<testcase").count();
    assert_eq!(cases, v["checks"].as_array().unwrap().len());
    // Unreadable input: exit 2.
    let (code, _, err) = run(&["validate", t.path().join("nothing").to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
}

#[test]
fn export_folder_validates_from_its_settled_poses() {
    let o = export_validated(&root().join("fixtures/ball_bowl"));
    if o.code != 0 {
        panic!("ball_bowl must pass: {}", o.report["validation"]["checks"]);
    }
    let dir = o.out.path().join("out");
    let scene = read_json(&dir.join("scene.json"));
    assert!(
        scene["objects"][1].get("composed_pose").is_some(),
        "composed pose kept"
    );
    let xml = std::fs::read_to_string(dir.join("scene.xml")).unwrap();
    assert!(xml.contains(r#"<key name="composed""#) && xml.contains(r#"<key name="settled""#));
    let (code, stdout, err) = run(&[
        "validate",
        dir.to_str().unwrap(),
        "--json",
        "--points",
        "100000",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    for b in v["settle"]["bodies"].as_array().unwrap() {
        assert!(
            b["settle_displacement"].as_f64().unwrap() < 0.5 * MM,
            "already at rest: {b}"
        );
    }
}

/// Issue #4's analytic check: after export, the ball lies at the bottom of the bowl in MuJoCo.
/// Export `fixture`, check its verdict passes, run it 2 s in MuJoCo, assert MuJoCo finds no
/// initial contact between objects deeper than 0.1 mm, and return where each body ends.
fn rest_in_mujoco_after_2_s(fixture: &str) -> serde_json::Value {
    let o = export_validated(&root().join("fixtures").join(fixture));
    assert_eq!(o.code, 0, "{}", o.report["validation"]["checks"]);
    let dir = o.out.path().join("out");
    let mj = python_json(
        "check_mujoco.py",
        &[dir.to_str().unwrap(), "--seconds", "2"],
    );
    assert!(
        mj["initial_penetration"].as_f64().unwrap() <= 0.1 * MM,
        "{fixture}: {}",
        mj["initial_penetration"]
    );
    mj["final_pos"].clone()
}

/// Body `name`'s final position.
fn body_pos(pos: &serde_json::Value, name: &str) -> [f64; 3] {
    let p = &pos[name];
    [0, 1, 2].map(|k| p[k].as_f64().unwrap())
}

/// `what` ended within 1 mm of `expected`.
fn assert_within_1_mm(what: &str, got: [f64; 3], expected: [f64; 3]) {
    let err = (0..3)
        .map(|k| (got[k] - expected[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(
        err <= MM,
        "{what} at {got:?}, expected {expected:?}: {:.3} mm off",
        err / MM
    );
}

/// From the bowl fixture's construction (fixtures/ball_bowl/README.md): the ball's centre is on
/// the bowl's axis, its resting quad face on the flat inner floor, so its centre is
/// 36.684 mm above the bowl's foot (37.434 mm in the composed pose minus the 0.75 mm gap).
/// The bowl is symmetric about its axis, so its centre of mass lies on that axis.
#[test]
fn ball_rests_at_the_bottom_of_the_bowl_in_mujoco_after_2_s() {
    if !python_or_skip("validate::ball_rests_at_the_bottom_of_the_bowl_in_mujoco_after_2_s") {
        return;
    }
    let pos = rest_in_mujoco_after_2_s("ball_bowl");
    let bowl = body_pos(&pos, "bowl");
    let expected = [bowl[0], bowl[1], 0.036684];
    assert_within_1_mm("ball", body_pos(&pos, "ball"), expected);
}

/// From the shelf fixture's construction (fixtures/shelf_item/README.md): the box stands on the
/// middle board, whose top face is at z = 300 mm, at (x, y) = (30, 10) mm; its centre rests
/// 50 mm above the board (350.75 mm in the composed pose minus the 0.75 mm gap). After 2 s in
/// MuJoCo the box must still be there, in the shelf.
#[test]
fn box_stays_on_the_middle_shelf_board_in_mujoco_after_2_s() {
    if !python_or_skip("validate::box_stays_on_the_middle_shelf_board_in_mujoco_after_2_s") {
        return;
    }
    let pos = rest_in_mujoco_after_2_s("shelf_item");
    assert_within_1_mm("box", body_pos(&pos, "box"), [0.030, 0.010, 0.350]);
}

/// Whole-object pieces (V-HACD's hulls, star pieces) are not taken where they would lift what a
/// neighbour stands on: with V-HACD's hulls for the lunch box of shared scene 00009 the bottle
/// standing on its lid slid 27.7 mm and turned 34° while settling in Rapier, and the scene
/// failed. It passes, with nothing moving more than the settle limits.
#[test]
fn bottle_standing_on_the_lunch_box_settles() {
    let Some(scene) = shared_or_skip(
        "validate::bottle_standing_on_the_lunch_box_settles",
        "datasets/scenes/household/00009_bottle_lunchbox",
    ) else {
        return;
    };
    let o = export_validated(&scene);
    assert_eq!(o.code, 0, "{}", o.report["validation"]["checks"]);
    assert!(rapier_failed(&o.report).is_empty());
}
