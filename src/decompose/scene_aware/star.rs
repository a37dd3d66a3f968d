//! Star pieces: cones from an object's centre of volume over its surface as seen from there,
//! for closed solids that are not convex (see the engine's module doc, step 1). Entry points:
//! [`star`] (the pieces alone, or over what the centre sees), [`star_on_slabs`] (under
//! one-sided patches where a neighbour rests), [`star_with_patches`] (surface patches over what
//! the centre does not see), and [`hidden`] (how much of the surface hides from the centre).

use super::*;

/// Star pieces of a closed object seen from inside (see [`geom::star_pieces`]): the surface
/// as rays from its centre of volume first meet it ([`geom::radial_mesh`], as many directions
/// as `budget` pieces of `max_vertices` hold), cut into cones from the centre. When that leaves
/// the mesh out of reach (below), where the rays leave it for good instead: a generated
/// avocado half is a closed flesh with its pit an open cap poking out of the cut face, which
/// rays from the centre meet only after the face (alone: p95 2.16 % of its diagonal with
/// surface patches, 0.38 % so). The pieces fill
/// the object, so nothing of its inside is collision surface. A solid that is not convex
/// (an apple's stem dimple, a bottle's shoulder) otherwise gets surface patches, a shell whose
/// inner faces, the chords of round patches, lie inside it: the YCB apple's 32 patches kept
/// 24 % of its volume, their boundary 3.4 % of the diagonal from its surface at the 95th
/// percentile where its single convex hull is 1.25 %. `None` for a centre outside (by the
/// winding number), more than a fifth of the surface hidden from it 10 tolerances deep (see
/// [`hidden`]; not with `slabs`), more than 2 % of the rays meeting no surface (a mesh open
/// wide), or when the mesh is not within reach of the pieces (not star-shaped about its
/// centre: more than 1 % of its surface beyond the tolerance outside them). Returns them with
/// their [`distance_stats`] 95th percentile.
///
/// Next to a neighbour that may rest on the object (`support`, see [`support`]), a piece
/// grows only while it keeps those triangles level ([`flat_over`]). `slabs`: hulls that
/// already cover those triangles (see [`star_on_slabs`]); the rays that meet the surface within
/// half a tolerance of them then stop at `z = floor`, under the slabs, and the slabs count as
/// pieces for the reach test and the 95th percentile (and are not returned). `seen_only`: no
/// reach test, the pieces over where the rays first meet the surface; the caller covers the
/// rest (see [`star_with_patches`]).
pub(super) fn star(
    s: &Surface,
    p: &Params,
    opts: &DecomposeOptions,
    budget: usize,
    support: &[u32],
    slabs: Option<&Slabs>,
    seen_only: bool,
) -> Option<(f64, Vec<Part>)> {
    if budget < 2 {
        return None;
    }
    // With slabs the caller ([`star_on_slabs`]) has found the centre and the probes, and
    // checked what hides, once for its three tries.
    let own;
    let (c, probes) = match slabs {
        Some(sl) => (sl.centre, sl.probes),
        None => {
            let c = centre(s)?;
            own = s.samples(HIDDEN_PROBES, HIDDEN_SEED);
            if hidden(s, &c, &own, 10.0 * p.tol) > HIDDEN_MAX {
                return None;
            }
            (c, &own[..])
        }
    };
    // As many directions as `budget` pieces hold, spread two ways (see `geom::ray_frames`),
    // the closer at the 95th percentile kept. Pieces may bulge a tolerance past the surface
    // seen, or more (×1.5 each time) when that takes more pieces than the budget.
    let cap = opts.max_vertices.checked_sub(1)?;
    let n = budget * cap / 2;
    let level = |h: &Hull| flat_over(s, p, support, h);
    let level = (!support.is_empty()).then_some(&level as &(dyn Fn(&Hull) -> bool + Sync));
    let (extra, floor) = slabs.map_or((&[][..], f64::INFINITY), |sl| (sl.hulls, sl.floor));
    // The pieces' hulls with the slabs: what the reach test and the 95th percentile measure.
    let with_slabs = |pieces: &[(Hull, Vec<P3>, V3)]| -> Vec<Hull> {
        pieces
            .iter()
            .map(|x| x.0.clone())
            .chain(extra.iter().cloned())
            .collect()
    };
    let lowered = |q: &P3| {
        let r2 = (0.5 * p.tol).powi(2);
        q.z > floor
            && support.iter().any(|&t| {
                let [a, b, d] = s
                    .mesh
                    .triangle(t as usize)
                    .map(|v| crate::mesh::to_dvec(&v));
                geom::point_triangle_dist2(crate::mesh::to_dvec(q), a, b, d) <= r2
            })
    };
    let best = geom::ray_frames(s)
        .par_iter()
        .filter_map(|axes| {
            let attempt = |last: bool| {
                let (mut v, t) = geom::radial_mesh(s, &c, n, axes, last)?;
                if slabs.is_some() {
                    for q in v.iter_mut().filter(|q| lowered(q)) {
                        q.z = floor;
                    }
                }
                let pieces = (0..6)
                    .map(|k| p.tol * 1.5f64.powi(k))
                    .chain([f64::INFINITY])
                    .find_map(|bulge| {
                        geom::star_pieces(&v, &t, &c, opts.max_vertices, budget, bulge, level)
                    })?;
                let hulls = with_slabs(&pieces);
                // The mesh within reach: what the rays could not see (a fold, a second lobe)
                // sticks out.
                let out = || {
                    probes
                        .iter()
                        .filter(|q| !hulls.iter().any(|h| h.within_planes(q, p.tol)))
                        .count()
                };
                (seen_only || out() as f64 <= 0.01 * probes.len() as f64).then_some((pieces, hulls))
            };
            let (pieces, hulls) = if seen_only {
                attempt(false)?
            } else {
                attempt(false).or_else(|| attempt(true))?
            };
            let (p95, max) = distance_stats(s, &hulls)?;
            Some((p95, max, pieces))
        })
        .collect::<Vec<_>>()
        .into_iter()
        .min_by(|a, b| a.0.total_cmp(&b.0))?;
    // `max` is relative to the diagonal; a part's `dev` is a length.
    let (mut p95, mut max, mut pieces) = best;
    if grow_pieces(s, p, opts, &mut pieces, support, extra) {
        (p95, max) = distance_stats(s, &with_slabs(&pieces))?;
    }
    let dev = max * s.diag;
    let parts = pieces
        .into_iter()
        .map(|(hull, outer, normal)| Part::piece(hull, outer, normal, dev))
        .collect();
    Some((p95, parts))
}

/// What [`star_on_slabs`] hands [`star`]: the slabs' hulls and the height under them
/// (`floor`), and the centre of volume and the surface probes it has already found (the same
/// [`centre`] and samples `star` finds alone).
pub(super) struct Slabs<'a> {
    hulls: &'a [Hull],
    floor: f64,
    centre: P3,
    probes: &'a [P3],
}

/// The largest share of the surface [`star`] (and [`star_on_slabs`]) lets hide from the
/// centre more than 10 tolerances deep (see [`hidden`]) before it gives up without casting
/// its rays.
const HIDDEN_MAX: f64 = 0.2;

/// The surface samples [`star`]'s reach test and [`hidden`] probe with: how many, and their
/// seed.
const HIDDEN_PROBES: usize = 2000;
const HIDDEN_SEED: u64 = 0x57a2;

/// The centre of volume of a closed surface (tetrahedra from the origin, in triangle order),
/// `None` without volume or when it lies outside by the winding number (so a scan with small
/// holes, the YCB pear, qualifies): where [`star`]'s rays start, which must all meet the
/// surface.
fn centre(s: &Surface) -> Option<P3> {
    let (mut vol, mut mom) = (0.0, V3::zeros());
    for t in 0..s.mesh.triangles.len() {
        let [a, b, c] = s.mesh.triangle(t);
        let v = a.coords.dot(&b.coords.cross(&c.coords)) / 6.0;
        vol += v;
        mom += (a.coords + b.coords + c.coords) * (v / 4.0);
    }
    if !(vol.abs() > 0.0) {
        return None;
    }
    let c = P3::from(mom / vol);
    (s.winding_number(&c).abs() > 0.5).then_some(c)
}

/// The fraction of `probes` (surface samples) that the segment from `c` meets the surface
/// more than `depth` before reaching. Star pieces reach such a sample only by bulging that far
/// past what their rays see, so [`star`] does not cast its rays (two frames, up to seven
/// bulges, the reach test, twice) when more than `HIDDEN_MAX` of the surface hides 10
/// tolerances deep. A heuristic, measured on `../shared`: the GSO shoes hide 35–77 % of their
/// surface so, the fork, spoon, scissors and duplo 26–61 %, the GSO pitcher 62 %, and none
/// of them kept star pieces (the ZIGLITE shoe's passed the reach test, but lay farther than
/// its patches); every object that keeps them, or takes them with patches (soup can, YCB
/// pitcher, teapot), hides at most 6.7 %. With it, all 43 objects alone and the 15 scene and
/// fixture exports get the same hulls, byte for byte; the GSO Chelsea shoe takes 0.70 s
/// instead of 0.95, the TROCHILUS 2.04 instead of 2.25, the ZIGLITE 2.38 instead of 2.74.
pub(super) fn hidden(s: &Surface, c: &P3, probes: &[P3], depth: f64) -> f64 {
    let behind = probes
        .par_iter()
        .filter(|q| {
            let d = *q - c;
            let len = d.norm();
            len > depth && s.ray(c, &(d / len), len - depth).is_some()
        })
        .count();
    behind as f64 / probes.len().max(1) as f64
}

/// Star pieces grown towards the mesh between their rays; whether any grew. A piece's
/// vertices are where about a thousand rays met the surface, and between them the mesh bulges
/// out of the pieces: each mesh vertex outside every piece goes to the piece it is least
/// outside of, and each piece grows towards its own as the wall segments do (`refit::grow`: a
/// vertex joins when the faces it brings lie within the tolerance of the mesh); the vertices
/// gained join the piece's surface points. Uncovered (bench, alone): YCB apple 14.1 → 9.0 %,
/// pear 14.3 → 7.5 %, GSO bottle 21.5 → 4.6 %, for p95 0.459 → 0.458, 0.494 → 0.499,
/// 0.772 → 0.826 %; in the scenes, the avocado half 15.2 → 1.8 %, the marker in the mug
/// 12.1 → 0.9 % (p95 0.65 → 0.77 %). A piece does not grow past what keeps `support` level
/// ([`flat_over`]), nor towards vertices within the `slabs`.
fn grow_pieces(
    s: &Surface,
    p: &Params,
    opts: &DecomposeOptions,
    pieces: &mut [(Hull, Vec<P3>, V3)],
    support: &[u32],
    slabs: &[Hull],
) -> bool {
    let eps = refit::OUTSIDE * s.diag;
    let owner: Vec<Option<usize>> = s
        .mesh
        .vertices
        .par_iter()
        .map(|v| {
            let d: Vec<f64> = pieces.iter().map(|x| x.0.plane_distance(v)).collect();
            if d.iter().any(|&x| x <= eps) || slabs.iter().any(|h| h.plane_distance(v) <= eps) {
                return None;
            }
            (0..d.len()).min_by(|&a, &b| d[a].total_cmp(&d[b]))
        })
        .collect();
    let mut cands: Vec<Vec<P3>> = vec![Vec::new(); pieces.len()];
    for (o, v) in owner.iter().zip(&s.mesh.vertices) {
        if let Some(k) = o {
            cands[*k].push(*v);
        }
    }
    let grown: Vec<Option<Hull>> = pieces
        .par_iter()
        .zip(&cands)
        .map(|(x, c)| refit::grow(s, p, opts, &x.0, c).filter(|g| flat_over(s, p, support, g)))
        .collect();
    let mut any = false;
    for (x, g) in pieces.iter_mut().zip(grown) {
        if let Some(g) = g {
            let gained: Vec<P3> = g
                .vertices
                .iter()
                .filter(|v| !x.0.vertices.contains(v))
                .copied()
                .collect();
            x.1.extend(gained);
            x.0 = g;
            any = true;
        }
    }
    any
}

/// Star pieces under *slabs* where a neighbour rests: a solid that carries a neighbour on a
/// surface that is not flat (the `00009` lunch box's lid, which undulates by 4 mm under the
/// bottle) gets star pieces that rise above it, and keeping them level takes more pieces than
/// the budget (36–51 for the lunch box, against 28), so it used to fall back to surface
/// patches: a shell with the inside hollow, p95 3.93 % of its diagonal. Here the triangles
/// the neighbour may rest on (`support`) become one-sided surface patches first (`slabs`, as
/// [`build_part`] builds them, split by their [`rebalance::lift`] over those triangles while
/// it exceeds `CONTACT_DEV` of the tolerance), the rays of the star pieces that meet the
/// surface within half a tolerance of them stop below the lowest of them, and the star pieces
/// fill the rest (see [`star`]). The slabs are patches: the contact refinement splits them as
/// it splits the patches of the bottom-up strategy. Between the slabs and the lowered star
/// pieces lies a hollow at most as deep as the support undulates. The slabs get 1/7, 3/14 or
/// 2/7 of the budget (4, 6 or 8 of 28), the three tried in parallel; the closest at the 95th
/// percentile is kept (the lunch box: 1.02, 0.81, 0.97 %). Its bottle still settles in
/// Rapier (1.7 mm, 2.0°), and over 2 s in MuJoCo moves 0.9 mm and turns 1.0° from the
/// composed pose (1.6 mm, 1.4° on the patches).
///
/// `None` at once, before any slab is built, when more than [`HIDDEN_MAX`] of the surface
/// hides from the centre 10 tolerances deep (see [`hidden`]), as [`star`] gives up alone:
/// the rays then see too little for the pieces to reach the mesh. On the 10 shared scenes
/// the slabs ran on four objects: the lunch box hides none of its surface (kept, 0.85 %),
/// while the `00008` mug (51.6 %, its slabs 3.23 % against its patches' 0.68 %) and two of
/// the `00005` sneakers (34.6 and 46.1 %, no pieces within reach) never kept them, for
/// 0.64 CPU-s of the mug's 2.0 and 2.15 of `00005`'s 14.7 (one thread, docs/speed.md,
/// eleventh stop). The scenes' hulls are the same, byte for byte.
pub(super) fn star_on_slabs(
    s: &Surface,
    p: &Params,
    opts: &DecomposeOptions,
    budget: usize,
    support: &[u32],
    feat: &patches::Features,
) -> Option<(f64, Vec<Part>)> {
    let level = Params {
        tol: CONTACT_DEV * p.tol,
        memo: Memo::default(),
        ..p.clone()
    };
    let floor = support
        .iter()
        .flat_map(|&t| s.mesh.triangle(t as usize))
        .map(|v| v.z)
        .fold(f64::INFINITY, f64::min)
        - 1e-4 * s.diag;
    let c = centre(s)?;
    let probes = s.samples(HIDDEN_PROBES, HIDDEN_SEED);
    if hidden(s, &c, &probes, 10.0 * p.tol) > HIDDEN_MAX {
        return None;
    }
    let lift = |q: &Part| rebalance::lift(s, &q.hull, &q.tris);
    [4, 6, 8]
        .par_iter()
        .filter_map(|&k| {
            let n = (k * budget / 28).max(1);
            let mut slabs: Vec<Part> = patches::kmeans(s, feat, support, n / 2, p.lambda, 16)
                .into_iter()
                .filter_map(|g| build_part(s, &level, opts, g, Vec::new()))
                .collect();
            // Each slab's lift, and whether it is set aside (no split of it was found).
            let mut lifts: Vec<(f64, bool)> = slabs.iter().map(|q| (lift(q), false)).collect();
            while slabs.len() < n {
                let Some(w) = (0..slabs.len())
                    .filter(|&i| !lifts[i].1 && lifts[i].0 > level.tol)
                    .max_by(|&i, &j| lifts[i].0.total_cmp(&lifts[j].0).then(j.cmp(&i)))
                else {
                    break;
                };
                match split(s, feat, &level, opts, &slabs[w], f64::INFINITY) {
                    Some((a, b)) => {
                        lifts[w] = (lift(&a), false);
                        lifts.push((lift(&b), false));
                        slabs[w] = a;
                        slabs.push(b);
                    }
                    None => lifts[w].1 = true,
                }
            }
            let hulls = hulls_of(&slabs);
            let rest = budget.checked_sub(slabs.len())?;
            let under = Slabs {
                hulls: &hulls,
                floor,
                centre: c,
                probes: &probes,
            };
            let (_, mut parts) = star(s, p, opts, rest, support, Some(&under), false)?;
            parts.extend(slabs);
            let (p95, _) = distance_stats(s, &hulls_of(&parts))?;
            Some((p95, parts))
        })
        .collect::<Vec<_>>()
        .into_iter()
        .reduce(|a, b| if b.0 < a.0 { b } else { a })
}

/// The shares of the budget [`star_with_patches`] tries for its star pieces, in parallel.
const STAR_SHARES: [(usize, usize); 2] = [(1, 2), (3, 4)];

/// Star pieces over what rays from the centre of volume first meet, surface patches over the
/// rest: a thick solid that its centre does not see whole. A soup can's rim stands above its
/// recessed lid and hides from the centre behind the lid's edge; a pitcher's handle and a
/// teapot's spout and handle loop away from the body. The star pieces then fail their reach
/// test ([`star`]) and the patches alone leave a shell with its inner chords as collision
/// surface (p95 2.58, 2.34, 3.08 % of the diagonal for the YCB soup can, the YCB pitcher and
/// the GSO teapot), so these took V-HACD's hulls (2.57, 2.05, 1.97 %). Here the star pieces
/// take a share of the budget (half or three quarters, both tried, the closer kept), and the
/// triangles with a vertex farther than the tolerance outside every piece become patches that
/// share the rest ([`grow_parts`], the pieces as fixed parts): 1.07, 0.94, 0.88 %. `None`
/// when the centre is outside, or the pieces leave nothing out.
#[allow(clippy::too_many_arguments)]
pub(super) fn star_with_patches(
    s: &Surface,
    opts: &DecomposeOptions,
    feat: &patches::Features,
    budget: usize,
    effort: Effort,
    near: &[f64],
    carried: &[u32],
) -> Option<(f64, Vec<Part>)> {
    STAR_SHARES
        .par_iter()
        .filter_map(|&(num, den)| {
            let p = Params::new(s, opts, Strategy::Patches);
            let (_, pieces) = star(s, &p, opts, budget * num / den, carried, None, true)?;
            let hulls = hulls_of(&pieces);
            let out: Vec<bool> = s
                .mesh
                .vertices
                .par_iter()
                .map(|v| !hulls.iter().any(|h| h.within_planes(v, p.tol)))
                .collect();
            let unseen: Vec<u32> = (0..s.mesh.triangles.len() as u32)
                .filter(|&t| {
                    s.mesh.triangles[t as usize]
                        .iter()
                        .any(|&v| out[v as usize])
                })
                .collect();
            if unseen.is_empty() {
                return None;
            }
            let (parts, _) = grow_parts(s, feat, &p, opts, &pieces, &unseen, budget, effort, near);
            let (p95, _) = distance_stats(s, &hulls_of(&parts))?;
            Some((p95, parts))
        })
        .collect::<Vec<_>>()
        .into_iter()
        .reduce(|a, b| if b.0 < a.0 { b } else { a })
}
