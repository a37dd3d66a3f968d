//! Metrics against independent expectations: analytic volumes, areas and distances, parry's own
//! cuboid–cuboid contact, and invariants (symmetry, determinism, thread count).

use super::*;
use crate::mesh::V3;
use crate::shapes::{cuboid, uv_sphere};
use nalgebra::Matrix4;
use std::f64::consts::PI;

fn moved(m: &Mesh, x: f64, y: f64, z: f64) -> Mesh {
    m.transformed(&Matrix4::new_translation(&V3::new(x, y, z)))
}

fn boxm(x: f64, y: f64, z: f64) -> Mesh {
    cuboid(V3::new(x, y, z))
}

fn prep(m: &Mesh) -> Prepared {
    Prepared::new(Solid::Mesh(m))
}

fn opts(points: usize) -> MetricsOptions {
    MetricsOptions {
        points,
        ..Default::default()
    }
}

/// Volume of the lens of two balls of radius r whose centres are d apart.
fn lens_volume(r: f64, d: f64) -> f64 {
    PI * (4.0 * r + d) * (2.0 * r - d).powi(2) / 12.0
}

#[test]
fn spheres_lens_within_one_percent_at_a_million_points() {
    // 5 cm balls, centres 4 cm apart: R = lens / (2 V - lens).
    let (r, d) = (0.05, 0.04);
    let s = uv_sphere(r, 64, 128);
    let a = prep(&s);
    let b = prep(&moved(&s, d * 0.6, d * 0.8, 0.0));
    let est = r_volume(&a, &b, &opts(1_000_000));
    let lens = lens_volume(r, d);
    let expect = lens / (2.0 * 4.0 / 3.0 * PI * r.powi(3) - lens);
    assert_eq!(est.points, 1_000_000);
    let rel = (est.r_volume - expect).abs() / expect;
    assert!(rel < 0.01, "R = {} expected {expect} ({rel})", est.r_volume);
    // The counts also give the sphere volume: the box is [-r, d·0.6 + r] x [-r, d·0.8 + r] x
    // [-r, r].
    let bx = (2.0 * r + d * 0.6) * (2.0 * r + d * 0.8) * 2.0 * r;
    let va = est.inside_a as f64 / est.points as f64 * bx;
    let poly = s.signed_volume();
    assert!((va - poly).abs() / poly < 0.005, "{va} vs {poly}");
}

#[test]
fn boxes_overlap_matches_analytic_ratio() {
    let a = prep(&boxm(1.0, 1.0, 1.0));
    let b = prep(&moved(&boxm(1.0, 1.0, 1.0), 0.5, 0.3, 0.2));
    let overlap = 0.5 * 0.7 * 0.8;
    let expect = overlap / (2.0 - overlap);
    let est = r_volume(&a, &b, &opts(300_000));
    let rel = (est.r_volume - expect).abs() / expect;
    assert!(rel < 0.01, "R = {} expected {expect}", est.r_volume);
    // Same estimate with the roles swapped (the sampling box is symmetric; the counts swap).
    let swapped = r_volume(&b, &a, &opts(300_000));
    assert_eq!(swapped.inside_both, est.inside_both);
    assert_eq!(swapped.inside_a, est.inside_b);
}

#[test]
fn disjoint_boxes_zero_ratios_and_exact_gap() {
    // 5 cm cubes 3 mm apart along x, offset sideways so the boxes of the sampling overlap in y, z.
    let a = prep(&boxm(0.05, 0.05, 0.05));
    let b = prep(&moved(&boxm(0.05, 0.05, 0.05), 0.053, 0.01, -0.02));
    let m = pair_metrics(&a, &b, &opts(100_000));
    assert_eq!(m.r_volume, 0.0);
    assert_eq!(m.r_surface, 0.0);
    assert_eq!(m.max_penetration_depth, 0.0);
    assert!(
        (m.min_clearance - 0.003).abs() < 1e-9,
        "{}",
        m.min_clearance
    );
    // Diagonal gap: corner to corner along (1, 1, 1) · 2 mm each.
    let c = prep(&moved(&boxm(0.05, 0.05, 0.05), 0.052, 0.052, 0.052));
    let g = min_clearance(&a, &c);
    assert!((g - 0.002 * 3f64.sqrt()).abs() < 1e-12, "{g}");
}

#[test]
fn disjoint_spheres_with_overlapping_boxes_sample_and_get_zero() {
    let s = uv_sphere(0.05, 32, 64);
    let a = prep(&s);
    let b = prep(&moved(&s, 0.08, 0.08, 0.0));
    let m = pair_metrics(&a, &b, &opts(200_000));
    assert!(m.points == 200_000 && m.inside_either > 0);
    assert_eq!(m.r_volume, 0.0);
    assert_eq!(m.r_surface, 0.0);
    assert_eq!(m.max_penetration_depth, 0.0);
    // The polyhedra are inside the balls, so the gap is at least the balls' gap; the
    // equatorial vertices at 45° lie on the balls, so it is exactly that gap.
    let gap = 0.08 * 2f64.sqrt() - 0.1;
    assert!(
        (m.min_clearance - gap).abs() < 1e-12,
        "{} vs {gap}",
        m.min_clearance
    );
}

#[test]
fn mesh_against_itself_is_one() {
    let s = uv_sphere(0.03, 16, 32);
    let a = prep(&s);
    let b = prep(&s);
    let m = pair_metrics(&a, &b, &opts(50_000));
    assert_eq!(m.r_volume, 1.0);
    assert_eq!(m.r_surface, 1.0);
    assert_eq!(m.min_clearance, 0.0);
}

#[test]
fn r_surface_plate_through_cube_counts_exact_triangles() {
    // A 2 x 2 x 0.1 plate through the middle of a unit cube: all 8 side triangles of the cube
    // (area 4) and the 4 big triangles of the plate (area 8) cross; nothing else touches.
    let a = prep(&boxm(1.0, 1.0, 1.0));
    let b = prep(&boxm(2.0, 2.0, 0.1));
    let expect = (4.0 + 8.0) / (6.0 + 8.0 + 4.0 * 0.2);
    let r = r_surface(&a, &b);
    assert!((r - expect).abs() < 1e-12, "{r} vs {expect}");
    assert_eq!(r, r_surface(&b, &a));
    // Partial overlap of two cubes offset by (0.5, 0.3, 0.2): every face of each cube that
    // crosses the other cube's interior takes part with both its triangles (each face square is
    // cut by the other cube along a line that spans both halves); the three faces facing away do
    // not. Both cubes: 3 faces each of area 1 → R = 6 / 12.
    let c = prep(&moved(&boxm(1.0, 1.0, 1.0), 0.5, 0.3, 0.2));
    let r2 = r_surface(&a, &c);
    assert!((r2 - 0.5).abs() < 1e-12, "{r2}");
}

#[test]
fn penetration_of_a_box_pushed_two_millimetres() {
    // A 4 cm cube standing 2 mm deep in a 10 x 10 x 2 cm slab.
    let a = prep(&boxm(0.04, 0.04, 0.04));
    let b = prep(&moved(&boxm(0.1, 0.1, 0.02), 0.003, -0.002, -0.028));
    let m = pair_metrics(&a, &b, &opts(100_000));
    assert!(
        (m.max_penetration_depth - 0.002).abs() < 1e-9,
        "{}",
        m.max_penetration_depth
    );
    assert_eq!(m.min_clearance, 0.0);
    assert!(m.r_surface > 0.0 && m.r_volume > 0.0);
    // R_volume: overlap 4 x 4 x 0.2 cm over the union.
    let ov = 0.04 * 0.04 * 0.002;
    let expect = ov / (0.04f64.powi(3) + 0.1 * 0.1 * 0.02 - ov);
    assert!(
        (m.r_volume - expect).abs() / expect < 0.05,
        "{} vs {expect}",
        m.r_volume
    );
}

#[test]
fn penetration_of_crossed_bars_needs_surface_samples() {
    // No vertex of either bar is inside the other; the deepest surface point is 0.1 deep.
    let a = prep(&boxm(1.0, 0.2, 0.2));
    let b = prep(&boxm(0.2, 1.0, 0.4));
    let d = max_penetration_depth(&a, &b, &MetricsOptions::default());
    assert!(d <= 0.1 + 1e-12 && d > 0.1 - 0.02, "{d}");
    // A finer spacing gets closer.
    let fine = MetricsOptions {
        depth_spacing: Some(0.002),
        ..Default::default()
    };
    let d2 = max_penetration_depth(&a, &b, &fine);
    assert!(d2 <= 0.1 + 1e-12 && d2 > 0.1 - 0.002 && d2 >= d, "{d2}");
    assert_eq!(min_clearance(&a, &b), 0.0);
}

#[test]
fn contained_object_overlaps_without_surface_contact() {
    let big = prep(&boxm(0.1, 0.1, 0.1));
    let small = prep(&moved(&boxm(0.02, 0.02, 0.02), 0.01, 0.0, 0.0));
    let m = pair_metrics(&big, &small, &opts(100_000));
    assert_eq!(m.r_surface, 0.0);
    assert_eq!(m.min_clearance, 0.0);
    // The deepest surface point is the centre of the small cube's -x face, at the big cube's
    // centre: 0.05 from every face (its vertices are only 0.04 deep). The lattice gets within
    // one spacing (1/64 of the small cube's diagonal) of it.
    let spacing = 0.02 * 3f64.sqrt() / 64.0;
    let d = m.max_penetration_depth;
    assert!(d <= 0.05 + 1e-12 && d > 0.05 - spacing, "{d}");
    let expect = 0.02f64.powi(3) / 0.1f64.powi(3);
    assert!(
        (m.r_volume - expect).abs() / expect < 0.05,
        "{}",
        m.r_volume
    );
}

/// A sphere with a few triangles removed: the first three of the top and of the bottom fan
/// (the same azimuths, so z lines pass through both holes), and a few elsewhere.
fn holey_sphere(r: f64) -> (Mesh, Mesh) {
    let slices = 96;
    let s = uv_sphere(r, 48, slices);
    let n = s.triangles.len();
    let bottom = n - slices;
    let drop = [
        0,
        1,
        2,
        bottom,
        bottom + 1,
        bottom + 2,
        500,
        501,
        2000,
        3333,
        4000,
        4001,
        4002,
    ];
    let mut open = s.clone();
    open.triangles = s
        .triangles
        .iter()
        .enumerate()
        .filter(|(i, _)| !drop.contains(i))
        .map(|(_, t)| *t)
        .collect();
    assert!(!open.is_closed());
    (s, open)
}

#[test]
fn open_sphere_volume_close_to_closed() {
    let (closed, open) = holey_sphere(0.05);
    let other = moved(&closed, 0.03, 0.02, 0.01);
    let pc = prep(&closed);
    let po = prep(&open);
    let pb = prep(&other);
    let o = opts(300_000);
    let rc = r_volume(&pc, &pb, &o);
    let ro = r_volume(&po, &pb, &o);
    // Same points: the only differences are points misclassified because of the holes (the
    // thin prism of z columns through both polar holes, whose lines are even and wrong).
    let diff = (rc.inside_a as f64 - ro.inside_a as f64).abs() / rc.inside_a as f64;
    assert!(diff < 1e-3, "inside count differs by {diff}");
    assert!((rc.r_volume - ro.r_volume).abs() / rc.r_volume < 2e-3);
    // Single-point queries vote over all three axes: the z axis passes through both polar holes
    // (the perturbed line goes through the removed fan triangles: 0 crossings), yet the centre
    // is inside; and near a hole, inside and outside are still told apart.
    let Shape::Mesh(rm) = &po.shape else {
        unreachable!()
    };
    assert!(
        !rm.parity_only([0.0, 0.0, 0.0], 2),
        "the z line should meet no triangle"
    );
    assert!(po.contains(&P3::new(0.0, 0.0, 0.0)));
    assert!(po.contains(&P3::new(0.0, 0.0, 0.049)));
    assert!(!po.contains(&P3::new(0.0, 0.0, 0.051)));
}

#[test]
fn sphere_with_missing_cap_still_has_its_volume() {
    // Remove the whole bottom cap (4 of 32 stacks, 22.5° around the pole), as in a scan of an
    // object standing on a table: every z line through the opening crosses the mesh once, so
    // z parity alone inverts those columns.
    let (r, stacks, slices) = (0.05, 32, 64);
    let s = uv_sphere(r, stacks, slices);
    let cap = slices + 3 * 2 * slices;
    let open = Mesh::new(
        s.vertices.clone(),
        s.triangles[..s.triangles.len() - cap].to_vec(),
    );
    let pc = prep(&s);
    let po = prep(&open);
    let pb = prep(&moved(&s, 0.04, 0.0, 0.0));
    let o = opts(200_000);
    let (rc, ro) = (r_volume(&pc, &pb, &o), r_volume(&po, &pb, &o));
    // What the open mesh loses is exactly the cap above the opening (outside by the vote: its
    // x and y lines meet nothing); a spherical cap of height r (1 - cos 22.5°).
    let h = r * (1.0 - (PI / 8.0).cos());
    let cap_fraction = PI * h * h * (3.0 * r - h) / 3.0 / (4.0 / 3.0 * PI * r.powi(3));
    let lost = (rc.inside_a as f64 - ro.inside_a as f64) / rc.inside_a as f64;
    assert!(
        lost >= 0.0 && lost < cap_fraction * 1.2,
        "lost {lost}, cap {cap_fraction}"
    );
    // Points well inside, above the opening: the vote classifies all of them right, while
    // z parity alone gets every one under the opening wrong.
    let Shape::Mesh(rm) = &po.shape else {
        unreachable!()
    };
    let (mut voted_wrong, mut parity_wrong, mut n) = (0, 0, 0);
    let mut rng = Rng(3);
    while n < 2000 {
        let p = [0.0, 1.0, 2.0].map(|_| (rng.next_f64() * 2.0 - 1.0) * 0.8 * r);
        if geom::norm2(p) > (0.8 * r).powi(2) {
            continue;
        }
        n += 1;
        voted_wrong += usize::from(!rm.contains(p));
        parity_wrong += usize::from(!rm.parity_only(p, 2));
    }
    assert_eq!(voted_wrong, 0);
    // The opening has radius r sin 22.5° = 0.38 r: about 0.38² / 0.8² of the inner ball's
    // z columns pass through it.
    assert!(parity_wrong > n / 10, "{parity_wrong}");
}

#[test]
fn hull_sets_overlap_depth_and_gap() {
    let unit = boxm(1.0, 1.0, 1.0);
    let ha = [unit.clone()];
    let hb = [moved(&unit, 0.8, 0.1, 0.05)];
    let a = Prepared::new(Solid::Hulls(&ha));
    let b = Prepared::new(Solid::Hulls(&hb));
    let m = pair_metrics(&a, &b, &opts(300_000));
    let ov = 0.2 * 0.9 * 0.95;
    let expect = ov / (2.0 - ov);
    assert!(
        (m.r_volume - expect).abs() / expect < 0.01,
        "{} vs {expect}",
        m.r_volume
    );
    assert!(
        (m.max_penetration_depth - 0.2).abs() < 1e-12,
        "{}",
        m.max_penetration_depth
    );
    assert_eq!(m.min_clearance, 0.0);
    // The same boxes as meshes classify every point identically.
    let (ma, mb) = (prep(&ha[0]), prep(&hb[0]));
    let vm = r_volume(&ma, &mb, &opts(300_000));
    assert_eq!(vm.inside_both, m.inside_both);
    assert_eq!(vm.inside_a + vm.inside_b - vm.inside_both, m.inside_either);
    // Mixed pair: mesh against hulls.
    let vx = r_volume(&ma, &b, &opts(300_000));
    assert_eq!(vx.inside_both, m.inside_both);
    // 3 mm gap between hull sets.
    let hc = [moved(&unit, 1.003, 0.2, 0.1)];
    let c = Prepared::new(Solid::Hulls(&hc));
    let g = pair_metrics(&a, &c, &opts(10_000));
    assert!(
        (g.min_clearance - 0.003).abs() < 1e-9,
        "{}",
        g.min_clearance
    );
    assert_eq!((g.r_volume, g.max_penetration_depth), (0.0, 0.0));
}

#[test]
fn hull_union_of_two_boxes_counts_overlap_once() {
    // An L of two overlapping hulls against a box: analytic volumes.
    let ha = [
        boxm(1.0, 0.2, 0.2),
        moved(&boxm(0.2, 1.0, 0.2), 0.4, 0.4, 0.0),
    ];
    let a = Prepared::new(Solid::Hulls(&ha));
    let hb = [moved(&boxm(0.5, 0.5, 0.5), 0.5, 0.0, 0.0)];
    let b = Prepared::new(Solid::Hulls(&hb));
    // A = bar [-0.5,0.5]x[-0.1,0.1]x[-0.1,0.1] ∪ bar [0.3,0.5]x[-0.1,0.9]x[-0.1,0.1]
    // (their overlap [0.3,0.5]x[-0.1,0.1] counted once): 0.04 + 0.04 - 0.008 = 0.072.
    // B = [0.25,0.75]x[-0.25,0.25]x[-0.25,0.25]; A ∩ B = [0.25,0.5]x[-0.1,0.1]x[-0.1,0.1]
    // ∪ [0.3,0.5]x[0.1,0.25]x[-0.1,0.1] = 0.01 + 0.006 = 0.016.
    let (va, vb, vab) = (0.072, 0.125, 0.016);
    let expect = vab / (va + vb - vab);
    let v = r_volume(&a, &b, &opts(300_000));
    assert!(
        (v.r_volume - expect).abs() / expect < 0.02,
        "{} vs {expect}",
        v.r_volume
    );
}

#[test]
fn sat_depth_matches_parry_cuboid_contact() {
    use parry3d_f64::math::{Pose, Vector};
    use parry3d_f64::shape::Cuboid;
    let mut rng = Rng(7);
    for _ in 0..40 {
        let mut pose = || {
            let mut f = || rng.next_f64() * 2.0 - 1.0;
            Pose::new(
                Vector::new(0.3 * f(), 0.3 * f(), 0.3 * f()),
                Vector::new(2.0 * f(), 2.0 * f(), 2.0 * f()),
            )
        };
        let (p1, p2) = (pose(), pose());
        let (h1, h2) = (Vector::new(0.3, 0.2, 0.1), Vector::new(0.25, 0.15, 0.2));
        let hull = |pose: &Pose, h: Vector| {
            let m = boxm(2.0 * h.x, 2.0 * h.y, 2.0 * h.z);
            let verts = m
                .vertices
                .iter()
                .map(|p| crate::mesh::from_dvec(pose.transform_point(crate::mesh::to_dvec(p))))
                .collect();
            Mesh::new(verts, m.triangles)
        };
        let (m1, m2) = ([hull(&p1, h1)], [hull(&p2, h2)]);
        let (a, b) = (
            Prepared::new(Solid::Hulls(&m1)),
            Prepared::new(Solid::Hulls(&m2)),
        );
        let ours = max_penetration_depth(&a, &b, &MetricsOptions::default());
        let c =
            parry3d_f64::query::contact(&p1, &Cuboid::new(h1), &p2, &Cuboid::new(h2), 0.0).unwrap();
        let theirs = c.map(|c| (-c.dist).max(0.0)).unwrap_or(0.0);
        assert!((ours - theirs).abs() < 1e-9, "{ours} vs {theirs}");
        if ours == 0.0 {
            let gap = parry3d_f64::query::distance(&p1, &Cuboid::new(h1), &p2, &Cuboid::new(h2))
                .unwrap()
                .distance;
            assert!((min_clearance(&a, &b) - gap).abs() < 1e-9);
        }
    }
}

#[test]
fn deterministic_across_runs_and_thread_counts() {
    let s = uv_sphere(0.04, 24, 48);
    let solids_m = [
        s.clone(),
        moved(&s, 0.03, 0.0, 0.01),
        moved(&boxm(0.05, 0.05, 0.05), 0.0, 0.03, 0.0),
    ];
    let hulls = [boxm(0.02, 0.02, 0.08)];
    let solids = [
        Solid::Mesh(&solids_m[0]),
        Solid::Mesh(&solids_m[1]),
        Solid::Mesh(&solids_m[2]),
        Solid::Hulls(&hulls),
    ];
    let o = opts(60_000);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| scene_metrics(&solids, &o))
    };
    let r1 = run(1);
    let r2 = run(2);
    let r3 = scene_metrics(&solids, &o);
    assert_eq!(r1, r2);
    assert_eq!(r1, r3);
    assert_eq!(r1.len(), 6);
    assert_eq!((r1[0].a, r1[0].b, r1[5].a, r1[5].b), (0, 1, 2, 3));
    // A different seed gives different points but the same answer within noise.
    let other = scene_metrics(
        &solids,
        &MetricsOptions {
            seed: 99,
            ..o.clone()
        },
    );
    assert_ne!(other[0].metrics.inside_both, r1[0].metrics.inside_both);
    assert!((other[0].metrics.r_volume - r1[0].metrics.r_volume).abs() < 0.02);
    // Field names of the serialised result.
    let j = serde_json::to_value(r1[0]).unwrap();
    for k in [
        "a",
        "b",
        "r_volume",
        "r_surface",
        "max_penetration_depth",
        "min_clearance",
        "points",
        "seed",
    ] {
        assert!(j.get(k).is_some(), "{k} missing in {j}");
    }
}

/// `RayMesh::contains` stops after two lines when they give 0 or 4 of the six votes. Against
/// the full vote (all three lines, ties to the winding number) on an open sphere, where the
/// lines disagree near the opening (turned to face +x, so the first line goes through it):
/// every answer the same, and both the early stop and the full vote occur in quantity.
#[test]
fn contains_stopping_after_two_lines_answers_as_the_full_vote() {
    let (r, stacks, slices) = (0.05, 32, 64);
    let s = uv_sphere(r, stacks, slices);
    let cap = slices + 3 * 2 * slices;
    // A quarter turn about y: (x, y, z) -> (z, y, -x), the opening from -z to +x.
    let turn = Matrix4::new(
        0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    );
    let open = Mesh::new(
        s.vertices.clone(),
        s.triangles[..s.triangles.len() - cap].to_vec(),
    )
    .transformed(&turn);
    let po = prep(&open);
    let Shape::Mesh(rm) = &po.shape else {
        unreachable!()
    };
    let mut line = Vec::new();
    let full = |p: V, line: &mut Vec<f64>| -> (bool, usize) {
        let mut votes = Vec::new();
        for axis in 0..3 {
            rm.crossings(axis, p, line);
            let below = line.partition_point(|&t| t < p[axis]);
            votes.push(below % 2 + (line.len() - below) % 2);
        }
        let total: usize = votes.iter().sum();
        let inside = match total {
            v if v > 3 => true,
            v if v < 3 => false,
            _ => rm.winding_number(p).abs() > 0.5,
        };
        (inside, votes[0] + votes[1])
    };
    let mut rng = Rng(11);
    let (mut early, mut late, mut inside) = (0, 0, 0);
    for _ in 0..20_000 {
        let p = [0.0, 1.0, 2.0].map(|_| (rng.next_f64() * 2.0 - 1.0) * 1.05 * r);
        let (want, two) = full(p, &mut line);
        assert_eq!(rm.contains(p), want, "at {p:?}");
        if geom::norm2(p) <= r * r {
            if two == 0 || two == 4 {
                early += 1;
            } else {
                late += 1;
            }
        }
        inside += usize::from(want);
    }
    assert!(early > 1000 && late > 100, "{early} {late}");
    assert!(inside > 2000 && inside < 18_000, "{inside}");
}
