//! The scenes themselves, each pose computed from the shapes' dimensions, and the compose sample.

use super::*;

pub(crate) fn ball_bowl(root: &Path) {
    let (r, h, w) = (0.08, 0.055, 0.004);
    let bowl = shapes::bowl(r, h, w, 64, 12);
    let dims = shapes::bowl_dims(r, h, w);
    let rho = 0.033;
    let ball = shapes::uv_sphere(rho, 16, 32);
    // Rest the ball on one of its planar quads just below the equator (a near-square trapezoid
    // about 6.5 mm wide: a stable 4-point rest): rotate that quad's outward normal onto −z.
    // Triangle 32 + 2·(7·32) is the first triangle of ring 8 (the equator) → ring 9, slice 0.
    let [p0, p1, p2] = ball.triangle(32 + 2 * 7 * 32);
    let normal = (p1 - p0).cross(&(p2 - p0)).normalize();
    let face_down = UnitQuaternion::rotation_between(&normal, &-V3::z()).unwrap();
    let q = yaw(40.0) * face_down;
    let lowest = ball
        .vertices
        .iter()
        .map(|p| (q * p.coords).z)
        .fold(f64::INFINITY, f64::min);
    let face_depth = -lowest; // distance from the centre down to the resting face
    let cz = dims.floor_z + GAP - lowest;
    let objs = vec![
        Obj::new(
            "object_a",
            "bowl",
            format!("shapes::bowl(R {r}, H {h}, wall {w}, 64 slices, 12 rings)"),
            bowl,
            UvProjection::Cylindrical { repeat: 4.0 },
            shapes::checker_texture(TEX, 8, [196, 38, 38], [236, 200, 170], "bowl checker"),
            pose(V3::zeros(), yaw(30.0)),
        ),
        Obj::new(
            "object_b",
            "ball",
            format!("shapes::uv_sphere(r {rho}, 16 stacks, 32 slices)"),
            ball,
            UvProjection::Spherical { repeat: 1.0 },
            shapes::stripes_texture(TEX, 8, [220, 220, 40], [40, 90, 200], "ball stripes"),
            pose(V3::new(0.0, 0.0, cz), q),
        ),
    ];
    let margin = face_rest_margin(&objs[1].world_z());
    assert!(margin > 0.001);
    let floor_y = dims.floor_z;
    let contacts = vec![Contact {
        a: 1,
        b: 0,
        what: "ball resting face on the bowl's flat inner floor",
        filter: Box::new(move |t: &[P3; 3]| t.iter().all(|p| (p.y - floor_y).abs() < 1e-6)),
    }];
    let facts = format!(
        "Analytic facts (world +Y up): the bowl stands on its flat foot (radius {} mm) at y = 0; its flat inner floor (radius {} mm) is at y = {} mm, its rim at y = {} mm (inner rim radius {} mm). The ball (circumradius {} mm, a 32×16 UV sphere) is turned so one of its planar quads (between the equator and the next ring) faces straight down; that face is {} mm below the ball's centre, so the centre is at y = floor {} + gap {} + {} = **{} mm** on the bowl axis. The centre of mass projects {} mm inside the resting face: a stable 4-point rest.",
        mm(dims.flat_radius),
        mm(dims.flat_radius),
        mm(dims.floor_z),
        mm(h),
        mm(dims.inner_rim_radius),
        mm(rho),
        mm(face_depth),
        mm(dims.floor_z),
        mm(GAP),
        mm(face_depth),
        mm(cz),
        mm(margin),
    );
    write_sample_folder(
        &root.join("ball_bowl"),
        "toys",
        "A yellow and blue striped ball resting at the bottom of a red bowl.",
        "ball_bowl",
        &objs,
        &contacts,
        "",
        &facts,
    );
}

pub(crate) fn pen_mug(root: &Path) {
    let (rm, hm, wm, bm, nm) = (0.04, 0.095, 0.004, 0.006, 64);
    let ri = rm - wm;
    let (rho, len, np) = (0.0055, 0.14, 24);
    let mug = shapes::mug(rm, hm, wm, bm, nm);
    let pen = shapes::pen(rho, len, np);
    // The pen leans in the x-z plane towards +x, tilted by α from vertical, axis u = (sin α, 0,
    // cos α), e1 = (cos α, 0, −sin α). Its bottom-cap vertex at +e1 is the lowest point (gap to
    // the floor), the one at −e1 the leftmost (gap to the wall's vertex line at φ = π), and its
    // lateral edge at +e1 passes the inner rim vertex Q = (rᵢ, 0, H):
    //   x_B = −rᵢ + g_w + ρ cos α,  z_B = b + g + ρ sin α,  (Q − B)·e1 − ρ = g_r.
    // The mug is a 64-gon: the exact gap to the wall faces beside the vertex line is
    // g_w·cos(π/64), and to the rim chords beside Q it is g_r / sqrt(1 + cos²α·tan²(π/64)), so
    // g_w and g_r are chosen to make both exactly `GAP`.
    let t = (PI / nm as f64).tan();
    let g_w = GAP / (PI / nm as f64).cos();
    let g_r = |c: f64| GAP * (1.0 + c * c * t * t).sqrt();
    let f = |al: f64| {
        let (s, c) = al.sin_cos();
        (2.0 * ri - g_w - rho * c) * c - (hm - bm - GAP - rho * s) * s - rho - g_r(c)
    };
    let (mut lo, mut hi) = (0.0, PI / 2.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let al = 0.5 * (lo + hi);
    let (s, c) = al.sin_cos();
    let u = V3::new(s, 0.0, c);
    let e1 = V3::new(c, 0.0, -s);
    let b = P3::new(-ri + g_w + rho * c, 0.0, bm + GAP + rho * s);
    let q_rim = P3::new(ri, 0.0, hm);
    let s_rim = (q_rim - b).dot(&u);
    let tip = (3.0 * rho).min(len / 4.0);
    assert!(
        s_rim > 0.0 && s_rim < len - tip,
        "rim contact off the pen's body"
    );
    assert!(((q_rim - b).dot(&e1) - rho - g_r(c)).abs() < 1e-12);
    let rot = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), al);
    let centre = b + u * (len / 2.0);
    let scene_yaw = yaw(25.0);
    let pen_pose = pose(scene_yaw * centre.coords, scene_yaw * rot);
    let mug_pose = pose(V3::zeros(), scene_yaw);
    let objs = vec![
        Obj::new(
            "object_a",
            "mug",
            format!("shapes::mug(R {rm}, H {hm}, wall {wm}, bottom {bm}, {nm} slices)"),
            mug,
            UvProjection::Cylindrical { repeat: 3.0 },
            shapes::checker_texture(TEX, 8, [245, 245, 235], [235, 190, 30], "mug checker"),
            mug_pose,
        ),
        Obj::new(
            "object_b",
            "pen",
            format!("shapes::pen(r {rho}, length {len}, {np} slices)"),
            pen,
            UvProjection::Cylindrical { repeat: 1.0 },
            shapes::stripes_texture(TEX, 4, [20, 20, 20], [200, 30, 30], "pen stripes"),
            pen_pose,
        ),
    ];
    // Frictionless equilibrium in the lean plane: wall (+x), floor (+z) and rim (−e1) forces.
    let (_, com_local) = mass_props(&objs[1].mesh);
    let com = b + rot * (com_local.coords + V3::new(0.0, 0.0, len / 2.0));
    let (vol, _) = mass_props(&objs[1].mesh);
    let mg = vol * DENSITY * 9.81;
    let p_floor = b + e1 * rho;
    let rq = q_rim - p_floor;
    let rc = com - p_floor;
    let n_rim = rc.x * mg / (rq.x * s + rq.z * c - 2.0 * rho * s * c);
    let n_wall = n_rim * c;
    let n_floor = mg - n_rim * s;
    assert!(
        n_rim > 0.0 && n_wall > 0.0 && n_floor > 0.0,
        "pen cannot rest"
    );
    let top = b + u * len;
    let rim_side = move |p: &P3| p.z > hm - 0.01 && p.x > 0.0;
    let floor = move |p: &P3| (p.z - bm).abs() < 1e-6;
    let far_wall = move |p: &P3| (p.x.hypot(p.y) - ri).abs() < 1e-6 && p.x < 0.0;
    let contacts = vec![
        Contact {
            a: 1,
            b: 0,
            what: "pen side on the mug's inner rim edge (near side)",
            filter: local_filter(&mug_pose, rim_side),
        },
        Contact {
            a: 1,
            b: 0,
            what: "pen bottom edge on the mug's inner floor",
            filter: local_filter(&mug_pose, floor),
        },
        Contact {
            a: 1,
            b: 0,
            what: "pen bottom edge against the mug's inner wall (far side)",
            filter: local_filter(&mug_pose, far_wall),
        },
    ];
    let (g_w_text, g_r_text) = (
        format!("{:.4}", g_w * 1000.0),
        format!("{:.4}", g_r(c) * 1000.0),
    );
    let facts = format!(
        "Analytic facts (computed in a Z-up frame, then the whole scene turned 25° about the vertical and converted to +Y up): mug inner radius rᵢ = {} mm, inner floor at {} mm, rim at {} mm. The pen (a 24-gon prism, circumradius ρ = {} mm, length {} mm with a conical tip) leans across the mug: its bottom cap sits in the far corner, {} mm above the floor and {} mm (horizontally, from the wall's vertex line; {} mm from its faces) from the wall, and its side passes {} mm from the inner rim vertex on the near side ({} mm from the rim chords beside it). Solving these three conditions gives a tilt of **{:.3}°** from vertical; bottom-cap centre at {} mm from the axis, height {} mm; the rim touches the pen {} mm up its axis; the top end is at height {} mm ({} mm above the rim). Frictionless equilibrium (weight {:.4} N): rim force {:.4} N, wall {:.4} N, floor {:.4} N, all positive, so the pen rests even without friction.",
        mm(ri),
        mm(bm),
        mm(hm),
        mm(rho),
        mm(len),
        mm(GAP),
        g_w_text,
        mm(GAP),
        g_r_text,
        mm(GAP),
        al.to_degrees(),
        mm(-b.x),
        mm(b.z),
        mm(s_rim),
        mm(top.z),
        mm(top.z - hm),
        mg,
        n_rim,
        n_wall,
        n_floor
    );
    write_sample_folder(
        &root.join("pen_mug"),
        "stationery",
        "A black and red pen leaning inside a white and yellow mug, like a pen in a pen holder.",
        "pen_mug",
        &objs,
        &contacts,
        "",
        &facts,
    );
}

pub(crate) fn fruit_basket(root: &Path) {
    let (ext, h, w, inset, rc, seg) = ([0.30, 0.22], 0.08, 0.005, 0.02, 0.05, 8);
    let basket = shapes::basket(ext, h, w, inset, rc, seg);
    // (key, label, radius, half height, flat radius, yaw°, y offset, texture colours)
    type FruitSpec = (
        &'static str,
        &'static str,
        f64,
        f64,
        f64,
        f64,
        f64,
        [u8; 3],
        [u8; 3],
    );
    let specs: [FruitSpec; 3] = [
        (
            "object_b",
            "apple",
            0.040,
            0.036,
            0.020,
            10.0,
            0.02,
            [200, 40, 40],
            [230, 200, 60],
        ),
        (
            "object_c",
            "orange",
            0.036,
            0.035,
            0.018,
            50.0,
            -0.015,
            [240, 140, 20],
            [250, 170, 60],
        ),
        (
            "object_d",
            "plum",
            0.024,
            0.026,
            0.012,
            80.0,
            0.01,
            [110, 40, 120],
            [80, 20, 90],
        ),
    ];
    let floor = w;
    let meshes: Vec<Mesh> = specs
        .iter()
        .map(|s| shapes::fruit(s.2, s.3, s.4, 32, 16))
        .collect();
    // Each fruit stands on its flat spot at floor + gap; neighbours are spaced along x by
    // bisection on the exact mesh distance to 1.0 mm.
    let placed = |k: usize, x: f64| {
        meshes[k].transformed(&pose(V3::new(x, specs[k].6, floor + GAP), yaw(specs[k].5)).matrix())
    };
    let mut xs = vec![0.0];
    for k in 1..specs.len() {
        let prev = placed(k - 1, xs[k - 1]);
        let (mut lo, mut hi) = (xs[k - 1], xs[k - 1] + 0.2);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if mesh_distance(&prev, &placed(k, mid)) < 0.001 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        xs.push(hi);
    }
    let left = xs[0] - specs[0].2;
    let right = xs[2] + specs[2].2;
    let shift = -(left + right) / 2.0;
    let mut objs = vec![Obj::new(
        "object_a",
        "basket",
        format!("shapes::basket(top {} x {}, H {h}, wall {w}, inset {inset}, corner radius {rc}, {seg} segments)", ext[0], ext[1]),
        basket,
        UvProjection::Box { tile: 0.05 },
        shapes::checker_texture(TEX, 8, [150, 100, 50], [200, 160, 100], "basket weave"),
        pose(V3::zeros(), yaw(-15.0)),
    )];
    let turn = yaw(-15.0);
    let mut fact_rows = String::new();
    for (k, s) in specs.iter().enumerate() {
        let local = V3::new(xs[k] + shift, s.6, floor + GAP);
        objs.push(Obj::new(
            s.0,
            s.1,
            format!(
                "shapes::fruit(r {}, half height {}, flat radius {}, 32 slices, 16 rings)",
                s.2, s.3, s.4
            ),
            meshes[k].clone(),
            UvProjection::Spherical { repeat: 2.0 },
            shapes::stripes_texture(TEX, 8, s.7, s.8, s.1),
            pose(turn * local, turn * yaw(s.5)),
        ));
        let margin = face_rest_margin(&objs[k + 1].world_z());
        assert!(margin > 0.003);
        let _ = writeln!(
            fact_rows,
            "- {}: flat spot (radius {} mm) on the floor, bottom at height {} mm (floor {} + gap {}), centre of mass {} mm inside the flat; top at {} mm.",
            s.1,
            mm(s.4),
            mm(floor + GAP),
            mm(floor),
            mm(GAP),
            mm(margin),
            mm(floor + GAP + objs[k + 1].mesh.aabb().unwrap().max.z)
        );
    }
    let floor_y = floor;
    let mut contacts = Vec::new();
    for (k, what) in [
        "apple on the basket floor",
        "orange on the basket floor",
        "plum on the basket floor",
    ]
    .into_iter()
    .enumerate()
    {
        contacts.push(Contact {
            a: k + 1,
            b: 0,
            what,
            filter: Box::new(move |t: &[P3; 3]| t.iter().all(|p| (p.y - floor_y).abs() < 1e-6)),
        });
    }
    let facts = format!(
        "Analytic facts (computed Z-up, the scene turned −15° about the vertical, then converted to +Y up): the basket stands on its flat bottom at y = 0, flat inner floor at y = {} mm, rim at {} mm; walls lean outwards (bottom inset {} mm per side). The three fruits are spheroids cut flat at the bottom so each rests on its own flat spot on the floor (they do not lean on each other or on the walls):\n\n{}\nAlong the row, neighbours are spaced so the exact mesh distance is 1.0 mm (bisection; apple–orange and orange–plum), so they are \"touching\" in the Interact3D sense without any force between them.",
        mm(floor),
        mm(h),
        mm(inset),
        fact_rows
    );
    write_sample_folder(
        &root.join("fruit_basket"),
        "food",
        "A wicker basket holding an apple, an orange and a plum.",
        "fruit_basket",
        &objs,
        &contacts,
        "",
        &facts,
    );
}

pub(crate) fn box_tray(root: &Path) {
    let (ext, w, rim) = ([0.30, 0.20], 0.006, 0.018);
    let tray = shapes::tray(ext, w, rim);
    let bx = V3::new(0.12, 0.08, 0.05);
    let cz = w + GAP + bx.z / 2.0;
    let objs = [
        Obj::new(
            "tray",
            "tray",
            format!(
                "shapes::tray({} x {}, wall {w}, rim height {rim})",
                ext[0], ext[1]
            ),
            tray,
            UvProjection::Box { tile: 0.1 },
            shapes::checker_texture(TEX, 8, [120, 130, 140], [170, 180, 190], "tray checker"),
            pose(V3::zeros(), yaw(0.0)),
        ),
        checker_box(
            bx,
            ([190, 150, 100], [160, 120, 75], "cardboard"),
            V3::new(0.02, -0.01, cz),
            15.0,
        ),
    ];
    let margin = resting_box_margin(&objs[1]);
    let facts = format!(
        "Expected outcome: **passes**. The tray stands on the ground (z = 0); its flat inner floor is at z = {} mm, rim top at {} mm. The box ({} × {} × {} mm, turned 15° about z) rests flat on the floor with a {} mm gap: centre at z = {} + {} + {} = **{} mm**, (x, y) = (20, −10) mm; its centre of mass projects {} mm inside its bottom face. Poses: the tray uses translation + quaternion, the box a 4×4 matrix.",
        mm(w),
        mm(w + rim),
        mm(bx.x),
        mm(bx.y),
        mm(bx.z),
        mm(GAP),
        mm(w),
        mm(GAP),
        mm(bx.z / 2.0),
        mm(cz),
        mm(margin)
    );
    write_box_on(
        root,
        "box_tray",
        &objs,
        PoseForm::Matrix,
        "A cardboard box resting on a flat tray with a raised rim. Each OBJ has a PNG texture (`map_Kd`).",
        &facts,
    );
}

pub(crate) fn shelf_item(root: &Path) {
    let (w, d, h, t) = (0.40, 0.25, 0.60, 0.018);
    let levels = [0.05, 0.30, 0.55];
    let shelf = shapes::shelf(w, d, h, t, &levels);
    let bx = V3::new(0.12, 0.08, 0.10);
    let (cx, cy) = (0.03, 0.01);
    let cz = levels[1] + GAP + bx.z / 2.0;
    let objs = [
        Obj::new(
            "shelf",
            "shelf",
            format!(
                "shapes::shelf({w} x {d} x {h}, boards {t} thick, board tops at z = {} / {} / {})",
                levels[0], levels[1], levels[2]
            ),
            shelf,
            UvProjection::Box { tile: 0.2 },
            shapes::stripes_texture(TEX, 8, [150, 105, 60], [175, 130, 80], "wood grain"),
            pose(V3::zeros(), yaw(0.0)),
        ),
        checker_box(
            bx,
            ([60, 110, 170], [40, 80, 130], "blue box"),
            V3::new(cx, cy, cz),
            20.0,
        ),
    ];
    let margin = resting_box_margin(&objs[1]);
    let facts = format!(
        "Expected outcome: **passes**. The shelf ({} × {} × {} mm, open front and back) stands on its two side panels on the ground (z = 0). Its boards are {} mm thick with their top faces at z = {}, {} and {} mm; the cavity between the middle and the top board is {} mm high and {} mm wide. The box ({} × {} × {} mm, turned 20° about z) rests flat on the middle board with a {} mm gap: centre at z = {} + {} + {} = **{} mm**, (x, y) = ({}, {}) mm; its centre of mass projects {} mm inside its bottom face. A single convex hull of the shelf would fill the cavity and swallow the box.",
        mm(w),
        mm(d),
        mm(h),
        mm(t),
        mm(levels[0]),
        mm(levels[1]),
        mm(levels[2]),
        mm(levels[2] - t - levels[1]),
        mm(w - 2.0 * t),
        mm(bx.x),
        mm(bx.y),
        mm(bx.z),
        mm(GAP),
        mm(levels[1]),
        mm(GAP),
        mm(bx.z / 2.0),
        mm(cz),
        mm(cx),
        mm(cy),
        mm(margin)
    );
    write_box_on(
        root,
        "shelf_item",
        &objs,
        PoseForm::Parts,
        "A blue box standing on the middle board of an open wooden shelf. Each OBJ has a PNG texture (`map_Kd`).",
        &facts,
    );
}

/// The box of the two manifest scenes where a box rests on a support: a `bx` cuboid with a
/// checker texture (`colours`: two RGB tones and the texture's name), centred at `at` and turned
/// `yaw_deg` about z.
fn checker_box(bx: V3, colours: ([u8; 3], [u8; 3], &str), at: V3, yaw_deg: f64) -> Obj {
    Obj::new(
        "box",
        "box",
        format!("shapes::cuboid({} x {} x {})", bx.x, bx.y, bx.z),
        shapes::cuboid(bx),
        UvProjection::Box { tile: 0.12 },
        shapes::checker_texture(TEX, 4, colours.0, colours.1, colours.2),
        pose(at, yaw(yaw_deg)),
    )
}

/// How far (metres) the box's centre of mass projects inside its bottom face; more than 1 cm, or
/// the scene would not rest.
fn resting_box_margin(bx: &Obj) -> f64 {
    let margin = face_rest_margin(&bx.world_z());
    assert!(margin > 0.01, "{}: rest margin {margin}", bx.key);
    margin
}

/// Writes a manifest scene `name` of a support (`objs[0]`, pose as translation + quaternion) and
/// the box resting on it (`objs[1]`, pose written as `box_form`), both with friction 0.8, and
/// checks the box's gap to the support as written is `GAP`.
fn write_box_on(
    root: &Path,
    name: &str,
    objs: &[Obj; 2],
    box_form: PoseForm,
    description: &str,
    facts: &str,
) {
    let pairs = write_manifest(
        &root.join(name),
        name,
        &[
            (&objs[0], PoseForm::Parts, json!({ "friction": 0.8 })),
            (&objs[1], box_form, json!({ "friction": 0.8 })),
        ],
        description,
        facts,
    );
    assert!(
        (pairs[0].2 - GAP).abs() < 1e-9,
        "{name}: box-support gap {}",
        pairs[0].2
    );
}

pub(crate) fn plain_box(key: &str, label: &str, ext: V3, color: [f64; 4], p: Similarity) -> Obj {
    let m = shapes::cuboid(ext);
    let mut visual = shapes::visual(&m, UvProjection::Box { tile: 0.1 }, Default::default());
    visual.parts[0].material = interact3d::mesh::Material {
        name: label.into(),
        base_color: color,
        texture: None,
    };
    Obj {
        key: key.into(),
        label: label.into(),
        description: format!("shapes::cuboid({} x {} x {})", ext.x, ext.y, ext.z),
        mesh: m,
        visual,
        pose: p,
    }
}

pub(crate) fn fail_interpenetrating(root: &Path) {
    let big = V3::new(0.2, 0.2, 0.1);
    let small = V3::new(0.1, 0.1, 0.1);
    let sink = 0.003;
    let objs = [
        plain_box(
            "base",
            "box",
            big,
            [0.3, 0.5, 0.8, 1.0],
            pose(V3::new(0.0, 0.0, big.z / 2.0), yaw(0.0)),
        ),
        plain_box(
            "top",
            "box",
            small,
            [0.8, 0.4, 0.2, 1.0],
            pose(V3::new(0.02, 0.01, big.z - sink + small.z / 2.0), yaw(0.0)),
        ),
    ];
    let facts = format!(
        "Expected outcome: **fails** (interpenetration). The base box ({} × {} × {} mm) rests on the ground (z = 0 … {} mm). The top box ({} mm cube, centre at (20, 10, {}) mm) has its bottom at z = {} mm, i.e. **sunk {} mm** into the base: penetration depth 3 mm, overlap volume {} × {} × {} mm = **{:.1} cm³** (of {:.1} cm³ for the top box: {:.1} %).",
        mm(big.x),
        mm(big.y),
        mm(big.z),
        mm(big.z),
        mm(small.x),
        mm(big.z - sink + small.z / 2.0),
        mm(big.z - sink),
        mm(sink),
        mm(small.x),
        mm(small.y),
        mm(sink),
        small.x * small.y * sink * 1e6,
        small.x * small.y * small.z * 1e6,
        100.0 * sink / small.z
    );
    let pairs = write_manifest(
        &root.join("fail_interpenetrating"),
        "fail_interpenetrating",
        &[
            (&objs[0], PoseForm::Parts, json!({})),
            (&objs[1], PoseForm::Parts, json!({})),
        ],
        "A box sunk 3 mm into another box that rests on the ground. Untextured (MTL `Kd` colours only).",
        &facts,
    );
    assert_eq!(pairs[0].2, 0.0);
}

pub(crate) fn fail_unstable(root: &Path) {
    let ext = V3::new(0.1, 0.1, 0.06);
    let tilt = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), PI / 4.0);
    let low = shapes::cuboid(ext)
        .vertices
        .iter()
        .map(|p| (tilt * p.coords).z)
        .fold(f64::INFINITY, f64::min);
    let cz = -low + 0.0005;
    let obj = plain_box(
        "box",
        "box",
        ext,
        [0.9, 0.8, 0.2, 1.0],
        pose(V3::new(0.0, 0.0, cz), tilt),
    );
    let w = obj.world_z();
    let zmin = w.aabb().unwrap().min.z;
    let edge: Vec<&P3> = w.vertices.iter().filter(|p| p.z - zmin < 1e-9).collect();
    assert_eq!(edge.len(), 2, "rests on one edge");
    let offset = edge[0].y; // COM (y = 0) minus the edge's y
    let facts = format!(
        "Expected outcome: **fails** (not at rest: it topples). A box of {} × {} × {} mm rotated 45° about the horizontal x axis stands on one edge (parallel to x) {} mm above the ground; centre at z = {} mm. The support is a line, so the static support polygon has zero area. Because the box's cross-section is not square ({} × {} mm), its centre of mass is not over the edge but **{} mm beside it** (the edge is at y = {} mm, the centre at y = 0): gravity tips it about the edge by 45° onto its {} × {} mm face (centre of mass falls from {} mm to {} mm). A cube would be balanced exactly over its edge, an unstable equilibrium that a deterministic simulator may hold; this one falls for any solver.",
        mm(ext.x),
        mm(ext.y),
        mm(ext.z),
        mm(0.0005),
        mm(cz),
        mm(ext.y),
        mm(ext.z),
        mm(-offset),
        mm(offset),
        mm(ext.x),
        mm(ext.y),
        mm(cz),
        mm(ext.z / 2.0)
    );
    write_manifest(
        &root.join("fail_unstable"),
        "fail_unstable",
        &[(&obj, PoseForm::Parts, json!({}))],
        "A box standing on one edge on the ground. Untextured (MTL `Kd` colour only).",
        &facts,
    );
}

/// Seed of the guidance generator for `compose/ball_bowl` (tests/compose.rs regenerates it).
/// With seed 7 the striped ball came out 165° off its stripe-axis symmetry; seed 8 composes.
pub(crate) const COMPOSE_SEED: u64 = 8;

/// `compose/ball_bowl/`: the ball_bowl sample as `compose` takes it — the object GLBs, a
/// guidance part for each (`guidance_object_*.glb`: what segmenting a generated, fused scene
/// gives, from `interact3d::compose::synth` at [`COMPOSE_SEED`]), the descriptive metadata
/// without the registration, and the truth compose should find (`ground_truth_compose.json`).
/// A folder under `compose/`, so the scene fixtures' loops (every folder with a metadata.json)
/// do not take this registration-less sample for a scene.
pub(crate) fn compose_sample(root: &Path) {
    use interact3d::compose::synth;
    let src = root.join("ball_bowl");
    let dir = root.join("compose").join("ball_bowl");
    let _ = std::fs::remove_dir_all(&dir);
    let truth = synth::load_truth(&src).unwrap();
    let s = synth::make(&truth, COMPOSE_SEED, &synth::SynthOptions::default());
    synth::write_sample(&s, Some(&src), &dir).unwrap();
    write_text(
        &dir.join("README.md"),
        &format!(
            "# compose/ball_bowl\n\nThe `ball_bowl` fixture as `interact3d compose` takes it: `object_a.glb` (bowl) and `object_b.glb` (ball) as in `../../ball_bowl/`, and a guidance part for each, `guidance_object_*.glb`, made by `interact3d::compose::synth` (seed {COMPOSE_SEED}): each object placed by its true pose, the scene moved by a random similarity, {:.0} % and {:.0} % of the surfaces cut away as ragged holes, a strip of the neighbour fused in, noise, decimation and a tint. `metadata.json` is the sample's without its registration (what compose finds); `ground_truth_compose.json` gives the true object → guidance transforms. Generated by `cargo run --example make_fixtures`; do not edit by hand.\n\n```sh\ninteract3d compose fixtures/compose/ball_bowl -o out/composed\ninteract3d export out/composed -o out/composed_export --size bowl=0.16   # compose keeps the guidance scale\n```\n",
            100.0 * s.removed[0],
            100.0 * s.removed[1]
        ),
    );
}
