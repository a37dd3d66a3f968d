//! The anchor's signed distance field Φ (negative inside): a grid whose nodes are computed when
//! a query first needs them ([`SdfGrid`]), trilinear with an analytic gradient, and exact
//! queries (nearest triangle + the metrics' inside test) in a thin band around the surface,
//! where a grid would blur thin walls (a 4 mm bowl wall is a fraction of a cell).

use crate::mesh::{Aabb, Mesh, P3, V3};
use crate::metrics::{Prepared, Solid};
use std::sync::OnceLock;

/// A regular grid of signed distances, each node's value computed the first time a query needs
/// it: a query touches the 8 nodes of its cell, and the queries of a composition (the item's
/// samples near where it rests) touch a fraction of the anchor's grid, so most of the exact
/// distances an eager grid computes were never read. A node's value is the same whenever it is
/// computed, so the field is the eager grid's, value for value.
pub struct SdfGrid {
    origin: P3,
    cell: f64,
    dims: [usize; 3],
    values: Vec<OnceLock<f64>>,
}

impl SdfGrid {
    /// A grid covering `bb` with cubic cells of size `cell`, no node computed yet.
    pub fn new(bb: &Aabb, cell: f64) -> SdfGrid {
        let e = bb.extents();
        let dims = [0, 1, 2].map(|k| ((e[k] / cell).ceil() as usize + 1).max(2));
        let n = dims[0] * dims[1] * dims[2];
        SdfGrid {
            origin: bb.min,
            cell,
            dims,
            values: (0..n).map(|_| OnceLock::new()).collect(),
        }
    }

    /// Nodes whose value has been computed.
    pub fn computed(&self) -> usize {
        self.values.iter().filter(|v| v.get().is_some()).count()
    }

    /// Trilinear value and gradient of the field `f` sampled at the nodes; `None` outside the
    /// grid. `f` must be the same function at every call (it fills the nodes it is asked for).
    pub fn eval(&self, p: &P3, f: impl Fn(&P3) -> f64) -> Option<(f64, V3)> {
        let q = (p - self.origin) / self.cell;
        let mut i = [0usize; 3];
        let mut fr = [0.0; 3];
        for k in 0..3 {
            if !(q[k] >= 0.0) || q[k] > (self.dims[k] - 1) as f64 {
                return None;
            }
            let c = (q[k].floor() as usize).min(self.dims[k] - 2);
            i[k] = c;
            fr[k] = q[k] - c as f64;
        }
        let at = |dx: usize, dy: usize, dz: usize| {
            let (x, y, z) = (i[0] + dx, i[1] + dy, i[2] + dz);
            *self.values[x + self.dims[0] * (y + self.dims[1] * z)].get_or_init(|| {
                f(&(self.origin + V3::new(x as f64, y as f64, z as f64) * self.cell))
            })
        };
        // The cell's corners, c[dx][dy][dz].
        let c = [0, 1].map(|dx| [0, 1].map(|dy| [0, 1].map(|dz| at(dx, dy, dz))));
        let c = |dx: usize, dy: usize, dz: usize| c[dx][dy][dz];
        let (fx, fy, fz) = (fr[0], fr[1], fr[2]);
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let c00 = lerp(c(0, 0, 0), c(1, 0, 0), fx);
        let c10 = lerp(c(0, 1, 0), c(1, 1, 0), fx);
        let c01 = lerp(c(0, 0, 1), c(1, 0, 1), fx);
        let c11 = lerp(c(0, 1, 1), c(1, 1, 1), fx);
        let c0 = lerp(c00, c10, fy);
        let c1 = lerp(c01, c11, fy);
        let v = lerp(c0, c1, fz);
        // Partial derivatives of the trilinear interpolant.
        let dx = {
            let a0 = lerp(c(1, 0, 0) - c(0, 0, 0), c(1, 1, 0) - c(0, 1, 0), fy);
            let a1 = lerp(c(1, 0, 1) - c(0, 0, 1), c(1, 1, 1) - c(0, 1, 1), fy);
            lerp(a0, a1, fz)
        };
        let dy = lerp(c10 - c00, c11 - c01, fz);
        let dz = c1 - c0;
        Some((v, V3::new(dx, dy, dz) / self.cell))
    }
}

/// Φ of a fixed scene (one or more placed objects): the minimum of their signed distances.
pub struct AnchorField {
    parts: Vec<(Prepared, SdfGrid, Aabb)>,
    band: f64,
}

impl AnchorField {
    /// Precompute the fields of `meshes` (guidance frame), with about `resolution` cells along
    /// each mesh's longest side.
    pub fn new(meshes: &[Mesh], resolution: usize) -> AnchorField {
        let mut f = AnchorField {
            parts: Vec::new(),
            band: 0.0,
        };
        for m in meshes {
            f.push(m, resolution);
        }
        f
    }

    /// Add a fixed object (the composed scene grows by one).
    pub fn push(&mut self, m: &Mesh, resolution: usize) {
        let Some(bb) = m.aabb() else { return };
        let cell = bb.extents().max() / resolution.max(4) as f64;
        let pad = 3.0 * cell;
        let grown = Aabb {
            min: bb.min - V3::repeat(pad),
            max: bb.max + V3::repeat(pad),
        };
        let prep = Prepared::new(Solid::Mesh(m));
        let grid = SdfGrid::new(&grown, cell);
        self.band = self.band.max(2.0 * cell);
        self.parts.push((prep, grid, grown));
    }

    /// Φ(p) and ∇Φ(p): the grid far from the surface, exact within the band.
    pub fn eval(&self, p: &P3) -> (f64, V3) {
        let mut best = (f64::INFINITY, V3::zeros());
        for (prep, grid, bb) in &self.parts {
            let r = match grid.eval(p, |x| prep.signed_distance(x).0) {
                Some((v, g)) if v.abs() > self.band => (v, g),
                Some(_) => exact(prep, p),
                None => {
                    // Outside the grid: distance to the padded box (a lower bound, positive).
                    let c = p.coords.sup(&bb.min.coords).inf(&bb.max.coords);
                    let d = p.coords - c;
                    let n = d.norm();
                    (n + self.band, if n > 0.0 { d / n } else { V3::zeros() })
                }
            };
            if r.0 < best.0 {
                best = r;
            }
        }
        best
    }

    /// Exact Φ (no grid), for reporting.
    pub fn exact(&self, p: &P3) -> f64 {
        self.parts
            .iter()
            .map(|(prep, _, _)| prep.signed_distance(p).0)
            .fold(f64::INFINITY, f64::min)
    }
}

fn exact(prep: &Prepared, p: &P3) -> (f64, V3) {
    let (s, c) = prep.signed_distance(p);
    let d = p - c;
    let n = d.norm();
    if n < 1e-15 {
        return (s, V3::zeros());
    }
    (s, if s < 0.0 { -d / n } else { d / n })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear field is reproduced exactly by trilinear interpolation (value and gradient),
    /// whichever nodes were computed before; a query computes its cell's 8 nodes and no more,
    /// a second query in the same cell none, and every node's value is `f` at the node.
    #[test]
    fn lazy_grid_computes_only_the_nodes_it_reads() {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let bb = Aabb {
            min: P3::new(-1.0, -0.5, 0.0),
            max: P3::new(1.0, 0.5, 2.0),
        };
        let grid = SdfGrid::new(&bb, 0.1);
        let calls = AtomicUsize::new(0);
        let f = |p: &P3| {
            calls.fetch_add(1, Ordering::Relaxed);
            0.3 * p.x - 1.2 * p.y + 0.7 * p.z + 0.05
        };
        let (v, g) = grid.eval(&P3::new(0.23, -0.11, 1.37), f).unwrap();
        assert_eq!(calls.load(Ordering::Relaxed), 8);
        assert_eq!(grid.computed(), 8);
        assert!(
            (v - (0.3 * 0.23 + 1.2 * 0.11 + 0.7 * 1.37 + 0.05)).abs() < 1e-12,
            "{v}"
        );
        assert!((g - V3::new(0.3, -1.2, 0.7)).norm() < 1e-9, "{g:?}");
        // The same cell: no new node.
        grid.eval(&P3::new(0.21, -0.19, 1.31), f).unwrap();
        assert_eq!(calls.load(Ordering::Relaxed), 8);
        // Points all over the grid: the value is the linear field's wherever it is read.
        let mut rng = crate::rng::Rng::new(2);
        for _ in 0..200 {
            let p = P3::new(
                rng.range(-1.0, 1.0),
                rng.range(-0.5, 0.5),
                rng.range(0.0, 2.0),
            );
            let (v, _) = grid.eval(&p, f).unwrap();
            assert!((v - (0.3 * p.x - 1.2 * p.y + 0.7 * p.z + 0.05)).abs() < 1e-12);
        }
        assert_eq!(calls.load(Ordering::Relaxed), grid.computed());
        assert!(grid.computed() < 21 * 11 * 21);
        assert!(grid.eval(&P3::new(1.5, 0.0, 0.0), f).is_none());
    }

    #[test]
    fn sphere_sign_value_and_gradient() {
        let r = 0.05;
        let sphere = crate::shapes::uv_sphere(r, 48, 96);
        let f = AnchorField::new(&[sphere], 24);
        let mut rng = crate::rng::Rng::new(5);
        for _ in 0..300 {
            let p = P3::new(
                rng.range(-0.08, 0.08),
                rng.range(-0.08, 0.08),
                rng.range(-0.08, 0.08),
            );
            let truth = p.coords.norm() - r;
            let (v, g) = f.eval(&p);
            if p.coords.amax() > 0.062 {
                // Outside the grid (sphere box + 3 cells): a positive lower bound.
                assert!(v > 0.0 && v <= truth + 1e-9, "{p:?}: {v} vs {truth}");
                continue;
            }
            // The tessellation is within r·(1 − cos(π/48)) ≈ 0.1 mm of the sphere; the grid
            // part (far from the surface) is exact for a distance field up to interpolation.
            assert!((v - truth).abs() < 1.5e-3, "{p:?}: {v} vs {truth}");
            assert_eq!(v < 0.0, truth < 0.0, "{p:?}: {v} vs {truth}");
            if truth.abs() > 0.005 {
                let radial = p.coords.normalize();
                assert!(g.normalize().dot(&radial) > 0.95, "{p:?} {g:?}");
            }
            // Exact queries: within the tessellation error.
            assert!((f.exact(&p) - truth).abs() < 2e-4);
        }
        // Far outside the grid: positive.
        assert!(f.eval(&P3::new(1.0, 0.0, 0.0)).0 > 0.5);
    }
}
