//! Where an object's guidance may be missing for a physical reason: surface that the other
//! objects of the scene touch or hide. A fused scene mesh has no surface where two objects touch
//! (the fused skin is cut from both parts) and none where one object hides another (a pen's
//! lower half inside a mug). Such surface is within τ of a placed object's surface, or faces the
//! other objects from close by, so that most of the directions it could be seen from are
//! blocked by them. Its missing guidance is then no evidence against a pose, so the coverage
//! term ([`super::global::Fit::object_covered`]) leaves it out. Surface deeper than τ inside a
//! placed object is penetrating, not hidden, and stays in.
//!
//! The test is on directions, not on containment: a holey guidance part has no inside, and its
//! convex hull would swallow whatever sits in a bowl or a basket, visible or not. The blockers
//! are the placed meshes of the objects already composed (complete surfaces) and the guidance
//! parts of the others (holey, so they block less than they should).

use super::sdf::AnchorField;
use crate::mesh::{Aabb, P3, V3};
use std::sync::OnceLock;

/// Direction bins: 6 cube faces × 3 × 3 cells.
const BINS: usize = 54;

fn bin(d: &V3) -> usize {
    let a = d.abs();
    let k = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    let m = a[k];
    if m <= 0.0 {
        return 0;
    }
    let face = 2 * k + (d[k] < 0.0) as usize;
    let cell = |c: f64| (((c / m + 1.0) * 1.5) as usize).min(2);
    let (u, v) = (d[(k + 1) % 3], d[(k + 2) % 3]);
    face * 9 + cell(u) * 3 + cell(v)
}

/// The bins of the directions from `q` to `points` (a point at `q` itself has none).
fn mask_of(points: &[P3], q: &P3) -> u64 {
    let mut m = 0u64;
    for p in points {
        let d = p - q;
        if d.norm_squared() > 0.0 {
            m |= 1u64 << bin(&d);
        }
    }
    m
}

/// Every bin a direction `d` with `lo[k] <= d[k] <= hi[k]` may fall in (a superset; every bin
/// when the box reaches within 1e-100 of the origin). [`bin`] takes the face of the largest
/// |d_k|, which is at least the largest lower bound of the three and at most its own upper
/// bound; on that face each of the other two coordinates over it is least and largest at the
/// box's corners, and the rounded ratio, plus one, times 1.5 and truncated are monotone: the
/// cells between those of the least and the largest ratio.
fn box_bins(lo: &V3, hi: &V3) -> u64 {
    const ALL: u64 = (1u64 << BINS) - 1;
    let alo = V3::from_fn(|k, _| {
        if lo[k] > 0.0 {
            lo[k]
        } else if hi[k] < 0.0 {
            -hi[k]
        } else {
            0.0
        }
    });
    let ahi = V3::from_fn(|k, _| lo[k].abs().max(hi[k].abs()));
    let mlo = alo.max();
    // Far above underflow: every direction's squared norm is then positive (none is skipped).
    if !(mlo > 1e-100) {
        return ALL;
    }
    let cell = |c: f64| (((c + 1.0) * 1.5) as usize).min(2);
    let mut out = 0u64;
    for k in 0..3 {
        // |d_k| ≤ ahi[k] < alo[j] ≤ |d_j|: never the largest.
        if (0..3).any(|j| ahi[k] < alo[j]) {
            continue;
        }
        let mhi = ahi[k];
        let cells = |j: usize| {
            let least = if lo[j] < 0.0 {
                lo[j] / mlo
            } else {
                lo[j] / mhi
            };
            let most = if hi[j] < 0.0 {
                hi[j] / mhi
            } else {
                hi[j] / mlo
            };
            cell(least)..=cell(most)
        };
        let (u, v) = ((k + 1) % 3, (k + 2) % 3);
        for (face, possible) in [(2 * k, hi[k] >= 0.0), (2 * k + 1, lo[k] < 0.0)] {
            if !possible {
                continue;
            }
            for cu in cells(u) {
                for cv in cells(v) {
                    out |= 1u64 << (face * 9 + cu * 3 + cv);
                }
            }
        }
    }
    out
}

/// The blockers in a tree of boxes (median splits, leaves of a few points). A box whose
/// directions from a query may fall only in bins already set ([`box_bins`]) is skipped, and one
/// whose every direction falls in one bin sets it, without their points being read: the same
/// mask as binning every blocker ([`mask_of`]), the bins being OR-ed in any order. No tree when
/// a coordinate is not finite: every blocker is then binned one by one.
struct BlockerBoxes {
    /// The blockers, in tree order when there is a tree.
    points: Vec<P3>,
    /// (lo, hi, start, end, first child; 0 for a leaf); empty without a tree.
    nodes: Vec<(P3, P3, u32, u32, u32)>,
}

impl BlockerBoxes {
    const LEAF: usize = 8;

    fn new(blockers: Vec<P3>) -> BlockerBoxes {
        let finite = blockers.iter().all(|p| p.iter().all(|x| x.is_finite()));
        let mut t = BlockerBoxes {
            points: blockers,
            nodes: Vec::new(),
        };
        if finite && !t.points.is_empty() {
            t.nodes.push((P3::origin(), P3::origin(), 0, 0, 0));
            t.build(0, 0, t.points.len());
        }
        t
    }

    fn build(&mut self, node: usize, start: usize, end: usize) {
        let pts = &mut self.points[start..end];
        let (mut lo, mut hi) = (pts[0], pts[0]);
        for p in pts.iter() {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        self.nodes[node] = (lo, hi, start as u32, end as u32, 0);
        if end - start <= Self::LEAF {
            return;
        }
        let axis = (hi - lo).imax();
        let mid = (end - start) / 2;
        pts.select_nth_unstable_by(mid, |a, b| a[axis].total_cmp(&b[axis]));
        let left = self.nodes.len();
        self.nodes.push(self.nodes[node]);
        self.nodes.push(self.nodes[node]);
        self.nodes[node].4 = left as u32;
        self.build(left, start, start + mid);
        self.build(left + 1, start + mid, end);
    }

    fn mask_from(&self, q: &P3) -> u64 {
        if self.nodes.is_empty() {
            return mask_of(&self.points, q);
        }
        let mut m = 0u64;
        let mut stack = vec![0u32];
        while let Some(n) = stack.pop() {
            let (lo, hi, start, end, left) = self.nodes[n as usize];
            // The box relative to `q`, rounded as each point's `p - q` is (monotone).
            let bins = box_bins(&(lo - q), &(hi - q));
            if bins & !m == 0 {
                continue;
            }
            if bins.count_ones() == 1 {
                // Every point of the box (not empty, none at `q`) falls in this one bin.
                m |= bins;
            } else if left == 0 {
                m |= mask_of(&self.points[start as usize..end as usize], q);
            } else {
                stack.push(left);
                stack.push(left + 1);
            }
        }
        m
    }
}

fn bin_centres() -> [V3; BINS] {
    let mut out = [V3::zeros(); BINS];
    for (face, chunk) in out.chunks_mut(9).enumerate() {
        let k = face / 2;
        let s = if face % 2 == 0 { 1.0 } else { -1.0 };
        for (i, c) in chunk.iter_mut().enumerate() {
            let mut d = V3::zeros();
            d[k] = s;
            d[(k + 1) % 3] = (i / 3) as f64 * 2.0 / 3.0 - 2.0 / 3.0;
            d[(k + 2) % 3] = (i % 3) as f64 * 2.0 / 3.0 - 2.0 / 3.0;
            *c = d.normalize();
        }
    }
    out
}

/// The other objects of a scene as blockers, seen from the neighbourhood of one object: a
/// lazily filled grid of blocked-direction masks.
pub struct Occlusion<'a> {
    /// The blockers in boxes, for [`Occlusion::mask`].
    blockers: BlockerBoxes,
    /// The placed objects as solids: a point inside one, deeper than `tolerance`, is not hidden
    /// but penetrating, which explains nothing.
    solids: Option<(&'a AnchorField, f64)>,
    lo: P3,
    cell: f64,
    dims: [usize; 3],
    masks: Vec<OnceLock<u64>>,
    centres: [V3; BINS],
    /// Fraction of a point's outward half-sphere of directions that must be blocked.
    pub threshold: f64,
}

impl<'a> Occlusion<'a> {
    /// Blockers `blockers` (guidance frame), queried within `region` grown by `margin`, on
    /// cells of side `cell`.
    pub fn new(blockers: Vec<P3>, region: &Aabb, margin: f64, cell: f64) -> Occlusion<'a> {
        let lo = region.min - V3::repeat(margin);
        let ext = region.max - region.min + V3::repeat(2.0 * margin);
        let dims = [0, 1, 2].map(|k| ((ext[k] / cell).ceil() as usize).clamp(1, 200));
        let n = dims[0] * dims[1] * dims[2];
        Occlusion {
            blockers: BlockerBoxes::new(blockers),
            solids: None,
            lo,
            cell,
            dims,
            masks: (0..n).map(|_| OnceLock::new()).collect(),
            centres: bin_centres(),
            threshold: 0.6,
        }
    }

    /// Placed objects as solids (their signed distance), with a depth `tolerance`.
    pub fn with_solids(mut self, field: &'a AnchorField, tolerance: f64) -> Occlusion<'a> {
        self.solids = Some((field, tolerance));
        self
    }

    /// The directions blocked from the centre of `q`'s cell; `None` outside the grid.
    fn mask(&self, q: &P3) -> Option<u64> {
        let mut idx = [0usize; 3];
        for k in 0..3 {
            let f = (q[k] - self.lo[k]) / self.cell;
            if !(f >= 0.0 && f < self.dims[k] as f64) {
                return None;
            }
            idx[k] = f as usize;
        }
        let i = (idx[2] * self.dims[1] + idx[1]) * self.dims[0] + idx[0];
        Some(*self.masks[i].get_or_init(|| {
            let c = P3::new(
                self.lo.x + (idx[0] as f64 + 0.5) * self.cell,
                self.lo.y + (idx[1] as f64 + 0.5) * self.cell,
                self.lo.z + (idx[2] as f64 + 0.5) * self.cell,
            );
            self.blockers.mask_from(&c)
        }))
    }

    /// Is the surface point `q` with outward normal `n` hidden: within the depth tolerance of a
    /// placed object's surface (contact), or are at least `threshold` of the directions of its
    /// outward half-sphere blocked? Not when deeper inside a placed object (penetration).
    pub fn hidden(&self, q: &P3, n: &V3) -> bool {
        if let Some((f, tol)) = self.solids {
            let phi = f.eval(q).0;
            if phi < -tol {
                return false;
            }
            if phi < tol {
                return true;
            }
        }
        if self.blockers.points.is_empty() {
            return false;
        }
        let Some(m) = self.mask(q) else {
            return false;
        };
        let (mut seen, mut blocked) = (0u32, 0u32);
        for (b, c) in self.centres.iter().enumerate() {
            if c.dot(n) > 0.1 {
                seen += 1;
                blocked += ((m >> b) & 1) as u32;
            }
        }
        seen > 0 && blocked as f64 >= self.threshold * seen as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// The boxes give every query the mask of binning each blocker, bit for bit: random clouds
    /// (flat, like a plate, and spread), and an integer grid whose directions from grid and
    /// half-grid queries lie on the bins' borders (|x| = |y|, a ratio of exactly ±1/3) and hit
    /// blockers exactly (no direction).
    #[test]
    fn boxes_give_the_mask_of_every_blocker() {
        let mut rng = Rng::new(9);
        let flat: Vec<P3> = (0..3000)
            .map(|_| {
                P3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-0.02, 0.02),
                    rng.range(-1.0, 1.0),
                )
            })
            .collect();
        let spread: Vec<P3> = (0..2000)
            .map(|_| P3::new(rng.normal(), rng.normal() * 0.5, rng.normal() * 2.0))
            .collect();
        let mut grid = Vec::new();
        for x in -6..=6 {
            for y in -3..=3 {
                for z in -6..=6 {
                    grid.push(P3::new(x as f64, y as f64, z as f64));
                }
            }
        }
        let mut queries: Vec<P3> = (0..300)
            .map(|_| {
                P3::new(
                    rng.range(-3.0, 3.0),
                    rng.range(-1.0, 2.0),
                    rng.range(-3.0, 3.0),
                )
            })
            .collect();
        for x in -4..=4 {
            for z in -4..=4 {
                queries.push(P3::new(x as f64, 0.0, z as f64));
                queries.push(P3::new(x as f64 * 0.5, 1.5, z as f64 * 1.5));
            }
        }
        for set in [&flat, &spread, &grid] {
            let boxes = BlockerBoxes::new(set.clone());
            for q in &queries {
                assert_eq!(boxes.mask_from(q), mask_of(set, q), "{q:?}");
            }
        }
        // A box far off one face is one bin; one straddling a face's border two, each the bin
        // of one of its points; every bin of a box's points is among its bins.
        let (lo, hi) = (V3::new(5.0, -0.1, -0.1), V3::new(5.2, 0.1, 0.1));
        assert_eq!(box_bins(&lo, &hi), 1u64 << bin(&V3::new(5.1, 0.0, 0.0)));
        let (lo, hi) = (V3::new(5.0, 4.9, 0.0), V3::new(5.2, 5.1, 0.1));
        let two = (1u64 << bin(&V3::new(5.2, 4.9, 0.05))) | (1u64 << bin(&V3::new(5.0, 5.1, 0.05)));
        assert_eq!(box_bins(&lo, &hi), two);
        for _ in 0..2000 {
            let c = V3::new(rng.normal(), rng.normal(), rng.normal());
            let h = V3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * 0.5;
            let bins = box_bins(&(c - h), &(c + h));
            for _ in 0..20 {
                let d = c + h.component_mul(&V3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                ));
                assert!(
                    d.norm_squared() == 0.0 || bins >> bin(&d) & 1 == 1,
                    "{c:?} {h:?} {d:?}"
                );
            }
        }
        // A blocker that is not finite: no tree, every blocker binned one by one.
        let odd = vec![P3::new(f64::NAN, 0.0, 0.0), P3::new(1.0, 0.0, 0.0)];
        let boxes = BlockerBoxes::new(odd.clone());
        assert!(boxes.nodes.is_empty());
        assert_eq!(boxes.mask_from(&P3::origin()), mask_of(&odd, &P3::origin()));
    }

    #[test]
    fn bins_cover_the_sphere_and_match_their_centres() {
        let c = bin_centres();
        for (b, d) in c.iter().enumerate() {
            assert_eq!(bin(d), b);
        }
    }

    #[test]
    fn a_point_in_a_cup_is_hidden_sideways_and_seen_from_above() {
        // An open cylinder (walls and floor, radius 1, height 2) of blockers.
        let mut pts = Vec::new();
        for i in 0..60 {
            let a = i as f64 / 60.0 * std::f64::consts::TAU;
            for h in 0..20 {
                pts.push(P3::new(a.cos(), h as f64 * 0.1, a.sin()));
            }
            for r in 1..10 {
                pts.push(P3::new(
                    0.1 * r as f64 * a.cos(),
                    0.0,
                    0.1 * r as f64 * a.sin(),
                ));
            }
        }
        let region = Aabb {
            min: P3::new(-1.0, 0.0, -1.0),
            max: P3::new(1.0, 2.0, 1.0),
        };
        let o = Occlusion::new(pts, &region, 0.5, 0.05);
        // Low inside, facing the wall: hidden; facing up too (the walls block all but a cone
        // of 32° half-angle). Near the rim, facing up: seen.
        assert!(o.hidden(&P3::new(0.0, 0.3, 0.0), &V3::x()));
        assert!(o.hidden(&P3::new(0.0, 0.3, 0.0), &V3::y()));
        assert!(!o.hidden(&P3::new(0.0, 1.7, 0.0), &V3::y()));
        // Outside the cup, facing away: seen.
        assert!(!o.hidden(&P3::new(1.3, 0.3, 0.0), &V3::x()));
    }
}
