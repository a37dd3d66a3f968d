//! `compose --agent CMD`: the agentic loop driven by scripted commands. The sample is the
//! ball-in-bowl fixture with the ball's guidance part sunk a quarter of its diagonal into the
//! bowl's floor (so the composition penetrates far above 1 %); the "fix" is the true guidance.
//! Composition runs without the collision-aware refinement (`--method global-icp`) so the
//! penetration is the guidance's, not repaired behind the loop's back.

mod common;

use common::{root, run};
use interact3d::compose::synth;
use serde_json::Value;
use std::path::{Path, PathBuf};

struct Setup {
    _tmp: tempfile::TempDir,
    dir: PathBuf,
    sample: PathBuf,
    good: PathBuf,
    bad: PathBuf,
}

fn setup() -> Setup {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().canonicalize().unwrap();
    let src = root().join("fixtures/ball_bowl");
    let truth = synth::load_truth(&src).unwrap();
    let s = synth::make(&truth, 1, &synth::SynthOptions::default());
    let good_dir = dir.join("good");
    synth::write_sample(&s, Some(&src), &good_dir).unwrap();
    // Sink the ball's guidance towards the bowl's centre by a quarter of its diagonal.
    let mut bad = s;
    let bb = |v: &interact3d::mesh::VisualMesh| v.geometry().aabb().unwrap();
    let (ia, ib) = (0, 1);
    assert_eq!(bad.inputs[ib].name, "object_b");
    let (ba, bb_) = (bb(&bad.inputs[ia].guidance), bb(&bad.inputs[ib].guidance));
    let dir_v = (ba.center() - bb_.center()).normalize() * (0.25 * bb_.diagonal());
    bad.inputs[ib]
        .guidance
        .transform(&nalgebra::Translation3::from(dir_v).to_homogeneous());
    let sample = dir.join("sample");
    synth::write_sample(&bad, Some(&src), &sample).unwrap();
    std::fs::copy(src.join("metadata.json"), sample.join("metadata.json")).unwrap();
    let good = dir.join("fix_guidance_object_b.glb");
    std::fs::copy(good_dir.join("guidance_object_b.glb"), &good).unwrap();
    let badf = dir.join("bad_guidance_object_b.glb");
    std::fs::copy(sample.join("guidance_object_b.glb"), &badf).unwrap();
    Setup {
        _tmp: tmp,
        dir,
        sample,
        good,
        bad: badf,
    }
}

fn listing(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

/// A script that answers `answer(n)` on its n-th call and keeps each stdin it got.
fn script(s: &Setup, body: &str) -> String {
    let path = s.dir.join("agent.sh");
    std::fs::write(
        &path,
        format!(
            "#!/bin/sh\nD={d}\nn=$(cat $D/count 2>/dev/null || echo 0); n=$((n+1)); echo $n > $D/count\ncat > $D/stdin_$n.json\n{body}\n",
            d = s.dir.display()
        ),
    )
    .unwrap();
    format!("sh {}", path.display())
}

fn compose(s: &Setup, out: &Path, cmd: &str, max: &str) -> (i32, String) {
    let (code, _, err) = run(&[
        "compose",
        s.sample.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--method",
        "global-icp",
        "--agent",
        cmd,
        "--max-iterations",
        max,
    ]);
    (code, err)
}

fn metadata(out: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(out.join("metadata.json")).unwrap()).unwrap()
}

#[test]
fn fixed_on_the_second_try() {
    let s = setup();
    let before = listing(&s.sample);
    let cmd = script(
        &s,
        &format!(
            "if [ $n -ge 2 ]; then f={}; else f={}; fi\necho '{{\"replace\": {{\"object_b\": {{\"guidance\": \"'$f'\"}}}}, \"note\": \"try '$n'\"}}'",
            s.good.display(),
            s.bad.display()
        ),
    );
    let out = s.dir.join("out");
    let (code, err) = compose(&s, &out, &cmd, "5");
    assert_eq!(code, 0, "{err}");
    assert_eq!(listing(&s.sample), before, "the input sample was modified");
    let rec = &metadata(&out)["agent_optimization"];
    assert_eq!(rec["iterations"], 2, "{rec}");
    assert_eq!(rec["success"], true);
    assert_eq!(rec["stop_reason"], "success");
    let a = rec["attempts"].as_array().unwrap();
    // The first attempt changed nothing (same sunk guidance): still far above 1 %; the second
    // brought the true guidance back: at most 1 %.
    let before0 = a[0]["penetration_ratio_before"].as_f64().unwrap();
    assert!(before0 > 0.05, "the sunk ball should penetrate: {before0}");
    assert!(a[0]["penetration_ratio_after"].as_f64().unwrap() > 0.01);
    assert!(a[1]["penetration_ratio_after"].as_f64().unwrap() <= 0.01);
    assert_eq!(a[1]["note"], "try 2");
    // What the command was given: prompt and category from metadata.json, renders that exist,
    // the collision report, and the earlier attempt on the second call.
    let meta_in: Value =
        serde_json::from_slice(&std::fs::read(s.sample.join("metadata.json")).unwrap()).unwrap();
    let first: Value =
        serde_json::from_slice(&std::fs::read(s.dir.join("stdin_1.json")).unwrap()).unwrap();
    let prompt = meta_in
        .get("prompt")
        .or_else(|| meta_in["input"].get("scene_prompt"));
    assert_eq!(first.get("prompt"), prompt);
    assert!(
        first["collision_report"]["penetration_ratio"]
            .as_f64()
            .unwrap()
            > 0.05
    );
    let views = first["renders"]["views"].as_array().unwrap();
    assert_eq!(views.len(), 6);
    assert!(!first["renders"]["sections"].as_array().unwrap().is_empty());
    assert_eq!(first["attempts"].as_array().unwrap().len(), 0);
    let second: Value =
        serde_json::from_slice(&std::fs::read(s.dir.join("stdin_2.json")).unwrap()).unwrap();
    assert_eq!(second["attempts"].as_array().unwrap().len(), 1);
    // Records in OUT: the renders the command saw, its output, the metrics that followed.
    for f in [
        "agent/iter_01/stdin.json",
        "agent/iter_01/stdout.txt",
        "agent/iter_01/metrics.json",
        "agent/iter_01/render/views/front.png",
        "agent/iter_02/files/new_guidance_object_b.glb",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    assert_eq!(
        std::fs::read(out.join("agent/iter_02/files/new_guidance_object_b.glb")).unwrap(),
        std::fs::read(&s.good).unwrap()
    );
}

#[test]
fn never_fixed_stops_at_the_limit() {
    let s = setup();
    let cmd = script(
        &s,
        &format!(
            "echo '{{\"replace\": {{\"object_b\": {{\"guidance\": \"{}\"}}}}}}'",
            s.bad.display()
        ),
    );
    let out = s.dir.join("out");
    let (code, err) = compose(&s, &out, &cmd, "2");
    assert_eq!(code, 1, "{err}");
    let rec = &metadata(&out)["agent_optimization"];
    assert_eq!(rec["iterations"], 2);
    assert_eq!(rec["success"], false);
    assert_eq!(rec["stop_reason"], "max_iterations");
    assert!(rec["final_penetration_ratio"].as_f64().unwrap() > 0.01);
    assert!(out.join("agent/iter_02/metrics.json").is_file());
    assert!(!out.join("agent/iter_03").exists());
}

#[test]
fn failing_or_garbage_commands_are_clear_errors_and_lose_nothing() {
    for (body, expect) in [
        ("echo 'this is not json'", "not a JSON object"),
        ("echo oops >&2; exit 3", "failed"),
        (
            "echo '{\"replace\": {\"object_z\": {\"object\": \"x.glb\"}}}'",
            "unknown object",
        ),
    ] {
        let s = setup();
        let before = listing(&s.sample);
        let out = s.dir.join("out");
        let (code, err) = compose(&s, &out, &script(&s, body), "5");
        assert_eq!(code, 2, "{body}: {err}");
        assert!(
            err.contains("iteration 1") && err.contains(expect),
            "{body}: {err}"
        );
        assert!(
            err.contains("agent/iter_01"),
            "the error names the records: {err}"
        );
        assert_eq!(listing(&s.sample), before);
        // OUT holds the composition and every record.
        let meta = metadata(&out);
        assert!(meta["registration"]["transforms"]["object_b"].is_object());
        let rec = &meta["agent_optimization"];
        assert_eq!(rec["stop_reason"], "agent_error");
        assert!(rec["error"].as_str().unwrap().contains(expect));
        assert!(out.join("agent/iter_01/stdin.json").is_file());
        assert!(out.join("agent/iter_01/stdout.txt").is_file());
        assert!(out.join("scene.json").is_file());
    }
}
