//! The pieces of a hull's face outside the other hulls, for [`super::union_boundary`]: the
//! face's convex polygons clipped hull by hull, kept in flat buffers that one worker reuses
//! from face to face.
//!
//! Entry point: [`Pieces::outside`].

use crate::decompose::Hull;
use crate::mesh::{Aabb, P3, V3};

/// Convex polygons one after another: polygon `i` is `pts[ends[i - 1]..ends[i]]`.
#[derive(Default)]
struct Polys {
    pts: Vec<P3>,
    ends: Vec<usize>,
}

impl Polys {
    fn clear(&mut self) {
        self.pts.clear();
        self.ends.clear();
    }

    fn len(&self) -> usize {
        self.ends.len()
    }

    fn get(&self, i: usize) -> &[P3] {
        let start = if i == 0 { 0 } else { self.ends[i - 1] };
        &self.pts[start..self.ends[i]]
    }

    fn push(&mut self, poly: &[P3]) {
        self.pts.extend_from_slice(poly);
        self.ends.push(self.pts.len());
    }
}

/// One worker's buffers. A vector per polygon and per clip, as first written, was 1.9 million
/// allocations on the two objects of `00003_marker_mug`, and the clipping 19 % of that scene's
/// instructions; the arithmetic here is the same, in the same order, so the pieces are the
/// same to the bit.
#[derive(Default)]
pub(super) struct Pieces {
    cur: Polys,
    next: Polys,
    rest: Vec<P3>,
    tmp: Vec<P3>,
}

impl Pieces {
    /// The parts of the triangle `tri` of hull `me` outside every hull of `others` (each with
    /// its index) grown by `eps`, as convex polygons, each handed to `emit` in turn: beyond
    /// each hull's plane k and within its planes before k, hull after hull (none when the
    /// triangle lies inside; the triangle itself when no hull reaches it). A face `tri` shares
    /// with a later hull, facing the same way, is outer surface and kept here (see
    /// [`shared_face_plane`]).
    pub(super) fn outside(
        &mut self,
        tri: [P3; 3],
        others: &[(usize, &Hull)],
        me: usize,
        eps: f64,
        mut emit: impl FnMut(&[P3]),
    ) {
        let Pieces {
            cur,
            next,
            rest,
            tmp,
        } = self;
        cur.clear();
        cur.push(&tri);
        for &(j, g) in others {
            let own = if j > me {
                shared_face_plane(&tri, g, eps)
            } else {
                None
            };
            next.clear();
            for i in 0..cur.len() {
                outside_of(cur.get(i), g, eps, own, next, rest, tmp);
            }
            std::mem::swap(cur, next);
            if cur.len() == 0 {
                break;
            }
        }
        for i in 0..cur.len() {
            emit(cur.get(i));
        }
    }
}

/// The face plane of `g` (its index) that the triangle `tri` lies in (within `eps`) and faces
/// the same way as, if any: where the two faces coincide, both are outer surface, and only
/// one of the two hulls may give it up to the other.
fn shared_face_plane(tri: &[P3; 3], g: &Hull, eps: f64) -> Option<usize> {
    let n = (tri[1] - tri[0])
        .cross(&(tri[2] - tri[0]))
        .try_normalize(0.0)?;
    g.planes.iter().position(|(m, d)| {
        m.dot(&n) > 1.0 - 1e-9 && tri.iter().all(|p| (m.dot(&p.coords) - d).abs() <= eps)
    })
}

/// Appends to `out` the parts of the convex polygon `poly` outside `g` grown by `eps`, as
/// convex polygons (nothing when it lies inside; `poly` itself when one face plane has it all
/// beyond). Face plane `own` of `g` (one `poly` lies in, see [`shared_face_plane`]) is shrunk
/// by `eps` instead: `poly` is beyond it, and kept whole. `rest` and `tmp` are scratch.
fn outside_of(
    poly: &[P3],
    g: &Hull,
    eps: f64,
    own: Option<usize>,
    out: &mut Polys,
    rest: &mut Vec<P3>,
    tmp: &mut Vec<P3>,
) {
    let Some(b) = Aabb::of_points(poly) else {
        return;
    };
    let grow = |k: usize| if own == Some(k) { -eps } else { eps };
    if !g.aabb.intersects(&b, eps)
        || g.planes
            .iter()
            .enumerate()
            .any(|(k, (n, d))| poly.iter().all(|p| n.dot(&p.coords) - d > grow(k)))
    {
        out.push(poly);
        return;
    }
    // Beyond plane k and within the planes before it: disjoint pieces whose union is the
    // polygon less the grown hull.
    rest.clear();
    rest.extend_from_slice(poly);
    for (k, (n, d)) in g.planes.iter().enumerate() {
        let off = d + grow(k);
        let start = out.pts.len();
        tmp.clear();
        clip_both(rest, n, off, &mut out.pts, tmp);
        if out.pts.len() - start >= 3 {
            out.ends.push(out.pts.len());
        } else {
            out.pts.truncate(start);
        }
        std::mem::swap(rest, tmp);
        if rest.len() < 3 {
            break;
        }
    }
}

/// Sutherland–Hodgman, both halves in one pass: appends to `beyond` the part of the convex
/// polygon `poly` with `n·x >= off` and to `within` the part with `n·x <= off`. Each vertex's
/// side `n·x - off` is computed once (it was four times: two clips, each reading both ends of
/// every edge); each half is then built from the same values by the same expressions, in the
/// same order, as when clipped apart, so the pieces are the same to the bit (issue #37).
fn clip_both(poly: &[P3], n: &V3, off: f64, beyond: &mut Vec<P3>, within: &mut Vec<P3>) {
    const SMALL: usize = 16;
    let mut few = [0.0f64; SMALL];
    let mut many = Vec::new();
    let side: &mut [f64] = if poly.len() <= SMALL {
        &mut few[..poly.len()]
    } else {
        many.resize(poly.len(), 0.0);
        &mut many
    };
    for (s, p) in side.iter_mut().zip(poly) {
        *s = n.dot(&p.coords) - off;
    }
    for k in 0..poly.len() {
        let l = (k + 1) % poly.len();
        let (a, b) = (poly[k], poly[l]);
        for (out, sa, sb) in [
            (&mut *beyond, side[k], side[l]),
            (&mut *within, -side[k], -side[l]),
        ] {
            if sa >= 0.0 {
                out.push(a);
            }
            if (sa >= 0.0) != (sb >= 0.0) {
                let t = sa / (sa - sb);
                out.push(a + (b - a) * t);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one-pass clip gives both halves of the two clips it replaced, bit for bit: on
    /// random polygons (up to 40 corners, beyond the stack buffer), planes through corners
    /// (sides exactly 0) included.
    #[test]
    fn clip_both_is_two_half_clips() {
        fn clip_half(poly: &[P3], n: &V3, off: f64, below: bool, out: &mut Vec<P3>) {
            let side = |p: &P3| {
                let s = n.dot(&p.coords) - off;
                if below {
                    -s
                } else {
                    s
                }
            };
            for k in 0..poly.len() {
                let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                let (sa, sb) = (side(&a), side(&b));
                if sa >= 0.0 {
                    out.push(a);
                }
                if (sa >= 0.0) != (sb >= 0.0) {
                    let t = sa / (sa - sb);
                    out.push(a + (b - a) * t);
                }
            }
        }
        let bits = |v: &[P3]| {
            v.iter()
                .flat_map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                .collect::<Vec<_>>()
        };
        let mut rng = crate::rng::Rng::new(9);
        let mut cut = 0;
        for round in 0..2000 {
            let m = 3 + round % 38;
            // A convex polygon: points on an ellipse in a tilted plane, in angle order.
            let (u, v) = (V3::new(1.0, 0.2, -0.1), V3::new(-0.1, 0.7, 0.4));
            let poly: Vec<P3> = (0..m)
                .map(|i| {
                    let a = std::f64::consts::TAU * (i as f64 + 0.5 * rng.next_f64()) / m as f64;
                    P3::new(0.1, -0.2, 0.3) + u * a.cos() + v * a.sin()
                })
                .collect();
            let n = V3::new(
                rng.next_f64() - 0.5,
                rng.next_f64() - 0.5,
                rng.next_f64() - 0.5,
            )
            .normalize();
            let off = if round % 3 == 0 {
                n.dot(&poly[round % m].coords)
            } else {
                rng.next_f64() - 0.5
            };
            let (mut a, mut b) = (Vec::new(), Vec::new());
            clip_half(&poly, &n, off, false, &mut a);
            clip_half(&poly, &n, off, true, &mut b);
            let (mut c, mut d) = (vec![P3::origin()], Vec::new());
            clip_both(&poly, &n, off, &mut c, &mut d);
            assert_eq!(bits(&c[1..]), bits(&a), "round {round}");
            assert_eq!(bits(&d), bits(&b), "round {round}");
            cut += (!a.is_empty() && !b.is_empty()) as usize;
        }
        assert!(cut > 500, "{cut} polygons cut in two");
    }
}
