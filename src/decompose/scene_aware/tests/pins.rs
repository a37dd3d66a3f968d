//! What a neighbour pins: which triangles a neighbour may rest on, which patches its contact
//! keeps as the quality loop made them.

use super::*;

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
