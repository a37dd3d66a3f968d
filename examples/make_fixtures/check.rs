//! Exact geometry checks: the minimum distance between triangle meshes as written, mass properties, how far an item is from tipping.

use super::*;

/// Distance between two triangles (0 when they intersect), by the library's exact test, the one
/// the validation's metrics use.
pub(crate) fn triangle_distance(a: &[P3; 3], b: &[P3; 3]) -> f64 {
    let v = |t: &[P3; 3]| t.map(|p| [p.x, p.y, p.z]);
    interact3d::metrics::tri_tri_dist2(&v(a), &v(b)).sqrt()
}

pub(crate) struct TriSet {
    pub(crate) tris: Vec<[P3; 3]>,
    pub(crate) boxes: Vec<(P3, P3)>,
}

impl TriSet {
    pub(crate) fn of(m: &Mesh, keep: impl Fn(&[P3; 3]) -> bool) -> TriSet {
        let tris: Vec<[P3; 3]> = (0..m.triangles.len())
            .map(|i| m.triangle(i))
            .filter(|t| keep(t))
            .collect();
        let boxes = tris
            .iter()
            .map(|t| (t[0].inf(&t[1]).inf(&t[2]), t[0].sup(&t[1]).sup(&t[2])))
            .collect();
        TriSet { tris, boxes }
    }
    pub(crate) fn all(m: &Mesh) -> TriSet {
        TriSet::of(m, |_| true)
    }
}

pub(crate) fn box_gap(a: &(P3, P3), b: &(P3, P3)) -> f64 {
    let mut s = 0.0;
    for i in 0..3 {
        let d = (a.0[i] - b.1[i]).max(b.0[i] - a.1[i]).max(0.0);
        s += d * d;
    }
    s.sqrt()
}

/// Exact minimum distance between two triangle sets (0 when their surfaces intersect).
pub(crate) fn set_distance(a: &TriSet, b: &TriSet) -> f64 {
    let mut best = f64::INFINITY;
    for (ta, ba) in a.tris.iter().zip(&a.boxes) {
        for (tb, bb) in b.tris.iter().zip(&b.boxes) {
            if box_gap(ba, bb) < best {
                best = best.min(triangle_distance(ta, tb));
            }
        }
    }
    best
}

pub(crate) fn mesh_distance(a: &Mesh, b: &Mesh) -> f64 {
    set_distance(&TriSet::all(a), &TriSet::all(b))
}

/// Volume and centre of mass of a closed mesh.
pub(crate) fn mass_props(m: &Mesh) -> (f64, P3) {
    let mut v = 0.0;
    let mut c = V3::zeros();
    for i in 0..m.triangles.len() {
        let [a, b, cc] = m.triangle(i);
        let dv = a.coords.dot(&b.coords.cross(&cc.coords)) / 6.0;
        v += dv;
        c += (a.coords + b.coords + cc.coords) * (dv / 4.0);
    }
    (v, P3::from(c / v))
}

/// Signed distance from 2D point `p` to the boundary of the convex hull of `pts` (positive
/// inside). The hull is built by gift wrapping; fine for the few points of a contact face.
pub(crate) fn inside_margin_2d(pts: &[[f64; 2]], p: [f64; 2]) -> f64 {
    let mut hull: Vec<[f64; 2]> = Vec::new();
    let start = (0..pts.len())
        .min_by(|&i, &j| pts[i].partial_cmp(&pts[j]).unwrap())
        .unwrap();
    let mut cur = start;
    loop {
        hull.push(pts[cur]);
        let mut next = (cur + 1) % pts.len();
        for k in 0..pts.len() {
            let (a, b, c) = (pts[cur], pts[next], pts[k]);
            let cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            if cross < 0.0 {
                next = k;
            }
        }
        cur = next;
        if cur == start || hull.len() > pts.len() {
            break;
        }
    }
    let n = hull.len();
    (0..n)
        .map(|i| {
            let (a, b) = (hull[i], hull[(i + 1) % n]);
            let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
            (ex * (p[1] - a[1]) - ey * (p[0] - a[0])) / ex.hypot(ey)
        })
        .fold(f64::INFINITY, f64::min)
}

/// For an item resting on a flat face (Z-up world mesh): the face's vertices are the lowest
/// ones; returns how far inside that face the centre of mass projects (m, positive = stable).
pub(crate) fn face_rest_margin(world: &Mesh) -> f64 {
    let zmin = world.aabb().unwrap().min.z;
    let low: Vec<[f64; 2]> = world
        .vertices
        .iter()
        .filter(|p| p.z - zmin < 1e-9)
        .map(|p| [p.x, p.y])
        .collect();
    assert!(low.len() >= 3, "item does not rest on a face");
    let (_, com) = mass_props(world);
    inside_margin_2d(&low, [com.x, com.y])
}
