//! Cross-sections through contacts: where two objects come closest (or overlap deepest), three
//! axis-aligned planes through that point, each object's interior filled in its colour and any
//! point inside two objects bright red.
//!
//! Entry points: [`contacts`] (the section centre of each pair of nearby objects, from their
//! collision hulls), [`Plane`] (a square window on an axis-aligned plane and its pixel ↔ world
//! map), [`slice`] (which pixels of a plane lie inside a mesh).
//!
//! # Exactness
//! A plane cuts a welded mesh into segments (each mesh edge that changes side gives one point,
//! computed from the edge's lower vertex index first, so two triangles sharing an edge give the
//! same point bit for bit, and a vertex on the plane counts as above it). A pixel row crosses the
//! segments at sorted abscissae; with an even count the pixel centres between pairs are inside
//! (even-odd rule, exact for a closed mesh). A row with an odd count went through a hole of an
//! open scan: its pixels ask the metrics' voted inside test ([`crate::metrics::Prepared::contains`])
//! one by one.

use crate::decompose::Hull;
use crate::mesh::{Mesh, P3, V3};

/// Where a pair of objects is sectioned.
#[derive(Clone, Debug, PartialEq)]
pub struct Contact {
    pub a: usize,
    pub b: usize,
    /// Midway between the deepest hull vertex of one object inside the other's hulls and the
    /// face it is nearest to (or, for separate objects, the closest hull vertex and face),
    /// averaged over the vertices within 5 % of that depth.
    pub point: P3,
    /// Penetration depth (> 0) or gap (< 0), by face-plane distance of hull vertices (m).
    pub depth: f64,
}

/// The section centre of each pair of objects whose hull boxes are within `margin` of each
/// other, in pair order. `hulls[i]` are object `i`'s hulls in the world frame.
pub fn contacts(hulls: &[Vec<Hull>], margin: f64) -> Vec<Contact> {
    let boxes: Vec<Option<crate::mesh::Aabb>> = hulls
        .iter()
        .map(|hs| hs.iter().map(|h| h.aabb).reduce(|a, b| a.union(&b)))
        .collect();
    let mut out = Vec::new();
    for a in 0..hulls.len() {
        for b in a + 1..hulls.len() {
            let (Some(ba), Some(bb)) = (boxes[a], boxes[b]) else {
                continue;
            };
            if !ba.intersects(&bb, margin) {
                continue;
            }
            // Face-plane distance of every vertex of one side to every nearby hull of the
            // other; the centre is the mean of the points within 5 % of the smallest (a face
            // sunk flat into another gives the middle of the face, not one of its corners).
            let mut cand: Vec<(f64, P3)> = Vec::new();
            for (from, to) in [(a, b), (b, a)] {
                for h in &hulls[to] {
                    for g in &hulls[from] {
                        if !g.aabb.intersects(&h.aabb, margin) {
                            continue;
                        }
                        for v in &g.vertices {
                            let (d, n) = h.planes.iter().fold(
                                (f64::NEG_INFINITY, V3::zeros()),
                                |(d, n), (m, o)| {
                                    let e = m.dot(&v.coords) - o;
                                    if e > d {
                                        (e, *m)
                                    } else {
                                        (d, n)
                                    }
                                },
                            );
                            cand.push((d, v - n * (0.5 * d)));
                        }
                    }
                }
            }
            let Some(best) = cand.iter().map(|c| c.0).reduce(f64::min) else {
                continue;
            };
            let scale = ba.union(&bb).diagonal();
            let tol = 0.05 * best.abs() + 1e-9 * scale;
            let near: Vec<&P3> = cand
                .iter()
                .filter(|c| c.0 <= best + tol)
                .map(|c| &c.1)
                .collect();
            let mean = near.iter().fold(V3::zeros(), |s, p| s + p.coords) / near.len() as f64;
            out.push(Contact {
                a,
                b,
                point: P3::from(mean),
                depth: -best,
            });
        }
    }
    out
}

/// A square window on the plane `p[axis] = center[axis]`, `size` pixels wide, pixel side
/// `pixel`. Image right is world `u_axis`, image up is world `v_axis`:
/// `world[u] = center[u] + (col + 0.5 − size/2)·pixel`, `world[v] = center[v] − (row + 0.5 − size/2)·pixel`.
#[derive(Clone, Debug, PartialEq)]
pub struct Plane {
    pub axis: usize,
    pub center: P3,
    pub pixel: f64,
    pub size: u32,
}

impl Plane {
    /// The in-plane axes (right, up): z-normal → (x, y); y-normal → (x, z); x-normal → (y, z).
    pub fn uv_axes(&self) -> (usize, usize) {
        match self.axis {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        }
    }

    /// World coordinate along `u` of column `col`'s centre.
    pub fn u_of(&self, col: f64) -> f64 {
        let (u, _) = self.uv_axes();
        self.center[u] + (col + 0.5 - 0.5 * self.size as f64) * self.pixel
    }

    /// World coordinate along `v` of row `row`'s centre.
    pub fn v_of(&self, row: f64) -> f64 {
        let (_, v) = self.uv_axes();
        self.center[v] - (row + 0.5 - 0.5 * self.size as f64) * self.pixel
    }

    /// The world point at a pixel's centre.
    pub fn world(&self, col: u32, row: u32) -> P3 {
        let (u, v) = self.uv_axes();
        let mut p = self.center;
        p[u] = self.u_of(col as f64);
        p[v] = self.v_of(row as f64);
        p
    }
}

/// Which pixels of `plane` lie inside `mesh` (row-major, `size²`). `inside` answers single
/// points for rows that cross the mesh an odd number of times (holes).
pub fn slice(mesh: &Mesh, plane: &Plane, inside: &dyn Fn(&P3) -> bool) -> Vec<bool> {
    let n = plane.size as usize;
    let mut mask = vec![false; n * n];
    let Some(bb) = mesh.aabb() else {
        return mask;
    };
    let (ua, va) = plane.uv_axes();
    let c = plane.center[plane.axis];
    if c < bb.min[plane.axis] || c > bb.max[plane.axis] {
        return mask;
    }
    // Segments of the cut, in (u, v).
    let side: Vec<f64> = mesh.vertices.iter().map(|p| p[plane.axis] - c).collect();
    let edge_point = |i: u32, j: u32| -> [f64; 2] {
        let (i, j) = if i < j { (i, j) } else { (j, i) };
        let (p, q) = (mesh.vertices[i as usize], mesh.vertices[j as usize]);
        let t = side[i as usize] / (side[i as usize] - side[j as usize]);
        [p[ua] + t * (q[ua] - p[ua]), p[va] + t * (q[va] - p[va])]
    };
    let mut segs: Vec<[[f64; 2]; 2]> = Vec::new();
    for t in &mesh.triangles {
        let s = t.map(|i| side[i as usize] >= 0.0);
        if s[0] == s[1] && s[1] == s[2] {
            continue;
        }
        let mut pts = [[0.0; 2]; 2];
        let mut k = 0;
        for e in 0..3 {
            let (i, j) = (e, (e + 1) % 3);
            if s[i] != s[j] && k < 2 {
                pts[k] = edge_point(t[i], t[j]);
                k += 1;
            }
        }
        segs.push(pts);
    }
    let mut xs = Vec::new();
    for row in 0..n {
        let vr = plane.v_of(row as f64);
        if vr < bb.min[va] || vr > bb.max[va] {
            continue;
        }
        xs.clear();
        for [p, q] in &segs {
            if (p[1] > vr) != (q[1] > vr) {
                xs.push(p[0] + (vr - p[1]) * (q[0] - p[0]) / (q[1] - p[1]));
            }
        }
        if xs.is_empty() {
            continue;
        }
        let line = &mut mask[row * n..(row + 1) * n];
        if xs.len() % 2 == 1 {
            for (col, m) in line.iter_mut().enumerate() {
                let u = plane.u_of(col as f64);
                if u >= bb.min[ua] && u <= bb.max[ua] {
                    *m = inside(&plane.world(col as u32, row as u32));
                }
            }
            continue;
        }
        xs.sort_unstable_by(f64::total_cmp);
        for pair in xs.chunks_exact(2) {
            // Columns whose centres lie in [pair[0], pair[1]).
            let first = ((pair[0] - plane.u_of(0.0)) / plane.pixel).ceil().max(0.0);
            let last = ((pair[1] - plane.u_of(0.0)) / plane.pixel)
                .ceil()
                .min(n as f64);
            for col in first as usize..last.max(first) as usize {
                line[col] = true;
            }
        }
    }
    mask
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;

    fn cube(center: P3, half: f64) -> Mesh {
        let mut m = shapes::cuboid(V3::repeat(2.0 * half));
        for v in &mut m.vertices {
            *v += center.coords;
        }
        m
    }

    #[test]
    fn box_section_area_is_exact_and_sphere_section_is_pi_r_squared() {
        let plane = |axis| Plane {
            axis,
            center: P3::new(0.013, -0.007, 0.021),
            pixel: 0.01,
            size: 300,
        };
        let no = |_: &P3| panic!("a closed mesh needs no fallback");
        // Box 1.2 × 0.8 × 1.6 (half 0.6, 0.4, 0.8): sections 0.8·1.6, 1.2·1.6, 1.2·0.8.
        let b = shapes::cuboid(V3::new(1.2, 0.8, 1.6)).welded(0.0);
        for (axis, want) in [(0, 0.8 * 1.6), (1, 1.2 * 1.6), (2, 1.2 * 0.8)] {
            let m = slice(&b, &plane(axis), &no);
            let area = m.iter().filter(|&&x| x).count() as f64 * 1e-4;
            // Pixel centres on a 0.01 grid: the edge error is at most one pixel row per side.
            let perimeter_px = 2.0 * (1.2 + 1.6 + 0.8) / 0.01;
            assert!(
                (area - want).abs() <= perimeter_px * 1e-4,
                "axis {axis}: {area} vs {want}"
            );
        }
        // Sphere of radius 1 (fine UV sphere): the section through z=0.021 has radius
        // sqrt(1 - 0.021²) minus the polygon's sag.
        let s = shapes::uv_sphere(1.0, 64, 128).welded(0.0);
        let m = slice(&s, &plane(2), &no);
        let area = m.iter().filter(|&&x| x).count() as f64 * 1e-4;
        let r2 = 1.0 - 0.021f64 * 0.021;
        let want = std::f64::consts::PI * r2;
        assert!((area - want).abs() / want < 0.01, "{area} vs {want}");
    }

    #[test]
    fn contact_point_sits_in_the_overlap_of_two_boxes() {
        // Unit boxes overlapping by 0.1 along x (offset in y and z too, so no faces are
        // coplanar): depth 0.1, the centre inside the overlap box.
        let a = Hull::from_mesh(cube(P3::new(0.0, 0.0, 0.0), 0.5)).unwrap();
        let b = Hull::from_mesh(cube(P3::new(0.9, 0.2, 0.1), 0.5)).unwrap();
        let c = contacts(&[vec![a.clone()], vec![b]], 0.01);
        assert_eq!(c.len(), 1);
        assert!((c[0].depth - 0.1).abs() < 1e-12, "{}", c[0].depth);
        let p = c[0].point;
        assert!(
            p.x >= 0.4 && p.x <= 0.5 && p.y >= -0.3 && p.y <= 0.5 && p.z >= -0.4 && p.z <= 0.5,
            "{p:?}"
        );
        // Apart by 0.2 along x: a gap (negative depth), the centre in the gap.
        let b = Hull::from_mesh(cube(P3::new(1.2, 0.2, 0.1), 0.5)).unwrap();
        let c = contacts(&[vec![a.clone()], vec![b.clone()]], 0.5);
        assert!((c[0].depth + 0.2).abs() < 1e-12, "{}", c[0].depth);
        assert!(
            c[0].point.x >= 0.5 && c[0].point.x <= 0.7,
            "{:?}",
            c[0].point
        );
        // Farther than the margin: no section.
        assert!(contacts(&[vec![a], vec![b]], 0.1).is_empty());
    }
}
