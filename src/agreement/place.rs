//! Dropping an object onto what is already placed: the lowest height at which its collision
//! hulls touch nothing (exact convex intersection tests, parry), found by stepping down from
//! above everything and bisecting the last step. Stepping (not bisecting the whole range) keeps
//! an item on a mug's rim from being found inside the mug's wall.

use super::CatalogObject;
use crate::pose::parry_pose;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion};
use rapier3d_f64::math::{Pose, Vector};
use rapier3d_f64::parry::query;
use rapier3d_f64::parry::shape::ConvexPolyhedron;

/// Parry shapes of every catalog object's hulls (body frame).
pub struct Placer {
    shapes: Vec<Vec<(ConvexPolyhedron, Vec<Point3<f64>>)>>,
}

const STEP: f64 = 0.002;
const BISECTIONS: usize = 30;

type Bounds = ([f64; 3], [f64; 3]);

fn bounds(points: &[Point3<f64>], iso: &Isometry3<f64>) -> Bounds {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        let w = iso * p;
        for k in 0..3 {
            lo[k] = lo[k].min(w[k]);
            hi[k] = hi[k].max(w[k]);
        }
    }
    (lo, hi)
}

fn overlap(a: &Bounds, b: &Bounds) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

impl Placer {
    pub fn new(objects: &[CatalogObject]) -> Placer {
        let shapes = objects
            .iter()
            .map(|o| {
                o.body
                    .hulls
                    .iter()
                    .filter_map(|h| {
                        let v: Vec<Vector> = h
                            .vertices
                            .iter()
                            .map(|p| Vector::new(p.x, p.y, p.z))
                            .collect();
                        let poly = ConvexPolyhedron::from_convex_mesh(v.clone(), &h.triangles)
                            .or_else(|| ConvexPolyhedron::from_convex_hull(&v))?;
                        Some((poly, h.vertices.clone()))
                    })
                    .collect()
            })
            .collect();
        Placer { shapes }
    }

    /// Height of the centre of mass of object `k`, turned by `rot`, at (x, y), resting on the
    /// floor or on the placed objects (catalog index, pose), whichever is higher.
    pub fn drop_height(
        &self,
        k: usize,
        rot: &UnitQuaternion<f64>,
        x: f64,
        y: f64,
        placed: &[(usize, Isometry3<f64>)],
    ) -> f64 {
        let turned = Isometry3::from_parts(Translation3::identity(), *rot);
        let lowest = self.shapes[k]
            .iter()
            .map(|(_, pts)| bounds(pts, &turned).0[2])
            .fold(f64::INFINITY, f64::min);
        let floor = -lowest;
        let others: Vec<(&ConvexPolyhedron, Pose, Bounds)> = placed
            .iter()
            .flat_map(|(j, pose)| {
                self.shapes[*j]
                    .iter()
                    .map(move |(s, pts)| (s, parry_pose(pose), bounds(pts, pose)))
            })
            .collect();
        let Some(top) = others.iter().map(|o| o.2 .1[2]).reduce(f64::max) else {
            return floor;
        };
        let hits = |z: f64| -> bool {
            let iso = Isometry3::from_parts(Translation3::new(x, y, z), *rot);
            let pose = parry_pose(&iso);
            self.shapes[k].iter().any(|(s, pts)| {
                let b = bounds(pts, &iso);
                others.iter().any(|(o, op, ob)| {
                    overlap(&b, ob)
                        && query::intersection_test(&pose, s, op, *o).is_ok_and(|i| i.intersecting)
                })
            })
        };
        let mut free = (top + floor + STEP).max(floor);
        loop {
            let z = free - STEP;
            if z <= floor {
                return if hits(floor) {
                    bisect(free, floor, &hits)
                } else {
                    floor
                };
            }
            if hits(z) {
                return bisect(free, z, &hits);
            }
            free = z;
        }
    }
}

/// The lowest free height between a free `hi` and a hit `lo`.
fn bisect(mut free: f64, mut hit: f64, hits: &dyn Fn(f64) -> bool) -> f64 {
    for _ in 0..BISECTIONS {
        let mid = 0.5 * (free + hit);
        if hits(mid) {
            hit = mid;
        } else {
            free = mid;
        }
    }
    free
}
