//! `interact3d batch` on generated datasets in the nine-category layout: good scenes converted and
//! broken ones reported (exit 2), a second run reuses everything, shards partition the dataset
//! and merge back, and a run killed midway then resumed gives the bytes of one clean run.

mod batch_data;
mod common;

use batch_data::{make_dataset, Made, Spec};
use common::*;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Validation settings that keep the tests fast (R_volume on 20k points instead of 1M).
const FAST: [&str; 2] = ["--points", "20000"];

fn batch(root: &Path, out: &Path, extra: &[&str]) -> (i32, String, String) {
    let mut args = vec![
        "batch",
        root.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--progress",
        "lines",
    ];
    args.extend_from_slice(&FAST);
    args.extend_from_slice(extra);
    run(&args)
}

/// A generated dataset in a new temporary folder: (the folder, its `data` root, the scenes made).
fn dataset(good: usize, failing: usize, broken: bool) -> (tempfile::TempDir, PathBuf, Vec<Made>) {
    let t = tempfile::tempdir().unwrap();
    let root = t.path().join("data");
    let made = make_dataset(
        &root,
        Spec {
            good,
            failing,
            broken,
        },
    );
    (t, root, made)
}

/// `batch --list` with `extra` options: the selected scenes, one relative path each.
fn list(root: &Path, out: &Path, extra: &[&str]) -> Vec<String> {
    let (code, stdout, err) = batch(root, out, &[&["--list"], extra].concat());
    assert_eq!(code, 0, "{err}");
    stdout.lines().map(str::to_string).collect()
}

fn rows(summary: &Value) -> &Vec<Value> {
    summary["scenes"].as_array().unwrap()
}

#[test]
fn converts_good_scenes_reports_broken_ones_and_a_rerun_reuses_them() {
    let (t, root, made) = dataset(9, 1, true);
    assert_eq!(made.len(), 12);
    let out = t.path().join("out");

    let t0 = Instant::now();
    let (code, _, err) = batch(&root, &out, &["--jobs", "2"]);
    let first = t0.elapsed();
    assert_eq!(code, 2, "broken scenes make the exit code 2:\n{err}");
    let s = read_json(&out.join("summary.json"));
    assert_eq!(s["counts"]["scenes"], 12);
    assert_eq!(s["counts"]["pass"], 9, "{err}");
    assert_eq!(s["counts"]["fail"], 1);
    assert_eq!(s["counts"]["error"], 2);
    assert_eq!(s["exit_code"], 2);
    let r = rows(&s);
    for (m, row) in made.iter().zip(r) {
        assert_eq!(row["path"], m.rel.as_str(), "stable order by path");
        assert_eq!(row["verdict"], m.verdict, "{}: {row}", m.rel);
        let dir = out.join(&m.rel);
        if m.verdict == "error" {
            assert!(!dir.exists(), "no output for {}", m.rel);
            let e = row["error"].as_str().unwrap();
            assert!(
                e.contains(&m.rel) || e.contains("metadata.json") || e.contains(".glb"),
                "{e}"
            );
        } else {
            for f in ["scene.xml", "report.json", "scene.json", "batch.json"] {
                assert!(dir.join(f).is_file(), "{}/{f}", m.rel);
            }
            let rec = read_json(&dir.join("batch.json"));
            assert_eq!(rec["verdict"], m.verdict);
            assert_eq!(rec["hash"].as_str().unwrap().len(), 64);
            assert_eq!(row["objects"], 2);
            assert_eq!(row["hulls"].as_array().unwrap().len(), 2);
            assert!(row["r_volume"].is_number() && row["max_displacement_m"].is_number());
            assert_eq!(row["category"], m.rel.split('/').nth(1).unwrap());
        }
    }
    // The failing scene says which check failed.
    let fail = r.iter().find(|x| x["verdict"] == "fail").unwrap();
    assert!(
        fail["failed_checks"]
            .to_string()
            .contains("visual_penetration"),
        "{fail}"
    );
    // CSV: header + one line per scene; HTML: self-contained.
    let csv = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 13);
    assert!(lines[0].starts_with("path,id,category,objects,verdict,r_volume,max_penetration_m"));
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("<table") && html.contains("00001_box_on_box"));
    assert!(
        !html.contains("http://") && !html.contains("https://"),
        "no network"
    );
    assert!(!out.join(".interact3d-staging").exists());

    // Second run: nothing to convert but the two broken scenes (retried, they fail at once).
    let before = snapshot_scenes(&out, &made);
    let ids_before = file_identities(&out, &made);
    let t1 = Instant::now();
    let (code2, _, err2) = batch(&root, &out, &["--jobs", "2"]);
    let second = t1.elapsed();
    assert_eq!(code2, 2, "{err2}");
    let s2 = read_json(&out.join("summary.json"));
    assert_eq!(s2["run"]["reused"], 10, "{err2}");
    assert_eq!(s2["run"]["converted"], 2);
    assert_eq!(
        before,
        snapshot_scenes(&out, &made),
        "reused folders untouched"
    );
    // The work check: converting writes every file anew (temporary path, then rename), so a
    // reused scene's files keep their inode and modification time. Output is deterministic, so
    // the bytes above could not tell a reconversion from a reuse. The times are printed only:
    // a wall-clock ratio failed CI once on a 66 ms first run, and timing belongs in benches.
    assert_eq!(
        ids_before,
        file_identities(&out, &made),
        "reused scenes are not written again"
    );
    eprintln!(
        "first run {:.2} s, second {:.2} s ({:.1}%)",
        first.as_secs_f64(),
        second.as_secs_f64(),
        100.0 * second.as_secs_f64() / first.as_secs_f64()
    );

    // A changed option converts everything again.
    let (code3, _, _) = batch(&root, &out, &["--jobs", "2", "--max-hulls", "8"]);
    assert_eq!(code3, 2);
    assert_eq!(read_json(&out.join("summary.json"))["run"]["reused"], 0);
    // ... and the work check sees it: every converted scene's files are new.
    let ids_after = file_identities(&out, &made);
    assert!(
        ids_after.iter().all(|f| !ids_before.contains(f)),
        "a reconversion writes new files"
    );
}

fn snapshot_scenes(out: &Path, made: &[Made]) -> Vec<(String, Vec<u8>)> {
    made.iter()
        .filter(|m| out.join(&m.rel).exists())
        .flat_map(|m| {
            snapshot(&out.join(&m.rel))
                .into_iter()
                .map(move |(f, b)| (format!("{}/{f}", m.rel), b))
        })
        .collect()
}

/// (path, inode, modification time in ns) of every file under the scenes' output folders.
fn file_identities(out: &Path, made: &[Made]) -> Vec<(String, u64, i128)> {
    use std::os::unix::fs::MetadataExt;
    let mut v: Vec<_> = made
        .iter()
        .map(|m| out.join(&m.rel))
        .filter(|d| d.exists())
        .flat_map(|d| walk(&d))
        .map(|f| {
            let md = std::fs::symlink_metadata(&f).unwrap();
            let ns = md.mtime() as i128 * 1_000_000_000 + md.mtime_nsec() as i128;
            (f.display().to_string(), md.ino(), ns)
        })
        .collect();
    v.sort();
    v
}

/// Start `interact3d batch ROOT -o OUT --shard auto` as task `id` of a Slurm array 0..=max,
/// with the variables sbatch sets (and no other scheduler's).
fn slurm_task(root: &Path, out: &Path, id: usize, max: usize) -> std::process::Child {
    let mut args = vec![
        "batch",
        root.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--jobs",
        "1",
        "--progress",
        "quiet",
        "--shard",
        "auto",
    ];
    args.extend_from_slice(&FAST);
    std::process::Command::new(env!("CARGO_BIN_EXE_interact3d"))
        .args(&args)
        .env("SLURM_ARRAY_TASK_ID", id.to_string())
        .env("SLURM_ARRAY_TASK_MIN", "0")
        .env("SLURM_ARRAY_TASK_MAX", max.to_string())
        .env("SLURM_ARRAY_TASK_STEP", "1")
        .env("SLURM_ARRAY_TASK_COUNT", (max + 1).to_string())
        .env_remove("JOB_COMPLETION_INDEX")
        .env_remove("AWS_BATCH_JOB_ARRAY_INDEX")
        .env_remove("INTERACT3D_SHARDS")
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

/// Issue #38: three array tasks write into one OUT at the same time (`--shard auto` from the
/// Slurm variables), one is killed midway and run again with the same index, and the merge
/// equals a one-machine run: same scene files byte for byte, same summary, CSV and index but
/// for the times. Also #36: the merged files are readable by others (0644 under umask 022).
#[test]
fn shards_cover_every_scene_exactly_once_and_merge_back() {
    let (t, root, made) = dataset(9, 1, true);
    let out = t.path().join("out");
    let list = |extra: &[&str]| list(&root, &out, extra);
    let all = list(&[]);
    assert_eq!(all, made.iter().map(|m| m.rel.clone()).collect::<Vec<_>>());
    let parts: Vec<Vec<String>> = (1..=3)
        .map(|i| list(&["--shard", &format!("{i}/3")]))
        .collect();
    let mut union: Vec<String> = parts.concat();
    union.sort();
    assert_eq!(union, all, "every scene in exactly one shard");
    assert!(!out.exists(), "--list writes nothing");

    // The reference: one process, the whole dataset.
    let single = t.path().join("single");
    let (code_single, _, err) = batch(&root, &single, &["--jobs", "1"]);
    assert_eq!(code_single, 2, "two broken scenes: {err}");

    // Three array tasks (ids 0, 1, 2) at once into a fresh OUT; the biggest shard is killed
    // as soon as one of its scenes is in place.
    let victim = (0..3).max_by_key(|&i| parts[i].len()).unwrap();
    assert!(parts[victim].len() >= 2, "{parts:?}");
    let mut tasks: Vec<_> = (0..3).map(|id| slurm_task(&root, &out, id, 2)).collect();
    let done = |rel: &String| out.join(rel).join("batch.json").is_file();
    let deadline = Instant::now() + Duration::from_secs(120);
    while !parts[victim].iter().any(done) {
        assert!(
            Instant::now() < deadline,
            "no scene of shard {} in 120 s",
            victim + 1
        );
        assert!(
            tasks[victim].try_wait().unwrap().is_none(),
            "shard {} finished before the kill",
            victim + 1
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    tasks[victim].kill().unwrap(); // SIGKILL: a crashed node
    tasks[victim].wait().unwrap();
    let finished = parts[victim].iter().filter(|r| done(r)).count();
    for (i, task) in tasks.into_iter().enumerate().filter(|(i, _)| *i != victim) {
        let o = task.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains(&format!(
                "shard {}/3 from Slurm array task {i} of 0..=2",
                i + 1
            )),
            "{err}"
        );
        assert!(matches!(o.status.code(), Some(0..=2)), "task {i}: {err}");
        assert!(out
            .join(format!("summary.shard-{}-of-3.json", i + 1))
            .is_file());
    }
    let victim_summary = out.join(format!("summary.shard-{}-of-3.json", victim + 1));
    assert!(!victim_summary.exists());
    // Merging now says a shard is missing (exit 2).
    let merge = || {
        std::process::Command::new("sh")
            .args(["-c", "umask 022; exec \"$0\" \"$@\""])
            .arg(env!("CARGO_BIN_EXE_interact3d"))
            .args(["batch", "--merge-reports", "-o", out.to_str().unwrap()])
            .output()
            .unwrap()
    };
    let m = merge();
    assert_eq!(m.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&m.stderr).contains("missing shard"));

    // The crashed task is run again with the same array index: its finished scenes are reused.
    let o = slurm_task(&root, &out, victim, 2)
        .wait_with_output()
        .unwrap();
    assert!(
        matches!(o.status.code(), Some(0..=2)),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let vs = read_json(&victim_summary);
    assert_eq!(vs["run"]["reused"], finished);
    assert_eq!(
        vs["run"]["converted"].as_u64().unwrap() as usize,
        parts[victim].len() - finished
    );

    let m = merge();
    assert_eq!(
        m.status.code(),
        Some(code_single),
        "{}",
        String::from_utf8_lossy(&m.stderr)
    );
    // Same files (scene folders byte for byte) apart from the summaries and our hidden files.
    let summaries = ["summary.json", "summary.csv", "index.html"];
    let files = |d: &Path| -> Vec<(String, Vec<u8>)> {
        snapshot(d)
            .into_iter()
            .filter(|(f, _)| !summaries.contains(&f.as_str()) && !f.starts_with('.'))
            .filter(|(f, _)| !f.starts_with("summary.shard-"))
            .collect()
    };
    let (a, b) = (files(&single), files(&out));
    assert_same_files(&a, &b);
    let merged = read_json(&out.join("summary.json"));
    assert_eq!(merged["counts"]["scenes"], made.len());
    assert_eq!(
        stable(read_json(&single.join("summary.json"))),
        stable(merged)
    );
    let csv = |d: &Path| stable_csv(&std::fs::read_to_string(d.join("summary.csv")).unwrap());
    assert_eq!(csv(&single), csv(&out));
    let html = |d: &Path| stable_html(&std::fs::read_to_string(d.join("index.html")).unwrap());
    assert_eq!(html(&single), html(&out));

    // Readable by other users and web servers, as export files are.
    use std::os::unix::fs::PermissionsExt;
    let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    for f in ["summary.json", "summary.csv", "index.html"] {
        assert_eq!(mode(&out.join(f)), 0o644, "{f}");
    }
}

/// The summary without what legitimately differs between runs: timings, reuse flags, run info.
fn stable(mut s: Value) -> Value {
    s.as_object_mut().unwrap().remove("run");
    for r in s["scenes"].as_array_mut().unwrap() {
        let r = r.as_object_mut().unwrap();
        r.remove("time_s");
        r.remove("reused");
    }
    s
}

/// Parse CSV (RFC 4180 quoting) and drop the columns time_s and reused.
fn stable_csv(text: &str) -> Vec<Vec<String>> {
    let mut rows = Vec::new();
    let (mut row, mut field, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            (true, '"') => quoted = false,
            (true, c) => field.push(c),
            (false, '"') => quoted = true,
            (false, ',') => row.push(std::mem::take(&mut field)),
            (false, '\n') => {
                row.push(std::mem::take(&mut field));
                rows.push(std::mem::take(&mut row));
            }
            (false, c) => field.push(c),
        }
    }
    let header = rows[0].clone();
    let drop: Vec<usize> = ["time_s", "reused"]
        .iter()
        .map(|c| header.iter().position(|h| h == c).unwrap())
        .collect();
    rows.into_iter()
        .map(|r| {
            r.into_iter()
                .enumerate()
                .filter(|(i, _)| !drop.contains(i))
                .map(|(_, f)| f)
                .collect()
        })
        .collect()
}

/// index.html is the page with the summary embedded: compare the page around the data, and the
/// data as JSON without timings.
fn stable_html(html: &str) -> (String, Value) {
    let start = html.find("const DATA = ").unwrap() + "const DATA = ".len();
    let end = start + html[start..].find(";\nconst COLS").unwrap();
    let data: Value = serde_json::from_str(&html[start..end]).unwrap();
    (format!("{}{}", &html[..start], &html[end..]), stable(data))
}

#[test]
fn a_run_killed_midway_then_resumed_equals_one_clean_run() {
    let (t, root, made) = dataset(6, 1, true);
    let clean = t.path().join("clean");
    let (code_clean, _, err) = batch(&root, &clean, &["--jobs", "1"]);
    assert_eq!(code_clean, 2, "{err}");

    // Start the same run, kill -9 it as soon as the first scene folder is in place.
    let killed = t.path().join("killed");
    let mut args: Vec<String> = [
        "batch",
        root.to_str().unwrap(),
        "-o",
        killed.to_str().unwrap(),
        "--jobs",
        "1",
        "--progress",
        "quiet",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    args.extend(FAST.iter().map(|s| s.to_string()));
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_interact3d"))
        .args(&args)
        .spawn()
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(120);
    let done = |m: &Made| killed.join(&m.rel).join("batch.json").is_file();
    while !made.iter().any(done) {
        assert!(Instant::now() < deadline, "no scene finished in 120 s");
        assert!(
            child.try_wait().unwrap().is_none(),
            "finished before the kill"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let finished = made.iter().filter(|m| done(m)).count();
    assert!(
        finished < made.len() - 2,
        "killed too late ({finished} done)"
    );
    // No half-written scene folder: every folder in place is complete.
    for m in &made {
        let d = killed.join(&m.rel);
        assert!(!d.exists() || d.join("batch.json").is_file(), "{}", m.rel);
    }
    assert!(!killed.join("summary.json").exists());

    let (code, _, err) = batch(&root, &killed, &["--jobs", "1", "--resume"]);
    assert_eq!(code, code_clean, "{err}");
    let s = read_json(&killed.join("summary.json"));
    assert_eq!(s["run"]["reused"], finished);

    // Byte for byte: every file but the three summaries, which differ only in timings.
    let summaries = ["summary.json", "summary.csv", "index.html"];
    let files = |d: &Path| -> Vec<(String, Vec<u8>)> {
        snapshot(d)
            .into_iter()
            .filter(|(f, _)| !summaries.contains(&f.as_str()))
            .collect()
    };
    let (a, b) = (files(&clean), files(&killed));
    assert_same_files(&a, &b);
    assert_eq!(
        stable(read_json(&clean.join("summary.json"))),
        stable(read_json(&killed.join("summary.json")))
    );
    let csv = |d: &Path| stable_csv(&std::fs::read_to_string(d.join("summary.csv")).unwrap());
    assert_eq!(csv(&clean), csv(&killed));
    let html = |d: &Path| stable_html(&std::fs::read_to_string(d.join("index.html")).unwrap());
    assert_eq!(html(&clean), html(&killed));
}

#[test]
fn filters_and_usage_errors() {
    let (t, root, _) = dataset(9, 0, false);
    let out = t.path().join("out");
    let list = |extra: &[&str]| list(&root, &out, extra);
    assert_eq!(
        list(&["--include", "outputs/{food,toys}/**"]),
        [
            "outputs/food/00003_tower_on_box",
            "outputs/toys/00009_tower_on_box"
        ]
    );
    assert_eq!(
        list(&[
            "--include",
            "outputs/{food,toys}/**",
            "--exclude",
            "**/00009_*"
        ]),
        ["outputs/food/00003_tower_on_box"]
    );
    assert_eq!(list(&["--exclude", "**/*_on_box"]).len(), 0);
    // No scenes, a missing ROOT, a foreign OUT, --resume with nothing to resume: exit 2.
    let empty = t.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    assert_eq!(batch(&empty, &out, &[]).0, 2);
    assert_eq!(batch(&t.path().join("missing"), &out, &[]).0, 2);
    let foreign = t.path().join("foreign");
    std::fs::create_dir_all(&foreign).unwrap();
    std::fs::write(foreign.join("notes.txt"), b"mine").unwrap();
    let (code, _, err) = batch(&root, &foreign, &[]);
    assert_eq!(code, 2);
    assert!(err.contains("not an interact3d batch"), "{err}");
    let (code, _, err) = batch(&root, &t.path().join("fresh"), &["--resume"]);
    assert_eq!(code, 2);
    assert!(err.contains("--resume"), "{err}");
    assert!(!t.path().join("fresh").exists());
}

/// Two snapshots hold the same file names (more than 30 of them) with the same bytes.
fn assert_same_files(a: &[(String, Vec<u8>)], b: &[(String, Vec<u8>)]) {
    assert_eq!(
        a.iter().map(|x| &x.0).collect::<Vec<_>>(),
        b.iter().map(|x| &x.0).collect::<Vec<_>>(),
        "same files"
    );
    assert!(a.len() > 30);
    for (x, y) in a.iter().zip(b) {
        assert!(x.1 == y.1, "{} differs", x.0);
    }
}
