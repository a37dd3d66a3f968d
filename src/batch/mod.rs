//! Batch conversion of a dataset: every scene under ROOT exported and validated in parallel into
//! a mirrored layout under OUT, resumable, shardable, with a summary.
//!
//! * **Discovery** ([`discover`]): every folder holding `metadata.json` or `scene.json`, sorted
//!   by relative path, filtered by `--include`/`--exclude` globs and `--shard I/N`.
//! * **Reuse**: each scene's output folder `OUT/<rel>/` holds a `batch.json` with a SHA-256 of
//!   the tool version, the options, the relative path and every input file ([`hash`]). A scene
//!   whose hash matches is not converted again.
//! * **Atomicity**: a scene is exported into `OUT/.interact3d-staging*/`, its `batch.json` added,
//!   and the finished folder renamed to `OUT/<rel>`; a killed run leaves only the staging folder,
//!   which the next run clears.
//! * **Isolation**: each scene runs under `catch_unwind`; an error or a panic becomes a row with
//!   verdict `error` and the batch goes on.
//! * **Bounded memory**: rayon workers take scenes from the list and send a small [`Row`] to the
//!   collector as each finishes; meshes and reports live only while their scene is in flight.
//! * **Shards sharing one OUT** (cluster array jobs, [`scheduler`] for `--shard auto`): a scene
//!   belongs to exactly one shard, so no two shards write the same scene folder; each shard has
//!   its own staging folder, held by a lock file (`.interact3d-staging-I-of-N.lock`) so a second
//!   process of the same shard stops at once, and its own summary `summary.shard-I-of-N.json`.
//!   The marker is created once (no replacing), and OUT counts as empty while it holds only our
//!   hidden files, so shards starting together on a fresh OUT do not refuse each other. A
//!   crashed shard is resumed by running the same index again.
//!
//! Entry points: [`run`], [`run_with`], [`scenes`], [`merge_reports`], [`counts_line`].

pub mod discover;
pub mod hash;
mod html;
pub mod scheduler;
pub mod summary;

pub use discover::{SceneEntry, SceneKind, Shard};
pub use scheduler::ShardArg;
pub use summary::{Counts, Row, RunInfo, SceneRecord, SceneResult, Summary, Verdict};

use crate::error::{Error, Result};
use crate::pipeline::{export_scene, ExportJob, Exported};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The marker file that makes a folder a batch output.
pub const MARKER: &str = ".interact3d-batch";
const MARKER_TEXT: &str =
    "interact3d batch output: scene folders, summary.json, summary.csv, index.html\n";

/// How progress is shown on stderr.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Progress {
    /// A progress bar when stderr is a terminal, else one line per finished scene.
    #[default]
    Auto,
    Bar,
    Lines,
    Quiet,
}

/// Everything a batch needs.
#[derive(Clone, Debug)]
pub struct BatchOptions {
    pub root: PathBuf,
    pub out: PathBuf,
    pub include: Vec<String>,
    pub exclude: Vec<String>,
    /// Worker threads (`None`: all cores).
    pub jobs: Option<usize>,
    pub shard: Option<Shard>,
    /// OUT must already hold a batch (guards against a mistyped OUT silently starting over).
    pub resume: bool,
    /// Convert every scene even when its output is current; accept an OUT that is not a batch.
    pub force: bool,
    /// What each scene goes through.
    pub job: ExportJob,
    pub progress: Progress,
}

impl BatchOptions {
    pub fn new(root: impl Into<PathBuf>, out: impl Into<PathBuf>, job: ExportJob) -> Self {
        BatchOptions {
            root: root.into(),
            out: out.into(),
            include: Vec::new(),
            exclude: Vec::new(),
            jobs: None,
            shard: None,
            resume: false,
            force: false,
            job,
            progress: Progress::Auto,
        }
    }
}

/// The scenes a batch with these options would process (after filters and shard), in order.
pub fn scenes(opts: &BatchOptions) -> Result<Vec<SceneEntry>> {
    let all = discover::discover(&opts.root, std::slice::from_ref(&opts.out))?;
    discover::select(all, &opts.include, &opts.exclude, opts.shard)
}

/// What converts one scene into a folder (the pipeline; tests inject failures).
pub type Worker<'w> = dyn Fn(&SceneEntry, &Path, &ExportJob) -> Result<Exported> + Sync + 'w;

/// Run the batch. Returns the summary (also written to OUT); an `Err` only for problems with
/// ROOT, OUT or the options, never for a scene.
pub fn run(opts: &BatchOptions) -> Result<Summary> {
    run_with(opts, &|e, out, job| export_scene(&e.dir, out, job))
}

/// [`run`] with another per-scene worker.
pub fn run_with(opts: &BatchOptions, worker: &Worker<'_>) -> Result<Summary> {
    let start = Instant::now();
    let entries = scenes(opts)?;
    if entries.is_empty() && opts.shard.is_none() {
        return Err(Error::input(
            &opts.root,
            "no scenes found (folders with metadata.json or scene.json, after --include/--exclude)",
        ));
    }
    prepare_out(opts)?;
    let staging = opts.out.join(match opts.shard {
        None => ".interact3d-staging".to_string(),
        Some(s) => format!(".interact3d-staging-{}-of-{}", s.index, s.count),
    });
    // Held until this function returns: the staging folder and the shard's summary are ours.
    let _lock = lock(&staging, opts.shard)?;
    // Whatever a killed run left in our staging folder is incomplete by construction.
    if staging.exists() {
        std::fs::remove_dir_all(&staging).map_err(|e| Error::io(&staging, e))?;
    }
    crate::fsutil::create_dir(&staging)?;

    let fingerprint = hash::options_fingerprint(&opts.job)?;
    let options_hash = hash::options_hash(&fingerprint);
    let jobs = opts.jobs.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.max(1))
        .thread_name(|i| format!("batch-{i}"))
        .build()
        .map_err(|e| Error::Internal(format!("thread pool: {e}")))?;
    let mut job = opts.job.clone();
    job.export.force = true; // the staging folder is ours
    let ctx = Ctx {
        out: &opts.out,
        staging: &staging,
        fingerprint: &fingerprint,
        force: opts.force,
        job: &job,
        worker,
    };

    let total = entries.len();
    let (tx, rx) = std::sync::mpsc::channel::<Row>();
    let rows = std::thread::scope(|s| {
        let progress = opts.progress;
        let collector = s.spawn(move || collect(rx, total, progress));
        pool.install(|| {
            entries
                .par_iter()
                .enumerate()
                .with_max_len(1)
                .for_each_with(tx, |tx, (i, e)| {
                    let _ = tx.send(ctx.process(i, e));
                })
        });
        collector.join()
    })
    .map_err(|_| Error::Internal("progress collector panicked".into()))?;

    let _ = std::fs::remove_dir_all(&staging);
    let reused = rows.iter().filter(|r| r.reused).count();
    let run = RunInfo {
        elapsed_s: (start.elapsed().as_secs_f64() * 1000.0).round() / 1000.0,
        jobs,
        converted: rows.len() - reused,
        reused,
        merged_from: Vec::new(),
    };
    let summary = Summary::new(
        opts.root.display().to_string(),
        opts.shard,
        options_hash,
        rows,
        run,
    );
    summary.write(&opts.out)?;
    Ok(summary)
}

/// Check OUT (missing, empty, or an earlier batch; anything with `force`) and mark it as ours.
fn prepare_out(opts: &BatchOptions) -> Result<()> {
    let out = &opts.out;
    let marker = out.join(MARKER);
    if out.exists() && !out.is_dir() {
        return Err(Error::Usage(format!(
            "{} exists and is not a folder",
            out.display()
        )));
    }
    let is_batch = marker.is_file();
    if opts.resume && !is_batch {
        return Err(Error::Usage(format!(
            "--resume: {} holds no earlier batch (no {MARKER}); leave out --resume to start one",
            out.display()
        )));
    }
    // Our hidden files (another shard's staging folder, lock or half-written marker) do not make
    // OUT foreign: shards starting together on a fresh OUT would otherwise refuse each other.
    let empty = std::fs::read_dir(out)
        .map(|mut it| {
            it.all(|e| e.is_ok_and(|e| e.file_name().to_string_lossy().starts_with(".interact3d")))
        })
        .unwrap_or(true);
    if !is_batch && !empty && !opts.force {
        return Err(Error::Usage(format!(
            "{} exists and is not an interact3d batch output; choose another folder or pass --force",
            out.display()
        )));
    }
    crate::fsutil::create_dir(out)?;
    if !is_batch {
        // Created once: a shard that lost the race leaves the winner's marker alone.
        crate::fsutil::write_new_atomically(&marker, MARKER_TEXT.as_bytes())?;
    }
    Ok(())
}

/// Take the lock of a staging folder (`<staging>.lock`, kept empty and never removed, so every
/// process locks the same inode). A second process of the same shard stops here with a usage
/// error rather than clearing the first one's staging folder under it.
fn lock(staging: &Path, shard: Option<Shard>) -> Result<std::fs::File> {
    let mut name = staging.as_os_str().to_owned();
    name.push(".lock");
    let path = PathBuf::from(name);
    let file = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&path)
        .map_err(|e| Error::io(&path, e))?;
    match try_lock(&file) {
        Ok(()) => Ok(file),
        Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => Err(Error::Usage(format!(
            "another interact3d batch is running {} in this OUT (it holds {}); \
             wait for it to end or stop it",
            shard.map_or("the whole selection".to_string(), |s| format!("shard {s}")),
            path.display()
        ))),
        // A file system without locks: go on unguarded, as before, but say so.
        Err(e) => {
            eprintln!(
                "warning: cannot lock {} ({e}); make sure no other process runs the same shard",
                path.display()
            );
            Ok(file)
        }
    }
}

/// An exclusive `flock`, without waiting; released when the file is closed (or the process
/// dies, so a crashed shard leaves no stale lock).
#[cfg(unix)]
fn try_lock(file: &std::fs::File) -> std::io::Result<()> {
    use rustix::fs::{flock, FlockOperation};
    flock(file, FlockOperation::NonBlockingLockExclusive).map_err(std::io::Error::from)
}

#[cfg(not(unix))]
fn try_lock(_file: &std::fs::File) -> std::io::Result<()> {
    Err(std::io::Error::other("no file locks on this platform"))
}

struct Ctx<'a> {
    out: &'a Path,
    staging: &'a Path,
    fingerprint: &'a [u8],
    force: bool,
    job: &'a ExportJob,
    worker: &'a Worker<'a>,
}

impl Ctx<'_> {
    /// One scene, start to finish; never fails, never panics out.
    fn process(&self, index: usize, e: &SceneEntry) -> Row {
        let t = Instant::now();
        let caught =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| self.convert(index, e)));
        let (scene, reused, error) = match caught {
            Ok(Ok((scene, reused))) => (scene, reused, None),
            Ok(Err(err)) => (None, false, Some(err.to_string())),
            Err(payload) => {
                let msg = payload
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| payload.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "unknown panic".into());
                (None, false, Some(format!("internal error (panic): {msg}")))
            }
        };
        let scene = match (scene, &error) {
            (Some(s), _) => s,
            (None, _) => {
                // Leave no half-made or stale output for a scene that now fails to convert.
                let _ = std::fs::remove_dir_all(self.staging.join(format!("{index:07}")));
                self.remove_stale(e);
                SceneResult::empty(&e.rel, e.id(), e.category(), Verdict::Error)
            }
        };
        Row {
            scene,
            error: error.map(|m| m.replace(['\n', '\r'], " ")),
            time_s: (t.elapsed().as_secs_f64() * 1000.0).round() / 1000.0,
            reused,
        }
    }

    /// Reuse the scene's output if current, else convert it. `Ok((result, reused))`.
    fn convert(&self, index: usize, e: &SceneEntry) -> Result<(Option<SceneResult>, bool)> {
        let hash = hash::scene_hash(e, self.fingerprint)?;
        let dest = self.out.join(&e.rel);
        if !self.force {
            if let Some(rec) = read_record(&dest) {
                if rec.hash == hash && rec.result.path == e.rel {
                    return Ok((Some(rec.result), true));
                }
            }
        }
        let stage = self.staging.join(format!("{index:07}"));
        let exported = (self.worker)(e, &stage, self.job)?;
        let mut result = SceneResult::from_export(
            &e.rel,
            e.id(),
            e.category(),
            &exported.report,
            exported.validation.as_ref(),
        );
        result.rendered = exported.rendered;
        drop(exported);
        let record = SceneRecord {
            tool: "interact3d".into(),
            version: env!("CARGO_PKG_VERSION").into(),
            hash,
            result: result.clone(),
        };
        crate::fsutil::write(
            &stage.join("batch.json"),
            &crate::fsutil::json_bytes(&record)?,
        )?;
        self.install(index, &stage, &dest)?;
        Ok((Some(result), false))
    }

    /// Move the finished folder to its place, replacing an earlier output of ours.
    fn install(&self, index: usize, stage: &Path, dest: &Path) -> Result<()> {
        if let Some(parent) = dest.parent() {
            crate::fsutil::create_dir(parent)?;
        }
        if dest.exists() {
            if !ours(dest) {
                return Err(Error::Usage(format!(
                    "{} exists and is not an interact3d output; move it away or remove it",
                    dest.display()
                )));
            }
            let old = self.staging.join(format!("{index:07}.old"));
            std::fs::rename(dest, &old).map_err(|e| Error::io(dest, e))?;
            if let Err(err) = std::fs::rename(stage, dest) {
                let _ = std::fs::rename(&old, dest);
                return Err(Error::io(dest, err));
            }
            let _ = std::fs::remove_dir_all(&old);
        } else {
            std::fs::rename(stage, dest).map_err(|e| Error::io(dest, e))?;
        }
        Ok(())
    }

    fn remove_stale(&self, e: &SceneEntry) {
        let dest = self.out.join(&e.rel);
        if dest.join("batch.json").is_file() {
            let _ = std::fs::remove_dir_all(&dest);
        }
    }
}

/// A scene output's record, if it has a readable one.
fn read_record(dest: &Path) -> Option<SceneRecord> {
    let bytes = std::fs::read(dest.join("batch.json")).ok()?;
    serde_json::from_slice(&bytes).ok()
}

/// Whether a folder may be replaced: ours (batch.json or an interact3d report.json) or empty.
fn ours(dir: &Path) -> bool {
    dir.join("batch.json").is_file()
        || std::fs::read_to_string(dir.join("report.json"))
            .map(|s| s.contains("\"tool\": \"interact3d\""))
            .unwrap_or(false)
        || std::fs::read_dir(dir)
            .map(|mut it| it.next().is_none())
            .unwrap_or(false)
}

/// Receive rows as scenes finish, show progress, return all rows.
fn collect(rx: std::sync::mpsc::Receiver<Row>, total: usize, progress: Progress) -> Vec<Row> {
    let bar = match progress {
        Progress::Bar => true,
        Progress::Auto => std::io::stderr().is_terminal(),
        Progress::Lines | Progress::Quiet => false,
    };
    let pb = bar.then(|| {
        let pb = ProgressBar::with_draw_target(Some(total as u64), ProgressDrawTarget::stderr());
        pb.set_style(
            ProgressStyle::with_template(
                "{elapsed_precise} [{wide_bar}] {pos}/{len} {msg} {per_sec} ETA {eta}",
            )
            .expect("valid template")
            .progress_chars("=> "),
        );
        pb
    });
    let start = Instant::now();
    let mut c = Counts::default();
    let mut converted = 0usize;
    let mut rows = Vec::with_capacity(total);
    for row in rx {
        c.scenes += 1;
        converted += usize::from(!row.reused);
        match row.scene.verdict {
            Verdict::Pass => c.pass += 1,
            Verdict::Fail => c.fail += 1,
            Verdict::Error => c.error += 1,
        }
        let counts = format!("pass {} fail {} error {}", c.pass, c.fail, c.error);
        if let Some(pb) = &pb {
            if let Some(err) = &row.error {
                pb.println(format!("error {}: {err}", row.scene.path));
            }
            pb.set_message(counts);
            pb.inc(1);
        } else if progress != Progress::Quiet {
            eprintln!(
                "[{:>w$}/{total}] {:<5} {} ({}) | {counts} | {}{}",
                c.scenes,
                row.scene.verdict.as_str(),
                row.scene.path,
                if row.reused {
                    "reused".to_string()
                } else {
                    format!("{:.2} s", row.time_s)
                },
                speed(converted, start.elapsed().as_secs_f64(), total - c.scenes),
                row.error
                    .as_ref()
                    .map(|e| format!("\n    {e}"))
                    .unwrap_or_default(),
                w = total.to_string().len(),
            );
        }
        rows.push(row);
    }
    if let Some(pb) = pb {
        pb.finish_and_clear();
    }
    rows
}

/// The conversion speed and ETA: scenes converted (reused ones do not count: checking a hash
/// is not converting) per minute of wall time, or "reused" while nothing was converted yet.
fn speed(converted: usize, elapsed_s: f64, left: usize) -> String {
    if converted == 0 {
        return "all reused so far".into();
    }
    let per_s = converted as f64 / elapsed_s.max(1e-9);
    format!(
        "{:.1} scenes/min converting, ETA {:.0} s",
        per_s * 60.0,
        left as f64 / per_s
    )
}

/// The result of `--merge-reports`.
pub struct Merged {
    pub summary: Summary,
    pub warnings: Vec<String>,
    /// Some shard summaries are missing, so the merge does not cover the dataset.
    pub incomplete: bool,
}

/// Merge the shard summaries in `inputs` (files, or folders holding `summary.shard-*.json`;
/// OUT itself when empty) into `OUT/summary.json`, `summary.csv` and `index.html`.
pub fn merge_reports(out: &Path, inputs: &[PathBuf]) -> Result<Merged> {
    let inputs = if inputs.is_empty() {
        vec![out.to_path_buf()]
    } else {
        inputs.to_vec()
    };
    let files = summary::shard_files(&inputs)?;
    let (summary, warnings) = summary::merge(&files)?;
    let incomplete = warnings.iter().any(|w| w.starts_with("missing shard"));
    crate::fsutil::create_dir(out)?;
    summary.write(out)?;
    Ok(Merged {
        summary,
        warnings,
        incomplete,
    })
}

/// One-line text of the counts, for the end of a run.
pub fn counts_line(s: &Summary) -> String {
    let rate = if s.run.converted > 0 {
        format!(
            ", {:.1} scenes/min converted",
            s.run.converted as f64 * 60.0 / s.run.elapsed_s.max(1e-3)
        )
    } else {
        String::new()
    };
    format!(
        "{} scenes: {} pass, {} fail, {} error ({} converted, {} reused) in {:.1} s{rate}",
        s.counts.scenes,
        s.counts.pass,
        s.counts.fail,
        s.counts.error,
        s.run.converted,
        s.run.reused,
        s.run.elapsed_s
    )
}

#[cfg(test)]
mod tests;
