//! Convex decomposition: each object of a scene becomes a set of convex hulls that a simulator
//! can collide. Engines sit behind [`Decomposer`], which sees the whole scene (world frame), so a
//! scene-aware engine can keep hulls off the neighbours. Every engine's output goes through
//! [`finish`]: at most `max_hulls` hulls per object, at most `max_vertices` vertices per hull,
//! no degenerate or paper-thin hulls. Every engine's hulls then go through [`physx_legal`]: at
//! most `max_polygons` polygons per hull (PhysX re-cooks a hull over 64 polygons into another
//! shape, silently), no slivers PhysX keeps off the GPU, every vertex bulging past PhysX's
//! plane tolerance but those an object's pieces share. With a polygon budget, engines are
//! called with [`DecomposeOptions::engine_budget`], so their hulls are within it as built.

pub mod cache;
mod hull;
pub mod scene_aware;
pub mod vhacd;

pub use hull::{Hull, PhysxLimits, PHYSX_PLANE_TOLERANCE};

use crate::error::Result;
use crate::mesh::Mesh;

/// The default hull budget per object (`DecomposeOptions::max_hulls`, `--max-hulls`).
pub const DEFAULT_MAX_HULLS: usize = 32;

/// PhysX's polygon budget per hull: it re-cooks a hull of more polygons into another shape,
/// silently (`--target isaac` or `--max-hull-polygons 64` keeps every hull within it). Not
/// the default: with the budget in the engine ([`DecomposeOptions::engine_budget`]) it costs
/// +0.08 points of two-sided p95 on average over the 43 shared objects, but up to +1.1 on
/// small round solids (docs/usd.md), so it is asked for by those who export for Isaac.
pub const PHYSX_MAX_POLYGONS: usize = 64;

/// Hulls whose [`Hull::sliver_ratio`] is above this are dropped by [`physx_legal`] (unless they
/// are all an object has): PhysX keeps a convex mesh whose extent/inner-radius ratio passes
/// 100 off the GPU.
pub const MAX_SLIVER_RATIO: f64 = 100.0;

/// Limits every decomposition meets.
#[derive(Clone, Debug, PartialEq)]
pub struct DecomposeOptions {
    /// Most hulls per object.
    pub max_hulls: usize,
    /// Most vertices per hull (PhysX/Isaac accept 64; MuJoCo any).
    pub max_vertices: usize,
    /// Most polygons per hull, coplanar triangles merged (PhysX cooks at most 64 as written;
    /// MuJoCo any). `usize::MAX`: no limit.
    pub max_polygons: usize,
    /// Hulls thinner than this (m) are dropped: MuJoCo refuses near-flat meshes.
    pub min_thickness: f64,
    /// V-HACD voxel resolution along the longest axis.
    pub resolution: u32,
    /// V-HACD concavity threshold (relative).
    pub concavity: f64,
    /// Scene-aware engine: allowed one-sided distance from the hull surfaces to the mesh
    /// (95th percentile), relative to the object's bounding-box diagonal.
    pub tolerance: f64,
    /// Scene-aware engine: smallest distance (m) kept between hulls of different objects.
    pub clearance: f64,
    /// Folder of the decomposition cache (content-addressed); `None`: no cache.
    pub cache_dir: Option<std::path::PathBuf>,
    /// Scene-aware engine: race an object's strategies and drop one far behind at a
    /// checkpoint (`scene_aware/race.rs`); `false` runs every strategy to the end (slower; the
    /// check that the race's margins keep the winner).
    pub race: bool,
}

impl Default for DecomposeOptions {
    fn default() -> Self {
        DecomposeOptions {
            max_hulls: DEFAULT_MAX_HULLS,
            max_vertices: 64,
            max_polygons: usize::MAX,
            min_thickness: 2e-4,
            resolution: 64,
            concavity: 0.01,
            tolerance: 0.01,
            clearance: 1e-4,
            cache_dir: None,
            race: true,
        }
    }
}

impl DecomposeOptions {
    /// The options an engine builds hulls with so that they are within the polygon budget by
    /// construction: with `max_polygons` set, at most `max_polygons / 2 + 2` vertices per hull.
    /// A convex polyhedron of `V` vertices triangulates into exactly `2V − 4` triangles (Euler),
    /// and merging coplanar ones only lowers the count, so such a hull never has more than
    /// `max_polygons` polygons, whatever its shape (34 vertices for PhysX's 64; PhysX's own
    /// re-cooking of round hulls also lands on 34). The engine's quality loop then measures
    /// the hulls it will ship and splits where they deviate, instead of [`physx_legal`]
    /// shrinking them after the fact (docs/usd.md has the cost of both). Without a polygon
    /// budget the options are unchanged.
    pub fn engine_budget(&self) -> DecomposeOptions {
        let mut o = self.clone();
        if self.max_polygons != usize::MAX {
            o.max_vertices = self.max_vertices.min(self.max_polygons / 2 + 2).max(4);
        }
        o
    }

    /// PhysX's plane tolerance, with margin ([`PHYSX_PLANE_TOLERANCE`]), when hulls are built
    /// for it (a polygon budget is set): every hull vertex must bulge out of the hull of the
    /// others by more, or PhysX's cooking skips it. `None` without a polygon budget.
    pub fn plane_tolerance(&self) -> Option<f64> {
        (self.max_polygons != usize::MAX).then_some(PHYSX_PLANE_TOLERANCE)
    }
}

/// A convex decomposition engine.
pub trait Decomposer: Send + Sync {
    /// Short name, recorded in reports.
    fn name(&self) -> &'static str;
    /// Hulls for every object of the scene (`objects` in the world frame, metres), in order.
    fn decompose(&self, objects: &[&Mesh], opts: &DecomposeOptions) -> Result<Vec<Vec<Hull>>>;
    /// Notes on each object from the last `decompose` call (e.g. meshes that interpenetrate a
    /// neighbour, hull overlaps left), for the caller to add to its warnings. Empty by default.
    fn object_warnings(&self) -> Vec<Vec<String>> {
        Vec::new()
    }
    /// The objects' surfaces the last `decompose` call built, in order, handed over once (the
    /// next call returns none): the fidelity measure (`body::assemble`) then need not build
    /// them again from the same meshes. Empty by default, and when nothing was built (a cache
    /// hit).
    fn take_surfaces(&self) -> Vec<Option<scene_aware::geom::Surface>> {
        Vec::new()
    }
}

/// Bring raw hull point sets within the limits: build hulls, drop degenerate ones, merge down to
/// `max_hulls` (cheapest merges first), then simplify each to `max_vertices`.
pub fn finish(raw: Vec<Vec<crate::mesh::P3>>, opts: &DecomposeOptions) -> Vec<Hull> {
    finish_with(raw, opts, Hull::simplified)
}

/// [`finish`] with another way (`reduce`) to bring a hull down to `max_vertices`.
pub fn finish_with(
    raw: Vec<Vec<crate::mesh::P3>>,
    opts: &DecomposeOptions,
    reduce: impl Fn(Hull, usize) -> Option<Hull>,
) -> Vec<Hull> {
    let mut hulls: Vec<Hull> = raw
        .iter()
        .filter_map(|pts| Hull::from_points(pts))
        .filter(|h| h.thickness() >= opts.min_thickness)
        .collect();
    merge_down(&mut hulls, opts.max_hulls);
    hulls
        .into_iter()
        .filter_map(|h| reduce(h, opts.max_vertices))
        .filter(|h| h.thickness() >= opts.min_thickness)
        .collect()
}

/// Merge hulls pairwise until at most `max` remain, each time the pair whose merged hull adds
/// the least volume. Deterministic (ties broken by index).
fn merge_down(hulls: &mut Vec<Hull>, max: usize) {
    while hulls.len() > max.max(1) {
        let mut best: Option<(f64, usize, usize, Hull)> = None;
        for i in 0..hulls.len() {
            for j in i + 1..hulls.len() {
                let gap = hulls[i].aabb.union(&hulls[j].aabb).diagonal();
                // Cheap lower bound first: skip pairs that cannot beat the best.
                if let Some((cost, ..)) = &best {
                    if *cost <= 0.0 && gap > 0.0 {
                        continue;
                    }
                }
                let mut pts = hulls[i].vertices.clone();
                pts.extend_from_slice(&hulls[j].vertices);
                if let Some(m) = Hull::from_points(&pts) {
                    let cost = m.volume - hulls[i].volume - hulls[j].volume;
                    if best.as_ref().is_none_or(|b| cost < b.0) {
                        best = Some((cost, i, j, m));
                    }
                }
            }
        }
        match best {
            Some((_, i, j, m)) => {
                hulls.remove(j);
                hulls[i] = m;
            }
            None => {
                hulls.truncate(max);
            }
        }
    }
}

/// What [`physx_legal`] did to one object's hulls.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LegalNote {
    /// Hulls that lost vertices to fit.
    pub reduced: usize,
    /// Slivers dropped.
    pub dropped: usize,
    /// Hulls no reduction could fit (kept as they were: PhysX will re-cook them).
    pub over: usize,
}

/// Bring every object's hulls within PhysX's cooking limits (`max_vertices`, `max_polygons`,
/// 32 vertices per polygon; see [`Hull::within`]) and drop slivers (see [`MAX_SLIVER_RATIO`]),
/// keeping an object's hulls when all of them are slivers (a thin plate must still collide).
/// Hulls only shrink (their vertices are a subset of the input's), so a decomposition kept off
/// its neighbours stays off them. With `max_polygons == usize::MAX` and the vertex budget met,
/// nothing changes. Returns what was done to each object.
pub fn physx_legal(sets: &mut [Vec<Hull>], opts: &DecomposeOptions) -> Vec<LegalNote> {
    let limits = PhysxLimits {
        max_vertices: opts.max_vertices,
        max_polygons: opts.max_polygons,
        max_polygon_vertices: if opts.max_polygons == usize::MAX {
            usize::MAX
        } else {
            PhysxLimits::default().max_polygon_vertices
        },
        plane_tolerance: opts.plane_tolerance(),
    };
    sets.iter_mut()
        .map(|hulls| {
            let (mut reduced, mut over) = (0, 0);
            let seams = seam_vertices(hulls);
            let pinned = |p: &crate::mesh::P3| seams.binary_search(&key_of(p)).is_ok();
            let mut out = Vec::with_capacity(hulls.len());
            for h in hulls.drain(..) {
                let before = h.vertices.len();
                let fallback = h.clone();
                let h = match h
                    .within_pinned(&limits, &pinned)
                    .filter(|h| h.thickness() >= opts.min_thickness)
                {
                    Some(h) => h,
                    None => {
                        over += 1;
                        fallback
                    }
                };
                if h.vertices.len() != before {
                    reduced += 1;
                }
                out.push(h);
            }
            let dropped = if opts.max_polygons == usize::MAX {
                0
            } else {
                let keep: Vec<bool> = out
                    .iter()
                    .map(|h| h.sliver_ratio() <= MAX_SLIVER_RATIO)
                    .collect();
                if keep.iter().any(|&k| k) {
                    let n = out.len();
                    let mut k = keep.into_iter();
                    out.retain(|_| k.next().unwrap());
                    n - out.len()
                } else {
                    0
                }
            };
            *hulls = out;
            LegalNote {
                reduced,
                dropped,
                over,
            }
        })
        .collect()
}

/// How many hulls PhysX would re-cook: more than [`PHYSX_MAX_POLYGONS`] polygons (counted as
/// [`Hull::polygons`] does, which errs high) or more vertices than its 255. An export without
/// a polygon budget writes such hulls into its USD as they are, and PhysX simulates another
/// shape (`body::assemble` warns with this count).
pub fn physx_recooked(sets: &[Vec<Hull>]) -> usize {
    sets.iter()
        .flatten()
        .filter(|h| h.vertices.len() > 255 || h.polygons().len() > PHYSX_MAX_POLYGONS)
        .count()
}

/// A point's coordinates as bits, to compare points exactly.
fn key_of(p: &crate::mesh::P3) -> [u64; 3] {
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}

/// The keys ([`key_of`], sorted) of the vertices (exactly equal coordinates) that two or more
/// of `hulls` share: the seams where an object's pieces meet.
fn seam_vertices(hulls: &[Hull]) -> Vec<[u64; 3]> {
    let mut all: Vec<([u64; 3], usize)> = hulls
        .iter()
        .enumerate()
        .flat_map(|(k, h)| h.vertices.iter().map(move |v| (key_of(v), k)))
        .collect();
    all.sort_unstable();
    all.dedup();
    let mut out: Vec<[u64; 3]> = Vec::new();
    for w in all.windows(2) {
        if w[0].0 == w[1].0 && out.last() != Some(&w[0].0) {
            out.push(w[0].0);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::P3;
    use crate::shapes;

    /// A box has 6 polygons, a 10 × 16 UV sphere 16·8 quads + 2·16 cap triangles = 160:
    /// only the sphere is over PhysX's 64, with or without the box beside it.
    #[test]
    fn physx_recooked_counts_hulls_over_64_polygons() {
        let cube = Hull::from_mesh(shapes::cuboid(crate::mesh::V3::new(0.1, 0.2, 0.3))).unwrap();
        assert_eq!(cube.polygons().len(), 6);
        let ball = Hull::from_mesh(shapes::uv_sphere(0.05, 10, 16)).unwrap();
        assert_eq!(ball.polygons().len(), 16 * 8 + 2 * 16);
        assert_eq!(physx_recooked(&[vec![cube.clone()]]), 0);
        assert_eq!(
            physx_recooked(&[vec![cube.clone(), ball.clone()], vec![ball]]),
            2
        );
    }

    #[test]
    fn engine_budget_bounds_polygons_by_euler() {
        let o = DecomposeOptions {
            max_polygons: PHYSX_MAX_POLYGONS,
            ..Default::default()
        };
        assert_eq!(o.engine_budget().max_vertices, 34);
        assert_eq!(o.plane_tolerance(), Some(PHYSX_PLANE_TOLERANCE));
        // Without a polygon budget nothing changes.
        let free = DecomposeOptions::default();
        assert_eq!(free.engine_budget(), free);
        assert_eq!(free.plane_tolerance(), None);
        // A round hull of 34 vertices (no two faces coplanar) has exactly 2·34 − 4 = 64 faces:
        // the most polygons a 34-vertex hull can have.
        let h = Hull::from_points(&shapes::uv_sphere(0.05, 24, 48).vertices)
            .unwrap()
            .simplified(34)
            .unwrap();
        assert_eq!(h.vertices.len(), 34);
        assert_eq!(h.triangles.len(), 64);
        assert!(h.polygon_stats().0 <= 64);
    }

    #[test]
    fn physx_legal_keeps_the_seams_between_pieces() {
        // Two halves of a 2 cm ball, cut by the plane x = 0: they share the ring on the cut.
        // Its vertices are about 3 mm apart and bulge about s²/2R = 0.5 mm, less than PhysX's
        // plane tolerance: dropping them from a cap is allowed, but the shared ring must stay
        // in both halves, or a gap opens between them.
        let s = shapes::uv_sphere(0.01, 10, 20);
        let mut left: Vec<P3> = vec![P3::origin()];
        let mut right: Vec<P3> = vec![P3::origin()];
        for v in &s.vertices {
            if v.x <= 1e-12 {
                left.push(*v);
            }
            if v.x >= -1e-12 {
                right.push(*v);
            }
        }
        let mut sets = vec![vec![
            Hull::from_points(&left).unwrap(),
            Hull::from_points(&right).unwrap(),
        ]];
        let seam: Vec<P3> = sets[0][0]
            .vertices
            .iter()
            .filter(|v| sets[0][1].vertices.contains(v))
            .copied()
            .collect();
        assert!(seam.len() >= 10, "{}", seam.len());
        let before: Vec<usize> = sets[0].iter().map(|h| h.vertices.len()).collect();
        let o = DecomposeOptions {
            max_polygons: PHYSX_MAX_POLYGONS,
            ..Default::default()
        };
        let notes = physx_legal(&mut sets, &o);
        assert_eq!(notes[0].over, 0);
        for (h, n) in sets[0].iter().zip(before) {
            assert!(h.vertices.len() < n, "insignificant cap vertices dropped");
            for v in &seam {
                assert!(h.vertices.contains(v), "seam vertex {v:?} kept");
            }
            let (p, pv) = h.polygon_stats();
            assert!(h.vertices.len() <= 64 && p <= 64 && pv <= 32, "{p} {pv}");
        }
        // Without the seams kept, each half alone loses seam vertices.
        let alone = Hull::from_points(&left)
            .unwrap()
            .within(&PhysxLimits::default())
            .unwrap();
        assert!(seam.iter().any(|v| !alone.vertices.contains(v)));
    }
}
