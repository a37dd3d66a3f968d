//! The batch's results: one [`Row`] per scene, written as `summary.json`, `summary.csv` and
//! `index.html`, and merged from shard summaries.

use super::discover::Shard;
use crate::error::{Error, Result};
use crate::export::format::round;
use crate::fsutil::{json_bytes, write_atomically};
use crate::validate::Validation;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The outcome of one scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// Exported and validated.
    Pass,
    /// Exported; validation failed (the export's report.json says why).
    Fail,
    /// Could not be read or converted (or the converter panicked); nothing written.
    Error,
}

impl Verdict {
    pub fn as_str(&self) -> &'static str {
        match self {
            Verdict::Pass => "pass",
            Verdict::Fail => "fail",
            Verdict::Error => "error",
        }
    }
}

/// What is known about a scene independently of the run that computed it; stored in the
/// scene's `batch.json`, so a reused scene gives exactly the row a fresh one would.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneResult {
    /// Relative path under ROOT (and under OUT).
    pub path: String,
    pub id: String,
    pub category: String,
    pub objects: Option<usize>,
    pub verdict: Verdict,
    /// Largest R_volume over the pairs, on the visual meshes (the paper's metric; the collision
    /// hulls' when visual metrics are off).
    pub r_volume: Option<f64>,
    /// Largest penetration depth over the pairs, visual meshes (m), same fallback.
    pub max_penetration_m: Option<f64>,
    /// Largest penetration between collision hulls at the composed pose (m): the gated value.
    pub collision_penetration_m: Option<f64>,
    /// Largest settle + rest displacement of a body in the simulation (m).
    pub max_displacement_m: Option<f64>,
    /// Hull count of each object, in object order.
    pub hulls: Vec<usize>,
    /// Failed checks as `name subject`.
    pub failed_checks: Vec<String>,
    /// Pictures were drawn into the scene's `render/` folder (`--render`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub rendered: bool,
}

/// One line of the summary.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    #[serde(flatten)]
    pub scene: SceneResult,
    /// Why it could not be converted (verdict `error`).
    pub error: Option<String>,
    /// Seconds this run spent on the scene (hashing, and converting unless reused).
    pub time_s: f64,
    /// The output was reused from an earlier run (inputs, options and version unchanged).
    pub reused: bool,
}

impl SceneResult {
    /// The result of a converted scene.
    pub fn from_export(
        path: &str,
        id: &str,
        category: &str,
        report: &crate::report::Report,
        validation: Option<&Validation>,
    ) -> SceneResult {
        let mut r = SceneResult::empty(path, id, category, Verdict::Pass);
        r.objects = Some(report.objects.len());
        r.hulls = report.objects.iter().map(|o| o.hull_count).collect();
        if let Some(v) = validation {
            r.verdict = if v.passed {
                Verdict::Pass
            } else {
                Verdict::Fail
            };
            let max = |it: &mut dyn Iterator<Item = f64>| {
                it.fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))))
            };
            let metric = |p: &crate::validate::PairReport| p.visual.unwrap_or(p.collision);
            r.r_volume = max(&mut v.pairs.iter().map(|p| metric(p).r_volume)).map(round);
            r.max_penetration_m =
                max(&mut v.pairs.iter().map(|p| metric(p).max_penetration_depth)).map(round);
            r.collision_penetration_m =
                max(&mut v.pairs.iter().map(|p| p.collision.max_penetration_depth)).map(round);
            r.max_displacement_m = max(&mut v
                .settle
                .bodies
                .iter()
                .filter(|b| !b.fixed)
                .map(|b| b.settle_displacement + b.rest_displacement))
            .map(round);
            r.failed_checks = v
                .checks
                .iter()
                .filter(|c| !c.passed)
                .map(|c| format!("{} {}", c.name, c.subject))
                .collect();
            if !v.settle.passed && r.failed_checks.is_empty() {
                r.failed_checks.push("settle scene".into());
            }
        }
        r
    }

    /// A result with no metrics.
    pub fn empty(path: &str, id: &str, category: &str, verdict: Verdict) -> SceneResult {
        SceneResult {
            path: path.into(),
            id: id.into(),
            category: category.into(),
            objects: None,
            verdict,
            r_volume: None,
            max_penetration_m: None,
            collision_penetration_m: None,
            max_displacement_m: None,
            hulls: Vec::new(),
            failed_checks: Vec::new(),
            rendered: false,
        }
    }
}

/// `OUT/<scene>/batch.json`: written inside the scene's atomic folder, so its presence means the
/// folder is complete; `hash` decides whether it can be reused.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SceneRecord {
    pub tool: String,
    pub version: String,
    pub hash: String,
    #[serde(flatten)]
    pub result: SceneResult,
}

/// Scene counts by verdict.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Counts {
    pub scenes: usize,
    pub pass: usize,
    pub fail: usize,
    pub error: usize,
}

impl Counts {
    pub fn of(rows: &[Row]) -> Counts {
        let mut c = Counts {
            scenes: rows.len(),
            ..Default::default()
        };
        for r in rows {
            match r.scene.verdict {
                Verdict::Pass => c.pass += 1,
                Verdict::Fail => c.fail += 1,
                Verdict::Error => c.error += 1,
            }
        }
        c
    }

    /// 0 all pass, 1 some failed validation, 2 some could not be read.
    pub fn exit_code(&self) -> u8 {
        if self.error > 0 {
            2
        } else if self.fail > 0 {
            1
        } else {
            0
        }
    }
}

/// How this run went (varies between runs; everything else in the summary does not).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RunInfo {
    pub elapsed_s: f64,
    pub jobs: usize,
    pub converted: usize,
    pub reused: usize,
    /// Shard summaries this one was merged from.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub merged_from: Vec<String>,
}

/// `summary.json` (and a shard's `summary.shard-I-of-N.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    pub tool: String,
    pub version: String,
    pub root: String,
    /// The shard this summary covers (absent: the whole selection, or a merge).
    pub shard: Option<Shard>,
    /// Hash of the options and tool version (equal across shards of one job).
    pub options_hash: String,
    pub counts: Counts,
    pub exit_code: u8,
    pub run: RunInfo,
    pub scenes: Vec<Row>,
}

impl Summary {
    pub fn new(
        root: String,
        shard: Option<Shard>,
        options_hash: String,
        mut rows: Vec<Row>,
        run: RunInfo,
    ) -> Summary {
        rows.sort_by(|a, b| a.scene.path.cmp(&b.scene.path));
        let counts = Counts::of(&rows);
        Summary {
            tool: "interact3d".into(),
            version: env!("CARGO_PKG_VERSION").into(),
            root,
            shard,
            options_hash,
            exit_code: counts.exit_code(),
            counts,
            run,
            scenes: rows,
        }
    }

    /// The file name of this summary in OUT.
    pub fn file_name(shard: Option<Shard>) -> String {
        match shard {
            None => "summary.json".into(),
            Some(s) => format!("summary.shard-{}-of-{}.json", s.index, s.count),
        }
    }

    /// Write `summary.json`, `summary.csv` and `index.html` (whole batch), or only the shard's
    /// JSON summary (a shard), each atomically.
    pub fn write(&self, out: &Path) -> Result<()> {
        write_atomically(&out.join(Self::file_name(self.shard)), &json_bytes(self)?)?;
        if self.shard.is_none() {
            write_atomically(&out.join("summary.csv"), self.csv().as_bytes())?;
            write_atomically(&out.join("index.html"), super::html::page(self)?.as_bytes())?;
        }
        Ok(())
    }

    /// One row per scene; `hulls` and `failed_checks` joined with `;`.
    pub fn csv(&self) -> String {
        let mut s = String::from("path,id,category,objects,verdict,r_volume,max_penetration_m,collision_penetration_m,max_displacement_m,hulls,failed_checks,time_s,reused,error\n");
        let num = |x: Option<f64>| x.map(|v| v.to_string()).unwrap_or_default();
        for r in &self.scenes {
            let c = &r.scene;
            let fields = [
                c.path.clone(),
                c.id.clone(),
                c.category.clone(),
                c.objects.map(|n| n.to_string()).unwrap_or_default(),
                c.verdict.as_str().into(),
                num(c.r_volume),
                num(c.max_penetration_m),
                num(c.collision_penetration_m),
                num(c.max_displacement_m),
                c.hulls
                    .iter()
                    .map(|h| h.to_string())
                    .collect::<Vec<_>>()
                    .join(";"),
                c.failed_checks.join(";"),
                format!("{:.3}", r.time_s),
                r.reused.to_string(),
                r.error.clone().unwrap_or_default(),
            ];
            s += &fields
                .iter()
                .map(|f| csv_field(f))
                .collect::<Vec<_>>()
                .join(",");
            s.push('\n');
        }
        s
    }

    /// Read a summary file.
    pub fn read(path: &Path) -> Result<Summary> {
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        serde_json::from_slice(&bytes)
            .map_err(|e| Error::input(path, format!("not a batch summary: {e}")))
    }
}

/// RFC 4180: quote fields holding a comma, quote or line break; double the quotes.
pub fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The shard summaries named by `inputs` (files, or folders searched for
/// `summary.shard-*.json`).
pub fn shard_files(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for i in inputs {
        if i.is_dir() {
            let mut v: Vec<PathBuf> = std::fs::read_dir(i)
                .map_err(|e| Error::io(i, e))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(|n| n.starts_with("summary.shard-") && n.ends_with(".json"))
                })
                .collect();
            v.sort();
            files.extend(v);
        } else if i.is_file() {
            files.push(i.clone());
        } else {
            return Err(Error::input(i, "no such file or folder"));
        }
    }
    Ok(files)
}

/// Combine shard summaries into one. Refuses summaries of different option sets or tool
/// versions and scenes that appear in two shards; warns (in the returned list) about missing
/// shards.
pub fn merge(files: &[PathBuf]) -> Result<(Summary, Vec<String>)> {
    if files.is_empty() {
        return Err(Error::Usage(
            "--merge-reports: no summary.shard-*.json found".into(),
        ));
    }
    let mut warnings = Vec::new();
    let mut rows: Vec<Row> = Vec::new();
    let mut first: Option<Summary> = None;
    let mut shards_seen = std::collections::BTreeSet::new();
    let mut count = None;
    let mut run = RunInfo::default();
    for f in files {
        let s = Summary::read(f)?;
        if let Some(a) = &first {
            if a.options_hash != s.options_hash || a.version != s.version {
                return Err(Error::input(
                    f,
                    format!(
                        "options or version differ from {} (options {} vs {}, version {} vs {}); shards must run the same command",
                        files[0].display(),
                        s.options_hash,
                        a.options_hash,
                        s.version,
                        a.version
                    ),
                ));
            }
            if a.root != s.root {
                warnings.push(format!(
                    "{}: root {} differs from {}",
                    f.display(),
                    s.root,
                    a.root
                ));
            }
        }
        if let Some(sh) = s.shard {
            if *count.get_or_insert(sh.count) != sh.count {
                return Err(Error::input(
                    f,
                    format!(
                        "shard {sh} does not split the same way as the others (N = {})",
                        count.unwrap()
                    ),
                ));
            }
            if !shards_seen.insert(sh.index) {
                return Err(Error::input(f, format!("shard {sh} given twice")));
            }
        }
        run.elapsed_s = run.elapsed_s.max(s.run.elapsed_s);
        run.jobs += s.run.jobs;
        run.converted += s.run.converted;
        run.reused += s.run.reused;
        run.merged_from.push(f.display().to_string());
        rows.extend(s.scenes.iter().cloned());
        if first.is_none() {
            first = Some(s);
        }
    }
    if let Some(n) = count {
        let missing: Vec<String> = (1..=n)
            .filter(|i| !shards_seen.contains(i))
            .map(|i| format!("{i}/{n}"))
            .collect();
        if !missing.is_empty() {
            warnings.push(format!(
                "missing shard summaries: {} (the merged summary is incomplete)",
                missing.join(", ")
            ));
        }
    }
    rows.sort_by(|a, b| a.scene.path.cmp(&b.scene.path));
    for w in rows.windows(2) {
        if w[0].scene.path == w[1].scene.path {
            return Err(Error::Usage(format!(
                "scene {} appears in two shard summaries",
                w[0].scene.path
            )));
        }
    }
    let first = first.expect("at least one file");
    Ok((
        Summary::new(first.root, None, first.options_hash, rows, run),
        warnings,
    ))
}
