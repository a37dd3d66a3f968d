//! Our own exports read back, the CI outputs (JSON, JUnit, SARIF, annotations) and exit
//! codes, and `--changed-since`.

use super::*;

#[test]
fn our_export_reads_back_as_the_same_bodies() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out");
    export(&root().join("fixtures/ball_bowl"), &out, &["--no-validate"]);
    let folder = interact3d::export::read::load(&out, &Default::default()).unwrap();
    let mj = interact3d::io::asset::load(&out.join("scene.xml"), &Default::default()).unwrap();
    assert_eq!(mj.bodies.len(), folder.bodies.len());
    assert!(mj.floor.is_some());
    for fb in &folder.bodies {
        let b = mj.bodies.iter().find(|b| b.name == fb.name).unwrap();
        let urdf = interact3d::io::asset::load(
            &out.join(format!("{}.urdf", fb.name)),
            &Default::default(),
        )
        .unwrap();
        let ub = &urdf.bodies[0];
        let i = b.inertial.as_ref().unwrap();
        let ui = ub.inertial.as_ref().unwrap();
        for x in [i, ui] {
            assert!(
                (x.mass - fb.inertial.mass).abs() / fb.inertial.mass < 1e-9,
                "{}",
                fb.name
            );
            assert!(
                (x.inertia - fb.inertial.inertia).norm() / fb.inertial.inertia.norm() < 1e-8,
                "{}",
                fb.name
            );
        }
        // Same pose (the MJCF's; the URDF is placed by scene.json).
        assert!((b.pose.translation.vector - fb.pose.translation.vector).norm() < 1e-9);
        // The same hulls: count and volume.
        for hulls in [b.hulls(), ub.hulls()] {
            assert_eq!(hulls.len(), fb.hulls.len(), "{}", fb.name);
            let v: f64 = hulls.iter().map(|h| h.volume).sum();
            let w: f64 = fb.hulls.iter().map(|h| h.volume).sum();
            assert!((v - w).abs() / w < 1e-6, "{}: {v} vs {w}", fb.name);
        }
    }
}

#[test]
fn cli_outputs_and_exit_codes() {
    let t = tempfile::tempdir().unwrap();
    let d = pybullet_data();
    let duck = d.join("duck_vhacd.urdf");
    let duck = duck.to_str().unwrap();
    let bad = write(t.path(), "bad.urdf", "<robot><link name=\"a\">\n</robot>\n");
    let sarif = t.path().join("out.sarif");
    let junit = t.path().join("out.xml");
    let (code, out, err) = run(&[
        "validate",
        duck,
        bad.to_str().unwrap(),
        "--json",
        "--sarif",
        sarif.to_str().unwrap(),
        "--junit",
        junit.to_str().unwrap(),
        "--no-physics",
    ]);
    // The unreadable file is an error finding among readable assets: exit 1, not 2.
    assert_eq!(code, 1, "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["assets"].as_array().unwrap().len(), 2);
    let f = &j["assets"][0]["findings"][0];
    for k in [
        "check", "severity", "subject", "file", "line", "message", "value", "limit",
    ] {
        assert!(f.get(k).is_some(), "{k} missing in {f}");
    }
    assert_eq!(j["assets"][1]["findings"][0]["check"], "file.parse_error");
    assert_eq!(
        j["assets"][1]["findings"][0]["line"], 2,
        "the mismatched end tag"
    );
    let s: serde_json::Value = serde_json::from_slice(&std::fs::read(&sarif).unwrap()).unwrap();
    assert_eq!(s["version"], "2.1.0");
    let rules = s["runs"][0]["tool"]["driver"]["rules"].as_array().unwrap();
    assert_eq!(rules.len(), interact3d::validate::finding::CHECKS.len());
    for r in s["runs"][0]["results"].as_array().unwrap() {
        let idx = r["ruleIndex"].as_u64().unwrap() as usize;
        assert_eq!(rules[idx]["id"], r["ruleId"]);
        assert!(
            r["locations"][0]["physicalLocation"]["region"]["startLine"]
                .as_u64()
                .unwrap()
                >= 1
        );
    }
    let x = std::fs::read_to_string(&junit).unwrap();
    let cases = x.matches("<testcase").count();
    let expected: usize = j["assets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["checks"].as_array().unwrap().len())
        .sum();
    assert_eq!(cases, expected);
    // Only warnings on the duck: exit 0 at the default --fail-on error, 1 at warning.
    assert_eq!(run(&["validate", duck, "--no-physics"]).0, 0);
    let (code, out, _) = run(&[
        "validate",
        duck,
        "--no-physics",
        "--fail-on",
        "warning",
        "--github",
    ]);
    assert_eq!(code, 1);
    assert!(
        out.lines().any(|l| l.starts_with("::warning file=")
            && l.contains(",line=10,")
            && l.contains("inertia.placeholder")),
        "{out}"
    );
    // A baseline of today's findings passes tomorrow's run.
    let base = t.path().join("base.json");
    assert_eq!(
        run(&[
            "validate",
            duck,
            "--no-physics",
            "--write-baseline",
            base.to_str().unwrap()
        ])
        .0,
        0
    );
    assert_eq!(
        run(&[
            "validate",
            duck,
            "--no-physics",
            "--fail-on",
            "warning",
            "--baseline",
            base.to_str().unwrap()
        ])
        .0,
        0
    );
    // Nothing readable: 2. Nothing there: 2.
    assert_eq!(run(&["validate", bad.to_str().unwrap()]).0, 2);
    assert_eq!(
        run(&["validate", t.path().join("none.urdf").to_str().unwrap()]).0,
        2
    );
    // A folder and a glob find the same files; the same run gives the same bytes.
    let glob = format!("{}/*_vhacd.urdf", d.display());
    let (c1, o1, _) = run(&["validate", &glob, "--json", "--no-physics"]);
    let (c2, o2, _) = run(&["validate", &glob, "--json", "--no-physics"]);
    assert_eq!((c1, &o1), (c2, &o2));
    let j: serde_json::Value = serde_json::from_str(&o1).unwrap();
    assert!(j["assets"].as_array().unwrap().len() >= 2);
}

#[test]
fn changed_since_checks_only_assets_whose_file_or_mesh_changed() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path();
    let git = |args: &[&str]| {
        let o = std::process::Command::new("git")
            .arg("-C")
            .arg(d)
            .args(args)
            .output()
            .expect("git");
        assert!(
            o.status.success(),
            "git {args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    };
    let commit = |msg: &str| {
        git(&[
            "-c",
            "user.name=t",
            "-c",
            "user.email=t@t",
            "commit",
            "-qm",
            msg,
        ])
    };
    let cube = |s: f64| box_obj([s; 3]);
    for n in ["a", "b", "c"] {
        write(d, &format!("{n}.obj"), &cube(0.03));
        write(
            d,
            &format!("{n}.urdf"),
            &urdf(
                &inertial(0.2, box_inertia(0.2, [0.06; 3]), [0.0; 3]),
                &format!("<mesh filename=\"{n}.obj\"/>"),
                &format!("<mesh filename=\"{n}.obj\"/>"),
            ),
        );
    }
    git(&["init", "-q"]);
    git(&["add", "."]);
    commit("assets");
    // b's mesh changes (uncommitted), c's URDF is untouched, d is new and untracked.
    write(d, "b.obj", &cube(0.031));
    write(
        d,
        "d.urdf",
        &std::fs::read_to_string(d.join("a.urdf")).unwrap(),
    );
    let dir = d.to_str().unwrap();
    let (code, out, err) = run(&[
        "validate",
        dir,
        "--changed-since",
        "HEAD",
        "--json",
        "--no-physics",
    ]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    let files: Vec<String> = j["assets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| {
            Path::new(a["file"].as_str().unwrap())
                .file_name()
                .unwrap()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    assert_eq!(files, vec!["b.urdf", "d.urdf"], "{err}");
    // Nothing changed since the working tree: nothing to check, exit 0; a bad revision: 2.
    git(&["add", "."]);
    commit("more");
    let (code, out, _) = run(&["validate", dir, "--changed-since", "HEAD", "--json"]);
    assert_eq!(code, 0);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["assets"].as_array().unwrap().len(), 0);
    assert_eq!(
        run(&["validate", dir, "--changed-since", "no-such-ref"]).0,
        2
    );
}
