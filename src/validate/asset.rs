//! Checks on a URDF or MJCF asset as authored: file, inertia, geometry, contact and physics.
//!
//! Entry points: [`check_path`] (read + check one file, never fails: an unreadable file is a
//! `file.parse_error` finding), [`check_asset`], [`AssetCheckOptions`].
//!
//! Geometry is what the engines collide: the convex hull of every collision mesh piece (OBJ
//! groups of a URDF are separate pieces, as PyBullet loads them; an MJCF mesh is one hull, as
//! MuJoCo loads it) and, for the bounding checks, tessellated primitives. Contact depths use
//! parry's exact boxes, spheres, capsules and cylinders ([`super::contact`]; ellipsoids and
//! meshes as hulls) in f64;
//! the settle and rest tests are [`crate::physics::settle`] through [`super::dynamic_checks`].

use super::contact::{self, Collider};
use super::finding::{AssetReport, Finding, CHECKS};
use crate::decompose::Hull;
use crate::io::asset::{geometric_inertial, Asset, AssetBody, ReadOptions, Shape, Source};
use crate::mesh::{Aabb, Mesh, P3};
use crate::physics::SettleOptions;
use nalgebra::Isometry3;
use std::path::Path;

/// Thresholds of the asset checks.
#[derive(Clone, Debug)]
pub struct AssetCheckOptions {
    pub read: ReadOptions,
    /// `inertia.placeholder`: largest ratio between an authored principal moment and the one
    /// the geometry implies at the authored mass.
    pub max_inertia_ratio: f64,
    /// `inertia.density`: plausible mass / volume range (kg/m³): foam to osmium.
    pub density_range: (f64, f64),
    /// `geometry.size`: plausible longest extent of a free body (m).
    pub size_range: (f64, f64),
    /// `geometry.concave_collision`: hull volume added, relative to the mesh's volume.
    pub max_hull_excess: f64,
    /// `geometry.gpu_hull_limit`: vertices and polygons of one convex shape.
    pub max_hull_vertices: usize,
    pub max_hull_polygons: usize,
    /// `geometry.visual_collision_mismatch`: largest bounding-box difference, relative to the
    /// visual diagonal.
    pub max_visual_collision_gap: f64,
    /// `contact.*`: largest initial penetration (m).
    pub max_penetration: f64,
    /// Run the settle and rest tests.
    pub physics: bool,
    /// The settle options; [`AssetCheckOptions::default`] turns the initial rotation kick off:
    /// a lone authored object is not a composed balance, and a ball given a kick rolls forever
    /// in every engine (no rolling resistance).
    pub settle: SettleOptions,
}

/// Cap on the settle phase for a lone asset (s). A scene's export settles up to 6 s so that
/// the pose it writes has come to rest (issue #33); an asset is judged where its author placed
/// it, over the same 4 s the engine judges of `tests/asset_judges.rs` watch (3 s of settling,
/// 1 s of rest): a half-cylinder tilted 15° still rocks 38° in PyBullet's 4th second, while
/// Rapier's contacts have damped it by the 7th.
pub const ASSET_SETTLE_MAX_TIME: f64 = 3.0;

impl Default for AssetCheckOptions {
    fn default() -> Self {
        AssetCheckOptions {
            read: ReadOptions::default(),
            max_inertia_ratio: 10.0,
            density_range: (5.0, 25_000.0),
            size_range: (0.005, 3.0),
            max_hull_excess: 0.05,
            max_hull_vertices: 64,
            max_hull_polygons: 64,
            max_visual_collision_gap: 0.10,
            max_penetration: 1e-3,
            physics: true,
            settle: SettleOptions {
                perturbation_speed: 0.0,
                settle_max_time: ASSET_SETTLE_MAX_TIME,
                ..SettleOptions::default()
            },
        }
    }
}

/// Read and check one URDF/MJCF file. `shown` is how the path is written in the report.
pub fn check_path(path: &Path, shown: &str, opts: &AssetCheckOptions) -> AssetReport {
    match crate::io::asset::load(path, &opts.read) {
        Ok(a) => check_asset(&a, shown, opts),
        Err(e) => {
            let msg = e.to_string();
            // "file: line N: ..." → N.
            let line = msg
                .split("line ")
                .nth(1)
                .and_then(|s| s.split(|c: char| !c.is_ascii_digit()).next())
                .and_then(|s| s.parse().ok())
                .unwrap_or(0);
            let file = match &e {
                crate::Error::Input { path, .. } | crate::Error::Io { path, .. } => {
                    path.display().to_string()
                }
                _ => shown.to_string(),
            };
            AssetReport {
                file: shown.to_string(),
                format: "unreadable".into(),
                bodies: 0,
                checks: vec!["file.parse_error".into()],
                findings: vec![Finding::new(
                    "file.parse_error",
                    shown,
                    &file,
                    line,
                    msg,
                    None,
                    None,
                    shown,
                )],
            }
        }
    }
}

/// Convex shapes of a body in the body frame: (geom name, its source, hull).
/// Primitives also carry their exact shape (core, radius, pose in the body frame), which the
/// contact depths use; their tessellated hull serves the bounding checks.
type BodyShape = (String, Source, Hull, Option<Mesh>, Option<Primitive>);
type Primitive = (parry3d_f64::shape::SharedShape, f64, Isometry3<f64>);

fn shapes(b: &AssetBody) -> Vec<BodyShape> {
    let mut out = Vec::new();
    for g in b.geoms.iter().filter(|g| g.collision) {
        let is_mesh = matches!(g.shape, Shape::Mesh { .. });
        let exact = contact::exact_primitive(g);
        let meshes = g.body_meshes();
        let n = meshes.len();
        for (k, m) in meshes.into_iter().enumerate() {
            if let Some(h) = Hull::from_points(&m.vertices) {
                // Pieces of one mesh file (OBJ groups) are told apart by their index.
                let name = if n > 1 {
                    format!("{}#{k}", g.name)
                } else {
                    g.name.clone()
                };
                out.push((name, g.src.clone(), h, is_mesh.then_some(m), exact.clone()));
            }
        }
    }
    out
}

/// Polygons of a hull: triangles merged by coplanarity.
fn polygon_count(h: &Hull) -> usize {
    let scale = h.aabb.diagonal().max(1e-12);
    let mut planes: Vec<(crate::mesh::V3, f64)> = Vec::new();
    for (n, d) in &h.planes {
        if !planes
            .iter()
            .any(|(m, e)| n.dot(m) > 1.0 - 1e-6 && (d - e).abs() < 1e-6 * scale)
        {
            planes.push((*n, *d));
        }
    }
    planes.len()
}

fn world_hull(h: &Hull, pose: &Isometry3<f64>) -> Hull {
    h.transformed(pose)
}

/// Run every check on an asset read without error.
pub fn check_asset(a: &Asset, shown: &str, opts: &AssetCheckOptions) -> AssetReport {
    let mut f: Vec<Finding> = Vec::new();
    let file_of = |s: &Source| s.file.display().to_string();
    let mut add = |check: &str,
                   subject: &str,
                   src: &Source,
                   message: String,
                   value: Option<f64>,
                   limit: Option<f64>| {
        f.push(Finding::new(
            check,
            subject,
            &file_of(src),
            src.line,
            message,
            value,
            limit,
            shown,
        ))
    };
    for i in &a.issues {
        add(i.check, &i.subject, &i.src, i.message.clone(), None, None);
    }
    // Placement: the file's floor at z = 0; without one, the lowest collision point on z = 0.
    let lift = match &a.floor {
        Some((h, _)) => -h,
        None => -a
            .bodies
            .iter()
            .flat_map(|b| {
                shapes(b).into_iter().flat_map(|s| {
                    s.2.vertices
                        .iter()
                        .map(|v| (b.pose * v).z)
                        .collect::<Vec<_>>()
                })
            })
            .fold(f64::INFINITY, f64::min),
    };
    let lift = if lift.is_finite() { lift } else { 0.0 };
    let place = |b: &AssetBody| {
        Isometry3::from_parts(
            nalgebra::Translation3::new(0.0, 0.0, lift) * b.pose.translation,
            b.pose.rotation,
        )
    };
    let body_shapes: Vec<_> = a.bodies.iter().map(shapes).collect();
    let world: Vec<Vec<Hull>> = a
        .bodies
        .iter()
        .zip(&body_shapes)
        .map(|(b, s)| s.iter().map(|x| world_hull(&x.2, &place(b))).collect())
        .collect();
    let mut inertia_ok = true;
    // Bodies whose authored tensor is a placeholder: simulated with the one their geometry
    // implies (one defect, one finding; see `physics_inertia`).
    let mut substitute: Vec<(String, nalgebra::Matrix3<f64>)> = Vec::new();
    for (bi, b) in a.bodies.iter().enumerate() {
        let name = &b.name;
        let all_pts: Vec<P3> = body_shapes[bi]
            .iter()
            .flat_map(|s| s.2.vertices.clone())
            .collect();
        let body_hull = Hull::from_points(&all_pts);
        // Inertia (dynamic bodies: a fixed body's mass is not simulated).
        if !b.fixed {
            if let Some(ai) = &b.inertial {
                let eig = ai.inertia.symmetric_eigenvalues();
                let mut e: Vec<f64> = eig.iter().copied().collect();
                e.sort_by(f64::total_cmp);
                if !(ai.mass > 0.0) || !(e[0] > 0.0) {
                    inertia_ok = false;
                    add(
                        "inertia.positive_definite",
                        name,
                        &ai.src,
                        format!(
                            "mass {:.4e} kg, principal moments ({:.3e}, {:.3e}, {:.3e}) kg·m²: mass and moments must be > 0",
                            ai.mass, e[0], e[1], e[2]
                        ),
                        Some(ai.mass.min(e[0])),
                        Some(0.0),
                    );
                } else {
                    let excess = e[2] - (e[0] + e[1]);
                    if excess > 1e-9 * e[2] {
                        inertia_ok = false;
                        add(
                            "inertia.triangle_inequality",
                            name,
                            &ai.src,
                            format!(
                                "principal moments ({:.4e}, {:.4e}, {:.4e}) kg·m²: the largest exceeds the sum of the other two by {:.3e} (limit 0)",
                                e[0], e[1], e[2], excess
                            ),
                            Some(excess),
                            Some(0.0),
                        );
                    }
                    if let Some(g) = geometric_inertial(b).filter(|g| g.mass > 0.0) {
                        let density = ai.mass / g.volume;
                        let (lo, hi) = opts.density_range;
                        if g.volume > 0.0 && !(lo..=hi).contains(&density) {
                            add(
                                "inertia.density",
                                name,
                                &ai.src,
                                format!(
                                    "mass {:.4} kg in {:.4e} m³ of collision volume is {:.4e} kg/m³, outside {lo}..{hi} kg/m³{}",
                                    ai.mass, g.volume, density,
                                    if density > hi { " (mass in grams?)" } else { "" }
                                ),
                                Some(density),
                                Some(if density > hi { hi } else { lo }),
                            );
                        }
                        let implied = g.with_mass(ai.mass);
                        let mut ge: Vec<f64> = implied
                            .inertia
                            .symmetric_eigenvalues()
                            .iter()
                            .copied()
                            .collect();
                        ge.sort_by(f64::total_cmp);
                        let ratio = (0..3)
                            .map(|k| (e[k] / ge[k]).max(ge[k] / e[k]))
                            .fold(0.0f64, f64::max);
                        if ratio > opts.max_inertia_ratio {
                            substitute.push((name.clone(), implied.inertia));
                            add(
                                "inertia.placeholder",
                                name,
                                &ai.src,
                                format!(
                                    "authored principal moments ({:.3e}, {:.3e}, {:.3e}) kg·m² are {ratio:.3e}x the ({:.3e}, {:.3e}, {:.3e}) its geometry implies at {:.4} kg (limit {}x)",
                                    e[0], e[1], e[2], ge[0], ge[1], ge[2], ai.mass, opts.max_inertia_ratio
                                ),
                                Some(ratio),
                                Some(opts.max_inertia_ratio),
                            );
                        }
                    }
                }
                if let Some(h) = &body_hull {
                    let d = h.plane_distance(&ai.com);
                    let tol = 0.01 * h.aabb.diagonal();
                    if d > tol {
                        add(
                            "inertia.com_outside",
                            name,
                            &ai.src,
                            format!(
                                "centre of mass ({:.4}, {:.4}, {:.4}) m is {:.2} mm outside the convex hull of the body's collision geometry (limit {:.2} mm)",
                                ai.com.x, ai.com.y, ai.com.z, d * 1e3, tol * 1e3
                            ),
                            Some(d),
                            Some(tol),
                        );
                    }
                }
            }
        }
        // Geometry.
        let vis = Aabb::of_points(b.visual_meshes().iter().flat_map(|m| m.vertices.iter()));
        if !b.fixed {
            if let Some(v) = &vis {
                let ext = v.extents().max();
                let (lo, hi) = opts.size_range;
                if !(lo..=hi).contains(&ext) {
                    add(
                        "geometry.size",
                        name,
                        &b.src,
                        format!(
                            "longest extent {ext:.4} m is outside {lo}..{hi} m for a tabletop object{}",
                            if ext > hi { " (a mesh in millimetres?)" } else { " (a mesh in metres scaled twice?)" }
                        ),
                        Some(ext),
                        Some(if ext > hi { hi } else { lo }),
                    );
                }
            }
        }
        let col = Aabb::of_points(body_shapes[bi].iter().flat_map(|s| s.2.vertices.iter()));
        let has_visual = b.geoms.iter().any(|g| g.visual && !g.collision);
        if let (Some(v), Some(c), true) = (&vis, &col, has_visual) {
            let gap = (0..3)
                .map(|k| (v.min[k] - c.min[k]).abs().max((v.max[k] - c.max[k]).abs()))
                .fold(0.0f64, f64::max);
            let rel = gap / v.diagonal().max(1e-12);
            if rel > opts.max_visual_collision_gap {
                add(
                    "geometry.visual_collision_mismatch",
                    name,
                    &b.src,
                    format!(
                        "visual and collision bounding boxes differ by {:.2} mm, {:.1}% of the visual diagonal (limit {:.0}%)",
                        gap * 1e3, rel * 100.0, opts.max_visual_collision_gap * 100.0
                    ),
                    Some(rel),
                    Some(opts.max_visual_collision_gap),
                );
            }
        }
        for (si, (gname, src, h, mesh, _)) in body_shapes[bi].iter().enumerate() {
            let polys = polygon_count(h);
            let nv = h.vertices.len();
            // Primitives are analytic shapes in every engine; only meshes are cooked.
            if mesh.is_some() && (nv > opts.max_hull_vertices || polys > opts.max_hull_polygons) {
                add(
                    "geometry.gpu_hull_limit",
                    gname,
                    src,
                    format!(
                        "convex shape has {nv} vertices and {polys} polygons, over the PhysX GPU limit of {} vertices / {} polygons",
                        opts.max_hull_vertices, opts.max_hull_polygons
                    ),
                    Some(nv.max(polys) as f64),
                    Some(opts.max_hull_vertices.min(opts.max_hull_polygons) as f64),
                );
            }
            let Some(m) = mesh else { continue };
            let vol = m.signed_volume();
            if !(m.is_closed() && vol > 0.0) {
                continue;
            }
            let added = h.volume - vol;
            let rel = added / vol;
            if rel <= opts.max_hull_excess {
                continue;
            }
            add(
                "geometry.concave_collision",
                gname,
                src,
                format!(
                    "collision mesh is concave: the convex hull engines collide with adds {:.3} cm³, {:.1}% of its {:.3} cm³ (limit {:.0}%)",
                    added * 1e6, rel * 100.0, vol * 1e6, opts.max_hull_excess * 100.0
                ),
                Some(rel),
                Some(opts.max_hull_excess),
            );
            // Does another body sit inside that hull?
            let wh = &world[bi][si];
            for (oj, ob) in a.bodies.iter().enumerate() {
                if oj == bi {
                    continue;
                }
                let deepest = world[oj]
                    .iter()
                    .flat_map(|oh| oh.vertices.iter())
                    .map(|p| -wh.plane_distance(p))
                    .fold(f64::NEG_INFINITY, f64::max);
                if deepest > opts.max_penetration {
                    add(
                        "geometry.hull_inside_body",
                        &format!("{gname}/{}", ob.name),
                        src,
                        format!(
                            "body {} sits {:.2} mm inside the convex hull of concave collision mesh {gname}: engines will push it out (limit {:.2} mm)",
                            ob.name, deepest * 1e3, opts.max_penetration * 1e3
                        ),
                        Some(deepest),
                        Some(opts.max_penetration),
                    );
                }
            }
        }
    }
    // Contact at the initial pose: exact primitives, hulls of meshes and ellipsoids.
    let colliders: Vec<Vec<Collider>> = a
        .bodies
        .iter()
        .enumerate()
        .map(|(i, b)| {
            body_shapes[i]
                .iter()
                .zip(&world[i])
                .filter_map(|(s, wh)| match &s.4 {
                    Some((core, r, local)) => {
                        Some(Collider::primitive(core.clone(), *r, local, &place(b)))
                    }
                    None => Collider::hull(wh),
                })
                .collect()
        })
        .collect();
    for i in 0..a.bodies.len() {
        for j in i + 1..a.bodies.len() {
            if a.bodies[i].fixed && a.bodies[j].fixed {
                continue;
            }
            let deepest = contact::pair_depth(&colliders[i], &colliders[j]);
            if deepest > opts.max_penetration {
                let (bi, bj) = (&a.bodies[i], &a.bodies[j]);
                add(
                    "contact.penetration",
                    &format!("{}/{}", bi.name, bj.name),
                    &bj.src,
                    format!(
                        "collision shapes of {} and {} interpenetrate by {:.3} mm at the initial pose (limit {:.3} mm)",
                        bi.name, bj.name, deepest * 1e3, opts.max_penetration * 1e3
                    ),
                    Some(deepest),
                    Some(opts.max_penetration),
                );
            }
        }
    }
    if a.floor.is_some() {
        for (i, b) in a.bodies.iter().enumerate() {
            let low = contact::lowest_z(&colliders[i]);
            if -low > opts.max_penetration {
                add(
                    "contact.floor",
                    &b.name,
                    &b.src,
                    format!(
                        "collision shapes reach {:.3} mm below the floor at the initial pose (limit {:.3} mm)",
                        -low * 1e3,
                        opts.max_penetration * 1e3
                    ),
                    Some(-low),
                    Some(opts.max_penetration),
                );
            }
        }
    }
    let mut checks: Vec<String> = CHECKS
        .iter()
        .map(|c| c.0.to_string())
        .filter(|c| c != "file.parse_error" && (a.floor.is_some() || c != "contact.floor"))
        .collect();
    // Physics.
    let mut assembly = a.to_assembly();
    for b in &mut assembly.bodies {
        b.pose.translation.vector.z += lift;
        b.composed_pose = b.pose;
        if let Some((_, t)) = substitute.iter().find(|s| s.0 == b.name) {
            b.inertial.inertia = *t;
        }
    }
    let dynamic = assembly.bodies.iter().any(|b| !b.fixed);
    if !opts.physics {
        checks.retain(|c| !c.starts_with("physics."));
    } else if !inertia_ok || !dynamic {
        let why = if !dynamic {
            "no free body to simulate"
        } else {
            "an authored inertia is invalid (MuJoCo refuses such a model)"
        };
        let src = a.bodies.first().map(|b| b.src.clone()).unwrap_or(Source {
            file: a.file.clone(),
            line: 0,
        });
        add(
            "physics.skipped",
            &a.name,
            &src,
            format!("settle and rest tests not run: {why}"),
            None,
            None,
        );
    } else {
        match crate::physics::settle(&super::sim_bodies(&assembly), &opts.settle) {
            Ok(report) => {
                for c in super::dynamic_checks(&report, &opts.settle)
                    .into_iter()
                    .filter(|c| !c.passed)
                {
                    let b = a.bodies.iter().find(|b| b.name == c.subject);
                    let src = b.map(|b| b.src.clone()).unwrap_or(Source {
                        file: a.file.clone(),
                        line: 0,
                    });
                    let note = if substitute.iter().any(|s| s.0 == c.subject) {
                        " (simulated with the inertia its geometry implies: the authored one is a placeholder)"
                    } else {
                        ""
                    };
                    add(
                        &format!("physics.{}", c.name),
                        &c.subject,
                        &src,
                        format!("{}{note}", c.message),
                        Some(c.value),
                        Some(c.limit),
                    );
                }
            }
            Err(e) => add(
                "physics.skipped",
                &a.name,
                &Source {
                    file: a.file.clone(),
                    line: 0,
                },
                format!("settle and rest tests not run: {e}"),
                None,
                None,
            ),
        }
    }
    f.sort_by(|x, y| {
        (&x.file, x.line, &x.check, &x.subject).cmp(&(&y.file, y.line, &y.check, &y.subject))
    });
    AssetReport {
        file: shown.to_string(),
        format: a.format.to_string(),
        bodies: a.bodies.len(),
        checks,
        findings: f,
    }
}
