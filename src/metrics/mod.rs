//! Interpenetration metrics of the Interact3D paper for a pair of objects in world coordinates
//! (metres): R_volume, R_surface, maximum penetration depth and minimum clearance, on visual
//! meshes (possibly open scans) and on collision geometry (sets of convex hulls).
//!
//! # Use
//! Prepare each object once ([`Prepared::new`] on a [`Solid`]: acceleration structures are
//! built there), then call [`pair_metrics`] or the single metrics; [`scene_metrics`] runs every
//! pair of a scene in parallel. Results are deterministic: the same numbers on every run and for
//! any number of threads (integer counts, per-column random streams, fixed traversal orders).
//!
//! # R_volume
//! `N` points uniform in the box enclosing both objects; `R_volume = #(in A and B) / #(in A or
//! B)` (0 when no point is in either, and exactly 0 without sampling when the boxes are
//! disjoint). The points come in columns parallel to a coordinate axis: a third of the columns
//! along each of x, y, z; column positions are jittered-stratified over the box face (one per
//! cell of a grid shaped like the face), and the [`MetricsOptions::points_per_column`] points of
//! a column are independent and uniform along it. Every point is therefore uniform in the box, as
//! in the paper; stratifying the columns removes the extra variance that correlated points of a
//! column would otherwise add, so the spread is at most that of independent points. Streams are
//! seeded per column from [`MetricsOptions::seed`].
//!
//! ## Inside-ness of a mesh: ray parity, voted where a ray meets a hole
//! One ray per column and object (an axis-parallel line through the whole object) gives all
//! crossings, sorted; every point of the column is then classified by the parity of the
//! crossings below it. The ray–triangle test is watertight: axis-parallel rays reduce it to a 2D
//! test whose edge orientations are evaluated canonically with symbolic perturbation, so a ray
//! through a shared edge or vertex of a closed mesh counts once (see `inside.rs`).
//!
//! Real scans are not closed. A line through a hole crosses the surface an odd number of times,
//! so its two half-lines disagree; that is detectable per column at no cost. Such a point is
//! classified by a vote of the six half-lines through it along ±x, ±y, ±z (the two of the
//! column line, which cancel, plus two more lines), and a 3:3 tie by the generalised winding
//! number. What remains undetected is a column whose line passes through two holes (even, yet
//! wrong); for a few missing triangles that is a vanishing fraction of the points (the tests
//! remove both polar fans, aligned along z: the inside count changes by < 0.1%). Single-point
//! queries ([`Prepared::contains`], used for penetration and containment) always take the vote
//! of all six half-lines, so they also survive that case.
//! Why not the generalised winding number everywhere: it is O(triangles) per point (1.6·10^10
//! solid angles for 10^6 points against 16k triangles) and its fast approximations are
//! approximate; parity is exact for closed meshes, costs a few 2D tests per column, does not
//! depend on triangle orientation (inward or mixed normals are fine), and voting repairs it
//! exactly where it is unreliable.
//!
//! ## Inside-ness of a hull set
//! Inside any hull, by face-plane tests `n·p <= d` in f64 (no tolerance). A grid of cells over
//! the set, resolved once per object, answers most points without any plane test and leaves the
//! rest the few planes that cross their cell; the answers are the direct test's bit for bit
//! (see `hullgrid.rs` for why).
//!
//! # R_surface
//! Area of the triangles of A and of B that intersect (closed test: touching counts) some
//! triangle of the other, over `area(A) + area(B)`. Pairs come from a BVH pair traversal; the
//! triangle test is a predicate-only segment–triangle decomposition in f64. For a hull set the
//! "mesh" is the soup of all hull faces.
//!
//! # Penetration depth and clearance
//! * Clearance: 0 when the objects overlap (surfaces intersect, or a vertex of one is inside the
//!   other); otherwise the exact minimum distance between the two triangle sets (BVH branch and
//!   bound with exact triangle–triangle distances). For hull sets the triangles are the hull
//!   faces, so this is the exact distance between the unions.
//! * Penetration of meshes (and mesh against hulls): the largest distance, to the other object's
//!   surface, of a point of one object's surface that lies inside the other, both ways. The
//!   points are all vertices plus, on triangles larger than the sample spacing
//!   ([`MetricsOptions::depth_spacing`], default 1/64 of the smaller object diagonal), a
//!   barycentric lattice of that spacing. Without the lattice two boxes crossing like a plus sign
//!   (no vertex of either inside the other) would report 0; with it the answer is within one
//!   spacing of the maximum over the whole surface, since the depth is 1-Lipschitz. The depth
//!   inside a hull set is the depth inside the deepest hull containing the point (exact for one
//!   hull; for overlapping hulls of one object a lower bound).
//! * Penetration of two hull sets: the largest exact convex penetration depth (shortest
//!   separating translation, by separating axes in f64) over all pairs of hulls.

mod bvh;
mod geom;
mod hullgrid;
mod inside;
#[cfg(test)]
mod tests;

use crate::mesh::{Mesh, P3};
use crate::rng::Rng;
use bvh::{Bb, Bvh};
/// Squared distance between two closed triangles (0 when they intersect): vertex–triangle and
/// edge–edge distances after an intersection test. `examples/make_fixtures/` checks the
/// fixtures' gaps with it.
pub use geom::tri_tri_dist2;
use geom::V;
use hullgrid::HullGrid;
use inside::{Hull, RayMesh};
use rayon::prelude::*;
use serde::Serialize;

/// An object as the metrics see it, in world coordinates (metres).
#[derive(Clone, Copy, Debug)]
pub enum Solid<'a> {
    /// A triangle mesh, possibly open (a scan with holes); orientation does not matter.
    Mesh(&'a Mesh),
    /// Convex hulls (each a closed convex mesh); the solid is their union.
    Hulls(&'a [Mesh]),
}

// One per object, built once and never moved in a loop: boxing the mesh would buy nothing.
#[allow(clippy::large_enum_variant)]
enum Shape {
    Mesh(RayMesh),
    /// The hulls, and the grid that answers their inside test (none for a box that is not
    /// finite).
    Hulls(Vec<Hull>, Option<HullGrid>),
}

/// An object with its acceleration structures, built once and reused for every pair.
pub struct Prepared {
    shape: Shape,
    /// All surface triangles (the mesh, or every face of every hull).
    surface: Bvh,
    /// All vertices (welded mesh vertices, or every hull's vertices).
    verts: Vec<V>,
    area: f64,
    bb: Bb,
}

fn v(p: &P3) -> V {
    [p.x, p.y, p.z]
}

impl Prepared {
    /// Build the acceleration structures. Mesh vertices at bit-identical positions are merged
    /// first (split UV seams would otherwise look like holes).
    pub fn new(solid: Solid) -> Prepared {
        match solid {
            Solid::Mesh(m) => {
                let m = m.welded(0.0);
                let verts: Vec<V> = m.vertices.iter().map(v).collect();
                let soup = m
                    .triangles
                    .iter()
                    .map(|t| t.map(|i| verts[i as usize]))
                    .collect();
                let rm = RayMesh::new(verts.clone(), m.triangles.clone());
                Prepared::finish(Shape::Mesh(rm), soup, verts)
            }
            Solid::Hulls(hs) => {
                let mut soup = Vec::new();
                let mut verts = Vec::new();
                let hulls: Vec<Hull> = hs
                    .iter()
                    .filter(|h| !h.triangles.is_empty())
                    .map(|h| {
                        let hv: Vec<V> = h.vertices.iter().map(v).collect();
                        soup.extend(h.triangles.iter().map(|t| t.map(|i| hv[i as usize])));
                        verts.extend(h.triangles.iter().flatten().map(|&i| hv[i as usize]));
                        Hull::new(hv, &h.triangles)
                    })
                    .collect();
                verts.sort_by(|a, b| {
                    a.iter()
                        .zip(b)
                        .fold(std::cmp::Ordering::Equal, |o, (x, y)| {
                            o.then(x.total_cmp(y))
                        })
                });
                verts.dedup();
                let grid = HullGrid::new(&hulls);
                Prepared::finish(Shape::Hulls(hulls, grid), soup, verts)
            }
        }
    }

    fn finish(shape: Shape, soup: Vec<[V; 3]>, verts: Vec<V>) -> Prepared {
        let area = soup.iter().fold(0.0, |s, t| s + tri_area(t));
        let mut bb = Bb::EMPTY;
        for p in &verts {
            bb.grow(*p);
        }
        Prepared {
            shape,
            surface: Bvh::new(soup),
            verts,
            area,
            bb,
        }
    }

    /// Surface area (for hulls: the sum of all hull faces).
    pub fn area(&self) -> f64 {
        self.area
    }

    /// Whether `p` is inside the solid (see the module documentation for the method).
    pub fn contains(&self, p: &P3) -> bool {
        self.contains_v(v(p))
    }

    /// Signed distance from `p` to the surface (negative inside, by the same inside test as
    /// [`Prepared::contains`]) and the nearest surface point. Used by the collision-aware
    /// refinement of `compose` near the anchor's surface, where a grid would blur thin walls.
    pub fn signed_distance(&self, p: &P3) -> (f64, P3) {
        let q = v(p);
        let (d2, t) = self.surface.nearest(q, None);
        if t == usize::MAX {
            return (f64::INFINITY, *p);
        }
        let tri = &self.surface.tris[t];
        let c = geom::closest_on_tri(q, tri[0], tri[1], tri[2]);
        let d = d2.sqrt();
        let s = if self.contains_v(q) { -d } else { d };
        (s, P3::new(c[0], c[1], c[2]))
    }

    fn contains_v(&self, p: V) -> bool {
        if !self.bb.contains(p) {
            return false;
        }
        match &self.shape {
            Shape::Mesh(m) => m.contains(p),
            Shape::Hulls(_, Some(g)) => g.contains(p),
            Shape::Hulls(hs, None) => hs.iter().any(|h| h.contains(p)),
        }
    }

    /// Distance from `p` to the surface when `p` is inside, else 0; with the nearest surface
    /// triangle when known (a hint for the next, nearby point).
    fn depth_v(&self, p: V, hint: Option<usize>) -> (f64, Option<usize>) {
        if !self.contains_v(p) {
            return (0.0, hint);
        }
        match &self.shape {
            Shape::Mesh(_) => {
                let (d2, t) = self.surface.nearest(p, hint);
                (d2.sqrt(), Some(t))
            }
            Shape::Hulls(hs, _) => (
                hs.iter()
                    .filter(|h| h.contains(p))
                    .map(|h| h.depth(p))
                    .fold(0.0, f64::max),
                None,
            ),
        }
    }

    /// Largest depth inside `self` over the points. A sparse first pass (every 64th point)
    /// gives a global lower bound; then, in parallel chunks, a point is skipped when an upper
    /// bound on its depth cannot beat the best so far: the depth of the previous point plus
    /// their distance (the distance to a surface is 1-Lipschitz), or its distance to the
    /// previous point's nearest triangle. The maximum is exact and independent of the chunking.
    fn max_depth_of(&self, points: &[V]) -> f64 {
        let seed = points
            .par_iter()
            .step_by(64)
            .map(|&p| self.depth_v(p, None).0)
            .reduce(|| 0.0, f64::max);
        points
            .par_chunks(256)
            .map(|chunk| {
                let mut best = seed;
                let mut last: Option<(V, f64)> = None;
                let mut hint: Option<usize> = None;
                for &p in chunk {
                    if let Some((q, dq)) = last {
                        if dq + geom::norm2(geom::sub(p, q)).sqrt() <= best {
                            continue;
                        }
                    }
                    if let Some(h) = hint {
                        if geom::point_tri_dist2(p, &self.surface.tris[h]).sqrt() <= best {
                            continue;
                        }
                    }
                    let (d, h) = self.depth_v(p, hint);
                    hint = h;
                    if d > 0.0 {
                        last = Some((p, d));
                        best = best.max(d);
                    }
                }
                best
            })
            .reduce(|| seed, f64::max)
    }

    /// Points of the surface for depth queries: every vertex inside `within`, plus a
    /// barycentric lattice of the given spacing on the triangles that are larger than it.
    fn surface_samples(&self, within: &Bb, spacing: f64) -> Vec<V> {
        let mut out: Vec<V> = self
            .verts
            .iter()
            .copied()
            .filter(|p| within.contains(*p))
            .collect();
        for t in &self.surface.tris {
            let mut tb = Bb::EMPTY;
            t.iter().for_each(|p| tb.grow(*p));
            if !tb.overlaps(within) {
                continue;
            }
            let longest = (0..3)
                .map(|k| geom::norm2(geom::sub(t[k], t[(k + 1) % 3])))
                .fold(0.0, f64::max)
                .sqrt();
            if !(longest > spacing) {
                continue;
            }
            let n = ((longest / spacing).ceil() as usize).min(4096);
            for i in 0..=n {
                for j in 0..=n - i {
                    let k = n - i - j;
                    if i == n || j == n || k == n {
                        continue; // a corner: already a vertex
                    }
                    let (a, b) = (i as f64 / n as f64, j as f64 / n as f64);
                    let p = geom::add(
                        t[2],
                        geom::add(
                            geom::scale(geom::sub(t[0], t[2]), a),
                            geom::scale(geom::sub(t[1], t[2]), b),
                        ),
                    );
                    if within.contains(p) {
                        out.push(p);
                    }
                }
            }
        }
        out
    }
}

fn tri_area(t: &[V; 3]) -> f64 {
    0.5 * geom::norm2(geom::cross(geom::sub(t[1], t[0]), geom::sub(t[2], t[0]))).sqrt()
}

/// Options of the metrics.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MetricsOptions {
    /// Number of sample points for R_volume (the paper: 10^6).
    pub points: usize,
    /// Seed of the sampling; the same seed gives the same points.
    pub seed: u64,
    /// Points per sampling column (one ray per column and object). 8 amortises the ray well;
    /// the columns are stratified, so larger values do not add variance.
    pub points_per_column: usize,
    /// Spacing of the surface samples for the penetration depth of meshes, metres; `None`:
    /// 1/64 of the smaller object's bounding-box diagonal.
    pub depth_spacing: Option<f64>,
}

impl Default for MetricsOptions {
    fn default() -> Self {
        MetricsOptions {
            points: 1_000_000,
            seed: 0x001A_7E3D,
            points_per_column: 8,
            depth_spacing: None,
        }
    }
}

/// The R_volume estimate with its counts.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct VolumeEstimate {
    pub r_volume: f64,
    /// Points sampled (0 when the boxes are disjoint: no sampling needed).
    pub points: u64,
    pub inside_a: u64,
    pub inside_b: u64,
    pub inside_both: u64,
    pub seed: u64,
}

/// All metrics of one pair.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PairMetrics {
    pub r_volume: f64,
    pub r_surface: f64,
    /// Metres, >= 0; 0 when not overlapping.
    pub max_penetration_depth: f64,
    /// Metres, >= 0; 0 when overlapping or touching.
    pub min_clearance: f64,
    /// Sample points of R_volume.
    pub points: u64,
    /// Points inside at least one / inside both.
    pub inside_either: u64,
    pub inside_both: u64,
    pub seed: u64,
}

/// Metrics of the pair (a, b) of a scene, `a < b` indexing the input.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ScenePair {
    pub a: usize,
    pub b: usize,
    #[serde(flatten)]
    pub metrics: PairMetrics,
}

/// How the points of one axis are laid out in columns.
struct AxisLayout {
    axis: usize,
    uv: [usize; 2],
    points: usize,
    columns: usize,
    /// Stratification grid over the face (gu * gv <= columns; the rest are unstratified).
    gu: usize,
    gv: usize,
}

impl AxisLayout {
    fn new(axis: usize, points: usize, per_col: usize, ext: V) -> AxisLayout {
        let uv = [(axis + 1) % 3, (axis + 2) % 3];
        let columns = points.div_ceil(per_col);
        let (eu, ev) = (ext[uv[0]], ext[uv[1]]);
        let gu = ((columns as f64 * eu / ev).sqrt().round() as usize).clamp(1, columns.max(1));
        let gv = (columns / gu).max(1);
        let (gu, gv) = if gu * gv > columns { (0, 0) } else { (gu, gv) };
        AxisLayout {
            axis,
            uv,
            points,
            columns,
            gu,
            gv,
        }
    }
}

#[derive(Clone, Copy, Default)]
struct Counts {
    a: u64,
    b: u64,
    both: u64,
    total: u64,
}

/// Scratch buffers of one worker.
#[derive(Default)]
struct Scratch {
    ts: Vec<f64>,
    line: Vec<f64>,
    other: Vec<f64>,
    ins_a: Vec<bool>,
}

/// Inside flags of the points `p(t) = base with p[axis] = t` for t in `ts`.
fn classify_column(
    s: &Prepared,
    axis: usize,
    base: V,
    ts: &[f64],
    line: &mut Vec<f64>,
    other: &mut Vec<f64>,
    out: &mut Vec<bool>,
) {
    out.clear();
    out.resize(ts.len(), false);
    let bb = &s.bb;
    let uv = [(axis + 1) % 3, (axis + 2) % 3];
    if uv
        .iter()
        .any(|&k| base[k] < bb.min[k] || base[k] > bb.max[k])
    {
        return;
    }
    match &s.shape {
        Shape::Mesh(m) => {
            let mut have_line = false;
            for (o, &t) in out.iter_mut().zip(ts) {
                if t < bb.min[axis] || t > bb.max[axis] {
                    continue;
                }
                if !have_line {
                    m.crossings(axis, base, line);
                    have_line = true;
                }
                let mut p = base;
                p[axis] = t;
                *o = m.classify(p, axis, line, other);
            }
        }
        Shape::Hulls(_, Some(g)) => {
            // Each cell of the grid is resolved once (inside, outside, or the few plane tests
            // its points still need): the same answers as testing every hull, see `hullgrid`.
            let Some(col) = g.column(axis, base) else {
                return;
            };
            for (o, &t) in out.iter_mut().zip(ts) {
                let mut p = base;
                p[axis] = t;
                *o = g.contains_in(col, p);
            }
        }
        Shape::Hulls(hs, None) => {
            // Only the hulls whose box the column passes through can hold its points.
            let crossed: Vec<&Hull> = hs
                .iter()
                .filter(|h| {
                    uv.iter()
                        .all(|&k| h.bb.min[k] <= base[k] && base[k] <= h.bb.max[k])
                })
                .collect();
            for (o, &t) in out.iter_mut().zip(ts) {
                let mut p = base;
                p[axis] = t;
                *o = crossed.iter().any(|h| h.contains(p));
            }
        }
    }
}

fn column_seed(seed: u64, axis: usize, c: usize) -> u64 {
    let mut r = Rng(seed ^ ((axis as u64 + 1) << 58));
    r.0 ^= r.next_u64() ^ (c as u64).wrapping_mul(0xD6E8_FEB8_6659_FD93);
    r.next_u64()
}

#[allow(clippy::too_many_arguments)]
fn count_columns(
    a: &Prepared,
    b: &Prepared,
    bx: &Bb,
    lay: &AxisLayout,
    per_col: usize,
    seed: u64,
    cols: std::ops::Range<usize>,
    s: &mut Scratch,
) -> Counts {
    let ext = geom::sub(bx.max, bx.min);
    let mut c = Counts::default();
    let mut ins_b = Vec::new();
    for col in cols {
        let mut rng = Rng(column_seed(seed, lay.axis, col));
        let (r0, r1) = (rng.next_f64(), rng.next_f64());
        let (fu, fv) = if col < lay.gu * lay.gv {
            let (iu, iv) = (col % lay.gu, col / lay.gu);
            (
                (iu as f64 + r0) / lay.gu as f64,
                (iv as f64 + r1) / lay.gv as f64,
            )
        } else {
            (r0, r1)
        };
        let mut base = [0.0; 3];
        base[lay.uv[0]] = bx.min[lay.uv[0]] + fu * ext[lay.uv[0]];
        base[lay.uv[1]] = bx.min[lay.uv[1]] + fv * ext[lay.uv[1]];
        let m = if col + 1 == lay.columns {
            lay.points - per_col * (lay.columns - 1)
        } else {
            per_col
        };
        s.ts.clear();
        s.ts.extend((0..m).map(|_| bx.min[lay.axis] + rng.next_f64() * ext[lay.axis]));
        classify_column(
            a,
            lay.axis,
            base,
            &s.ts,
            &mut s.line,
            &mut s.other,
            &mut s.ins_a,
        );
        classify_column(
            b,
            lay.axis,
            base,
            &s.ts,
            &mut s.line,
            &mut s.other,
            &mut ins_b,
        );
        for (&x, &y) in s.ins_a.iter().zip(&ins_b) {
            c.a += x as u64;
            c.b += y as u64;
            c.both += (x && y) as u64;
        }
        c.total += m as u64;
    }
    c
}

/// R_volume of the pair, with its counts.
pub fn r_volume(a: &Prepared, b: &Prepared, opts: &MetricsOptions) -> VolumeEstimate {
    let mut est = VolumeEstimate {
        r_volume: 0.0,
        points: 0,
        inside_a: 0,
        inside_b: 0,
        inside_both: 0,
        seed: opts.seed,
    };
    if a.surface.is_empty() || b.surface.is_empty() || !a.bb.overlaps(&b.bb) || opts.points == 0 {
        return est;
    }
    let bx = a.bb.merge(&b.bb);
    let ext = geom::sub(bx.max, bx.min);
    if ext.iter().any(|&e| !(e > 0.0)) {
        return est; // flat box: no volume
    }
    let per_col = opts.points_per_column.max(1);
    let layouts: Vec<AxisLayout> = (0..3)
        .map(|ax| {
            let n = opts.points / 3 + usize::from(ax < opts.points % 3);
            AxisLayout::new(ax, n, per_col, ext)
        })
        .collect();
    const CHUNK: usize = 2048;
    let jobs: Vec<(usize, usize)> = layouts
        .iter()
        .enumerate()
        .filter(|(_, l)| l.points > 0)
        .flat_map(|(i, l)| (0..l.columns).step_by(CHUNK).map(move |s| (i, s)))
        .collect();
    let c = jobs
        .par_iter()
        .map_init(Scratch::default, |s, &(i, start)| {
            let l = &layouts[i];
            count_columns(
                a,
                b,
                &bx,
                l,
                per_col,
                opts.seed,
                start..(start + CHUNK).min(l.columns),
                s,
            )
        })
        .reduce(Counts::default, |x, y| Counts {
            a: x.a + y.a,
            b: x.b + y.b,
            both: x.both + y.both,
            total: x.total + y.total,
        });
    let either = c.a + c.b - c.both;
    est.points = c.total;
    est.inside_a = c.a;
    est.inside_b = c.b;
    est.inside_both = c.both;
    est.r_volume = if either == 0 {
        0.0
    } else {
        c.both as f64 / either as f64
    };
    est
}

/// R_surface: area of the triangles of A and B that intersect the other's surface, over
/// area(A) + area(B).
pub fn r_surface(a: &Prepared, b: &Prepared) -> f64 {
    let total = a.area + b.area;
    if !(total > 0.0) || !a.bb.overlaps(&b.bb) {
        return 0.0;
    }
    let mut ha = vec![false; a.surface.tris.len()];
    let mut hb = vec![false; b.surface.tris.len()];
    a.surface.overlapping_pairs(&b.surface, |i, j| {
        if !(ha[i] && hb[j]) && geom::tri_tri_intersect(&a.surface.tris[i], &b.surface.tris[j]) {
            ha[i] = true;
            hb[j] = true;
        }
        true
    });
    let sum = |h: &[bool], tris: &[[V; 3]]| -> f64 {
        h.iter()
            .zip(tris)
            .filter(|(&x, _)| x)
            .fold(0.0, |s, (_, t)| s + tri_area(t))
    };
    (sum(&ha, &a.surface.tris) + sum(&hb, &b.surface.tris)) / total
}

/// Whether a vertex of one object lies inside the other.
fn some_vertex_inside(a: &Prepared, b: &Prepared) -> bool {
    let any = |src: &Prepared, dst: &Prepared| src.verts.par_iter().any(|p| dst.contains_v(*p));
    any(a, b) || any(b, a)
}

/// Minimum clearance (metres): 0 when the objects overlap or touch, else the exact distance
/// between their surfaces.
pub fn min_clearance(a: &Prepared, b: &Prepared) -> f64 {
    if a.surface.is_empty() || b.surface.is_empty() {
        return f64::INFINITY;
    }
    if surfaces_intersect(a, b) || some_vertex_inside(a, b) {
        return 0.0;
    }
    a.surface.min_dist2(&b.surface).sqrt()
}

/// Whether any triangle of one touches a triangle of the other (stops at the first).
fn surfaces_intersect(a: &Prepared, b: &Prepared) -> bool {
    let mut hit = false;
    a.surface.overlapping_pairs(&b.surface, |i, j| {
        hit = geom::tri_tri_intersect(&a.surface.tris[i], &b.surface.tris[j]);
        !hit
    });
    hit
}

/// Maximum penetration depth (metres, >= 0; 0 when not overlapping). See the module
/// documentation for the definition on meshes and on hull sets.
pub fn max_penetration_depth(a: &Prepared, b: &Prepared, opts: &MetricsOptions) -> f64 {
    if !a.bb.overlaps(&b.bb) {
        return 0.0;
    }
    if let (Shape::Hulls(ha, _), Shape::Hulls(hb, _)) = (&a.shape, &b.shape) {
        let pairs: Vec<(usize, usize)> = (0..ha.len())
            .flat_map(|i| (0..hb.len()).map(move |j| (i, j)))
            .filter(|&(i, j)| ha[i].bb.overlaps(&hb[j].bb))
            .collect();
        return pairs
            .par_iter()
            .map(|&(i, j)| ha[i].penetration(&hb[j]))
            .reduce(|| 0.0, f64::max);
    }
    let diag = |p: &Prepared| geom::norm2(geom::sub(p.bb.max, p.bb.min)).sqrt();
    let spacing = opts
        .depth_spacing
        .unwrap_or_else(|| diag(a).min(diag(b)) / 64.0);
    let into =
        |src: &Prepared, dst: &Prepared| dst.max_depth_of(&src.surface_samples(&dst.bb, spacing));
    into(a, b).max(into(b, a))
}

/// All four metrics of a pair.
pub fn pair_metrics(a: &Prepared, b: &Prepared, opts: &MetricsOptions) -> PairMetrics {
    let vol = r_volume(a, b, opts);
    let r_surface = r_surface(a, b);
    let depth = max_penetration_depth(a, b, opts);
    let min_clearance = if depth > 0.0 || r_surface > 0.0 {
        0.0
    } else {
        min_clearance(a, b)
    };
    PairMetrics {
        r_volume: vol.r_volume,
        r_surface,
        max_penetration_depth: depth,
        min_clearance,
        points: vol.points,
        inside_either: vol.inside_a + vol.inside_b - vol.inside_both,
        inside_both: vol.inside_both,
        seed: vol.seed,
    }
}

/// Metrics of every pair (i < j) of a scene, in order (0,1), (0,2), …, (1,2), …; objects are
/// prepared once, pairs run in parallel, results do not depend on the thread count.
pub fn scene_metrics(solids: &[Solid], opts: &MetricsOptions) -> Vec<ScenePair> {
    let prepared: Vec<Prepared> = solids.par_iter().map(|s| Prepared::new(*s)).collect();
    scene_metrics_prepared(&prepared, opts)
}

/// [`scene_metrics`] on objects already prepared.
pub fn scene_metrics_prepared(objects: &[Prepared], opts: &MetricsOptions) -> Vec<ScenePair> {
    let n = objects.len();
    let pairs: Vec<(usize, usize)> = (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .collect();
    pairs
        .par_iter()
        .map(|&(a, b)| ScenePair {
            a,
            b,
            metrics: pair_metrics(&objects[a], &objects[b], opts),
        })
        .collect()
}
