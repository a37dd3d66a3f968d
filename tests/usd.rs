//! USD export, judged by the engines that read it: usd-core opens every file and its validators
//! report nothing; UsdPhysics' own parser finds every body and every `convexHull` shape, with the
//! report's masses and inertias; PhysX (ovphysx, CPU) cooks every hull as written (within
//! 0.1 mm) and keeps every body of a passing scene within 1 mm and 1° over 2 s; Newton imports
//! the files. Needs Python with tests/python/requirements-usd.txt (.ci/run installs it);
//! `INTERACT3D_USD_PYTHON` names that interpreter (default: `INTERACT3D_PYTHON`, then `python3`).
//! The full sweep over every shared scene is `examples/usd_sweep.rs`.

mod common;
use common::*;
use interact3d::decompose::Hull;
use interact3d::mesh::P3;
use std::path::Path;
use std::process::Command;

const MM: f64 = 1e-3;

/// The export options for Isaac: the `isaac` profile, every hull within PhysX's 64 polygons
/// (not the default).
const ISAAC: &[&str] = &["--target", "isaac"];

/// How far (m) an authored hull vertex may lie outside the hull PhysX cooked, and a cooked
/// vertex from every authored one: issue #31's 0.1 mm (see `judge`).
const COOK_GAP: f64 = 0.1 * MM;

fn usd_python() -> String {
    std::env::var("INTERACT3D_USD_PYTHON").unwrap_or_else(|_| python())
}

fn check_usd(out: &Path, extra: &[&str]) -> serde_json::Value {
    let o = Command::new(usd_python())
        .arg(root().join("tests/python/check_usd.py"))
        .arg(out)
        .args(extra)
        .output()
        .expect("python3 must be installed (see .ci/run)");
    assert!(
        o.status.success(),
        "check_usd.py {} failed (install tests/python/requirements-usd.txt):\n{}",
        out.display(),
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| {
        panic!(
            "check_usd.py: bad JSON ({e}): {}",
            String::from_utf8_lossy(&o.stdout)
        )
    })
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// The farthest an authored hull vertex lies outside the hull PhysX cooked from it (m), over
/// every hull, and that hull's path. The cooked hull is the convex hull of the cooked vertices
/// matched to the hull's authored ones; the distance is exact (to its nearest triangle).
fn cooked_deviation(cooked: &serde_json::Value) -> (f64, String) {
    let pts = |v: &serde_json::Value| -> Vec<P3> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|p| P3::new(f(&p[0]), f(&p[1]), f(&p[2])))
            .collect()
    };
    let mut worst = (0.0f64, String::new());
    for h in cooked["per_hull"].as_array().unwrap() {
        let path = h["path"].as_str().unwrap().to_string();
        let (a, c) = (pts(&h["authored"]), pts(&h["cooked"]));
        let Some(hull) = Hull::from_points(&c) else {
            return (f64::INFINITY, path);
        };
        for p in &a {
            let d = if hull.plane_distance(p) <= 0.0 {
                0.0
            } else {
                hull.triangles
                    .iter()
                    .map(|t| {
                        let [x, y, z] = t.map(|k| hull.vertices[k as usize]);
                        point_triangle(p, &x, &y, &z)
                    })
                    .fold(f64::INFINITY, f64::min)
            };
            if d > worst.0 {
                worst = (d, path.clone());
            }
        }
    }
    worst
}

/// Distance from `p` to the triangle `abc` (Ericson, Real-Time Collision Detection, 5.1.5).
fn point_triangle(p: &P3, a: &P3, b: &P3, c: &P3) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.norm();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.norm();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (p - (a + ab * v)).norm();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.norm();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (p - (a + ac * w)).norm();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (p - (b + (c - b) * w)).norm();
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (p - (a + ab * v + ac * w)).norm()
}

#[test]
fn point_triangle_distance_is_exact_on_known_points() {
    let (a, b, c) = (
        P3::new(0.0, 0.0, 0.0),
        P3::new(1.0, 0.0, 0.0),
        P3::new(0.0, 1.0, 0.0),
    );
    for (p, want) in [
        (P3::new(0.25, 0.25, 2.0), 2.0),
        (P3::new(-3.0, -4.0, 0.0), 5.0),
        (P3::new(0.5, -1.0, 0.0), 1.0),
        (P3::new(1.0, 1.0, 0.0), 0.5f64.sqrt()),
        (P3::new(2.0, 0.0, 0.0), 1.0),
    ] {
        assert!(
            (point_triangle(&p, &a, &b, &c) - want).abs() < 1e-12,
            "{p:?}"
        );
    }
}

/// Export `scene` and hold its USD files to every judge; returns (report, check result).
fn judge(scene: &Path, extra: &[&str]) -> (serde_json::Value, serde_json::Value) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let code = export(scene, &out, extra);
    let report = read_json(&out.join("report.json"));
    let objects = report["objects"].as_array().unwrap();
    let u = check_usd(&out, &["--seconds", "2"]);
    let what = scene.display();

    // usd-core: every file opens, the validators report nothing, the stage metadata is set.
    let files = u["files"].as_object().unwrap();
    assert_eq!(
        files.len(),
        objects.len() + 1,
        "{what}: scene + one file per object"
    );
    for (name, fu) in files {
        assert_eq!(fu["opened"], true, "{what}: {name}");
        assert!(
            fu["errors"].as_array().unwrap().is_empty(),
            "{what}: {name}: validators report {}",
            fu["errors"]
        );
        assert!(f(&fu["validators"]) >= 10.0, "the validators were loaded");
        assert_eq!(fu["meters_per_unit"], 1.0, "{name}");
        assert_eq!(fu["kilograms_per_unit"], 1.0, "{name}");
        assert_eq!(fu["up_axis"], "Z", "{name}");
        assert!(fu["default_prim"].is_string(), "{name}");
    }

    // UsdPhysics' parser: one scene, every body, every hull a convexHull shape of its body,
    // masses and the inertia rebuilt from diagonalInertia + principalAxes as in report.json.
    let up = &u["usdphysics"];
    assert_eq!(up["scenes"], 1, "{what}: one PhysicsScene");
    assert_eq!(
        up["static_shapes"].as_array().unwrap().len(),
        1,
        "{what}: the ground is the only static collider: {}",
        up["static_shapes"]
    );
    let bodies = up["bodies"].as_object().unwrap();
    assert_eq!(bodies.len(), objects.len(), "{what}: {:?}", bodies.keys());
    for o in objects {
        let name = o["name"].as_str().unwrap();
        let b = &bodies[name];
        assert_eq!(b["dynamic"], !o["fixed"].as_bool().unwrap(), "{name}");
        let shapes = b["shapes"].as_array().unwrap();
        assert_eq!(
            shapes.len() as u64,
            o["hull_count"].as_u64().unwrap(),
            "{name}"
        );
        for s in shapes {
            assert_eq!(s["approximation"], "convexHull", "{name}: {s}");
        }
        let mass = f(&o["mass"]);
        assert!(((f(&b["mass"]) - mass) / mass).abs() < 1e-6, "{name}: mass");
        let (mut err, mut norm) = (0.0f64, 0.0f64);
        for r in 0..3 {
            for c in 0..3 {
                let want = f(&o["inertia"][r][c]);
                err = err.max((f(&b["inertia"][r][c]) - want).abs());
                norm = norm.max(want.abs());
            }
        }
        assert!(
            err <= 1e-5 * norm,
            "{name}: inertia from USD {} vs report {}",
            b["inertia"],
            o["inertia"]
        );
        for v in o["hull_vertex_counts"].as_array().unwrap() {
            assert!(v.as_u64().unwrap() <= 64, "{name}: hull of {v} vertices");
        }
    }

    // The PhysX settings the settle test assumed, as usd-core reads them with the PhysX schemas
    // registered: every body, collider and material carries them (src/export/usd.rs, PhysxCtx).
    physx_settings_are_the_settles(&u, &report, &what.to_string());

    // PhysX cooks every hull as written: its cooked vertices are authored ones, and every
    // authored vertex lies within 0.1 mm of the cooked hull (PhysX may drop a vertex that sits
    // on a face or an edge, never one that shapes the hull).
    let px = &u["physx"];
    let cooked = &px["cooked"];
    let hulls: u64 = objects
        .iter()
        .map(|o| o["hull_count"].as_u64().unwrap())
        .sum();
    assert_eq!(cooked["hulls"].as_u64().unwrap(), hulls, "{what}");
    // PhysX makes up no vertex of its own.
    assert!(
        f(&cooked["cooked_to_authored_max_m"]) <= COOK_GAP,
        "{what}: PhysX made up vertices: {}",
        cooked["cooked_to_authored_max_m"]
    );
    let (dev, path) = cooked_deviation(cooked);
    // Cooked as written: every authored vertex within 0.1 mm of the hull PhysX collides with.
    // Hull points are written in decimetres (scaled back by xformOp:scale), where PhysX's
    // plane tolerance is 0.07 mm instead of 0.7 mm (src/export/usd.rs); in
    // metres it skipped vertices up to 1.8 mm out, and past 64 polygons it re-cooks a round
    // hull up to 8 mm inside.
    let cook_limit = COOK_GAP;
    assert!(
        dev <= cook_limit,
        "{what}: PhysX re-cooked {path}: an authored vertex is {:.3} mm outside the cooked hull",
        dev / MM
    );
    // PhysX simulates the bodies with our masses; a passing scene stays where it was shipped.
    for o in objects.iter().filter(|o| !o["fixed"].as_bool().unwrap()) {
        let name = o["name"].as_str().unwrap();
        let b = &px["bodies"][name];
        assert_eq!(b["finite"], true, "{what}: {name}");
        let mass = f(&o["mass"]);
        assert!(
            ((f(&b["mass"]) - mass) / mass).abs() < 1e-5,
            "{name}: PhysX mass {}",
            b["mass"]
        );
        // The same agreement the MuJoCo tests hold. (With hull points in metres PhysX's
        // cooking dropped vertices up to 1.8 mm out and rolled ball_bowl's ball 1.46° and a
        // fruit of 00002_fruit_bowl 4.8°; cooked as written, 0.013° and 0.27°.)
        if code == 0 {
            assert!(
                f(&b["moved_m"]) <= MM && f(&b["turned_deg"]) <= 1.0,
                "{what}: validate calls it stable but PhysX moved {name} {:.3} mm, {:.3}° in 2 s",
                f(&b["moved_m"]) / MM,
                f(&b["turned_deg"])
            );
        }
    }
    (report, u)
}

/// Every body has `PhysxRigidBodyAPI` with the settle's damping and depenetration speed, every
/// hull and the ground `PhysxCollisionAPI` with PhysX's own contact offset and a rest offset
/// of 0 (on a scene with a heavily loaded body, a hull's offset is between -2 mm and 0: the depth
/// its stack rests at, `loaded_stacks_rest_at_the_settles_depth`), every material
/// `PhysxMaterialAPI` averaging friction as Rapier does, and the ground has the settle's floor
/// friction.
fn physx_settings_are_the_settles(u: &serde_json::Value, report: &serde_json::Value, what: &str) {
    let objects = report["objects"].as_array().unwrap();
    let loaded = report["validation"]["settle"]["heavily_loaded"]
        .as_array()
        .is_some_and(|l| !l.is_empty());
    let o = interact3d::physics::SettleOptions::default();
    let authored = u["physx_authored"].as_object().unwrap();
    let with = |schema: &str| -> Vec<(&String, &serde_json::Value)> {
        authored
            .iter()
            .filter(|(_, r)| r["schemas"].as_array().unwrap().iter().any(|s| s == schema))
            .collect()
    };
    // Authored as float (32 bits).
    let near = |v: &serde_json::Value, want: f64| (f(v) - want).abs() <= 1e-7 * want.abs().max(1.0);
    let bodies = with("PhysxRigidBodyAPI");
    assert_eq!(bodies.len(), objects.len(), "{what}: {:?}", bodies);
    for (p, r) in &bodies {
        let a = &r["attrs"];
        for (k, want) in [
            ("physxRigidBody:angularDamping", o.angular_damping),
            ("physxRigidBody:linearDamping", o.linear_damping),
            (
                "physxRigidBody:maxDepenetrationVelocity",
                o.max_corrective_velocity,
            ),
        ] {
            assert!(near(&a[k], want), "{what}: {p}: {k}: {a}");
        }
    }
    let hulls: u64 = objects
        .iter()
        .map(|o| o["hull_count"].as_u64().unwrap())
        .sum();
    let colliders = with("PhysxCollisionAPI");
    assert_eq!(
        colliders.len() as u64,
        hulls + 1,
        "{what}: every hull and the ground"
    );
    for (p, r) in &colliders {
        let a = &r["attrs"];
        // PhysX's own contact offset (not authored): Rapier's 2 mm toppled two scenes.
        assert!(
            a.get("physxCollision:contactOffset").is_none(),
            "{what}: {p}: {a}"
        );
        let rest = f(&a["physxCollision:restOffset"]);
        if !loaded || p.as_str() == "/World/Ground/Collider" {
            assert!(rest == 0.0, "{what}: {p}: {a}");
        } else {
            // The depth of a loaded stack, never an air gap.
            assert!((-2.0 * MM..=0.0).contains(&rest), "{what}: {p}: {a}");
        }
    }
    let materials = with("PhysxMaterialAPI");
    assert_eq!(
        materials.len(),
        objects.len() + 1,
        "{what}: every object's and the ground's"
    );
    for (p, r) in &materials {
        assert_eq!(
            r["attrs"]["physxMaterial:frictionCombineMode"], "average",
            "{what}: {p}"
        );
    }
    let ground = &authored["/World/Ground/PhysicsMaterial"]["attrs"];
    for k in ["physics:staticFriction", "physics:dynamicFriction"] {
        assert!(near(&ground[k], o.floor_friction), "{what}: {k}: {ground}");
    }
}

#[test]
fn fixtures_are_valid_usd_that_physx_simulates_as_written() {
    let fx = fixtures();
    assert!(fx.len() >= 4);
    let mut passing = 0;
    for f in fx {
        let (report, _) = judge(&f, ISAAC);
        passing += report["validation"]["passed"].as_bool().unwrap() as usize;
    }
    assert!(
        passing >= 4,
        "the passing fixtures were checked for stability"
    );
}

#[test]
fn shared_scenes_slice_is_valid_usd_that_physx_simulates_as_written() {
    if !shared().exists() {
        eprintln!("../shared not present: skipped");
        return;
    }
    let scenes = shared_scenes();
    assert!(scenes.len() >= 10);
    // A slice: the full sweep is examples/usd_sweep.rs. 00002_fruit_bowl is the scene PhysX
    // moved most while it cooked hulls other than ours (a fruit turned 4.8° in 2 s), and
    // 00009_bottle_lunchbox the one whose cooked hulls lay farthest inside ours (1.8 mm).
    for name in ["00002_fruit_bowl", "00009_bottle_lunchbox"] {
        let s = scenes
            .iter()
            .find(|s| s.ends_with(name))
            .unwrap_or_else(|| panic!("{name} in ../shared"));
        judge(s, ISAAC);
    }
}

#[test]
fn newton_imports_the_files() {
    let fx = root().join("fixtures/fruit_basket");
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    export(&fx, &out, ISAAC);
    let report = read_json(&out.join("report.json"));
    let u = check_usd(&out, &["--no-physx", "--newton"]);
    let n = &u["newton"];
    let objects = report["objects"].as_array().unwrap();
    let hulls: u64 = objects
        .iter()
        .map(|o| o["hull_count"].as_u64().unwrap())
        .sum();
    assert_eq!(
        n["scene.usda"]["bodies"].as_u64().unwrap() as usize,
        objects.len(),
        "{n}"
    );
    // Every hull, plus the ground, collides (the visual meshes do not).
    assert_eq!(
        n["scene.usda"]["collision_shapes"].as_u64().unwrap(),
        hulls + 1,
        "{n}"
    );
    // Newton collides the hulls at their authored size (it applies the hull Mesh's
    // xformOp:scale to the decimetre points): the diameters of its mesh shapes equal those
    // of the authored hulls in metres.
    let diag = |v: &serde_json::Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let (newton, authored) = (
        diag(&n["scene.usda"]["hull_diameters_m"]),
        diag(&n["authored_hull_diameters_m"]),
    );
    assert_eq!(newton.len() as u64, hulls, "{n}");
    assert_eq!(authored.len(), newton.len(), "{n}");
    for (a, b) in authored.iter().zip(&newton) {
        assert!(
            (a - b).abs() < 1e-6,
            "Newton hull diameter {b} m, authored {a} m"
        );
    }
    for o in objects {
        let name = o["name"].as_str().unwrap();
        let one = &n[format!("{name}.usda")];
        assert_eq!(one["bodies"], 1, "{name}: {n}");
        assert_eq!(one["collision_shapes"], o["hull_count"], "{name}: {n}");
    }
}

/// A heavily loaded body (one carrying at least `SettleOptions::load_ratio` times its own mass)
/// carries PhysX solver iterations in its USD; every other body keeps PhysX's own. Two box
/// stacks written here as our manifest, 0.4 m apart, each upper box 0.1 mm above the lower:
/// a 3 cm cube of 27 g under a 10 × 10 × 5 cm box of 1 kg (37×, loaded), and a 6 cm cube of
/// 108 g under a 0.5 kg box (4.6×, not). The masses, and so which body is loaded, are computed
/// here from the boxes' volumes and densities; PhysX then holds both stacks where our settle
/// left them (1 mm, 1° over 2 s).
#[test]
fn loaded_bodies_carry_the_loaded_solver_iterations() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = tmp.path().join("scene");
    std::fs::create_dir_all(scene.join("meshes")).unwrap();
    let gap = 1e-4;
    // (name, extents, density, x, bottom)
    let boxes: [(&str, [f64; 3], f64, f64, f64); 4] = [
        ("dice", [0.03, 0.03, 0.03], 1000.0, 0.0, 0.0),
        ("brick", [0.1, 0.1, 0.05], 2000.0, 0.0, 0.03 + gap),
        ("pad", [0.06, 0.06, 0.06], 500.0, 0.4, 0.0),
        ("weight", [0.1, 0.1, 0.05], 1000.0, 0.4, 0.06 + gap),
    ];
    let mut objects = Vec::new();
    for (name, e, density, x, bottom) in boxes {
        std::fs::write(
            scene.join(format!("meshes/{name}.obj")),
            common::box_extents_obj(e),
        )
        .unwrap();
        objects.push(serde_json::json!({
            "name": name,
            "mesh": format!("meshes/{name}.obj"),
            "label": name,
            "pose": {
                "translation": [x, 0.0, bottom + e[2] / 2.0],
                "quaternion_wxyz": [1.0, 0.0, 0.0, 0.0],
                "scale": 1.0
            },
            "density": density,
        }));
    }
    let manifest = serde_json::json!({
        "format": "interact3d-scene",
        "version": 1,
        "name": "stacks",
        "units": "m",
        "up_axis": "z",
        "objects": objects,
    });
    std::fs::write(
        scene.join("scene.json"),
        serde_json::to_string_pretty(&manifest).unwrap(),
    )
    .unwrap();
    let mass = |k: usize| boxes[k].1.iter().product::<f64>() * boxes[k].2;
    let o = interact3d::physics::SettleOptions::default();
    let loaded_by_hand = [
        mass(1) >= o.load_ratio * mass(0),
        false,
        mass(3) >= o.load_ratio * mass(2),
        false,
    ];
    assert_eq!(loaded_by_hand, [true, false, false, false]);

    let (report, u) = judge(&scene, ISAAC);
    assert_eq!(
        report["validation"]["passed"], true,
        "both stacks stand: {}",
        report["validation"]
    );
    // PhysX's own 16 position iterations times the settle's biased sweeps of a loaded island
    // over an unloaded one's (8 substeps × 4 sweeps against 4 × 1: 128); velocity PhysX's 1.
    let pos = 16 * (o.loaded_solver_iterations * o.loaded_pgs_iterations)
        / (o.solver_iterations * o.pgs_iterations);
    let vel = 1;
    assert_eq!(pos, 128, "the default settle's loaded island");
    assert_eq!(
        interact3d::export::usd::loaded_iterations(&o),
        (pos as u32, vel)
    );
    let authored = u["physx_authored"].as_object().unwrap();
    for (k, (name, ..)) in boxes.iter().enumerate() {
        let a = &authored[&format!("/World/{name}")]["attrs"];
        let counts = (
            a.get("physxRigidBody:solverPositionIterationCount"),
            a.get("physxRigidBody:solverVelocityIterationCount"),
        );
        if loaded_by_hand[k] {
            assert_eq!(
                (counts.0.map(f), counts.1.map(f)),
                (Some(pos as f64), Some(vel as f64)),
                "{name}: {a}"
            );
        } else {
            assert_eq!(counts, (None, None), "{name}: {a}");
        }
    }
    loaded_stacks_rest_at_the_settles_depth(&boxes, &loaded_by_hand, &u);
}

/// The rest offsets of the boxes of `loaded_bodies_carry_the_loaded_solver_iterations`, from
/// their exported poses: the loaded stack (dice under brick) rests its contacts as deep as our
/// settle left them, each pair's offsets summing to minus its depth (the dice's on the floor,
/// the dice's and the brick's), computed here from the boxes' extents and poses; the other
/// stack (not loaded) keeps 0. PhysX, from the exported pose, moves the brick less than a fifth
/// of the depth it would push out with rigid contacts.
fn loaded_stacks_rest_at_the_settles_depth(
    boxes: &[(&str, [f64; 3], f64, f64, f64); 4],
    loaded_by_hand: &[bool; 4],
    u: &serde_json::Value,
) {
    let authored = u["physx_authored"].as_object().unwrap();
    let offset = |name: &str| {
        f(
            &authored[&format!("/World/{name}/Collisions/Hull_00")]["attrs"]
                ["physxCollision:restOffset"],
        )
    };
    // A box's corners at its exported pose (body frame at its centre) and its rotation.
    let placed = |k: usize| -> (Vec<nalgebra::Point3<f64>>, nalgebra::Rotation3<f64>) {
        let (name, e, ..) = boxes[k];
        let b = &u["usdphysics"]["bodies"][name];
        let q: Vec<f64> = (0..4).map(|i| f(&b["orientation"][i])).collect();
        let r = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            q[0], q[1], q[2], q[3],
        ))
        .to_rotation_matrix();
        let c = nalgebra::Vector3::new(
            f(&b["position"][0]),
            f(&b["position"][1]),
            f(&b["position"][2]),
        );
        let corners = (0..8)
            .map(|m| {
                let s = |bit: usize| if m >> bit & 1 == 1 { 0.5 } else { -0.5 };
                let local = nalgebra::Vector3::new(s(0) * e[0], s(1) * e[1], s(2) * e[2]);
                nalgebra::Point3::from(c + r * local)
            })
            .collect();
        (corners, r)
    };
    let (dice, rd) = placed(0);
    let (brick, rb) = placed(1);
    let floor_depth = -dice.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
    // Two boxes resting face on face: the penetration is the smaller overlap along the two
    // face normals (the dice's top, the brick's bottom); a separating-axis depth.
    let along = |n: nalgebra::Vector3<f64>| -> f64 {
        let hi = dice
            .iter()
            .map(|p| n.dot(&p.coords))
            .fold(f64::MIN, f64::max);
        let lo = brick
            .iter()
            .map(|p| n.dot(&p.coords))
            .fold(f64::MAX, f64::min);
        hi - lo
    };
    let up = |r: &nalgebra::Rotation3<f64>| {
        let n = r * nalgebra::Vector3::z();
        if n.z < 0.0 {
            -n
        } else {
            n
        }
    };
    let pair_depth = along(up(&rd)).min(along(up(&rb)));
    // r_dice + 0 = -floor depth; r_dice + r_brick = -pair depth; written to the micrometre.
    let want = [-floor_depth, floor_depth - pair_depth];
    for (k, w) in want.iter().enumerate() {
        let got = offset(boxes[k].0);
        assert!(
            (got - w).abs() <= 3e-6,
            "{}: rest offset {got} m, the settle's depth says {w} m",
            boxes[k].0
        );
    }
    assert!(loaded_by_hand[0] && !loaded_by_hand[2]);
    for k in [2, 3] {
        assert_eq!(
            offset(boxes[k].0),
            0.0,
            "{}: not a loaded stack",
            boxes[k].0
        );
    }
    let moved = f(&u["physx"]["bodies"][boxes[1].0]["moved_m"]);
    eprintln!(
        "loaded stack: floor depth {:.4} mm, pair depth {:.4} mm; PhysX moved the brick {:.4} mm",
        floor_depth / MM,
        pair_depth / MM,
        moved / MM
    );
    assert!(
        moved <= 0.2 * pair_depth,
        "PhysX moved the brick {moved} m out of a {pair_depth} m deep rest"
    );
}
