//! Patches and their hulls: the search's parameters ([`Params`], [`Strategy`]), a part
//! ([`Part`]: a patch of triangles and its hull) and how one is built and measured.
//!
//! Entry points: [`build_part`], [`build_part_below`], [`build_new_part`], [`deviation`],
//! [`deviation_until`], [`inflate`].

use super::vertex_set::VertexSet;
use super::*;

/// Derived absolute parameters of one object.
#[derive(Clone, Debug)]
pub(super) struct Params {
    pub(super) tol: f64,
    pub(super) d_max: f64,
    pub(super) d_min: f64,
    pub(super) lambda: f64,
    pub(super) merge_depth: f64,
    pub(super) n_outer: usize,
    pub(super) strategy: Strategy,
    /// Parts built so far (see [`build_part`]).
    pub(super) memo: Memo,
}

/// How an object's patches are found. For an object alone, [`decompose_object`] runs both and
/// keeps the one whose hulls lie closer to the surface (95th percentile), as neither wins on
/// every shape:
/// * `Patches` starts bottom-up from `budget / 2` k-means surface patches (at most 16, see
///   [`Strategy::initial_patches`]) and splits the worst across its own principal directions.
///   Best on the YCB mug (p95 3.29 % against 3.50 %).
/// * `Planes` starts top-down from 2 patches, and may also cut a patch by planes normal to the
///   scene's axes at a quarter, half and three quarters of the patch's extent, as CoACD cuts
///   by axis-aligned planes. Objects are prepared Z-up, so the horizontal cuts follow what a
///   standing object has level: a cup's foot ring, recessed floor and rim lip become bands,
///   where patch-local cuts made pie slices. YCB cup p95 2.81 → 2.04 %, mug fixture
///   1.02 → 0.82 % (alone). The object's own principal axes did worse (mug fixture 0.90 %,
///   sneaker 2.41 against 2.10 %): their horizontal pair is arbitrary on a round object.
///
/// Under a neighbour that also leans on its side (an up-facing triangle within reach of a
/// neighbour that may rest on it, see `support`, and a steeper one a neighbour touches from the
/// side or above, see [`leaned_on`]) only `Patches` runs: its contact geometry is what the MuJoCo
/// agreement tests hold, and the horizontal cuts put a seam under the pen of `pen_mug`
/// leaning on its mug's rim (with both, Rapier's validation failed and MuJoCo turned the pen
/// 7.8° in 2 s). An object that carries neighbours only on level triangles, or only rests on
/// others, runs both, as alone: the dice cup of `00010` p95 2.70 → 2.34 %, the avocado's
/// plate of `00006` 1.25 → 1.09 %, the bowl of `ball_bowl` 1.64 → 1.62 %, the sneaker on the
/// tray of `00004` 1.74 → 1.68 %. All of them still settle, and MuJoCo moves the ball of
/// `ball_bowl` 0.42 mm and turns it 0.70° in 2 s from its settled pose (0.39 mm and 0.66°
/// with the patches). Before Rapier's stale contact manifolds were recomputed
/// (`physics::fresh`), the halving planes under that ball made MuJoCo roll it 2.6 mm, and
/// every carried object took the patches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Strategy {
    Patches,
    Planes,
}

/// Where [`Strategy::Planes`] cuts a patch along each axis, as fractions of its extent (and
/// the polishing along the patch's principal axes, as fractions of its area).
pub(super) const PLANE_FRACTIONS: [f64; 3] = [0.25, 0.5, 0.75];

impl Strategy {
    /// Both, in the order ties are broken.
    pub(super) const ALL: [Strategy; 2] = [Strategy::Patches, Strategy::Planes];

    /// How many k-means patches the quality loop starts from: a share of the budget, but no
    /// more than of the default 32 (16 and 2). A larger budget then starts where 32 does and
    /// the quality loop goes on from there, so that more hulls do not make an object read
    /// worse: from `budget/2` patches the mug fixture read 0.70 % of the diagonal with 47
    /// hulls at 48, against 0.46 % with 26 at 32.
    pub(super) fn initial_patches(self, budget: usize) -> usize {
        let b = budget.min(super::super::DEFAULT_MAX_HULLS);
        match self {
            Strategy::Patches => (b / 2).max(1),
            Strategy::Planes => (b / 16).max(1),
        }
    }
}

impl Params {
    /// How deep inside the material a wall segment's face may lie and still count as a seam
    /// (see [`deviation`]): the thickest wall, `2·merge_depth`. Half of it measured worse
    /// (ten shared scenes: sum of p95 40.9 % against 38.0 %; the sneaker 2.08 against 1.29 %):
    /// where a segment meets a floor or a thicker rim, its end faces lie deeper than half a wall.
    pub(super) fn seam_depth(&self) -> f64 {
        2.0 * self.merge_depth
    }

    pub(super) fn new(s: &Surface, opts: &DecomposeOptions, strategy: Strategy) -> Params {
        let tol = opts.tolerance * s.diag;
        let d_min = 1.5 * opts.min_thickness;
        Params {
            tol,
            d_max: (0.5 * tol).max(d_min),
            d_min,
            lambda: 0.1 * s.diag,
            merge_depth: 0.03 * s.diag,
            n_outer: (opts.max_vertices / 2).max(4),
            strategy,
            memo: Memo::default(),
        }
    }
}

/// One hull and where it came from.
#[derive(Clone, Debug)]
pub(super) struct Part {
    /// Triangles of the patch (empty for the convex shortcut).
    pub(super) tris: Vec<u32>,
    pub(super) hull: Hull,
    /// Surface points the hull spans (patch vertices kept, or the shortcut's vertices).
    pub(super) outer: Vec<P3>,
    /// Mean outward normal of the patch (zero for the shortcut).
    pub(super) normal: V3,
    /// Half-spaces `n·x ≤ c` applied against neighbours.
    pub(super) cuts: Vec<(V3, f64)>,
    /// Largest sampled distance from the hull surface to the mesh (m).
    pub(super) dev: f64,
}

impl Part {
    /// A piece of a whole object (the shortcut, cone, star or V-HACD pieces): no triangles of
    /// its own, no cuts.
    pub(super) fn piece(hull: Hull, outer: Vec<P3>, normal: V3, dev: f64) -> Part {
        Part {
            tris: Vec::new(),
            hull,
            outer,
            normal,
            cuts: Vec::new(),
            dev,
        }
    }
}

pub(super) const DEV_SAMPLES: usize = 64;

/// Largest sampled one-sided distance from the hull's surface to the mesh. Hull vertices
/// among `on_mesh` (mesh vertices the hull was built from) are at distance 0 and not queried:
/// a third of the queries of a decomposition on the GSO mug.
///
/// With `seams: Some(depth)` (a wall segment: both sides of a wall), points inside the
/// material within `depth` of the surface are not counted. A wall segment ends in faces across
/// the wall, half the wall's thickness from the surface at their middle, and its foot may cross
/// a thicker floor: those are seams with the segments beside it, which hold the material
/// beyond. On the mug fixture (4 mm wall, 6 mm floor, 1.48 mm tolerance) every segment
/// deviated more than the tolerance by those faces alone (2.8 mm for one of 22.5°, whose chord
/// bulges 0.69 mm into the cup), and so did the GSO mug's and the sneaker's: the quality loop
/// and the rebalancing split and moved patches for them instead of for where hulls bridge the
/// cavity. With seams, bench p95: mug fixture 0.82 → 0.46 % (CoACD 32×64: 0.57), GSO mug
/// 1.23 → 1.16 % (1.19), YCB mug 2.21 → 2.02 %, sneaker 1.64 → 1.29 %; the ten shared scenes
/// sum 41.6 → 38.0. A one-sided patch of a thick solid is a shell whose inner faces nothing
/// else covers: all its points count (the lunch box of scene 00009: 3.8 → 7.8 % when they
/// did not).
pub(super) fn deviation(
    s: &Surface,
    h: &Hull,
    seed: u64,
    on_mesh: &[P3],
    seams: Option<f64>,
) -> f64 {
    deviation_until(s, h, seed, on_mesh, seams, f64::INFINITY)
}

/// [`deviation`], stopped at the first point `stop` or more from the surface (see
/// [`Surface::max_distance_until`]): exact below `stop`, at least `stop` otherwise.
pub(super) fn deviation_until(
    s: &Surface,
    h: &Hull,
    seed: u64,
    on_mesh: &[P3],
    seams: Option<f64>,
    stop: f64,
) -> f64 {
    let samples = geom::sample_hull(h, DEV_SAMPLES, seed);
    // The vertices first: pushed into the material or cut, they are the likeliest to be far.
    let pts = h
        .vertices
        .iter()
        .filter(|v| !on_mesh.contains(v))
        .chain(&samples);
    // No seams: every point counts (see `Surface::max_distance_until`).
    s.max_distance_until(pts, seams.unwrap_or(-1.0), stop)
}

/// Build the hull of a patch (with earlier cuts applied). A patch holding both sides of a wall
/// (at least 10 % of its area facing each way along its main normal) spans them directly: up
/// to `n_outer` surface vertices of each side. A one-sided patch takes `n_outer` surface
/// vertices plus copies pushed into the material.
pub(super) fn build_part(
    s: &Surface,
    p: &Params,
    opts: &DecomposeOptions,
    tris: Vec<u32>,
    cuts: Vec<(V3, f64)>,
) -> Option<Part> {
    build_part_below(s, p, opts, tris, cuts, f64::INFINITY)
}

/// [`build_part`], or `None` when the hull deviates `bound` or more: its deviation is then
/// measured only until a point that far is found (see [`deviation_until`]). Most of the
/// rebalancing's candidates fail so: on the sneaker, 2,688 of the 3,646 bounded builds (both
/// strategies).
pub(super) fn build_part_below(
    s: &Surface,
    p: &Params,
    opts: &DecomposeOptions,
    tris: Vec<u32>,
    cuts: Vec<(V3, f64)>,
    bound: f64,
) -> Option<Part> {
    let key = Memo::key(&tris, &cuts);
    // A part kept "above" a lower bound than this one says nothing here: built again.
    let built = match p.memo.get(&key) {
        Some(Built::Above(dev)) if dev < bound => None,
        known => known,
    };
    let built = built.unwrap_or_else(|| {
        let b = match build_new_part(s, p, opts, tris, cuts, bound) {
            Some(q) if q.dev >= bound => Built::Above(q.dev),
            part => Built::Done(part),
        };
        p.memo.put(key, b.clone());
        b
    });
    match built {
        Built::Done(part) => part.filter(|q| q.dev < bound),
        Built::Above(_) => None,
    }
}

/// [`build_part_below`] without the memo: the part, its deviation measured until `bound`.
pub(super) fn build_new_part(
    s: &Surface,
    p: &Params,
    opts: &DecomposeOptions,
    tris: Vec<u32>,
    cuts: Vec<(V3, f64)>,
    bound: f64,
) -> Option<Part> {
    let mut normal = V3::zeros();
    // The range of the patch's vertex indices, for its vertex sets.
    let (mut lo, mut hi) = (u32::MAX, 0);
    for &t in &tris {
        normal += s.tri_normal[t as usize] * s.tri_area[t as usize];
        for k in s.mesh.triangles[t as usize] {
            lo = lo.min(k);
            hi = hi.max(k);
        }
    }
    if normal.norm() > 0.0 {
        normal.normalize_mut();
    }
    let axis_t = *tris.iter().max_by(|&&a, &&b| {
        s.tri_area[a as usize]
            .total_cmp(&s.tri_area[b as usize])
            .then(b.cmp(&a))
    })?;
    let axis = s.tri_normal[axis_t as usize];
    // The vertices of the triangles facing along `axis` and of the others, each once.
    let (mut pos, mut neg) = (VertexSet::new(lo, hi), VertexSet::new(lo, hi));
    let (mut a_pos, mut a_neg) = (0.0, 0.0);
    for &t in &tris {
        let tri = s.mesh.triangles[t as usize];
        if s.tri_normal[t as usize].dot(&axis) >= 0.0 {
            tri.into_iter().for_each(|k| pos.insert(k));
            a_pos += s.tri_area[t as usize];
        } else {
            tri.into_iter().for_each(|k| neg.insert(k));
            a_neg += s.tri_area[t as usize];
        }
    }
    let two_sided = a_pos.min(a_neg) >= 0.1 * (a_pos + a_neg);
    // Up to `n_outer` of the vertices `v` (distinct, ascending), spread out.
    let pick = |v: &[u32]| -> Vec<u32> {
        super::fps::farthest_of(v.len(), |i| s.mesh.vertices[v[i] as usize], p.n_outer)
            .into_iter()
            .map(|k| v[k])
            .collect()
    };
    let mut all: Vec<P3> = Vec::with_capacity(2 * p.n_outer);
    let mut outer = Vec::with_capacity(2 * p.n_outer);
    if two_sided {
        let (pos, neg) = (pos.to_vec(), neg.to_vec());
        for v in pick(&pos).into_iter().chain(pick(&neg)) {
            outer.push(s.mesh.vertices[v as usize]);
        }
        all.extend_from_slice(&outer);
        normal = V3::zeros();
    } else {
        pos.union_with(&neg);
        let set = pos.ranked();
        // Vertex normals from this patch's triangles only: at a crease (a floor meeting a
        // wall) the whole-mesh normal would push the copies sideways, along the patch.
        let vs = set.to_vec();
        let mut vn = vec![V3::zeros(); vs.len()];
        for &t in &tris {
            let w = s.tri_normal[t as usize] * s.tri_area[t as usize];
            for k in s.mesh.triangles[t as usize] {
                vn[set.rank(k)] += w;
            }
        }
        let ray_max = p.d_max / 0.45 * 1.01;
        for v in pick(&vs) {
            let q = s.mesh.vertices[v as usize];
            let mut n = vn[set.rank(v)];
            n = if n.norm() > 0.0 {
                n.normalize()
            } else {
                normal
            };
            let thick = s.thickness(&q, &n, ray_max);
            let d = (0.45 * thick).min(p.d_max).max(p.d_min);
            outer.push(q);
            all.push(q);
            all.push(q - n * d);
        }
    }
    let mut hull = Hull::from_points(&all).or_else(|| {
        // A flat two-sided selection (degenerate): fall back to pushed copies.
        let extra: Vec<P3> = outer.iter().map(|q| q - normal * p.d_min).collect();
        let mut v = all.clone();
        v.extend(extra);
        Hull::from_points(&v)
    })?;
    for (n, c) in &cuts {
        hull = clip(&hull, n, *c)?;
        outer.retain(|q| n.dot(&q.coords) <= *c);
    }
    if hull.vertices.len() > opts.max_vertices {
        hull = hull.simplified(opts.max_vertices)?;
    }
    let dev = deviation_until(
        s,
        &hull,
        tris[0] as u64,
        &outer,
        two_sided.then_some(p.seam_depth()),
        bound,
    );
    Some(Part {
        tris,
        hull,
        outer,
        normal,
        cuts,
        dev,
    })
}

/// A little of the volume a simplified hull `h` lost (`volume`: the original's) given back by a
/// uniform scale about its centroid (keeps faces planar and level), capped so that no vertex
/// moves more than `cap` (a quarter of the tolerance: at most 0.25 % of the diagonal of any
/// gap is used up).
pub(super) fn inflate(h: Hull, volume: f64, cap: f64, max_vertices: usize) -> Hull {
    if h.volume >= volume * 0.999 {
        return h;
    }
    let c = P3::from(h.vertices.iter().map(|v| v.coords).sum::<V3>() / h.vertices.len() as f64);
    let reach = h
        .vertices
        .iter()
        .map(|v| (v - c).norm())
        .fold(0.0, f64::max);
    let k = (volume / h.volume)
        .cbrt()
        .min(1.0 + cap / reach.max(1e-300));
    let pts: Vec<P3> = h.vertices.iter().map(|v| c + (v - c) * k).collect();
    Hull::from_points(&pts)
        .filter(|g| g.vertices.len() <= max_vertices)
        .unwrap_or(h)
}
