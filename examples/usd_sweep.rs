//! USD sweep (issue #31): every fixture and every shared scene exported and held to the USD
//! judges of `tests/python/check_usd.py` (usd-core validators, UsdPhysics' parser, PhysX through
//! ovphysx on the CPU), then the cost of the PhysX polygon limit on every shared object.
//!
//! ```text
//! cargo run --release --example usd_sweep -- [--no-scenes] [--no-objects] [--only WORD] [--python PY]
//! ```
//! Table 1, per scene: hulls, most vertices and most polygons on one hull, PhysX's largest
//! displacement and rotation of a dynamic body over 2 s from the shipped pose, the farthest an
//! authored hull vertex lies outside its cooked hull (or a cooked vertex from every authored
//! one), how many hulls PhysX changed by more than 0.1 mm, and the validation verdict.
//! Table 2, per shared object (scene-aware engine alone): the two-sided p95 (% of the
//! bounding-box diagonal, `decompose::scene_aware::metrics::two_sided_of`) of its hulls without
//! a polygon budget ("free"), of those hulls brought within 64 polygons afterwards by
//! `decompose::physx_legal` alone ("post-hoc"), and of the hulls the engine builds when given
//! the budget (`DecomposeOptions::engine_budget`, then `physx_legal`, as `export` does with the
//! 64-polygon limit: "engine"); the costs in percentage points (one-sided p95 too), and times.
//! `--only WORD` keeps the objects whose id contains WORD.
//! Needs `pip install -r tests/python/requirements-usd.txt` for table 1.

use interact3d::decompose::scene_aware::{metrics, SceneAware};
use interact3d::decompose::{physx_legal, DecomposeOptions, Decomposer, Hull};
use interact3d::mesh::P3;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn shared() -> PathBuf {
    root().join("../shared")
}

fn scenes() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("fixtures"))
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("metadata.json").is_file() || p.join("scene.json").is_file())
        .collect();
    v.sort();
    let mut s = Vec::new();
    for c in std::fs::read_dir(shared().join("datasets/scenes"))
        .into_iter()
        .flatten()
    {
        for e in std::fs::read_dir(c.unwrap().path()).into_iter().flatten() {
            let p = e.unwrap().path();
            if p.join("metadata.json").is_file() {
                s.push(p);
            }
        }
    }
    s.sort();
    v.extend(s);
    v
}

fn pct(v: &[f64], q: f64) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    if s.is_empty() {
        return f64::NAN;
    }
    s[((s.len() - 1) as f64 * q).round() as usize]
}

fn sweep_scenes(python: &str) {
    println!("| scene | pass | objects | hulls | max verts/hull | max polygons/hull | PhysX max moved (mm) | PhysX max turned (°) | authored outside cooked (mm) | hulls PhysX changed | export s | judges s |");
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let (mut moved_all, mut turned_all) = (Vec::new(), Vec::new());
    let mut worst_cook: f64 = 0.0;
    let mut failures = 0;
    for scene in scenes() {
        let name = scene.file_name().unwrap().to_string_lossy().to_string();
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("out");
        let t = Instant::now();
        let mut job = interact3d::pipeline::ExportJob {
            validate: Some(Default::default()),
            ..Default::default()
        };
        // For Isaac: every hull within PhysX's polygon budget (`--max-hull-polygons 64`).
        job.build.decompose.max_polygons = interact3d::decompose::PHYSX_MAX_POLYGONS;
        let exported = match interact3d::pipeline::export_scene(&scene, &out, &job) {
            Ok(e) => e,
            Err(e) => {
                println!("| {name} | export failed: {e} |");
                failures += 1;
                continue;
            }
        };
        let t_export = t.elapsed().as_secs_f64();
        let passed = exported.validation.as_ref().is_some_and(|v| v.passed);
        let a = interact3d::export::read::load(&out, &Default::default()).unwrap();
        let hulls: Vec<&Hull> = a.bodies.iter().flat_map(|b| &b.hulls).collect();
        let max_v = hulls.iter().map(|h| h.vertices.len()).max().unwrap_or(0);
        let max_p = hulls.iter().map(|h| h.polygon_stats().0).max().unwrap_or(0);
        let t = Instant::now();
        let o = Command::new(python)
            .arg(root().join("tests/python/check_usd.py"))
            .arg(&out)
            .output()
            .expect("run python");
        let t_judge = t.elapsed().as_secs_f64();
        if !o.status.success() {
            println!(
                "| {name} | check_usd.py failed: {} |",
                String::from_utf8_lossy(&o.stderr)
                    .lines()
                    .last()
                    .unwrap_or("")
            );
            failures += 1;
            continue;
        }
        let u: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let errors: usize = u["files"]
            .as_object()
            .unwrap()
            .values()
            .map(|f| f["errors"].as_array().unwrap().len())
            .sum();
        let (mut moved, mut turned) = (0.0f64, 0.0f64);
        for b in u["physx"]["bodies"].as_object().unwrap().values() {
            moved = moved.max(b["moved_m"].as_f64().unwrap());
            turned = turned.max(b["turned_deg"].as_f64().unwrap());
        }
        let c = &u["physx"]["cooked"];
        // How far an authored vertex lies outside its cooked hull (PhysX dropped it), and
        // how far a cooked vertex is from every authored one (PhysX made it up).
        let cook = c["deviation_max_m"]
            .as_f64()
            .unwrap_or(0.0)
            .max(c["cooked_to_authored_max_m"].as_f64().unwrap_or(0.0));
        let changed = c["changed_hulls"].as_array().map_or(0, Vec::len);
        worst_cook = worst_cook.max(cook);
        if passed {
            moved_all.push(moved);
            turned_all.push(turned);
        }
        if errors > 0 || cook > 1e-4 || (passed && (moved > 1e-3 || turned > 1.0)) {
            failures += 1;
        }
        println!(
            "| {name} | {} | {} | {} | {max_v} | {max_p} | {:.3} | {:.3} | {:.4} | {changed} | {t_export:.1} | {t_judge:.1} |{}",
            if passed { "yes" } else { "no" },
            a.bodies.len(),
            hulls.len(),
            moved * 1e3,
            turned,
            cook * 1e3,
            if errors > 0 { format!(" {errors} validator errors") } else { String::new() }
        );
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    println!(
        "\nPassing scenes: PhysX max moved mean {:.3} mm, worst {:.3} mm; max turned mean {:.3}°, worst {:.3}°; cooked hulls within {:.4} mm of the authored ones. Scenes failing a judge: {failures}.\n",
        mean(&moved_all) * 1e3,
        moved_all.iter().cloned().fold(0.0, f64::max) * 1e3,
        mean(&turned_all),
        turned_all.iter().cloned().fold(0.0, f64::max),
        worst_cook * 1e3
    );
}

fn sweep_objects(only: Option<&str>) {
    let index: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(shared().join("datasets/objects/index.json")).unwrap(),
    )
    .unwrap();
    println!("| object | hulls free / engine | max polygons free | two-sided p95 free (%) | post-hoc (%) | engine (%) | post-hoc cost (pp) | engine cost (pp) | one-sided cost post-hoc / engine (pp) | free s | engine s |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let (mut post, mut eng, mut one_post, mut one_eng) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut hulls_total, mut hulls_over) = (0, 0);
    let limited = DecomposeOptions {
        max_polygons: interact3d::decompose::PHYSX_MAX_POLYGONS,
        ..Default::default()
    };
    for o in index.as_array().unwrap() {
        let id = o["id"].as_str().unwrap();
        if only.is_some_and(|w| !id.contains(w)) {
            continue;
        }
        let mut scale = o["scale_to_m"].as_f64().unwrap_or(1.0);
        if id.contains("tray") {
            scale *= 0.5;
        }
        let path = shared()
            .join("datasets/objects")
            .join(o["mesh"].as_str().unwrap());
        let Ok(v) = interact3d::io::load_visual(&path, &Default::default()) else {
            println!("| {id} | unreadable |");
            continue;
        };
        let mut m = v.geometry();
        for p in &mut m.vertices {
            *p = P3::from(p.coords * scale);
        }
        // Free: no polygon budget (the default engine output).
        let t = Instant::now();
        let Ok(free) = SceneAware::new().decompose(&[&m], &DecomposeOptions::default()) else {
            println!("| {id} | decomposition failed |");
            continue;
        };
        let t_free = t.elapsed().as_secs_f64();
        // Post-hoc: the free hulls brought within the limits by `physx_legal` alone.
        let mut posthoc = free.clone();
        physx_legal(&mut posthoc, &limited);
        // Engine: the budget given to the engine (`engine_budget`), then `physx_legal`, as
        // `body::assemble` does with `--max-hull-polygons 64`.
        let t = Instant::now();
        let Ok(mut engine) = SceneAware::new().decompose(&[&m], &limited.engine_budget()) else {
            println!("| {id} | decomposition failed (budget) |");
            continue;
        };
        physx_legal(&mut engine, &limited);
        let t_eng = t.elapsed().as_secs_f64();
        let over = free[0].iter().filter(|h| h.polygon_stats().0 > 64).count();
        let max_p = free[0]
            .iter()
            .map(|h| h.polygon_stats().0)
            .max()
            .unwrap_or(0);
        let two = |h: &[Hull]| metrics::two_sided_of(&m, h).map_or(f64::NAN, |t| t.p95) * 100.0;
        let one = |h: &[Hull]| metrics::measure(&m, h).dist_p95 * 100.0;
        let (t0, t1, t2) = (two(&free[0]), two(&posthoc[0]), two(&engine[0]));
        let (o0, o1, o2) = (one(&free[0]), one(&posthoc[0]), one(&engine[0]));
        hulls_total += free[0].len();
        hulls_over += over;
        post.push(t1 - t0);
        eng.push(t2 - t0);
        one_post.push(o1 - o0);
        one_eng.push(o2 - o0);
        println!(
            "| {id} | {} / {} | {max_p} | {t0:.3} | {t1:.3} | {t2:.3} | {:+.3} | {:+.3} | {:+.3} / {:+.3} | {t_free:.1} | {t_eng:.1} |",
            free[0].len(),
            engine[0].len(),
            t1 - t0,
            t2 - t0,
            o1 - o0,
            o2 - o0
        );
    }
    let summary = |name: &str, c: &[f64]| {
        println!(
            "{name}: mean {:+.3}, median {:+.3}, 95th percentile {:+.3}, worst {:+.3}",
            c.iter().sum::<f64>() / c.len().max(1) as f64,
            pct(c, 0.5),
            pct(c, 0.95),
            c.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
        )
    };
    println!(
        "\n{} objects, {hulls_over} of {hulls_total} free hulls over 64 polygons. Cost of the 64-polygon limit in percentage points of the diagonal:",
        post.len()
    );
    summary("two-sided p95, post-hoc reduction", &post);
    summary("two-sided p95, budget in the engine", &eng);
    summary("one-sided p95, post-hoc reduction", &one_post);
    summary("one-sided p95, budget in the engine", &one_eng);
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let python = args
        .iter()
        .position(|a| a == "--python")
        .and_then(|i| args.get(i + 1).cloned())
        .or_else(|| std::env::var("INTERACT3D_USD_PYTHON").ok())
        .unwrap_or_else(|| "python3".into());
    if !args.iter().any(|a| a == "--no-scenes") {
        sweep_scenes(&python);
    }
    if !args.iter().any(|a| a == "--no-objects") && Path::new(&shared()).exists() {
        let only = args
            .iter()
            .position(|a| a == "--only")
            .and_then(|i| args.get(i + 1))
            .map(String::as_str);
        sweep_objects(only);
    }
}
