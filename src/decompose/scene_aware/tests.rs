//! Tests of the scene-aware engine against independent expectations: analytic shapes and the
//! generated fixtures (0.75 mm gaps), real scenes when `../shared` is present.

use super::metrics;
use super::*;
use crate::decompose::Decomposer;
use crate::mesh::{Mesh, P3, V3};
use crate::shapes;
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::shape::ConvexPolyhedron;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

fn opts() -> DecomposeOptions {
    DecomposeOptions::default()
}

/// `m` moved by `d`.
fn moved(m: &Mesh, d: V3) -> Mesh {
    m.transformed(&nalgebra::Translation3::from(d).to_homogeneous())
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name)
}

/// `shared/` beside the repository, or beside the worktree's parent.
fn shared() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    [root.join("../shared"), root.join("../../shared")]
        .into_iter()
        .find(|p| p.join("datasets/scenes").is_dir())
}

/// The geometry of a shared object, `rel` under `shared/datasets/objects`.
fn shared_object(sh: &Path, rel: &str) -> Mesh {
    let p = sh.join("datasets/objects").join(rel);
    crate::io::load_visual(&p, &crate::io::Limits::default())
        .unwrap()
        .geometry()
}

fn world_meshes(path: &Path) -> Vec<Mesh> {
    let scene = crate::scene::load(path, &crate::io::Limits::default()).expect("scene loads");
    let prep = crate::prepare::prepare(&scene, &Default::default()).expect("scene prepares");
    prep.objects.into_iter().map(|o| o.geometry).collect()
}

/// A shared scene's world meshes and their decomposition at [`opts`]; `None` (the test is
/// skipped) without `shared/`.
fn shared_scene(name: &str) -> Option<(Vec<Mesh>, Vec<Vec<Hull>>, SceneAwareReport)> {
    let Some(sh) = shared() else {
        eprintln!("shared datasets not present: skipped");
        return None;
    };
    let meshes = world_meshes(&sh.join("datasets/scenes").join(name));
    let refs: Vec<&Mesh> = meshes.iter().collect();
    let (hulls, rep) = decompose_scene(&refs, &opts());
    Some((meshes, hulls, rep))
}

/// Independent check of the limits every hull must meet.
fn assert_limits(hulls: &[Hull], o: &DecomposeOptions) {
    assert!(
        !hulls.is_empty() && hulls.len() <= o.max_hulls,
        "{} hulls",
        hulls.len()
    );
    for h in hulls {
        assert!(
            h.vertices.len() <= o.max_vertices,
            "{} vertices",
            h.vertices.len()
        );
        assert!(
            h.thickness() >= o.min_thickness,
            "thickness {}",
            h.thickness()
        );
        assert!(h.volume > 0.0);
    }
}

/// Deepest overlap between hulls of different objects, by parry (built from the vertices
/// alone, independently of the engine's own triangles); 0 when all are apart.
fn deepest_cross_overlap(hulls: &[Vec<Hull>]) -> f64 {
    let poly = |h: &Hull| {
        let v: Vec<Vector> = h.vertices.iter().map(crate::mesh::to_dvec).collect();
        ConvexPolyhedron::from_convex_hull(&v).unwrap()
    };
    let id = Pose::identity();
    let mut worst = 0.0f64;
    for a in 0..hulls.len() {
        for b in a + 1..hulls.len() {
            for ha in &hulls[a] {
                for hb in &hulls[b] {
                    if !ha.aabb.intersects(&hb.aabb, 0.0) {
                        continue;
                    }
                    let c =
                        parry3d_f64::query::contact(&id, &poly(ha), &id, &poly(hb), 0.0).unwrap();
                    if let Some(c) = c {
                        worst = worst.max(-c.dist);
                    }
                }
            }
        }
    }
    worst
}

fn bowl() -> Mesh {
    shapes::bowl(0.08, 0.055, 0.004, 48, 10)
}

#[test]
fn bowl_keeps_its_cavity_and_follows_the_surface() {
    let o = opts();
    let mesh = bowl();
    let (hulls, rep) = decompose_scene(&[&mesh], &o);
    let hulls = &hulls[0];
    assert_limits(hulls, &o);
    assert!(!rep.objects[0].convex_shortcut);
    // Centre of the cavity, half-way up between floor (z = 4 mm) and rim (55 mm).
    let centre = P3::new(0.0, 0.0, 0.5 * (0.004 + 0.055));
    assert!(hulls.iter().all(|h| !h.contains(&centre)));
    // A 30 mm ball resting 0.75 mm above the floor meets no hull.
    let ball = shapes::uv_sphere(0.03, 16, 32).transformed(
        &nalgebra::Translation3::new(0.0, 0.0, 0.004 + 0.00075 + 0.03).to_homogeneous(),
    );
    let ball_hull = Hull::from_points(&ball.vertices).unwrap();
    assert_eq!(
        deepest_cross_overlap(&[hulls.clone(), vec![ball_hull]]),
        0.0
    );
    let q = metrics::measure(&mesh, hulls);
    // The issue asks p95 <= 1 % of the diagonal. On this thin, strongly curved bowl 32 convex
    // pieces leave a sagitta of ~5 mm where they bridge the inside (measured p95 1.86 %;
    // CoACD 1.05 % with 46 hulls of up to 341 vertices): we hold what we reach and show that
    // the budget, not the method, is the limit (64 hulls: 1.17 %).
    assert!(q.dist_p95 <= 0.02, "{q:?}");
    assert_eq!(q.cavity_kept, Some(true));
    assert!(q.uncovered < 0.02, "{q:?}");
    assert!(q.volume_ratio > 0.8 && q.volume_ratio < 1.7, "{q:?}");
    let o64 = DecomposeOptions {
        max_hulls: 64,
        ..opts()
    };
    let (h64, _) = decompose_scene(&[&mesh], &o64);
    let q64 = metrics::measure(&mesh, &h64[0]);
    assert!(
        q64.dist_p95 <= 0.0125 && q64.dist_p95 < q.dist_p95,
        "{q64:?}"
    );
    assert_eq!(q64.cavity_kept, Some(true));
}

#[test]
fn a_larger_budget_starts_where_the_default_does() {
    // The mug of `pen_mug` meets the tolerance with 26 hulls at the default 32. Started from
    // `budget/2` patches, 48 hulls read 0.70 % of the diagonal with 47 hulls against 0.46 %.
    let mug = world_meshes(&fixture("pen_mug")).swap_remove(0);
    let at = |max_hulls| {
        let o = DecomposeOptions {
            max_hulls,
            ..opts()
        };
        let (hulls, _) = decompose_scene(&[&mug], &o);
        assert_limits(&hulls[0], &o);
        metrics::measure(&mug, &hulls[0])
    };
    let (q32, q48) = (at(32), at(48));
    assert!(q32.dist_p95 <= opts().tolerance, "{q32:?}");
    assert_eq!(q48.hulls, q32.hulls, "{q48:?}");
    assert!(q48.dist_p95 <= q32.dist_p95, "{q32:?} {q48:?}");
}

#[test]
fn convex_shortcut_for_sphere_and_box() {
    // The shortcut hull is built from mesh vertices and inflated by at most a quarter of the
    // tolerance (so it cannot close a gap left by the composition). A 64-vertex hull of a fine
    // sphere is then 1.2 % of the diagonal off at the 95th percentile (measured), over the 1 %
    // tolerance, so the sphere takes the shortcut with a 128-vertex budget; at 64 it gets patch
    // hulls instead. The shortcut is one hull, or exact cone pieces of the sphere's hull when
    // one hull leaves more than half the tolerance of its surface outside (issue #35): either
    // way the volume is the sphere's within 3 % and the surface within the tolerance.
    let mut o = opts();
    o.max_vertices = 128;
    let sphere = shapes::uv_sphere(0.05, 24, 48);
    let cube = shapes::cuboid(V3::new(0.04, 0.06, 0.03));
    let (hulls, rep) = decompose_scene(&[&sphere], &o);
    assert!(rep.objects[0].convex_shortcut);
    let v = sphere.signed_volume();
    // Cone pieces overlap one another: the volume of their union (grid of 128 cells across).
    let vol = metrics::union_volume(&hulls[0], 128);
    assert!((vol - v).abs() <= 0.03 * v, "{vol} vs {v}");
    assert!(hulls[0].iter().all(|h| h.vertices.len() <= 128));
    let f = metrics::two_sided_of(&sphere, &hulls[0]).unwrap();
    assert!(
        f.p95 <= o.tolerance && f.outside_p99 <= 0.5 * o.tolerance,
        "{f:?}"
    );
    let o = opts();
    let (hulls, rep) = decompose_scene(&[&cube], &o);
    assert!(rep.objects[0].convex_shortcut);
    assert_eq!(hulls[0].len(), 1);
    assert!((hulls[0][0].volume - cube.signed_volume()).abs() < 1e-12);
}

/// Issue #35: a rounded solid whose 64-vertex hull cuts its surface off does not get that one
/// hull. The YCB strawberry's simplified hull leaves more than three quarters of the tolerance
/// outside at the 99th percentile (the shortcut's inflation gives back at most a quarter);
/// the engine's hulls leave at most half of it outside and lie within it both ways.
#[test]
fn one_hull_is_refused_when_it_leaves_the_surface_outside() {
    let Some(shared) = shared() else {
        eprintln!("shared datasets not present: skipped");
        return;
    };
    let path = shared.join("datasets/objects/ycb/012_strawberry/textured.obj");
    let m = crate::io::load_visual(&path, &Default::default())
        .unwrap()
        .geometry();
    let o = opts();
    let one = Hull::from_points(&m.vertices)
        .unwrap()
        .simplified(o.max_vertices)
        .unwrap();
    let f1 = metrics::two_sided_of(&m, &[one]).unwrap();
    assert!(f1.outside_p99 > 0.75 * o.tolerance, "{f1:?}");
    let (hulls, rep) = decompose_scene(&[&m], &o);
    assert!(hulls[0].len() > 1, "{:?}", rep.objects[0]);
    let f = metrics::two_sided_of(&m, &hulls[0]).unwrap();
    assert!(f.outside_p99 <= 0.5 * o.tolerance, "{f:?}");
    assert!(f.p95 <= o.tolerance, "{f:?}");
}

/// A fixture scene: limits met, no hull of one object within the clearance of another's
/// (0.1 mm penetration allowed by the issue; we ask for none), contained items stay inside
/// (the container's cavity probe is free).
fn check_scene(path: &Path) -> SceneAwareReport {
    let meshes = world_meshes(path);
    let refs: Vec<&Mesh> = meshes.iter().collect();
    let o = opts();
    let t = std::time::Instant::now();
    let (hulls, rep) = decompose_scene(&refs, &o);
    eprintln!(
        "{}: {:.2} s {:?}",
        path.display(),
        t.elapsed().as_secs_f64(),
        rep
    );
    for h in &hulls {
        assert_limits(h, &o);
    }
    let worst = deepest_cross_overlap(&hulls);
    assert!(worst <= 1e-4, "{}: overlap {worst}", path.display());
    assert!(worst == 0.0, "{}: overlap {worst}", path.display());
    for (k, r) in rep.objects.iter().enumerate() {
        assert_eq!(r.overlaps, 0);
        assert!(r.mesh_penetration.is_empty(), "{r:?}");
        // An object farther from its mesh than the tolerance, either way, says so (the
        // warning `body::assemble` adds).
        let f = metrics::two_sided_of(&meshes[k], &hulls[k]).unwrap();
        let w = metrics::tolerance_warning(&f, o.tolerance, hulls[k].len(), o.max_hulls);
        assert_eq!(w.is_some(), f.p95 > o.tolerance, "{f:?}");
    }
    // The support (object 0) keeps its cavity where it is a container.
    let s = geom::Surface::new(&meshes[0]).unwrap();
    if let Some(p) = metrics::cavity_probe(&s) {
        assert!(hulls[0].iter().all(|h| !h.contains(&p)), "cavity filled");
    }
    // Items: every vertex of an item's hulls is outside the support's hulls (it is not
    // pushed out of the container by a bulge).
    for item in &hulls[1..] {
        for h in item {
            for v in &h.vertices {
                assert!(hulls[0].iter().all(|g| !g.contains(v)));
            }
        }
    }
    rep
}

#[test]
fn pen_in_mug_hulls_apart() {
    check_scene(&fixture("pen_mug"));
}

#[test]
fn ball_in_bowl_hulls_apart() {
    // The ball (960 triangles) is too round for a single 64-vertex hull within 1 % (see
    // convex_shortcut_for_sphere_and_box); check_scene asserts its hulls stay off the bowl.
    check_scene(&fixture("ball_bowl"));
}

#[test]
fn fruit_in_basket_hulls_apart() {
    check_scene(&fixture("fruit_basket"));
}

#[test]
fn box_on_tray_hulls_apart() {
    check_scene(&fixture("box_tray"));
}

#[test]
fn box_on_shelf_hulls_apart_and_the_shelf_stays_open() {
    check_scene(&fixture("shelf_item"));
    // From fixtures/shelf_item/README.md: the cavity between the middle board (top face at
    // z = 300 mm) and the top board (bottom face at 532 mm) spans x in ±182 mm. Points across
    // it, in front of, at and behind the box's place, are outside every hull of the shelf.
    let meshes = world_meshes(&fixture("shelf_item"));
    let (hulls, _) = decompose_scene(&[&meshes[0]], &opts());
    for x in [-0.17, -0.09, 0.0, 0.09, 0.17] {
        for y in [-0.1, 0.0, 0.1] {
            for z in [0.31, 0.42, 0.52] {
                let p = P3::new(x, y, z);
                assert!(hulls[0].iter().all(|h| !h.contains(&p)), "{p:?} filled");
            }
        }
    }
}

#[test]
fn real_scenes_hulls_apart() {
    let Some(shared) = shared() else {
        eprintln!("shared datasets not present: skipped");
        return;
    };
    // 00008: the polishing next to a neighbour moves patches; 00009: V-HACD's hulls for the
    // bottle, not for the lunch box it stands on.
    for s in [
        "food/00001_lemon_bowl",
        "toys/00007_ball_mug",
        "kitchenware/00008_spoon_mug",
        "household/00009_bottle_lunchbox",
        // Star pieces: the apple and the plum in the bowl; shoes resting on one another.
        "food/00002_fruit_bowl",
        "apparel/00005_shoes_tray",
    ] {
        check_scene(&shared.join("datasets/scenes").join(s));
    }
}

/// A neighbour hovering over a floor within the tolerance lands on it, so the contact splits
/// reach it (`contact_splits`). The ball of `ball_bowl` lifted 0.8 of the bowl's tolerance
/// above its composed pose (1.9 mm): the floor is still split under it, and the hull straight
/// below its lowest point is level within 1° (0.65°; 5.3° when the splits stopped at the
/// hulls' own reach, where a patch spanning floor and wall tilted it).
#[test]
fn a_neighbour_hovering_within_the_tolerance_is_split_under() {
    let o = opts();
    let meshes = world_meshes(&fixture("ball_bowl"));
    let (bowl, ball) = (&meshes[0], &meshes[1]);
    let tol = o.tolerance * bowl.aabb().unwrap().diagonal();
    let lifted = moved(ball, V3::new(0.0, 0.0, 0.8 * tol));
    let (hulls, rep) = decompose_scene(&[bowl, &lifted], &o);
    assert!(rep.objects[0].neighbour_splits > 0, "{:?}", rep.objects[0]);
    let low = lifted
        .vertices
        .iter()
        .min_by(|a, b| a.z.total_cmp(&b.z))
        .unwrap();
    // The top face of each hull the vertical line through `low` crosses, at that line.
    let top = |h: &Hull| {
        let mut best: Option<(f64, V3)> = None;
        for (n, d) in &h.planes {
            if n.z > 1e-6 {
                let z = (d - n.x * low.x - n.y * low.y) / n.z;
                if best.is_none_or(|b| z < b.0) {
                    best = Some((z, *n));
                }
            }
        }
        best.filter(|(z, _)| h.contains(&P3::new(low.x, low.y, z - 1e-7)))
    };
    let (z, n) = hulls[0]
        .iter()
        .filter_map(top)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .expect("a hull under the ball");
    assert!(z < low.z, "{z} above the ball's lowest point {}", low.z);
    let tilt = n.z.acos().to_degrees();
    assert!(tilt <= 1.0, "the floor under the ball tilts {tilt:.2}°");
}

/// The shoe on the tray of `00004` needs none of the four hulls kept back for its neighbour:
/// they go to its free patches, closer to its surface, and the tray is left as it was.
#[test]
fn what_the_neighbours_leave_of_the_budget_is_spent() {
    let Some(sh) = shared() else {
        eprintln!("shared datasets not present: skipped");
        return;
    };
    let o = opts();
    let meshes = world_meshes(&sh.join("datasets/scenes/apparel/00004_shoe_tray"));
    let refs: Vec<&Mesh> = meshes.iter().collect();
    let (kept, r_kept, _) = decompose_scene_with(&refs, &o, false);
    let (spent, r_spent) = decompose_scene(&refs, &o);
    let (r0, r1) = (&r_kept.objects[1], &r_spent.objects[1]);
    let left = o.max_hulls - kept[1].len();
    assert!(left > 0 && r0.neighbour_splits < o.max_hulls / 8, "{r0:?}");
    assert_eq!(spent[1].len(), o.max_hulls);
    assert_eq!(r1.topped_up, left);
    assert_eq!(kept[0], spent[0], "the tray is left as it is");
    assert_eq!(deepest_cross_overlap(&spent), 0.0);
    assert_limits(&spent[1], &o);
    let p95 = |h: &[Hull]| metrics::measure(&meshes[1], h).dist_p95;
    let (before, after) = (p95(&kept[1]), p95(&spent[1]));
    eprintln!("shoe p95 {:.3} % -> {:.3} %", before * 100.0, after * 100.0);
    assert!(after <= 0.95 * before, "{before} -> {after}");
}

/// The lunch box of `00009` carries a bottle on a lid that undulates by 4 mm: its star pieces
/// rise above the lid and keeping them level takes more pieces than the budget, so it got
/// surface patches, a shell 3.93 % of its diagonal from its surface at the 95th percentile.
/// Star pieces under slabs where the bottle stands bring it within the tolerance (0.81 %).
#[test]
fn a_solid_carrying_a_neighbour_on_an_uneven_top_is_star_pieces_under_slabs() {
    let Some((meshes, hulls, rep)) = shared_scene("household/00009_bottle_lunchbox") else {
        return;
    };
    let o = opts();
    let r = &rep.objects[0];
    assert!(r.star_pieces && r.slabs >= 4, "{r:?}");
    assert_limits(&hulls[0], &o);
    assert_eq!(deepest_cross_overlap(&hulls), 0.0);
    let q = metrics::measure(&meshes[0], &hulls[0]);
    eprintln!("lunch box: {q:?}");
    assert!(q.dist_p95 <= o.tolerance, "{q:?}");
    // A solid: the hulls hold most of its volume (the patches held a shell).
    let vol = meshes[0].signed_volume().abs();
    assert!(metrics::union_volume(&hulls[0], 48) > 0.9 * vol);
}

/// The ground pins nothing: a plate under an avocado half (shared scene 00006) is rebalanced
/// and polished but where the avocado may touch it, and comes within 1.3× of its p95 alone
/// (measured 1.25 against 0.99 % of its diagonal; 1.51 % when its underside was pinned).
#[test]
fn the_ground_does_not_pin_what_stands_on_it() {
    let Some((meshes, in_scene, rep)) = shared_scene("food/00006_avocado_plate") else {
        return;
    };
    let (alone, _) = decompose_scene(&[&meshes[0]], &opts());
    let p95 = |h: &[Hull]| metrics::measure(&meshes[0], h).dist_p95;
    let (a, b) = (p95(&alone[0]), p95(&in_scene[0]));
    eprintln!(
        "plate p95 alone {:.3} %, in its scene {:.3} %",
        a * 100.0,
        b * 100.0
    );
    assert!(rep.objects[0].polish_rounds > 0, "{:?}", rep.objects[0]);
    assert!(b <= 1.3 * a, "{b} vs {a} alone");
    assert_eq!(deepest_cross_overlap(&in_scene), 0.0);
}

/// A container carrying a neighbour on its floor alone runs both strategies and keeps the
/// closer: the cup of `00010`, with a die lying at its bottom, takes the top-down plane cuts
/// (p95 2.34 % of its diagonal, 2.70 % with the patches). The mug of `pen_mug`, with the pen
/// leaning on its rim, keeps the patches.
#[test]
fn only_a_neighbour_leaning_on_a_side_keeps_a_carrier_to_the_patches() {
    let o = opts();
    let meshes = world_meshes(&fixture("pen_mug"));
    let refs: Vec<&Mesh> = meshes.iter().collect();
    let (_, rep) = decompose_scene(&refs, &o);
    assert!(!rep.objects[0].top_down, "{:?}", rep.objects[0]);
    let Some((meshes, hulls, rep)) = shared_scene("toys/00010_dice_cup") else {
        return;
    };
    assert!(rep.objects[0].top_down, "{:?}", rep.objects[0]);
    let p95 = metrics::measure(&meshes[0], &hulls[0]).dist_p95;
    eprintln!("dice cup p95 {:.3} %", p95 * 100.0);
    assert!(p95 < 0.025, "{p95}");
    assert_eq!(deepest_cross_overlap(&hulls), 0.0);
}

#[test]
fn interpenetrating_meshes_are_reported_and_hulls_cut_apart() {
    let a = shapes::cuboid(V3::new(0.05, 0.05, 0.05));
    // A 30 mm box sunk 1 mm into the first through its +x face.
    let b = shapes::cuboid(V3::new(0.03, 0.03, 0.03))
        .transformed(&nalgebra::Translation3::new(0.039, 0.0, 0.0).to_homogeneous());
    let (hulls, rep) = decompose_scene(&[&a, &b], &opts());
    let pen = rep.objects[0].mesh_penetration[0];
    assert_eq!(pen.0, 1);
    assert!((pen.1 - 0.001).abs() < 1e-6, "{pen:?}");
    assert_eq!(deepest_cross_overlap(&hulls), 0.0);
    assert!(!rep.objects[0].warnings().is_empty());
}

#[test]
fn deterministic_and_cached() {
    let meshes = world_meshes(&fixture("pen_mug"));
    let refs: Vec<&Mesh> = meshes.iter().collect();
    let dir = tempfile::tempdir().unwrap();
    let o = DecomposeOptions {
        cache_dir: Some(dir.path().to_path_buf()),
        ..opts()
    };
    let engine = SceneAware::new();
    let t = std::time::Instant::now();
    let first = engine.decompose(&refs, &o).unwrap();
    let cold = t.elapsed();
    assert!(!engine.last_report().unwrap().cached);
    let again = decompose_scene(&refs, &opts()).0;
    assert!(first == again, "two runs differ");
    let t = std::time::Instant::now();
    let cached = engine.decompose(&refs, &o).unwrap();
    let warm = t.elapsed();
    assert!(engine.last_report().unwrap().cached);
    assert!(first == cached, "cached hulls differ");
    assert!(warm * 5 < cold, "cache {warm:?} vs {cold:?}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn cone_pieces_are_exactly_the_hull() {
    // A 32x16 UV sphere: 32 x 15 ring vertices + 2 poles = 482 hull vertices, far over 64.
    let sphere = shapes::uv_sphere(0.033, 16, 32);
    let full = Hull::from_points(&sphere.vertices).unwrap();
    assert_eq!(full.vertices.len(), 482);
    let pieces = geom::cone_pieces(&full, 64, 32).unwrap();
    assert!(pieces.len() >= 8 && pieces.len() <= 16, "{}", pieces.len());
    // The union is the hull: every point of the hull is in a piece (pieces may overlap where
    // a patch outline is not convex as seen from the centre, so volumes do not simply add up).
    let sum: f64 = pieces.iter().map(|p| p.0.volume).sum();
    assert!(sum >= full.volume * (1.0 - 1e-12));
    let mut rng = crate::rng::Rng(7);
    let mut inside = 0;
    for _ in 0..20_000 {
        let q = P3::new(
            (rng.next_f64() - 0.5) * 0.068,
            (rng.next_f64() - 0.5) * 0.068,
            (rng.next_f64() - 0.5) * 0.068,
        );
        if full.contains(&q) {
            inside += 1;
            assert!(
                pieces.iter().any(|(h, _, _)| h.contains(&q)),
                "{q:?} uncovered"
            );
        }
    }
    assert!(inside > 8_000, "{inside}");
    for (h, outer, normal) in &pieces {
        assert!(h.vertices.len() <= 64);
        assert!(outer.len() <= 63 && normal.norm() > 0.99);
        // Inside the hull.
        assert!(h.vertices.iter().all(|v| full.plane_distance(v) <= 1e-12));
    }
    // Every hull face lies on the boundary of some piece (its centroid is on a piece's face
    // plane and inside the piece): together the pieces cover the whole surface.
    for t in &full.triangles {
        let c = P3::from(
            t.iter()
                .map(|&i| full.vertices[i as usize].coords)
                .sum::<V3>()
                / 3.0,
        );
        assert!(pieces
            .iter()
            .any(|(h, _, _)| h.plane_distance(&c).abs() <= 1e-12));
    }
    // Too few pieces allowed: refused.
    assert!(geom::cone_pieces(&full, 64, 3).is_none());
}

/// Rebalancing keeps the hull count and never raises the worst deviation; on shapes where the
/// binary splits left the patches uneven it lowers it. Measured independently of the engine's
/// own `dev` (64 samples per hull): the union-boundary distances of `metrics`.
#[test]
fn rebalancing_lowers_the_worst_deviation_at_the_same_budget() {
    let o = opts();
    let mut shapes_: Vec<(&str, Mesh, usize)> = vec![
        ("bowl/12", bowl(), 12),
        ("bowl/20", bowl(), 20),
        ("mug/16", shapes::mug(0.04, 0.09, 0.004, 0.006, 40), 16),
    ];
    if let Some(sh) = shared() {
        let p = sh.join("datasets/objects/gso/Room_Essentials_Mug_White_Yellow/model.obj");
        if let Ok(v) = crate::io::load_visual(&p, &crate::io::Limits::default()) {
            shapes_.push(("GSO mug/32", v.geometry(), 32));
        }
    }
    for strategy in &Strategy::ALL {
        let mut improved = 0;
        for (name, mesh, budget) in &shapes_ {
            // The rebalancing alone, without the polishing that follows it.
            let run = |rounds| {
                let effort = Effort {
                    rebalance: rounds,
                    polish: 0,
                };
                decompose_object(
                    Surface::new(mesh),
                    &o,
                    *budget,
                    effort,
                    &[],
                    &[],
                    &[*strategy],
                )
            };
            let (off, on) = (run(0), run(*budget));
            let hulls = |x: &Obj| x.parts.iter().map(|p| p.hull.clone()).collect::<Vec<_>>();
            let (h_off, h_on) = (hulls(&off), hulls(&on));
            assert_eq!(h_off.len(), h_on.len(), "{name}");
            assert_limits(&h_on, &o);
            let s = Surface::new(mesh).unwrap();
            let worst = |h: &[Hull]| {
                let d = metrics::surface_distances(&s, h, 20_000);
                metrics::stats(&d).2
            };
            let (w_off, w_on) = (worst(&h_off), worst(&h_on));
            eprintln!(
                "{name} {strategy:?}: {} rounds, worst {:.3} % -> {:.3} %",
                on.report.rebalance_rounds,
                w_off * 100.0,
                w_on * 100.0
            );
            // 2 % slack: the engine's own deviations are sampled more coarsely.
            assert!(w_on <= w_off * 1.02, "{name}: {w_off} -> {w_on}");
            if on.report.rebalance_rounds > 0 && w_on < 0.9 * w_off {
                improved += 1;
            }
            if on.report.rebalance_rounds == 0 {
                assert_eq!(h_off, h_on, "{name}: no round kept, same hulls");
            }
        }
        assert!(improved >= 1, "{strategy:?}: rebalancing helped nowhere");
    }
}

/// Next to a neighbour, the rebalancing and the polishing leave the patches the neighbour may
/// touch exactly as the quality loop made them, and still rebalance the rest: a ball resting
/// in the bowl, 0.75 mm above its floor.
#[test]
fn rebalancing_next_to_a_neighbour_keeps_the_patches_it_may_touch() {
    let o = opts();
    let mesh = bowl();
    let dims = shapes::bowl_dims(0.08, 0.055, 0.004);
    let r = 0.03;
    let lift = nalgebra::Matrix4::new_translation(&V3::new(0.0, 0.0, dims.floor_z + 7.5e-4 + r));
    let ball = shapes::uv_sphere(r, 16, 32).transformed(&lift);
    let s = Surface::new(&mesh).unwrap();
    let nb = Surface::new(&ball).unwrap();
    let (near, _) = contact_distances(&s, &[&nb], &o);
    let budget = o.max_hulls - o.max_hulls / 8;
    for strategy in &Strategy::ALL {
        let st = &[*strategy];
        let none = Effort {
            rebalance: 0,
            polish: 0,
        };
        let full = Effort::full(budget);
        let off = decompose_object(Surface::new(&mesh), &o, budget, none, &near, &near, st);
        let on = decompose_object(Surface::new(&mesh), &o, budget, full, &near, &near, st);
        assert!(
            on.report.rebalance_rounds > 0,
            "{strategy:?}: nothing rebalanced"
        );
        let p = on.params.unwrap();
        let mut kept = 0;
        for part in &on.parts {
            if rebalance::pinned(&near, &part.tris, part.dev, &p, &o) {
                assert!(
                    off.parts
                        .iter()
                        .any(|q| q.tris == part.tris && q.hull == part.hull),
                    "{strategy:?}: a pinned patch changed"
                );
                kept += 1;
            }
        }
        // The floor under the ball, in two patches at least (3 and 4 measured).
        assert!(kept >= 2, "{strategy:?}: {kept} pinned patches");
        // Unpinned, the same bowl's rebalancing changes some of those patches.
        let free = decompose_object(Surface::new(&mesh), &o, budget, full, &[], &[], st);
        let changed = off
            .parts
            .iter()
            .filter(|q| rebalance::pinned(&near, &q.tris, q.dev, &p, &o))
            .filter(|q| {
                !free
                    .parts
                    .iter()
                    .any(|f| f.tris == q.tris && f.hull == q.hull)
            })
            .count();
        eprintln!(
            "{strategy:?}: rounds {} + {} polished, pinned {kept}, changed when unpinned {changed} ({} rounds)",
            on.report.rebalance_rounds, on.report.polish_rounds, free.report.rebalance_rounds
        );
        assert!(changed > 0, "{strategy:?}: the pin protected nothing");
    }
}

/// A mesh made of closed convex pieces (a shelf of two panels and three boards) gets one exact
/// hull per piece: the hulls' volumes add up to the shelf's analytic volume, and no sampled
/// point of their surfaces is off the mesh.
#[test]
fn convex_pieces_of_a_mesh_get_one_exact_hull_each() {
    let o = opts();
    let (w, d, h, t) = (0.4, 0.25, 0.5, 0.018);
    let mesh = shapes::shelf(w, d, h, t, &[0.1, 0.25, 0.4]);
    let (hulls, rep) = decompose_scene(&[&mesh], &o);
    assert_eq!(hulls[0].len(), 5, "{:?}", rep.objects[0]);
    assert_eq!(rep.objects[0].quality_splits, 0);
    let vol: f64 = hulls[0].iter().map(|h| h.volume).sum();
    let expect = shapes::shelf_volume(w, d, h, t, 3);
    assert!((vol - expect).abs() <= 1e-9 * expect, "{vol} vs {expect}");
    let q = metrics::measure(&mesh, &hulls[0]);
    assert!(q.dist_max <= 1e-9, "{q:?}");
    assert!(q.uncovered == 0.0, "{q:?}");
    // One piece that is not convex (a bowl) next to a convex one (a box beside it): the box
    // keeps its exact hull, the bowl is decomposed as usual.
    let mut two = bowl();
    let cube = shapes::cuboid(V3::new(0.05, 0.05, 0.05))
        .transformed(&nalgebra::Translation3::new(0.2, 0.0, 0.025).to_homogeneous());
    two.append(&cube);
    let (hulls, _) = decompose_scene(&[&two], &o);
    assert!(hulls[0].len() > 2);
    assert!(
        hulls[0]
            .iter()
            .any(|h| h.vertices.len() == 8 && (h.volume - 0.05f64.powi(3)).abs() < 1e-12),
        "the box's own hull"
    );
}

/// Alone, the top-down plane cuts follow a standing container's level features and the engine
/// keeps them when they measure closer: the mug fixture (p95 1.02 → 0.82 % of the diagonal)
/// and, when `../shared` is present, the YCB cup with its foot ring and recessed floor
/// (2.81 → 2.04 %). Measured on the union boundary with 20,000 samples, not the engine's
/// 4,000. Next to a neighbour the bottom-up patches stay (the same mug, with its pen).
#[test]
fn top_down_plane_cuts_win_alone_on_level_featured_containers() {
    let o = opts();
    let mut cases: Vec<(&str, Mesh, f64)> = vec![(
        "mug fixture",
        world_meshes(&fixture("pen_mug")).remove(0),
        0.9,
    )];
    if let Some(sh) = shared() {
        let p = sh.join("datasets/objects/ycb/065-j_cups/textured.obj");
        if let Ok(v) = crate::io::load_visual(&p, &crate::io::Limits::default()) {
            cases.push(("YCB cup", v.geometry(), 0.8));
        }
    }
    for (name, mesh, ratio) in &cases {
        let b = o.max_hulls;
        let hulls = |x: &Obj| x.parts.iter().map(|p| p.hull.clone()).collect::<Vec<_>>();
        let e = Effort::full(b);
        let patches = hulls(&decompose_alone(mesh, &o, b, e, &[Strategy::Patches]));
        let planes = hulls(&decompose_alone(mesh, &o, b, e, &[Strategy::Planes]));
        let both = decompose_alone(mesh, &o, b, e, &Strategy::ALL);
        assert_limits(&planes, &o);
        let (q_patches, q_planes) = (
            metrics::measure(mesh, &patches),
            metrics::measure(mesh, &planes),
        );
        eprintln!(
            "{name}: p95 {:.3} % bottom-up, {:.3} % top-down",
            q_patches.dist_p95 * 100.0,
            q_planes.dist_p95 * 100.0
        );
        assert!(
            q_planes.dist_p95 <= ratio * q_patches.dist_p95,
            "{name}: {} vs {}",
            q_planes.dist_p95,
            q_patches.dist_p95
        );
        assert_eq!(q_planes.cavity_kept, Some(true), "{name}");
        assert!(both.report.top_down, "{name}: the closer strategy not kept");
        assert_eq!(hulls(&both), planes, "{name}");
    }
    let (_, rep) = decompose_scene(
        &world_meshes(&fixture("pen_mug")).iter().collect::<Vec<_>>(),
        &o,
    );
    assert!(!rep.objects[0].top_down, "plane cuts next to a neighbour");
}

/// The polishing (objects alone) lowers the 95th percentile of the distance from the union's
/// boundary to the surface, at the same hull budget and limits, with the cavity open: measured
/// on 20,000 samples, independently of the 8,000 the polishing chose its moves on. Never worse
/// (1 % slack for the sampling), and on the YCB cup (p95 2.04 → 1.66 % of the diagonal) by
/// 15 % at least. The mug fixture is already within the tolerance: nothing to polish.
#[test]
fn polishing_lowers_the_95th_percentile_alone() {
    let o = opts();
    let mut cases: Vec<(&str, Mesh, f64)> = vec![
        (
            "bowl fixture",
            world_meshes(&fixture("ball_bowl")).remove(0),
            1.01,
        ),
        (
            "mug fixture",
            world_meshes(&fixture("pen_mug")).remove(0),
            1.0,
        ),
    ];
    if let Some(sh) = shared() {
        let p = sh.join("datasets/objects/ycb/065-j_cups/textured.obj");
        if let Ok(v) = crate::io::load_visual(&p, &crate::io::Limits::default()) {
            cases.push(("YCB cup", v.geometry(), 0.85));
        }
    }
    let b = o.max_hulls;
    for (name, mesh, ratio) in &cases {
        let rebalanced = Effort {
            rebalance: b,
            polish: 0,
        };
        let off = decompose_alone(mesh, &o, b, rebalanced, &Strategy::ALL);
        let on = decompose_alone(mesh, &o, b, Effort::full(b), &Strategy::ALL);
        let hulls = |x: &Obj| x.parts.iter().map(|p| p.hull.clone()).collect::<Vec<_>>();
        let (h_off, h_on) = (hulls(&off), hulls(&on));
        assert_limits(&h_on, &o);
        assert_eq!(h_on.len(), h_off.len(), "{name}: same budget");
        let (q_off, q_on) = (
            metrics::measure(mesh, &h_off),
            metrics::measure(mesh, &h_on),
        );
        eprintln!(
            "{name}: p95 {:.3} % -> {:.3} % ({} moves)",
            q_off.dist_p95 * 100.0,
            q_on.dist_p95 * 100.0,
            on.report.polish_rounds
        );
        assert!(
            q_on.dist_p95 <= ratio * q_off.dist_p95,
            "{name}: {} -> {}",
            q_off.dist_p95,
            q_on.dist_p95
        );
        assert_eq!(q_on.cavity_kept, Some(true), "{name}");
        if *ratio == 1.0 {
            assert_eq!(
                h_on, h_off,
                "{name}: within the tolerance, nothing to polish"
            );
        } else {
            assert!(on.report.polish_rounds > 0, "{name}");
        }
    }
}

/// Next to a neighbour the polishing works on the patches out of its reach:
/// the cup with a die lying at its bottom (shared scene 00010), decomposed at the scene's
/// budget with its pins, comes out closer at the 95th percentile than rebalanced only
/// (measured 3.07 → 2.90 % of the diagonal in the whole scene), on 20,000 independent
/// samples, and keeps every pinned patch as the quality loop made it.
#[test]
fn polishing_next_to_a_neighbour_lowers_the_95th_percentile() {
    let Some(sh) = shared() else {
        eprintln!("shared datasets not present: skipped");
        return;
    };
    let o = opts();
    let meshes = world_meshes(&sh.join("datasets/scenes/toys/00010_dice_cup"));
    let (cup, die) = (&meshes[0], &meshes[1]);
    let s = Surface::new(cup).unwrap();
    let nb = Surface::new(die).unwrap();
    let (near, _) = contact_distances(&s, &[&nb], &o);
    let b = o.max_hulls - o.max_hulls / 8;
    let rebalanced = Effort {
        rebalance: b,
        polish: 0,
    };
    let st = &[Strategy::Patches];
    let off = decompose_object(Surface::new(cup), &o, b, rebalanced, &near, &near, st);
    let on = decompose_object(Surface::new(cup), &o, b, Effort::full(b), &near, &near, st);
    let hulls = |x: &Obj| x.parts.iter().map(|p| p.hull.clone()).collect::<Vec<_>>();
    let (h_off, h_on) = (hulls(&off), hulls(&on));
    assert_limits(&h_on, &o);
    assert_eq!(h_on.len(), h_off.len(), "same budget");
    let (q_off, q_on) = (metrics::measure(cup, &h_off), metrics::measure(cup, &h_on));
    eprintln!(
        "cup: p95 {:.3} % -> {:.3} % ({} moves)",
        q_off.dist_p95 * 100.0,
        q_on.dist_p95 * 100.0,
        on.report.polish_rounds
    );
    assert!(on.report.polish_rounds > 0);
    assert!(
        q_on.dist_p95 <= 0.97 * q_off.dist_p95,
        "{} -> {}",
        q_off.dist_p95,
        q_on.dist_p95
    );
    let p = on.params.unwrap();
    let pinned: Vec<&Part> = on
        .parts
        .iter()
        .filter(|q| rebalance::pinned(&near, &q.tris, q.dev, &p, &o))
        .collect();
    assert!(!pinned.is_empty(), "the floor under the die at least");
    for q in pinned {
        assert!(
            off.parts
                .iter()
                .any(|f| f.tris == q.tris && f.hull == q.hull),
            "a pinned patch changed"
        );
    }
}

/// Decompose a solid alone and check it is filled by star pieces: within the limits, the
/// union of the hulls has the solid's `volume` (grid-sampled, 3 % slack) and lies within the
/// tolerance of its surface at the 95th percentile. Returns the hulls.
fn assert_star_filled(mesh: &Mesh, volume: f64, o: &DecomposeOptions) -> Vec<Hull> {
    let (mut hulls, rep) = decompose_scene(&[mesh], o);
    assert!(rep.objects[0].star_pieces, "{:?}", rep.objects[0]);
    let hulls = hulls.remove(0);
    assert_limits(&hulls, o);
    let q = metrics::measure(mesh, &hulls);
    let filled = metrics::union_volume(&hulls, 96) / volume;
    eprintln!(
        "{} pieces, p95 {:.3} %, union / solid volume {filled:.4}, uncovered {:.2} %",
        hulls.len(),
        q.dist_p95 * 100.0,
        q.uncovered * 100.0
    );
    assert!((0.97..=1.03).contains(&filled), "{filled}");
    assert!(q.dist_p95 <= o.tolerance, "{q:?}");
    hulls
}

/// A solid that is not convex but is star-shaped about its centre, like an apple: a body of
/// revolution with a stem dimple 30 % of its radius deep. Surface patches made a shell of it
/// (their chords inside); star pieces fill it: the union of the hulls has the solid's analytic
/// volume (grid-sampled, 3 % slack), lies within the tolerance of its surface at the 95th
/// percentile, and the dimple stays open (a point in it, 10 % of the radius above its floor, is
/// in no hull, where the convex hull would hold it).
#[test]
fn star_pieces_fill_a_dimpled_solid_and_keep_the_dimple_open() {
    let o = opts();
    let r = 0.04;
    let n = 48;
    let dimple = |phi: f64| 1.0 - 0.3 * (-(phi / 0.35).powi(2)).exp();
    let mut profile: Vec<[f64; 2]> = vec![[0.0, -r * dimple(PI)]];
    profile.extend((1..n).map(|i| {
        let phi = PI * (1.0 - i as f64 / n as f64);
        [r * dimple(phi) * phi.sin(), r * dimple(phi) * phi.cos()]
    }));
    profile.push([0.0, r * dimple(0.0)]);
    let slices = 64;
    let mesh = shapes::revolve(&profile, slices);
    let volume = shapes::revolved_volume(&profile, slices);
    let probe = P3::new(0.0, 0.0, r * (dimple(0.0) + 0.1));
    let full = Hull::from_points(&mesh.vertices).unwrap();
    assert!(full.contains(&probe), "the probe is in the dimple");
    let hulls = assert_star_filled(&mesh, volume, &o);
    assert!(!hulls.iter().any(|h| h.contains(&probe)), "dimple filled");
}

/// A solid with an open cap poking out of it, as a generated avocado half carries its pit: an
/// oblate body (semi-axes 25, 25, 12.5 mm) and the upper half of a 10 mm sphere whose open
/// rim is sunk 2 mm under the body's top. Rays from the centre meet the body first and never
/// see the cap (10 % of the surface), so the star pieces are taken where the rays leave the
/// mesh for good: the union of the hulls holds the body and the cap (volume within 3 % of the
/// shapes' own, grid-sampled from their equations; the cap is about 6 % of it), the cap's
/// apex, and lies within the tolerance of the surface at the 95th percentile. With the first
/// hits only, the mesh took V-HACD's hulls instead.
#[test]
fn star_pieces_reach_a_cap_poking_out_of_a_solid() {
    let o = opts();
    let (a, c, r) = (0.025, 0.0125, 0.01);
    let base_z = c - 0.002;
    let body = shapes::uv_sphere(1.0, 32, 64);
    let mut mesh = Mesh::new(
        body.vertices
            .iter()
            .map(|v| P3::new(v.x * a, v.y * a, v.z * c))
            .collect(),
        body.triangles,
    );
    let cap = shapes::uv_sphere(r, 24, 48);
    let first = mesh.vertices.len() as u32;
    let lift = V3::new(0.0, 0.0, base_z);
    mesh.vertices.extend(cap.vertices.iter().map(|v| v + lift));
    mesh.triangles.extend(
        cap.triangles
            .iter()
            .filter(|t| t.iter().all(|&i| cap.vertices[i as usize].z >= -1e-12))
            .map(|t| t.map(|i| i + first)),
    );
    assert!(!mesh.is_closed());
    // The solid the mesh bounds, by its shapes' equations.
    let inside = |p: &P3| {
        (p.x / a).powi(2) + (p.y / a).powi(2) + (p.z / c).powi(2) <= 1.0
            || (p.z >= base_z && (p - P3::new(0.0, 0.0, base_z)).norm() <= r)
    };
    let k = 160;
    let (lo, hi) = (P3::new(-a, -a, -c), P3::new(a, a, base_z + r));
    let cell = (hi - lo) / k as f64;
    let count = (0..k * k * k)
        .filter(|i| {
            let (x, y, z) = (i % k, (i / k) % k, i / (k * k));
            inside(
                &(lo + cell.component_mul(&V3::new(
                    x as f64 + 0.5,
                    y as f64 + 0.5,
                    z as f64 + 0.5,
                ))),
            )
        })
        .count();
    let volume = count as f64 * cell.x * cell.y * cell.z;
    let apex = P3::new(0.0, 0.0, base_z + r);
    let hulls = assert_star_filled(&mesh, volume, &o);
    let diag = mesh.aabb().unwrap().diagonal();
    assert!(
        hulls.iter().any(|g| g.holds(&apex, o.tolerance * diag)),
        "the cap's apex is outside every hull"
    );
}

/// What a point sees of a cube: from its centre, all of it; from a point on the x axis outside
/// it, only the face towards the point, so 5/6 of the (area-sampled) surface lies behind the
/// near face, and the far face, a cube's width behind it, is 1/6 (sampling: 2,000 points,
/// standard error 0.008).
#[test]
fn hidden_is_the_share_of_the_surface_behind_the_surface() {
    let cube = shapes::cuboid(V3::new(1.0, 1.0, 1.0));
    let s = Surface::new(&cube).unwrap();
    let probes = s.samples(2000, 7);
    assert_eq!(hidden(&s, &P3::origin(), &probes, 1e-6), 0.0);
    let out = P3::new(3.0, 0.0, 0.0);
    let h = hidden(&s, &out, &probes, 1e-6);
    assert!((h - 5.0 / 6.0).abs() < 0.03, "{h}");
    let h = hidden(&s, &out, &probes, 0.999);
    assert!((h - 1.0 / 6.0).abs() < 0.03, "{h}");
}

/// A can, as the YCB soup can is built: a cylinder (radius 33 mm, 100 mm tall) whose lid is
/// recessed 6 mm inside a 2 mm rim. Rays from its centre meet the lid before the rim, which
/// stands in their shadow, so the star pieces fail their reach test, and surface patches
/// alone leave a shell with their chords inside it (the YCB can took V-HACD's hulls, p95 2.57 %
/// of its diagonal). Star pieces where the centre sees, patches over the rim: the union of the
/// hulls holds the can's analytic volume (grid-sampled, 3 % slack) and its surface within the
/// tolerance at the 95th percentile, the top of the rim all round, and the recess above the lid
/// stays open.
#[test]
fn star_pieces_with_patches_over_what_the_centre_does_not_see() {
    let o = opts();
    let (r, h, w, d): (f64, f64, f64, f64) = (0.033, 0.1, 0.002, 0.006);
    // The profile from the bottom centre to the lid's centre, points 2 mm apart or closer.
    let corners = [
        [0.0, 0.0],
        [r, 0.0],
        [r, h],
        [r - w, h],
        [r - w, h - d],
        [0.0, h - d],
    ];
    let mut profile = vec![corners[0]];
    for c in corners.windows(2) {
        let ([x0, y0], [x1, y1]) = (c[0], c[1]);
        let n = ((x1 - x0).hypot(y1 - y0) / 0.002).ceil().max(1.0) as usize;
        profile.extend((1..=n).map(|i| {
            let t = i as f64 / n as f64;
            [x0 + t * (x1 - x0), y0 + t * (y1 - y0)]
        }));
    }
    let slices = 96;
    let mesh = shapes::revolve(&profile, slices);
    let volume = shapes::revolved_volume(&profile, slices);
    let (mut hulls, rep) = decompose_scene(&[&mesh], &o);
    let r0 = &rep.objects[0];
    assert!(r0.star_pieces && r0.unseen_patches > 0, "{r0:?}");
    let hulls = hulls.remove(0);
    assert_limits(&hulls, &o);
    let q = metrics::measure(&mesh, &hulls);
    let filled = metrics::union_volume(&hulls, 96) / volume;
    eprintln!("can: {q:?}, union / solid volume {filled:.4}, {r0:?}");
    assert!((0.97..=1.03).contains(&filled), "{filled}");
    assert!(q.dist_p95 <= o.tolerance, "{q:?}");
    let diag = mesh.aabb().unwrap().diagonal();
    for k in 0..16 {
        let a = 2.0 * PI * k as f64 / 16.0;
        let top = P3::new((r - 0.5 * w) * a.cos(), (r - 0.5 * w) * a.sin(), h);
        assert!(
            hulls.iter().any(|g| g.holds(&top, o.tolerance * diag)),
            "the rim's top at {a:.2} rad is outside every hull"
        );
    }
    let recess = P3::new(0.0, 0.0, h - 0.5 * d);
    assert!(!hulls.iter().any(|g| g.contains(&recess)), "recess filled");
}

/// The avocado half of the shared scene `00006` (a closed flesh and an open pit cap, lying on
/// a 26 cm plate) is filled by star pieces within the tolerance (measured p95 0.36 % of its
/// diagonal, where its surface patches read 3.37 %): the plate lies under it, so nothing rests
/// on its cut face. Counting the plate there kept the star pieces out, the cut face's big
/// triangles (circumradius 12 mm) being within the loose bound plus the plate's 3.7 mm
/// tolerance of it.
#[test]
fn an_avocado_half_on_a_plate_is_filled_by_star_pieces() {
    let Some((meshes, hulls, rep)) = shared_scene("food/00006_avocado_plate") else {
        return;
    };
    let o = opts();
    let avocado = &rep.objects[1];
    eprintln!("avocado: {avocado:?}");
    assert!(avocado.star_pieces, "{avocado:?}");
    assert_limits(&hulls[1], &o);
    let q = metrics::measure(&meshes[1], &hulls[1]);
    assert!(q.dist_p95 <= o.tolerance, "{q:?}");
    assert_eq!((avocado.overlaps, rep.objects[0].overlaps), (0, 0));
}

/// The second bound of `contact_distances` counts only the neighbours that may rest on a
/// triangle, those whose box centre lies above it: a slab under the object leaves it at ∞, a
/// slab above gives the same bound as the first.
#[test]
fn only_neighbours_above_a_triangle_may_rest_on_it() {
    let o = opts();
    let lift = |m: Mesh, dz: f64| moved(&m, V3::new(0.0, 0.0, dz));
    let body = Surface::new(&lift(shapes::cuboid(V3::new(0.04, 0.04, 0.02)), 0.03)).unwrap();
    let slab = |dz: f64| Surface::new(&lift(shapes::cuboid(V3::new(0.1, 0.1, 0.01)), dz)).unwrap();
    let (below, above) = (slab(0.0149), slab(0.0451));
    let (near, under) = contact_distances(&body, &[&below], &o);
    assert!(near.iter().any(|d| d.is_finite()), "{near:?}");
    assert!(under.iter().all(|d| d.is_infinite()), "{under:?}");
    let (near, under) = contact_distances(&body, &[&above], &o);
    assert!(near.iter().any(|d| d.is_finite()), "{near:?}");
    assert_eq!(near, under);
}

/// What pins a patch (`pin_contacts`): a ball of 30 mm radius rests 0.05 mm above a wide
/// slab (1 m: its tolerance pad, 1 % of its diagonal, is 14 mm) and 0.05 mm from a wall beside
/// it. Its down-facing triangles are free; its steep ones within that pad of the slab but
/// farther than the clearance from its surface (the lowest 2.8 mm above it) are free; those
/// the wall touches stay pinned. A cylinder standing on the slab: its side triangles, which
/// reach down to the slab, touch it only from above (free); a wall against its side pins
/// those it touches.
#[test]
fn a_patch_is_pinned_by_touched_walls_and_floors_in_reach_only() {
    let o = opts();
    let (r, gap) = (0.03, 5e-5);
    let ball = Surface::new(&moved(
        &shapes::uv_sphere(r, 64, 128),
        V3::new(0.0, 0.0, r + gap),
    ))
    .unwrap();
    let slab = moved(
        &shapes::cuboid(V3::new(1.0, 1.0, 0.01)),
        V3::new(0.0, 0.0, -0.005),
    );
    let slab = Surface::new(&slab).unwrap();
    // A 10 mm wall whose face is at x.
    let wall_at = |x: f64| {
        let m = moved(
            &shapes::cuboid(V3::new(0.01, 0.2, 0.2)),
            V3::new(x + 0.005, 0.0, 0.1),
        );
        Surface::new(&m).unwrap()
    };
    // The padded bounds (`contact_distances`) and what pins after `pin_contacts`.
    let pins = |s: &Surface, nbs: &[&Surface]| {
        let (padded, _) = contact_distances(s, nbs, &o);
        let mut near = padded.clone();
        pin_contacts(s, nbs, &mut near, &o);
        (padded, near)
    };
    let wall = wall_at(r + gap);
    let (padded, near) = pins(&ball, &[&slab, &wall]);
    let n = |t: usize| ball.tri_normal[t];
    let steep = |t: usize| n(t).z.abs() < SUPPORT_NZ;
    // Down-facing triangles the slab was within reach of: all free.
    let under: Vec<usize> = (0..near.len())
        .filter(|&t| n(t).z <= -SUPPORT_NZ && padded[t].is_finite())
        .collect();
    assert!(!under.is_empty());
    assert!(under.iter().all(|&t| near[t].is_infinite()));
    // Steep triangles facing the slab, within its pad: free now.
    let low: Vec<usize> = (0..near.len())
        .filter(|&t| steep(t) && n(t).x < 0.5 && padded[t] <= o.clearance)
        .collect();
    assert!(low.len() >= 100, "{}", low.len());
    assert!(low.iter().all(|&t| near[t].is_infinite()));
    // The wall's contact: the steep triangles facing it at the equator stay pinned.
    let touched = (0..near.len())
        .filter(|&t| n(t).x > 0.99 && near[t] <= o.clearance)
        .count();
    assert!(touched >= 2, "{touched}");
    // No steep triangle is pinned farther than its circumradius and the clearance from both.
    for t in (0..near.len()).filter(|&t| steep(t) && near[t].is_finite()) {
        let c = ball.tri_centroid[t];
        let gap = slab.distance(&c).min(wall.distance(&c));
        assert!(gap <= circumradius(&ball, t) + o.clearance, "{t}: {gap}");
    }
    let (rc, h) = (0.02, 0.04);
    let cyl = moved(
        &shapes::cylinder(rc, h, 64),
        V3::new(0.0, 0.0, h / 2.0 + gap),
    );
    let cyl = Surface::new(&cyl).unwrap();
    let sides: Vec<usize> = (0..cyl.tri_normal.len())
        .filter(|&t| cyl.tri_normal[t].z.abs() < 0.1)
        .collect();
    // By distance alone every side triangle touches the slab.
    assert!(sides
        .iter()
        .all(|&t| slab.distance(&cyl.tri_centroid[t]) <= circumradius(&cyl, t) + o.clearance));
    let (_, near) = pins(&cyl, &[&slab]);
    assert!(sides.iter().all(|&t| near[t].is_infinite()));
    let (_, near) = pins(&cyl, &[&slab, &wall_at(rc + gap)]);
    let facing = |t: usize| cyl.tri_normal[t].x > 0.99;
    assert!(sides.iter().any(|&t| facing(t) && near[t].is_finite()));
    // Those facing away from it, farther from it than their circumradius (27 mm: they span the
    // cylinder's height), stay free.
    assert!(sides
        .iter()
        .all(|&t| cyl.tri_normal[t].x > -0.5 || near[t].is_infinite()));
}

/// A floor pins only under a neighbour (`pin_contacts`). A puck 200 mm wide, its top in
/// 5 mm rings: a tall wall touching its side comes within reach (`rebalance::reach`, the
/// puck's tolerance 2.8 mm) of the top triangles up to about 10 mm from it, but lies over none
/// of them; those farther from it than their circumradius are freed. A cube resting on the
/// top, 0.05 mm above it, pins every top triangle under it.
#[test]
fn a_floor_pins_under_a_neighbour_not_beside_one() {
    let o = opts();
    let (rp, top, gap) = (0.1, 0.02, 5e-5);
    let mut profile = vec![[rp, 0.0], [rp, top]];
    profile.extend((1..20).map(|k| [rp - 0.005 * k as f64, top]));
    let puck = Surface::new(&shapes::revolve(&profile, 128)).unwrap();
    let p = Params::new(&puck, &o, Strategy::Patches);
    let wall = moved(
        &shapes::cuboid(V3::new(0.01, 0.2, 0.2)),
        V3::new(rp + gap + 0.005, 0.0, 0.1),
    );
    let wall = Surface::new(&wall).unwrap();
    let cube = moved(
        &shapes::cuboid(V3::new(0.03, 0.03, 0.03)),
        V3::new(0.0, 0.0, top + gap + 0.015),
    );
    let cube = Surface::new(&cube).unwrap();
    let pins = |nbs: &[&Surface]| {
        let (padded, _) = contact_distances(&puck, nbs, &o);
        let mut near = padded.clone();
        pin_contacts(&puck, nbs, &mut near, &o);
        (padded, near)
    };
    let tops: Vec<usize> = (0..puck.tri_normal.len())
        .filter(|&t| puck.tri_normal[t].z > 0.99)
        .collect();
    let reach = rebalance::reach(p.tol, &p, &o);
    let (padded, near) = pins(&[&wall]);
    let in_reach: Vec<usize> = tops
        .iter()
        .copied()
        .filter(|&t| padded[t] <= reach)
        .collect();
    assert!(in_reach.len() >= 20, "{}", in_reach.len());
    let freed: Vec<usize> = in_reach
        .iter()
        .copied()
        .filter(|&t| near[t].is_infinite())
        .collect();
    assert!(
        freed.len() * 2 >= in_reach.len(),
        "{} of {}",
        freed.len(),
        in_reach.len()
    );
    // Pinned only within their circumradius of the wall, horizontally.
    for &t in &in_reach {
        let c = puck.tri_centroid[t];
        let beside = rp + gap - c.x <= circumradius(&puck, t);
        assert_eq!(near[t].is_finite(), beside, "{t}: {c:?}");
    }
    let (padded, near) = pins(&[&cube]);
    let under: Vec<usize> = tops
        .iter()
        .copied()
        .filter(|&t| {
            let c = puck.tri_centroid[t];
            c.x.abs() < 0.015 && c.y.abs() < 0.015
        })
        .collect();
    assert!(under.len() >= 4, "{}", under.len());
    assert!(under
        .iter()
        .all(|&t| near[t] == padded[t] && near[t] <= reach));
}

/// Real solids: the YCB apple, filled by star pieces, where its 32 surface patches kept 24 % of
/// its volume at p95 3.5 % of the diagonal (measured 0.46 %, volume 1.00); the pear, whose star
/// pieces are within the tolerance (0.49 %) and kept without V-HACD, although V-HACD's hulls
/// lie closer (0.28 %; CoACD 32×64: 1.80 %); the banana, which
/// its centre does not see whole, by V-HACD's hulls, where its patches kept 36 % of its
/// volume at p95 1.64 % (measured 0.19 %, volume 1.01, 2 % of its surface uncovered; 19 % when
/// the hulls were brought to 64 vertices by farthest-point sampling, see `voxel_parts`).
#[test]
fn real_solids_are_filled_star_pieces_for_an_apple_and_a_pear_voxels_for_a_banana() {
    let Some(sh) = shared() else {
        eprintln!("shared datasets not present: skipped");
        return;
    };
    let o = opts();
    let load = |rel: &str| shared_object(&sh, &format!("ycb/{rel}"));
    let apple = load("013_apple/textured.obj");
    let (hulls, rep) = decompose_scene(&[&apple], &o);
    assert!(rep.objects[0].star_pieces);
    assert_limits(&hulls[0], &o);
    let q = metrics::measure(&apple, &hulls[0]);
    eprintln!("apple: {q:?}");
    assert!(q.dist_p95 <= 0.006, "{q:?}");
    assert!(q.volume_ratio >= 0.95, "{q:?}");
    // The pieces grown towards the mesh vertices between the rays (measured 9.0 %; 14.1 %
    // ungrown).
    assert!(q.uncovered <= 0.11, "{q:?}");
    let pear = load("016_pear/textured.obj");
    let (hulls, rep) = decompose_scene(&[&pear], &o);
    assert!(rep.objects[0].star_pieces && !rep.objects[0].voxel_hulls);
    assert_limits(&hulls[0], &o);
    let q = metrics::measure(&pear, &hulls[0]);
    eprintln!("pear: {q:?}");
    assert!(q.dist_p95 <= o.tolerance, "{q:?}");
    assert!(q.volume_ratio >= 0.95, "{q:?}");
    // Measured 7.5 %; 14.3 % ungrown.
    assert!(q.uncovered <= 0.10, "{q:?}");
    let banana = load("011_banana/textured.obj");
    let (hulls, rep) = decompose_scene(&[&banana], &o);
    assert!(!rep.objects[0].star_pieces);
    assert!(rep.objects[0].voxel_hulls);
    assert_limits(&hulls[0], &o);
    let q = metrics::measure(&banana, &hulls[0]);
    eprintln!("banana: {q:?}");
    assert!(q.dist_p95 <= 0.005, "{q:?}");
    assert!(q.volume_ratio >= 0.9, "{q:?}");
    assert!(q.uncovered <= 0.05, "{q:?}");
}

/// Two real solids their centre does not see whole, the YCB pitcher (its handle) and the GSO
/// teapot (spout, handle, lid knob): star pieces where the centre sees, patches over the rest,
/// fill them (union over mesh volume ≥ 0.95) within the tolerance at the 95th percentile. They
/// took V-HACD's hulls before: p95 2.04 and 1.95 %, the teapot's farthest hull 7.1 % past its
/// surface.
#[test]
fn real_solids_the_centre_does_not_see_whole_get_star_pieces_with_patches() {
    let Some(sh) = shared() else {
        eprintln!("shared datasets not present: skipped");
        return;
    };
    let o = opts();
    for rel in [
        "ycb/019_pitcher_base/textured.obj",
        "gso/Threshold_Porcelain_Teapot_White/model.obj",
    ] {
        let mesh = shared_object(&sh, rel);
        let (hulls, rep) = decompose_scene(&[&mesh], &o);
        let r = &rep.objects[0];
        assert!(r.star_pieces && r.unseen_patches > 0, "{rel}: {r:?}");
        assert_limits(&hulls[0], &o);
        let q = metrics::measure(&mesh, &hulls[0]);
        eprintln!("{rel}: {q:?}");
        assert!(q.dist_p95 <= o.tolerance, "{rel}: {q:?}");
        assert!(q.volume_ratio >= 0.95, "{rel}: {q:?}");
        assert!(q.dist_max <= 3.0 * o.tolerance, "{rel}: {q:?}");
    }
}

#[test]
fn surface_distance_queries_agree_with_parry() {
    // The engine's own "any triangle within r" descent against parry's `project_point` (an
    // independent implementation), and the exact tests built on it: on the bowl, at points
    // from inside the wall to 10 % of the diagonal out.
    let s = geom::Surface::new(&bowl()).expect("surface");
    let mut rng = crate::rng::Rng::new(7);
    let (lo, hi) = (s.aabb.min, s.aabb.max);
    let pts: Vec<P3> = (0..2000)
        .map(|_| {
            let f = |a: f64, b: f64, u: f64| a + (b - a) * (1.2 * u - 0.1);
            P3::new(
                f(lo.x, hi.x, rng.next_f64()),
                f(lo.y, hi.y, rng.next_f64()),
                f(lo.z, hi.z, rng.next_f64()),
            )
        })
        .collect();
    let mut all = Vec::new();
    for p in &pts {
        let d = s.distance(p);
        assert!(s.within(p, d * (1.0 + 1e-12) + 1e-15));
        assert!(d == 0.0 || !s.within(p, d * (1.0 - 1e-12)));
        // `farther` is exactly `distance > r`, ties included.
        for r in [d, d * (1.0 - 1e-6), d * (1.0 + 1e-6), 0.01 * s.diag] {
            assert_eq!(s.farther(p, r), d > r, "r {r} d {d}");
        }
        all.push(d);
    }
    let max = all.iter().copied().fold(0.0, f64::max);
    assert!(max > 0.05 * s.diag, "points reach out: {max}");
    assert_eq!(s.max_distance(&pts), max);
    assert_eq!(s.max_distance(pts.iter().rev()), max);
    // Stopped early: exact when nothing reaches `stop`; else the first point at least that far.
    assert_eq!(s.max_distance_until(&pts, -1.0, max * (1.0 + 1e-9)), max);
    for stop in [0.5 * max, 0.9 * max, max] {
        let first = all
            .iter()
            .copied()
            .find(|&d| d >= stop)
            .expect("max reaches it");
        assert_eq!(s.max_distance_until(&pts, -1.0, stop), first, "stop {stop}");
    }
}

#[test]
fn point_triangle_distance_of_degenerate_triangles_is_that_of_their_edges() {
    // Two corners at one point: the triangle is the segment from (0,0,0) to (1,0,0).
    let (o, x) = (Vector::new(0.0, 0.0, 0.0), Vector::new(1.0, 0.0, 0.0));
    let p = Vector::new(0.5, 2.0, 0.0);
    assert_eq!(geom::point_triangle_dist2(p, o, o, x), 4.0);
    assert_eq!(geom::point_triangle_dist2(p, o, x, x), 4.0);
    // Three corners in a line, the middle one between: beyond the end, the distance to it.
    let m = Vector::new(0.25, 0.0, 0.0);
    let q = Vector::new(3.0, 0.0, 4.0);
    assert!((geom::point_triangle_dist2(q, o, m, x) - 20.0).abs() < 1e-12);
    // All three at one point.
    assert_eq!(geom::point_triangle_dist2(p, x, x, x), 0.25 + 4.0);
    // A proper triangle, against the analytic distance to its plane and its edges.
    let (a, b, c) = (o, Vector::new(2.0, 0.0, 0.0), Vector::new(0.0, 2.0, 0.0));
    assert_eq!(
        geom::point_triangle_dist2(Vector::new(0.5, 0.5, 3.0), a, b, c),
        9.0
    );
    assert_eq!(
        geom::point_triangle_dist2(Vector::new(1.0, -2.0, 0.0), a, b, c),
        4.0
    );
    assert_eq!(
        geom::point_triangle_dist2(Vector::new(2.0, 2.0, 0.0), a, b, c),
        2.0
    );
}

/// The refit (`refit.rs`) covers more of the surface: the bowl fixture's final wall segments,
/// each rebuilt the way the search builds them (farthest-point-sampled vertices per side), leave
/// more of the bowl's surface more than 0.1 % of the diagonal outside every hull than the grown
/// ones (measured 3.4 → 1.8 %, 21 of 32 grown; p95 1.308 → 1.312 %). A grown hull holds the
/// sampled one, its vertices are its patch's own mesh vertices, and the faces it gained lie
/// within the tolerance of the mesh (by 2,000 samples: 1.026 of it, 32 in `hugs`).
#[test]
fn refitting_wall_segments_covers_more_of_the_surface() {
    let o = opts();
    let mesh = world_meshes(&fixture("ball_bowl")).remove(0);
    let b = o.max_hulls;
    let obj = decompose_alone(&mesh, &o, b, Effort::full(b), &Strategy::ALL);
    let (s, p) = (obj.surf.as_ref().unwrap(), obj.params.as_ref().unwrap());
    assert!(obj.report.refitted > 0, "{:?}", obj.report);
    let mut rebuilt = 0;
    let mut gained_max: f64 = 0.0;
    let sampled: Vec<Hull> = obj
        .parts
        .iter()
        .map(|q| {
            let old = build_part(s, p, &o, q.tris.clone(), q.cuts.clone()).unwrap();
            if old.hull != q.hull {
                rebuilt += 1;
                assert!(q.hull.vertices.len() <= o.max_vertices);
                for v in &old.hull.vertices {
                    assert!(q.hull.holds(v, 1e-9 * s.diag), "{v:?} left the grown hull");
                }
                for v in &q.hull.vertices {
                    assert!(
                        q.tris.iter().any(|&t| s.mesh.triangles[t as usize]
                            .iter()
                            .any(|&i| s.mesh.vertices[i as usize] == *v)),
                        "{v:?} is not a vertex of the patch"
                    );
                }
                // The faces gained: those not on a face plane of the sampled hull.
                let gained: Vec<[P3; 3]> = q
                    .hull
                    .triangles
                    .iter()
                    .map(|t| t.map(|i| q.hull.vertices[i as usize]))
                    .filter(|f| {
                        !old.hull.planes.iter().any(|(n, d)| {
                            f.iter()
                                .all(|x| (n.dot(&x.coords) - d).abs() <= 1e-9 * s.diag)
                        })
                    })
                    .collect();
                let pts = geom::sample_triangles(&gained, 2_000, 5);
                gained_max =
                    gained_max.max(s.max_distance_until(&pts, p.seam_depth(), f64::INFINITY));
            }
            old.hull
        })
        .collect();
    assert_eq!(rebuilt, obj.report.refitted);
    let refitted: Vec<Hull> = obj.parts.iter().map(|q| q.hull.clone()).collect();
    let (before, after) = (
        metrics::uncovered(s, &sampled, 8_000),
        metrics::uncovered(s, &refitted, 8_000),
    );
    let p95 = |h: &[Hull]| metrics::stats(&metrics::surface_distances(s, h, 20_000)).1;
    let (p_before, p_after) = (p95(&sampled), p95(&refitted));
    eprintln!(
        "bowl: uncovered {before:.4} -> {after:.4}, p95 {p_before:.5} -> {p_after:.5}, \
         {rebuilt} grown, gained faces within {:.3} of the tolerance",
        gained_max / p.tol
    );
    assert!(after <= 0.8 * before, "{before} -> {after}");
    assert!(p_after <= p_before * 1.01, "{p_before} -> {p_after}");
    assert!(gained_max <= 1.1 * p.tol, "{gained_max} > {}", p.tol);
}

#[test]
fn a_wall_segments_end_faces_are_seams_and_only_its_chord_deviates() {
    // The mug fixture's cup: 4 mm wall, inner radius 36 mm, 64 slices. A segment of 4 slices
    // (22.5°) of both sides of the wall: its inner face is the chord across the 4 inner facets,
    // r·(1 − cos 11.25°) = 0.69 mm from the inner wall at most. Its end faces cross the wall,
    // 2 mm from the surface at their middle, and its foot crosses the 6 mm floor slab, up to
    // 3 mm from it: more than the 1.48 mm tolerance, and all inside the material.
    let (r, wall, floor) = (0.04, 0.004, 0.006);
    let mesh = shapes::mug(r, 0.095, wall, floor, 64);
    let s = Surface::new(&mesh).unwrap();
    assert!(s.closed && s.sided);
    let o = opts();
    let p = Params::new(&s, &o, Strategy::Patches);
    let angle = |q: &P3| q.y.atan2(q.x);
    let tris: Vec<u32> = (0..mesh.triangles.len() as u32)
        .filter(|&t| {
            s.tri_normal[t as usize].z.abs() < 0.1
                && mesh.triangle(t as usize).iter().all(|q| {
                    let a = angle(q);
                    (-1e-9..=PI / 8.0 + 1e-9).contains(&a)
                })
        })
        .collect();
    assert_eq!(tris.len(), 16, "4 slices, 2 triangles each, both sides");
    let part = build_part(&s, &p, &o, tris.clone(), Vec::new()).unwrap();
    assert_eq!(part.normal, V3::zeros(), "a two-sided wall segment");
    let chord = (r - wall) * (1.0 - (PI / 16.0).cos());
    let all = deviation(&s, &part.hull, tris[0] as u64, &part.outer, None);
    eprintln!(
        "segment: {:.3} mm with seams, {:.3} mm counting every face; chord {:.3} mm, tolerance {:.3} mm",
        part.dev * 1e3,
        all * 1e3,
        chord * 1e3,
        p.tol * 1e3
    );
    assert!(part.dev <= chord * (1.0 + 1e-9), "{} > {chord}", part.dev);
    assert!(part.dev >= 0.8 * chord, "{} < 0.8 × {chord}", part.dev);
    assert!(all >= wall / 2.0 && all <= floor / 2.0 + 1e-9, "{all}");
    assert!(part.dev < p.tol && all > p.tol);
}

/// The lane-wise farthest-point sampling picks what the textbook greedy picks: each next
/// point the one farthest from those kept, the lower index among equals. On a random cloud
/// whose size is not a whole number of lanes, and on a lattice, where ties are everywhere.
#[test]
fn farthest_points_is_the_greedy_farthest_first_order() {
    fn greedy(pts: &[P3], k: usize) -> Vec<usize> {
        let c = pts.iter().fold(V3::zeros(), |a, p| a + p.coords) / pts.len() as f64;
        let mut best = 0;
        for i in 1..pts.len() {
            if (pts[i].coords - c).norm_squared() > (pts[best].coords - c).norm_squared() {
                best = i;
            }
        }
        let mut kept = vec![best];
        while kept.len() < k.min(pts.len()) {
            let gap = |i: usize| {
                kept.iter()
                    .map(|&j| (pts[i] - pts[j]).norm_squared())
                    .fold(f64::INFINITY, f64::min)
            };
            let mut far = 0;
            for i in 1..pts.len() {
                if gap(i) > gap(far) {
                    far = i;
                }
            }
            if gap(far) <= 0.0 {
                break;
            }
            kept.push(far);
        }
        kept
    }
    let mut rng = crate::rng::Rng::new(11);
    let cloud: Vec<P3> = (0..203)
        .map(|_| P3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()))
        .collect();
    let lattice: Vec<P3> = (0..5 * 5 * 3)
        .map(|i| P3::new((i % 5) as f64, (i / 5 % 5) as f64, (i / 25) as f64))
        .collect();
    for pts in [&cloud, &lattice] {
        for k in [1, 8, 32, 74] {
            assert_eq!(geom::farthest_points(pts, k), greedy(pts, k), "k = {k}");
        }
    }
    // Duplicates only: one point, then nothing is farther.
    assert_eq!(geom::farthest_points(&[P3::origin(); 20], 5), vec![0]);
}

#[test]
fn distinct_sorted_is_sort_and_dedup() {
    let mut rng = crate::rng::Rng::new(3);
    for (n, range) in [
        (0, 1),
        (1, 1),
        (50, 10),
        (1000, 100_000),
        (300, 64),
        (70, 65),
    ] {
        let v: Vec<u32> = (0..n).map(|_| 5 + rng.below(range) as u32).collect();
        let mut want = v.clone();
        want.sort_unstable();
        want.dedup();
        assert_eq!(geom::distinct_sorted(&v), want, "{n} values below {range}");
    }
}

/// Star pieces grown in batches of faces (`geom::star_pieces`) are the pieces grown one face at
/// a time, one cone check per face (the region growing as first written, below, with the
/// engine's own depth test), on a bumpy
/// solid star-shaped about its centre, at bulge limits that reject few to many faces.
#[test]
fn star_pieces_in_batches_are_the_face_by_face_growth() {
    fn face_by_face(v: &[P3], t: &[[u32; 3]], c: &P3, cap: usize, bulge: f64) -> Vec<Vec<u32>> {
        // Neighbours in the order of the edge they share, as the engine orders them.
        let mut adj: Vec<Vec<([u32; 2], usize)>> = vec![Vec::new(); t.len()];
        for (f, a) in t.iter().enumerate() {
            for (g, b) in t.iter().enumerate() {
                let shared: Vec<u32> = a.iter().copied().filter(|x| b.contains(x)).collect();
                if f != g && shared.len() == 2 {
                    adj[f].push(([shared[0].min(shared[1]), shared[0].max(shared[1])], g));
                }
            }
            adj[f].sort();
        }
        let mut assigned = vec![false; t.len()];
        let mut pieces = Vec::new();
        for seed in 0..t.len() {
            if assigned[seed] {
                continue;
            }
            let mut verts: Vec<u32> = Vec::new();
            let mut queued = vec![false; t.len()];
            let mut queue = std::collections::VecDeque::from([seed]);
            queued[seed] = true;
            while let Some(f) = queue.pop_front() {
                let new: Vec<u32> = t[f]
                    .iter()
                    .copied()
                    .filter(|x| !verts.contains(x))
                    .collect();
                if verts.len() + new.len() > cap {
                    continue;
                }
                if !new.is_empty() && !verts.is_empty() {
                    let mut pts: Vec<P3> =
                        verts.iter().chain(&new).map(|&i| v[i as usize]).collect();
                    pts.push(*c);
                    let fits = Hull::from_points(&pts).is_some_and(|h| {
                        pts[..pts.len() - 1]
                            .iter()
                            .all(|p| geom::depth_under(&h, c, p) <= bulge)
                    });
                    if !fits {
                        continue;
                    }
                }
                verts.extend(new);
                assigned[f] = true;
                for &(_, g) in &adj[f] {
                    if !assigned[g] && !queued[g] {
                        queued[g] = true;
                        queue.push_back(g);
                    }
                }
            }
            pieces.push(verts);
        }
        pieces
    }
    let (dirs, tris) = geom::sphere_directions(600, &[V3::x(), V3::y(), V3::z()]).unwrap();
    let c = P3::new(0.1, -0.2, 0.3);
    let verts: Vec<P3> = dirs
        .iter()
        .map(|u| c + u * (1.0 + 0.25 * (3.0 * u.x).sin() * (2.0 * u.y).cos() + 0.15 * u.z * u.z))
        .collect();
    let mut rejected = 0;
    for max_vertices in [16, 64] {
        for bulge in [0.002, 0.01, 0.05, f64::INFINITY] {
            let want = face_by_face(&verts, &tris, &c, max_vertices - 1, bulge);
            let got =
                geom::star_pieces(&verts, &tris, &c, max_vertices, 10_000, bulge, None).unwrap();
            let got: Vec<Vec<P3>> = got.into_iter().map(|(_, outer, _)| outer).collect();
            let want: Vec<Vec<P3>> = want
                .iter()
                .map(|p| p.iter().map(|&i| verts[i as usize]).collect())
                .collect();
            assert_eq!(got, want, "{max_vertices} vertices, bulge {bulge}");
            // Tighter bulges take more pieces: faces were rejected.
            let loose = face_by_face(&verts, &tris, &c, max_vertices - 1, f64::INFINITY).len();
            rejected += want.len().saturating_sub(loose);
        }
    }
    assert!(rejected > 0, "no bulge limit rejected a face");
}

/// The bowl as a surface, with the parameters and features of `strategy` and all its
/// triangles, to make patches of.
fn bowl_for_patches(
    strategy: Strategy,
) -> (
    DecomposeOptions,
    Surface,
    Params,
    patches::Features,
    Vec<u32>,
) {
    let o = opts();
    let s = Surface::new(&bowl()).unwrap();
    let p = Params::new(&s, &o, strategy);
    let f = patches::Features::new(&s, p.merge_depth, p.d_max);
    let all: Vec<u32> = (0..s.mesh.triangles.len() as u32).collect();
    (o, s, p, f, all)
}

/// The closest ways to split, built below the bound and the `keep`-th least deviation found
/// so far, are those of building every way in full, admitting and sorting: on the bowl's
/// patches, for both sets of ways, several shortlist lengths and bounds.
#[test]
fn closest_splits_are_those_of_building_every_way() {
    let (o, s, p, f, all) = bowl_for_patches(Strategy::Planes);
    let admit = |a: &Part, b: &Part| a.tris.len() + 8 >= b.tris.len();
    let mut compared = 0;
    for tris in patches::kmeans(&s, &f, &all, 6, p.lambda, 12) {
        let part = build_part(&s, &p, &o, tris, Vec::new()).unwrap();
        for fine in [false, true] {
            // Every way built in full, with a memo of its own.
            let fresh = Params::new(&s, &o, Strategy::Planes);
            let full: Vec<(usize, (Part, Part))> = split_ways(&s, &f, &p, &part, fine)
                .into_iter()
                .enumerate()
                .filter_map(|(k, (a, b))| {
                    let a = build_part(&s, &fresh, &o, a, Vec::new())?;
                    let b = build_part(&s, &fresh, &o, b, Vec::new())?;
                    Some((k, (a, b)))
                })
                .collect();
            let mut worse: Vec<f64> = full.iter().map(|(_, (a, b))| a.dev.max(b.dev)).collect();
            worse.sort_by(f64::total_cmp);
            let median = worse[worse.len() / 2];
            for bound in [f64::INFINITY, median] {
                for keep in [1, 3, 6] {
                    let mut want: Vec<&(usize, (Part, Part))> = full
                        .iter()
                        .filter(|(_, (a, b))| a.dev < bound && b.dev < bound && admit(a, b))
                        .collect();
                    want.sort_by(|x, y| closer_split(x, y));
                    want.truncate(keep);
                    let ways = split_ways(&s, &f, &p, &part, fine);
                    let got = closest_splits(&s, &p, &o, &part, ways, bound, keep, &admit);
                    assert_eq!(
                        got.len(),
                        want.len(),
                        "fine {fine} bound {bound} keep {keep}"
                    );
                    for ((k, (a, b)), (l, (c, d))) in got.iter().zip(want) {
                        assert_eq!(k, l);
                        assert_eq!((a.dev, b.dev), (c.dev, d.dev));
                        assert_eq!((&a.hull, &b.hull), (&c.hull, &d.hull));
                    }
                    compared += got.len();
                }
            }
        }
    }
    assert!(compared >= 60, "{compared} splits compared");
}

/// Two patches are adjacent when they share a mesh vertex: `rebalance::adjacency` against
/// that definition, pair by pair, on the bowl's k-means patches.
#[test]
fn patches_sharing_a_vertex_are_adjacent() {
    let (o, s, p, f, all) = bowl_for_patches(Strategy::Patches);
    let parts: Vec<Part> = patches::kmeans(&s, &f, &all, 12, p.lambda, 12)
        .into_iter()
        .map(|tris| build_part(&s, &p, &o, tris, Vec::new()).unwrap())
        .collect();
    let verts: Vec<Vec<u32>> = parts.iter().map(|q| s.vertices_of(&q.tris)).collect();
    let adj = rebalance::adjacency(&s, &parts);
    let mut pairs = 0;
    for i in 0..parts.len() {
        let want: Vec<usize> = (0..parts.len())
            .filter(|&j| j != i && verts[i].iter().any(|v| verts[j].binary_search(v).is_ok()))
            .collect();
        assert_eq!(adj[i], want, "patch {i}");
        pairs += want.len();
    }
    // Every patch of a connected bowl touches another; some vertices are shared by three.
    assert!(pairs >= 2 * parts.len(), "{pairs}");
}
