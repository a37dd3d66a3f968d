//! Rebalancing a full budget: move hulls from where patches fit well to the patch that deviates
//! most, while that lowers the worst deviation.
//!
//! The quality loop splits the worst patch in two until the budget is spent. Binary splits
//! leave the patches uneven: a patch split once too few keeps twice its neighbours' sagitta.
//! On the GSO mug scan, 32 hulls ended with a worst deviation of 3.9 % of the diagonal, and
//! rounds here brought it to 2.8 % (p95 distance 2.4 % → 1.5 %). Each round takes the patch
//! that deviates most (w) and tries two moves:
//!
//! 1. merge the pair of adjacent patches (i, j ≠ w) whose merged hull deviates least, and
//!    split w with the freed hull;
//! 2. else move w's border with one of its neighbours: merge the two and split them again.
//!
//! A move is kept only when every new hull deviates less than w did: the hull count stays the
//! same and the maximum over the object never goes up. A patch that neither move improves is
//! set aside and the next worst is tried; the loop ends after `rounds` kept moves, when no
//! patch is left above the tolerance, or after `2·rounds` tries.
//!
//! A merge may not lift the hull above the patches' up-facing triangles (a floor, a shelf)
//! more than the two hulls did (nor above `CONTACT_DEV` of the tolerance), so what an object
//! may be put on stays as flat as the quality loop left it; a rim merged into the wall
//! segment under it is fine, since the merged hull's top is the rim. Scenes are Z-up by the
//! time they are decomposed.
//!
//! Next to neighbours, the patches within reach of a neighbour are pinned (see [`pinned`]):
//! on the `ball_bowl` scene, a bowl rebalanced everywhere let MuJoCo roll the ball 0.6 mm and
//! turn it 1.02° while Rapier held it (merges only; with the border moves Rapier rolled it
//! 7 mm). The bowl's foot, near the ground, was pinned too until Rapier's stale contacts were
//! recomputed; it no longer changes the ball's motion (see `decompose_scene_with`).
//!
//! Merged hulls are cached by the pair of patch ids (a patch gets a new id when it changes),
//! so a round builds only the merges next to the three patches it changed.

use super::geom::Surface;
use super::patches::Features;
use super::{build_part_below, split, Params, Part, CONTACT_DEV, SUPPORT_NZ};
use crate::decompose::DecomposeOptions;
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Rebalance `parts` in place (at most `rounds` rounds); returns the rounds kept.
pub(super) fn rebalance(
    s: &Surface,
    f: &Features,
    p: &Params,
    opts: &DecomposeOptions,
    parts: &mut [Part],
    rounds: usize,
    near: &[f64],
) -> usize {
    let is_pinned = |tris: &[u32], dev: f64| pinned(near, tris, dev, p, opts);
    let mut ids: Vec<u64> = (0..parts.len() as u64).collect();
    let mut next_id = parts.len() as u64;
    // The adjacency of the parts named by the ids (see [`adjacency`]).
    let mut adj_at: (Vec<u64>, Vec<Vec<usize>>) = (Vec::new(), Vec::new());
    // Merges, with their lift, by the pair of part ids; lifts of the current parts by id.
    let mut merged: BTreeMap<(u64, u64), Option<(Part, f64)>> = BTreeMap::new();
    let mut lift_of: BTreeMap<u64, f64> = BTreeMap::new();
    let mut kept = 0;
    // Patches whose best split does not go below their own deviation (by id): skipped, and the
    // next worst is tried instead.
    let mut stuck: Vec<u64> = Vec::new();
    for _ in 0..2 * rounds {
        if kept >= rounds {
            break;
        }
        if parts.len() < 3 {
            break;
        }
        let Some(w) = (0..parts.len())
            .filter(|&i| {
                parts[i].tris.len() >= 2
                    && !stuck.contains(&ids[i])
                    && !is_pinned(&parts[i].tris, parts[i].dev)
            })
            .max_by(|&i, &j| parts[i].dev.total_cmp(&parts[j].dev).then(j.cmp(&i)))
        else {
            break;
        };
        let worst = parts[w].dev;
        if worst <= p.tol {
            break;
        }
        // The parts change only with their ids: a round after one that kept no move finds
        // the same adjacency.
        if adj_at.0 != ids {
            adj_at = (ids.clone(), adjacency(s, parts));
        }
        let adj = &adj_at.1;
        // Adjacent pairs, w excluded, in index order.
        let pairs: Vec<(usize, usize)> = adjacent_pairs(adj, w);
        // How far each hull rises above its patch's up-facing triangles.
        let lifts: Vec<f64> = lifts_by_id(s, parts, &ids, &mut lift_of);
        let missing: Vec<(usize, usize)> = pairs
            .iter()
            .copied()
            .filter(|&(i, j)| !merged.contains_key(&(ids[i], ids[j])))
            .collect();
        // Built below `worst`: a merge deviating more is never kept (move 1 needs `m.dev <
        // worst`), neither now nor later, since `worst` never grows from round to round (the
        // parts a kept move makes deviate less, the others keep their deviation and the set
        // aside stay aside). The least merge below it is the least of all when one is below.
        let built: Vec<Option<(Part, f64)>> = missing
            .par_iter()
            .map(|&(i, j)| {
                let m = build_merge(s, p, opts, &parts[i], &parts[j], worst)?;
                let l = lift(s, &m.hull, &m.tris);
                Some((m, l))
            })
            .collect();
        for (&(i, j), b) in missing.iter().zip(built) {
            merged.insert((ids[i], ids[j]), b);
        }
        // A merge may not lift the hull above an up-facing surface (a floor, where something
        // may be put later) more than the two hulls did: it would rest on the merged chord.
        let top = |i: usize, j: usize| lifts[i].max(lifts[j]).max(CONTACT_DEV * p.tol);
        let best = pairs
            .iter()
            .filter_map(|&(i, j)| {
                let (m, m_lift) = merged.get(&(ids[i], ids[j]))?.as_ref()?;
                let free = [&parts[i], &parts[j], m]
                    .iter()
                    .all(|q| !is_pinned(&q.tris, q.dev));
                (*m_lift <= top(i, j) && free).then_some((m.dev, i, j))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
        // Move 1: merge the best pair, split w.
        let halves = best
            .filter(|&(m_dev, _, _)| m_dev < worst)
            .and_then(|_| split(s, f, p, opts, &parts[w], worst));
        let Some((a, b)) = halves else {
            // Move 2: move w's border with one of its neighbours (merge the two, split again)
            // when that brings both below w's deviation.
            // The least worse half of a neighbour's move kept so far: another neighbour's split
            // is built below it (ties admitted, then broken by the neighbour's index), since
            // only the least is kept. A neighbour whose closest split is not below it would
            // lose; one whose closest split is below it gets the same split as below `worst`.
            let least = std::sync::Mutex::new(worst);
            let relaxed = adj[w]
                .par_iter()
                .filter_map(|&j| {
                    // `split` reads only the triangles and the cuts of the part it splits.
                    let both = Part {
                        tris: union(&parts[w], &parts[j]),
                        ..parts[w].clone()
                    };
                    let l = *least.lock().expect("no panic holding it");
                    let bound = if l < worst { l.next_up() } else { worst };
                    let (a, b) = split(s, f, p, opts, &both, bound)?;
                    let ok = !is_pinned(&parts[j].tris, parts[j].dev)
                        && !is_pinned(&a.tris, a.dev)
                        && !is_pinned(&b.tris, b.dev)
                        && lift(s, &a.hull, &a.tris) <= top(w, j)
                        && lift(s, &b.hull, &b.tris) <= top(w, j);
                    if ok {
                        let mut l = least.lock().expect("no panic holding it");
                        *l = l.min(a.dev.max(b.dev));
                    }
                    ok.then_some((a.dev.max(b.dev), j, a, b))
                })
                .min_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            match relaxed {
                Some((_, j, a, b)) => {
                    parts[w] = a;
                    parts[j] = b;
                    for k in [w, j] {
                        ids[k] = next_id;
                        next_id += 1;
                    }
                    kept += 1;
                }
                None => stuck.push(ids[w]),
            }
            continue;
        };
        let (_, i, j) = best.expect("move 1 needs a merge");
        let (m, _) = merged
            .remove(&(ids[i], ids[j]))
            .flatten()
            .expect("merge was just found");
        // Replace i by the merge, w and j by the halves: no index moves.
        parts[i] = m;
        parts[w] = a;
        parts[j] = b;
        for k in [i, w, j] {
            ids[k] = next_id;
            next_id += 1;
        }
        kept += 1;
    }
    kept
}

/// Whether a patch (`tris`, its hull deviating `dev`) is within reach of a neighbour (`near`:
/// per triangle, see `contact_distances`): its hull may bulge `dev` past its surface, a
/// quarter more for sampling. Pinned patches are not merged, moved or split by the
/// rebalancing.
pub(super) fn pinned(
    near: &[f64],
    tris: &[u32],
    dev: f64,
    p: &Params,
    opts: &DecomposeOptions,
) -> bool {
    !near.is_empty() && {
        let reach = reach(dev, p, opts);
        tris.iter().any(|&t| near[t as usize] <= reach)
    }
}

/// How near a neighbour (`near`) a triangle of a patch whose hull deviates `dev` may touch it:
/// the hull may bulge `dev` (at least the tolerance) past the surface, a quarter more for
/// sampling.
pub(super) fn reach(dev: f64, p: &Params, opts: &DecomposeOptions) -> f64 {
    opts.clearance + 1.25 * dev.max(p.tol)
}

/// How far the hull's surface lies above the patch's up-facing triangles (normal within
/// about 25° of +Z): the largest distance, straight up from a triangle's centroid, to where
/// it leaves the hull. 0 when the patch has none.
pub(super) fn lift(s: &Surface, h: &crate::decompose::Hull, tris: &[u32]) -> f64 {
    let mut worst: f64 = 0.0;
    for &t in tris {
        if s.tri_normal[t as usize].z < SUPPORT_NZ {
            continue;
        }
        let c = s.tri_centroid[t as usize];
        let exit = h
            .planes
            .iter()
            .filter(|(n, _)| n.z > 1e-9)
            .map(|(n, d)| (d - n.dot(&c.coords)) / n.z)
            .fold(f64::INFINITY, f64::min);
        if exit.is_finite() {
            worst = worst.max(exit);
        }
    }
    worst
}

/// [`lift`] of each part, computed once per part id (`ids[k]` names `parts[k]`; a part gets a
/// new id when it changes) and kept in `cache`.
pub(super) fn lifts_by_id(
    s: &Surface,
    parts: &[Part],
    ids: &[u64],
    cache: &mut BTreeMap<u64, f64>,
) -> Vec<f64> {
    parts
        .iter()
        .zip(ids)
        .map(|(q, id)| {
            *cache
                .entry(*id)
                .or_insert_with(|| lift(s, &q.hull, &q.tris))
        })
        .collect()
}

/// The pairs of adjacent patches (`i < j`), `w` excluded, in index order.
pub(super) fn adjacent_pairs(adj: &[Vec<usize>], w: usize) -> Vec<(usize, usize)> {
    (0..adj.len())
        .filter(|&i| i != w)
        .flat_map(|i| {
            adj[i]
                .iter()
                .filter(move |&&j| j > i && j != w)
                .map(move |&j| (i, j))
        })
        .collect()
}

/// The part two patches make together, with the first one's cuts (every merge keeps them), or
/// `None` when their triangles make no part or it deviates `bound` or more (see
/// [`build_part_below`]; `f64::INFINITY`: any deviation).
pub(super) fn build_merge(
    s: &Surface,
    p: &Params,
    opts: &DecomposeOptions,
    a: &Part,
    b: &Part,
    bound: f64,
) -> Option<Part> {
    build_part_below(s, p, opts, union(a, b), a.cuts.clone(), bound)
}

/// The triangles of two patches, ascending.
pub(super) fn union(a: &Part, b: &Part) -> Vec<u32> {
    let mut tris = a.tris.clone();
    tris.extend_from_slice(&b.tris);
    // Two ascending runs: the stable sort finds and merges them in one pass.
    tris.sort();
    tris
}

/// For each patch, the patches sharing a mesh vertex with it, ascending.
pub(super) fn adjacency(s: &Surface, parts: &[Part]) -> Vec<Vec<usize>> {
    // The first part owning each vertex, and the other owners of the few that have more (on
    // patch borders) apart: a list per vertex cost 4,227 allocations per call on the GSO mug.
    let mut first = vec![usize::MAX; s.mesh.vertices.len()];
    let mut more: Vec<(u32, usize)> = Vec::new();
    for (k, part) in parts.iter().enumerate() {
        for &t in &part.tris {
            for v in s.mesh.triangles[t as usize] {
                let f = &mut first[v as usize];
                if *f == usize::MAX {
                    *f = k;
                } else if *f != k {
                    more.push((v, k));
                }
            }
        }
    }
    more.sort_unstable();
    more.dedup();
    let mut adj: Vec<Vec<usize>> = vec![Vec::new(); parts.len()];
    let mut owners = Vec::new();
    for shared in more.chunk_by(|a, b| a.0 == b.0) {
        owners.clear();
        owners.push(first[shared[0].0 as usize]);
        owners.extend(shared.iter().map(|e| e.1));
        for &a in &owners {
            adj[a].extend(owners.iter().copied().filter(|&b| b != a));
        }
    }
    for n in &mut adj {
        n.sort_unstable();
        n.dedup();
    }
    adj
}
