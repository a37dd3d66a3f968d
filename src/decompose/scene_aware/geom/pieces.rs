//! Pieces of a whole object and the rays they are built over, split out of `geom.rs`:
//! the exact cones of a hull with too many vertices ([`cone_pieces`]), the star pieces grown
//! over a radial mesh ([`star_pieces`], [`depth_under`]), the ray directions and frames
//! ([`sphere_directions`], [`ray_frames`], [`principal_axes`]) and the radial mesh itself
//! ([`radial_mesh`]).
//!
//! Entry points: [`cone_pieces`], [`star_pieces`], [`depth_under`], [`sphere_directions`],
//! [`ray_frames`], [`principal_axes`], [`radial_mesh`].

use super::*;

/// Exact convex pieces of a convex hull with too many vertices for one engine hull.
///
/// The hull's faces are grouped into edge-connected patches of at most `max_vertices − 1`
/// vertices (breadth-first region growing from the lowest unassigned face, so patches are
/// compact and the result deterministic), and each patch becomes the cone from the hull's
/// vertex centroid over it: `conv(patch ∪ {c})`. Every piece lies inside the hull (convexity)
/// and every hull face lies on the boundary of one piece, so the union of the pieces *is* the
/// hull: no deviation, no bulge, and the facet an object rests on survives. Pieces overlap
/// where a patch's outline is not convex as seen from `c`; within one body that is harmless
/// (no self-collision; inertia comes from the mesh). Returns each piece with its
/// patch's vertices (its part of the outer surface) and the patch's mean outward normal, or
/// `None` when more than `max_pieces` pieces would be needed or a piece is degenerate.
pub fn cone_pieces(
    full: &Hull,
    max_vertices: usize,
    max_pieces: usize,
) -> Option<Vec<(Hull, Vec<P3>, V3)>> {
    let c =
        P3::from(full.vertices.iter().map(|v| v.coords).sum::<V3>() / full.vertices.len() as f64);
    star_pieces(
        &full.vertices,
        &full.triangles,
        &c,
        max_vertices,
        max_pieces,
        f64::INFINITY,
        None,
    )
}

/// [`cone_pieces`] of any closed polyhedron (`vertices`, `triangles`, outward) that is
/// star-shaped about `c` (every face seen from `c` from inside): each piece `conv(patch ∪ {c})`
/// holds the cones from `c` over its patch's faces, so the union of the pieces holds the whole
/// polyhedron, with no gap between pieces. On a convex polyhedron the pieces lie inside it;
/// on a non-convex one a piece bulges past it where its patch is concave as seen from `c`: a
/// face joins a patch only if no vertex of the patch then lies deeper than `bulge` under the
/// piece's outer boundary, along its ray from `c` (so concave regions get smaller pieces), and
/// the piece passes `accept` (if given; it must hold for a piece whenever it holds for a larger
/// one, as the bulge does, see `Growth::grow_checked`).
pub fn star_pieces(
    vertices: &[P3],
    triangles: &[[u32; 3]],
    c: &P3,
    max_vertices: usize,
    max_pieces: usize,
    bulge: f64,
    accept: Option<&(dyn Fn(&Hull) -> bool + Sync)>,
) -> Option<Vec<(Hull, Vec<P3>, V3)>> {
    let cap = max_vertices.checked_sub(1).filter(|&c| c >= 3)?;
    let nt = triangles.len();
    if nt < 4 {
        return None;
    }
    // Face adjacency through shared edges (sorted edge list: deterministic, no hashing).
    let mut edges: Vec<([u32; 2], usize)> = Vec::with_capacity(3 * nt);
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.push(([a.min(b), a.max(b)], f));
        }
    }
    edges.sort_unstable();
    let mut adj: Vec<Vec<usize>> = vec![Vec::new(); nt];
    for w in edges.windows(2) {
        if w[0].0 == w[1].0 {
            adj[w[0].1].push(w[1].1);
            adj[w[1].1].push(w[0].1);
        }
    }
    let mut assigned = vec![false; nt];
    let mut queued = vec![false; nt];
    let mut pieces = Vec::new();
    for seed in 0..nt {
        if assigned[seed] {
            continue;
        }
        if pieces.len() == max_pieces {
            return None;
        }
        let mut g = Growth {
            verts: Vec::with_capacity(cap),
            faces: Vec::new(),
            queue: std::collections::VecDeque::from([seed]),
            queued: vec![seed],
            assigned: &mut assigned,
            queued_mark: &mut queued,
        };
        g.queued_mark[seed] = true;
        if bulge.is_finite() || accept.is_some() {
            g.grow_checked(triangles, &adj, cap, |verts| {
                let mut pts: Vec<P3> = verts.iter().map(|&i| vertices[i as usize]).collect();
                pts.push(*c);
                let h = Hull::from_points(&pts)?;
                let ok = pts[..pts.len() - 1]
                    .iter()
                    .all(|v| depth_under(&h, c, v) <= bulge)
                    && accept.is_none_or(|a| a(&h));
                Some((ok, h.volume, h.aabb.diagonal()))
            });
        } else {
            g.grow(triangles, &adj, cap, None);
        }
        let (faces, verts) = g.finish();
        let mut normal = V3::zeros();
        for &f in &faces {
            let [a, b, d] = triangles[f].map(|i| vertices[i as usize]);
            normal += (b - a).cross(&(d - a));
        }
        let normal = normal.try_normalize(1e-300).unwrap_or_else(V3::zeros);
        let outer: Vec<P3> = verts.iter().map(|&i| vertices[i as usize]).collect();
        let mut pts = outer.clone();
        pts.push(*c);
        let piece = Hull::from_points(&pts).filter(|h| h.vertices.len() <= max_vertices)?;
        pieces.push((piece, outer, normal));
    }
    Some(pieces)
}

/// How far `v` lies under the boundary of `h` (which holds `c` and `v`), along the ray from
/// `c` through `v`.
pub(in crate::decompose::scene_aware) fn depth_under(h: &Hull, c: &P3, v: &P3) -> f64 {
    let u = v - c;
    let r = u.norm();
    if !(r > 0.0) {
        return 0.0;
    }
    let u = u / r;
    let t = h
        .planes
        .iter()
        .filter(|(n, _)| n.dot(&u) > 1e-12)
        .map(|(n, d)| (d - n.dot(&c.coords)) / n.dot(&u))
        .fold(f64::INFINITY, f64::min);
    if t.is_finite() {
        (t - r).max(0.0)
    } else {
        0.0
    }
}

/// One star piece's patch as it grows (see [`star_pieces`]): breadth first from its seed, a
/// face joining when its new vertices fit in `cap` and, if checked, the cone over the patch
/// then bulges no more than allowed.
struct Growth<'a> {
    verts: Vec<u32>,
    faces: Vec<usize>,
    queue: std::collections::VecDeque<usize>,
    /// Faces queued for this patch (their marks are cleared when it is done or rolled back).
    queued: Vec<usize>,
    assigned: &'a mut [bool],
    queued_mark: &'a mut [bool],
}

impl Growth<'_> {
    /// Grows the patch face by face, a face joining when its new vertices fit in `cap`. With
    /// `limit = Some((checks, skip))`, the faces that add a vertex to a non-empty patch (the
    /// ones a cone check is for) are counted: the first `skip` of them are rejected, and the
    /// growth stops before the one after `checks` have joined. Returns how many joined.
    fn grow(
        &mut self,
        triangles: &[[u32; 3]],
        adj: &[Vec<usize>],
        cap: usize,
        limit: Option<(usize, usize)>,
    ) -> usize {
        let (mut joined, mut seen) = (0, 0);
        while let Some(&f) = self.queue.front() {
            let new: Vec<u32> = triangles[f]
                .iter()
                .copied()
                .filter(|v| !self.verts.contains(v))
                .collect();
            let counted = limit.filter(|_| !new.is_empty() && !self.verts.is_empty());
            if counted.is_some_and(|(checks, _)| joined == checks) {
                break;
            }
            self.queue.pop_front();
            if self.verts.len() + new.len() > cap {
                continue;
            }
            if let Some((_, skip)) = counted {
                seen += 1;
                if seen <= skip {
                    continue;
                }
                joined += 1;
            }
            self.verts.extend(new);
            self.assigned[f] = true;
            self.faces.push(f);
            for &g in &adj[f] {
                if !self.assigned[g] && !self.queued_mark[g] {
                    self.queued_mark[g] = true;
                    self.queued.push(g);
                    self.queue.push_back(g);
                }
            }
        }
        joined
    }

    /// [`Growth::grow`] where a face that adds a vertex to a non-empty patch joins only if the
    /// cone over the patch with it passes `check` (`Some((passes, volume, diagonal))`; `None`:
    /// degenerate, fails), with the same result as checking one face at a time. Faces are
    /// tried in batches: the cone only grows as faces join, and a vertex lies no deeper under
    /// a smaller cone along its ray, so a batch whose final cone passes would have passed face
    /// by face. A batch that fails is halved and tried again, a single face that fails is
    /// rejected. A batch is tried only when the last cone that passed holds more than the
    /// degenerate volume of the batch's (1e-12 diagonal³, see [`Hull::from_mesh`]), so no
    /// cone in between could have been degenerate.
    fn grow_checked(
        &mut self,
        triangles: &[[u32; 3]],
        adj: &[Vec<usize>],
        cap: usize,
        check: impl Fn(&[u32]) -> Option<(bool, f64, f64)>,
    ) {
        let (mut batch, mut volume) = (1, 0.0f64);
        loop {
            let mark = (
                self.verts.len(),
                self.faces.len(),
                self.queued.len(),
                self.queue.clone(),
            );
            let mut skip = 0;
            loop {
                let joined = self.grow(triangles, adj, cap, Some((batch, skip)));
                if joined == 0 {
                    if skip == 0 {
                        return;
                    }
                    break;
                }
                let cone = check(&self.verts)
                    .filter(|&(ok, _, diag)| ok && (batch == 1 || volume > 1e-12 * diag.powi(3)));
                if let Some((_, v, _)) = cone {
                    volume = v;
                    batch = (batch * 2).min(MAX_BATCH);
                    break;
                }
                self.roll_back(&mark);
                if batch > 1 {
                    batch /= 2;
                } else {
                    skip += 1;
                }
            }
        }
    }

    /// The patch's faces and vertices; the queue marks are cleared for the next patch.
    fn finish(self) -> (Vec<usize>, Vec<u32>) {
        for &f in &self.queued {
            self.queued_mark[f] = false;
        }
        (self.faces, self.verts)
    }

    /// Undoes the growth since `mark` (lengths of `verts`, `faces`, `queued`, and the queue).
    fn roll_back(&mut self, mark: &(usize, usize, usize, std::collections::VecDeque<usize>)) {
        for &f in &self.faces[mark.1..] {
            self.assigned[f] = false;
        }
        for &f in &self.queued[mark.2..] {
            self.queued_mark[f] = false;
        }
        self.verts.truncate(mark.0);
        self.faces.truncate(mark.1);
        self.queued.truncate(mark.2);
        self.queue.clone_from(&mark.3);
    }
}

/// The most faces [`Growth::grow_checked`] tries at once.
const MAX_BATCH: usize = 64;

/// `n` unit directions spread evenly over the ellipsoid of (orthogonal) semi-axes `axes` (a
/// Fibonacci lattice on the sphere, stretched), and a triangulation of them (the hull of the
/// stretched points), outward. Stretched, an elongated object's ends get their share of rays.
pub fn sphere_directions(n: usize, axes: &[V3; 3]) -> Option<(Vec<V3>, Vec<[u32; 3]>)> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let dirs: Vec<P3> = (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let a = golden * i as f64;
            P3::from(axes[0] * (r * a.cos()) + axes[1] * (r * a.sin()) + axes[2] * z)
        })
        .collect();
    let h = Hull::from_points(&dirs)?;
    // Every point is a hull vertex (they lie on the ellipsoid): `h` keeps only those.
    let dirs: Option<Vec<V3>> = h
        .vertices
        .iter()
        .map(|p| p.coords.try_normalize(1e-300))
        .collect();
    (h.vertices.len() == n).then_some((dirs?, h.triangles))
}

/// The ellipsoids [`radial_mesh`] spreads its directions over: the bounding box's, and the
/// one along the surface's principal axes (area-weighted), each as long as the mesh along its
/// axes (a tilted marker's ends get their rays only from the second).
pub fn ray_frames(s: &Surface) -> Vec<[V3; 3]> {
    let extent = |e: &V3| {
        let (lo, hi) =
            s.mesh
                .vertices
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                    let x = e.dot(&v.coords);
                    (l.min(x), h.max(x))
                });
        e * ((hi - lo) / 2.0).max(1e-6 * s.diag)
    };
    let mut frames = vec![[V3::x(), V3::y(), V3::z()].map(|e| extent(&e))];
    let centroids = s
        .tri_centroid
        .iter()
        .copied()
        .zip(s.tri_area.iter().copied());
    if let Some(eig) = principal_axes(centroids) {
        frames.push(std::array::from_fn(|k| {
            extent(&eig.eigenvectors.column(k).into_owned())
        }));
    }
    frames
}

/// Principal axes of weighted points: the eigen-decomposition of their weighted covariance
/// about their weighted mean; `None` when the weights add up to nothing.
pub fn principal_axes(
    pts: impl Iterator<Item = (P3, f64)> + Clone,
) -> Option<nalgebra::SymmetricEigen<f64, nalgebra::U3>> {
    let w: f64 = pts.clone().map(|(_, a)| a).sum();
    if !(w > 0.0) {
        return None;
    }
    let mean = pts.clone().fold(V3::zeros(), |m, (q, a)| m + q.coords * a) / w;
    let mut cov = nalgebra::Matrix3::zeros();
    for (q, a) in pts {
        let d = q.coords - mean;
        cov += d * d.transpose() * a;
    }
    Some(nalgebra::SymmetricEigen::new(cov))
}

/// The surface as seen from `c`, inside it: along each of `n` directions (spread over the
/// ellipsoid of semi-axes `axes`, see [`ray_frames`]), the first point where a ray from `c`
/// leaves the mesh (`last`: the last, where it leaves for good), triangulated as the
/// directions are. A polyhedron star-shaped about `c` by
/// construction, whose vertices lie on the mesh (or, through a hole, on its convex hull).
/// `None` when more than 2 % of the rays find no surface (`c` outside or the mesh open wide).
pub fn radial_mesh(
    s: &Surface,
    c: &P3,
    n: usize,
    axes: &[V3; 3],
    last: bool,
) -> Option<(Vec<P3>, Vec<[u32; 3]>)> {
    let (dirs, tris) = sphere_directions(n, axes)?;
    let far = 2.0 * s.diag;
    let hits: Vec<Option<f64>> = dirs
        .par_iter()
        .map(|u| {
            if last {
                // Cast back from beyond the mesh: the first hit is the last crossing.
                s.ray(&(c + u * far), &(-u), far).map(|t| far - t)
            } else {
                s.ray(c, u, far)
            }
        })
        .collect();
    // A ray through a hole (scans have small ones) stops where it leaves the mesh's convex
    // hull instead; more than 2 % of them: the mesh is open wide.
    let misses = hits.iter().filter(|t| t.is_none()).count();
    if misses * 50 > hits.len() {
        return None;
    }
    let full = if misses > 0 {
        Some(Hull::from_points(&s.mesh.vertices)?)
    } else {
        None
    };
    let pts: Option<Vec<P3>> = dirs
        .iter()
        .zip(&hits)
        .map(|(u, t)| {
            let t = t.or_else(|| full.as_ref().map(|h| depth_under(h, c, &(c + u)) + 1.0))?;
            Some(c + u * t)
        })
        .collect();
    Some((pts?, tris))
}
