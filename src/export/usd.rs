//! USD export: `scene.usda` and one `<object>.usda` per object, text USD rendered from the
//! templates `scene.usda.j2` and `object.usda.j2` (UsdPhysics + PhysX schemas).
//!
//! Entry point: [`write_usd`], called by [`super::export`] after the mesh files are written (the
//! object files read the PNG textures under `meshes/`). [`principal_axes`] turns a full inertia
//! tensor into USD's diagonal inertia and principal-axes quaternion.
//!
//! Each object file: an Xform default prim with `PhysicsRigidBodyAPI` + `PhysicsMassAPI` (mass,
//! centre of mass, diagonal inertia, principal axes), `Looks` (a physics material, one
//! `UsdPreviewSurface` per visual material reading our PNGs), `Visuals` (meshes with normals and
//! UVs) and `Collisions` (one guide-purpose `Mesh` per hull, `convexHull` approximation,
//! `PhysxConvexHullCollisionAPI` vertex limit 64, bound to the physics material). The scene
//! file: a `PhysicsScene` with gravity, a static ground box, and every object referenced at its
//! initial pose, the composed pose in `customData`, fixed objects static. Both say, in PhysX's
//! schemas, what our settle test assumed ([`PhysxCtx`]: damping, depenetration speed, friction
//! combine rule, rest offset, the floor's friction), and a body our settle marked heavily loaded
//! carries the solver iterations its island got there ([`loaded_iterations`]).

use super::files::{material_groups, BodyFiles};
use super::format::f;
use super::{Templates, GENERATOR};
use crate::body::{Assembly, Body};
use crate::error::Result;
use crate::mesh::{P3, V3};
use crate::physics::SettleOptions;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use rayon::prelude::*;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

#[derive(Clone, Serialize)]
struct MaterialCtx {
    prim: String,
    color: String,
    opacity: String,
    texture: Option<String>,
}

#[derive(Clone, Serialize)]
struct MeshCtx {
    prim: String,
    material: String,
    points: String,
    counts: String,
    indices: String,
    normals: String,
    st: Option<String>,
    extent: String,
    /// A hull's `physxCollision:restOffset` (m): the depth its loaded stack rests at
    /// ([`super::rest_offset`]), 0 outside one; empty for a visual mesh.
    rest_offset: String,
}

#[derive(Clone, Serialize)]
struct ObjectCtx {
    prim: String,
    name: String,
    file: String,
    mass: String,
    com: String,
    diagonal_inertia: String,
    principal_axes: String,
    friction: String,
    fixed: bool,
    fixed_usd: &'static str,
    /// Our settle marked this body heavily loaded: it carries the loaded solver iterations.
    loaded: bool,
    pos: String,
    orient: String,
    composed_pos: String,
    composed_orient: String,
    materials: Vec<MaterialCtx>,
    visuals: Vec<MeshCtx>,
    hulls: Vec<MeshCtx>,
}

/// The PhysX settings the files author (`PhysxRigidBodyAPI`, `PhysxMaterialAPI`,
/// `PhysxCollisionAPI`, the ground's friction): what the settle test that validated the pose
/// assumed, so that PhysX simulates the same world instead of its own defaults. PhysX's default
/// differs on angular damping (0.05 where Rapier has none); the ground's friction was 1 where
/// the settle's floor has 0.8. The rest is PhysX's default authored so that the file says it:
/// friction combined by averaging (Rapier's rule), rest offset 0, depenetration at most 3 m/s
/// (Rapier's `max_corrective_velocity`), no linear damping. The contact offset stays PhysX's
/// own: Rapier's 2 mm prediction distance (1 mm a shape) let PhysX topple two shoes in mugs from
/// the composed pose that it holds with its default (docs/agreement.md, session 15).
#[derive(Clone, Serialize)]
pub struct PhysxCtx {
    /// `physxRigidBody:angularDamping`, `linearDamping` (1/s).
    angular_damping: String,
    linear_damping: String,
    /// `physxRigidBody:maxDepenetrationVelocity` (m/s).
    max_depenetration_velocity: String,
    /// `physxMaterial:frictionCombineMode` of every material, the ground's included.
    friction_combine: &'static str,
    /// The ground's friction coefficient.
    floor_friction: String,
    /// `physxRigidBody:solverPositionIterationCount` / `solverVelocityIterationCount` of a body
    /// our settle marked heavily loaded ([`loaded_iterations`]); other bodies keep PhysX's.
    loaded_position_iterations: u32,
    loaded_velocity_iterations: u32,
}

/// PhysX's own solver iterations (the `PhysxRigidBodyAPI` defaults: 16 position, 1 velocity).
pub const PHYSX_POSITION_ITERATIONS: u32 = 16;
pub const PHYSX_VELOCITY_ITERATIONS: u32 = 1;

/// The solver iterations (position, velocity) a heavily loaded body gets in PhysX: PhysX's own
/// position iterations scaled by how much more our settle solves a loaded island than any other
/// ([`crate::physics::load_ratio`]): Rapier runs `solver_iterations × pgs_iterations` biased
/// sweeps a step and a loaded island `loaded_solver_iterations × loaded_pgs_iterations` (4 × 1
/// → 8 × 4: 8×), so 16 → 128 (within PhysX's 255). The velocity iterations stay PhysX's 1: a
/// Rapier substep ends with its own unbiased sweep, which TGS's position iterations (one
/// integration each) already stand for, while PhysX's velocity iterations are one pass at the
/// end of the step; measured, 2 (the substep ratio) broke two more verdicts on 400..700 and
/// fixed one rest more (docs/agreement.md, "Twelfth stop"). PhysX solves an island with the
/// largest count of its bodies, as Rapier adds a loaded body's extra iterations to its
/// island, so the count on the loaded body alone reaches the whole stack.
pub fn loaded_iterations(o: &SettleOptions) -> (u32, u32) {
    // A loaded island runs at least the world's substeps and sweeps (`load_extra_iterations`
    // adds only what is missing).
    let own = (o.solver_iterations * o.pgs_iterations).max(1) as f64;
    let loaded = (o.loaded_solver_iterations.max(o.solver_iterations)
        * o.loaded_pgs_iterations.max(o.pgs_iterations))
    .max(1) as f64;
    let ratio = loaded / own;
    let pos = (PHYSX_POSITION_ITERATIONS as f64 * ratio).round() as u32;
    (
        pos.clamp(PHYSX_POSITION_ITERATIONS, 255),
        PHYSX_VELOCITY_ITERATIONS,
    )
}

impl PhysxCtx {
    /// The settings of the settle test `o`.
    pub fn from_settle(o: &SettleOptions) -> Self {
        let (loaded_position_iterations, loaded_velocity_iterations) = loaded_iterations(o);
        PhysxCtx {
            angular_damping: f(o.angular_damping),
            linear_damping: f(o.linear_damping),
            max_depenetration_velocity: f(o.max_corrective_velocity),
            // Rapier's default combine rule; the settle never sets another.
            friction_combine: "average",
            floor_friction: f(o.floor_friction),
            loaded_position_iterations,
            loaded_velocity_iterations,
        }
    }
}

/// Write `scene.usda` and `<object>.usda` for every body into `dir` (the export folder, whose
/// `meshes/` already holds the textures named in `files`, one entry per body), with the PhysX
/// settings `physx`; the bodies named in `loaded` (our settle's heavily loaded ones) carry the
/// loaded solver iterations.
pub fn write_usd(
    a: &Assembly,
    files: &[BodyFiles],
    dir: &Path,
    templates: &Templates,
    physx: &PhysxCtx,
    loaded: &[String],
) -> Result<()> {
    let prims = prim_names(a.bodies.iter().map(|b| b.name.as_str()));
    let offsets = super::rest_offset::rest_offsets(a, loaded);
    // One file per body, written side by side; the first error in body order is reported.
    let jobs: Vec<(&Body, &BodyFiles, String, Vec<f64>)> = a
        .bodies
        .iter()
        .zip(files)
        .zip(prims)
        .zip(offsets)
        .map(|(((b, fl), prim), r)| (b, fl, prim, r))
        .collect();
    let written: Vec<Result<ObjectCtx>> = jobs
        .into_par_iter()
        .map(|(b, fl, prim, rest_offset)| {
            let ctx = object_context(b, fl, prim, loaded.contains(&b.name), &rest_offset);
            let text = templates.render(
                "object.usda.j2",
                minijinja::context! {
                    generator => GENERATOR,
                    b => ctx.clone(),
                    hull_scale => hull_scale(),
                    physx => physx,
                },
            )?;
            crate::fsutil::write(&dir.join(&ctx.file), text.as_bytes())?;
            // The scene needs no mesh data.
            Ok(ObjectCtx {
                materials: Vec::new(),
                visuals: Vec::new(),
                hulls: Vec::new(),
                ..ctx
            })
        })
        .collect();
    let objects = written.into_iter().collect::<Result<Vec<_>>>()?;
    let text = templates.render(
        "scene.usda.j2",
        minijinja::context! {
            generator => GENERATOR,
            bodies => objects,
            floor_friction => physx.floor_friction.clone(),
            physx => physx,
        },
    )?;
    crate::fsutil::write(&dir.join("scene.usda"), text.as_bytes())
}

/// USD prim names for object names: `-` and anything else outside `[A-Za-z0-9_]` become `_`, a
/// leading digit gets a `_`, and a name taken twice gets `_2`, `_3`… (object names are unique,
/// but `a-b` and `a_b` are one prim name).
fn prim_names<'a>(names: impl Iterator<Item = &'a str>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for n in names {
        let mut p: String = n
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        if !p.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') {
            p.insert(0, '_');
        }
        let base = p.clone();
        let mut k = 2;
        while out.contains(&p) || p == "World" {
            p = format!("{base}_{k}");
            k += 1;
        }
        out.push(p);
    }
    out
}

fn object_context(
    b: &Body,
    files: &BodyFiles,
    prim: String,
    loaded: bool,
    rest_offsets: &[f64],
) -> ObjectCtx {
    let (diag, axes) = principal_axes(&b.inertial.inertia);
    let c = b.inertial.com;
    let groups = material_groups(b);
    let materials: Vec<MaterialCtx> = files
        .materials
        .iter()
        .enumerate()
        .map(|(k, m)| MaterialCtx {
            prim: format!("Material_{k:02}"),
            color: tuple(&[m.rgba[0], m.rgba[1], m.rgba[2]]),
            opacity: f(m.rgba[3]),
            texture: m.texture.as_ref().map(|t| format!("./meshes/{t}")),
        })
        .collect();
    let mut visuals = Vec::new();
    for (k, (_, parts)) in groups.iter().enumerate() {
        for p in parts {
            visuals.push(MeshCtx {
                prim: format!("Visual_{:02}", visuals.len()),
                material: materials[k].prim.clone(),
                points: points(&p.positions),
                counts: counts(p.triangles.len()),
                indices: indices(&p.triangles),
                normals: points(&vertex_normals(&p.positions, &p.triangles)),
                // glTF's v grows downwards, USD's st upwards.
                st: p.uvs.as_ref().map(|uv| {
                    let mut s = String::from("[");
                    for (i, t) in uv.iter().enumerate() {
                        if i > 0 {
                            s.push_str(", ");
                        }
                        write!(s, "({}, {})", f(t[0]), f(1.0 - t[1])).unwrap();
                    }
                    s.push(']');
                    s
                }),
                extent: extent(&p.positions),
                rest_offset: String::new(),
            });
        }
    }
    let hulls = b
        .hulls
        .iter()
        .enumerate()
        .map(|(k, h)| MeshCtx {
            prim: format!("Hull_{k:02}"),
            material: String::new(),
            points: points(&in_hull_units(&h.vertices)),
            counts: counts(h.triangles.len()),
            indices: indices(&h.triangles),
            normals: String::new(),
            st: None,
            extent: extent(&in_hull_units(&h.vertices)),
            rest_offset: f(rest_offsets[k]),
        })
        .collect();
    let quat = |q: &UnitQuaternion<f64>| tuple(&[q.w, q.i, q.j, q.k]);
    let pos = |v: &Vector3<f64>| tuple(&[v.x, v.y, v.z]);
    ObjectCtx {
        file: format!("{}.usda", b.name),
        name: b.name.clone(),
        prim,
        mass: f(b.inertial.mass),
        com: tuple(&[c.x, c.y, c.z]),
        diagonal_inertia: tuple(&[diag.x, diag.y, diag.z]),
        principal_axes: quat(&axes),
        friction: f(b.friction),
        fixed: b.fixed,
        fixed_usd: if b.fixed { "true" } else { "false" },
        loaded,
        pos: pos(&b.pose.translation.vector),
        orient: quat(&b.pose.rotation),
        composed_pos: pos(&b.composed_pose.translation.vector),
        composed_orient: quat(&b.composed_pose.rotation),
        materials,
        visuals,
        hulls,
    }
}

/// USD's form of a full inertia tensor `i` (body frame): the principal moments and the rotation
/// whose columns are the principal axes, `i = R·diag(d)·Rᵀ`. Deterministic: a tensor already
/// diagonal (off-diagonal terms under 1e-12 of the largest moment) keeps its axes and the
/// identity; otherwise the moments are sorted ascending, each axis points so that its largest
/// component is positive, the third axis is flipped if needed to make a rotation, and the
/// quaternion has `w ≥ 0`.
pub fn principal_axes(i: &Matrix3<f64>) -> (Vector3<f64>, UnitQuaternion<f64>) {
    let scale = (0..3).map(|k| i[(k, k)].abs()).fold(0.0, f64::max);
    let off = [i[(0, 1)], i[(0, 2)], i[(1, 2)]]
        .iter()
        .map(|x| x.abs())
        .fold(0.0, f64::max);
    if off <= 1e-12 * scale {
        return (
            Vector3::new(i[(0, 0)], i[(1, 1)], i[(2, 2)]),
            UnitQuaternion::identity(),
        );
    }
    let sym = (i + i.transpose()) * 0.5;
    let e = sym.symmetric_eigen();
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| {
        e.eigenvalues[a]
            .total_cmp(&e.eigenvalues[b])
            .then(a.cmp(&b))
    });
    let mut r = Matrix3::zeros();
    for (col, &k) in order.iter().enumerate() {
        let mut v: Vector3<f64> = e.eigenvectors.column(k).into_owned();
        let big = (0..3)
            .max_by(|&a, &b| v[a].abs().total_cmp(&v[b].abs()).then(b.cmp(&a)))
            .unwrap();
        if v[big] < 0.0 {
            v = -v;
        }
        r.set_column(col, &v.normalize());
    }
    if r.determinant() < 0.0 {
        let c = -r.column(2).into_owned();
        r.set_column(2, &c);
    }
    let mut q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(&r));
    if q.w < 0.0 {
        q = UnitQuaternion::new_unchecked(-q.into_inner());
    }
    let d = Vector3::new(
        e.eigenvalues[order[0]],
        e.eigenvalues[order[1]],
        e.eigenvalues[order[2]],
    );
    (d, q)
}

/// Hull points are written in decimetres, each hull `Mesh` scaled back to metres by
/// `xformOp:scale` = [`hull_scale`]. PhysX cooks a convex mesh in its own (unscaled) units and
/// skips every point within its plane tolerance, 0.0007 × max(1, half the box perimeter) in
/// those units, of the hull built so far; the mesh scale is applied after cooking. In metres
/// that is 0.7 mm for any household-sized hull, and PhysX silently dropped barely-bulging
/// vertices (the cooked hull up to 1.8 mm inside the written one, measured with ovphysx). In
/// decimetres it is 0.07 mm, or 0.07 % of the hull's size above 10 cm of half perimeter, and
/// ovphysx's read-back gives every authored vertex back within 0.07 mm (tests/usd.rs holds
/// 0.1 mm). Millimetres (scale 0.001) cooked exactly too, but PhysX's contact with a convex
/// mesh depends on the mesh scale: at 0.001 and 0.01 it rocked a box at rest that it holds at
/// 1 and 0.1 (docs/usd.md, docs/agreement.md).
pub const HULL_POINTS_PER_METRE: f64 = 10.0;

/// `xformOp:scale` of every hull `Mesh`, `(0.1, 0.1, 0.1)`: 1 / [`HULL_POINTS_PER_METRE`],
/// derived so that the two cannot disagree.
pub fn hull_scale() -> String {
    let s = 1.0 / HULL_POINTS_PER_METRE;
    format!("({s}, {s}, {s})")
}

fn in_hull_units(ps: &[P3]) -> Vec<P3> {
    ps.iter().map(|p| p * HULL_POINTS_PER_METRE).collect()
}

fn tuple(v: &[f64]) -> String {
    let s: Vec<String> = v.iter().map(|x| f(*x)).collect();
    format!("({})", s.join(", "))
}

fn points(ps: &[P3]) -> String {
    let mut s = String::with_capacity(ps.len() * 36 + 2);
    s.push('[');
    for (i, p) in ps.iter().enumerate() {
        if i > 0 {
            s.push_str(", ");
        }
        write!(s, "({}, {}, {})", f(p.x), f(p.y), f(p.z)).unwrap();
    }
    s.push(']');
    s
}

fn counts(n: usize) -> String {
    format!("[{}]", vec!["3"; n].join(", "))
}

fn indices(t: &[[u32; 3]]) -> String {
    let mut s = String::with_capacity(t.len() * 18 + 2);
    s.push('[');
    for (i, t) in t.iter().enumerate() {
        if i > 0 {
            s.push_str(", ");
        }
        write!(s, "{}, {}, {}", t[0], t[1], t[2]).unwrap();
    }
    s.push(']');
    s
}

fn extent(ps: &[P3]) -> String {
    let mut lo = P3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let mut hi = -lo;
    for p in ps {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    if ps.is_empty() {
        lo = P3::origin();
        hi = P3::origin();
    }
    format!(
        "[{}, {}]",
        tuple(&[lo.x, lo.y, lo.z]),
        tuple(&[hi.x, hi.y, hi.z])
    )
}

/// Area-weighted vertex normals (a vertex no triangle uses gets +Z).
fn vertex_normals(ps: &[P3], tris: &[[u32; 3]]) -> Vec<P3> {
    let mut n = vec![V3::zeros(); ps.len()];
    for t in tris {
        let [a, b, c] = t.map(|k| ps[k as usize]);
        let w = (b - a).cross(&(c - a));
        for k in t {
            n[*k as usize] += w;
        }
    }
    n.into_iter()
        .map(|v| {
            let len = v.norm();
            P3::from(if len > 0.0 { v / len } else { V3::z() })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rebuilt(d: &Vector3<f64>, q: &UnitQuaternion<f64>) -> Matrix3<f64> {
        let r = q.to_rotation_matrix().into_inner();
        r * Matrix3::from_diagonal(d) * r.transpose()
    }

    #[test]
    fn principal_axes_rebuild_the_tensor() {
        // A box's tensor turned by a known rotation: the moments come back sorted, the tensor
        // rebuilds to 1e-12 relative, and a turned copy of the same input gives the same output.
        let base = Matrix3::from_diagonal(&Vector3::new(3e-4, 1e-4, 2e-4));
        let rot = UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1);
        let r = rot.to_rotation_matrix().into_inner();
        let i = r * base * r.transpose();
        let (d, q) = principal_axes(&i);
        assert!(
            (d.x - 1e-4).abs() < 1e-15 && (d.y - 2e-4).abs() < 1e-15 && (d.z - 3e-4).abs() < 1e-15
        );
        assert!(
            (rebuilt(&d, &q) - i).norm() < 1e-12 * i.norm(),
            "{i} vs {}",
            rebuilt(&d, &q)
        );
        assert!(q.w >= 0.0);
        assert_eq!(principal_axes(&i), principal_axes(&i.clone()));
        // A diagonal tensor keeps its axes.
        let (d, q) = principal_axes(&base);
        assert_eq!(d, Vector3::new(3e-4, 1e-4, 2e-4));
        assert_eq!(q, UnitQuaternion::identity());
        // Two equal moments (a cylinder about a tilted axis): still a rotation that rebuilds it.
        let cyl = Matrix3::from_diagonal(&Vector3::new(2e-4, 2e-4, 1e-4));
        let i = r * cyl * r.transpose();
        let (d, q) = principal_axes(&i);
        assert!((rebuilt(&d, &q) - i).norm() < 1e-12 * i.norm());
    }

    #[test]
    fn loaded_iterations_scale_physx_by_the_settles_sweeps() {
        // The default settle: 8 × 4 biased sweeps against 4 × 1, so 16 × 8.
        assert_eq!(loaded_iterations(&SettleOptions::default()), (128, 1));
        let o = |sub, pgs, lsub, lpgs| SettleOptions {
            solver_iterations: sub,
            pgs_iterations: pgs,
            loaded_solver_iterations: lsub,
            loaded_pgs_iterations: lpgs,
            ..Default::default()
        };
        // 6 × 2 against 4 × 1: 16 × 3.
        assert_eq!(loaded_iterations(&o(4, 1, 6, 2)), (48, 1));
        // No extra sweeps (or fewer, which the settle raises to its own): PhysX's own 16.
        assert_eq!(loaded_iterations(&o(4, 1, 4, 1)), (16, 1));
        assert_eq!(loaded_iterations(&o(4, 2, 2, 1)), (16, 1));
        // Each count raised to the world's on its own: 4 substeps × 4 sweeps against 4 × 1.
        assert_eq!(loaded_iterations(&o(4, 1, 2, 4)), (64, 1));
        // PhysX takes at most 255.
        assert_eq!(loaded_iterations(&o(1, 1, 64, 64)), (255, 1));
    }

    #[test]
    fn prim_names_are_usd_identifiers_and_unique() {
        let n = prim_names(["a-b", "a_b", "3d", "World", "ok"].into_iter());
        assert_eq!(n, vec!["a_b", "a_b_2", "_3d", "World_2", "ok"]);
    }
}
