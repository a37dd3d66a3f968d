//! The quickhull against parry's `try_convex_hull`, to the bit: random, degenerate and real
//! point sets.

use super::{assert_parry_agrees, convex_hull, parry_hull};
use crate::rng::Rng;
use parry3d_f64::math::Vector3;

/// Checks one set; `true` when parry built a hull of it.
fn check(points: &[Vector3]) -> bool {
    let got = std::panic::catch_unwind(|| convex_hull(points))
        .ok()
        .and_then(|r| r.ok());
    assert_parry_agrees(points, got.as_ref());
    got.is_some()
}

fn shuffled(rng: &mut Rng, mut v: Vec<Vector3>) -> Vec<Vector3> {
    for i in (1..v.len()).rev() {
        v.swap(i, rng.below(i + 1));
    }
    v
}

/// Counts of (hull built, failed) over the sets.
fn tally(sets: impl IntoIterator<Item = Vec<Vector3>>) -> (usize, usize) {
    sets.into_iter().fold((0, 0), |(ok, bad), s| {
        if check(&s) {
            (ok + 1, bad)
        } else {
            (ok, bad + 1)
        }
    })
}

#[test]
fn random_sets_match_parry() {
    let mut rng = Rng::new(37);
    let mut sets = Vec::new();
    for k in 0..3000 {
        let n = 4 + k % 61;
        let (s, o) = (rng.range(1e-3, 10.0), rng.range(-5.0, 5.0));
        let mut v: Vec<Vector3> = (0..n)
            .map(|_| {
                Vector3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * s + Vector3::splat(o)
            })
            .collect();
        if k % 3 == 0 {
            // On a sphere: every point a vertex.
            for p in &mut v {
                let d = Vector3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
                *p = d * s + Vector3::splat(o);
            }
        }
        sets.push(v);
    }
    // Larger sets, as `Hull::from_mesh`'s callers pass whole meshes.
    for n in [100, 300, 1000] {
        sets.push(
            (0..n)
                .map(|_| Vector3::new(rng.normal(), rng.normal(), rng.normal()))
                .collect(),
        );
    }
    let (ok, bad) = tally(sets);
    assert!(ok >= 2990, "{ok} built, {bad} failed");
}

#[test]
fn degenerate_sets_match_parry() {
    let mut rng = Rng::new(3737);
    let mut sets: Vec<Vec<Vector3>> = Vec::new();
    for k in 0..400 {
        let n = 4 + k % 61;
        let base: Vec<Vector3> = (0..n)
            .map(|_| Vector3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()))
            .collect();
        // Coplanar, collinear and one point (parry's 2-, 1- and 0-dimensional cases).
        sets.push(base.iter().map(|p| Vector3::new(p.x, p.y, 0.25)).collect());
        sets.push(
            base.iter()
                .map(|p| Vector3::new(p.x, 2.0 * p.x + 1.0, -p.x))
                .collect(),
        );
        sets.push(vec![base[0]; n]);
        // Nearly coplanar: a slab 1e-15 to 1e-6 thick (around parry's 1e-7 eigenvalue test
        // and its 100 ε visibility threshold).
        let t = [1e-15, 1e-13, 1e-11, 1e-9, 1e-8, 1e-7, 1e-6][k % 7];
        sets.push(
            base.iter()
                .map(|p| Vector3::new(p.x, p.y, t * p.z))
                .collect(),
        );
        // Duplicates: every point twice or three times, shuffled.
        let mut d = base.clone();
        d.extend_from_slice(&base[..n / 2]);
        d.extend_from_slice(&base);
        sets.push(shuffled(&mut rng, d));
        // A grid: coplanar faces, ties everywhere, with and without a tiny jitter.
        let m = 2 + k % 3;
        let grid: Vec<Vector3> = (0..m * m * m)
            .map(|i| Vector3::new((i % m) as f64, ((i / m) % m) as f64, (i / (m * m)) as f64))
            .collect();
        let j = [0.0, 1e-16, 1e-14, 1e-12][k % 4];
        let grid: Vec<Vector3> = grid
            .into_iter()
            .map(|p| p + Vector3::new(rng.normal(), rng.normal(), rng.normal()) * j)
            .collect();
        sets.push(shuffled(&mut rng, grid));
        // A box with points on its faces, pushed out or in by up to 1e-13.
        let mut b: Vec<Vector3> = (0..8)
            .map(|i| Vector3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect();
        for _ in 0..n {
            let (u, w) = (rng.next_f64(), rng.next_f64());
            let e = rng.range(-1e-13, 1e-13);
            b.push(match rng.below(3) {
                0 => Vector3::new(1.0 + e, u, w),
                1 => Vector3::new(u, -e, w),
                _ => Vector3::new(u, w, 1.0 + e),
            });
        }
        sets.push(shuffled(&mut rng, b));
    }
    let (ok, bad) = tally(sets);
    // The single-point sets fail in both (flat and straight ones give parry's flat meshes).
    assert!(ok > 2000 && bad >= 400, "{ok} built, {bad} failed");
}

/// `shared/` beside the repository, or beside the worktree's parent.
fn shared() -> Option<std::path::PathBuf> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    [root.join("../shared"), root.join("../../shared")]
        .into_iter()
        .find(|p| p.join("datasets/objects/index.json").is_file())
}

/// Every shared object (at its `scale_to_m`): its whole vertex set, and patches of its
/// surface (the 8 to 64 vertices nearest a random vertex: the near-coplanar, near-duplicate
/// sets a candidate part's picks are made of), against parry.
#[test]
fn shared_objects_match_parry() {
    let Some(sh) = shared() else {
        eprintln!("shared datasets not present: skipped");
        return;
    };
    let index: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(sh.join("datasets/objects/index.json")).unwrap(),
    )
    .unwrap();
    let mut rng = Rng::new(43);
    let (mut objects, mut ok, mut bad) = (0, 0, 0);
    for o in index.as_array().unwrap() {
        let Some(rel) = o.get("mesh").and_then(|v| v.as_str()) else {
            continue;
        };
        let scale = o.get("scale_to_m").and_then(|v| v.as_f64()).unwrap_or(1.0);
        let p = sh.join("datasets/objects").join(rel);
        let mesh = crate::io::load_visual(&p, &crate::io::Limits::default())
            .unwrap()
            .geometry();
        let pts: Vec<Vector3> = mesh
            .vertices
            .iter()
            .map(|v| Vector3::new(v.x, v.y, v.z) * scale)
            .collect();
        objects += 1;
        let mut sets = vec![pts.clone()];
        for k in 0..40 {
            let c = pts[rng.below(pts.len())];
            let mut near: Vec<(f64, usize)> = pts
                .iter()
                .enumerate()
                .map(|(i, p)| ((*p - c).length_squared(), i))
                .collect();
            near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let n = [8, 16, 32, 64][k % 4].min(pts.len());
            sets.push(near[..n].iter().map(|&(_, i)| pts[i]).collect());
        }
        let (o, b) = tally(sets);
        ok += o;
        bad += b;
    }
    assert_eq!(objects, 43);
    assert!(ok > 1000, "{ok} built, {bad} failed");
    eprintln!("{objects} objects: {ok} hulls built, {bad} failed, all as parry");
}

#[test]
fn a_tetrahedron_is_parry_s() {
    let t = [
        Vector3::ZERO,
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(0.0, 1.0, 0.0),
        Vector3::new(0.0, 0.0, 1.0),
    ];
    let (v, i) = convex_hull(&t).unwrap();
    assert_eq!(v.len(), 4);
    assert_eq!(i.len(), 4);
    assert_eq!(Some((v, i)), parry_hull(&t));
}
