//! Every shared object decomposed alone by the scene-aware engine (default options): time,
//! hulls, the two-sided p95 and the one-sided p95 of `decompose::scene_aware::metrics`, and a
//! fingerprint of the hulls, so a speed change can show it leaves the output bit for bit as it
//! was (or what it costs each object).
//!
//! ```text
//! cargo run --release --example bench_objects                 # the 43 objects of index.json
//! cargo run --release --example bench_objects -- --only mug,duplo   # ids containing "mug" or "duplo"
//! ```
//!
//! One row per object: triangles, hulls, wall and CPU seconds (all threads, from
//! `/proc/self/stat`, 10 ms ticks), the two-sided p95 (`metrics::two_sided_of`, the headline
//! of `docs/collision_fit.md`), the outside depth (p99 / max), the one-sided p95 and max
//! distance (% of the diagonal) and the FNV-1a hash of every hull vertex's coordinates (bits,
//! in order). Last: totals, the worst object beside the mean (CPU, two-sided p95, outside
//! p99), and one hash over all objects. Objects are loaded as `bench_decompose --shared`
//! loads them, at their `scale_to_m` (the tray's is its URDF scale 0.5), so the two benches
//! measure the same meshes.

use interact3d::decompose::scene_aware::{metrics, SceneAware};
use interact3d::decompose::{DecomposeOptions, Hull};
use interact3d::mesh::P3;
use std::path::PathBuf;
use std::time::Instant;

#[path = "common/procstat.rs"]
mod procstat;
use procstat::cpu_s;

fn shared() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared")
}

/// FNV-1a over the bits of every vertex coordinate, hull by hull, continuing from `h`.
fn fnv(mut h: u64, hulls: &[Hull]) -> u64 {
    let mut eat = |w: u64| {
        for b in w.to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x100_0000_01b3);
        }
    };
    for hull in hulls {
        eat(hull.vertices.len() as u64);
        for v in &hull.vertices {
            eat(v.x.to_bits());
            eat(v.y.to_bits());
            eat(v.z.to_bits());
        }
    }
    h
}

const FNV_START: u64 = 0xcbf2_9ce4_8422_2325;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let only = args
        .iter()
        .position(|a| a == "--only")
        .and_then(|i| args.get(i + 1))
        .cloned();
    let index: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(shared().join("datasets/objects/index.json"))
            .expect("../shared/datasets/objects/index.json"),
    )
    .expect("index.json");
    println!(
        "| object | triangles | hulls | wall s | CPU s | two-sided p95 % | outside p99 / max % | p95 % | max % | hash |"
    );
    println!("|---|---:|---:|---:|---:|---:|---|---:|---:|---|");
    let opts = DecomposeOptions::default();
    let (mut wall, mut cpu, mut all) = (0.0, 0.0, FNV_START);
    // (id, CPU s, two-sided p95, outside p99)
    let mut rows: Vec<(String, f64, f64, f64)> = Vec::new();
    for o in index.as_array().expect("a list") {
        let id = o["id"].as_str().unwrap_or("?");
        if only
            .as_ref()
            .is_some_and(|w| !w.split(',').any(|x| id.contains(x)))
        {
            continue;
        }
        // `scale_to_m` holds the tray's URDF scale 0.5 already (applying it twice measured
        // a tray half the size `bench_decompose` measures).
        let scale = o["scale_to_m"].as_f64().unwrap_or(1.0);
        let path = shared()
            .join("datasets/objects")
            .join(o["mesh"].as_str().unwrap_or(""));
        let Ok(v) = interact3d::io::load_visual(&path, &Default::default()) else {
            println!("| {id} | unreadable |");
            continue;
        };
        let mut m = v.geometry();
        for p in &mut m.vertices {
            *p = P3::from(p.coords * scale);
        }
        let (t, c) = (Instant::now(), cpu_s());
        let Ok((sets, _)) = SceneAware::new().run(&[&m], &opts) else {
            println!("| {id} | decomposition failed |");
            continue;
        };
        let (w, c) = (t.elapsed().as_secs_f64(), cpu_s() - c);
        let hulls = &sets[0];
        let q = metrics::measure(&m, hulls);
        let t2 = metrics::two_sided_of(&m, hulls);
        let two = t2.map_or(f64::NAN, |t| t.p95);
        let (out99, out_max) = t2.map_or((f64::NAN, f64::NAN), |t| (t.outside_p99, t.outside_max));
        let h = fnv(FNV_START, hulls);
        all = fnv(all, hulls);
        wall += w;
        cpu += c;
        rows.push((id.to_string(), c, two, out99));
        println!(
            "| {id} | {} | {} | {w:.2} | {c:.2} | {:.3} | {:.3} / {:.3} | {:.3} | {:.3} | {h:016x} |",
            m.triangles.len(),
            hulls.len(),
            two * 100.0,
            out99 * 100.0,
            out_max * 100.0,
            q.dist_p95 * 100.0,
            q.dist_max * 100.0
        );
    }
    let n = rows.len().max(1) as f64;
    let worst = rows
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|r| format!("{} {:.2} s", r.0, r.1))
        .unwrap_or_default();
    println!(
        "\n{} objects: {wall:.1} s wall, {cpu:.1} s CPU (mean {:.2} s, worst {worst}); two-sided p95 mean {:.3} %, worst {}; outside p99 mean {:.3} %, worst {}, {} above 0.5 %; all hulls {all:016x}",
        rows.len(),
        cpu / n,
        rows.iter().map(|r| r.2).sum::<f64>() / n * 100.0,
        rows.iter()
            .max_by(|a, b| a.2.total_cmp(&b.2))
            .map(|r| format!("{} {:.3} %", r.0, r.2 * 100.0))
            .unwrap_or_default(),
        rows.iter().map(|r| r.3).sum::<f64>() / n * 100.0,
        rows.iter()
            .max_by(|a, b| a.3.total_cmp(&b.3))
            .map(|r| format!("{} {:.3} %", r.0, r.3 * 100.0))
            .unwrap_or_default(),
        rows.iter().filter(|r| r.3 > 0.005).count()
    );
}
