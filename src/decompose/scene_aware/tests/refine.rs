//! After the quality loop: exact pieces (cones, convex parts), the rebalancing, the top-down
//! plane cuts and the polishing, each measured on the union boundary independently.

use super::*;

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
