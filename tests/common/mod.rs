//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `../shared` beside the repository (CI has it there).
pub fn shared() -> PathBuf {
    root().join("..").join("shared")
}

/// Run the `interact3d` binary; returns (exit code, stdout, stderr).
pub fn run(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_interact3d"))
        .args(args)
        .output()
        .expect("run interact3d");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Export `scene` to `out` with the binary, panicking with its stderr unless the assets were
/// written (exit 0, or 1 when the scene failed validation: it is exported all the same).
/// Returns the exit code.
pub fn export(scene: &Path, out: &Path, extra: &[&str]) -> i32 {
    export_logged(scene, out, extra).0
}

/// [`export`], returning the exit code and the command's stderr.
pub fn export_logged(scene: &Path, out: &Path, extra: &[&str]) -> (i32, String) {
    let mut args = vec![
        "export",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let (code, _, err) = run(&args);
    assert!(
        code == 0 || code == 1,
        "export {} failed: {err}",
        scene.display()
    );
    assert!(
        out.join("report.json").is_file(),
        "export {} wrote no report: {err}",
        scene.display()
    );
    (code, err)
}

/// The Python interpreter for the interoperability tests.
pub fn python() -> String {
    std::env::var("INTERACT3D_PYTHON").unwrap_or_else(|_| "python3".into())
}

/// A prerequisite a test may lack on a user's machine.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Prereq {
    /// `../shared` (the project's shared datasets, beside the repository).
    Shared,
    /// A Python interpreter with the packages of tests/python/requirements.txt.
    Python,
}

impl Prereq {
    fn key(self) -> &'static str {
        match self {
            Prereq::Shared => "shared",
            Prereq::Python => "python",
        }
    }
}

/// Whether a missing `what` must fail the test rather than skip it: always under CI
/// (`CI=true`), and for each kind listed in `INTERACT3D_REQUIRE` (`.ci/test` lists `python`,
/// since it installed the packages itself).
pub fn required(what: Prereq) -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true")
        || std::env::var("INTERACT3D_REQUIRE")
            .is_ok_and(|v| v.split(',').any(|k| k.trim() == what.key()))
}

/// A check that cannot run here: fails the test when `what` is required (see [`required`]);
/// else says so loudly — one `SKIPPED` line written straight to the process's stderr, which
/// the test harness does not capture, so it shows in a plain `cargo test` — and appends the
/// line to `$INTERACT3D_SKIP_LOG` (`.ci/test` lists them all at the end).
pub fn skip(test: &str, what: Prereq, reason: &str) {
    let line = format!("{test}: {reason}");
    if required(what) {
        panic!(
            "{line} (a required prerequisite: CI=true or INTERACT3D_REQUIRE={})",
            what.key()
        );
    }
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "SKIPPED {line}");
    if let Ok(log) = std::env::var("INTERACT3D_SKIP_LOG") {
        if let Ok(mut f) = fs::OpenOptions::new().create(true).append(true).open(log) {
            let _ = writeln!(f, "{line}");
        }
    }
}

/// `../shared/<rel>` when it exists; else [`skip`]s `test` and gives `None`.
pub fn shared_or_skip(test: &str, rel: &str) -> Option<PathBuf> {
    let p = shared().join(rel);
    if p.exists() {
        return Some(p);
    }
    skip(
        test,
        Prereq::Shared,
        &format!(
            "{} not found (the project's shared datasets belong beside the repository as ../shared)",
            p.display()
        ),
    );
    None
}

/// Why [`python()`] cannot run the engine checks (cannot start, or lacks a package), or
/// `None` when it can. Asked once per test binary.
pub fn python_problem() -> Option<String> {
    static PROBLEM: std::sync::OnceLock<Option<String>> = std::sync::OnceLock::new();
    PROBLEM
        .get_or_init(|| {
            let py = python();
            match Command::new(&py)
                .args(["-c", "import mujoco, pybullet, numpy"])
                .output()
            {
                Err(e) => Some(format!("cannot run Python {py:?} ({e})")),
                Ok(o) if !o.status.success() => Some(format!(
                    "Python {py:?} lacks a package of tests/python/requirements.txt ({}); run .ci/test, which makes its own venv, or point INTERACT3D_PYTHON at a Python that has them",
                    String::from_utf8_lossy(&o.stderr)
                        .lines()
                        .last()
                        .unwrap_or("import failed")
                        .trim()
                )),
                Ok(_) => None,
            }
        })
        .clone()
}

/// Whether the Python engine checks can run; if not, [`skip`]s `test` with the reason.
pub fn python_or_skip(test: &str) -> bool {
    match python_problem() {
        None => true,
        Some(why) => {
            skip(test, Prereq::Python, &why);
            false
        }
    }
}

/// Run one of tests/python/*.py and parse its JSON output.
pub fn python_json(script: &str, args: &[&str]) -> serde_json::Value {
    let out = Command::new(python())
        .arg(root().join("tests/python").join(script))
        .args(args)
        .output()
        .expect("python3 must be installed (see .ci/run)");
    assert!(
        out.status.success(),
        "{script} {args:?} failed (install the packages in tests/python/requirements.txt):\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{script}: bad JSON ({e}): {}",
            String::from_utf8_lossy(&out.stdout)
        )
    })
}

/// Read a JSON file.
pub fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// Every fixture folder (holding metadata.json or scene.json).
pub fn fixtures() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("fixtures"))
        .map(|it| {
            it.filter_map(|e| e.ok())
                .map(|e| e.path())
                .filter(|p| p.join("metadata.json").is_file() || p.join("scene.json").is_file())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// Every composed scene in ../shared/datasets/scenes.
pub fn shared_scenes() -> Vec<PathBuf> {
    let base = shared().join("datasets/scenes");
    let mut v = Vec::new();
    if let Ok(cats) = std::fs::read_dir(&base) {
        for c in cats.filter_map(|e| e.ok()) {
            if let Ok(sc) = std::fs::read_dir(c.path()) {
                v.extend(
                    sc.filter_map(|e| e.ok())
                        .map(|e| e.path())
                        .filter(|p| p.join("metadata.json").is_file()),
                );
            }
        }
    }
    v.sort();
    v
}

/// A broken scene is rejected: `export` and `validate` both exit 2 with one stderr line naming
/// `culprit` and `problem`, print nothing on stdout, create no output folder, leave no temporary
/// folder, and leave the inputs byte-identical.
pub fn rejects(dir: &Path, culprit: &str, problem: &str) {
    rejects_with(dir, &[], culprit, problem)
}

/// [`rejects`] with extra options; `scene` is a folder or a file (its folder is the input).
pub fn rejects_with(scene: &Path, extra: &[&str], culprit: &str, problem: &str) {
    let input = if scene.is_dir() {
        scene
    } else {
        scene.parent().unwrap()
    };
    let before = snapshot(input);
    let out = input.parent().unwrap().join("never");
    let out_s = out.to_str().unwrap();
    for cmd in ["export", "validate"] {
        let mut args = vec![cmd, scene.to_str().unwrap()];
        if cmd == "export" {
            args.extend(["-o", out_s]);
        }
        args.extend_from_slice(extra);
        let (code, stdout, stderr) = run(&args);
        assert_eq!(code, 2, "{cmd}: {stderr}");
        assert!(stdout.is_empty(), "{cmd}: {stdout}");
        let line = stderr.trim();
        assert_eq!(line.lines().count(), 1, "{cmd}: one line: {line}");
        assert!(
            line.contains(culprit) && line.contains(problem),
            "{cmd}: expected {culprit:?} and {problem:?} in: {line}"
        );
        assert!(!line.contains("panicked"), "{cmd}: {line}");
        assert!(!out.exists(), "{cmd}: no output folder");
        let leftovers: Vec<_> = fs::read_dir(input.parent().unwrap())
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().starts_with(".interact3d"))
            .collect();
        assert!(
            leftovers.is_empty(),
            "{cmd}: temporary folders left: {leftovers:?}"
        );
        assert_eq!(before, snapshot(input), "{cmd}: inputs untouched");
    }
}

/// Every file under `dir` (links not followed, a link's bytes are its target) as (path
/// relative to `dir`, '/'-separated, bytes), sorted.
pub fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<_> = walk(dir)
        .into_iter()
        .map(|p| {
            let bytes = if p.is_symlink() {
                fs::read_link(&p)
                    .unwrap()
                    .display()
                    .to_string()
                    .into_bytes()
            } else {
                fs::read(&p).unwrap()
            };
            let rel = p
                .strip_prefix(dir)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            (rel, bytes)
        })
        .collect();
    v.sort();
    v
}

/// Every file under `dir` (symlinks as files, not followed), depth first.
pub fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in fs::read_dir(dir).unwrap().filter_map(|e| e.ok()) {
        let p = e.path();
        if p.is_dir() && !p.is_symlink() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

/// An axis-aligned box of extents `e` (m) centred at the origin, as OBJ text (`asset_cases::box_obj`
/// takes half-extents and winds its faces in another order).
pub fn box_extents_obj(e: [f64; 3]) -> String {
    let h = e.map(|x| x / 2.0);
    let mut obj = String::new();
    for x in [-h[0], h[0]] {
        for y in [-h[1], h[1]] {
            for z in [-h[2], h[2]] {
                obj += &format!("v {x} {y} {z}\n");
            }
        }
    }
    // Vertex k + 1 has x = k & 4, y = k & 2, z = k & 1 (set = +h); faces wound outwards.
    for t in [
        [1, 3, 4],
        [1, 4, 2],
        [5, 6, 8],
        [5, 8, 7],
        [1, 2, 6],
        [1, 6, 5],
        [3, 7, 8],
        [3, 8, 4],
        [1, 5, 7],
        [1, 7, 3],
        [2, 4, 8],
        [2, 8, 6],
    ] {
        obj += &format!("f {} {} {}\n", t[0], t[1], t[2]);
    }
    obj
}
