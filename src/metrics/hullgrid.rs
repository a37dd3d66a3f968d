//! Inside-ness of a hull set through a uniform grid of cells, each cell resolved once at
//! preparation: inside some hull, outside every hull, or the few (hull, face plane) tests its
//! points still need. The answers are those of `hulls.iter().any(|h| h.contains(p))` bit for
//! bit, not approximately.
//!
//! Entry points: [`HullGrid::new`], [`HullGrid::contains`], and for the points of one
//! axis-parallel column [`HullGrid::column`] then [`HullGrid::contains_in`].
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
//!
//! Each hull's cells are resolved by bisection from its box's cells: a node's verdict on a
//! plane holds for its children (their widened boxes lie in the node's), so a node only looks
//! at the planes that cross its parent, and nodes outside a hull or inside it are not split.
//! The entries are gathered as flat records and put in cell order by counting.

use super::bvh::Bb;
use super::geom::{self, V};
use super::inside::Hull;

/// Blocks of the grid, about; shaped like the box (the grid has `SUB` cells a block along each
/// axis with an extent). The resolution the queries see; unchanged by the bisection build.
const TARGET_BLOCKS: f64 = 8192.0;
/// Cells per block along each axis with an extent.
const SUB: usize = 2;

/// What the points of one cell still need from one hull: its box test (`bbx`, an index into
/// [`HullGrid::boxes`], or [`NO_BOX`] when the cell lies inside that box) and the planes
/// `planes[start..end]` (copies, contiguous per entry).
#[derive(Clone, Copy, Debug)]
struct Entry {
    bbx: u32,
    start: u32,
    end: u32,
}

/// [`Entry::bbx`] of an entry whose cell lies inside its hull's box.
const NO_BOX: u32 = u32::MAX;

#[derive(Clone, Debug)]
pub struct HullGrid {
    bb: Bb,
    dims: [usize; 3],
    /// Index step of one cell along each axis.
    stride: [usize; 3],
    inv_cell: [f64; 3],
    /// Every point of the cell is inside some hull.
    inside: Vec<bool>,
    /// CSR: the entries of cell c are `entries[first[c]..first[c + 1]]`.
    first: Vec<u32>,
    entries: Vec<Entry>,
    planes: Vec<(V, f64)>,
    /// The hulls' bounding boxes, by hull index.
    boxes: Vec<Bb>,
}

/// The cells of one column: the index of its first cell and the axis it runs along.
#[derive(Clone, Copy, Debug)]
pub struct Column {
    axis: usize,
    offset: usize,
}

/// A box's verdict on a face plane `n·p <= d`, with the margin `m`: every point of the box
/// passes (`Some(true)`), every point fails (`Some(false)`), or undecided.
#[inline]
fn box_vs_plane(cen: V, half: V, n: V, d: f64, m: f64) -> Option<bool> {
    let mid = geom::dot(n, cen);
    let r = n[0].abs() * half[0] + n[1].abs() * half[1] + n[2].abs() * half[2];
    if mid - r > d + m {
        Some(false)
    } else if mid + r <= d - m {
        Some(true)
    } else {
        None
    }
}

/// The build's state for one hull's bisection: the grid's geometry, where records go, and a
/// stack of the planes each open node still has undecided.
struct Build<'a> {
    bb: Bb,
    cell_w: [f64; 3],
    stride: [usize; 3],
    m: f64,
    hull: &'a Hull,
    hx: u32,
    inside: &'a mut Vec<bool>,
    /// (cell, entry) in the order found; planes of the entries in `planes`.
    recs: &'a mut Vec<(u32, Entry)>,
    planes: &'a mut Vec<(V, f64)>,
    /// Undecided planes of the nodes on the current path, each node's after its parent's.
    stack: Vec<(V, f64)>,
}

impl Build<'_> {
    /// The widened box of the cells [a, b) along each axis, as low and high corners, centre
    /// and half extents.
    fn span(&self, a: [usize; 3], b: [usize; 3]) -> (V, V, V, V) {
        let lo = [0, 1, 2].map(|k| self.bb.min[k] + a[k] as f64 * self.cell_w[k] - self.m);
        let hi = [0, 1, 2].map(|k| self.bb.min[k] + b[k] as f64 * self.cell_w[k] + self.m);
        let cen = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
        let half = [0, 1, 2].map(|k| 0.5 * (hi[k] - lo[k]));
        (lo, hi, cen, half)
    }

    /// The node of cells [a, b) (b exclusive), whose parent left `stack[from..]` undecided:
    /// dropped when outside some plane, marked inside when inside every plane and the hull's
    /// box, a record when it is one cell, and otherwise split at the middle of every side longer
    /// than one cell.
    /// A child's widened box lies in its parent's, so a parent's verdict on a plane holds for
    /// its children.
    fn node(&mut self, a: [usize; 3], b: [usize; 3], from: usize) {
        let (lo, hi, cen, half) = self.span(a, b);
        let to = self.stack.len();
        for i in from..to {
            let (nrm, d) = self.stack[i];
            match box_vs_plane(cen, half, nrm, d, self.m) {
                Some(false) => {
                    self.stack.truncate(to);
                    return;
                }
                Some(true) => {}
                None => self.stack.push((nrm, d)),
            }
        }
        let bb = &self.hull.bb;
        let in_bb = (0..3).all(|k| bb.min[k] <= lo[k] && hi[k] <= bb.max[k]);
        let one = (0..3).all(|k| b[k] == a[k] + 1);
        if self.stack.len() == to && in_bb {
            for i2 in a[2]..b[2] {
                for i1 in a[1]..b[1] {
                    for i0 in a[0]..b[0] {
                        self.inside[i0 + i1 * self.stride[1] + i2 * self.stride[2]] = true;
                    }
                }
            }
        } else if one {
            let c = a[0] + a[1] * self.stride[1] + a[2] * self.stride[2];
            if !self.inside[c] {
                let start = self.planes.len() as u32;
                self.planes.extend_from_slice(&self.stack[to..]);
                let bbx = if in_bb { NO_BOX } else { self.hx };
                let end = self.planes.len() as u32;
                self.recs.push((c as u32, Entry { bbx, start, end }));
            }
        } else {
            // Split every side of two cells or more at its middle (up to eight children).
            let mid = [0, 1, 2].map(|k| a[k] + (b[k] - a[k]) / 2);
            let halves = [0, 1, 2].map(|k| {
                if b[k] - a[k] >= 2 {
                    [(a[k], mid[k]), (mid[k], b[k])]
                } else {
                    [(a[k], b[k]), (b[k], b[k])]
                }
            });
            for &(a2, b2) in &halves[2] {
                for &(a1, b1) in &halves[1] {
                    for &(a0, b0) in &halves[0] {
                        if a0 < b0 && a1 < b1 && a2 < b2 {
                            self.node([a0, a1, a2], [b0, b1, b2], to);
                        }
                    }
                }
            }
        }
        self.stack.truncate(to);
    }
}

impl HullGrid {
    /// The grid over the union of the hulls' boxes; `None` when that box is empty or not
    /// finite.
    ///
    /// Each hull is bisected from the cells of its box down to single cells, only where its
    /// boundary crosses: a node outside a face plane is dropped, a node inside the hull marks
    /// its cells inside, and a node's children only test the planes it left undecided. The
    /// cells' entries are found as flat records, then put in cell order (no vector per cell).
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
        // Blocks shaped like the box: side = (volume / target)^(1/3), flat axes one cell.
        let live: Vec<f64> = ext.iter().copied().filter(|&e| e > 0.0).collect();
        let side = if live.is_empty() {
            1.0
        } else {
            let vol: f64 = live.iter().product();
            (vol / TARGET_BLOCKS).powf(1.0 / live.len() as f64)
        };
        let sub = ext.map(|e| if e > 0.0 { SUB } else { 1 });
        let blocks = ext.map(|e| {
            if e > 0.0 {
                ((e / side).round() as usize).clamp(1, 64)
            } else {
                1
            }
        });
        let dims = [0, 1, 2].map(|k| blocks[k] * sub[k]);
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
            stride: [1, dims[0], dims[0] * dims[1]],
            inv_cell,
            inside: vec![false; n],
            first: Vec::new(),
            entries: Vec::new(),
            planes: Vec::new(),
            boxes: hulls.iter().map(|h| h.bb).collect(),
        };
        let cell_w = [0, 1, 2].map(|k| ext[k] / dims[k] as f64);
        let mut recs: Vec<(u32, Entry)> = Vec::new();
        let mut planes: Vec<(V, f64)> = Vec::new();
        let mut stack: Vec<(V, f64)> = Vec::new();
        for (hx, h) in hulls.iter().enumerate() {
            // The cells that can hold a point of the hull's box.
            let lo_i = [0, 1, 2].map(|k| g.cell(k, h.bb.min[k]));
            let hi_i = [0, 1, 2].map(|k| g.cell(k, h.bb.max[k]) + 1);
            stack.clear();
            stack.extend_from_slice(&h.planes);
            let mut b = Build {
                bb,
                cell_w,
                stride: g.stride,
                m,
                hull: h,
                hx: hx as u32,
                inside: &mut g.inside,
                recs: &mut recs,
                planes: &mut planes,
                stack: std::mem::take(&mut stack),
            };
            b.node(lo_i, hi_i, 0);
            stack = b.stack;
        }
        // Records of cells found inside a later hull are dropped; the rest are put in cell
        // order by counting (stable: a cell's entries keep the hulls' order).
        let mut first = vec![0u32; n + 1];
        for &(c, _) in &recs {
            if !g.inside[c as usize] {
                first[c as usize + 1] += 1;
            }
        }
        for c in 0..n {
            first[c + 1] += first[c];
        }
        let mut next = first.clone();
        let none = Entry {
            bbx: NO_BOX,
            start: 0,
            end: 0,
        };
        let mut entries = vec![none; first[n] as usize];
        for (c, e) in recs {
            if !g.inside[c as usize] {
                let slot = &mut next[c as usize];
                entries[*slot as usize] = e;
                *slot += 1;
            }
        }
        g.first = first;
        g.entries = entries;
        g.planes = planes;
        Some(g)
    }

    /// Index along axis k of the cell holding coordinate x (clamped to the grid): monotone
    /// non-decreasing in x. `as` truncates: `floor` for the values >= 1 it sees, inlined.
    #[inline]
    fn cell(&self, k: usize, x: f64) -> usize {
        let f = (x - self.bb.min[k]) * self.inv_cell[k];
        if !(f >= 1.0) {
            0
        } else {
            (f as usize).min(self.dims[k] - 1)
        }
    }

    /// The verdict of cell `c` on `p`, a point filed under it.
    #[inline]
    fn resolve(&self, c: usize, p: V) -> bool {
        if self.inside[c] {
            return true;
        }
        self.entries[self.first[c] as usize..self.first[c + 1] as usize]
            .iter()
            .any(|e| {
                (e.bbx == NO_BOX || self.boxes[e.bbx as usize].contains(p))
                    && self.planes[e.start as usize..e.end as usize]
                        .iter()
                        .all(|(n, d)| geom::dot(*n, p) <= *d)
            })
    }

    /// Exactly `hulls.iter().any(|h| h.contains(p))` for the hulls the grid was built from.
    #[inline]
    pub fn contains(&self, p: V) -> bool {
        if !self.bb.contains(p) {
            return false;
        }
        let c = (0..3).map(|k| self.cell(k, p[k]) * self.stride[k]).sum();
        self.resolve(c, p)
    }

    /// The column of points `base` with `base[axis]` replaced; `None` when it misses the grid
    /// (no point of it is inside any hull).
    #[inline]
    pub fn column(&self, axis: usize, base: V) -> Option<Column> {
        let mut offset = 0;
        for k in [(axis + 1) % 3, (axis + 2) % 3] {
            if !(self.bb.min[k] <= base[k] && base[k] <= self.bb.max[k]) {
                return None;
            }
            offset += self.cell(k, base[k]) * self.stride[k];
        }
        Some(Column { axis, offset })
    }

    /// [`HullGrid::contains`] of `p`, a point of the column `col` (the same answer).
    #[inline]
    pub fn contains_in(&self, col: Column, p: V) -> bool {
        let t = p[col.axis];
        if !(self.bb.min[col.axis] <= t && t <= self.bb.max[col.axis]) {
            return false;
        }
        self.resolve(
            col.offset + self.cell(col.axis, t) * self.stride[col.axis],
            p,
        )
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
            assert_eq!(g.contains(*p), want, "at {p:?}");
            for axis in 0..3 {
                let via_column = g.column(axis, *p).is_some_and(|c| g.contains_in(c, *p));
                assert_eq!(via_column, want, "at {p:?} along {axis}");
            }
            inside += want as usize;
        }
        // Both answers occur in quantity (the comparison is not vacuous).
        assert!(inside > 10_000 && inside < pts.len() - 10_000, "{inside}");
    }
}
