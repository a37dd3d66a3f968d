//! The realistic benchmark (issue #34): pairs of shared objects, guidance from
//! `compose::realistic`, ADD-S and scale per object, success per seed, time per pair.

use interact3d::compose::contact_scale::ContactOptions;
use interact3d::compose::realistic::{self, AddS, SourceObject};
use interact3d::compose::reconstruction::{self, ReconOptions};
use interact3d::compose::rest;
use interact3d::compose::{compose, ComposeOptions};
use interact3d::metrics::{pair_metrics, MetricsOptions, Prepared, Solid};
use interact3d::rng::Rng;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use super::colour_probe;
use super::guidance_stats::{self, GuidanceStats};
use super::miss_probe;
use super::profile_probe;

/// (support or container, item, spread of the item's position over the support's half
/// footprint). Every one of the 43 shared objects appears; flat supports: the plate, the
/// Cardboard package as a board, the tray; box-like items: the printed cereal box and milk
/// carton, the toothbrush package, the Rubik's cube, the die, the Duplo brick.
const PAIRS: &[(&str, &str, f64)] = &[
    ("ycb/029_plate", "ycb/013_apple", 0.3),
    ("ycb/029_plate", "ycb/011_banana", 0.3),
    ("ycb/029_plate", "gen/cereal_box", 0.2),
    ("ycb/029_plate", "ycb/015_peach", 0.3),
    ("pybullet_data/tray", "gso/Reebok_TURBO_RC", 0.3),
    ("pybullet_data/tray", "khronos_gltf/WaterBottle", 0.4),
    ("pybullet_data/tray", "gen/milk_carton", 0.4),
    (
        "pybullet_data/tray",
        "gso/Chelsea_lo_fl_rdheel_zAQrnhlEfw8",
        0.3,
    ),
    ("pybullet_data/tray", "gso/TROCHILUS_BOOST", 0.3),
    ("pybullet_data/tray", "ycb/043_phillips_screwdriver", 0.4),
    (
        "pybullet_data/tray",
        "gso/Threshold_Porcelain_Teapot_White",
        0.3,
    ),
    (
        "gso/Google_Cardboard_Original_package",
        "ycb/077_rubiks_cube",
        0.3,
    ),
    (
        "gso/Google_Cardboard_Original_package",
        "ycb/005_tomato_soup_can",
        0.3,
    ),
    (
        "gso/Google_Cardboard_Original_package",
        "ycb/037_scissors",
        0.2,
    ),
    (
        "gso/Google_Cardboard_Original_package",
        "ycb/073-a_lego_duplo",
        0.4,
    ),
    ("ycb/024_bowl", "ycb/017_orange", 0.1),
    ("ycb/024_bowl", "ycb/014_lemon", 0.2),
    ("ycb/024_bowl", "ycb/018_plum", 0.2),
    ("ycb/025_mug", "ycb/040_large_marker", 0.1),
    ("ycb/065-j_cups", "ycb/012_strawberry", 0.1),
    ("ycb/065-a_cups", "ycb/058_golf_ball", 0.05),
    ("ycb/019_pitcher_base", "ycb/016_pear", 0.1),
    (
        "gso/Olive_Kids_Game_On_Lunch_Box",
        "gso/Hyaluronic_Acid",
        0.4,
    ),
    (
        "gso/LEGO_Bricks_More_Creative_Suitcase",
        "gso/Philips_Sonicare_Tooth_Brush_2_count",
        0.3,
    ),
    (
        "gso/LEGO_Bricks_More_Creative_Suitcase",
        "gso/Reebok_ZIGLITE_RUSH",
        0.3,
    ),
    ("gso/ACE_Coffee_Mug_Kristen_16_oz_cup", "ycb/031_spoon", 0.1),
    ("gso/Cole_Hardware_Mug_Classic_Blue", "ycb/030_fork", 0.1),
    ("gso/Room_Essentials_Mug_White_Yellow", "ycb/062_dice", 0.1),
    (
        "gso/Threshold_Porcelain_Coffee_Mug_All_Over_Bead_White",
        "ycb/056_tennis_ball",
        0.1,
    ),
    (
        "gso/Threshold_Porcelain_Pitcher_White",
        "khronos_gltf/Avocado",
        0.1,
    ),
];

fn load(objects: &Path, id: &str) -> SourceObject {
    match id {
        "gen/cereal_box" => {
            realistic::printed_box(id, interact3d::mesh::V3::new(0.19, 0.30, 0.07), 30)
        }
        "gen/milk_carton" => {
            realistic::printed_box(id, interact3d::mesh::V3::new(0.095, 0.245, 0.095), 170)
        }
        _ => realistic::load_object(objects, id).unwrap_or_else(|e| panic!("{id}: {e}")),
    }
}

struct Record {
    pair: usize,
    seed: u64,
    id: String,
    add_s: f64,
    scale: f64,
    /// Signed scale error (estimate / truth − 1).
    scale_signed: f64,
    stage: String,
    guidance: GuidanceStats,
}

struct SceneRecord {
    seed: u64,
    r_volume: f64,
    truth_r_volume: f64,
    /// The true item's exact gap to the true support, as a fraction of its diagonal.
    truth_gap: f64,
    secs: f64,
    /// What the pair's cost depends on, for the slowest-pairs list: each input's triangles
    /// (object mesh, guidance part) and largest texture.
    sizes: [ObjectSize; 2],
}

/// An input's size: the object's and its guidance part's triangles, its largest texture.
#[derive(Clone, Copy, Default)]
struct ObjectSize {
    tris: usize,
    guidance_tris: usize,
    texture: (u32, u32),
}

fn object_size(inp: &interact3d::compose::ObjectInput) -> ObjectSize {
    let texture = inp
        .visual
        .parts
        .iter()
        .filter_map(|p| p.material.texture.as_ref())
        .map(|t| (t.width, t.height))
        .max_by_key(|&(w, h)| w as u64 * h as u64)
        .unwrap_or((0, 0));
    ObjectSize {
        tris: inp.visual.triangle_count(),
        guidance_tris: inp.guidance.triangle_count(),
        texture,
    }
}

/// CPU time of the calling thread (s), from /proc (10 ms ticks); 0 where unavailable.
fn thread_cpu() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/thread-self/stat") else {
        return 0.0;
    };
    // Fields after the command name (which ends at the last ')'): utime and stime are the
    // 12th and 13th.
    let rest = stat.rsplit_once(')').map_or("", |r| r.1);
    let f: Vec<f64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|x| x.parse().ok())
        .collect();
    f.iter().sum::<f64>() / 100.0
}

fn pct(a: usize, n: usize) -> String {
    format!("{a}/{n} ({:.1} %)", 100.0 * a as f64 / n.max(1) as f64)
}

pub fn run(args: &[String]) {
    let value = |flag: &str| -> Option<&String> {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
    };
    let seeds: u64 = value("--seeds").and_then(|s| s.parse().ok()).unwrap_or(5);
    let offset: u64 = value("--seed-offset")
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let threads: usize = value("--threads").and_then(|s| s.parse().ok()).unwrap_or(1);
    let jobs: usize = value("--jobs").and_then(|s| s.parse().ok()).unwrap_or(1);
    let only: Vec<String> = value("--only")
        .map(|s| s.split(',').map(str::to_string).collect())
        .unwrap_or_default();
    let verbose = args.iter().any(|a| a == "-v");
    // `--profile-probe`: the axial profile's scale of each object, no compose ([`profile_probe`]).
    let profile_only = args.iter().any(|a| a == "--profile-probe");
    // `--colour-probe`: the colour profile's scale of each object, no compose ([`colour_probe`]).
    let colour_only = args.iter().any(|a| a == "--colour-probe");
    // `--dump`: each object's pose and stage fits at full precision (stderr), so two builds
    // can be diffed for the same results (a cost-only change must print the same lines).
    let dump = args.iter().any(|a| a == "--dump");
    // The contact-scale stage: `grow` (default, as `compose`: ungated, floating items only),
    // `off`, `on` (gated) or `ungated` (no coverage gate: the gap, the lever and the guard
    // decide).
    let contact = match value("--contact").map(String::as_str) {
        Some("on") => Some(ContactOptions::default()),
        Some("off") => None,
        Some("ungated") => Some(ContactOptions {
            coverage_max: f64::INFINITY,
            ..Default::default()
        }),
        None | Some("grow") => Some(ContactOptions::grow()),
        Some(other) => {
            eprintln!("--contact {other}: expected on, off, ungated or grow");
            std::process::exit(2);
        }
    };
    // The support sweep (`--support on`; off by default, as in `compose`).
    let support_sweep = match value("--support").map(String::as_str) {
        None | Some("off") => None,
        Some("on") => Some(interact3d::compose::support::SupportOptions::default()),
        Some(other) => {
            eprintln!("--support {other}: expected on or off");
            std::process::exit(2);
        }
    };
    // The earlier realistic guidance: the objects' own surfaces, subdivided, with holes.
    let subdivided = args.iter().any(|a| a == "--subdivided");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let objects = root.join("../shared/datasets/objects");
    if !objects.is_dir() {
        eprintln!("../shared/datasets/objects not found: nothing to benchmark");
        std::process::exit(2);
    }
    let pairs: Vec<usize> = (0..PAIRS.len())
        .filter(|&k| {
            only.is_empty()
                || only
                    .iter()
                    .any(|o| PAIRS[k].0.contains(o.as_str()) || PAIRS[k].1.contains(o.as_str()))
        })
        .collect();
    let t_all = Instant::now();
    let work: Vec<(usize, u64)> = pairs
        .iter()
        .flat_map(|&k| (offset..offset + seeds).map(move |s| (k, s)))
        .collect();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: std::sync::Mutex<Vec<(usize, Vec<Record>, SceneRecord)>> = Default::default();
    std::thread::scope(|scope| {
        for _ in 0..jobs.max(1) {
            scope.spawn(|| {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads.max(1))
                    .build()
                    .expect("thread pool");
                loop {
                    let w = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                    let Some(&(k, seed)) = work.get(w) else { break };
                    let (sid, iid, spread) = PAIRS[k];
                    let support = load(&objects, sid);
                    let item = load(&objects, iid);
                    let mut rng = Rng::new(7000 + seed);
                    // The pair's scene depends on the pair and the seed only.
                    for _ in 0..k {
                        rng.next_u64();
                    }
                    let scene = realistic::pair_scene(&support, &item, spread, &mut rng);
                    let gen_seed = rng.next_u64();
                    let t_gen = Instant::now();
                    let s = if subdivided {
                        realistic::make(&scene, gen_seed, &realistic::RealisticOptions::default())
                    } else {
                        reconstruction::make(&scene, gen_seed, &ReconOptions::default())
                    };
                    if verbose {
                        let tris: Vec<String> = s
                            .inputs
                            .iter()
                            .zip(&s.removed)
                            .map(|(i, r)| {
                                format!("{} tris, {:.0} % removed", i.guidance.triangle_count(), 100.0 * r)
                            })
                            .collect();
                        eprintln!(
                            "pair {k:2} seed {seed}: guidance {} ({:.1} s)",
                            tris.join(" / "),
                            t_gen.elapsed().as_secs_f64()
                        );
                    }
                    if profile_only {
                        for (n, inp) in s.inputs.iter().enumerate() {
                            let id = if n == 0 { sid } else { iid };
                            profile_probe::print(id, seed, inp, &s.truth[n]);
                            if std::env::var_os("PROFILE_DUMP").is_some() {
                                profile_probe::dump(inp, &s.truth[n]);
                            }
                        }
                        continue;
                    }
                    if colour_only {
                        for (n, inp) in s.inputs.iter().enumerate() {
                            let id = if n == 0 { sid } else { iid };
                            colour_probe::print(id, seed, inp, &s.truth[n]);
                        }
                        continue;
                    }
                    let gstats: Vec<GuidanceStats> = s
                        .inputs
                        .iter()
                        .zip(&s.truth)
                        .map(|(i, t)| guidance_stats::measure(i, t))
                        .collect();
                    let o = ComposeOptions {
                        seed,
                        contact,
                        support: support_sweep,
                        ..Default::default()
                    };
                    let t0 = Instant::now();
                    // A cold start, as for a user: no texture decoded yet.
                    interact3d::compose::cloud::forget_decoded();
                    let (comp, cpu) = pool.install(|| {
                        let c0 = thread_cpu();
                        let comp = compose(&s.inputs, &o).expect("compose");
                        (comp, thread_cpu() - c0)
                    });
                    let wall = t0.elapsed().as_secs_f64();
                    // On one thread the CPU time of the pool's thread is the pair's cost on one
                    // core, whatever else the machine runs; on more, the wall time.
                    let secs = if threads <= 1 { cpu } else { wall };
                    if dump {
                        eprintln!("TIME pair {k} seed {seed}: {secs:.3} s");
                    }
                    let mut recs = Vec::new();
                    let mut placed = Vec::new();
                    let mut truth_placed = Vec::new();
                    for (n, inp) in s.inputs.iter().enumerate() {
                        let r = comp.get(&inp.name).unwrap();
                        let est = r.transform;
                        let add = AddS::new(&inp.visual).eval(&est, &s.truth[n]);
                        let scale = (est.scale / s.truth[n].scale - 1.0).abs();
                        let id = if n == 0 { sid } else { iid };
                        if dump {
                            let stages: Vec<String> = r
                                .stages
                                .iter()
                                .map(|st| format!("{}:{:?}:{:?}:{}", st.stage, st.fit, st.scale, st.accepted))
                                .collect();
                            eprintln!(
                                "DUMP pair {k} seed {seed} object {n}: scale {:?} rotation {:?} translation {:?} stage {} [{}]",
                                est.scale,
                                est.rotation.coords.as_slice(),
                                est.translation.as_slice(),
                                r.pose_stage,
                                stages.join(" ")
                            );
                        }
                        if verbose && !(add < 0.02 && scale < 0.03) {
                            eprintln!(
                                "  MISS {id:<44} (pair {k:2}, seed {seed}) ADD-S {:6.2} % scale {:+6.2} % [{}]",
                                100.0 * add,
                                100.0 * (est.scale / s.truth[n].scale - 1.0),
                                r.method
                            );
                            let gs = gstats[n];
                            eprintln!(
                                "      guidance: {:.1} % outliers, {:.1} % of the object uncovered, offset {:+.2} % of the diagonal, extent ratio {:.3}; scale/offset corr² {:.3}",
                                gs.outliers, gs.uncovered, gs.offset, gs.extent_ratio,
                                interact3d::compose::plane_icp::scale_offset_correlation(
                                    &interact3d::compose::cloud::Cloud::sample(&inp.visual, 4000, 1)
                                )
                            );
                            let truth_s = s.truth[n].scale;
                            miss_probe::print(inp, &s.truth[n], &est, r.initial_scale);
                            for st in &r.stages {
                                eprintln!(
                                    "      {:<20} fit {:.3e} scale {:+6.2} % {}",
                                    st.stage,
                                    st.fit,
                                    100.0 * (st.scale / truth_s - 1.0),
                                    if st.accepted { "taken" } else { "refused" }
                                );
                            }
                        }
                        recs.push(Record {
                            pair: k,
                            seed,
                            id: id.to_string(),
                            add_s: add,
                            scale,
                            scale_signed: est.scale / s.truth[n].scale - 1.0,
                            stage: r.pose_stage.clone(),
                            guidance: gstats[n],
                        });
                        placed.push(inp.visual.geometry().transformed(&est.matrix()));
                        truth_placed.push(inp.visual.geometry().transformed(&s.truth[n].matrix()));
                        if std::env::var_os("COLOUR_JUDGE").is_some() {
                            let anchor = (n > 0).then(|| &placed[0]);
                            colour_probe::judge(id, seed, inp, &s.truth[n], &est, anchor);
                        }
                        if n > 0 && std::env::var_os("SUPPORT_PROBE").is_some() {
                            miss_probe::support(id, inp, &placed[0], &s.truth[n], &est);
                        }
                        if verbose && n > 0 {
                            miss_probe::contact(
                                id,
                                inp,
                                (&placed[0], &est),
                                (&truth_placed[0], &s.truth[n]),
                                r.contact.as_ref(),
                            );
                            if let Some(cr) = &r.colour_rest {
                                eprintln!(
                                    "  COLOURREST {id:<44} (pair {k:2}, seed {seed}) {}",
                                    serde_json::to_string(cr).unwrap_or_default()
                                );
                            }
                            if let Some(sr) = &r.support {
                                eprintln!(
                                    "  SUPPORTSTAGE {id:<44} (pair {k:2}, seed {seed}) {}",
                                    serde_json::to_string(sr).unwrap_or_default()
                                );
                            }
                        }
                    }
                    let mopts = MetricsOptions {
                        points: 100_000,
                        ..Default::default()
                    };
                    let rv = |m: &[interact3d::mesh::Mesh]| {
                        let a = Prepared::new(Solid::Mesh(&m[0]));
                        let b = Prepared::new(Solid::Mesh(&m[1]));
                        pair_metrics(&a, &b, &mopts).r_volume
                    };
                    let diagonal = interact3d::mesh::Aabb::of_points(&truth_placed[1].vertices)
                        .map_or(0.0, |b| b.extents().norm());
                    let scene_rec = SceneRecord {
                        seed,
                        r_volume: rv(&placed),
                        truth_r_volume: rv(&truth_placed),
                        truth_gap: rest::mesh_gap(&truth_placed[0], &truth_placed[1]) / diagonal,
                        secs,
                        sizes: [object_size(&s.inputs[0]), object_size(&s.inputs[1])],
                    };
                    if verbose {
                        eprintln!(
                            "pair {k:2} seed {seed}: {sid} + {iid}: {secs:.2} s ({wall:.2} s wall), R_volume {:.1e} (truth {:.1e}, true gap {:.3} % of the item's diagonal), done at {:.0} s",
                            scene_rec.r_volume,
                            scene_rec.truth_r_volume,
                            100.0 * scene_rec.truth_gap,
                            t_all.elapsed().as_secs_f64()
                        );
                    }
                    results.lock().unwrap().push((w, recs, scene_rec));
                }
            });
        }
    });
    let mut results = results.into_inner().unwrap();
    results.sort_by_key(|r| r.0);
    let slowest: Vec<(usize, &SceneRecord)> = {
        let mut v: Vec<(usize, &SceneRecord)> =
            results.iter().map(|r| (r.1[0].pair, &r.2)).collect();
        // Slowest first; ties by pair, then seed (the listing does not depend on the jobs).
        v.sort_by(|a, b| {
            b.1.secs
                .total_cmp(&a.1.secs)
                .then(a.0.cmp(&b.0))
                .then(a.1.seed.cmp(&b.1.seed))
        });
        v
    };
    let recs: Vec<&Record> = results.iter().flat_map(|r| &r.1).collect();
    let scenes: Vec<&SceneRecord> = results.iter().map(|r| &r.2).collect();
    let ok2 = |r: &Record| r.add_s < 0.02 && r.scale < 0.03;
    let ok5 = |r: &Record| r.add_s < 0.05 && r.scale < 0.05;

    println!(
        "\n#### Realistic guidance ({}): {} pairs × {seeds} seeds (generator seeds 7000+s, pipeline seeds s = {offset}..{})\n",
        if subdivided { "subdivided object surfaces" } else { "separate reconstruction" },
        pairs.len(),
        offset + seeds
    );
    println!("| seed | objects | ≤ 2 % ADD-S & 3 % scale | ≤ 5 % & 5 % | max R_volume | scenes R_volume > 1e-4 | mean s / pair | max s / pair |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|");
    let mut seed_list: Vec<u64> = scenes.iter().map(|s| s.seed).collect();
    seed_list.sort();
    seed_list.dedup();
    let row = |label: String, rs: &[&Record], ss: &[&SceneRecord]| {
        let n = rs.len();
        let times: Vec<f64> = ss.iter().map(|s| s.secs).collect();
        println!(
            "| {label} | {n} | {} | {} | {:.1e} | {} | {:.2} | {:.2} |",
            pct(rs.iter().filter(|r| ok2(r)).count(), n),
            pct(rs.iter().filter(|r| ok5(r)).count(), n),
            ss.iter().map(|s| s.r_volume).fold(0.0, f64::max),
            ss.iter().filter(|s| s.r_volume > 1e-4).count(),
            times.iter().sum::<f64>() / times.len().max(1) as f64,
            times.iter().cloned().fold(0.0, f64::max),
        );
    };
    for &sd in &seed_list {
        let rs: Vec<&Record> = recs.iter().copied().filter(|r| r.seed == sd).collect();
        let ss: Vec<&SceneRecord> = scenes.iter().copied().filter(|s| s.seed == sd).collect();
        row(sd.to_string(), &rs, &ss);
    }
    row("all".into(), &recs, &scenes);
    println!(
        "\nground-truth scenes: max R_volume {:.1e} (the truth's own contact, for reference)",
        scenes.iter().map(|s| s.truth_r_volume).fold(0.0, f64::max)
    );
    // The truth rests: R_volume 0 and every item's exact gap in [0, 2 × the clearance].
    let bad_truth = scenes
        .iter()
        .filter(|s| {
            s.truth_r_volume > 0.0
                || !(0.0..=2.0 * realistic::REST_CLEARANCE).contains(&s.truth_gap)
        })
        .count();
    for &sd in &seed_list {
        let g = scenes
            .iter()
            .filter(|s| s.seed == sd)
            .map(|s| s.truth_gap)
            .fold(0.0, f64::max);
        println!(
            "seed {sd}: max true gap {:.3} % of the item's diagonal",
            100.0 * g
        );
    }
    println!(
        "truth check (R_volume 0, gap within [0, {:.1} %]): {bad_truth} of {} scenes fail",
        200.0 * realistic::REST_CLEARANCE,
        scenes.len()
    );

    println!("\n#### Per object (over seeds): ADD-S and scale error in % of the object's diagonal / size\n");
    println!("| pair | object | ≤ 2 % | ≤ 5 % | mean ADD-S | worst ADD-S | mean scale err | worst scale err | mean signed scale err | guidance outliers | object uncovered | guidance offset | guidance extent ratio | winning stages |");
    println!("|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    let mut keys: Vec<(usize, String)> = recs.iter().map(|r| (r.pair, r.id.clone())).collect();
    keys.sort();
    keys.dedup();
    for (k, id) in keys {
        let rs: Vec<&Record> = recs
            .iter()
            .copied()
            .filter(|r| r.pair == k && r.id == id)
            .collect();
        let n = rs.len();
        let mut stages: BTreeMap<&str, usize> = BTreeMap::new();
        for r in &rs {
            *stages.entry(r.stage.as_str()).or_default() += 1;
        }
        let mean = |f: &dyn Fn(&Record) -> f64| rs.iter().map(|&r| f(r)).sum::<f64>() / n as f64;
        println!(
            "| {k} | {id} | {}/{n} | {}/{n} | {:.2} | {:.2} | {:.2} | {:.2} | {:+.2} | {:.1} % | {:.1} % | {:+.2} % | {:.3} | {} |",
            rs.iter().filter(|r| ok2(r)).count(),
            rs.iter().filter(|r| ok5(r)).count(),
            100.0 * rs.iter().map(|r| r.add_s).sum::<f64>() / n as f64,
            100.0 * rs.iter().map(|r| r.add_s).fold(0.0, f64::max),
            100.0 * rs.iter().map(|r| r.scale).sum::<f64>() / n as f64,
            100.0 * rs.iter().map(|r| r.scale).fold(0.0, f64::max),
            100.0 * mean(&|r| r.scale_signed),
            mean(&|r| r.guidance.outliers),
            mean(&|r| r.guidance.uncovered),
            mean(&|r| r.guidance.offset),
            mean(&|r| r.guidance.extent_ratio),
            stages
                .iter()
                .map(|(s, c)| format!("{s} ×{c}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let n_slow = if verbose {
        slowest.len()
    } else {
        slowest.len().min(10)
    };
    // A run that composed nothing (`--profile-probe`) has no pairs to list.
    if !slowest.is_empty() {
        println!(
            "\n#### The slowest pairs ({} of {}; s of `compose` a pair, CPU on one thread, else wall)\n",
            n_slow,
            slowest.len()
        );
        println!("| s | pair | seed | support | item | support tris (guidance) | item tris (guidance) | support texture | item texture |");
        println!("|---:|---:|---:|---|---|---:|---:|---:|---:|");
        let tex = |t: (u32, u32)| {
            if t.0 == 0 {
                "-".to_string()
            } else {
                format!("{}×{}", t.0, t.1)
            }
        };
        for &(k, s) in &slowest[..n_slow] {
            let [a, b] = s.sizes;
            println!(
                "| {:.2} | {k} | {} | {} | {} | {} ({}) | {} ({}) | {} | {} |",
                s.secs,
                s.seed,
                PAIRS[k].0,
                PAIRS[k].1,
                a.tris,
                a.guidance_tris,
                b.tris,
                b.guidance_tris,
                tex(a.texture),
                tex(b.texture)
            );
        }
    }
    println!(
        "\n{} compose calls, {} thread(s) each, {} job(s), total {:.1} s",
        scenes.len(),
        threads,
        jobs,
        t_all.elapsed().as_secs_f64()
    );
    if bad_truth > 0 {
        std::process::exit(1);
    }
}
