//! The cluster examples under `examples/cluster/` run as written (issue #38): the Slurm array
//! script under the variables sbatch sets (a real Slurm: `examples/cluster/slurm/
//! run_local_slurm.sh`, too slow for CI), the Kubernetes Indexed Job's container command once
//! per completion index, and the GitHub Actions matrix's `run:` steps once per matrix job in
//! separate folders (separate machines) whose outputs are then put together as
//! `download-artifact` with `merge-multiple` does. Each ends with `--merge-reports` covering
//! every scene of the dataset exactly once.

mod batch_data;
mod common;

use batch_data::{make_dataset, Made, Spec};
use common::*;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Fewer R_volume points than the examples' defaults, to keep the tests fast.
const FAST: [&str; 2] = ["--points", "20000"];

fn examples() -> PathBuf {
    root().join("examples/cluster")
}

/// A folder holding `interact3d` (a link to the built binary), for PATH.
fn bin_dir(t: &Path) -> String {
    let bin = t.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_interact3d"), bin.join("interact3d")).unwrap();
    format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    )
}

/// A command with no scheduler variables inherited from wherever the tests run.
fn clean(mut c: Command, path: &str) -> Command {
    for v in [
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_MIN",
        "SLURM_ARRAY_TASK_MAX",
        "SLURM_ARRAY_TASK_COUNT",
        "SLURM_ARRAY_TASK_STEP",
        "JOB_COMPLETION_INDEX",
        "AWS_BATCH_JOB_ARRAY_INDEX",
        "INTERACT3D_SHARDS",
    ] {
        c.env_remove(v);
    }
    c.env("PATH", path);
    c
}

fn output(mut c: Command) -> (i32, String) {
    let o = c.output().unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.code().unwrap_or(-1), text)
}

/// The merged summary in `out` lists exactly the dataset's scenes, all passing.
fn assert_complete(out: &Path, made: &[Made]) {
    let s = read_json(&out.join("summary.json"));
    let paths: Vec<&str> = s["scenes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["path"].as_str().unwrap())
        .collect();
    assert_eq!(
        paths,
        made.iter().map(|m| m.rel.as_str()).collect::<Vec<_>>()
    );
    assert_eq!(s["counts"]["pass"], made.len(), "{s}");
    for m in made {
        assert!(out.join(&m.rel).join("batch.json").is_file(), "{}", m.rel);
    }
}

fn dataset(t: &Path) -> (PathBuf, Vec<Made>) {
    let root = t.join("data");
    let made = make_dataset(
        &root,
        Spec {
            good: 5,
            failing: 0,
            broken: false,
        },
    );
    (root, made)
}

#[test]
fn slurm_array_script_runs_as_sbatch_would_from_id_1() {
    let t = tempfile::tempdir().unwrap();
    let path = bin_dir(t.path());
    let (root, made) = dataset(t.path());
    let out = t.path().join("out");
    let script = examples().join("slurm/convert.sbatch");
    // `#SBATCH --array=1-3`: ids 1, 2, 3 (the script's own default starts at 0; both work).
    for id in 1..=3 {
        let mut c = clean(Command::new("bash"), &path);
        c.arg(&script).arg(&root).arg(&out).args(FAST);
        for (k, v) in [
            ("SLURM_ARRAY_TASK_ID", id),
            ("SLURM_ARRAY_TASK_MIN", 1),
            ("SLURM_ARRAY_TASK_MAX", 3),
            ("SLURM_ARRAY_TASK_COUNT", 3),
            ("SLURM_ARRAY_TASK_STEP", 1),
            ("SLURM_CPUS_PER_TASK", 1),
        ] {
            c.env(k, v.to_string());
        }
        let (code, text) = output(c);
        assert_eq!(code, 0, "task {id}: {text}");
        assert!(text.contains(&format!("shard {id}/3 from Slurm")), "{text}");
    }
    // The merge before all summaries exist is refused; here all three are there.
    let mut c = clean(Command::new("bash"), &path);
    c.arg(examples().join("slurm/merge.sbatch")).arg(&out);
    let (code, text) = output(c);
    assert_eq!(code, 0, "{text}");
    assert_complete(&out, &made);
    // Outside an array the script stops with the error naming the variables (exit 2).
    let mut c = clean(Command::new("bash"), &path);
    c.arg(&script).arg(&root).arg(t.path().join("out2"));
    let (code, text) = output(c);
    assert_eq!(code, 2, "{text}");
    assert!(
        text.contains("SLURM_ARRAY_TASK_ID") && text.contains("JOB_COMPLETION_INDEX"),
        "{text}"
    );
}

/// The container's `sh -c` script with the volume's mount point moved to `data` and FAST added,
/// and its environment.
fn container_script(job: &Value, data: &Path) -> (String, Vec<(String, String)>) {
    let c = &job["spec"]["template"]["spec"]["containers"][0];
    let mount = c["volumeMounts"][0]["mountPath"].as_str().unwrap();
    assert_eq!(c["command"], serde_json::json!(["sh", "-c"]));
    let script = c["args"][0]
        .as_str()
        .unwrap()
        .replace(&format!("{mount}/"), &format!("{}/", data.display()));
    assert!(script.starts_with("interact3d batch "), "{script}");
    let script = script.replacen(
        "interact3d batch ",
        &format!("interact3d batch {} ", FAST.join(" ")),
        1,
    );
    let env = c["env"]
        .as_array()
        .map(|v| {
            v.iter()
                .map(|e| {
                    (
                        e["name"].as_str().unwrap().to_string(),
                        e["value"].as_str().unwrap().to_string(),
                    )
                })
                .collect()
        })
        .unwrap_or_default();
    (script, env)
}

#[test]
fn kubernetes_indexed_job_runs_once_per_completion_index() {
    let t = tempfile::tempdir().unwrap();
    let path = bin_dir(t.path());
    let data = t.path().join("volume");
    let (root, made) = dataset(&data);
    std::fs::rename(&root, data.join("scenes")).unwrap();
    let job = python_json(
        "yaml_to_json.py",
        &[examples()
            .join("kubernetes/indexed-job.yaml")
            .to_str()
            .unwrap()],
    );
    assert_eq!(job["kind"], "Job");
    assert_eq!(job["spec"]["completionMode"], "Indexed");
    let n = job["spec"]["completions"].as_u64().unwrap();
    let (script, env) = container_script(&job, &data);
    assert!(
        env.contains(&("INTERACT3D_SHARDS".into(), n.to_string())),
        "INTERACT3D_SHARDS must equal completions: {env:?}"
    );
    let run = |index: u64| {
        let mut c = clean(Command::new("sh"), &path);
        c.args(["-c", &script]).envs(env.iter().cloned());
        c.env("JOB_COMPLETION_INDEX", index.to_string());
        output(c)
    };
    for i in 0..n {
        let (code, text) = run(i);
        assert_eq!(code, 0, "index {i}: {text}");
        assert!(text.contains(&format!("shard {}/{n} from JOB_COMPLETION_INDEX", i + 1)));
    }
    // An index past the count (completions raised but not INTERACT3D_SHARDS) fails the pod.
    let (code, text) = run(n);
    assert_ne!(code, 0, "{text}");
    assert!(text.contains(&format!("outside 1..={n}")), "{text}");
    let merge = python_json(
        "yaml_to_json.py",
        &[examples()
            .join("kubernetes/merge-job.yaml")
            .to_str()
            .unwrap()],
    );
    let c = &merge["spec"]["template"]["spec"]["containers"][0];
    let mount = c["volumeMounts"][0]["mountPath"].as_str().unwrap();
    let cmd: Vec<String> = c["command"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_str().unwrap().replace(mount, data.to_str().unwrap()))
        .collect();
    let mut c = clean(Command::new(&cmd[0]), &path);
    c.args(&cmd[1..]);
    let (code, text) = output(c);
    assert_eq!(code, 0, "{text}");
    assert_complete(&data.join("out"), &made);
}

#[test]
fn github_matrix_jobs_on_separate_machines_merge_from_their_artifacts() {
    let t = tempfile::tempdir().unwrap();
    let path = bin_dir(t.path());
    let (root, made) = dataset(t.path());
    let wf = python_json(
        "yaml_to_json.py",
        &[examples().join("github/batch-matrix.yml").to_str().unwrap()],
    );
    let runs = |job: &str| -> Vec<String> {
        wf["jobs"][job]["steps"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|s| s["run"].as_str())
            .filter(|r| r.contains("interact3d batch"))
            .map(str::to_string)
            .collect()
    };
    let shards: Vec<String> = wf["jobs"]["convert"]["strategy"]["matrix"]["shard"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.to_string())
        .collect();
    assert!(shards.len() >= 2);
    let convert = runs("convert");
    assert_eq!(convert.len(), 1, "{convert:?}");
    // The merge job's folder, filled as download-artifact with merge-multiple does.
    let merged = t.path().join("merge");
    std::fs::create_dir_all(merged.join("out")).unwrap();
    for s in &shards {
        let machine = t.path().join(format!("job-{s}"));
        std::fs::create_dir_all(machine.join("data")).unwrap();
        std::os::unix::fs::symlink(&root, machine.join("data/scenes")).unwrap();
        let line = convert[0].replace("${{ matrix.shard }}", s).replace(
            "--progress lines",
            &format!("--progress lines {}", FAST.join(" ")),
        );
        let mut c = clean(Command::new("bash"), &path);
        c.args(["-e", "-c", &line]).current_dir(&machine);
        let (code, text) = output(c);
        assert_eq!(code, 0, "shard {s}: {text}");
        // The artifact: no file of one job may land on another's (the marker is identical).
        for f in walk(&machine.join("out")) {
            let rel = f.strip_prefix(machine.join("out")).unwrap();
            let dest = merged.join("out").join(rel);
            if dest.exists() {
                assert_eq!(
                    std::fs::read(&dest).unwrap(),
                    std::fs::read(&f).unwrap(),
                    "{} collides",
                    rel.display()
                );
                let name = rel.to_string_lossy();
                assert!(name.starts_with(".interact3d-"), "{name}");
            }
            std::fs::create_dir_all(dest.parent().unwrap()).unwrap();
            std::fs::copy(&f, &dest).unwrap();
        }
    }
    for line in runs("merge") {
        let mut c = clean(Command::new("bash"), &path);
        c.args(["-e", "-c", &line]).current_dir(&merged);
        let (code, text) = output(c);
        assert_eq!(code, 0, "{text}");
    }
    assert_complete(&merged.join("out"), &made);
}
