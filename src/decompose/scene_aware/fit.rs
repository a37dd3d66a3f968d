//! The other direction in the engine (issue #35): how far the mesh's own surface lies from
//! the hulls, where the engine otherwise measures only from the hulls to the mesh, and what a
//! cut against a neighbour leaves of a part. Entry points: [`mesh_side`] (the whole mesh
//! against one hull, for the convex shortcut) and [`kept_side`] (a part a neighbour cut would
//! leave too thin, rebuilt from what the cut leaves of its patch instead of dropped).

use super::*;

/// The mesh surface against one hull `h` by its face planes, on `n` samples: the 95th
/// percentile of the distance either side of the boundary (a dent the hull spans, surface
/// it leaves out) and the 99th percentile of the depth outside (m).
pub(super) fn mesh_side(s: &Surface, h: &Hull, n: usize) -> (f64, f64) {
    let d: Vec<f64> = s
        .samples(n, 0x5eed)
        .par_iter()
        .map(|q| h.plane_distance(q))
        .collect();
    let either: Vec<f64> = d.iter().map(|x| x.abs()).collect();
    let out: Vec<f64> = d.iter().map(|x| x.max(0.0)).collect();
    (metrics::stats(&either).1, metrics::percentile(&out, 0.99))
}

/// A part a cut `n·x ≤ c` against a neighbour would leave thinner than `min_thickness` (or
/// empty), built again from the triangles of its patch wholly on the kept side, with its cuts
/// and this one: a hull that reached the neighbour with one corner keeps covering the rest of
/// its patch (issue #35: a teddy bear lost a hull, and 4 % of its surface, so). `None` when
/// nothing of it is left or that is too thin too.
pub(super) fn kept_side(
    obj: &Obj,
    part: &Part,
    n: V3,
    c: f64,
    opts: &DecomposeOptions,
) -> Option<Part> {
    let (s, p) = (obj.surf.as_ref()?, obj.params.as_ref()?);
    let kept: Vec<u32> = part
        .tris
        .iter()
        .copied()
        .filter(|&t| {
            s.mesh.triangles[t as usize]
                .iter()
                .all(|&v| n.dot(&s.mesh.vertices[v as usize].coords) <= c)
        })
        .collect();
    if kept.is_empty() {
        return None;
    }
    let mut cuts = part.cuts.clone();
    cuts.push((n, c));
    build_part(s, p, opts, kept, cuts).filter(|q| q.hull.thickness() >= opts.min_thickness)
}
