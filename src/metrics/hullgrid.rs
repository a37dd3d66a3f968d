//! Inside-ness of a hull set through a uniform grid of cells, each cell resolved once at
//! preparation: inside some hull, outside every hull, or the few (hull, face plane) tests its
//! points still need. The answers are those of `hulls.iter().any(|h| h.contains(p))` bit for
//! bit, not approximately.
//!
//! Entry points: [`HullGrid::new`], [`HullGrid::contains`].
//!
//! # Why the answers are the same
//! [`Hull::contains`] is `bb.contains(p) && planes.all(|(n, d)| dot(n, p) <= d)` in f64. A cell
//! drops a plane test (or a whole hull) only when its conclusion holds with a margin `m` for
//! every point of the cell's box widened by `m`:
//! * a face plane with `max over the box of n·x <= d - m` is passed by every point of the box;
//! * one with `min over the box of n·x > d + m` fails every point of it, so the hull is out;
//! * a box inside the hull's bounding box (exact comparisons) passes its box test.
//!
//! `m` is 10⁻⁹ of the grid's largest coordinate (plus 10⁻⁹ m), while every rounding involved
//! (the f64 `dot` of the test, the box extremes, the cell index a point is filed under) is below
//! 10⁻¹⁵ of it: the computed test cannot come out differently from the exact one the margin
//! decides. Which cells a hull can touch comes from the cell index of its box's corners; the
//! index is monotone in the coordinate, so a point inside a hull's box is never filed outside
//! that range. The tests `any` and `all` do not depend on order, so the grid may test the kept
//! planes in any order. A grid whose box is not finite is not built (the caller tests every
//! hull).

use super::bvh::Bb;
use super::geom::{self, V};
use super::inside::Hull;

/// Cells of the grid, about; shaped like the box. Resolving a cell costs one pass over the
/// planes of each hull whose box it meets, so this bounds the preparation.
const TARGET_CELLS: f64 = 8192.0;

/// What the points of one cell still need: the hull's box test (unless the cell is inside
/// it) and its planes `planes[start..end]` (copies, contiguous per cell).
#[derive(Clone, Debug)]
struct Entry {
    hull: u32,
    check_bb: bool,
    start: u32,
    end: u32,
}

#[derive(Clone, Debug)]
pub struct HullGrid {
    bb: Bb,
    dims: [usize; 3],
    inv_cell: [f64; 3],
    /// Every point of the cell is inside some hull.
    inside: Vec<bool>,
    /// CSR: the entries of cell c are `entries[first[c]..first[c + 1]]`.
    first: Vec<u32>,
    entries: Vec<Entry>,
    planes: Vec<(V, f64)>,
}

impl HullGrid {
    /// The grid over the union of the hulls' boxes; `None` when that box is empty or not
    /// finite.
    pub fn new(hulls: &[Hull]) -> Option<HullGrid> {
        let mut bb = Bb::EMPTY;
        for h in hulls {
            bb = bb.merge(&h.bb);
        }
        if !(bb.min.iter().chain(&bb.max).all(|x| x.is_finite())) || hulls.is_empty() {
            return None;
        }
        let ext = geom::sub(bb.max, bb.min);
        let scale = bb
            .min
            .iter()
            .chain(&bb.max)
            .fold(0.0f64, |s, x| s.max(x.abs()));
        let m = 1e-9 * (1.0 + scale);
        // Cells shaped like the box: side = (volume / target)^(1/3), flat axes one cell.
        let live: Vec<f64> = ext.iter().copied().filter(|&e| e > 0.0).collect();
        let side = if live.is_empty() {
            1.0
        } else {
            let vol: f64 = live.iter().product();
            (vol / TARGET_CELLS).powf(1.0 / live.len() as f64)
        };
        let dims = ext.map(|e| {
            if e > 0.0 {
                ((e / side).round() as usize).clamp(1, 64)
            } else {
                1
            }
        });
        let inv_cell = [0, 1, 2].map(|k| {
            if ext[k] > 0.0 {
                dims[k] as f64 / ext[k]
            } else {
                0.0
            }
        });
        let n = dims[0] * dims[1] * dims[2];
        let mut g = HullGrid {
            bb,
            dims,
            inv_cell,
            inside: vec![false; n],
            first: Vec::new(),
            entries: Vec::new(),
            planes: Vec::new(),
        };
        let cell_w = [0, 1, 2].map(|k| ext[k] / dims[k] as f64);
        // Entries per cell while building, then flattened in cell order.
        let mut per_cell: Vec<Vec<(u32, bool, Vec<(V, f64)>)>> = vec![Vec::new(); n];
        let mut kept: Vec<(V, f64)> = Vec::new();
        for (hx, h) in hulls.iter().enumerate() {
            if h.planes.is_empty() && h.verts.is_empty() {
                continue;
            }
            let lo_i = [0, 1, 2].map(|k| g.cell(k, h.bb.min[k]));
            let hi_i = [0, 1, 2].map(|k| g.cell(k, h.bb.max[k]));
            for i2 in lo_i[2]..=hi_i[2] {
                for i1 in lo_i[1]..=hi_i[1] {
                    for i0 in lo_i[0]..=hi_i[0] {
                        let c = (i2 * dims[1] + i1) * dims[0] + i0;
                        if g.inside[c] {
                            continue;
                        }
                        let idx = [i0, i1, i2];
                        let lo = [0, 1, 2].map(|k| bb.min[k] + idx[k] as f64 * cell_w[k] - m);
                        let hi = [0, 1, 2].map(|k| bb.min[k] + (idx[k] + 1) as f64 * cell_w[k] + m);
                        let cen = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
                        let half = [0, 1, 2].map(|k| 0.5 * (hi[k] - lo[k]));
                        kept.clear();
                        let mut out = false;
                        for &(nrm, d) in &h.planes {
                            let mid = geom::dot(nrm, cen);
                            let r = nrm[0].abs() * half[0]
                                + nrm[1].abs() * half[1]
                                + nrm[2].abs() * half[2];
                            if mid - r > d + m {
                                out = true;
                                break;
                            }
                            if !(mid + r <= d - m) {
                                kept.push((nrm, d));
                            }
                        }
                        if out {
                            continue;
                        }
                        let in_bb = (0..3).all(|k| h.bb.min[k] <= lo[k] && hi[k] <= h.bb.max[k]);
                        if kept.is_empty() && in_bb {
                            g.inside[c] = true;
                            per_cell[c].clear();
                        } else {
                            per_cell[c].push((hx as u32, !in_bb, kept.clone()));
                        }
                    }
                }
            }
        }
        g.first.reserve(n + 1);
        g.first.push(0);
        for (c, list) in per_cell.into_iter().enumerate() {
            if !g.inside[c] {
                for (hull, check_bb, ps) in list {
                    let start = g.planes.len() as u32;
                    g.planes.extend(ps);
                    g.entries.push(Entry {
                        hull,
                        check_bb,
                        start,
                        end: g.planes.len() as u32,
                    });
                }
            }
            g.first.push(g.entries.len() as u32);
        }
        Some(g)
    }

    /// Index along axis k of the cell holding coordinate x (clamped to the grid): monotone
    /// non-decreasing in x.
    #[inline]
    fn cell(&self, k: usize, x: f64) -> usize {
        let f = ((x - self.bb.min[k]) * self.inv_cell[k]).floor();
        if f <= 0.0 {
            0
        } else {
            (f as usize).min(self.dims[k] - 1)
        }
    }

    /// Exactly `hulls.iter().any(|h| h.contains(p))` for the hulls the grid was built from.
    #[inline]
    pub fn contains(&self, hulls: &[Hull], p: V) -> bool {
        if !self.bb.contains(p) {
            return false;
        }
        let c = (self.cell(2, p[2]) * self.dims[1] + self.cell(1, p[1])) * self.dims[0]
            + self.cell(0, p[0]);
        if self.inside[c] {
            return true;
        }
        self.entries[self.first[c] as usize..self.first[c + 1] as usize]
            .iter()
            .any(|e| {
                (!e.check_bb || hulls[e.hull as usize].bb.contains(p))
                    && self.planes[e.start as usize..e.end as usize]
                        .iter()
                        .all(|(n, d)| geom::dot(*n, p) <= *d)
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A convex hull of `pts` by brute force (every triple whose plane has all points on one
    /// side), enough for a few dozen points in general position.
    fn brute_hull(pts: &[V]) -> Hull {
        let mut tris = Vec::new();
        let n = pts.len();
        for i in 0..n {
            for j in i + 1..n {
                for k in j + 1..n {
                    let nrm = geom::cross(geom::sub(pts[j], pts[i]), geom::sub(pts[k], pts[i]));
                    let s: Vec<f64> = pts
                        .iter()
                        .map(|p| geom::dot(nrm, geom::sub(*p, pts[i])))
                        .collect();
                    if s.iter().all(|&x| x <= 0.0) {
                        tris.push([i as u32, j as u32, k as u32]);
                    } else if s.iter().all(|&x| x >= 0.0) {
                        tris.push([i as u32, k as u32, j as u32]);
                    }
                }
            }
        }
        Hull::new(pts.to_vec(), &tris)
    }

    /// The grid against the direct test on random points, points solved onto face planes and
    /// nudged one ulp either way, and hull vertices: a single differing answer fails.
    #[test]
    fn grid_answers_exactly_as_the_hulls() {
        let mut rng = crate::rng::Rng(0x5EED_6A1D);
        let mut hulls = Vec::new();
        for h in 0..12 {
            let c = [
                rng.next_f64() * 0.3,
                rng.next_f64() * 0.2,
                0.5 + rng.next_f64() * 0.1,
            ];
            let r = 0.02 + 0.08 * rng.next_f64() * (1 + h % 3) as f64;
            let pts: Vec<V> = (0..14)
                .map(|_| {
                    let u = [0, 1, 2].map(|_| rng.next_f64() * 2.0 - 1.0);
                    let l = geom::norm2(u).sqrt().max(1e-3);
                    // Flattened along one axis for some: thin hulls like a bowl's wall.
                    let f = if h % 4 == 0 {
                        [1.0, 1.0, 0.05]
                    } else {
                        [1.0; 3]
                    };
                    [0, 1, 2].map(|k| c[k] + r * f[k] * u[k] / l)
                })
                .collect();
            hulls.push(brute_hull(&pts));
        }
        let g = HullGrid::new(&hulls).unwrap();
        assert!(g.inside.iter().any(|&x| x), "no cell resolved inside");
        let direct = |p: V| hulls.iter().any(|h| h.contains(p));
        let mut pts: Vec<V> = Vec::new();
        let (lo, hi) = (g.bb.min, g.bb.max);
        for _ in 0..200_000 {
            pts.push([0, 1, 2].map(|k| lo[k] - 0.01 + (hi[k] - lo[k] + 0.02) * rng.next_f64()));
        }
        for h in &hulls {
            pts.extend(h.verts.iter().copied());
            for &(n, d) in &h.planes {
                for _ in 0..50 {
                    // A point on the plane: random (x, y), z solved (n has some z) or the
                    // largest component solved.
                    let k = (0..3)
                        .max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
                        .unwrap();
                    let mut p = [0, 1, 2].map(|j| lo[j] + (hi[j] - lo[j]) * rng.next_f64());
                    p[k] = 0.0;
                    p[k] = (d - geom::dot(n, p)) / n[k];
                    for s in [-1.0, 0.0, 1.0] {
                        let mut q = p;
                        q[k] = if s == 0.0 {
                            p[k]
                        } else {
                            f64::from_bits((p[k].to_bits() as i64 + s as i64) as u64)
                        };
                        pts.push(q);
                    }
                }
            }
        }
        let mut inside = 0;
        for p in &pts {
            let want = direct(*p);
            assert_eq!(g.contains(&hulls, *p), want, "at {p:?}");
            inside += want as usize;
        }
        // Both answers occur in quantity (the comparison is not vacuous).
        assert!(inside > 10_000 && inside < pts.len() - 10_000, "{inside}");
    }
}
