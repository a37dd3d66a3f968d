//! Where a scene's time goes: the whole `export` pipeline on the shared scenes, stage by stage,
//! with wall time, CPU time (all threads) and peak resident memory per scene.
//!
//! ```text
//! cargo run --release --example bench_pipeline                       # the 10 shared scenes
//! cargo run --release --example bench_pipeline -- --scenes DIR       # another dataset root
//! cargo run --release --example bench_pipeline -- --only shoes       # scenes whose path contains it
//! cargo run --release --example bench_pipeline -- --threads 1        # one core
//! cargo run --release --example bench_pipeline -- --per-object       # + each object decomposed alone
//! ```
//!
//! Stages are the pipeline's own (`pipeline::export_scene` split into its calls): **load**
//! (`scene::load`: files, meshes, textures), **prepare** (metres, Z-up, on the ground),
//! **decompose** (the engine's `decompose` call, timed through a wrapper), **inertia** (the rest
//! of `body::assemble`: the hulls' two-sided fidelity measure, mass properties, body frames),
//! **validate** (metrics + settle) and **write** (`export::export` into a temporary folder).
//! Each scene runs in a fresh child process (this executable again), so its peak RSS (`VmHWM`)
//! is its own. CPU time is read from
//! `/proc/self/stat` (Linux; 10 ms ticks). `--per-object` adds, for each object, the time to
//! decompose its mesh alone, which is not the same work as its share of the scene (the scene
//! engine also keeps hulls off the neighbours), but tells which objects are expensive.
//! Most of **inertia** is the fidelity measure; the mass properties of a closed mesh take about
//! 1 ms an object (`docs/speed.md`, ninth stop).

use interact3d::body::{assemble, BuildOptions};
use interact3d::decompose::{DecomposeOptions, Decomposer, Hull};
use interact3d::mesh::Mesh;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;
use std::time::Instant;

#[path = "common/procstat.rs"]
mod procstat;
use procstat::{cpu_s, peak_rss_mib};

/// Wall and CPU seconds of one stage.
#[derive(Clone, Copy, Default)]
struct Span {
    wall: f64,
    cpu: f64,
}

fn timed<T>(f: impl FnOnce() -> T) -> (T, Span) {
    let (w, c) = (Instant::now(), cpu_s());
    let r = f();
    let span = Span {
        wall: w.elapsed().as_secs_f64(),
        cpu: cpu_s() - c,
    };
    (r, span)
}

/// The engine, with its `decompose` call timed.
struct Timed {
    inner: Box<dyn Decomposer>,
    span: Mutex<Span>,
}

impl Decomposer for Timed {
    fn name(&self) -> &'static str {
        self.inner.name()
    }
    fn decompose(
        &self,
        objects: &[&Mesh],
        opts: &DecomposeOptions,
    ) -> interact3d::Result<Vec<Vec<Hull>>> {
        let (r, s) = timed(|| self.inner.decompose(objects, opts));
        *self.span.lock().unwrap() = s;
        r
    }
    fn object_warnings(&self) -> Vec<Vec<String>> {
        self.inner.object_warnings()
    }
    fn take_surfaces(&self) -> Vec<Option<interact3d::decompose::scene_aware::geom::Surface>> {
        self.inner.take_surfaces()
    }
}

const STAGES: [&str; 6] = [
    "load",
    "prepare",
    "decompose",
    "inertia",
    "validate",
    "write",
];

/// In the child: run one scene, print one line "stage wall cpu ..." then object lines.
fn child(scene: &Path, per_object: bool) {
    let opts = BuildOptions::default();
    let limits = interact3d::io::Limits::default();
    let (s, load) = timed(|| interact3d::scene::load(scene, &limits).expect("load"));
    let (prepared, prep) =
        timed(|| interact3d::prepare::prepare(&s, &opts.prepare).expect("prepare"));
    let engine = Timed {
        inner: opts.engine.decomposer(),
        span: Mutex::new(Span::default()),
    };
    let (mut assembly, asm) =
        timed(|| assemble(&prepared, &engine, &opts.decompose, &s.source).expect("assemble"));
    let dec = *engine.span.lock().unwrap();
    let inertia = Span {
        wall: asm.wall - dec.wall,
        cpu: asm.cpu - dec.cpu,
    };
    let report0 = interact3d::report::Report::new(&assembly);
    let (v, val) =
        timed(|| interact3d::validate::validate(&assembly, &Default::default()).expect("validate"));
    if v.passed {
        interact3d::validate::apply_settled_poses(&mut assembly, &v);
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let (_, write) = timed(|| {
        interact3d::export::export(&assembly, &report0, &out, &Default::default()).expect("write")
    });
    let spans = [load, prep, dec, inertia, val, write];
    let tris: usize = prepared
        .objects
        .iter()
        .map(|o| o.geometry.triangles.len())
        .sum();
    print!(
        "scene {} {} {} {:.1}",
        assembly.bodies.len(),
        tris,
        if v.passed { "pass" } else { "fail" },
        peak_rss_mib()
    );
    for sp in spans {
        print!(" {:.4} {:.4}", sp.wall, sp.cpu);
    }
    println!();
    if per_object {
        for o in &prepared.objects {
            let e = opts.engine.decomposer();
            let (h, sp) = timed(|| e.decompose(&[&o.geometry], &opts.decompose).expect("alone"));
            println!(
                "object {} {} {} {:.4} {:.4}",
                o.name,
                o.geometry.triangles.len(),
                h[0].len(),
                sp.wall,
                sp.cpu
            );
        }
    }
}

fn scenes_under(root: &Path) -> Vec<PathBuf> {
    let mut v = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(d) = stack.pop() {
        if d.join("metadata.json").is_file() || d.join("scene.json").is_file() {
            v.push(d);
            continue;
        }
        if let Ok(rd) = std::fs::read_dir(&d) {
            for e in rd.flatten() {
                if e.path().is_dir() {
                    stack.push(e.path());
                }
            }
        }
    }
    v.sort();
    v
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    if let Some(scene) = value("--child") {
        child(Path::new(&scene), args.iter().any(|a| a == "--per-object"));
        return;
    }
    let root = value("--scenes").map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/datasets/scenes")
    });
    let only = value("--only");
    let threads = value("--threads");
    let per_object = args.iter().any(|a| a == "--per-object");
    let scenes: Vec<PathBuf> = scenes_under(&root)
        .into_iter()
        .filter(|p| {
            only.as_ref()
                .is_none_or(|o| p.to_string_lossy().contains(o))
        })
        .collect();
    if scenes.is_empty() {
        eprintln!("no scenes under {}", root.display());
        std::process::exit(2);
    }
    let exe = std::env::current_exe().expect("current exe");
    println!(
        "| scene | objects | triangles | verdict | {} | total wall | total CPU | peak RSS MiB |",
        STAGES
            .iter()
            .map(|s| format!("{s} wall/CPU s"))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    println!(
        "|---|---:|---:|---|{}---:|---:|---:|",
        "---:|".repeat(STAGES.len())
    );
    let mut sum = [Span::default(); 6];
    let mut objects = Vec::new();
    for scene in &scenes {
        let mut cmd = Command::new(&exe);
        cmd.arg("--child").arg(scene);
        if per_object {
            cmd.arg("--per-object");
        }
        if let Some(t) = &threads {
            cmd.env("RAYON_NUM_THREADS", t);
        }
        let out = cmd.output().expect("run child");
        let text = String::from_utf8_lossy(&out.stdout);
        let name = scene
            .strip_prefix(&root)
            .unwrap_or(scene)
            .display()
            .to_string();
        let Some(line) = text.lines().find(|l| l.starts_with("scene ")) else {
            println!(
                "| {name} | child failed: {} |",
                String::from_utf8_lossy(&out.stderr).trim()
            );
            continue;
        };
        let f: Vec<&str> = line.split_whitespace().collect();
        let nums: Vec<f64> = f[5..].iter().map(|v| v.parse().unwrap()).collect();
        let (mut tw, mut tc) = (0.0, 0.0);
        let mut cells = Vec::new();
        for k in 0..STAGES.len() {
            let (w, c) = (nums[2 * k], nums[2 * k + 1]);
            sum[k].wall += w;
            sum[k].cpu += c;
            tw += w;
            tc += c;
            cells.push(format!("{w:.2} / {c:.2}"));
        }
        println!(
            "| {name} | {} | {} | {} | {} | {tw:.2} | {tc:.2} | {} |",
            f[1],
            f[2],
            f[3],
            cells.join(" | "),
            f[4]
        );
        for l in text.lines().filter(|l| l.starts_with("object ")) {
            let o: Vec<&str> = l.split_whitespace().collect();
            objects.push(format!(
                "| {name} | {} | {} | {} | {} | {} |",
                o[1], o[2], o[3], o[4], o[5]
            ));
        }
    }
    let (tw, tc): (f64, f64) = sum
        .iter()
        .fold((0.0, 0.0), |a, s| (a.0 + s.wall, a.1 + s.cpu));
    println!(
        "| **all {}** | | | | {} | {tw:.2} | {tc:.2} | |",
        scenes.len(),
        sum.iter()
            .map(|s| format!("{:.2} / {:.2}", s.wall, s.cpu))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    println!(
        "\nCPU per scene: {:.2} core-s (mean over {} scenes); decompose share {:.0} %",
        tc / scenes.len() as f64,
        scenes.len(),
        100.0 * sum[2].cpu / tc
    );
    if per_object {
        println!("\n| scene | object | triangles | hulls | alone wall s | alone CPU s |");
        println!("|---|---|---:|---:|---:|---:|");
        for o in objects {
            println!("{o}");
        }
    }
}
