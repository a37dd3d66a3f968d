//! Step 3: the scene. Every object decomposed (in parallel), then hull pairs of different
//! objects closer than the clearance resolved by cuts and splits, and the kept-back budget topped
//! up.
//!
//! Entry points: [`decompose_scene`], [`decompose_scene_with`], [`refine`], [`resolve`],
//! [`top_up`].

use super::*;

pub(super) struct Obj {
    pub(super) surf: Option<Surface>,
    pub(super) feat: Option<patches::Features>,
    pub(super) params: Option<Params>,
    pub(super) parts: Vec<Part>,
    pub(super) report: ObjectReport,
}

/// A conflict: hull `i` of object `a` and hull `j` of object `b` (`a < b`) closer than allowed.
#[derive(Clone, Copy, Debug)]
pub(super) struct Conflict {
    pub(super) a: usize,
    pub(super) i: usize,
    pub(super) b: usize,
    pub(super) j: usize,
}

/// Decompose the whole scene (no cache).
pub fn decompose_scene(
    objects: &[&Mesh],
    opts: &DecomposeOptions,
) -> (Vec<Vec<Hull>>, SceneAwareReport) {
    let (hulls, report, _) = decompose_scene_with(objects, opts, true);
    (hulls, report)
}

/// [`decompose_scene`]; `spend_rest`: whether [`top_up`] spends what the neighbours left of
/// each object's budget.
/// Also returns each object's [`Surface`] (`None` without triangles), for the caller's
/// fidelity measure to reuse.
pub(super) fn decompose_scene_with(
    objects: &[&Mesh],
    opts: &DecomposeOptions,
    spend_rest: bool,
) -> (Vec<Vec<Hull>>, SceneAwareReport, Vec<Option<Surface>>) {
    let n = objects.len();
    let boxes: Vec<Option<crate::mesh::Aabb>> = objects.iter().map(|m| m.aabb()).collect();
    let near = |a: usize, b: usize| match (&boxes[a], &boxes[b]) {
        (Some(x), Some(y)) => {
            x.intersects(y, opts.clearance + 0.01 * x.diagonal().max(y.diagonal()))
        }
        _ => false,
    };
    let has_neighbour: Vec<bool> = (0..n)
        .map(|a| (0..n).any(|b| b != a && near(a, b)))
        .collect();
    let surfs: Vec<Option<Surface>> = objects.par_iter().map(|m| Surface::new(m)).collect();
    // Per triangle, how far the neighbours are: the rebalancing leaves the patches they may
    // touch as the quality loop made them. On `ball_bowl`, rebalancing the bowl let MuJoCo
    // roll the ball 0.6 mm and turn it 1.02° (Rapier 7 mm with the border moves). Pinning
    // the down-facing patches near the ground too (the bowl's foot) then gave back the motion
    // of no rebalancing (0.32 mm, 0.55°); since Rapier's stale contact manifolds are
    // recomputed (`physics::fresh`), it no longer changes it (0.37 mm and 0.62° with those
    // pins, 0.39 mm and 0.66° without, over 2 s from the settled pose), while it kept every
    // container's floor and foot ring out of the rebalancing and the polishing: without
    // it the sum of p95 over the ten shared scenes drops 30.11 → 29.07 (the avocado's plate
    // 1.51 → 1.25 %, the marker mug 2.11 → 1.88 %, the spoon mug 1.91 → 1.70 %, the lemon's
    // bowl 1.64 → 1.44 %), every scene and fixture still settles, and MuJoCo moves the
    // supports at most 0.18 mm in 2 s.
    let nears: Vec<(Vec<f64>, Vec<f64>)> = (0..n)
        .map(|k| {
            let nbs: Vec<&Surface> = (0..n)
                .filter(|&b| b != k && near(k, b))
                .filter_map(|b| surfs[b].as_ref())
                .collect();
            // An object alone is not pinned.
            match &surfs[k] {
                Some(s) if !nbs.is_empty() => {
                    let (mut d, under) = contact_distances(s, &nbs, opts);
                    pin_contacts(s, &nbs, &mut d, opts);
                    (d, under)
                }
                _ => (Vec::new(), Vec::new()),
            }
        })
        .collect();
    let mut objs: Vec<Obj> = surfs
        .into_par_iter()
        .zip(nears.par_iter())
        .enumerate()
        .map(|(k, (surf, (near_k, under_k)))| {
            let budget = if has_neighbour[k] {
                opts.max_hulls - opts.max_hulls / 8
            } else {
                opts.max_hulls
            };
            let budget = budget.max(1);
            let effort = Effort::full(budget);
            decompose_object(surf, opts, budget, effort, near_k, under_k, &Strategy::ALL)
        })
        .collect();
    // Meshes' own interpenetration.
    let pairs: Vec<(usize, usize)> = (0..n)
        .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
        .filter(|&(a, b)| near(a, b))
        .collect();
    let mut mesh_pen = vec![vec![0.0f64; n]; n];
    for &(a, b) in &pairs {
        if let (Some(sa), Some(sb)) = (&objs[a].surf, &objs[b].surf) {
            let d = vertex_depth(sa, sb).max(vertex_depth(sb, sa));
            if d > 0.0 {
                mesh_pen[a][b] = d;
                mesh_pen[b][a] = d;
                objs[a].report.mesh_penetration.push((b, d));
                objs[b].report.mesh_penetration.push((a, d));
            }
        }
    }
    contact_splits(&mut objs, &pairs, &mesh_pen, opts);
    let mut rounds = refine(&mut objs, &pairs, &mesh_pen, opts);
    if spend_rest && top_up(&mut objs, &nears, opts) {
        rounds += refine(&mut objs, &pairs, &mesh_pen, opts);
    }
    // Mesh surface left deep outside every hull, covered in index order (each object against
    // its neighbours' hulls as they are then).
    for k in 0..n {
        let nbs: Vec<usize> = (0..n).filter(|&b| b != k && near(k, b)).collect();
        let obstacles = cover::obstacles(&objs, &nbs);
        objs[k].report.covered = cover::cover(&mut objs[k], &nears[k].0, &obstacles, opts);
    }
    // Final limits and report.
    let mut hulls: Vec<Vec<Hull>> = Vec::with_capacity(n);
    for o in &mut objs {
        let mut hs = Vec::new();
        for part in &o.parts {
            let h = if part.hull.vertices.len() > opts.max_vertices {
                part.hull.clone().simplified(opts.max_vertices)
            } else {
                Some(part.hull.clone())
            };
            match h {
                Some(h) if h.thickness() >= opts.min_thickness => hs.push(h),
                _ => o.report.dropped_hulls += 1,
            }
        }
        o.report.hulls = hs.len();
        hulls.push(hs);
    }
    // Sampled surface distance and remaining overlaps.
    for (k, o) in objs.iter_mut().enumerate() {
        if let Some(s) = &o.surf {
            let d = metrics::surface_distances(s, &hulls[k], 128 * hulls[k].len());
            if !d.is_empty() {
                let (_, p95, max) = metrics::stats(&d);
                o.report.distance_p95 = p95;
                o.report.distance_max = max;
            }
        }
        o.report.tolerance = opts.tolerance;
        o.report.max_hulls = opts.max_hulls;
    }
    let polys: Vec<Vec<Option<parry3d_f64::shape::ConvexPolyhedron>>> = hulls
        .iter()
        .map(|hs| hs.par_iter().map(polyhedron).collect())
        .collect();
    for &(a, b) in &pairs {
        let qs: Vec<(usize, usize)> = (0..hulls[a].len())
            .flat_map(|i| (0..hulls[b].len()).map(move |j| (i, j)))
            .filter(|&(i, j)| {
                hulls[a][i]
                    .aabb
                    .intersects(&hulls[b][j].aabb, opts.clearance)
            })
            .collect();
        let res: Vec<f64> = qs
            .par_iter()
            .map(|&(i, j)| match (&polys[a][i], &polys[b][j]) {
                (Some(x), Some(y)) => geom::separation(x, y).map(|r| r.0).unwrap_or(0.0),
                _ => 0.0,
            })
            .collect();
        for d in res {
            if d < opts.clearance * 0.999 {
                for o in [a, b] {
                    objs[o].report.under_clearance += 1;
                    if d < 0.0 {
                        objs[o].report.overlaps += 1;
                        objs[o].report.max_overlap = objs[o].report.max_overlap.max(-d);
                    }
                }
            }
        }
    }
    let (reports, surfs) = objs.into_iter().map(|o| (o.report, o.surf)).unzip();
    let report = SceneAwareReport {
        objects: reports,
        rounds,
        cached: false,
    };
    (hulls, report, surfs)
}

/// Step 3b: spend what the neighbours left of each object's budget. An object next to a
/// neighbour keeps `max_hulls/8` of it for the contact splits and the refinement (step 3),
/// which often need few or none: the shoe on the tray of `00004` needs none and spends all
/// four here. (The bowl holding the lemon of `00001` ended with 29 of its 32 hulls and p95
/// 1.75 % of the diagonal, 1.64 % with the three left spent, until its contact splits reached
/// the lemon hovering above its floor.) When the object's hulls lie farther from the surface
/// than the tolerance (p95), its free patches (not pinned, see `rebalance::pinned`, and not
/// cut against a neighbour) go through the quality loop again up to `max_hulls`, then the
/// polishing and the refit; the patches a neighbour may touch are left as they were. Returns
/// whether any object changed (the refinement then runs again for the new hulls).
pub(super) fn top_up(
    objs: &mut [Obj],
    nears: &[(Vec<f64>, Vec<f64>)],
    opts: &DecomposeOptions,
) -> bool {
    let changed: Vec<bool> = objs
        .par_iter_mut()
        .zip(nears)
        .map(|(o, (near, _))| {
            let (Some(s), Some(p), Some(f)) = (&o.surf, &o.params, &o.feat) else {
                return false;
            };
            if near.is_empty()
                || o.parts.len() >= opts.max_hulls
                || distance_stats(s, &hulls_of(&o.parts)).is_none_or(|d| d.0 <= opts.tolerance)
            {
                return false;
            }
            // Parts cut against a neighbour are pinned with those within its reach.
            let mut near = near.clone();
            for q in o.parts.iter().filter(|q| !q.cuts.is_empty()) {
                for &t in &q.tris {
                    near[t as usize] = 0.0;
                }
            }
            let before = o.parts.len();
            let free = |q: &Part| !rebalance::pinned(&near, &q.tris, q.dev, p, opts);
            o.report.quality_splits +=
                quality_loop(s, f, p, opts, &mut o.parts, opts.max_hulls, &free);
            if o.parts.len() == before {
                return false;
            }
            let (trimmed, rounds) =
                polish::polish(s, f, p, opts, &mut o.parts, opts.max_hulls, &near);
            o.report.trimmed_patches += trimmed;
            o.report.polish_rounds += rounds;
            o.report.refitted += refit::refit(s, p, opts, &mut o.parts, &near);
            o.report.topped_up = o.parts.len() - before;
            p.memo.clear();
            true
        })
        .collect();
    changed.into_iter().any(|c| c)
}

pub(super) const MAX_ROUNDS: usize = 24;

/// Neighbour refinement; returns the number of rounds run.
pub(super) fn refine(
    objs: &mut [Obj],
    pairs: &[(usize, usize)],
    mesh_pen: &[Vec<f64>],
    opts: &DecomposeOptions,
) -> usize {
    let clearance = opts.clearance;
    // Pairs accepted as they are (surfaces closer than the clearance: cut as far as possible).
    let mut accepted: std::collections::BTreeSet<(usize, usize, usize, usize)> = Default::default();
    for round in 0..MAX_ROUNDS {
        let polys: Vec<Vec<Option<parry3d_f64::shape::ConvexPolyhedron>>> = objs
            .iter()
            .map(|o| o.parts.par_iter().map(|p| polyhedron(&p.hull)).collect())
            .collect();
        let mut cand: Vec<Conflict> = Vec::new();
        for &(a, b) in pairs {
            for i in 0..objs[a].parts.len() {
                for j in 0..objs[b].parts.len() {
                    if objs[a].parts[i]
                        .hull
                        .aabb
                        .intersects(&objs[b].parts[j].hull.aabb, clearance)
                        && !accepted.contains(&(a, i, b, j))
                    {
                        cand.push(Conflict { a, i, b, j });
                    }
                }
            }
        }
        let conflicts: Vec<Conflict> = cand
            .par_iter()
            .filter(|c| match (&polys[c.a][c.i], &polys[c.b][c.j]) {
                (Some(x), Some(y)) => geom::distance(x, y) < clearance,
                _ => false,
            })
            .copied()
            .collect();
        if conflicts.is_empty() {
            return round;
        }
        let mut touched: std::collections::BTreeSet<(usize, usize)> = Default::default();
        let mut removed: Vec<(usize, usize)> = Vec::new();
        for c in conflicts {
            if touched.contains(&(c.a, c.i)) || touched.contains(&(c.b, c.j)) {
                continue;
            }
            touched.insert((c.a, c.i));
            touched.insert((c.b, c.j));
            if let Some(acc) = resolve(objs, c, mesh_pen[c.a][c.b] > 0.0, opts, &mut removed) {
                if acc {
                    accepted.insert((c.a, c.i, c.b, c.j));
                }
            }
            // New parts appended by a split are left for the next round.
            for o in [c.a, c.b] {
                let len = objs[o].parts.len();
                for k in 0..len {
                    if k >= polys[o].len() {
                        touched.insert((o, k));
                    }
                }
            }
        }
        // Remove dropped parts (descending so indices stay valid); accepted keys shift, so
        // re-derive them conservatively by clearing.
        if !removed.is_empty() {
            removed.sort_unstable();
            removed.dedup();
            for &(o, k) in removed.iter().rev() {
                objs[o].parts.remove(k);
            }
            accepted.clear();
        }
    }
    MAX_ROUNDS
}

/// Resolve one conflict. Returns `Some(true)` when the pair is to be accepted as is from now
/// on (the surfaces themselves are closer than the clearance), `Some(false)` otherwise.
pub(super) fn resolve(
    objs: &mut [Obj],
    c: Conflict,
    meshes_interpenetrate: bool,
    opts: &DecomposeOptions,
    removed: &mut Vec<(usize, usize)>,
) -> Option<bool> {
    let clearance = opts.clearance;
    let (pa, pb) = (&objs[c.a].parts[c.i], &objs[c.b].parts[c.j]);
    let fat_a = 1e-6 * objs[c.a].surf.as_ref()?.diag;
    let fat_b = 1e-6 * objs[c.b].surf.as_ref()?.diag;
    let sa = geom::point_polyhedron(&pa.outer, &(-pa.normal), fat_a);
    let sb = geom::point_polyhedron(&pb.outer, &(-pb.normal), fat_b);
    let surf_sep = match (&sa, &sb) {
        (Some(x), Some(y)) => geom::separation(x, y),
        _ => None,
    };
    // Plane: normal n from a towards b, through m.
    let (n, m, gap) = match surf_sep {
        Some((d, n, p1, p2)) if d > 0.0 && n.norm() > 0.5 => (n, nalgebra::center(&p1, &p2), d),
        other => {
            // The surfaces' hulls overlap: split the bulgier patch when that can help.
            if !meshes_interpenetrate {
                let order = if pa.dev >= pb.dev {
                    [(c.a, c.i), (c.b, c.j)]
                } else {
                    [(c.b, c.j), (c.a, c.i)]
                };
                for (o, k) in order {
                    let obj = &objs[o];
                    if obj.parts.len() < opts.max_hulls && obj.parts[k].tris.len() >= 4 {
                        let (s, p) = (obj.surf.as_ref()?, obj.params.as_ref()?);
                        let f = obj.feat.as_ref()?;
                        if let Some((x, y)) = split(s, f, p, opts, &obj.parts[k], f64::INFINITY) {
                            let obj = &mut objs[o];
                            obj.parts[k] = x;
                            obj.parts.push(y);
                            obj.report.neighbour_splits += 1;
                            return Some(false);
                        }
                    }
                }
            }
            // Cut at the penetration mid-plane of the hulls themselves.
            let (ha, hb) = (polyhedron(&pa.hull)?, polyhedron(&pb.hull)?);
            let (_, n, p1, p2) = geom::separation(&ha, &hb)?;
            let n = if n.norm() > 0.5 {
                n
            } else {
                other.map(|o| o.1).filter(|v| v.norm() > 0.5)?
            };
            objs[c.a].report.lossy_cuts += 1;
            objs[c.b].report.lossy_cuts += 1;
            (n, nalgebra::center(&p1, &p2), 0.0)
        }
    };
    let half = if gap >= 1.1 * clearance || gap == 0.0 {
        0.55 * clearance
    } else {
        0.45 * gap
    };
    if gap > 0.0 {
        objs[c.a].report.clean_cuts += 1;
        objs[c.b].report.clean_cuts += 1;
    }
    let cm = n.dot(&m.coords);
    for (o, k, nn, cc) in [(c.a, c.i, n, cm - half), (c.b, c.j, -n, -(cm + half))] {
        let part = &objs[o].parts[k];
        match clip(&part.hull, &nn, cc) {
            Some(h) if h.thickness() >= opts.min_thickness => {
                let part = &mut objs[o].parts[k];
                part.hull = h;
                part.outer.retain(|q| nn.dot(&q.coords) <= cc);
                part.cuts.push((nn, cc));
            }
            // What the cut leaves of the patch elsewhere keeps its coverage.
            _ => match fit::kept_side(&objs[o], part, nn, cc, opts) {
                Some(q) => {
                    objs[o].parts[k] = q;
                    objs[o].report.rebuilt_hulls += 1;
                }
                None => {
                    removed.push((o, k));
                    objs[o].report.dropped_hulls += 1;
                }
            },
        }
    }
    Some(gap > 0.0 && gap < 1.1 * clearance)
}
