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
    blockers: Vec<P3>,
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
            blockers,
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

    fn mask_from(&self, q: &P3) -> u64 {
        let mut m = 0u64;
        for p in &self.blockers {
            let d = p - q;
            if d.norm_squared() > 0.0 {
                m |= 1u64 << bin(&d);
            }
        }
        m
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
            self.mask_from(&c)
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
        if self.blockers.is_empty() {
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
