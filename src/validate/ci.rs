//! Many assets at once, for CI: discovery of files, folders and globs, the parallel run, and
//! the outputs (table, JSON, SARIF 2.1.0, GitHub annotations, JUnit, baselines).
//!
//! Entry points: [`discover`], [`changed_since`] (`--changed-since REF`), [`run`]
//! ([`RunOptions`] → [`Run`]), [`table`], [`json`],
//! [`sarif`], [`github`], [`junit`], [`read_baseline`], [`baseline_json`], [`exit_code`].

use super::asset::{check_path, AssetCheckOptions};
use super::finding::{AssetReport, Finding, Severity, CHECKS};
use crate::error::{Error, Result};
use rayon::prelude::*;
use serde_json::{json, Value};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// What a path names.
#[derive(Clone, Debug, PartialEq)]
pub enum Kind {
    /// A URDF or MJCF file.
    Asset,
    /// An interact3d scene (sample folder, scene.json) or export folder.
    Scene,
}

/// One thing to check.
#[derive(Clone, Debug)]
pub struct Entry {
    pub path: PathBuf,
    /// The path as written in reports.
    pub shown: String,
    pub kind: Kind,
}

/// Whether a file is an MJCF model or a URDF (by extension and root element; MJCF include
/// fragments, `<mujocoinclude>`, are not models).
pub fn is_model_file(p: &Path) -> bool {
    let ext = p
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "urdf" | "mjcf" => true,
        "xml" => std::fs::read(p)
            .map(|b| {
                let head = String::from_utf8_lossy(&b[..b.len().min(4096)]).to_string();
                head.contains("<mujoco>") || head.contains("<mujoco ") || head.contains("<robot")
            })
            .unwrap_or(false),
        _ => false,
    }
}

/// A scene folder as `batch` finds them (a `scene.json`, or a sample folder's `metadata.json`),
/// or a folder of `object_*.glb`: its own reader then names what is wrong with it.
fn is_scene_dir(d: &Path) -> bool {
    d.join("scene.json").is_file()
        || d.join("metadata.json").is_file()
        || std::fs::read_dir(d)
            .map(|it| {
                it.flatten().any(|e| {
                    let n = e.file_name().to_string_lossy().to_string();
                    n.starts_with("object_") && n.ends_with(".glb")
                })
            })
            .unwrap_or(false)
}

fn walk(dir: &Path, out: &mut Vec<Entry>) -> Result<()> {
    let mut items: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .flatten()
        .map(|e| e.path())
        .collect();
    items.sort();
    for p in items {
        if p.is_dir() {
            if is_scene_dir(&p) {
                out.push(Entry {
                    shown: p.display().to_string(),
                    path: p,
                    kind: Kind::Scene,
                });
            } else {
                walk(&p, out)?;
            }
        } else if is_model_file(&p) {
            out.push(Entry {
                shown: p.display().to_string(),
                path: p,
                kind: Kind::Asset,
            });
        }
    }
    Ok(())
}

/// Expand files, folders (every URDF, MJCF model and scene under them) and globs (`*`, `?`,
/// `[...]`, `**`, matched from the part of the pattern before its first wildcard), in a stable
/// order, without duplicates. A path that names nothing is a usage error.
pub fn discover(paths: &[String]) -> Result<Vec<Entry>> {
    let mut out = Vec::new();
    for s in paths {
        let p = Path::new(s);
        if p.is_file() {
            let kind = if is_model_file(p)
                || matches!(
                    p.extension().and_then(|e| e.to_str()),
                    Some("xml" | "urdf" | "mjcf" | "xacro")
                ) {
                Kind::Asset
            } else {
                Kind::Scene
            };
            out.push(Entry {
                path: p.to_path_buf(),
                shown: s.clone(),
                kind,
            });
        } else if p.is_dir() {
            if is_scene_dir(p) {
                out.push(Entry {
                    path: p.to_path_buf(),
                    shown: s.clone(),
                    kind: Kind::Scene,
                });
            } else {
                let before = out.len();
                walk(p, &mut out)?;
                if out.len() == before {
                    return Err(Error::Usage(format!(
                        "{s}: no URDF, MJCF or scene found under this folder"
                    )));
                }
            }
        } else if s.contains(['*', '?', '[']) {
            let glob = globset::Glob::new(s)
                .map_err(|e| Error::Usage(format!("bad glob {s:?}: {e}")))?
                .compile_matcher();
            let cut = s.find(['*', '?', '[']).unwrap_or(0);
            let base = match s[..cut].rfind('/') {
                Some(k) => PathBuf::from(&s[..k.max(1)]),
                None => PathBuf::from("."),
            };
            let mut found = Vec::new();
            let mut all = Vec::new();
            collect_files(&base, &mut all);
            all.sort();
            for f in all {
                let rel = if base == Path::new(".") {
                    f.strip_prefix("./").unwrap_or(&f).to_path_buf()
                } else {
                    f.clone()
                };
                if glob.is_match(&rel) && is_model_file(&f) {
                    found.push(Entry {
                        shown: rel.display().to_string(),
                        path: f,
                        kind: Kind::Asset,
                    });
                }
            }
            if found.is_empty() {
                return Err(Error::Usage(format!(
                    "{s}: the pattern matches no URDF or MJCF file"
                )));
            }
            out.extend(found);
        } else {
            return Err(Error::Usage(format!("{s}: no such file or folder")));
        }
    }
    let mut seen = BTreeSet::new();
    out.retain(|e| seen.insert(e.path.clone()));
    Ok(out)
}

fn collect_files(dir: &Path, out: &mut Vec<PathBuf>) {
    if let Ok(it) = std::fs::read_dir(dir) {
        for e in it.flatten() {
            let p = e.path();
            if p.is_dir() {
                collect_files(&p, out);
            } else {
                out.push(p);
            }
        }
    }
}

/// Settings of a run.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    pub asset: AssetCheckOptions,
    /// For scenes and export folders found among the paths.
    pub scene_build: crate::body::BuildOptions,
    pub scene_validate: super::ValidateOptions,
    pub fail_on: Option<Severity>,
    /// Fingerprints of known findings.
    pub baseline: BTreeSet<String>,
}

/// The outcome of a run.
#[derive(Clone, Debug)]
pub struct Run {
    pub reports: Vec<AssetReport>,
    pub fail_on: Severity,
}

fn scene_report(e: &Entry, o: &RunOptions) -> AssetReport {
    let mk = |check: &str, subject: &str, msg: String, v: Option<f64>, l: Option<f64>| {
        Finding::new(check, subject, &e.shown, 0, msg, v, l, &e.shown)
    };
    match crate::pipeline::validate_path(
        &e.path,
        &o.asset.read.limits,
        &o.scene_build,
        &o.scene_validate,
    ) {
        Ok((a, v)) => {
            let findings = v
                .checks
                .iter()
                .filter(|c| !c.passed)
                .map(|c| {
                    let id = match c.name.as_str() {
                        "static_penetration" | "visual_penetration" => "contact.penetration",
                        "settle" => "physics.settle",
                        _ => "physics.rest",
                    };
                    mk(
                        id,
                        &c.subject,
                        c.message.clone(),
                        Some(c.value),
                        Some(c.limit),
                    )
                })
                .collect();
            AssetReport {
                file: e.shown.clone(),
                format: "scene".into(),
                bodies: a.bodies.len(),
                checks: vec![
                    "contact.penetration".into(),
                    "physics.settle".into(),
                    "physics.rest".into(),
                ],
                findings,
            }
        }
        Err(err) => AssetReport {
            file: e.shown.clone(),
            format: "unreadable".into(),
            bodies: 0,
            checks: vec!["file.parse_error".into()],
            findings: vec![mk(
                "file.parse_error",
                &e.shown,
                err.to_string(),
                None,
                None,
            )],
        },
    }
}

/// Check every entry in parallel (rayon), in input order; baselined findings are marked.
pub fn run(entries: &[Entry], o: &RunOptions) -> Run {
    let mut reports: Vec<AssetReport> = entries
        .par_iter()
        .map(|e| match e.kind {
            Kind::Asset => check_path(&e.path, &e.shown, &o.asset),
            Kind::Scene => scene_report(e, o),
        })
        .collect();
    for r in &mut reports {
        for f in &mut r.findings {
            f.baselined = o.baseline.contains(&f.fingerprint);
        }
    }
    Run {
        reports,
        fail_on: o.fail_on.unwrap_or(Severity::Error),
    }
}

/// 0: nothing at or above `--fail-on` (baselined findings aside); 1: something; 2: not one
/// asset could be read.
pub fn exit_code(r: &Run) -> u8 {
    if !r.reports.is_empty() && r.reports.iter().all(|x| x.format == "unreadable") {
        2
    } else if r.reports.iter().any(|x| x.failing(r.fail_on) > 0) {
        1
    } else {
        0
    }
}

fn verdict(r: &AssetReport, level: Severity) -> &'static str {
    if r.format == "unreadable" {
        "UNREADABLE"
    } else if r.failing(level) > 0 {
        "FAIL"
    } else {
        "pass"
    }
}

/// One line per asset, the findings at warning and above, and a summary.
pub fn table(r: &Run) -> String {
    let w = r
        .reports
        .iter()
        .map(|x| x.file.len())
        .max()
        .unwrap_or(5)
        .clamp(5, 70);
    let mut s = format!(
        "{:<w$} {:>6} {:>6} {:>8} {:>6}  verdict\n",
        "asset", "bodies", "errors", "warnings", "notes"
    );
    for x in &r.reports {
        s += &format!(
            "{:<w$} {:>6} {:>6} {:>8} {:>6}  {}\n",
            x.file,
            x.bodies,
            x.count(Severity::Error),
            x.count(Severity::Warning),
            x.count(Severity::Note),
            verdict(x, r.fail_on)
        );
    }
    for x in &r.reports {
        for f in x
            .findings
            .iter()
            .filter(|f| f.severity >= Severity::Warning)
        {
            s += &format!(
                "  {}:{}: {} {} [{}]{}: {}\n",
                f.file,
                f.line,
                f.severity.as_str(),
                f.check,
                f.subject,
                if f.baselined { " (baseline)" } else { "" },
                f.message
            );
        }
    }
    s += &summary_line(r);
    s += "\n";
    s
}

/// `N assets: P pass, F fail, U unreadable; E errors, W warnings, N notes (B baselined)`.
pub fn summary_line(r: &Run) -> String {
    let n = r.reports.len();
    let unread = r
        .reports
        .iter()
        .filter(|x| x.format == "unreadable")
        .count();
    let fail = r
        .reports
        .iter()
        .filter(|x| x.format != "unreadable" && x.failing(r.fail_on) > 0)
        .count();
    let all: Vec<&Finding> = r.reports.iter().flat_map(|x| &x.findings).collect();
    let c = |s: Severity| all.iter().filter(|f| f.severity == s).count();
    format!(
        "{n} assets: {} pass, {fail} fail, {unread} unreadable; {} errors, {} warnings, {} notes ({} baselined); failing at {}",
        n - fail - unread,
        c(Severity::Error),
        c(Severity::Warning),
        c(Severity::Note),
        all.iter().filter(|f| f.baselined).count(),
        r.fail_on.as_str()
    )
}

/// One JSON document: every asset with its findings, and a summary.
pub fn json(r: &Run) -> Value {
    json!({
        "fail_on": r.fail_on,
        "assets": r.reports.iter().map(|x| json!({
            "file": x.file,
            "format": x.format,
            "bodies": x.bodies,
            "verdict": verdict(x, r.fail_on),
            "checks": x.checks,
            "findings": x.findings,
        })).collect::<Vec<_>>(),
        "summary": {
            "assets": r.reports.len(),
            "failing": r.reports.iter().filter(|x| x.failing(r.fail_on) > 0).count(),
            "unreadable": r.reports.iter().filter(|x| x.format == "unreadable").count(),
            "exit_code": exit_code(r),
        }
    })
}

/// SARIF 2.1.0: one rule per check id, one result per finding at the file and line that
/// define its subject, `partialFingerprints` from the baseline fingerprint.
pub fn sarif(r: &Run) -> Value {
    let rules: Vec<Value> = CHECKS
        .iter()
        .map(|(id, sev, text)| {
            json!({
                "id": id,
                "name": id,
                "shortDescription": {"text": text},
                "defaultConfiguration": {"level": sev.as_str()},
            })
        })
        .collect();
    let results: Vec<Value> = r
        .reports
        .iter()
        .flat_map(|x| &x.findings)
        .map(|f| {
            let mut region = json!({});
            if f.line > 0 {
                region = json!({"startLine": f.line});
            }
            let mut res = json!({
                "ruleId": f.check,
                "ruleIndex": CHECKS.iter().position(|c| c.0 == f.check).unwrap_or(0),
                "level": f.severity.as_str(),
                "message": {"text": f.message},
                "locations": [{"physicalLocation": {
                    "artifactLocation": {"uri": f.file.replace('\\', "/")},
                    "region": region,
                }}],
                "partialFingerprints": {"interact3d/v1": f.fingerprint},
            });
            if f.baselined {
                res["baselineState"] = json!("unchanged");
            }
            res
        })
        .collect();
    json!({
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{
            "tool": {"driver": {
                "name": "interact3d",
                "version": env!("CARGO_PKG_VERSION"),
                "informationUri": "https://github.com/interact3d/interact3d",
                "rules": rules,
            }},
            "results": results,
        }]
    })
}

fn gh_escape(s: &str, property: bool) -> String {
    let s = s
        .replace('%', "%25")
        .replace('\r', "%0D")
        .replace('\n', "%0A");
    if property {
        s.replace(':', "%3A").replace(',', "%2C")
    } else {
        s
    }
}

/// GitHub Actions workflow commands, one per finding not in the baseline.
pub fn github(r: &Run) -> String {
    let mut s = String::new();
    for f in r
        .reports
        .iter()
        .flat_map(|x| &x.findings)
        .filter(|f| !f.baselined)
    {
        let cmd = match f.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Note => "notice",
        };
        s += &format!(
            "::{cmd} file={},line={},title={}::{}\n",
            gh_escape(&f.file, true),
            f.line.max(1),
            gh_escape(&format!("{} [{}]", f.check, f.subject), true),
            gh_escape(&f.message, false)
        );
    }
    s
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// JUnit XML: a test suite per asset, a test case per check that ran on it; a case fails when
/// the check has a finding at or above `--fail-on` that is not baselined.
pub fn junit(r: &Run) -> String {
    let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites>\n");
    for x in &r.reports {
        let failing = |c: &str| -> Vec<&Finding> {
            x.findings
                .iter()
                .filter(|f| f.check == c && f.severity >= r.fail_on && !f.baselined)
                .collect()
        };
        let failures = x.checks.iter().filter(|c| !failing(c).is_empty()).count();
        s += &format!(
            "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{failures}\">\n",
            xml_escape(&x.file),
            x.checks.len()
        );
        for c in &x.checks {
            s += &format!(
                "    <testcase classname=\"{}\" name=\"{}\">",
                xml_escape(&x.file),
                xml_escape(c)
            );
            let fs = failing(c);
            if !fs.is_empty() {
                let text: Vec<String> = fs
                    .iter()
                    .map(|f| format!("{}:{}: [{}] {}", f.file, f.line, f.subject, f.message))
                    .collect();
                s += &format!(
                    "<failure message=\"{}\">{}</failure>",
                    xml_escape(&fs[0].message),
                    xml_escape(&text.join("\n"))
                );
            }
            s += "</testcase>\n";
        }
        s += "  </testsuite>\n";
    }
    s += "</testsuites>\n";
    s
}

/// Read a baseline written by `--write-baseline`.
pub fn read_baseline(path: &Path) -> Result<BTreeSet<String>> {
    let b = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let v: Value = serde_json::from_slice(&b)
        .map_err(|e| Error::input(path, format!("not a baseline (JSON): {e}")))?;
    let list = v["fingerprints"]
        .as_array()
        .ok_or_else(|| Error::input(path, "not a baseline: no \"fingerprints\" array"))?;
    list.iter()
        .map(|x| {
            x.as_str()
                .map(str::to_string)
                .ok_or_else(|| Error::input(path, "baseline fingerprints must be strings"))
        })
        .collect()
}

/// A baseline of every finding of a run (sorted, so the same run writes the same bytes).
pub fn baseline_json(r: &Run) -> Value {
    let fps: BTreeSet<&str> = r
        .reports
        .iter()
        .flat_map(|x| &x.findings)
        .map(|f| f.fingerprint.as_str())
        .collect();
    json!({"version": 1, "tool": "interact3d validate", "fingerprints": fps})
}

/// Files changed since a git revision in the repository holding `dir`: `git diff --name-only
/// REF` (committed and uncommitted changes) plus untracked files, as absolute paths.
pub fn changed_files(dir: &Path, git_ref: &str) -> Result<BTreeSet<PathBuf>> {
    let git = |args: &[&str]| -> Result<String> {
        let out = std::process::Command::new("git")
            .arg("-C")
            .arg(dir)
            .args(args)
            .output()
            .map_err(|e| Error::Usage(format!("--changed-since needs git: {e}")))?;
        if !out.status.success() {
            return Err(Error::Usage(format!(
                "--changed-since {git_ref}: git {}: {}",
                args.join(" "),
                String::from_utf8_lossy(&out.stderr).trim()
            )));
        }
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    };
    let top = PathBuf::from(git(&["rev-parse", "--show-toplevel"])?.trim());
    let mut out = BTreeSet::new();
    for list in [
        git(&["diff", "--name-only", git_ref, "--"])?,
        git(&["ls-files", "--others", "--exclude-standard"])?,
    ] {
        for l in list.lines().filter(|l| !l.is_empty()) {
            let p = top.join(l);
            out.insert(p.canonicalize().unwrap_or(p));
        }
    }
    Ok(out)
}

/// The files an asset reads: itself, its includes and its meshes (as far as it can be read).
fn referenced_files(e: &Entry, read: &crate::io::asset::ReadOptions) -> Vec<PathBuf> {
    let mut v = vec![e.path.clone()];
    if e.kind == Kind::Asset {
        if let Ok(a) = crate::io::asset::load(&e.path, read) {
            for b in &a.bodies {
                v.push(b.src.file.clone());
                for g in &b.geoms {
                    v.push(g.src.file.clone());
                    if let crate::io::asset::Shape::Mesh { file, .. } = &g.shape {
                        v.push(file.clone());
                    }
                }
            }
            v.extend(a.issues.iter().map(|i| i.src.file.clone()));
        }
    }
    v
}

/// Only the entries whose file, included files or meshes are among `changed` (absolute paths);
/// a scene folder is kept when anything under it changed.
pub fn changed_only(
    entries: Vec<Entry>,
    changed: &BTreeSet<PathBuf>,
    read: &crate::io::asset::ReadOptions,
) -> Vec<Entry> {
    let abs = |p: &Path| p.canonicalize().unwrap_or_else(|_| p.to_path_buf());
    entries
        .into_iter()
        .filter(|e| match e.kind {
            Kind::Scene if e.path.is_dir() => {
                let d = abs(&e.path);
                changed.iter().any(|c| c.starts_with(&d))
            }
            _ => referenced_files(e, read)
                .iter()
                .any(|f| changed.contains(&abs(f))),
        })
        .collect()
}

/// `--changed-since`: the entries that read a file changed since `git_ref` in the repository of
/// `first` (the first path given: a folder, or a file's folder; else the working directory).
pub fn changed_since(
    entries: Vec<Entry>,
    first: &str,
    git_ref: &str,
    read: &crate::io::asset::ReadOptions,
) -> Result<Vec<Entry>> {
    let first = Path::new(first);
    let dir = if first.is_dir() {
        first.to_path_buf()
    } else {
        first
            .parent()
            .filter(|p| p.is_dir() && !p.as_os_str().is_empty())
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."))
    };
    Ok(changed_only(entries, &changed_files(&dir, git_ref)?, read))
}
