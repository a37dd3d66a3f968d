use super::*;
use crate::report::Report;
use std::sync::atomic::{AtomicUsize, Ordering};

fn dataset(root: &Path, names: &[&str]) {
    for n in names {
        let d = root.join(n);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("metadata.json"), n.as_bytes()).unwrap();
        std::fs::write(d.join("object_a.glb"), b"glb").unwrap();
    }
}

fn fake_report(name: &str) -> Report {
    Report {
        tool: "interact3d",
        version: env!("CARGO_PKG_VERSION"),
        scene: name.into(),
        decomposer: "test".into(),
        scale: 1.0,
        objects: Vec::new(),
        warnings: Vec::new(),
        validation: None,
    }
}

/// A worker that writes one file, fails on `*bad*` and panics on `*boom*`.
fn worker(
    calls: &AtomicUsize,
) -> impl Fn(&SceneEntry, &Path, &ExportJob) -> Result<Exported> + Sync + '_ {
    move |e, out, _| {
        calls.fetch_add(1, Ordering::SeqCst);
        if e.rel.contains("boom") {
            panic!("boom in {}", e.rel);
        }
        if e.rel.contains("bad") {
            return Err(Error::input(
                e.dir.join("metadata.json"),
                "broken on purpose",
            ));
        }
        crate::fsutil::write_dir_atomically(out, true, |d| {
            crate::fsutil::write(&d.join("scene.xml"), e.rel.as_bytes())
        })?;
        Ok(Exported {
            report: fake_report(e.name()),
            validation: None,
            rendered: false,
        })
    }
}

#[test]
fn errors_and_panics_are_rows_and_the_rest_is_converted_then_reused() {
    let t = tempfile::tempdir().unwrap();
    let root = t.path().join("root");
    dataset(
        &root,
        &[
            "food/00001_ok",
            "food/00002_bad",
            "toys/00003_boom",
            "toys/00004_ok",
        ],
    );
    let out = t.path().join("out");
    let mut opts = BatchOptions::new(&root, &out, ExportJob::default());
    opts.jobs = Some(2);
    opts.progress = Progress::Quiet;
    let calls = AtomicUsize::new(0);
    let s = run_with(&opts, &worker(&calls)).unwrap();
    assert_eq!(calls.load(Ordering::SeqCst), 4);
    assert_eq!(s.exit_code, 2);
    assert_eq!((s.counts.pass, s.counts.fail, s.counts.error), (2, 0, 2));
    let paths: Vec<&str> = s.scenes.iter().map(|r| r.scene.path.as_str()).collect();
    assert_eq!(
        paths,
        [
            "food/00001_ok",
            "food/00002_bad",
            "toys/00003_boom",
            "toys/00004_ok"
        ]
    );
    assert!(s.scenes[1]
        .error
        .as_ref()
        .unwrap()
        .contains("broken on purpose"));
    assert!(s.scenes[2].error.as_ref().unwrap().contains("panic"));
    assert!(out.join("food/00001_ok/batch.json").is_file());
    assert!(out.join("food/00001_ok/scene.xml").is_file());
    assert!(!out.join("food/00002_bad").exists());
    assert!(!out.join(".interact3d-staging").exists());
    for f in ["summary.json", "summary.csv", "index.html", MARKER] {
        assert!(out.join(f).is_file(), "{f}");
    }

    // Second run: the good ones are reused, the broken ones tried again.
    let s2 = run_with(&opts, &worker(&calls)).unwrap();
    assert_eq!(calls.load(Ordering::SeqCst), 6);
    assert_eq!(s2.run.reused, 2);
    assert!(s2.scenes[0].reused && !s2.scenes[1].reused);
    assert_eq!(s2.scenes[0].scene, s.scenes[0].scene);

    // A changed input is converted again; --force converts everything.
    std::fs::write(root.join("toys/00004_ok/object_a.glb"), b"glb2").unwrap();
    run_with(&opts, &worker(&calls)).unwrap();
    assert_eq!(calls.load(Ordering::SeqCst), 9);
    opts.force = true;
    run_with(&opts, &worker(&calls)).unwrap();
    assert_eq!(calls.load(Ordering::SeqCst), 13);
}

#[test]
fn out_must_be_a_batch_or_empty_and_resume_needs_one() {
    let t = tempfile::tempdir().unwrap();
    let root = t.path().join("root");
    dataset(&root, &["a/00001_ok"]);
    let out = t.path().join("out");
    let calls = AtomicUsize::new(0);
    let mut opts = BatchOptions::new(&root, &out, ExportJob::default());
    opts.progress = Progress::Quiet;
    opts.resume = true;
    assert!(run_with(&opts, &worker(&calls)).is_err());
    opts.resume = false;
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("precious.txt"), b"x").unwrap();
    assert!(run_with(&opts, &worker(&calls)).is_err());
    std::fs::remove_file(out.join("precious.txt")).unwrap();
    run_with(&opts, &worker(&calls)).unwrap();
    opts.resume = true;
    let s = run_with(&opts, &worker(&calls)).unwrap();
    assert_eq!(s.run.reused, 1);
}

#[test]
fn shard_summaries_merge_into_the_whole() {
    let t = tempfile::tempdir().unwrap();
    let root = t.path().join("root");
    let names: Vec<String> = (0..12).map(|i| format!("c{}/{i:05}_s", i % 3)).collect();
    dataset(&root, &names.iter().map(|s| s.as_str()).collect::<Vec<_>>());
    let out = t.path().join("out");
    let calls = AtomicUsize::new(0);
    for i in 1..=3 {
        let mut opts = BatchOptions::new(&root, &out, ExportJob::default());
        opts.progress = Progress::Quiet;
        opts.shard = Some(Shard { index: i, count: 3 });
        run_with(&opts, &worker(&calls)).unwrap();
        assert!(out.join(format!("summary.shard-{i}-of-3.json")).is_file());
    }
    assert_eq!(calls.load(Ordering::SeqCst), 12);
    assert!(!out.join("summary.json").exists());
    let m = merge_reports(&out, &[]).unwrap();
    assert!(!m.incomplete, "{:?}", m.warnings);
    let paths: Vec<String> = m
        .summary
        .scenes
        .iter()
        .map(|r| r.scene.path.clone())
        .collect();
    let mut want = names.clone();
    want.sort();
    assert_eq!(paths, want);
    assert!(out.join("summary.csv").is_file() && out.join("index.html").is_file());
    // A missing shard is reported.
    let only_two = merge_reports(
        &t.path().join("merged"),
        &[
            out.join("summary.shard-1-of-3.json"),
            out.join("summary.shard-3-of-3.json"),
        ],
    )
    .unwrap();
    assert!(only_two.incomplete);
}

#[test]
fn csv_quotes_what_needs_quoting() {
    assert_eq!(summary::csv_field("a,b"), "\"a,b\"");
    assert_eq!(summary::csv_field("say \"x\""), "\"say \"\"x\"\"\"");
    assert_eq!(summary::csv_field("plain"), "plain");
}

#[test]
fn a_second_process_of_the_same_shard_is_refused_and_others_go_on() {
    let t = tempfile::tempdir().unwrap();
    let root = t.path().join("root");
    let names: Vec<String> = (0..6).map(|i| format!("c/{i:05}_s")).collect();
    dataset(&root, &names.iter().map(|s| s.as_str()).collect::<Vec<_>>());
    let out = t.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    // Another process holds shard 1/2 (an open file lock, as run() takes it) and has started
    // its staging folder; OUT has no marker yet, which must not make shard 2 refuse OUT.
    let held = std::fs::File::create(out.join(".interact3d-staging-1-of-2.lock")).unwrap();
    try_lock(&held).unwrap();
    std::fs::create_dir(out.join(".interact3d-staging-1-of-2")).unwrap();
    let calls = AtomicUsize::new(0);
    let mut opts = BatchOptions::new(&root, &out, ExportJob::default());
    opts.progress = Progress::Quiet;
    opts.shard = Some(Shard { index: 1, count: 2 });
    let e = run_with(&opts, &worker(&calls)).unwrap_err().to_string();
    assert!(
        e.contains("another interact3d batch is running shard 1/2"),
        "{e}"
    );
    assert_eq!(calls.load(Ordering::SeqCst), 0);
    assert!(
        out.join(".interact3d-staging-1-of-2").is_dir(),
        "left alone"
    );
    opts.shard = Some(Shard { index: 2, count: 2 });
    let s = run_with(&opts, &worker(&calls)).unwrap();
    assert_eq!(s.counts.scenes, calls.load(Ordering::SeqCst));
    drop(held);
    opts.shard = Some(Shard { index: 1, count: 2 });
    let s1 = run_with(&opts, &worker(&calls)).unwrap();
    assert_eq!(s.counts.scenes + s1.counts.scenes, 6);
    // The marker was created once and is readable like any file made with the umask.
    use std::os::unix::fs::PermissionsExt;
    let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    std::fs::write(t.path().join("plain"), b"").unwrap();
    for f in [
        MARKER,
        "summary.shard-1-of-2.json",
        "summary.shard-2-of-2.json",
    ] {
        assert_eq!(mode(&out.join(f)), mode(&t.path().join("plain")), "{f}");
    }
}

#[test]
fn a_run_that_reuses_everything_reports_no_speed() {
    let t = tempfile::tempdir().unwrap();
    let root = t.path().join("root");
    dataset(&root, &["a/00001_ok", "a/00002_ok"]);
    let out = t.path().join("out");
    let calls = AtomicUsize::new(0);
    let mut opts = BatchOptions::new(&root, &out, ExportJob::default());
    opts.progress = Progress::Quiet;
    let first = run_with(&opts, &worker(&calls)).unwrap();
    assert!(counts_line(&first).contains("scenes/min converted"));
    let again = run_with(&opts, &worker(&calls)).unwrap();
    assert_eq!((again.run.converted, again.run.reused), (0, 2));
    let line = counts_line(&again);
    assert!(!line.contains("scenes/min"), "{line}");
    assert_eq!(speed(0, 1e-4, 3), "all reused so far");
    // 2 converted in 30 s: 4 per minute, 1 left: 15 s.
    assert_eq!(speed(2, 30.0, 1), "4.0 scenes/min converting, ETA 15 s");
    assert!(again.scenes.iter().all(|r| r.reused));
}
