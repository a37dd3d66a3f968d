//! Exact-in-f64 triangle primitives: orientation predicates, triangle–triangle intersection
//! (segment–triangle decomposition) and closest distances (point–triangle, segment–segment,
//! triangle–triangle). Plain `f64` arithmetic, no tolerances: a sign is trusted as computed.
//! Near-degenerate configurations (coplanar within rounding) may go either way; that is the
//! touching case, where either answer is acceptable for the metrics.

pub type V = [f64; 3];

#[inline]
pub fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline]
pub fn add(a: V, b: V) -> V {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
#[inline]
pub fn scale(a: V, s: f64) -> V {
    [a[0] * s, a[1] * s, a[2] * s]
}
#[inline]
pub fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline]
pub fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
#[inline]
pub fn norm2(a: V) -> f64 {
    dot(a, a)
}

/// Sign-carrying volume of the tetrahedron (a, b, c, d): positive when `d` is on the side the
/// counter-clockwise normal of (a, b, c) points to.
#[inline]
pub fn orient3d(a: V, b: V, c: V, d: V) -> f64 {
    dot(cross(sub(b, a), sub(c, a)), sub(d, a))
}

#[inline]
fn sgn(x: f64) -> i8 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

/// Drop the coordinate where `n` is largest: a projection that keeps a plane with normal `n`
/// non-degenerate.
#[inline]
fn drop_axis(n: V) -> (usize, usize) {
    let (ax, ay, az) = (n[0].abs(), n[1].abs(), n[2].abs());
    if ax >= ay && ax >= az {
        (1, 2)
    } else if ay >= az {
        (2, 0)
    } else {
        (0, 1)
    }
}

#[inline]
fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Closed 2D segment–segment intersection.
fn seg_seg_2d(p: [f64; 2], q: [f64; 2], a: [f64; 2], b: [f64; 2]) -> bool {
    let d1 = sgn(orient2d(a, b, p));
    let d2 = sgn(orient2d(a, b, q));
    let d3 = sgn(orient2d(p, q, a));
    let d4 = sgn(orient2d(p, q, b));
    if d1 * d2 < 0 && d3 * d4 < 0 {
        return true;
    }
    let on = |s: [f64; 2], e: [f64; 2], x: [f64; 2]| {
        x[0] >= s[0].min(e[0])
            && x[0] <= s[0].max(e[0])
            && x[1] >= s[1].min(e[1])
            && x[1] <= s[1].max(e[1])
    };
    (d1 == 0 && on(a, b, p))
        || (d2 == 0 && on(a, b, q))
        || (d3 == 0 && on(p, q, a))
        || (d4 == 0 && on(p, q, b))
}

/// Closed 2D point-in-triangle.
fn point_in_tri_2d(p: [f64; 2], a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> bool {
    let d1 = orient2d(a, b, p);
    let d2 = orient2d(b, c, p);
    let d3 = orient2d(c, a, p);
    let neg = d1 < 0.0 || d2 < 0.0 || d3 < 0.0;
    let pos = d1 > 0.0 || d2 > 0.0 || d3 > 0.0;
    !(neg && pos)
}

/// Closed segment [p, q] against closed triangle t, where the segment lies in the plane of t
/// (normal `n`).
fn coplanar_seg_tri(p: V, q: V, t: &[V; 3], n: V) -> bool {
    let (i, j) = drop_axis(n);
    let pr = |v: V| [v[i], v[j]];
    let (p2, q2) = (pr(p), pr(q));
    let (a, b, c) = (pr(t[0]), pr(t[1]), pr(t[2]));
    point_in_tri_2d(p2, a, b, c)
        || point_in_tri_2d(q2, a, b, c)
        || seg_seg_2d(p2, q2, a, b)
        || seg_seg_2d(p2, q2, b, c)
        || seg_seg_2d(p2, q2, c, a)
}

/// Closed segment [p, q] against closed triangle t.
pub fn seg_tri(p: V, q: V, t: &[V; 3]) -> bool {
    let [a, b, c] = *t;
    let sp = sgn(orient3d(a, b, c, p));
    let sq = sgn(orient3d(a, b, c, q));
    if sp * sq > 0 {
        return false;
    }
    if sp == 0 && sq == 0 {
        let n = cross(sub(b, a), sub(c, a));
        if n == [0.0; 3] {
            return false; // degenerate triangle
        }
        return coplanar_seg_tri(p, q, t, n);
    }
    // The segment meets the plane at one point; it lies in the closed triangle iff the line
    // through p, q passes on the same side of (or on) all three edges.
    let s1 = sgn(orient3d(p, q, a, b));
    let s2 = sgn(orient3d(p, q, b, c));
    let s3 = sgn(orient3d(p, q, c, a));
    !((s1 > 0 || s2 > 0 || s3 > 0) && (s1 < 0 || s2 < 0 || s3 < 0))
}

/// Closed triangle–triangle intersection (touching counts). Two triangles meet iff an edge of
/// one meets the other: the intersection of two triangles is a convex set whose extreme points
/// lie on edges (non-coplanar: the overlap of two intervals on the planes' common line; coplanar:
/// either edges cross or one contains the other, whose edges then lie inside it).
pub fn tri_tri_intersect(t: &[V; 3], u: &[V; 3]) -> bool {
    // Quick plane rejection.
    let su = [
        orient3d(t[0], t[1], t[2], u[0]),
        orient3d(t[0], t[1], t[2], u[1]),
        orient3d(t[0], t[1], t[2], u[2]),
    ];
    if (su[0] > 0.0 && su[1] > 0.0 && su[2] > 0.0) || (su[0] < 0.0 && su[1] < 0.0 && su[2] < 0.0) {
        return false;
    }
    let st = [
        orient3d(u[0], u[1], u[2], t[0]),
        orient3d(u[0], u[1], u[2], t[1]),
        orient3d(u[0], u[1], u[2], t[2]),
    ];
    if (st[0] > 0.0 && st[1] > 0.0 && st[2] > 0.0) || (st[0] < 0.0 && st[1] < 0.0 && st[2] < 0.0) {
        return false;
    }
    for k in 0..3 {
        if seg_tri(t[k], t[(k + 1) % 3], u) || seg_tri(u[k], u[(k + 1) % 3], t) {
            return true;
        }
    }
    false
}

/// Closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision Detection, 5.1.5).
pub fn closest_on_tri(p: V, a: V, b: V, c: V) -> V {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return add(a, scale(ab, v));
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return add(a, scale(ac, w));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return add(b, scale(sub(c, b), w));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    add(a, add(scale(ab, v), scale(ac, w)))
}

/// Squared distance from p to triangle t.
#[inline]
pub fn point_tri_dist2(p: V, t: &[V; 3]) -> f64 {
    norm2(sub(p, closest_on_tri(p, t[0], t[1], t[2])))
}

/// Squared distance between segments [p1, q1] and [p2, q2] (Ericson 5.1.9, degenerate cases
/// included).
pub fn seg_seg_dist2(p1: V, q1: V, p2: V, q2: V) -> f64 {
    let d1 = sub(q1, p1);
    let d2 = sub(q2, p2);
    let r = sub(p1, p2);
    let a = dot(d1, d1);
    let e = dot(d2, d2);
    let f = dot(d2, r);
    let (s, t);
    if a <= 0.0 && e <= 0.0 {
        return norm2(r);
    }
    if a <= 0.0 {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = dot(d1, r);
        if e <= 0.0 {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = dot(d1, d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    let c1 = add(p1, scale(d1, s));
    let c2 = add(p2, scale(d2, t));
    norm2(sub(c1, c2))
}

/// Squared distance between two closed triangles (0 when they intersect). When they do not
/// intersect, the closest pair involves a vertex of one and the other triangle, or two edges.
pub fn tri_tri_dist2(t: &[V; 3], u: &[V; 3]) -> f64 {
    if tri_tri_intersect(t, u) {
        return 0.0;
    }
    let mut best = f64::INFINITY;
    for k in 0..3 {
        best = best.min(point_tri_dist2(t[k], u));
        best = best.min(point_tri_dist2(u[k], t));
    }
    for i in 0..3 {
        for j in 0..3 {
            best = best.min(seg_seg_dist2(t[i], t[(i + 1) % 3], u[j], u[(j + 1) % 3]));
        }
    }
    best
}

/// Solid angle of triangle (a, b, c) seen from p, signed by orientation (Van Oosterom &
/// Strackee 1983). Summed over a closed outward mesh it is 4π inside and 0 outside.
pub fn solid_angle(p: V, t: &[V; 3]) -> f64 {
    let a = sub(t[0], p);
    let b = sub(t[1], p);
    let c = sub(t[2], p);
    let (la, lb, lc) = (norm2(a).sqrt(), norm2(b).sqrt(), norm2(c).sqrt());
    let num = dot(a, cross(b, c));
    let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
    2.0 * num.atan2(den)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tri_tri_cases() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        // Piercing.
        let u = [[0.2, 0.2, -1.0], [0.2, 0.2, 1.0], [0.3, 0.9, 0.0]];
        assert!(tri_tri_intersect(&t, &u));
        // Above.
        let u2 = [[0.2, 0.2, 0.1], [0.2, 0.3, 1.0], [0.3, 0.9, 0.1]];
        assert!(!tri_tri_intersect(&t, &u2));
        assert!((tri_tri_dist2(&t, &u2) - 0.01).abs() < 1e-15);
        // Coplanar overlapping, coplanar disjoint, coplanar contained.
        let c1 = [[0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]];
        assert!(tri_tri_intersect(&t, &c1));
        let c2 = [[2.0, 2.0, 0.0], [3.0, 2.0, 0.0], [2.0, 3.0, 0.0]];
        assert!(!tri_tri_intersect(&t, &c2));
        let c3 = [[0.1, 0.1, 0.0], [0.2, 0.1, 0.0], [0.1, 0.2, 0.0]];
        assert!(tri_tri_intersect(&t, &c3) && tri_tri_intersect(&c3, &t));
        // Edge–edge crossing in space: distance between skew edges.
        let e = [[0.5, -1.0, 0.5], [0.5, 1.0, 0.5], [0.5, 0.0, 2.0]];
        assert!((tri_tri_dist2(&t, &e) - 0.25).abs() < 1e-15);
    }

    #[test]
    fn solid_angle_of_closed_tetra() {
        let v = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let tris = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let w = |p: V| -> f64 {
            tris.iter()
                .map(|t| solid_angle(p, &[v[t[0]], v[t[1]], v[t[2]]]))
                .sum::<f64>()
                / (4.0 * std::f64::consts::PI)
        };
        assert!((w([0.1, 0.1, 0.1]) - 1.0).abs() < 1e-12);
        assert!(w([1.0, 1.0, 1.0]).abs() < 1e-12);
    }
}
