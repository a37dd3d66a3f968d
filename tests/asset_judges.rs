//! The engines' own verdict on the asset cases of tests/assets/: PyBullet on every URDF case
//! (loads or refuses, contact at the start, motion), MuJoCo on every MJCF case with a physics
//! verdict (motion), and the rest test: the half-cylinder rocker (fires) and its upright twin,
//! and the YCB URDFs whose placeholder inertia kept them rocking.
//! Needs Python with `pybullet` and `mujoco` (tests/python/requirements.txt).

#[path = "asset_cases/mod.rs"]
mod cases;
mod common;
use cases::*;
use common::*;
use interact3d::validate::finding::AssetReport;
use std::path::{Path, PathBuf};

/// PyBullet on a URDF placed as `validate` places it; the inertia from the file unless ours
/// found it a placeholder: ours then simulates the tensor the geometry implies, and PyBullet
/// gets the same moments (the diagonal in the link's axes; the pybullet_data and planted cases
/// have their inertial frame on the link's axes).
fn pybullet(p: &Path, r: &AssetReport) -> serde_json::Value {
    let (lift, _) = placement(p);
    let lift = lift.to_string();
    let mut args: Vec<String> = [p.to_str().unwrap(), "--lift", &lift, "--seconds", "4"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    if !find(r, "inertia.placeholder").is_empty() {
        let a = interact3d::io::asset::load(p, &Default::default()).unwrap();
        let b = &a.bodies[0];
        let mass = b.inertial.as_ref().unwrap().mass;
        let i = interact3d::io::asset::geometric_inertial(b)
            .unwrap()
            .with_mass(mass)
            .inertia;
        args.push("--inertia".into());
        args.extend((0..3).map(|k| i[(k, k)].to_string()));
    }
    if r.findings.iter().any(|f| f.check == "physics.skipped") && r.bodies > 0 {
        // Nothing to simulate (a static root, or an inertia MuJoCo refuses).
        args.push("--fixed".into());
    }
    let args: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
    python_json("check_asset_pybullet.py", &args)
}

/// Every URDF case: (file, whether ours has physics to compare).
fn urdf_cases(dir: &Path) -> Vec<PathBuf> {
    let d = pybullet_data();
    let mut v: Vec<PathBuf> = [
        "duck_vhacd.urdf",
        "teddy_vhacd.urdf",
        "cube_small.urdf",
        "sphere2.urdf",
        "tray/traybox.urdf",
    ]
    .iter()
    .map(|f| d.join(f))
    .collect();
    let e = [0.1, 0.06, 0.04];
    let geo = format!("<box size=\"{} {} {}\"/>", e[0], e[1], e[2]);
    let exact = box_inertia(0.3, e);
    for (name, mass, i, com) in [
        ("clean", 0.3, exact, [0.0; 3]),
        ("tri", 0.3, [1e-4, 1e-4, 3e-4], [0.0; 3]),
        ("neg", 0.3, [-1e-4, 1e-4, 1e-4], [0.0; 3]),
        ("ph", 0.3, exact.map(|x| x * 100.0), [0.0; 3]),
        ("grams", 300.0, box_inertia(300.0, e), [0.0; 3]),
        ("com", 0.3, exact, [0.0, 0.0, 0.12]),
    ] {
        v.push(write(
            dir,
            &format!("{name}.urdf"),
            &urdf(&inertial(mass, i, com), &geo, &geo),
        ));
    }
    let apple = apple();
    let ine = inertial(0.068, [4.1e-5, 4.2e-5, 4.2e-5], [0.0; 3]);
    v.push(write(
        dir,
        "apple.urdf",
        &urdf(
            &ine,
            &format!("<mesh filename=\"{apple}\"/>"),
            &format!("<mesh filename=\"{apple}\"/>"),
        ),
    ));
    v.push(write(
        dir,
        "missing.urdf",
        &urdf(
            &ine,
            "<box size=\"0.1 0.1 0.1\"/>",
            "<mesh filename=\"nowhere.obj\"/>",
        ),
    ));
    v.push(write(
        dir,
        "bad.urdf",
        "<robot><link name=\"a\">\n</robot>\n",
    ));
    v.push(rocker(dir, "rock", 15.0));
    v.push(rocker(dir, "still", 0.0));
    v
}

#[test]
fn every_urdf_case_agrees_with_pybullet() {
    let t = tempfile::tempdir().unwrap();
    let mut table = Vec::new();
    for p in urdf_cases(t.path()) {
        let r = check(&p);
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        let refused_by_us = r.findings.iter().any(|f| {
            f.check.starts_with("file.")
                && f.severity == interact3d::validate::finding::Severity::Error
        });
        let pb = if refused_by_us {
            python_json(
                "check_asset_pybullet.py",
                &[p.to_str().unwrap(), "--seconds", "0"],
            )
        } else {
            pybullet(&p, &r)
        };
        // Loads or refuses: a file PyBullet cannot load has a file error finding in ours.
        assert_eq!(
            pb["loads"].as_bool().unwrap(),
            !refused_by_us,
            "{name}: ours {:?}, PyBullet {pb}",
            ids(&r)
        );
        if !pb["loads"].as_bool().unwrap() {
            table.push(format!("{name}: refused by both"));
            continue;
        }
        // Contact at the start: placed on the plane, nothing goes through it. PyBullet keeps
        // convex shapes its 1 mm collision margin apart, and reports that margin as depth.
        let depth = pb["floor_penetration"].as_f64().unwrap();
        assert!(depth < 1.2e-3, "{name}: PyBullet floor depth {depth}");
        // Motion: ours fires physics.settle/rest exactly when PyBullet's base moves.
        if r.findings.iter().any(|f| f.check == "physics.skipped") {
            table.push(format!("{name}: not simulated (ours skipped)"));
            continue;
        }
        let (_, diags) = placement(&p);
        let (body, diag) = &diags[0];
        let theirs = engine_moves(&pb["motion"], &pb["window_motion"], *diag);
        let ours = we_say_moves(&r, body);
        table.push(format!(
            "{name}: ours moves={ours} PyBullet moves={theirs} (last second {:.3} mm, {:.2}°)",
            pb["window_motion"]["moved"].as_f64().unwrap() * 1e3,
            pb["window_motion"]["turned_deg"].as_f64().unwrap()
        ));
        assert_eq!(ours, theirs, "{name}: {:#?}\nPyBullet {pb}", r.findings);
    }
    eprintln!("{}", table.join("\n"));
}

#[test]
fn rest_fires_on_a_rocker_and_not_on_its_upright_twin() {
    let t = tempfile::tempdir().unwrap();
    let rock = rocker(t.path(), "rock", 15.0);
    let r = check(&rock);
    let f = find(&r, "physics.rest");
    assert_eq!(f.len(), 1, "{:#?}", r.findings);
    assert!(find(&r, "physics.settle").is_empty(), "{:#?}", r.findings);
    assert_eq!(f[0].line, 2, "line of the link");
    // A rigid rocker rolling without slipping keeps its energy (period 0.55 s, amplitude 15°):
    // over 1 s it turns by more than the 1° limit and by at most twice its amplitude.
    let turned: f64 = f[0]
        .message
        .split("turned ")
        .nth(1)
        .and_then(|s| s.split('°').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("{}", f[0].message));
    assert!(turned > 1.0 && turned <= 30.0, "{}", f[0].message);
    // Its exact inertial is not a placeholder.
    assert!(
        find(&r, "inertia.placeholder").is_empty(),
        "{:#?}",
        r.findings
    );
    let still = rocker(t.path(), "still", 0.0);
    let r = check(&still);
    assert!(
        r.findings.iter().all(|f| !f.check.starts_with("physics")),
        "{:#?}",
        r.findings
    );
}

#[test]
fn placeholder_inertia_is_reported_once_not_as_a_rest_failure() {
    // YCB's URDFs give every object I = 1e-3 kg·m², 20-1500x what their shape implies. With that
    // tensor PyBullet (URDF_USE_INERTIA_FROM_FILE) still rocks the lemon, the peach and the fork
    // in their 4th second; with the tensor their geometry implies (PyBullet's own, computed
    // from the shape) all three are still. Ours reports the placeholder and simulates the
    // implied tensor: no physics finding.
    for obj in [
        "014_lemon/lemon.urdf",
        "015_peach/peach.urdf",
        "030_fork/fork.urdf",
    ] {
        let Some(p) = shared_or_skip(
            "placeholder_inertia",
            &format!("datasets/objects/ycb/{obj}"),
        ) else {
            return;
        };
        let r = check(&p);
        assert_eq!(find(&r, "inertia.placeholder").len(), 1, "{obj}");
        assert!(
            r.findings.iter().all(|f| !f.check.starts_with("physics")),
            "{obj}: {:#?}",
            r.findings
        );
        let (lift, diags) = placement(&p);
        let lift = lift.to_string();
        let args = [p.to_str().unwrap(), "--lift", &lift, "--seconds", "4"];
        let own = python_json(
            "check_asset_pybullet.py",
            &[&args[..], &["--no-file-inertia"]].concat(),
        );
        assert!(
            !engine_moves(&own["motion"], &own["window_motion"], diags[0].1),
            "{obj}: PyBullet with its own inertia {own}"
        );
        let file = python_json("check_asset_pybullet.py", &args);
        assert!(
            file["window_motion"]["turned_deg"].as_f64().unwrap() > 1.0,
            "{obj}: PyBullet with the file's inertia {file}"
        );
    }
}

#[test]
fn every_mjcf_case_agrees_with_mujoco_on_motion() {
    let t = tempfile::tempdir().unwrap();
    let one = |name: &str| {
        let i = 0.5 * 0.01 / 6.0;
        write(
            t.path(),
            &format!("{name}.xml"),
            &format!("<mujoco>\n  <worldbody>\n    <geom type=\"plane\" size=\"1 1 0.1\"/>\n    <body name=\"b\" pos=\"0 0 0.05\">\n      <freejoint/>\n      <inertial pos=\"0 0 0\" mass=\"0.5\" diaginertia=\"{i} {i} {i}\"/>\n      <geom type=\"box\" size=\"0.05 0.05 0.05\"/>\n    </body>\n  </worldbody>\n</mujoco>\n"),
        )
    };
    let cases = [
        mug_scene(t.path(), "inside", true),
        mug_scene(t.path(), "beside", false),
        boxes(t.path(), "clean", 0.01, 0.0, 0.0),
        boxes(t.path(), "sunk", 0.01, 0.004, 0.0),
        boxes(t.path(), "tilt", 0.01, 0.0, 40.0),
        one("one_box"),
    ];
    let mut table = Vec::new();
    for p in &cases {
        let r = check(p);
        let mj = python_json(
            "check_asset_mujoco.py",
            &[p.to_str().unwrap(), "--seconds", "4", "--window", "1"],
        );
        assert_eq!(mj["loads"], true, "{mj}");
        let (_, diags) = placement(p);
        for (body, m) in mj["motion"].as_object().unwrap() {
            let diag = diags.iter().find(|d| &d.0 == body).unwrap().1;
            let theirs = engine_moves(m, &mj["window_motion"][body], diag);
            // An initial penetration fails our settle test whatever follows (the engines
            // push the bodies apart): count that as motion.
            let ours = we_say_moves(&r, body);
            let pushed = r.findings.iter().any(|f| {
                f.check.starts_with("contact.") && f.subject.split('/').any(|s| s == body)
            });
            table.push(format!(
                "{} {body}: ours moves={ours} MuJoCo moves={theirs} (moved {:.2} mm, turned {:.1}°; pushed at start: {pushed})",
                p.file_name().unwrap().to_string_lossy(),
                m["moved"].as_f64().unwrap() * 1e3,
                m["turned_deg"].as_f64().unwrap()
            ));
            assert_eq!(
                ours,
                theirs || pushed,
                "{}: {body}: {:#?}\nMuJoCo {mj}",
                p.display(),
                r.findings
            );
        }
    }
    eprintln!("{}", table.join("\n"));
}

#[test]
fn object_model_files_are_free_objects_and_mujoco_agrees() {
    // Google Scanned Objects' model.xml: one body of 32 V-HACD hulls, no joint, no floor.
    // Checked as a free object on the ground (a note says so); MuJoCo, given a free joint and
    // a plane at the same pose, moves it exactly when we say it moves.
    let Some(gso) = shared_or_skip("object_model_files", "datasets/objects/gso") else {
        return;
    };
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&gso)
        .unwrap()
        .flatten()
        .map(|e| e.path().join("model.xml"))
        .filter(|p| p.is_file())
        .collect();
    dirs.sort();
    assert!(dirs.len() >= 3);
    let mut table = Vec::new();
    for p in &dirs {
        let r = check(p);
        let note = find(&r, "asset.free_object");
        assert_eq!(note.len(), 1, "{}: {:?}", p.display(), ids(&r));
        assert!(note[0].line > 0);
        assert!(find(&r, "physics.skipped").is_empty(), "{:?}", ids(&r));
        let (lift, diags) = placement(p);
        let lift = lift.to_string();
        let mj = python_json(
            "check_asset_mujoco.py",
            &[
                p.to_str().unwrap(),
                "--seconds",
                "4",
                "--free-lone-body",
                &lift,
            ],
        );
        let (body, diag) = &diags[0];
        let m = mj["motion"]
            .as_object()
            .unwrap()
            .values()
            .next()
            .unwrap()
            .clone();
        let w = mj["window_motion"]
            .as_object()
            .unwrap()
            .values()
            .next()
            .unwrap()
            .clone();
        let theirs = engine_moves(&m, &w, *diag);
        let ours = we_say_moves(&r, body);
        table.push(format!(
            "{}: ours moves={ours} MuJoCo moves={theirs} (moved {:.2} mm, turned {:.1}°, last second {:.3} mm {:.2}°)",
            p.parent().unwrap().file_name().unwrap().to_string_lossy(),
            m["moved"].as_f64().unwrap() * 1e3,
            m["turned_deg"].as_f64().unwrap(),
            w["moved"].as_f64().unwrap() * 1e3,
            w["turned_deg"].as_f64().unwrap(),
        ));
        assert_eq!(
            ours,
            theirs,
            "{}: {:#?}\nMuJoCo {mj}",
            p.display(),
            r.findings
        );
    }
    eprintln!("{}", table.join("\n"));
    // --keep-welded: MuJoCo's own reading of the file alone, nothing to simulate.
    let mut o = interact3d::validate::asset::AssetCheckOptions::default();
    o.read.keep_welded = true;
    let r = interact3d::validate::asset::check_path(&dirs[0], "m", &o);
    assert!(find(&r, "asset.free_object").is_empty());
    assert_eq!(find(&r, "physics.skipped").len(), 1, "{:?}", ids(&r));
}
