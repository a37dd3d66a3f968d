//! The search's vertex resolution (issue #37, "decimate scans for the search only where the
//! result provably does not change beyond the tolerance"): the mesh's vertices clustered on a
//! grid, each standing for the lowest-numbered vertex of its cell, for the per-vertex work of
//! building a candidate part (the patch's distinct vertices and their farthest-point sampling,
//! see [`build_new_part`]). Triangles, the surface and every deviation stay the mesh's own.
//!
//! Entry point: [`representatives`].
//!
//! The bound: a vertex and its representative share a cell of edge `eps·diag`, so they lie
//! at most `eps·diag·√3` apart, and a hull spanned by representatives lies within that of the
//! hull the patch's own vertices would have spanned (every representative is a mesh vertex,
//! so it stays on the surface and the deviation's "hull vertex on the mesh" shortcut holds).
//! Measured (docs/speed.md, "Eighth stop"): at the eps that bound allows, far under the 1 %
//! tolerance, the scans' vertices are already further apart than a cell, and the clustering
//! merges almost nothing.

use super::*;
use std::collections::HashMap;
use std::sync::Arc;

/// Cell edge as a fraction of the object's diagonal; 0 = off. Read once from
/// `INTERACT3D_RESOLUTION` (a measurement knob of this stop, not an option).
pub(super) fn eps() -> f64 {
    static EPS: std::sync::OnceLock<f64> = std::sync::OnceLock::new();
    *EPS.get_or_init(|| {
        std::env::var("INTERACT3D_RESOLUTION")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(0.0)
    })
}

/// Only objects with at least this many vertices are clustered (the small ones are cheap):
/// 10,000, or `INTERACT3D_RESOLUTION_MIN` (a measurement knob).
pub(super) fn min_vertices() -> usize {
    static MIN: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *MIN.get_or_init(|| {
        std::env::var("INTERACT3D_RESOLUTION_MIN")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(10_000)
    })
}

/// Each vertex's representative: the lowest-numbered vertex in its grid cell (cells of edge
/// `eps·diag`, from the mesh's box's lower corner). `None` when `eps` is 0, the mesh has
/// fewer than [`min_vertices`] vertices, or no two vertices share a cell.
pub(super) fn representatives(s: &Surface, eps: f64) -> Option<Arc<[u32]>> {
    let m = &s.mesh;
    if eps <= 0.0 || m.vertices.len() < min_vertices() {
        return None;
    }
    let h = eps * s.diag;
    let lo = s.aabb.min;
    let mut first: HashMap<[i64; 3], u32> = HashMap::with_capacity(m.vertices.len());
    let mut merged = 0usize;
    let rep: Vec<u32> = m
        .vertices
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let c = [
                ((v.x - lo.x) / h).floor() as i64,
                ((v.y - lo.y) / h).floor() as i64,
                ((v.z - lo.z) / h).floor() as i64,
            ];
            let r = *first.entry(c).or_insert(i as u32);
            merged += usize::from(r != i as u32);
            r
        })
        .collect();
    (merged > 0).then(|| rep.into())
}
