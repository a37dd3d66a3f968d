//! Star pieces: solids filled about a centre (analytic volumes), what the centre does not see,
//! real solids, and the batched growth against the face-by-face one.

use super::*;

/// Decompose a solid alone and check it is filled by star pieces: within the limits, the
/// union of the hulls has the solid's `volume` (grid-sampled, 3 % slack) and lies within the
/// tolerance of its surface at the 95th percentile. Returns the hulls.
fn assert_star_filled(mesh: &Mesh, volume: f64, o: &DecomposeOptions) -> Vec<Hull> {
    let (mut hulls, rep) = decompose_scene(&[mesh], o);
    assert!(rep.objects[0].star_pieces, "{:?}", rep.objects[0]);
    let hulls = hulls.remove(0);
    assert_limits(&hulls, o);
    let q = metrics::measure(mesh, &hulls);
    let filled = metrics::union_volume(&hulls, 96) / volume;
    eprintln!(
        "{} pieces, p95 {:.3} %, union / solid volume {filled:.4}, uncovered {:.2} %",
        hulls.len(),
        q.dist_p95 * 100.0,
        q.uncovered * 100.0
    );
    assert!((0.97..=1.03).contains(&filled), "{filled}");
    assert!(q.dist_p95 <= o.tolerance, "{q:?}");
    hulls
}

/// A solid that is not convex but is star-shaped about its centre, like an apple: a body of
/// revolution with a stem dimple 30 % of its radius deep. Surface patches made a shell of it
/// (their chords inside); star pieces fill it: the union of the hulls has the solid's analytic
/// volume (grid-sampled, 3 % slack), lies within the tolerance of its surface at the 95th
/// percentile, and the dimple stays open (a point in it, 10 % of the radius above its floor, is
/// in no hull, where the convex hull would hold it).
#[test]
fn star_pieces_fill_a_dimpled_solid_and_keep_the_dimple_open() {
    let o = opts();
    let r = 0.04;
    let n = 48;
    let dimple = |phi: f64| 1.0 - 0.3 * (-(phi / 0.35).powi(2)).exp();
    let mut profile: Vec<[f64; 2]> = vec![[0.0, -r * dimple(PI)]];
    profile.extend((1..n).map(|i| {
        let phi = PI * (1.0 - i as f64 / n as f64);
        [r * dimple(phi) * phi.sin(), r * dimple(phi) * phi.cos()]
    }));
    profile.push([0.0, r * dimple(0.0)]);
    let slices = 64;
    let mesh = shapes::revolve(&profile, slices);
    let volume = shapes::revolved_volume(&profile, slices);
    let probe = P3::new(0.0, 0.0, r * (dimple(0.0) + 0.1));
    let full = Hull::from_points(&mesh.vertices).unwrap();
    assert!(full.contains(&probe), "the probe is in the dimple");
    let hulls = assert_star_filled(&mesh, volume, &o);
    assert!(!hulls.iter().any(|h| h.contains(&probe)), "dimple filled");
}

/// A solid with an open cap poking out of it, as a generated avocado half carries its pit: an
/// oblate body (semi-axes 25, 25, 12.5 mm) and the upper half of a 10 mm sphere whose open
/// rim is sunk 2 mm under the body's top. Rays from the centre meet the body first and never
/// see the cap (10 % of the surface), so the star pieces are taken where the rays leave the
/// mesh for good: the union of the hulls holds the body and the cap (volume within 3 % of the
/// shapes' own, grid-sampled from their equations; the cap is about 6 % of it), the cap's
/// apex, and lies within the tolerance of the surface at the 95th percentile. With the first
/// hits only, the mesh took V-HACD's hulls instead.
#[test]
fn star_pieces_reach_a_cap_poking_out_of_a_solid() {
    let o = opts();
    let (a, c, r) = (0.025, 0.0125, 0.01);
    let base_z = c - 0.002;
    let body = shapes::uv_sphere(1.0, 32, 64);
    let mut mesh = Mesh::new(
        body.vertices
            .iter()
            .map(|v| P3::new(v.x * a, v.y * a, v.z * c))
            .collect(),
        body.triangles,
    );
    let cap = shapes::uv_sphere(r, 24, 48);
    let first = mesh.vertices.len() as u32;
    let lift = V3::new(0.0, 0.0, base_z);
    mesh.vertices.extend(cap.vertices.iter().map(|v| v + lift));
    mesh.triangles.extend(
        cap.triangles
            .iter()
            .filter(|t| t.iter().all(|&i| cap.vertices[i as usize].z >= -1e-12))
            .map(|t| t.map(|i| i + first)),
    );
    assert!(!mesh.is_closed());
    // The solid the mesh bounds, by its shapes' equations.
    let inside = |p: &P3| {
        (p.x / a).powi(2) + (p.y / a).powi(2) + (p.z / c).powi(2) <= 1.0
            || (p.z >= base_z && (p - P3::new(0.0, 0.0, base_z)).norm() <= r)
    };
    let k = 160;
    let (lo, hi) = (P3::new(-a, -a, -c), P3::new(a, a, base_z + r));
    let cell = (hi - lo) / k as f64;
    let count = (0..k * k * k)
        .filter(|i| {
            let (x, y, z) = (i % k, (i / k) % k, i / (k * k));
            inside(
                &(lo + cell.component_mul(&V3::new(
                    x as f64 + 0.5,
                    y as f64 + 0.5,
                    z as f64 + 0.5,
                ))),
            )
        })
        .count();
    let volume = count as f64 * cell.x * cell.y * cell.z;
    let apex = P3::new(0.0, 0.0, base_z + r);
    let hulls = assert_star_filled(&mesh, volume, &o);
    let diag = mesh.aabb().unwrap().diagonal();
    assert!(
        hulls.iter().any(|g| g.holds(&apex, o.tolerance * diag)),
        "the cap's apex is outside every hull"
    );
}

/// What a point sees of a cube: from its centre, all of it; from a point on the x axis outside
/// it, only the face towards the point, so 5/6 of the (area-sampled) surface lies behind the
/// near face, and the far face, a cube's width behind it, is 1/6 (sampling: 2,000 points,
/// standard error 0.008).
#[test]
fn hidden_is_the_share_of_the_surface_behind_the_surface() {
    let cube = shapes::cuboid(V3::new(1.0, 1.0, 1.0));
    let s = Surface::new(&cube).unwrap();
    let probes = s.samples(2000, 7);
    assert_eq!(hidden(&s, &P3::origin(), &probes, 1e-6), 0.0);
    let out = P3::new(3.0, 0.0, 0.0);
    let h = hidden(&s, &out, &probes, 1e-6);
    assert!((h - 5.0 / 6.0).abs() < 0.03, "{h}");
    let h = hidden(&s, &out, &probes, 0.999);
    assert!((h - 1.0 / 6.0).abs() < 0.03, "{h}");
}

/// A can, as the YCB soup can is built: a cylinder (radius 33 mm, 100 mm tall) whose lid is
/// recessed 6 mm inside a 2 mm rim. Rays from its centre meet the lid before the rim, which
/// stands in their shadow, so the star pieces fail their reach test, and surface patches
/// alone leave a shell with their chords inside it (the YCB can took V-HACD's hulls, p95 2.57 %
/// of its diagonal). Star pieces where the centre sees, patches over the rim: the union of the
/// hulls holds the can's analytic volume (grid-sampled, 3 % slack) and its surface within the
/// tolerance at the 95th percentile, the top of the rim all round, and the recess above the lid
/// stays open.
#[test]
fn star_pieces_with_patches_over_what_the_centre_does_not_see() {
    let o = opts();
    let (r, h, w, d): (f64, f64, f64, f64) = (0.033, 0.1, 0.002, 0.006);
    // The profile from the bottom centre to the lid's centre, points 2 mm apart or closer.
    let corners = [
        [0.0, 0.0],
        [r, 0.0],
        [r, h],
        [r - w, h],
        [r - w, h - d],
        [0.0, h - d],
    ];
    let mut profile = vec![corners[0]];
    for c in corners.windows(2) {
        let ([x0, y0], [x1, y1]) = (c[0], c[1]);
        let n = ((x1 - x0).hypot(y1 - y0) / 0.002).ceil().max(1.0) as usize;
        profile.extend((1..=n).map(|i| {
            let t = i as f64 / n as f64;
            [x0 + t * (x1 - x0), y0 + t * (y1 - y0)]
        }));
    }
    let slices = 96;
    let mesh = shapes::revolve(&profile, slices);
    let volume = shapes::revolved_volume(&profile, slices);
    let (mut hulls, rep) = decompose_scene(&[&mesh], &o);
    let r0 = &rep.objects[0];
    assert!(r0.star_pieces && r0.unseen_patches > 0, "{r0:?}");
    let hulls = hulls.remove(0);
    assert_limits(&hulls, &o);
    let q = metrics::measure(&mesh, &hulls);
    let filled = metrics::union_volume(&hulls, 96) / volume;
    eprintln!("can: {q:?}, union / solid volume {filled:.4}, {r0:?}");
    assert!((0.97..=1.03).contains(&filled), "{filled}");
    assert!(q.dist_p95 <= o.tolerance, "{q:?}");
    let diag = mesh.aabb().unwrap().diagonal();
    for k in 0..16 {
        let a = 2.0 * PI * k as f64 / 16.0;
        let top = P3::new((r - 0.5 * w) * a.cos(), (r - 0.5 * w) * a.sin(), h);
        assert!(
            hulls.iter().any(|g| g.holds(&top, o.tolerance * diag)),
            "the rim's top at {a:.2} rad is outside every hull"
        );
    }
    let recess = P3::new(0.0, 0.0, h - 0.5 * d);
    assert!(!hulls.iter().any(|g| g.contains(&recess)), "recess filled");
}

/// The avocado half of the shared scene `00006` (a closed flesh and an open pit cap, lying on
/// a 26 cm plate) is filled by star pieces within the tolerance (measured p95 0.36 % of its
/// diagonal, where its surface patches read 3.37 %): the plate lies under it, so nothing rests
/// on its cut face. Counting the plate there kept the star pieces out, the cut face's big
/// triangles (circumradius 12 mm) being within the loose bound plus the plate's 3.7 mm
/// tolerance of it.
#[test]
fn an_avocado_half_on_a_plate_is_filled_by_star_pieces() {
    let Some((meshes, hulls, rep)) = shared_scene("food/00006_avocado_plate") else {
        return;
    };
    let o = opts();
    let avocado = &rep.objects[1];
    eprintln!("avocado: {avocado:?}");
    assert!(avocado.star_pieces, "{avocado:?}");
    assert_limits(&hulls[1], &o);
    let q = metrics::measure(&meshes[1], &hulls[1]);
    assert!(q.dist_p95 <= o.tolerance, "{q:?}");
    assert_eq!((avocado.overlaps, rep.objects[0].overlaps), (0, 0));
}

/// Real solids: the YCB apple, filled by star pieces, where its 32 surface patches kept 24 % of
/// its volume at p95 3.5 % of the diagonal (measured 0.46 %, volume 1.00); the pear, whose star
/// pieces are within the tolerance (0.49 %) and kept without V-HACD, although V-HACD's hulls
/// lie closer (0.28 %; CoACD 32×64: 1.80 %); the banana, which
/// its centre does not see whole, by V-HACD's hulls, where its patches kept 36 % of its
/// volume at p95 1.64 % (measured 0.19 %, volume 1.01, 2 % of its surface uncovered; 19 % when
/// the hulls were brought to 64 vertices by farthest-point sampling, see `voxel_parts`).
#[test]
fn real_solids_are_filled_star_pieces_for_an_apple_and_a_pear_voxels_for_a_banana() {
    let Some(sh) = shared() else {
        eprintln!("shared datasets not present: skipped");
        return;
    };
    let o = opts();
    let load = |rel: &str| shared_object(&sh, &format!("ycb/{rel}"));
    let apple = load("013_apple/textured.obj");
    let (hulls, rep) = decompose_scene(&[&apple], &o);
    assert!(rep.objects[0].star_pieces);
    assert_limits(&hulls[0], &o);
    let q = metrics::measure(&apple, &hulls[0]);
    eprintln!("apple: {q:?}");
    assert!(q.dist_p95 <= 0.006, "{q:?}");
    assert!(q.volume_ratio >= 0.95, "{q:?}");
    // The pieces grown towards the mesh vertices between the rays (measured 9.0 %; 14.1 %
    // ungrown).
    assert!(q.uncovered <= 0.11, "{q:?}");
    let pear = load("016_pear/textured.obj");
    let (hulls, rep) = decompose_scene(&[&pear], &o);
    assert!(rep.objects[0].star_pieces && !rep.objects[0].voxel_hulls);
    assert_limits(&hulls[0], &o);
    let q = metrics::measure(&pear, &hulls[0]);
    eprintln!("pear: {q:?}");
    assert!(q.dist_p95 <= o.tolerance, "{q:?}");
    assert!(q.volume_ratio >= 0.95, "{q:?}");
    // Measured 7.5 %; 14.3 % ungrown.
    assert!(q.uncovered <= 0.10, "{q:?}");
    let banana = load("011_banana/textured.obj");
    let (hulls, rep) = decompose_scene(&[&banana], &o);
    assert!(!rep.objects[0].star_pieces);
    assert!(rep.objects[0].voxel_hulls);
    assert_limits(&hulls[0], &o);
    let q = metrics::measure(&banana, &hulls[0]);
    eprintln!("banana: {q:?}");
    assert!(q.dist_p95 <= 0.005, "{q:?}");
    assert!(q.volume_ratio >= 0.9, "{q:?}");
    assert!(q.uncovered <= 0.05, "{q:?}");
}

/// Two real solids their centre does not see whole, the YCB pitcher (its handle) and the GSO
/// teapot (spout, handle, lid knob): star pieces where the centre sees, patches over the rest,
/// fill them (union over mesh volume ≥ 0.95) within the tolerance at the 95th percentile. They
/// took V-HACD's hulls before: p95 2.04 and 1.95 %, the teapot's farthest hull 7.1 % past its
/// surface.
#[test]
fn real_solids_the_centre_does_not_see_whole_get_star_pieces_with_patches() {
    let Some(sh) = shared() else {
        eprintln!("shared datasets not present: skipped");
        return;
    };
    let o = opts();
    for rel in [
        "ycb/019_pitcher_base/textured.obj",
        "gso/Threshold_Porcelain_Teapot_White/model.obj",
    ] {
        let mesh = shared_object(&sh, rel);
        let (hulls, rep) = decompose_scene(&[&mesh], &o);
        let r = &rep.objects[0];
        assert!(r.star_pieces && r.unseen_patches > 0, "{rel}: {r:?}");
        assert_limits(&hulls[0], &o);
        let q = metrics::measure(&mesh, &hulls[0]);
        eprintln!("{rel}: {q:?}");
        assert!(q.dist_p95 <= o.tolerance, "{rel}: {q:?}");
        assert!(q.volume_ratio >= 0.95, "{rel}: {q:?}");
        assert!(q.dist_max <= 3.0 * o.tolerance, "{rel}: {q:?}");
    }
}

/// Star pieces grown in batches of faces (`geom::star_pieces`) are the pieces grown one face at
/// a time, one cone check per face (the region growing as first written, below, with the
/// engine's own depth test), on a bumpy
/// solid star-shaped about its centre, at bulge limits that reject few to many faces.
#[test]
fn star_pieces_in_batches_are_the_face_by_face_growth() {
    fn face_by_face(v: &[P3], t: &[[u32; 3]], c: &P3, cap: usize, bulge: f64) -> Vec<Vec<u32>> {
        // Neighbours in the order of the edge they share, as the engine orders them.
        let mut adj: Vec<Vec<([u32; 2], usize)>> = vec![Vec::new(); t.len()];
        for (f, a) in t.iter().enumerate() {
            for (g, b) in t.iter().enumerate() {
                let shared: Vec<u32> = a.iter().copied().filter(|x| b.contains(x)).collect();
                if f != g && shared.len() == 2 {
                    adj[f].push(([shared[0].min(shared[1]), shared[0].max(shared[1])], g));
                }
            }
            adj[f].sort();
        }
        let mut assigned = vec![false; t.len()];
        let mut pieces = Vec::new();
        for seed in 0..t.len() {
            if assigned[seed] {
                continue;
            }
            let mut verts: Vec<u32> = Vec::new();
            let mut queued = vec![false; t.len()];
            let mut queue = std::collections::VecDeque::from([seed]);
            queued[seed] = true;
            while let Some(f) = queue.pop_front() {
                let new: Vec<u32> = t[f]
                    .iter()
                    .copied()
                    .filter(|x| !verts.contains(x))
                    .collect();
                if verts.len() + new.len() > cap {
                    continue;
                }
                if !new.is_empty() && !verts.is_empty() {
                    let mut pts: Vec<P3> =
                        verts.iter().chain(&new).map(|&i| v[i as usize]).collect();
                    pts.push(*c);
                    let fits = Hull::from_points(&pts).is_some_and(|h| {
                        pts[..pts.len() - 1]
                            .iter()
                            .all(|p| geom::depth_under(&h, c, p) <= bulge)
                    });
                    if !fits {
                        continue;
                    }
                }
                verts.extend(new);
                assigned[f] = true;
                for &(_, g) in &adj[f] {
                    if !assigned[g] && !queued[g] {
                        queued[g] = true;
                        queue.push_back(g);
                    }
                }
            }
            pieces.push(verts);
        }
        pieces
    }
    let (dirs, tris) = geom::sphere_directions(600, &[V3::x(), V3::y(), V3::z()]).unwrap();
    let c = P3::new(0.1, -0.2, 0.3);
    let verts: Vec<P3> = dirs
        .iter()
        .map(|u| c + u * (1.0 + 0.25 * (3.0 * u.x).sin() * (2.0 * u.y).cos() + 0.15 * u.z * u.z))
        .collect();
    let mut rejected = 0;
    for max_vertices in [16, 64] {
        for bulge in [0.002, 0.01, 0.05, f64::INFINITY] {
            let want = face_by_face(&verts, &tris, &c, max_vertices - 1, bulge);
            let got =
                geom::star_pieces(&verts, &tris, &c, max_vertices, 10_000, bulge, None).unwrap();
            let got: Vec<Vec<P3>> = got.into_iter().map(|(_, outer, _)| outer).collect();
            let want: Vec<Vec<P3>> = want
                .iter()
                .map(|p| p.iter().map(|&i| verts[i as usize]).collect())
                .collect();
            assert_eq!(got, want, "{max_vertices} vertices, bulge {bulge}");
            // Tighter bulges take more pieces: faces were rejected.
            let loose = face_by_face(&verts, &tris, &c, max_vertices - 1, f64::INFINITY).len();
            rejected += want.len().saturating_sub(loose);
        }
    }
    assert!(rejected > 0, "no bulge limit rejected a face");
}
