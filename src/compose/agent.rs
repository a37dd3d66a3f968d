//! The agentic loop of Interact3D, with the creative step outside: `compose --agent CMD`.
//!
//! interact3d composes the sample; while the result still penetrates (largest penetration depth
//! of a pair over the smaller object's bounding-box diagonal above [`AgentOptions::threshold`],
//! the reference implementation's 1 %), it renders the composed scene, runs `CMD` (through
//! `sh -c`) with a JSON description of the attempt on its stdin, reads a JSON answer naming
//! replacement files on its stdout, swaps them into a working copy of the sample and composes
//! again: at most [`AgentOptions::max_iterations`] times.
//!
//! # The protocol
//! stdin (one JSON object): `iteration`, `max_iterations`, `threshold`, `prompt`, `category`
//! (from `metadata.json`), `objects` (name, `object` and `guidance` GLB paths, label),
//! `collision_report` (the composition's pairwise metrics and `penetration_ratio`), `renders`
//! (`views`, `hulls`, `sections`: absolute PNG paths; `views_json`, `page`), `attempts` (the
//! earlier iterations: response and resulting ratio), `work_dir` (a folder the command may
//! write into).
//!
//! stdout (one JSON object): `{"replace": {"object_b": {"object": "new.glb", "guidance":
//! "new_guidance.glb"}}}`, either file optional, paths relative to `work_dir` or absolute;
//! an optional `"note"` is recorded.
//!
//! # Records
//! `OUT/agent/iter_NN/`: `stdin.json`, `stdout.txt`, `stderr.txt`, `render/` (what the command
//! saw), `files/` (copies of the replacement files) and `metrics.json` (the composition that
//! followed). `OUT/metadata.json` gets `agent_optimization`. When the command fails or answers
//! garbage, OUT is still written (the last good composition and every record) and the error
//! names the iteration and its record folder.
//!
//! Entry point: [`compose_with_agent`].

use super::folder::{compose_folder, read_sample};
use super::ComposeOptions;
use crate::error::{Error, Result};
use crate::io::Limits;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// How the loop runs.
#[derive(Clone, Debug)]
pub struct AgentOptions {
    /// Shell command run for each attempt.
    pub command: String,
    /// Most calls of the command.
    pub max_iterations: usize,
    /// Success: largest pair penetration over the smaller object's diagonal at most this.
    pub threshold: f64,
    /// Picture sizes for the attempts' renders.
    pub render: crate::render::RenderOptions,
}

impl AgentOptions {
    pub fn new(command: impl Into<String>) -> AgentOptions {
        AgentOptions {
            command: command.into(),
            max_iterations: 5,
            threshold: 0.01,
            render: crate::render::RenderOptions {
                size: 256,
                section_size: 256,
                ..Default::default()
            },
        }
    }
}

/// What the loop did.
#[derive(Clone, Debug)]
pub struct AgentOutcome {
    /// The `agent_optimization` record written to `metadata.json`.
    pub record: Value,
    pub success: bool,
    /// Penetration ratio of the final composition.
    pub ratio: f64,
    /// Calls of the command.
    pub iterations: usize,
}

fn copy_flat(from: &Path, to: &Path) -> Result<()> {
    crate::fsutil::create_dir(to)?;
    for e in std::fs::read_dir(from).map_err(|e| Error::io(from, e))? {
        let e = e.map_err(|e| Error::io(from, e))?;
        if e.file_type()
            .map_err(|er| Error::io(e.path(), er))?
            .is_file()
        {
            std::fs::copy(e.path(), to.join(e.file_name()))
                .map_err(|er| Error::io(e.path(), er))?;
        }
    }
    Ok(())
}

fn copy_tree(from: &Path, to: &Path) -> Result<()> {
    crate::fsutil::create_dir(to)?;
    for e in std::fs::read_dir(from).map_err(|e| Error::io(from, e))? {
        let e = e.map_err(|e| Error::io(from, e))?;
        let ft = e.file_type().map_err(|er| Error::io(e.path(), er))?;
        if ft.is_dir() {
            copy_tree(&e.path(), &to.join(e.file_name()))?;
        } else if ft.is_file() {
            std::fs::copy(e.path(), to.join(e.file_name()))
                .map_err(|er| Error::io(e.path(), er))?;
        }
    }
    Ok(())
}

/// Largest pair penetration over the smaller object's bounding-box diagonal, from a composed
/// folder's penetration check and the composed meshes.
fn penetration_ratio(composed: &Path, check: &Value, limits: &Limits) -> Result<f64> {
    let scene = crate::scene::load(composed, limits)?;
    let diag = |name: &str| -> f64 {
        scene
            .objects
            .iter()
            // The check names objects by their file ids (`object_b`); the composed scene.json
            // by their labels (`ball`), with the ids as aliases.
            .find(|o| o.name == name || o.aliases.iter().any(|a| a == name))
            .and_then(|o| o.visual.geometry().transformed(&o.pose.matrix()).aabb())
            .map(|b| b.diagonal())
            .unwrap_or(f64::NAN)
    };
    let mut worst = 0.0f64;
    for p in check["pairs"].as_array().into_iter().flatten() {
        let (Some(a), Some(b)) = (p["a"].as_str(), p["b"].as_str()) else {
            continue;
        };
        let d = p["max_penetration_depth"].as_f64().unwrap_or(0.0);
        let (da, db) = (diag(a), diag(b));
        let scale = da.min(db);
        if da.is_nan() || db.is_nan() {
            return Err(crate::Error::Internal(format!(
                "the penetration check names {a:?} and {b:?}, not both objects of {}",
                composed.display()
            )));
        }
        if d > 0.0 && scale > 0.0 {
            worst = worst.max(d / scale);
        }
    }
    Ok(worst)
}

/// Replacement files of one object: (name, new object mesh, new guidance mesh).
type Replacement = (String, Option<PathBuf>, Option<PathBuf>);

/// The command's answer: the replacements and the optional note.
fn parse_answer(
    stdout: &str,
    work: &Path,
    names: &[String],
) -> std::result::Result<(Vec<Replacement>, Option<String>), String> {
    let v: Value = serde_json::from_str(stdout.trim()).map_err(|e| {
        format!(
            "its stdout is not a JSON object ({e}); first bytes: {:?}",
            stdout.chars().take(80).collect::<String>()
        )
    })?;
    let obj = v
        .as_object()
        .ok_or("its stdout is JSON but not an object")?;
    let replace = obj
        .get("replace")
        .and_then(Value::as_object)
        .ok_or("its answer has no \"replace\" object naming replacement files")?;
    let resolve = |s: &str| {
        let p = PathBuf::from(s);
        if p.is_absolute() {
            p
        } else {
            work.join(p)
        }
    };
    let mut out = Vec::new();
    for (name, files) in replace {
        if !names.contains(name) {
            return Err(format!(
                "it names an unknown object {name:?} (objects: {})",
                names.join(", ")
            ));
        }
        let get = |k: &str| -> std::result::Result<Option<PathBuf>, String> {
            match files.get(k) {
                None | Some(Value::Null) => Ok(None),
                Some(Value::String(s)) => {
                    let p = resolve(s);
                    if p.is_file() {
                        Ok(Some(p))
                    } else {
                        Err(format!("{name}.{k}: no such file {}", p.display()))
                    }
                }
                Some(_) => Err(format!("{name}.{k} must be a path string")),
            }
        };
        let (o, g) = (get("object")?, get("guidance")?);
        if o.is_none() && g.is_none() {
            return Err(format!("{name}: neither \"object\" nor \"guidance\" given"));
        }
        out.push((name.clone(), o, g));
    }
    if out.is_empty() {
        return Err("its \"replace\" object is empty: nothing to recompose".into());
    }
    Ok((
        out,
        obj.get("note").and_then(Value::as_str).map(str::to_string),
    ))
}

fn files_of(kind: &str, renders: &crate::render::Renders, dir: &Path) -> Vec<String> {
    renders
        .pictures
        .iter()
        .filter(|p| p.record.kind == kind)
        .map(|p| dir.join(&p.file).display().to_string())
        .collect()
}

/// `compose SAMPLE -o OUT --agent CMD`: see the module documentation.
pub fn compose_with_agent(
    sample_dir: &Path,
    out: &Path,
    o: &ComposeOptions,
    limits: &Limits,
    force: bool,
    agent: &AgentOptions,
) -> Result<AgentOutcome> {
    let parent = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    crate::fsutil::create_dir(parent)?;
    let work = tempfile::Builder::new()
        .prefix(".interact3d-agent-")
        .tempdir_in(parent)
        .map_err(|e| Error::io(parent, e))?;
    let w = work
        .path()
        .canonicalize()
        .map_err(|e| Error::io(work.path(), e))?;
    let sample = w.join("sample");
    copy_flat(sample_dir, &sample)?;
    let agent_dir = w.join("agent");
    crate::fsutil::create_dir(&agent_dir)?;
    let meta = read_sample(&sample, limits)?.metadata;
    let prompt = meta
        .get("prompt")
        .or_else(|| meta.get("input").and_then(|i| i.get("scene_prompt")))
        .cloned()
        .unwrap_or(Value::Null);
    let category = meta
        .get("category")
        .or_else(|| meta.get("input").and_then(|i| i.get("category")))
        .cloned()
        .unwrap_or(Value::Null);
    let labels = meta.get("analysis").cloned().unwrap_or(Value::Null);

    let compose_into = |n: usize| -> Result<(PathBuf, Value, f64)> {
        let dir = w.join(format!("compose_{n:02}"));
        let (_, check) = compose_folder(&sample, &dir, o, limits, true)?;
        let ratio = penetration_ratio(&dir, &check, limits)?;
        Ok((dir, check, ratio))
    };
    let (mut composed, mut check, mut ratio) = compose_into(0)?;
    let mut attempts: Vec<Value> = Vec::new();
    let mut failure: Option<String> = None;
    let mut calls = 0;
    while ratio > agent.threshold && calls < agent.max_iterations {
        calls += 1;
        let rec = agent_dir.join(format!("iter_{calls:02}"));
        let files = rec.join("files");
        crate::fsutil::create_dir(&files)?;
        // What the command sees: the composed scene drawn, and the report.
        let mut build = crate::body::BuildOptions {
            engine: crate::body::Engine::Vhacd,
            ..Default::default()
        };
        build.decompose.max_hulls = 8;
        let assembly = crate::pipeline::load_assembly(&composed, limits, &build)?;
        let render_dir = rec.join("render");
        let renders =
            crate::render::render_to_dir(&assembly, &render_dir, &agent.render, None, true)?;
        let names: Vec<String> = read_sample(&sample, limits)?
            .inputs
            .iter()
            .map(|i| i.name.clone())
            .collect();
        let stdin = json!({
            "iteration": calls,
            "max_iterations": agent.max_iterations,
            "threshold": agent.threshold,
            "prompt": prompt,
            "category": category,
            "objects": names.iter().map(|n| json!({
                "name": n,
                "label": labels.get(n).cloned().unwrap_or(Value::Null),
                "object": sample.join(format!("{n}.glb")).display().to_string(),
                "guidance": sample.join(format!("guidance_{n}.glb")).display().to_string(),
            })).collect::<Vec<_>>(),
            "collision_report": { "penetration_ratio": ratio, "check": check },
            "renders": {
                "views": files_of("view", &renders, &render_dir),
                "hulls": files_of("hulls", &renders, &render_dir),
                "sections": files_of("section", &renders, &render_dir),
                "views_json": render_dir.join("views.json").display().to_string(),
                "page": render_dir.join("index.html").display().to_string(),
            },
            "attempts": attempts,
            "work_dir": files.display().to_string(),
        });
        let stdin_bytes = crate::fsutil::json_bytes(&stdin)?;
        crate::fsutil::write(&rec.join("stdin.json"), &stdin_bytes)?;
        let rel = format!("agent/iter_{calls:02}");
        let answer = run_command(&agent.command, &stdin_bytes, &files);
        let (stdout, stderr, status) = match answer {
            Ok(x) => x,
            Err(e) => {
                failure = Some(format!("iteration {calls}: could not run the agent command: {e} (records in OUT/{rel})"));
                break;
            }
        };
        crate::fsutil::write(&rec.join("stdout.txt"), stdout.as_bytes())?;
        crate::fsutil::write(&rec.join("stderr.txt"), stderr.as_bytes())?;
        if !status.success() {
            failure = Some(format!(
                "iteration {calls}: the agent command failed ({status}); its stderr: {:?} (records in OUT/{rel})",
                stderr.trim().chars().take(200).collect::<String>()
            ));
            break;
        }
        let (repl, note) = match parse_answer(&stdout, &files, &names) {
            Ok(x) => x,
            Err(m) => {
                failure = Some(format!("iteration {calls}: unusable answer from the agent command: {m} (records in OUT/{rel})"));
                break;
            }
        };
        // Keep copies, then swap the files into the working sample and recompose.
        let mut replaced = Vec::new();
        for (name, obj, guide) in &repl {
            for (src, file) in [
                (obj, format!("{name}.glb")),
                (guide, format!("guidance_{name}.glb")),
            ] {
                if let Some(src) = src {
                    let keep = files.join(format!("new_{file}"));
                    if src.canonicalize().ok() != keep.canonicalize().ok() {
                        std::fs::copy(src, &keep).map_err(|e| Error::io(src, e))?;
                    }
                    replaced.push(json!({"file": file, "from": src.display().to_string()}));
                }
            }
        }
        // Check the new files load before touching the working sample.
        for (_, obj, guide) in &repl {
            for p in [obj, guide].into_iter().flatten() {
                if let Err(e) = crate::io::load_visual(p, limits) {
                    failure = Some(format!("iteration {calls}: the agent command named an unreadable mesh: {e} (records in OUT/{rel})"));
                }
            }
        }
        if failure.is_some() {
            break;
        }
        for (name, obj, guide) in &repl {
            if let Some(p) = obj {
                std::fs::copy(p, sample.join(format!("{name}.glb")))
                    .map_err(|e| Error::io(p, e))?;
            }
            if let Some(p) = guide {
                std::fs::copy(p, sample.join(format!("guidance_{name}.glb")))
                    .map_err(|e| Error::io(p, e))?;
            }
        }
        let before = ratio;
        match compose_into(calls) {
            Ok((d, c, r)) => {
                composed = d;
                check = c;
                ratio = r;
            }
            Err(e) => {
                failure = Some(format!("iteration {calls}: recomposing with the agent's files failed: {e} (records in OUT/{rel})"));
                break;
            }
        }
        let attempt = json!({
            "iteration": calls,
            "penetration_ratio_before": before,
            "penetration_ratio_after": ratio,
            "success": ratio <= agent.threshold,
            "replaced": replaced,
            "note": note,
            "records": rel,
        });
        crate::fsutil::write(
            &rec.join("metrics.json"),
            &crate::fsutil::json_bytes(&json!({"penetration_ratio": ratio, "check": check}))?,
        )?;
        attempts.push(attempt);
    }
    let success = ratio <= agent.threshold;
    let record = json!({
        "enabled": true,
        "command": agent.command,
        "max_iterations": agent.max_iterations,
        "threshold": agent.threshold,
        "metric": "largest pair penetration depth / smaller object's bounding-box diagonal (visual meshes, composed poses)",
        "iterations": calls,
        "success": success,
        "final_penetration_ratio": ratio,
        "stop_reason": if failure.is_some() { "agent_error" } else if success { if calls == 0 { "no_penetration" } else { "success" } } else { "max_iterations" },
        "error": failure,
        "attempts": attempts,
    });
    // OUT: the last good composition, the records, and the agent_optimization record.
    let mpath = composed.join("metadata.json");
    let mut meta: Value =
        serde_json::from_slice(&std::fs::read(&mpath).map_err(|e| Error::io(&mpath, e))?)
            .map_err(|e| Error::Internal(format!("{}: {e}", mpath.display())))?;
    meta["agent_optimization"] = record.clone();
    crate::fsutil::write(&mpath, &crate::fsutil::json_bytes(&meta)?)?;
    crate::fsutil::write_dir_atomically(out, force, |tmp| {
        copy_tree(&composed, tmp)?;
        copy_tree(&agent_dir, &tmp.join("agent"))
    })?;
    if let Some(f) = failure {
        return Err(Error::Usage(format!(
            "compose --agent: {f}; {} written with the last good composition",
            out.display()
        )));
    }
    Ok(AgentOutcome {
        record,
        success,
        ratio,
        iterations: calls,
    })
}

/// Run `sh -c command` in `dir` with `stdin`; (stdout, stderr, status).
fn run_command(
    command: &str,
    stdin: &[u8],
    dir: &Path,
) -> std::io::Result<(String, String, std::process::ExitStatus)> {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(command)
        .current_dir(dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()?;
    let mut pipe = child.stdin.take().expect("piped stdin");
    let data = stdin.to_vec();
    let writer = std::thread::spawn(move || {
        // A command that does not read its stdin closes the pipe: not an error.
        let _ = pipe.write_all(&data);
    });
    let out = child.wait_with_output()?;
    let _ = writer.join();
    Ok((
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        out.status,
    ))
}
