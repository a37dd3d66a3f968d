//! Guidance as a separate reconstruction (issue #34): what a generated scene mesh, segmented,
//! gives for a pair of objects — not the objects' own surfaces with holes, but a new surface
//! with its own vertices.
//!
//! Entry points:
//! - [`make`]: the guidance parts of a ground-truth scene. The union of the posed objects
//!   becomes a truncated signed distance field on a grid whose spacing is tied to the scene
//!   (the whole reconstruction has the triangle budget of its parts, 20k–70k triangles each),
//!   blurred by a Gaussian of 0.5–1 % of the scene's diagonal (sharp edges rounded, the gap at
//!   the contact fused into one surface), with parts thinner than the blur thickened instead of
//!   lost, and meshed by surface nets. Each object's segment is the surface nearest to it plus a
//!   strip of the neighbour's that the segmentation bleeds across the contact. Then, sized to
//!   each object: a smooth warp and a volume-preserving stretch of ±1 % along random axes (the
//!   generated shape differs slightly from the user's mesh), a
//!   hole around the contact, three random holes of radius 12 % of the diagonal, Gaussian noise
//!   of 0.3 % of the diagonal and a colour tint, in a random guidance frame;
//! - [`ReconOptions`]: its knobs.
//!
//! Colour comes through the UV of the nearest true surface point, so textured objects keep
//! their print. Every random draw comes from the generator's own stream.

use super::kdtree::KdTree;
use super::synth::{Synthetic, TruthObject};
use super::ObjectInput;
use crate::mesh::{triangle_area, VisualMesh, VisualPart, P3, V3};
use crate::pose::Similarity;
use crate::rng::Rng;
use nalgebra::{UnitQuaternion, Vector3};
use rayon::prelude::*;

/// Knobs of the reconstruction (lengths as fractions of the scene's or each object's diagonal).
#[derive(Clone, Debug)]
pub struct ReconOptions {
    /// Triangles per guidance part, drawn uniformly in this range; the grid is sized so the
    /// whole reconstruction has the sum.
    pub triangles: [usize; 2],
    /// Gaussian blur of the signed distance field, fraction of the scene diagonal.
    pub blur: [f64; 2],
    /// Width of the strip of the neighbour that each segment bleeds over, fraction of the
    /// object's diagonal.
    pub bleed: [f64; 2],
    /// Amplitude of the smooth warp, fraction of the object's diagonal.
    pub warp: f64,
    /// Log-stretch of each of two random axes (the third keeps the volume).
    pub stretch: f64,
    pub contact_hole: f64,
    pub random_holes: usize,
    pub random_hole_radius: f64,
    pub noise: f64,
    pub max_tilt_deg: f64,
    pub scale: [f64; 2],
    pub colour_gain: f64,
    /// Upper bound on grid points (memory): the spacing grows past it.
    pub max_grid_points: usize,
}

impl Default for ReconOptions {
    fn default() -> Self {
        ReconOptions {
            triangles: [20_000, 70_000],
            blur: [0.005, 0.01],
            bleed: [0.02, 0.05],
            warp: 0.003,
            stretch: 0.01,
            contact_hole: 0.12,
            random_holes: 3,
            random_hole_radius: 0.12,
            noise: 0.003,
            max_tilt_deg: 10.0,
            scale: [0.5, 2.0],
            colour_gain: 0.1,
            max_grid_points: 4_000_000,
        }
    }
}

/// A point of the true surface: where, facing where, and whose (object, part, UV).
#[derive(Clone, Copy)]
struct Sample {
    p: P3,
    n: V3,
    obj: u16,
    part: u16,
    uv: [f64; 2],
}

/// Area-uniform samples of the placed objects, about `spacing` apart.
fn samples(placed: &[VisualMesh], spacing: f64, rng: &mut Rng) -> Vec<Sample> {
    let mut out = Vec::new();
    let per_area = 1.0 / (spacing * spacing);
    for (oi, v) in placed.iter().enumerate() {
        for (pi, part) in v.parts.iter().enumerate() {
            for t in &part.triangles {
                let q = t.map(|k| part.positions[k as usize]);
                let a = triangle_area(&q);
                if !(a > 0.0 && a.is_finite()) {
                    continue;
                }
                let n = (q[1] - q[0]).cross(&(q[2] - q[0])).normalize();
                let want = a * per_area;
                let count = want.floor() as usize + usize::from(rng.next_f64() < want.fract());
                for _ in 0..count {
                    let (r1, r2) = (rng.next_f64().sqrt(), rng.next_f64());
                    let w = [1.0 - r1, r1 * (1.0 - r2), r1 * r2];
                    let p = P3::from(q[0].coords * w[0] + q[1].coords * w[1] + q[2].coords * w[2]);
                    let uv = part.uvs.as_ref().map_or([0.0; 2], |uv| {
                        let u = t.map(|k| uv[k as usize]);
                        [
                            u[0][0] * w[0] + u[1][0] * w[1] + u[2][0] * w[2],
                            u[0][1] * w[0] + u[1][1] * w[1] + u[2][1] * w[2],
                        ]
                    });
                    out.push(Sample {
                        p,
                        n,
                        obj: oi as u16,
                        part: pi as u16,
                        uv,
                    });
                }
            }
        }
    }
    out
}

/// A regular grid of `dims` points, `h` apart, from `origin`.
struct Grid {
    origin: P3,
    h: f64,
    dims: [usize; 3],
}

impl Grid {
    fn len(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }
    fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.dims[1] + j) * self.dims[0] + i
    }
    fn point(&self, idx: usize) -> P3 {
        let i = idx % self.dims[0];
        let j = (idx / self.dims[0]) % self.dims[1];
        let k = idx / (self.dims[0] * self.dims[1]);
        self.origin + V3::new(i as f64, j as f64, k as f64) * self.h
    }
    /// Stride of one step along `axis`.
    fn stride(&self, axis: usize) -> usize {
        match axis {
            0 => 1,
            1 => self.dims[0],
            _ => self.dims[0] * self.dims[1],
        }
    }

    /// Apply `f` to every line of values along `axis` (in place, through a scratch copy).
    fn lines(&self, v: &mut [f32], axis: usize, mut f: impl FnMut(&[f32], &mut [f32])) {
        let n = self.dims[axis];
        let s = self.stride(axis);
        let mut src = vec![0f32; n];
        let mut dst = vec![0f32; n];
        for start in 0..self.len() {
            // A line starts where the coordinate along `axis` is 0.
            if (start / s) % n != 0 {
                continue;
            }
            for t in 0..n {
                src[t] = v[start + t * s];
            }
            f(&src, &mut dst);
            for t in 0..n {
                v[start + t * s] = dst[t];
            }
        }
    }
}

/// Separable Gaussian blur of standard deviation `sigma` cells (borders clamped).
fn blur(g: &Grid, v: &mut [f32], sigma: f64) {
    let r = (3.0 * sigma).ceil() as i64;
    let w: Vec<f32> = (-r..=r)
        .map(|x| (-(x * x) as f64 / (2.0 * sigma * sigma)).exp() as f32)
        .collect();
    let norm: f32 = w.iter().sum();
    for axis in 0..3 {
        g.lines(v, axis, |src, dst| {
            let n = src.len() as i64;
            for (t, d) in dst.iter_mut().enumerate() {
                let mut acc = 0f32;
                for (q, wq) in w.iter().enumerate() {
                    let u = (t as i64 + q as i64 - r).clamp(0, n - 1);
                    acc += wq * src[u as usize];
                }
                *d = acc / norm;
            }
        });
    }
}

/// Separable maximum over a cube of radius `r` cells.
fn max_filter(g: &Grid, v: &mut [f32], r: usize) {
    for axis in 0..3 {
        g.lines(v, axis, |src, dst| {
            let n = src.len();
            for (t, d) in dst.iter_mut().enumerate() {
                let lo = t.saturating_sub(r);
                let hi = (t + r + 1).min(n);
                *d = src[lo..hi]
                    .iter()
                    .cloned()
                    .fold(f32::NEG_INFINITY, f32::max);
            }
        });
    }
}

/// Surface nets of the zero level set of `f` (negative inside): one vertex per cell the surface
/// crosses (the mean of its edge crossings), one quad per crossed grid edge, faces outward.
fn surface_nets(g: &Grid, f: &[f32]) -> (Vec<P3>, Vec<[u32; 3]>) {
    let [nx, ny, nz] = g.dims;
    let cells = (nx - 1) * (ny - 1) * (nz - 1);
    let cell_index = |i: usize, j: usize, k: usize| (k * (ny - 1) + j) * (nx - 1) + i;
    let mut vert_of = vec![u32::MAX; cells];
    let mut verts = Vec::new();
    const CORNERS: [[usize; 3]; 8] = [
        [0, 0, 0],
        [1, 0, 0],
        [0, 1, 0],
        [1, 1, 0],
        [0, 0, 1],
        [1, 0, 1],
        [0, 1, 1],
        [1, 1, 1],
    ];
    const EDGES: [[usize; 2]; 12] = [
        [0, 1],
        [2, 3],
        [4, 5],
        [6, 7],
        [0, 2],
        [1, 3],
        [4, 6],
        [5, 7],
        [0, 4],
        [1, 5],
        [2, 6],
        [3, 7],
    ];
    for k in 0..nz - 1 {
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let val = CORNERS.map(|c| f[g.index(i + c[0], j + c[1], k + c[2])]);
                let inside = val.iter().filter(|&&x| x < 0.0).count();
                if inside == 0 || inside == 8 {
                    continue;
                }
                let mut acc = V3::zeros();
                let mut n = 0.0;
                for e in EDGES {
                    let (a, b) = (val[e[0]], val[e[1]]);
                    if (a < 0.0) != (b < 0.0) {
                        let t = (a / (a - b)) as f64;
                        let ca = CORNERS[e[0]].map(|x| x as f64);
                        let cb = CORNERS[e[1]].map(|x| x as f64);
                        acc += V3::new(
                            ca[0] + t * (cb[0] - ca[0]),
                            ca[1] + t * (cb[1] - ca[1]),
                            ca[2] + t * (cb[2] - ca[2]),
                        );
                        n += 1.0;
                    }
                }
                let local = acc / n;
                vert_of[cell_index(i, j, k)] = verts.len() as u32;
                verts.push(g.origin + (V3::new(i as f64, j as f64, k as f64) + local) * g.h);
            }
        }
    }
    let mut tris = Vec::new();
    // Each grid edge from (i, j, k) along `axis` whose ends differ in sign: the four cells
    // around it, in order around the axis.
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let a = f[g.index(i, j, k)];
                for axis in 0..3 {
                    let [di, dj, dk] = match axis {
                        0 => [1, 0, 0],
                        1 => [0, 1, 0],
                        _ => [0, 0, 1],
                    };
                    let (bi, bj, bk) = (i + di, j + dj, k + dk);
                    if bi >= nx || bj >= ny || bk >= nz {
                        continue;
                    }
                    let b = f[g.index(bi, bj, bk)];
                    if (a < 0.0) == (b < 0.0) {
                        continue;
                    }
                    // The two other axes (u, v) with (axis, u, v) right-handed.
                    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                    let base = [i, j, k];
                    if base[u] == 0
                        || base[v] == 0
                        || base[u] + 1 >= g.dims[u]
                        || base[v] + 1 >= g.dims[v]
                    {
                        continue;
                    }
                    let cell = |du: usize, dv: usize| {
                        let mut c = base;
                        c[u] = c[u] + du - 1;
                        c[v] = c[v] + dv - 1;
                        vert_of[cell_index(c[0], c[1], c[2])]
                    };
                    let q = [cell(0, 0), cell(1, 0), cell(1, 1), cell(0, 1)];
                    if q.contains(&u32::MAX) {
                        continue;
                    }
                    // Inside at the lower end: the surface faces +axis, (u, v) counter-clockwise.
                    let q = if a < 0.0 { q } else { [q[0], q[3], q[2], q[1]] };
                    tris.push([q[0], q[1], q[2]]);
                    tris.push([q[0], q[2], q[3]]);
                }
            }
        }
    }
    (verts, tris)
}

fn hash(a: u64, b: u64) -> u64 {
    Rng::new(a.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ b.rotate_left(29)).next_u64()
}

fn unit_f(h: u64) -> f64 {
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// Guidance parts for a ground-truth scene (see the module doc).
pub fn make(objects: &[TruthObject], seed: u64, o: &ReconOptions) -> Synthetic {
    let mut rng = Rng::new(seed ^ 0x5EC0_4517_0C7E_D000);
    let scene_bb = super::synth::scene_box(objects);
    let yaw =
        UnitQuaternion::from_axis_angle(&Vector3::y_axis(), rng.range(0.0, std::f64::consts::TAU));
    let tilt_axis = Vector3::new(rng.range(-1.0, 1.0), 0.0, rng.range(-1.0, 1.0));
    let tilt = UnitQuaternion::from_axis_angle(
        &nalgebra::Unit::new_normalize(tilt_axis + Vector3::new(1e-9, 0.0, 0.0)),
        rng.range(0.0, o.max_tilt_deg).to_radians(),
    );
    let frame = Similarity {
        scale: rng.range(o.scale[0].ln(), o.scale[1].ln()).exp(),
        rotation: tilt * yaw,
        translation: V3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        ) * scene_bb.diagonal(),
    };
    let truth: Vec<Similarity> = objects.iter().map(|t| frame.then_after(&t.pose)).collect();
    let placed = super::synth::placed(objects, &truth);
    let bb = placed
        .iter()
        .filter_map(|v| v.geometry().aabb())
        .reduce(|a, b| a.union(&b))
        .expect("scene has geometry");
    let diag = bb.diagonal();
    let obj_diag: Vec<f64> = placed
        .iter()
        .map(|v| v.geometry().aabb().map_or(diag, |b| b.diagonal()))
        .collect();
    let area: f64 = placed.iter().map(|v| v.area()).sum();

    // The grid: surface nets give about 3 triangles per h² of surface.
    let budget: usize = objects
        .iter()
        .map(|_| o.triangles[0] + rng.below(o.triangles[1] - o.triangles[0] + 1))
        .sum();
    let sigma = rng.range(o.blur[0], o.blur[1]) * diag;
    let mut h = (3.0 * area / budget as f64).sqrt();
    let band_of = |h: f64| 3.0 * sigma + 3.0 * h;
    let dims_of = |h: f64| {
        let pad = band_of(h) + 2.0 * h;
        let e = bb.extents();
        [e.x, e.y, e.z].map(|x| ((x + 2.0 * pad) / h).ceil() as usize + 1)
    };
    while dims_of(h).iter().product::<usize>() > o.max_grid_points {
        h *= 1.1;
    }
    let band = band_of(h);
    let pad = band + 2.0 * h;
    let grid = Grid {
        origin: bb.min - V3::repeat(pad),
        h,
        dims: dims_of(h),
    };

    // The true surface, finely sampled, and a tree per object.
    let all = samples(&placed, h / 3.0, &mut rng);
    let by_obj: Vec<Vec<usize>> = (0..placed.len())
        .map(|oi| {
            (0..all.len())
                .filter(|&s| all[s].obj as usize == oi)
                .collect()
        })
        .collect();
    let trees: Vec<KdTree> = by_obj
        .iter()
        .map(|ix| KdTree::new(&ix.iter().map(|&s| all[s].p).collect::<Vec<_>>()))
        .collect();
    // The nearest sample over all objects: (sample, distance) per object, then the closest.
    let nearest = |p: &P3| -> Vec<Option<(usize, f64)>> {
        trees
            .iter()
            .zip(&by_obj)
            .map(|(t, ix)| t.nearest(p).map(|(i, d2)| (ix[i], d2.sqrt())))
            .collect()
    };
    let spacing = h / 3.0;
    // Distance to the surface near a sample: to its plane when the point lies over it.
    let surface_distance = |p: &P3, s: &Sample| -> f64 {
        let d = p - s.p;
        let along = d.dot(&s.n);
        let tangential = (d.norm_squared() - along * along).max(0.0).sqrt();
        if tangential < 2.0 * spacing {
            along.abs()
        } else {
            d.norm()
        }
    };

    // Grid points within the band: those near a sample.
    let n_pts = grid.len();
    let mut near = vec![0f32; n_pts];
    for s in &all {
        let c = (s.p - grid.origin) / h;
        let (i, j, k) = (
            c.x.round() as usize,
            c.y.round() as usize,
            c.z.round() as usize,
        );
        near[grid.index(i, j, k)] = 1.0;
    }
    max_filter(&grid, &mut near, (band / h).ceil() as usize);
    // Truncated signed distance (sign from the nearest sample's normal) and unsigned distance.
    let vals: Vec<Option<(f32, f32)>> = (0..n_pts)
        .into_par_iter()
        .map(|idx| {
            if near[idx] == 0.0 {
                return None;
            }
            let p = grid.point(idx);
            let best = nearest(&p)
                .into_iter()
                .flatten()
                .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))?;
            let s = &all[best.0];
            let d = surface_distance(&p, s).min(band);
            let sign = if (p - s.p).dot(&s.n) < 0.0 { -1.0 } else { 1.0 };
            Some(((sign * d) as f32, d as f32))
        })
        .collect();
    // Far from the surface: outside when reached from the border without crossing the band.
    let mut outside = vec![false; n_pts];
    let mut stack: Vec<usize> = Vec::new();
    for idx in 0..n_pts {
        let p = grid.point(idx);
        let c = (p - grid.origin) / h;
        let border = [c.x, c.y, c.z]
            .iter()
            .zip(grid.dims)
            .any(|(&x, d)| x.round() as usize == 0 || x.round() as usize == d - 1);
        if border && vals[idx].is_none() {
            outside[idx] = true;
            stack.push(idx);
        }
    }
    while let Some(idx) = stack.pop() {
        let i = idx % grid.dims[0];
        let j = (idx / grid.dims[0]) % grid.dims[1];
        let k = idx / (grid.dims[0] * grid.dims[1]);
        let mut push = |ii: usize, jj: usize, kk: usize| {
            let q = grid.index(ii, jj, kk);
            if !outside[q] && vals[q].is_none() {
                outside[q] = true;
                stack.push(q);
            }
        };
        if i > 0 {
            push(i - 1, j, k);
        }
        if i + 1 < grid.dims[0] {
            push(i + 1, j, k);
        }
        if j > 0 {
            push(i, j - 1, k);
        }
        if j + 1 < grid.dims[1] {
            push(i, j + 1, k);
        }
        if k > 0 {
            push(i, j, k - 1);
        }
        if k + 1 < grid.dims[2] {
            push(i, j, k + 1);
        }
    }
    let sdf: Vec<f32> = (0..n_pts)
        .map(|idx| match vals[idx] {
            Some((s, _)) => s,
            None if outside[idx] => band as f32,
            None => -(band as f32),
        })
        .collect();
    let mut field = sdf.clone();
    blur(&grid, &mut field, sigma / h);
    // Parts thinner than the blur would vanish: where the solid is nowhere deeper than 1.2σ
    // within 2σ, the surface is kept, thickened by 0.6 h on each side (what a reconstruction
    // at this resolution does to a plate's rim, a spoon or an open shell).
    let mut depth: Vec<f32> = sdf.iter().map(|&s| (-s).max(0.0)).collect();
    max_filter(&grid, &mut depth, (2.0 * sigma / h).ceil() as usize);
    let tau = 0.6 * h;
    for idx in 0..n_pts {
        if let Some((s, d)) = vals[idx] {
            if (depth[idx] as f64) < 1.2 * sigma {
                let thin = if s < 0.0 { -tau } else { d as f64 - tau };
                field[idx] = field[idx].min(thin as f32);
            }
        }
    }
    let (mut verts, tris) = surface_nets(&grid, &field);

    // Segmentation: each vertex belongs to the object whose surface is nearest; each segment
    // also takes the neighbour's surface within its bleed width of the object.
    let info: Vec<(usize, Vec<f64>)> = verts
        .par_iter()
        .map(|p| {
            let nn = nearest(p);
            let d: Vec<f64> = nn
                .iter()
                .map(|x| x.map_or(f64::INFINITY, |(s, _)| surface_distance(p, &all[s])))
                .collect();
            let owner = nn
                .iter()
                .flatten()
                .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
                .map_or(0, |x| x.0);
            (owner, d)
        })
        .collect();
    // A smooth warp per object: the generated shape is not quite the user's mesh.
    let warps: Vec<[(V3, f64); 3]> = (0..objects.len())
        .map(|_| {
            [0, 1, 2].map(|_| {
                let dir = V3::new(rng.normal(), rng.normal(), rng.normal()).normalize();
                (dir, rng.range(0.0, std::f64::consts::TAU))
            })
        })
        .collect();
    // And a volume-preserving stretch along random axes (proportions off by up to ±2·stretch).
    let stretches: Vec<nalgebra::Matrix3<f64>> = placed
        .iter()
        .map(|_| {
            let r = rng.rotation().to_rotation_matrix().into_inner();
            let a = rng.range(-o.stretch, o.stretch);
            let b = rng.range(-o.stretch, o.stretch);
            let f = nalgebra::Matrix3::from_diagonal(&V3::new(a.exp(), b.exp(), (-a - b).exp()));
            r * f * r.transpose()
        })
        .collect();
    let centres: Vec<P3> = placed
        .iter()
        .map(|v| v.geometry().aabb().map_or(bb.center(), |b| b.center()))
        .collect();
    for (v, (s, _)) in verts.iter_mut().zip(&info) {
        let oi = all[*s].obj as usize;
        *v = centres[oi] + stretches[oi] * (*v - centres[oi]);
        let k = std::f64::consts::TAU / obj_diag[oi];
        let w = &warps[oi];
        let disp = V3::new(
            (k * w[0].0.dot(&v.coords) + w[0].1).sin(),
            (k * w[1].0.dot(&v.coords) + w[1].1).sin(),
            (k * w[2].0.dot(&v.coords) + w[2].1).sin(),
        );
        *v += disp * o.warp * obj_diag[oi];
    }

    let mut inputs = Vec::new();
    let mut removed = Vec::new();
    for (i, t) in objects.iter().enumerate() {
        let d_i = obj_diag[i];
        let bleed = rng.range(o.bleed[0], o.bleed[1]) * d_i;
        let owned = |v: usize| all[info[v].0].obj as usize == i;
        let in_seg: Vec<bool> = (0..verts.len())
            .map(|v| owned(v) || info[v].1[i] < bleed)
            .collect();
        // The contact: this object's vertex nearest to another object.
        let contact = (0..verts.len())
            .filter(|&v| owned(v))
            .map(|v| {
                let other = (0..objects.len())
                    .filter(|&j| j != i)
                    .map(|j| info[v].1[j])
                    .fold(f64::INFINITY, f64::min);
                (other, v)
            })
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut holes: Vec<(P3, f64)> = Vec::new();
        if let Some((_, v)) = contact {
            holes.push((verts[v], o.contact_hole * d_i));
        }
        let own: Vec<usize> = (0..verts.len()).filter(|&v| owned(v)).collect();
        for _ in 0..o.random_holes {
            if !own.is_empty() {
                holes.push((verts[own[rng.below(own.len())]], o.random_hole_radius * d_i));
            }
        }
        let sigma_n = o.noise * d_i;
        // Output parts by (object, part) of the triangle's first vertex.
        let mut groups: std::collections::BTreeMap<(u16, u16), (Vec<u32>, VisualPart)> =
            Default::default();
        let mut map: std::collections::HashMap<((u16, u16), u32), u32> = Default::default();
        let mut kept_area = 0.0;
        for (ti, tr) in tris.iter().enumerate() {
            if !tr.iter().all(|&v| in_seg[v as usize]) {
                continue;
            }
            let q = tr.map(|v| verts[v as usize]);
            let c = P3::from((q[0].coords + q[1].coords + q[2].coords) / 3.0);
            // Ragged rims: each triangle's radius varies by up to 30 %.
            let jag = 1.0 + 0.3 * unit_f(hash(seed ^ i as u64, ti as u64));
            if holes.iter().any(|(hc, r)| (c - hc).norm() * jag < *r) {
                continue;
            }
            kept_area += triangle_area(&q);
            let s0 = &all[info[tr[0] as usize].0];
            let key = (s0.obj, s0.part);
            let src = &placed[s0.obj as usize].parts[s0.part as usize];
            let (_, part) = groups.entry(key).or_insert_with(|| {
                (
                    Vec::new(),
                    VisualPart {
                        positions: Vec::new(),
                        uvs: src.uvs.as_ref().map(|_| Vec::new()),
                        triangles: Vec::new(),
                        material: src.material.clone(),
                    },
                )
            });
            let mut out = [0u32; 3];
            for (c, &v) in tr.iter().enumerate() {
                let next = part.positions.len() as u32;
                let idx = *map.entry((key, v)).or_insert(next);
                if idx == next {
                    let mut r = Rng::new(hash(seed ^ 0xA5 ^ ((i as u64) << 40), v as u64));
                    part.positions.push(
                        verts[v as usize] + V3::new(r.normal(), r.normal(), r.normal()) * sigma_n,
                    );
                    if let Some(uv) = &mut part.uvs {
                        uv.push(all[info[v as usize].0].uv);
                    }
                }
                out[c] = idx;
            }
            part.triangles.push(out);
        }
        let mut parts: Vec<VisualPart> = groups.into_values().map(|g| g.1).collect();
        for q in &mut parts {
            // Its own copy of the texture, as when read from its own file.
            if let Some(tex) = &mut q.material.texture {
                tex.bytes = std::sync::Arc::new(tex.bytes.as_ref().clone());
            }
            for k in 0..3 {
                q.material.base_color[k] = (q.material.base_color[k]
                    * (1.0 + rng.range(-o.colour_gain, o.colour_gain)))
                .clamp(0.0, 1.0);
            }
        }
        removed.push(1.0 - kept_area / placed[i].area().max(1e-300));
        inputs.push(ObjectInput {
            name: t.name.clone(),
            visual: t.visual.clone(),
            guidance: VisualMesh { parts },
        });
    }
    Synthetic {
        inputs,
        truth,
        frame,
        removed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Surface nets of a sphere's distance field: closed, outward, at the right radius.
    #[test]
    fn surface_nets_sphere() {
        let g = Grid {
            origin: P3::new(-1.5, -1.5, -1.5),
            h: 0.1,
            dims: [31, 31, 31],
        };
        let f: Vec<f32> = (0..g.len())
            .map(|i| (g.point(i).coords.norm() - 1.0) as f32)
            .collect();
        let (v, t) = surface_nets(&g, &f);
        let m = crate::mesh::Mesh::new(v.clone(), t);
        assert!(m.is_closed());
        // Volume of the unit sphere, 4π/3 = 4.18879, within 2 %.
        let vol = m.signed_volume();
        assert!((vol - 4.18879).abs() < 0.02 * 4.18879, "volume {vol}");
        let worst = v
            .iter()
            .map(|p| (p.coords.norm() - 1.0).abs())
            .fold(0.0, f64::max);
        assert!(worst < 0.02, "radius off by {worst}");
    }
}
