//! Time of `interact3d render` (all pictures of a scene: six views, six hull views, three
//! cross-sections per nearby pair, PNG encoding) on one core.
//!
//! ```text
//! cargo run --release --example bench_render                       # the shoes-tray scene
//! cargo run --release --example bench_render -- SCENE_OR_EXPORT...
//! ```
//!
//! The collision hulls come from the decomposition cache in target/bench-render-cache (the
//! first run decomposes; that time is not counted). Each scene is rendered three times in a
//! one-thread pool; the table gives CPU seconds (best, mean, worst: on a shared machine the wall clock also
//! counts other processes), the best wall time, and the wall-clock stage split of the best run.

use interact3d::body::BuildOptions;
use interact3d::io::Limits;
use interact3d::render::{png_bytes, render, RenderOptions};
use std::path::PathBuf;
use std::time::Instant;

#[path = "common/procstat.rs"]
mod procstat;
use procstat::cpu_s;

fn main() {
    let mut scenes: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if scenes.is_empty() {
        scenes.push("../shared/datasets/scenes/apparel/00005_shoes_tray".into());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let mut build = BuildOptions::default();
    build.decompose.cache_dir = Some("target/bench-render-cache".into());
    println!(
        "{:<20} {:>9} {:>6} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8}",
        "scene",
        "triangles",
        "images",
        "cpu_best",
        "cpu_mean",
        "cpu_worst",
        "wall_best",
        "meshes",
        "views",
        "hulls",
        "sections",
        "png"
    );
    for s in &scenes {
        let a = match interact3d::pipeline::load_any(s, &Limits::default(), &build) {
            Ok(a) => a,
            Err(e) => {
                eprintln!("{}: {e}", s.display());
                continue;
            }
        };
        let tris: usize = a.bodies.iter().map(|b| b.visual.triangle_count()).sum();
        let mut runs = Vec::new();
        for _ in 0..3 {
            let c0 = cpu_s();
            let (t, r, png) = pool.install(|| {
                let t = Instant::now();
                let r = render(&a, &RenderOptions::default()).unwrap();
                let tp = Instant::now();
                let bytes: usize = r
                    .pictures
                    .iter()
                    .map(|p| png_bytes(&p.image).unwrap().len())
                    .sum();
                std::hint::black_box(bytes);
                (t.elapsed().as_secs_f64(), r, tp.elapsed().as_secs_f64())
            });
            runs.push((t, r, png, cpu_s() - c0));
        }
        runs.sort_by(|x, y| x.3.total_cmp(&y.3));
        let cpu_mean = runs.iter().map(|r| r.3).sum::<f64>() / runs.len() as f64;
        let wall_best = runs.iter().map(|r| r.0).fold(f64::INFINITY, f64::min);
        let (_, r, png, cpu_best) = &runs[0];
        let stage = |n: &str| {
            r.timings
                .iter()
                .find(|t| t.0 == n)
                .map(|t| t.1)
                .unwrap_or(f64::NAN)
        };
        println!(
            "{:<20} {:>9} {:>6} {:>8.2} {:>8.2} {:>8.2} {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>8.3}",
            a.name,
            tris,
            r.pictures.len(),
            cpu_best,
            cpu_mean,
            runs[2].3,
            wall_best,
            stage("meshes"),
            stage("views"),
            stage("hulls"),
            stage("sections"),
            png
        );
    }
}
