//! What a user gives by hand (issue #36): `--up` for a lone mesh or a manifest, the unit
//! warning of a lone object, `--density` and `--mass` per object, object names from a sample's
//! metadata (its `object_*` ids kept as aliases), and every warning on stderr under the table,
//! counted by the summary line. Expectations are analytic: a box's extents and volume, the
//! fixtures' generated volumes (fixtures/*/ground_truth.json).

mod common;
use common::*;
use serde_json::Value;
use std::fs;
use std::path::{Path, PathBuf};

/// OBJ text of an axis-aligned box `x` × `y` × `z` (metres) centred at the origin, triangles
/// facing out; `open` leaves out the two triangles of the +Z face (a hole).
fn box_obj(x: f64, y: f64, z: f64, open: bool) -> String {
    let mut s = String::new();
    for k in 0..8 {
        let sx = if k & 1 == 0 { -x / 2.0 } else { x / 2.0 };
        let sy = if k & 2 == 0 { -y / 2.0 } else { y / 2.0 };
        let sz = if k & 4 == 0 { -z / 2.0 } else { z / 2.0 };
        s += &format!("v {sx} {sy} {sz}\n");
    }
    // Vertex k has bit 0 = +x, bit 1 = +y, bit 2 = +z (OBJ indices are k + 1).
    let faces: [[usize; 4]; 6] = [
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
    ];
    for (i, q) in faces.iter().enumerate() {
        if open && i == 1 {
            continue;
        }
        s += &format!("f {} {} {}\n", q[0] + 1, q[1] + 1, q[2] + 1);
        s += &format!("f {} {} {}\n", q[0] + 1, q[2] + 1, q[3] + 1);
    }
    s
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    fs::create_dir_all(dir).unwrap();
    let p = dir.join(name);
    fs::write(&p, text).unwrap();
    p
}

fn arr(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

/// Export with the binary; (exit code, stderr, report.json).
fn export_with(scene: &Path, out: &Path, extra: &[&str]) -> (i32, String, Value) {
    let (code, err) = common::export_logged(scene, out, extra);
    (code, err, read_json(&out.join("report.json")))
}

#[test]
fn up_flag_turns_a_y_up_obj_and_a_manifest() {
    let t = tempfile::tempdir().unwrap();
    // 0.1 wide, 0.3 tall along +Y (a Y-up file), 0.05 deep.
    let obj = write(t.path(), "post.obj", &box_obj(0.1, 0.3, 0.05, false));
    let (_, _, z) = export_with(&obj, &t.path().join("z"), &["--no-validate"]);
    let (_, _, y) = export_with(&obj, &t.path().join("y"), &["--no-validate", "--up", "y"]);
    // Default Z-up: taken as is. --up y: +90° about X, (x, y, z) -> (x, -z, y).
    assert!(
        close(&arr(&z["objects"][0]["extents"]), &[0.1, 0.3, 0.05], 1e-9),
        "{z}"
    );
    assert!(
        close(&arr(&y["objects"][0]["extents"]), &[0.1, 0.05, 0.3], 1e-9),
        "{y}"
    );
    // Standing on its end: the centre of mass at half the height.
    assert!((y["objects"][0]["com"][2].as_f64().unwrap() - 0.15).abs() < 1e-9);

    // A manifest saying z, overridden by --up y.
    let m = t.path().join("m");
    write(&m, "post.obj", &box_obj(0.1, 0.3, 0.05, false));
    write(
        &m,
        "scene.json",
        r#"{"format": "interact3d-scene", "up_axis": "z", "objects": [{"name": "post", "mesh": "post.obj"}]}"#,
    );
    let (_, _, my) = export_with(&m, &t.path().join("my"), &["--no-validate", "--up", "y"]);
    assert!(
        close(&arr(&my["objects"][0]["extents"]), &[0.1, 0.05, 0.3], 1e-9),
        "{my}"
    );
}

#[test]
fn up_z_is_refused_for_gltf_which_is_y_up_by_its_spec() {
    let t = tempfile::tempdir().unwrap();
    let ball_bowl = root().join("fixtures/ball_bowl");
    let (code, out, err) = run(&[
        "export",
        ball_bowl.to_str().unwrap(),
        "-o",
        t.path().join("o").to_str().unwrap(),
        "--up",
        "z",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(out.is_empty());
    assert!(
        err.contains("--up z") && err.contains("Y-up by its specification"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!t.path().join("o").exists());
}

#[test]
fn a_lone_object_out_of_range_is_warned_about_naming_size() {
    let t = tempfile::tempdir().unwrap();
    // 3 m, 4 mm: warned; 0.3 m: not; 3 m with --size: not.
    for (case, s, extra, warned) in [
        ("big", 3.0, &[][..], true),
        ("tiny", 0.004, &[], true),
        ("fine", 0.3, &[], false),
        ("sized", 3.0, &["--size", "sized=0.3"], false),
    ] {
        let obj = write(
            &t.path().join(case),
            &format!("{case}.obj"),
            &box_obj(s, s / 2.0, s / 3.0, false),
        );
        let mut args = vec!["--no-validate"];
        args.extend_from_slice(extra);
        let (_, err, report) = export_with(&obj, &t.path().join(case).join("out"), &args);
        let hint = format!("--size {case}=METRES");
        let lines: Vec<&str> = err.lines().filter(|l| l.contains(&hint)).collect();
        assert_eq!(lines.len(), usize::from(warned), "{case}: {err}");
        let in_report = report["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().contains(&hint));
        assert_eq!(in_report, warned, "{case}: {report}");
        if warned {
            assert!(lines[0].starts_with("warning: "), "{err}");
        }
    }
}

#[test]
fn density_and_mass_per_object_from_the_command_line() {
    let t = tempfile::tempdir().unwrap();
    let fixture = root().join("fixtures/ball_bowl");
    let truth = read_json(&fixture.join("ground_truth.json"));
    let volume = |id: &str| truth["objects"][id]["volume_m3"].as_f64().unwrap();
    // By label and by id (alias): the ball at 500 kg/m³, the bowl at 0.3 kg.
    let (_, _, r) = export_with(
        &fixture,
        &t.path().join("a"),
        &[
            "--no-validate",
            "--density",
            "ball=500",
            "--mass",
            "object_a=0.3",
        ],
    );
    let mass = |r: &Value, name: &str| {
        r["objects"]
            .as_array()
            .unwrap()
            .iter()
            .find(|o| o["name"] == name)
            .unwrap_or_else(|| panic!("no object {name} in {r}"))["mass"]
            .as_f64()
            .unwrap()
    };
    let ball = mass(&r, "ball");
    assert!(
        (ball - 500.0 * volume("object_b")).abs() < 1e-4 * ball,
        "ball {ball} kg, expected {}",
        500.0 * volume("object_b")
    );
    assert!((mass(&r, "bowl") - 0.3).abs() < 1e-9);
    // Unchanged default: 1000 kg/m³.
    let (_, _, d) = export_with(&fixture, &t.path().join("d"), &["--no-validate"]);
    assert!((mass(&d, "bowl") - 1000.0 * volume("object_a")).abs() < 1e-4 * mass(&d, "bowl"));
    // An unknown name is a usage error that lists names and aliases.
    let (code, _, err) = run(&[
        "export",
        fixture.to_str().unwrap(),
        "-o",
        t.path().join("x").to_str().unwrap(),
        "--mass",
        "lemon=0.1",
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("\"lemon\"") && err.contains("bowl (object_a), ball (object_b)"),
        "{err}"
    );
    // Not positive: refused by the parser.
    let (code, _, err) = run(&[
        "export",
        fixture.to_str().unwrap(),
        "-o",
        t.path().join("x").to_str().unwrap(),
        "--density",
        "ball=-3",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(!t.path().join("x").exists());
}

#[test]
fn sample_objects_are_named_from_the_metadata_with_ids_as_aliases() {
    let t = tempfile::tempdir().unwrap();
    let fixture = root().join("fixtures/ball_bowl");
    let out = t.path().join("o");
    // --size by the id: the bowl (object_a) 0.32 m across, twice the fixture's 0.16 m.
    let (_, err, r) = export_with(
        &fixture,
        &out,
        &["--no-validate", "--size", "object_a=0.32"],
    );
    let names: Vec<&str> = r["objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| o["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["bowl", "ball"]);
    assert!(
        (r["scale"].as_f64().unwrap() - 2.0).abs() < 1e-9,
        "{}",
        r["scale"]
    );
    // Files, MJCF bodies and URDF links by name; the table too.
    for n in ["bowl", "ball"] {
        assert!(out.join(format!("{n}.urdf")).is_file());
        assert!(out.join(format!("{n}.xml")).is_file());
        assert!(out.join("meshes").join(n).join("visual.obj").is_file());
        assert!(err.lines().any(|l| l.starts_with(n)), "{err}");
    }
    let xml = fs::read_to_string(out.join("scene.xml")).unwrap();
    assert!(xml.contains("name=\"bowl\"") && xml.contains("name=\"ball\""));
    // --size by the label gives the same scale.
    let (_, _, r2) = export_with(
        &fixture,
        &t.path().join("p"),
        &["--no-validate", "--size", "bowl=0.32"],
    );
    assert_eq!(r2["scale"], r["scale"]);
}

/// Every warning of report.json is one `warning:` line on stderr under the table, and the
/// summary line (the last) counts them; `validate` does the same.
#[test]
fn export_and_validate_print_every_warning_and_count_them() {
    let t = tempfile::tempdir().unwrap();
    // An open 3 m box: the unit warning and the open-mesh warning at least.
    let obj = write(t.path(), "crate.obj", &box_obj(3.0, 2.0, 1.0, true));
    let (_, err, r) = export_with(&obj, &t.path().join("o"), &["--points", "20000"]);
    let mut expected: Vec<String> = r["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap().to_string())
        .collect();
    for o in r["objects"].as_array().unwrap() {
        for w in o["warnings"].as_array().unwrap() {
            expected.push(format!(
                "{}: {}",
                o["name"].as_str().unwrap(),
                w.as_str().unwrap()
            ));
        }
    }
    expected.extend(
        r["validation"]["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .map(|w| w.as_str().unwrap().to_string()),
    );
    expected.dedup();
    assert!(expected.len() >= 2, "{r}");
    assert!(
        expected.iter().any(|w| w.contains("not closed")),
        "{expected:?}"
    );
    let printed: Vec<&str> = err
        .lines()
        .filter_map(|l| l.strip_prefix("warning: "))
        .collect();
    assert_eq!(printed, expected, "{err}");
    let last = err.trim_end().lines().last().unwrap();
    let n = expected.len();
    assert!(
        last.starts_with("exported ") && last.ends_with(&format!(", {n} warnings")),
        "{last}"
    );
    // The warnings come after the table's verdict.
    let verdict = err.lines().position(|l| l.starts_with("verdict:")).unwrap();
    let first_warning = err
        .lines()
        .position(|l| l.starts_with("warning: "))
        .unwrap();
    assert!(verdict < first_warning, "{err}");

    // validate: the same scene, the same build warnings, counted.
    let (code, _, verr) = run(&["validate", obj.to_str().unwrap(), "--points", "20000"]);
    assert!(code == 0 || code == 1, "{verr}");
    let vprinted = verr.lines().filter(|l| l.starts_with("warning: ")).count();
    assert!(vprinted >= 2, "{verr}");
    let last = verr.trim_end().lines().last().unwrap();
    assert!(
        last.starts_with("validated ") && last.ends_with(&format!(", {vprinted} warnings")),
        "{last}"
    );
}
