//! The other direction in the engine (issue #35): how far the mesh's own surface lies from
//! the hulls, where the engine otherwise measures only from the hulls to the mesh, and what a
//! cut against a neighbour leaves of a part. Entry points: [`mesh_side`] (the whole mesh
//! against one hull, for the convex shortcut), [`kept_side`] (a part a neighbour cut would
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use crate::shapes;

    /// How far the vertices of `tris` lie outside `h` (by its face planes, 0 inside).
    fn outside_depth(s: &Surface, h: &Hull, tris: &[u32]) -> f64 {
        s.vertices_of(tris)
            .iter()
            .map(|&i| h.plane_distance(&s.mesh.vertices[i as usize]))
            .fold(0.0, f64::max)
    }

    /// Two closed boxes as one mesh: a 100 × 100 × 10 mm slab and, 0.5 mm above its top, a
    /// 4 × 4 × 2 mm tile near one corner (all in m).
    fn slab_and_tile() -> Mesh {
        let slab = shapes::cuboid(V3::new(0.1, 0.1, 0.01));
        let tile = shapes::cuboid(V3::new(0.004, 0.004, 0.002));
        let mut vertices: Vec<P3> = slab
            .vertices
            .iter()
            .map(|p| p + V3::new(0.05, 0.05, 0.005))
            .collect();
        let off = vertices.len() as u32;
        vertices.extend(
            tile.vertices
                .iter()
                .map(|p| p + V3::new(0.082, 0.082, 0.0115)),
        );
        let mut triangles = slab.triangles.clone();
        triangles.extend(tile.triangles.iter().map(|t| t.map(|i| i + off)));
        Mesh::new(vertices, triangles)
    }

    /// The slab-and-tile case of the two tests below: its surface, options with 8 vertices a
    /// hull, the top faces (the patch), the part built on them, and the object holding it.
    fn top_faces_case() -> (Mesh, Surface, DecomposeOptions, Vec<u32>, Part, Obj) {
        let mesh = slab_and_tile();
        let s = Surface::new(&mesh).unwrap();
        let opts = DecomposeOptions {
            max_vertices: 8,
            ..Default::default()
        };
        let p = Params::new(&s, &opts, Strategy::Patches);
        let top: Vec<u32> = (0..mesh.triangles.len() as u32)
            .filter(|&t| s.tri_normal[t as usize].z > 0.99)
            .collect();
        let part = build_part(&s, &p, &opts, top.clone(), Vec::new()).unwrap();
        let obj = Obj {
            surf: Surface::new(&mesh),
            feat: None,
            params: Some(p),
            parts: Vec::new(),
            report: ObjectReport::default(),
        };
        (mesh, s, opts, top, part, obj)
    }

    /// The rebuild path of a cut against a neighbour (`resolve` → [`kept_side`]), on a case
    /// made for it: the patch is the two boxes' top faces, and with 8 vertices a hull (4
    /// surface vertices a patch) its hull spans the slab's four corners only, the tile 2.5 mm
    /// above it. A neighbour's cut keeping z ≥ 10.2 mm leaves nothing of that hull; what the
    /// cut leaves of the patch is the tile's top, and the rebuilt hull is exactly the tile's
    /// top pushed into the material by `d_max` (half the tolerance: the tile is 2 mm thick,
    /// 0.45 × 2 mm is more): x, y ∈ [80, 84] mm, z ∈ [12.5 mm − d_max, 12.5 mm].
    #[test]
    fn a_cut_leaving_nothing_of_a_hull_rebuilds_it_from_the_patch_on_the_kept_side() {
        let (mesh, s, opts, top, part, obj) = top_faces_case();
        assert_eq!(top.len(), 4);
        // The hull is the slab's top, the tile 2.5 mm above it.
        let tile_top = P3::new(0.084, 0.084, 0.0125);
        let above = part.hull.plane_distance(&tile_top);
        assert!((above - 0.0025).abs() < 1e-9, "{above}");
        assert!((outside_depth(&s, &part.hull, &part.tris) - 0.0025).abs() < 1e-9);
        let (n, c) = (-V3::z(), -0.0102);
        assert!(clip(&part.hull, &n, c).is_none(), "the cut leaves nothing");
        let q = kept_side(&obj, &part, n, c, &opts).expect("the tile's top is kept");
        let tile_tris: Vec<u32> = top
            .iter()
            .copied()
            .filter(|&t| mesh.triangle(t as usize).iter().all(|v| v.z > 0.012))
            .collect();
        assert_eq!(q.tris, tile_tris);
        assert_eq!(q.cuts, vec![(n, c)]);
        let d_max = 0.5 * opts.tolerance * s.diag;
        let b = crate::mesh::Aabb::of_points(&q.hull.vertices).unwrap();
        let want = ([0.080, 0.080, 0.0125 - d_max], [0.084, 0.084, 0.0125]);
        for a in 0..3 {
            assert!((b.min[a] - want.0[a]).abs() < 1e-12, "{b:?}");
            assert!((b.max[a] - want.1[a]).abs() < 1e-12, "{b:?}");
        }
        assert!((q.hull.thickness() - d_max).abs() < 1e-12);
        assert!(q.hull.thickness() >= opts.min_thickness);
        // The tile's top is covered again: no patch vertex outside the rebuilt hull.
        assert!(outside_depth(&s, &q.hull, &q.tris) < 1e-12);
    }

    /// Without vertices of the patch on the kept side (the cut above the tile too) nothing is
    /// rebuilt: the part is dropped.
    #[test]
    fn a_cut_leaving_nothing_of_the_patch_rebuilds_nothing() {
        let (_, _, opts, _, part, obj) = top_faces_case();
        assert!(kept_side(&obj, &part, -V3::z(), -0.013, &opts).is_none());
    }
}
