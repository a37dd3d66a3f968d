//! Where an object touches its neighbours at the composed pose: contact distances, the patches
//! pinned there, and the splits that separate a contact from the rest of a patch.
//!
//! Entry points: [`contact_distances`], [`vertex_depth`], [`pin_contacts`], [`contact_splits`].

use super::*;

/// For each triangle of `s`, a lower bound on its distance to the neighbours' collision
/// geometry (not the ground's: see [`decompose_scene_with`]). That is the distance from its
/// centroid, less its circumradius about the centroid and the neighbour's tolerance (its hulls
/// may bulge that far past its surface). Triangles beyond a quarter of the diagonal from a
/// neighbour's box skip its query. Second, the same over the neighbours that may rest on the
/// triangle, those whose box centre lies above its centroid (see [`keeps_support`]).
pub(super) fn contact_distances(
    s: &Surface,
    nbs: &[&Surface],
    opts: &DecomposeOptions,
) -> (Vec<f64>, Vec<f64>) {
    let far = 0.25 * s.diag;
    (0..s.mesh.triangles.len())
        .into_par_iter()
        .map(|t| {
            let c = s.tri_centroid[t];
            let r = circumradius(s, t);
            let probe = crate::mesh::Aabb { min: c, max: c };
            let (mut all, mut above) = (f64::INFINITY, f64::INFINITY);
            for nb in nbs {
                let pad = r + opts.tolerance * nb.diag;
                if !nb.aabb.intersects(&probe, far + pad) {
                    continue;
                }
                let d = nb.distance(&c) - pad;
                all = all.min(d);
                if nb.aabb.center().z > c.z {
                    above = above.min(d);
                }
            }
            (all, above)
        })
        .unzip()
}

/// How deep the vertices of `b` sit inside closed mesh `a` (0 when none does).
pub(super) fn vertex_depth(a: &Surface, b: &Surface) -> f64 {
    if !a.closed {
        return 0.0;
    }
    b.mesh
        .vertices
        .par_iter()
        .filter(|v| {
            a.aabb
                .intersects(&crate::mesh::Aabb { min: **v, max: **v }, 0.0)
        })
        .map(|v| if a.contains(v) { a.distance(v) } else { 0.0 })
        .reduce(|| 0.0, f64::max)
}

/// Largest deviation (fraction of the tolerance) allowed of a patch hull that a neighbour
/// could rest on.
pub(super) const CONTACT_DEV: f64 = 0.1;

/// Which triangles pin their patch (see `rebalance::pinned`); the others get `near = ∞`:
///
/// - an up-facing level one (normal within about 25° of +Z: a floor something stands on)
///   where a neighbour lies over it (its nearest point within the triangle's circumradius of
///   the centroid horizontally, and not below it by more than the clearance) and within reach
///   of its hull (`near`);
/// - a steep one only where a neighbour's surface touches it (within the clearance of the
///   triangle itself: its centroid's distance less its circumradius) from the side or from
///   above (a pen leaning on a mug's rim), not from below;
/// - a down-facing level one (an underside resting on a neighbour) never.
///
/// Pinning every patch within reach kept the walls of a container beside a neighbour as the
/// quality loop left them; freeing those that merely pass one lowered the sum of p95 over the
/// ten shared scenes 38.0 → 37.0, with every fixture and shared scene still settling. Pins on
/// level triangles alone (sum 35.7) freed the pen's mug wall too: MuJoCo then turned the
/// leaning pen 3.9° (limit 1°), and with no pins at all 19.5°. Freeing the floors too (only
/// the touched steep triangles pinned) let the lemon of `00001` roll 13 mm in Rapier.
///
/// A steep triangle used to be pinned where `near`, which is less the neighbour's tolerance
/// (its hulls may bulge that far), was within the clearance: by the tray's 8.7 mm (1 % of its
/// diagonal) every sole and tread wall of the sneakers on it. Measuring the surface instead,
/// and freeing the undersides, lowered the sum 28.55 → 27.74 (the sneakers of `00005` 1.66 →
/// 1.58, 3.33 → 3.10 and 1.85 → 1.57 %, the shoe of `00004` 1.68 → 1.58 %), with 0 overlaps;
/// every fixture and shared scene still passes, and over 2 s MuJoCo moves no body more than
/// 0.62 mm or 0.63° further than before (a fruit of `00002`; the fixtures' bodies as before).
/// The steep triangles that still pinned the sneakers were the rounded edges of their soles,
/// touching the tray below them: a resting contact like the undersides'. Freed too, the sum
/// fell 27.74 → 25.85 (the sneakers 1.58 → 1.18, 3.10 → 2.55 and 1.57 → 1.10 %, the shoe of
/// `00004` 1.58 → 1.12 %; the other objects unchanged), with 0 overlaps; the scenes still pass
/// and MuJoCo moves each sneaker at most 0.36 mm and 0.19° over 2 s from its settled pose.
/// No longer leaned on (see [`leaned_on`]), the second sneaker of `00005` runs both strategies
/// and takes the plane cuts, which leave more of it uncovered (9.5 → 15.3 %).
///
/// An up-facing triangle used to pin wherever a neighbour was within reach of its hull, beside
/// it as well as over it: the level tops of a sneaker's sole and upper next to the sneaker
/// beside it, a mug's rim and floor ring next to the ball in it. Pinned only under a
/// neighbour, the sum fell 25.85 → 23.87 (the second sneaker of `00005` 2.55 → 1.31 %, the
/// first 1.18 → 1.05 %, the third 1.10 → 1.18 %; the shoe of `00004` 1.12 → 1.02 %, the ball
/// mug 2.80 → 2.33 %, the spoon mug 1.70 → 1.58 %), with 0 overlaps; the ten scenes'
/// decomposition took 15.9 → 18.2 s, the freed patches being rebalanced and polished. The
/// fixtures' hulls are unchanged, every shared scene still passes validation, and over 2 s
/// MuJoCo moves no body more than 0.09 mm or 0.10° further than before.
pub(super) fn pin_contacts(
    s: &Surface,
    nbs: &[&Surface],
    near: &mut [f64],
    opts: &DecomposeOptions,
) {
    near.par_iter_mut().enumerate().for_each(|(t, d)| {
        if d.is_infinite() {
            return;
        }
        let nz = s.tri_normal[t].z;
        let c = s.tri_centroid[t];
        let pins = if nz >= SUPPORT_NZ {
            // A neighbour over the triangle: its nearest point within the triangle's
            // circumradius of the centroid horizontally, and not below it (less the clearance,
            // so that one level with it, beside it, pins whatever the rounding).
            let r = circumradius(s, t);
            nbs.iter().any(|nb| {
                let u = nb.closest(&c) - c;
                u.z >= -opts.clearance && u.x.hypot(u.y) <= r
            })
        } else {
            nz > -SUPPORT_NZ && *d <= opts.clearance && {
                let reach = circumradius(s, t) + opts.clearance;
                nbs.iter().any(|nb| {
                    let u = nb.closest(&c) - c;
                    let gap = u.norm();
                    gap <= reach && u.z > -SUPPORT_NZ * gap
                })
            }
        };
        if !pins {
            *d = f64::INFINITY;
        }
    });
}

/// The largest distance from triangle `t`'s centroid to its corners.
pub(super) fn circumradius(s: &Surface, t: usize) -> f64 {
    let c = s.tri_centroid[t];
    s.mesh
        .triangle(t)
        .iter()
        .map(|v| (v - c).norm())
        .fold(0.0, f64::max)
}

/// Least upward component of the normal from a patch to a neighbour resting on it (about 25°
/// from vertical).
pub(super) const SUPPORT_NZ: f64 = 0.9;

/// Refine where the neighbours rest, before any cut: a patch hull whose bulge (its chord over a
/// concave side, up to the tolerance) could reach a neighbour resting on it is split, worst
/// first, while the object's budget lasts, until its deviation is below `CONTACT_DEV` of the
/// tolerance. A ball on a bowl's flat floor otherwise rests on the chords of the two patches
/// that span the floor and the rising wall: a groove 0.1–0.3 mm above the floor, tilted 1–2°,
/// in which each engine finds a different rest (Rapier and MuJoCo 2.5 mm apart). Pairs whose
/// meshes interpenetrate are left to the cuts.
///
/// A neighbour counts as resting on a patch up to a tolerance above the hull's reach as well:
/// a composed scene leaves its items up to about that above their support, and they land on
/// it. The lemon of `00001` hovers 1.0 mm over its bowl's floor (the tolerance: 1.7 mm), which
/// the splits used to pass over: it settled 0.35 mm and 0.76° in Rapier, and at 48 hulls the
/// floor patches under it tilted 11° and it rolled out of the rest check (3.6°). With the
/// tolerance, 3 more splits under it (sum of p95 over the ten shared scenes 23.87 → 24.02:
/// the bowl 1.44 → 1.61 %): it settles 0.02 mm and 0.02°, MuJoCo turns it 2.89° in 2 s
/// (3.42° before), and of the fixtures and shared scenes at 40, 48 and 64 hulls only the pen
/// of `pen_mug` at 64 still fails (2 of 45 before).
pub(super) fn contact_splits(
    objs: &mut [Obj],
    pairs: &[(usize, usize)],
    mesh_pen: &[Vec<f64>],
    opts: &DecomposeOptions,
) {
    // Parts that cannot be split; indices stay valid (a split replaces part k and appends).
    let mut unsplittable: Vec<(usize, usize)> = Vec::new();
    for _ in 0..opts.max_hulls {
        let mut worst: Option<(f64, usize, usize)> = None;
        for &(a, b) in pairs {
            if mesh_pen[a][b] > 0.0 {
                continue;
            }
            for (o, other) in [(a, b), (b, a)] {
                let obj = &objs[o];
                let (Some(p), true) = (&obj.params, obj.parts.len() < opts.max_hulls) else {
                    continue;
                };
                for (k, part) in obj.parts.iter().enumerate() {
                    if part.tris.len() < 4
                        || part.dev <= CONTACT_DEV * p.tol
                        || unsplittable.contains(&(o, k))
                        || worst.is_some_and(|w| (w.0, w.1, w.2) >= (part.dev, o, k))
                    {
                        continue;
                    }
                    let reach = opts.clearance + part.dev + p.tol;
                    let Some(hp) = polyhedron(&part.hull) else {
                        continue;
                    };
                    // The neighbour rests on this patch: it is within reach, above it along a
                    // near-vertical normal (scenes are Z-up by now). Side and leaning contacts
                    // (a pen on a mug's rim) are left to the cuts: splitting the rim under a
                    // leaning pen let it roll 150° about its axis in Rapier.
                    let near = objs[other].parts.iter().any(|q| {
                        part.hull.aabb.intersects(&q.hull.aabb, reach)
                            && polyhedron(&q.hull).is_some_and(|hq| {
                                geom::separation(&hp, &hq)
                                    .is_some_and(|(d, n, _, _)| d < reach && n.z >= SUPPORT_NZ)
                            })
                    });
                    if near {
                        worst = Some((part.dev, o, k));
                    }
                }
            }
        }
        let Some((_, o, k)) = worst else { return };
        let obj = &objs[o];
        let (Some(s), Some(p), Some(f)) = (&obj.surf, &obj.params, &obj.feat) else {
            return;
        };
        match split(s, f, p, opts, &obj.parts[k], f64::INFINITY) {
            Some((x, y)) => {
                let obj = &mut objs[o];
                obj.parts[k] = x;
                obj.parts.push(y);
                obj.report.neighbour_splits += 1;
            }
            None => unsplittable.push((o, k)),
        }
    }
}
