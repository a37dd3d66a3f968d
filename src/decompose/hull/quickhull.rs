//! parry's 3-D quickhull (`parry3d_f64::transformation::try_convex_hull`, version 0.31.1), the
//! same arithmetic in the same order, with its buffers kept between calls.
//!
//! Entry point: [`convex_hull`], whose output is `try_convex_hull`'s to the bit (vertices in
//! the same order, the same triangles in the same order, an error where it errs or panics).
//! A `Hull` keeps parry's vertex and triangle order as they come (nothing canonicalises
//! them), so any other exact hull algorithm would change the exported bytes; this one does
//! not: it is parry's own loop, with each facet's visible points, the silhouette, the removed
//! facets and the undecidable points in vectors that keep their capacity (one set per thread)
//! instead of growing new ones on every call and every facet. The initial tetrahedron-free
//! start (two opposite facets on the principal plane) is parry's too, built from parry's own
//! public helpers (`utils::cov`, `utils::center`, the symmetric eigen-decomposition,
//! `Triangle`); inputs that are not 3-dimensional (a point, a segment, a plane by parry's
//! eigenvalue test) go to parry itself.
//!
//! Derived from parry3d-f64 0.31.1's `transformation/convex_hull3` (Copyright Sébastien Crozet,
//! <https://github.com/dimforge/parry>, licensed under the Apache License, Version 2.0). What this
//! file changes: the buffers are kept between calls; the algorithm and its arithmetic are parry's.
//! When parry's hull changes, `tests.rs` beside this file (every result compared with
//! `try_convex_hull` to the bit) says so, and this copy follows it or goes.

use parry3d_f64::math::{MatExt, Vector3, DEFAULT_EPSILON};
use parry3d_f64::shape::Triangle;
use std::cell::RefCell;
use std::cmp::Ordering;

/// Why the hull failed (parry's error or one of its panics, which the caller treats alike).
#[derive(Debug)]
pub struct Failed;

/// One triangle of the hull under construction (parry's `TriangleFacet`), its visible points
/// in a vector that keeps its capacity when the slot is reused.
struct Facet {
    valid: bool,
    affinely_dependent: bool,
    normal: Vector3,
    adj: [usize; 3],
    indirect_adj_id: [usize; 3],
    pts: [usize; 3],
    visible: Vec<usize>,
}

impl Facet {
    fn distance_to_point(&self, point: usize, points: &[Vector3]) -> f64 {
        self.normal.dot(points[point] - points[self.pts[0]])
    }

    fn first_point_from_edge(&self, id: usize) -> usize {
        self.pts[id]
    }

    fn second_point_from_edge(&self, id: usize) -> usize {
        self.pts[(id + 1) % 3]
    }

    fn can_see_point(&self, point: usize, points: &[Vector3]) -> bool {
        if self.affinely_dependent {
            return false;
        }
        (points[point] - points[self.pts[0]]).dot(self.normal) >= DEFAULT_EPSILON * 100.0
    }

    fn order_independent_can_be_seen_by_point(&self, point: usize, points: &[Vector3]) -> bool {
        if self.affinely_dependent {
            return true;
        }
        (0..3).any(|i| (points[point] - points[self.pts[i]]).dot(self.normal) >= 0.0)
    }

    /// `TriangleFacet::add_visible_point` (its `furthest_point` is never read by the loop).
    fn add_visible_point(&mut self, pid: usize, points: &[Vector3]) -> Result<(), Failed> {
        if !(self.distance_to_point(pid, points) > DEFAULT_EPSILON) {
            return Err(Failed); // parry asserts
        }
        self.visible.push(pid);
        Ok(())
    }
}

/// Of `facets`, the one that sees `point` farthest (parry's loop, written twice there: the
/// two-facet start and the undecidable points): the first strictly farther than those before
/// it and than 0, or `None` when none sees it.
fn farthest_seeing(facets: &[Facet], point: usize, points: &[Vector3]) -> Option<usize> {
    let mut furthest = None;
    let mut furthest_dist = 0.0;
    for (i, f) in facets.iter().enumerate() {
        if f.can_see_point(point, points) {
            let distance = f.distance_to_point(point, points);
            if distance > furthest_dist {
                furthest = Some(i);
                furthest_dist = distance;
            }
        }
    }
    furthest
}

/// The buffers of one thread's hulls.
#[derive(Default)]
struct Work {
    /// Facet slots; `len` of them in use.
    facets: Vec<Facet>,
    len: usize,
    normalized: Vec<Vector3>,
    undecidable: Vec<usize>,
    silhouette: Vec<(usize, usize)>,
    silhouette_old: Vec<(usize, usize)>,
    removed: Vec<usize>,
    workspace: Vec<u32>,
    used: Vec<bool>,
    remap: Vec<usize>,
}

impl Work {
    /// A new facet in the next slot (`TriangleFacet::new`), its index.
    fn push(&mut self, p1: usize, p2: usize, p3: usize) -> usize {
        let points = &self.normalized;
        let normal = (points[p2] - points[p1])
            .cross(points[p3] - points[p1])
            .normalize();
        let affinely_dependent =
            Triangle::new(points[p1], points[p2], points[p3]).is_affinely_dependent();
        if self.len == self.facets.len() {
            self.facets.push(Facet {
                valid: true,
                affinely_dependent,
                normal,
                adj: [0; 3],
                indirect_adj_id: [0; 3],
                pts: [p1, p2, p3],
                visible: Vec::new(),
            });
        } else {
            let f = &mut self.facets[self.len];
            f.valid = true;
            f.affinely_dependent = affinely_dependent;
            f.normal = normal;
            f.adj = [0; 3];
            f.indirect_adj_id = [0; 3];
            f.pts = [p1, p2, p3];
            f.visible.clear();
        }
        self.len += 1;
        self.len - 1
    }
}

/// Facet slots beyond which a thread's buffers are dropped after the call (the hull of a
/// whole mesh), so that they keep only what the search's small hulls (at most 64 points, a
/// few hundred facets) reuse: kept whole, they raised the scenes' peak RSS by 1-5 MiB.
const KEEP_FACETS: usize = 2048;

thread_local! {
    static WORK: RefCell<Work> = RefCell::new(Work::default());
}

/// `try_convex_hull(points)`, to the bit: the hull's vertices (a subset of `points`) and its
/// outward triangles.
pub fn convex_hull(points: &[Vector3]) -> Result<(Vec<Vector3>, Vec<[u32; 3]>), Failed> {
    if points.len() < 3 {
        return Err(Failed);
    }
    WORK.with(|w| match w.try_borrow_mut() {
        Ok(mut w) => {
            let hull = w.hull(points);
            if w.facets.len() > KEEP_FACETS {
                *w = Work::default();
            }
            hull
        }
        // Re-entered on this thread (cannot happen: nothing here calls back): parry's own.
        Err(_) => parry3d_f64::transformation::try_convex_hull(points).map_err(|_| Failed),
    })
}

impl Work {
    fn hull(&mut self, points: &[Vector3]) -> Result<(Vec<Vector3>, Vec<[u32; 3]>), Failed> {
        self.len = 0;
        self.undecidable.clear();
        self.normalized.clear();
        self.normalized.extend_from_slice(points);
        // Zero here, and zeroed again where `fix_silhouette_topology` counted.
        self.workspace.clear();
        self.workspace.resize(points.len(), 0);
        // `convex_hull_utils::normalize`.
        let aabb = parry3d_f64::bounding_volume::details::local_point_cloud_aabb_ref(
            self.normalized.iter(),
        );
        let diag = aabb.mins.distance(aabb.maxs);
        let center = aabb.center();
        for c in self.normalized.iter_mut() {
            *c = (*c - center) / diag;
        }
        if !self.initial_mesh()? {
            return parry3d_f64::transformation::try_convex_hull(points).map_err(|_| Failed);
        }

        let mut i = 0;
        while i != self.len {
            self.silhouette.clear();
            if !self.facets[i].valid || self.facets[i].affinely_dependent {
                i += 1;
                continue;
            }
            let pt_id = {
                let f = &self.facets[i];
                support(f.normal, &self.normalized, f.visible.iter().copied()).map(|(_, i)| i)
            };
            if let Some(point) = pt_id {
                self.facets[i].valid = false;
                self.removed.clear();
                self.removed.push(i);
                for j in 0..3 {
                    let (adj, ind) = (self.facets[i].adj[j], self.facets[i].indirect_adj_id[j]);
                    self.compute_silhouette(adj, ind, point);
                }
                self.fix_silhouette_topology()?;
                if self.silhouette.is_empty() {
                    let any_valid = self.facets[i + 1..self.len]
                        .iter()
                        .any(|t| t.valid && !t.affinely_dependent);
                    if any_valid {
                        return Err(Failed);
                    }
                    self.facets[i].valid = true;
                    break;
                }
                self.attach_and_push_facets(point)?;
            }
            i += 1;
        }

        let mut idx: Vec<[u32; 3]> = self.facets[..self.len]
            .iter()
            .filter(|f| f.valid)
            .map(|f| [f.pts[0] as u32, f.pts[1] as u32, f.pts[2] as u32])
            .collect();
        let mut out = points.to_vec();
        self.remove_unused_points(&mut out, &mut idx);
        Ok((out, idx))
    }

    /// `initial_mesh::try_get_initial_mesh` for 3-dimensional inputs: `Ok(false)` when parry
    /// sees fewer dimensions (the caller then asks parry).
    fn initial_mesh(&mut self) -> Result<bool, Failed> {
        let eig = parry3d_f64::utils::cov(&self.normalized).symmetric_eigen();
        let (eigvec, eigval) = (eig.eigenvectors, eig.eigenvalues);
        let mut eigpairs = [
            (eigvec.x_axis, eigval[0]),
            (eigvec.y_axis, eigval[1]),
            (eigvec.z_axis, eigval[2]),
        ];
        eigpairs.sort_by(|a, b| {
            if a.1 > b.1 {
                Ordering::Less
            } else if a.1 < b.1 {
                Ordering::Greater
            } else {
                Ordering::Equal
            }
        });
        // `relative_eq!(x, 0.0, epsilon = 1.0e-7)`: for a comparison with zero, |x| ≤ 1e-7.
        if eigpairs.iter().any(|e| e.1 == 0.0 || e.1.abs() <= 1.0e-7) {
            return Ok(false);
        }
        let center = parry3d_f64::utils::center(&self.normalized);
        let max_eigval = {
            let ax = eigval.x.abs();
            let ay = eigval.y.abs();
            let az = eigval.z.abs();
            ax.max(ay).max(az)
        };
        for point in self.normalized.iter_mut() {
            *point = (*point - center) / max_eigval;
        }
        let p1 = support(eigpairs[0].0, &self.normalized, 0..self.normalized.len())
            .ok_or(Failed)?
            .1;
        let p2 = support(-eigpairs[0].0, &self.normalized, 0..self.normalized.len())
            .ok_or(Failed)?
            .1;
        let mut max_area = 0.0;
        let mut p3 = usize::MAX;
        for (i, point) in self.normalized.iter().enumerate() {
            let area = Triangle::new(self.normalized[p1], self.normalized[p2], *point).area();
            if area > max_area {
                max_area = area;
                p3 = i;
            }
        }
        if p3 == usize::MAX {
            return Err(Failed);
        }
        let f1 = self.push(p1, p2, p3);
        let f2 = self.push(p2, p1, p3);
        self.facets[f1].adj = [1, 1, 1];
        self.facets[f1].indirect_adj_id = [0, 2, 1];
        self.facets[f2].adj = [0, 0, 0];
        self.facets[f2].indirect_adj_id = [0, 2, 1];
        let points = &self.normalized;
        for point in 0..points.len() {
            if points[point] == points[p1]
                || points[point] == points[p2]
                || points[point] == points[p3]
            {
                continue;
            }
            if let Some(f) = farthest_seeing(&self.facets[..2], point, points) {
                self.facets[f].add_visible_point(point, points)?;
            } else {
                self.undecidable.push(point);
            }
        }
        // parry's `check_facet_links` on the two facets holds by construction.
        Ok(true)
    }

    fn compute_silhouette(&mut self, facet: usize, indirect_id: usize, point: usize) {
        if !self.facets[facet].valid {
            return;
        }
        if !self.facets[facet].order_independent_can_be_seen_by_point(point, &self.normalized) {
            self.silhouette.push((facet, indirect_id));
        } else {
            self.facets[facet].valid = false;
            self.removed.push(facet);
            let (a1, i1) = (
                self.facets[facet].adj[(indirect_id + 1) % 3],
                self.facets[facet].indirect_adj_id[(indirect_id + 1) % 3],
            );
            self.compute_silhouette(a1, i1, point);
            let (a2, i2) = (
                self.facets[facet].adj[(indirect_id + 2) % 3],
                self.facets[facet].indirect_adj_id[(indirect_id + 2) % 3],
            );
            self.compute_silhouette(a2, i2, point);
        }
    }

    /// parry's `fix_silhouette_topology`, its per-point counts in `workspace` (zero on entry,
    /// zeroed again on a normal return where they were counted, instead of a new vector each
    /// time).
    fn fix_silhouette_topology(&mut self) -> Result<(), Failed> {
        let mut needs_fixing = false;
        for &(facet, adj_id) in &self.silhouette {
            let p = self.facets[facet].second_point_from_edge(adj_id);
            self.workspace[p] += 1;
            if self.workspace[p] > 1 {
                needs_fixing = true;
            }
        }
        if !needs_fixing {
            for &(facet, adj_id) in &self.silhouette {
                self.workspace[self.facets[facet].second_point_from_edge(adj_id)] = 0;
            }
            return Ok(());
        }
        let mut loop_start = 0;
        for &(facet, adj_id) in &self.silhouette {
            let p1 = self.normalized[self.facets[facet].second_point_from_edge(adj_id)];
            let p2 = self.normalized[self.facets[facet].first_point_from_edge(adj_id)];
            let (supp, _) = support(
                p2 - p1,
                &self.normalized,
                self.silhouette
                    .iter()
                    .map(|&(f, ai)| self.facets[f].second_point_from_edge(ai)),
            )
            .ok_or(Failed)?;
            let selected = self.silhouette[supp];
            if self.workspace[self.facets[selected.0].second_point_from_edge(selected.1)] == 1 {
                loop_start = supp;
                break;
            }
        }
        let mut removing = None;
        std::mem::swap(&mut self.silhouette, &mut self.silhouette_old);
        self.silhouette.clear();
        let n = self.silhouette_old.len();
        for i in 0..n {
            let (facet, adj_id) = self.silhouette_old[(loop_start + i) % n];
            let p1 = self.facets[facet].second_point_from_edge(adj_id);
            match removing {
                Some(p) => {
                    if p == p1 {
                        removing = None;
                    }
                }
                _ => {
                    if self.workspace[p1] > 1 {
                        removing = Some(p1);
                    }
                }
            }
            if removing.is_some() {
                if self.facets[facet].valid {
                    self.facets[facet].valid = false;
                    self.removed.push(facet);
                }
            } else {
                self.silhouette.push((facet, adj_id));
            }
        }
        for &(facet, adj_id) in &self.silhouette_old {
            self.workspace[self.facets[facet].second_point_from_edge(adj_id)] = 0;
        }
        Ok(())
    }

    fn attach_and_push_facets(&mut self, point: usize) -> Result<(), Failed> {
        // The new facets go straight into the slots after the current ones: parry builds them
        // aside and appends them, at the same indices, after the same steps.
        let base = self.len;
        let n = self.silhouette.len();
        for k in 0..n {
            let (adj_facet, indirect_id) = self.silhouette[k];
            let a = self.facets[adj_facet].second_point_from_edge(indirect_id);
            let b = self.facets[adj_facet].first_point_from_edge(indirect_id);
            self.push(point, a, b);
        }
        for i in 0..n {
            let prev_facet = if i == 0 { base + n - 1 } else { base + i - 1 };
            let (middle_facet, middle_id) = self.silhouette[i];
            let next_facet = base + (i + 1) % n;
            let f = &mut self.facets[base + i];
            f.adj = [prev_facet, middle_facet, next_facet];
            f.indirect_adj_id = [2, middle_id, 0];
            // parry asserts the overwritten link's facet is not valid (and indexes only the
            // facets before the new ones).
            let old = self.facets[middle_facet].adj[middle_id];
            if old >= base || self.facets[old].valid {
                return Err(Failed);
            }
            self.facets[middle_facet].adj[middle_id] = base + i;
            self.facets[middle_facet].indirect_adj_id[middle_id] = 1;
        }

        let points = &self.normalized;
        let (old, new) = self.facets.split_at_mut(base);
        let new = &mut new[..n];
        for &curr in &self.removed {
            for &visible_point in &old[curr].visible {
                if points[visible_point] == points[point] {
                    continue;
                }
                let mut furthest = usize::MAX;
                let mut furthest_dist = 0.0;
                for (i, f) in new.iter().enumerate() {
                    if !f.affinely_dependent {
                        let distance = f.distance_to_point(visible_point, points);
                        if distance > furthest_dist {
                            furthest = i;
                            furthest_dist = distance;
                        }
                    }
                }
                if furthest != usize::MAX && new[furthest].can_see_point(visible_point, points) {
                    new[furthest].add_visible_point(visible_point, points)?;
                }
            }
        }

        let mut i = 0;
        while i != self.undecidable.len() {
            let undecidable_point = self.undecidable[i];
            if let Some(f) = farthest_seeing(new, undecidable_point, points) {
                new[f].add_visible_point(undecidable_point, points)?;
                let _ = self.undecidable.swap_remove(i);
            } else {
                i += 1;
            }
        }
        Ok(())
    }

    /// `utils::remove_unused_points`.
    fn remove_unused_points(&mut self, points: &mut Vec<Vector3>, idx: &mut [[u32; 3]]) {
        self.used.clear();
        self.used.resize(points.len(), false);
        self.remap.clear();
        self.remap.extend(0..points.len());
        for t in idx.iter() {
            for k in t {
                self.used[*k as usize] = true;
            }
        }
        let mut i = 0;
        while i != points.len() {
            if !self.used[i] {
                let _ = points.swap_remove(i);
                self.remap[points.len()] = i;
                self.used[i] = self.used[points.len()];
            } else {
                i += 1;
            }
        }
        for t in idx.iter_mut() {
            for k in t.iter_mut() {
                *k = self.remap[*k as usize] as u32;
            }
        }
    }
}

/// The first of `idx`'s points farthest along `direction` (parry's `support_point_id`,
/// `indexed_support_point_id` and `indexed_support_point_nth` are this one loop): its position
/// in `idx` and its index, `None` when `idx` is empty.
fn support(
    direction: Vector3,
    points: &[Vector3],
    idx: impl Iterator<Item = usize>,
) -> Option<(usize, usize)> {
    let mut argmax = None;
    let mut max = -f64::MAX;
    for (k, i) in idx.enumerate() {
        let dot = direction.dot(points[i]);
        if dot > max {
            argmax = Some((k, i));
            max = dot;
        }
    }
    argmax
}

/// parry's own hull of `points` (`None` where it errs or panics).
#[cfg(test)]
pub(crate) fn parry_hull(points: &[Vector3]) -> Option<(Vec<Vector3>, Vec<[u32; 3]>)> {
    std::panic::catch_unwind(|| parry3d_f64::transformation::try_convex_hull(points))
        .ok()?
        .ok()
}

/// Panics unless `got` (this module's hull of `points`, `None` where it failed) is parry's
/// to the bit: the same vertex coordinates' bits in the same order, the same triangles.
#[cfg(test)]
pub(crate) fn assert_parry_agrees(points: &[Vector3], got: Option<&(Vec<Vector3>, Vec<[u32; 3]>)>) {
    let bits = |h: &(Vec<Vector3>, Vec<[u32; 3]>)| {
        let v: Vec<[u64; 3]> =
            h.0.iter()
                .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                .collect();
        (v, h.1.clone())
    };
    let want = parry_hull(points);
    assert_eq!(
        got.map(bits),
        want.as_ref().map(bits),
        "quickhull differs from parry on {points:?}"
    );
}

#[cfg(test)]
mod tests;
