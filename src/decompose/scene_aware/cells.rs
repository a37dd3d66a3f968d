//! A uniform grid of a surface's triangles: those whose box meets the cell of a point, in one
//! lookup. A first guess for the surface's "is any triangle within r" test (see
//! `Surface::within`): a point sampled on a hull is mostly near the mesh, and a triangle of
//! its own cell is then mostly near enough to answer without descending the BVH. The answers
//! do not depend on the guess. (As a bound for parry's nearest-triangle search it saved only
//! 5 % of that search's instructions on the GSO mug: left out.)

use parry3d_f64::math::Vector;

/// Cell size, as a fraction of the bounding-box diagonal, when the triangles are small: about
/// the engine's tolerance. On the GSO mug (8,454 triangles) cells of 0.5, 1 and 2 % answered
/// "within 0.35 % of the diagonal" for points that were in 0.18, 0.14 and 0.21 µs, against
/// 0.33 µs for the BVH descent alone.
const CELL: f64 = 0.01;

/// Most entries (triangle in a cell) per triangle, on average, beyond a fixed allowance: a
/// mesh of a few large triangles gets larger cells.
const ENTRIES_PER_TRIANGLE: usize = 16;

/// Most cells of a grid.
const MAX_CELLS: usize = 1 << 22;

pub(super) struct Cells {
    min: Vector,
    /// The cell size.
    h: f64,
    dims: [usize; 3],
    /// Where each cell's triangles start in `tris` (one more entry than cells).
    start: Vec<u32>,
    tris: Vec<u32>,
}

impl Cells {
    /// The grid of triangles `corners` (by index) over the box `min`–`max`.
    pub(super) fn new(corners: &[[Vector; 3]], min: Vector, max: Vector) -> Cells {
        let ext = max - min;
        let mut h = CELL * ext.length();
        if h.is_nan() || h <= 0.0 {
            h = 1.0;
        }
        let allowance = ENTRIES_PER_TRIANGLE * corners.len() + 65_536;
        loop {
            let grid = Grid::new(min, ext, h);
            let entries: usize = corners.iter().map(|c| grid.count(c)).sum();
            if (grid.cells() <= MAX_CELLS && entries <= allowance) || grid.cells() == 1 {
                return grid.fill(corners, entries);
            }
            h *= 1.5;
        }
    }

    /// The triangles whose box meets the cell of `p` (none outside the grid).
    pub(super) fn near(&self, p: Vector) -> &[u32] {
        let mut id = 0;
        for a in 0..3 {
            // As in `Grid::cell`, so that a point in a triangle's box finds it.
            let f = (p[a] - self.min[a]) / self.h;
            // Also false for NaN.
            if !(f >= 0.0 && f < self.dims[a] as f64) {
                return &[];
            }
            // Truncation is the floor here (f ≥ 0), without a call to libm's `floor`.
            id = id * self.dims[a] + f as usize;
        }
        &self.tris[self.start[id] as usize..self.start[id + 1] as usize]
    }
}

/// The grid's shape before it is filled.
struct Grid {
    min: Vector,
    h: f64,
    dims: [usize; 3],
}

impl Grid {
    fn new(min: Vector, ext: Vector, h: f64) -> Grid {
        let dims = [0, 1, 2].map(|a| ((ext[a] / h).floor() as usize).saturating_add(1));
        Grid { min, h, dims }
    }

    fn cells(&self) -> usize {
        self.dims.iter().fold(1usize, |n, &d| n.saturating_mul(d))
    }

    /// The cell coordinates of `p`, clamped to the grid (truncation is the floor of the
    /// non-negative coordinate).
    fn cell(&self, p: Vector) -> [usize; 3] {
        [0, 1, 2].map(|a| {
            let f = ((p[a] - self.min[a]) / self.h).max(0.0) as usize;
            f.min(self.dims[a] - 1)
        })
    }

    /// The ranges of cells the box of triangle `c` meets.
    fn span(&self, c: &[Vector; 3]) -> ([usize; 3], [usize; 3]) {
        let lo = self.cell(c[0].min(c[1]).min(c[2]));
        let hi = self.cell(c[0].max(c[1]).max(c[2]));
        (lo, hi)
    }

    fn count(&self, c: &[Vector; 3]) -> usize {
        let (lo, hi) = self.span(c);
        (0..3).map(|a| hi[a] - lo[a] + 1).product()
    }

    /// The indices of the cells the box of triangle `c` meets.
    fn cells_of(&self, c: &[Vector; 3]) -> impl Iterator<Item = usize> + '_ {
        let (lo, hi) = self.span(c);
        let [_, ny, nz] = self.dims;
        (lo[0]..=hi[0]).flat_map(move |i| {
            (lo[1]..=hi[1]).flat_map(move |j| (lo[2]..=hi[2]).map(move |k| (i * ny + j) * nz + k))
        })
    }

    /// Every triangle in the cells its box meets, ascending in each cell.
    fn fill(self, corners: &[[Vector; 3]], entries: usize) -> Cells {
        let n = self.cells();
        let mut start = vec![0u32; n + 1];
        for c in corners {
            for id in self.cells_of(c) {
                start[id + 1] += 1;
            }
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut next = start.clone();
        let mut tris = vec![0u32; entries];
        for (t, c) in corners.iter().enumerate() {
            for id in self.cells_of(c) {
                tris[next[id] as usize] = t as u32;
                next[id] += 1;
            }
        }
        Cells {
            min: self.min,
            h: self.h,
            dims: self.dims,
            start,
            tris,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::to_dvec;
    use crate::rng::Rng;
    use crate::shapes;

    fn corners(m: &crate::mesh::Mesh) -> Vec<[Vector; 3]> {
        (0..m.triangles.len())
            .map(|t| m.triangle(t).map(|p| to_dvec(&p)))
            .collect()
    }

    #[test]
    fn a_point_finds_every_triangle_whose_box_holds_it() {
        let m = shapes::uv_sphere(0.05, 24, 48);
        let c = corners(&m);
        let b = m.aabb().expect("box");
        let cells = Cells::new(&c, to_dvec(&b.min), to_dvec(&b.max));
        let mut rng = Rng::new(3);
        let mut found = 0;
        for (t, tri) in c.iter().enumerate() {
            // A point of the triangle's box, and the triangle's centroid.
            let lo = tri[0].min(tri[1]).min(tri[2]);
            let hi = tri[0].max(tri[1]).max(tri[2]);
            let u = Vector::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
            for p in [lo + (hi - lo) * u, (tri[0] + tri[1] + tri[2]) / 3.0] {
                let near = cells.near(p);
                assert!(near.contains(&(t as u32)), "triangle {t}");
                found += near.len();
            }
        }
        // Small cells: a few triangles each, not the whole sphere.
        assert!(found < 20 * 2 * c.len(), "{found} triangles found");
        assert!(cells.near(Vector::new(1.0, 0.0, 0.0)).is_empty());
        assert!(cells.near(Vector::new(f64::NAN, 0.0, 0.0)).is_empty());
    }

    #[test]
    fn large_triangles_get_large_cells() {
        // A cube's 12 triangles span the box: at 1 % of the diagonal each would fill
        // thousands of cells.
        let m = shapes::cuboid(crate::mesh::V3::new(1.0, 2.0, 3.0));
        let c = corners(&m);
        let b = m.aabb().expect("box");
        let cells = Cells::new(&c, to_dvec(&b.min), to_dvec(&b.max));
        assert!(cells.tris.len() <= ENTRIES_PER_TRIANGLE * c.len() + 65_536);
        assert!(cells.start.len() - 1 <= MAX_CELLS);
        // Still exact about boxes: a corner of the cube meets its triangles there.
        let near = cells.near(to_dvec(&b.min));
        assert!(!near.is_empty());
        // A flat mesh (no extent along z) has one layer of cells.
        let flat = crate::mesh::Mesh::new(
            vec![
                crate::mesh::P3::new(0.0, 0.0, 0.0),
                crate::mesh::P3::new(1.0, 0.0, 0.0),
                crate::mesh::P3::new(0.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2]],
        );
        let c = corners(&flat);
        let cells = Cells::new(&c, Vector::ZERO, Vector::new(1.0, 1.0, 0.0));
        assert_eq!(cells.dims[2], 1);
        assert_eq!(cells.near(Vector::new(0.2, 0.2, 0.0)), &[0]);
    }
}
