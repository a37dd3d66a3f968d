//! Step 1 of the engine: the whole-object candidates (convex shortcut, exact convex pieces,
//! voxel hulls of a thick solid) and the tests that decide whether one may stand for the object.
//!
//! Entry points: [`shortcut`], [`convex_components`], [`voxel_parts`], [`thick_solid`],
//! [`keeps_support`], [`support`], [`leaned_on`], [`hollow`].

use super::*;

/// The convex shortcut: one hull if the object is convex enough; else, for a convex object
/// too round for one hull within the vertex limit, exact cone pieces of its hull (at most
/// `budget`), see [`geom::cone_pieces`].
pub(super) fn shortcut(
    s: &Surface,
    p: &Params,
    opts: &DecomposeOptions,
    budget: usize,
) -> Option<Vec<Part>> {
    let full = Hull::from_points(&s.mesh.vertices)?;
    // Two simplifications, both using only mesh vertices (so the hull never leaves the mesh and
    // cannot close a gap the composition left: fruits 1 mm apart pushed each other away in MuJoCo
    // and Rapier when the hull was inflated back to the mesh's volume):
    // * facet-preserving: the flat spot an object rests on survives (a cut fruit, a box bottom);
    // * greedy volume-preserving: closest on round shapes.
    // The first that meets the tolerance wins, in that order.
    let deviation = |h: &Hull| -> Option<(f64, f64)> {
        let samples = geom::sample_hull(h, 512, 0x5eed);
        let d: Vec<f64> = samples.par_iter().map(|q| s.distance(q)).collect();
        if d.is_empty() {
            return None;
        }
        let (_, p95, max) = metrics::stats(&d);
        // Both ways (issue #35): the mesh's own surface against the hull too, or a dent the
        // hull spans and the corners a reduction cut off pass (a die's and a strawberry's one
        // hull left 1.1 % of their diagonal outside at the 99th percentile).
        let (either, out) = fit::mesh_side(s, h, 1024);
        if either > p.tol || out > 0.5 * p.tol {
            return Some((f64::INFINITY, f64::INFINITY));
        }
        Some((p95, max))
    };
    let inflate = |h: Hull| inflate(h, full.volume, 0.25 * p.tol, opts.max_vertices);
    let candidates = [
        full.clone().simplified(opts.max_vertices),
        greedy_hull(&full, opts.max_vertices),
    ];
    for h in candidates.into_iter().flatten().map(inflate) {
        let (p95, max) = deviation(&h)?;
        if p95 <= p.tol && max <= 3.0 * p.tol {
            let outer = h.vertices.clone();
            return Some(vec![Part::piece(h, outer, V3::zeros(), max)]);
        }
    }
    // Convex but too round for one hull: cone pieces of the full hull, or of a greedy
    // reduction of it (a 16k-triangle scan has thousands of hull vertices), whose union is
    // that hull exactly. Pieces overlapping a neighbour are cut like any other part.
    // Only for convex objects: when the full hull already deviates, no reduction of it helps.
    let (p95, max) = deviation(&full)?;
    if !(p95 <= p.tol && max <= 3.0 * p.tol) {
        return None;
    }
    let per_piece = opts.max_vertices.saturating_sub(1) / 2;
    // Farthest-point reduction (facets kept): O(n·k); the greedy volume-preserving one rebuilds
    // the hull per vertex and took 10 s for the ~870 vertices of a 16k-triangle lemon.
    let reduce = || full.clone().simplified((budget * per_piece).max(4));
    for h in [Some(full.clone()), None] {
        let Some(h) = h.or_else(reduce) else { continue };
        let (p95, max) = deviation(&h)?;
        if !(p95 <= p.tol && max <= 3.0 * p.tol) {
            continue;
        }
        if let Some(pieces) = geom::cone_pieces(&h, opts.max_vertices, budget) {
            return Some(
                pieces
                    .into_iter()
                    .map(|(hull, outer, normal)| Part::piece(hull, outer, normal, max))
                    .collect(),
            );
        }
    }
    None
}

/// How a solid was filled instead of surface patches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Solid {
    /// Cones from its centre (see [`star`]).
    Star,
    /// Star pieces under slabs where a neighbour rests (see [`star_on_slabs`]).
    StarOnSlabs,
    /// Star pieces over what the centre sees, patches over the rest (see
    /// [`star_with_patches`]).
    StarWithPatches,
    /// parry's V-HACD (see [`voxel_parts`]).
    Voxel,
}

impl Solid {
    /// `feat`: the object's patch features, kept for the slabs, which the contact refinement
    /// may split.
    pub(super) fn obj(
        self,
        parts: Vec<Part>,
        p: Params,
        surf: Option<Surface>,
        feat: Option<patches::Features>,
    ) -> Obj {
        // Surface patches among the parts (the slabs, or the patches over what the centre
        // does not see): the contact refinement may split them.
        let surface_patches = parts.iter().filter(|q| !q.tris.is_empty()).count();
        let with_patches = matches!(self, Solid::StarOnSlabs | Solid::StarWithPatches);
        Obj {
            parts,
            feat: feat.filter(|_| with_patches),
            surf,
            params: Some(p),
            report: ObjectReport {
                star_pieces: self != Solid::Voxel,
                slabs: if self == Solid::StarOnSlabs {
                    surface_patches
                } else {
                    0
                },
                unseen_patches: if self == Solid::StarWithPatches {
                    surface_patches
                } else {
                    0
                },
                voxel_hulls: self == Solid::Voxel,
                ..Default::default()
            },
        }
    }
}

/// Whether the object is a thick solid: at least half of (up to 256 of) its vertices have more
/// than 6 % of the diagonal of material under them (the wall-thickness limit of the patches'
/// mid-wall clustering). A banana or a bottle is; a mug, a bowl or a shoe is not.
pub(super) fn thick_solid(s: &Surface) -> bool {
    let n = s.mesh.vertices.len();
    let step = n.div_ceil(256).max(1);
    let probes: Vec<usize> = (0..n).step_by(step).collect();
    let thick = probes
        .par_iter()
        .filter(|&&i| {
            let nv = s.vert_normal[i];
            // Infinite: nothing under it (an open sheet), not thick.
            let t = s.thickness(&s.mesh.vertices[i], &nv, s.diag);
            nv.norm() > 0.5 && t.is_finite() && t > 0.06 * s.diag
        })
        .count();
    2 * thick >= probes.len()
}

/// parry's V-HACD (voxels, then the exact hull of each cluster's triangles, brought within the
/// limits and `budget`) as parts, for a solid that the patches left hollow and its centre does
/// not see whole (a curved banana): the YCB banana's 32 patches kept 36 % of its volume at p95
/// 1.64 % of the diagonal, V-HACD's 11 hulls 99 % at 0.25 %. Returns them with their
/// [`distance_stats`] 95th percentile.
pub(super) fn voxel_parts(
    s: &Surface,
    opts: &DecomposeOptions,
    budget: usize,
) -> Option<(f64, Vec<Part>)> {
    let o = DecomposeOptions {
        max_hulls: budget,
        ..opts.clone()
    };
    // Each cluster's hull is brought to `max_vertices` the way the convex shortcut does it:
    // the greedy reduction (it keeps the vertices that lose most volume, where parry's engine
    // spreads them by farthest-point sampling), then inflated back towards the cluster hull's
    // volume by at most a quarter of the tolerance. The reduced hulls lay inside the surface:
    // GSO bottle p95 0.70 → 0.65 %, uncovered 25 → 8 %; YCB banana 0.25 → 0.19 %, 19 → 2 %.
    let cap = 0.25 * opts.tolerance * s.diag;
    let hulls = super::super::vhacd::decompose_one_with(&s.mesh, &o, |h, k| {
        let g = greedy_hull(&h, k)?;
        Some(inflate(g, h.volume, cap, k))
    });
    let (p95, max) = distance_stats(s, &hulls)?;
    let parts = hulls
        .into_iter()
        .map(|hull| {
            let outer = hull.vertices.clone();
            Part::piece(hull, outer, V3::zeros(), max * s.diag)
        })
        .collect();
    Some((p95, parts))
}

/// Whether whole-object pieces (star or V-HACD, which the contact refinement cannot split)
/// keep what a neighbour may rest on as flat as the patches would: over every up-facing
/// triangle within reach of a neighbour that may rest on it (`under`: the neighbours whose box
/// centre lies above the triangle, see `contact_distances`), no hull holding its centroid
/// rises more than `CONTACT_DEV` of the tolerance (the patches' contact splits stop there).
/// V-HACD's hulls of the `00009` lunch box rose above its lid where the bottle stands, and the
/// bottle slid 27.7 mm and turned 34° while settling in Rapier. A plate under an avocado half
/// rests on nothing of it: with every neighbour counted, the avocado's cut face, 15 mm above
/// the plate but within the loose bound of its big triangles (circumradius 12 mm) and the
/// plate's tolerance (3.7 mm), kept its star pieces out (p95 3.37 % of its diagonal with
/// patches, 0.36 % with the star pieces).
///
/// `support`: those triangles (see [`support`]). Only the whole-object pieces are checked:
/// the slabs of [`star_on_slabs`] are patches, which the contact refinement splits.
pub(super) fn keeps_support(s: &Surface, p: &Params, support: &[u32], parts: &[Part]) -> bool {
    parts
        .iter()
        .filter(|q| q.tris.is_empty())
        .all(|q| flat_over(s, p, support, &q.hull))
}

/// Whether `h` rises at most `CONTACT_DEV` of the tolerance above the triangles of `support`
/// whose centroid it holds (see [`keeps_support`]).
pub(super) fn flat_over(s: &Surface, p: &Params, support: &[u32], h: &Hull) -> bool {
    let eps = 1e-9 * s.diag;
    let held: Vec<u32> = support
        .iter()
        .copied()
        .filter(|&t| h.holds(&s.tri_centroid[t as usize], eps))
        .collect();
    rebalance::lift(s, h, &held) <= CONTACT_DEV * p.tol
}

/// Whether a neighbour may touch a steep triangle (normal more than about 25° from vertical):
/// one leans on the object's side, as the pen of `pen_mug` on its mug's rim. `near`: as
/// [`pin_contacts`] leaves it, within the clearance there.
pub(super) fn leaned_on(s: &Surface, near: &[f64], opts: &DecomposeOptions) -> bool {
    near.iter()
        .zip(&s.tri_normal)
        .any(|(&d, n)| d <= opts.clearance && n.z.abs() < SUPPORT_NZ)
}

/// The up-facing triangles within reach of a neighbour that may rest on them (`under`, see
/// `contact_distances`; none when it is empty).
pub(super) fn support(s: &Surface, p: &Params, opts: &DecomposeOptions, under: &[f64]) -> Vec<u32> {
    if under.is_empty() {
        return Vec::new();
    }
    // The reach of a hull within the tolerance, as the patches' pins use.
    let reach = rebalance::reach(0.0, p, opts);
    (0..s.mesh.triangles.len() as u32)
        .filter(|&t| under[t as usize] <= reach && s.tri_normal[t as usize].z >= SUPPORT_NZ)
        .collect()
}

/// Whether the union of the parts' hulls holds less than half the mesh's volume (sampled on a
/// coarse grid): surface patches on a solid, a shell with the inside hollow.
pub(super) fn hollow(s: &Surface, parts: &[Part]) -> bool {
    let vol = s.mesh.signed_volume().abs();
    vol > 0.0 && metrics::union_volume(&hulls_of(parts), 48) < 0.5 * vol
}

/// The closed, convex connected components of a mesh of several (a shelf built of boards, a
/// chair of parts) get one exact hull each: their hull's volume is their own to 1e-6, and it
/// has at most `max_vertices` vertices. Returns those parts and the triangles left for the
/// patches. A mesh of one component, or with more convex components than `budget`, is left
/// whole. The `shelf_item` shelf (five boxes) took 32 patch hulls at p95 0.50 % of its
/// diagonal before; now five, exact.
pub(super) fn convex_components(
    s: &Surface,
    opts: &DecomposeOptions,
    budget: usize,
) -> (Vec<Part>, Vec<u32>) {
    let all: Vec<u32> = (0..s.mesh.triangles.len() as u32).collect();
    let comps = geom::components(&s.mesh);
    if comps.len() < 2 {
        return (Vec::new(), all);
    }
    let convex: Vec<Option<Part>> = comps
        .par_iter()
        .map(|tris| {
            let vs = s.vertices_of(tris);
            let pts: Vec<P3> = vs.iter().map(|&v| s.mesh.vertices[v as usize]).collect();
            let local = |v: u32| vs.binary_search(&v).unwrap_or(0) as u32;
            let m = Mesh::new(
                pts,
                tris.iter()
                    .map(|&t| s.mesh.triangles[t as usize].map(local))
                    .collect(),
            );
            if !m.is_closed() {
                return None;
            }
            let hull = Hull::from_points(&m.vertices)?;
            let vol = m.signed_volume().abs();
            if hull.vertices.len() > opts.max_vertices
                || (hull.volume - vol).abs() > 1e-6 * hull.volume
            {
                return None;
            }
            let dev = deviation(s, &hull, tris[0] as u64, &hull.vertices, None);
            Some(Part {
                tris: tris.to_vec(),
                outer: hull.vertices.clone(),
                hull,
                normal: V3::zeros(),
                cuts: Vec::new(),
                dev,
            })
        })
        .collect();
    let n_convex = convex.iter().flatten().count();
    if n_convex == 0 || n_convex > budget {
        return (Vec::new(), all);
    }
    let mut parts = Vec::with_capacity(n_convex);
    let mut rest = Vec::new();
    for (c, tris) in convex.into_iter().zip(comps) {
        match c {
            Some(part) => parts.push(part),
            None => rest.extend(tris),
        }
    }
    rest.sort_unstable();
    (parts, rest)
}
