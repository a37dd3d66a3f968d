//! Physical validation of a composed scene with Rapier (f64): the settle test.
//!
//! A composed scene places objects at poses chosen by a generator: millimetre gaps, round bottoms
//! that still have to rock into place. Those poses are not rest poses, so the check runs in two
//! phases on a Rapier world (floor at z = 0, to [`FLOOR_GAP`], gravity along −z, one dynamic or
//! fixed body per object, one convex collider per hull, the exported mass properties):
//!
//! 1. **Settle**: simulate from the composed pose until every dynamic body sleeps (capped). The
//!    drift from the composed pose (centre-of-mass displacement, rotation angle) must stay small
//!    relative to the object's size, and an object must still touch what it was resting in or on.
//!    A large rotation counts only if it moved the object's shape, not a pen's roll about its
//!    own axis (see [`SettleOptions::max_settle_rotation_deg`]).
//! 2. **Rest**: from the settled state, with sleeping disabled so that creep cannot hide behind
//!    the sleep heuristic, simulate some more: every object must stay put, and the contact
//!    penetration, measured with exact f64 convex queries (not Rapier's possibly recycled contact
//!    distances), must stay below a tolerance.
//!
//! The API is independent of file formats: callers build [`SimBody`]s from whatever they export.
//! Everything is deterministic: the same input gives a bitwise-identical [`SettleReport`].

use crate::mesh::{Mesh, P3};
use nalgebra::{Isometry3, Matrix3, Quaternion, Rotation3, Translation3, UnitQuaternion, Vector3};
use rapier3d_f64::math::{Pose, Real, Rotation, Vector};
use rapier3d_f64::parry::bounding_volume::{Aabb, BoundingVolume};
use rapier3d_f64::parry::query;
use rapier3d_f64::parry::shape::Shape;
use rapier3d_f64::prelude::{
    ColliderBuilder, ColliderHandle, MassProperties, NarrowPhase, PhysicsWorld, RigidBodyBuilder,
    RigidBodyHandle,
};
use serde::Serialize;

/// Name used for the floor in support lists and reasons.
pub const FLOOR: &str = "floor";

/// One object of the scene as the simulator sees it.
#[derive(Clone, Debug)]
pub struct SimBody {
    /// Unique name, used in reports.
    pub name: String,
    /// World pose of the body frame (the frame of `hulls` and `com`).
    pub pose: Isometry3<f64>,
    /// Convex hulls, vertices in the body frame, metres. Each becomes one convex collider (the
    /// convex hull of its vertices; triangles are not used).
    pub hulls: Vec<Mesh>,
    /// Mass in kg (ignored for fixed bodies).
    pub mass: f64,
    /// Centre of mass in the body frame.
    pub com: P3,
    /// Full symmetric inertia tensor about the centre of mass, body-frame axes (kg·m²).
    pub inertia: Matrix3<f64>,
    /// Coulomb friction coefficient of the object's surface.
    pub friction: f64,
    /// Fixed in space (a table, a wall) instead of dynamic.
    pub fixed: bool,
}

/// Simulation parameters and pass/fail thresholds. Distances in metres, angles in degrees.
#[derive(Clone, Debug, Serialize)]
pub struct SettleOptions {
    /// Fixed time step (s).
    pub dt: f64,
    /// Rapier solver iterations per step.
    pub solver_iterations: usize,
    /// Gravitational acceleration along −z (m/s²).
    pub gravity: f64,
    /// Cap on the settle phase (s): it ends earlier when every dynamic body sleeps.
    pub settle_max_time: f64,
    /// Length of the rest phase (s).
    pub rest_time: f64,
    /// Restitution of every collider (floor included).
    pub restitution: f64,
    /// Friction coefficient of the floor (combined with a body's by averaging, Rapier's default).
    pub floor_friction: f64,
    /// A body may sleep once its farthest point moves slower than this (m/s)...
    pub sleep_linear_threshold: f64,
    /// ...for this long (s).
    pub sleep_time: f64,
    /// Natural frequency (Hz) of the soft contact constraints between dynamic bodies. Rapier's
    /// default is 30 Hz for its 60 Hz step; we keep that ratio (half the step rate). At 30 Hz
    /// with a 240 Hz step a faceted ball resting on its pole vertex in a dynamic bowl kept
    /// circling for seconds (measured; 90 Hz and up: it settles).
    pub contact_frequency: f64,
    /// Natural frequency (Hz) of contacts with fixed bodies and the floor (Rapier: twice the
    /// dynamic one).
    pub static_contact_frequency: f64,
    /// Linear damping of every dynamic body (1/s).
    pub linear_damping: f64,
    /// Angular damping of every dynamic body (1/s), a crude stand-in for rolling resistance
    /// (which Rapier does not model). 0 by default: it did not stop the faceted-ball creep it
    /// was meant for (see the module tests) and it slows genuine toppling.
    pub angular_damping: f64,
    /// Speed (m/s) of the farthest point of every dynamic body due to a small deterministic
    /// rotation kick at the start of the settle phase, about a fixed oblique axis. A composed
    /// pose that is an unstable balance (a box on its edge, a pen on its tip) is otherwise kept
    /// forever by a symmetric simulation; the kick makes it fall as it would in the world.
    /// 0 disables it.
    pub perturbation_speed: f64,
    /// Distance (m) below which Rapier creates speculative contacts. Rapier's default is 2 cm
    /// (tuned for metre-sized bodies); at centimetre scale that pairs nearly every hull of an
    /// object with every hull of its container.
    pub prediction_distance: f64,
    /// Rapier's contact recycling: a pair whose relative pose moved less than
    /// `contact_recycle_distance` since its last narrow-phase update keeps its contact points.
    /// Its reported contact distances then go stale, which does not matter here: every
    /// measurement uses exact queries. On by default with a 0.5 mm distance: 3x faster on the
    /// 64-hull benchmark, and it stops the creep of a faceted ball on its pole vertex (with it
    /// off, that ball kept moving 0.4–4 mm per second, depending chaotically on solver settings).
    pub contact_recycling: bool,
    /// With recycling on: a pair's contacts are recomputed once its relative pose moved more
    /// than this (m). Rapier's default, 5 cm, is larger than our objects.
    pub contact_recycle_distance: f64,
    /// Settle fails when the centre of mass moves more than this fraction of the body's
    /// bounding-box diagonal.
    pub max_relative_drift: f64,
    /// Settle fails when the body turns more than this (degrees) and the turn moved its shape:
    /// some hull vertex, turned about the centre of mass, lies farther than
    /// `max_relative_drift` of the bounding-box diagonal from the unturned hulls (or the other
    /// way). A turn about an axis the body is nearly symmetric around (a pen rolling about its
    /// own axis, a ball) leaves the space it takes where it was and is only noted.
    pub max_settle_rotation_deg: f64,
    /// Rest fails when the centre of mass moves more than this (m) at any time of the rest phase.
    pub max_rest_motion: f64,
    /// Rest fails when the body turns more than this (degrees).
    pub max_rest_rotation_deg: f64,
    /// Rest fails when a contact penetrates deeper than this (m) at any step of the rest phase.
    pub max_rest_penetration: f64,
    /// The composed pose fails when two objects (or an object and the floor) interpenetrate
    /// deeper than this (m): the solver would push them apart, which is not a rest state.
    pub max_initial_penetration: f64,
    /// Two bodies closer than this (m) touch; at the composed pose this defines supports.
    pub support_distance: f64,
    /// After settling a body still touches a support when closer than `support_distance` plus
    /// this margin (m).
    pub support_release_margin: f64,
    /// A touching body is a support only when the contact normal pointing from it to the
    /// supported body has at least this upward (z) component (0.1 ≈ 6° above horizontal): side
    /// contacts between neighbours are not supports, a mug's rim under a leaning pen is.
    pub support_min_normal_z: f64,
}

impl Default for SettleOptions {
    fn default() -> Self {
        SettleOptions {
            dt: 1.0 / 240.0,
            solver_iterations: 4,
            gravity: 9.81,
            settle_max_time: 3.0,
            rest_time: 1.0,
            restitution: 0.0,
            floor_friction: 0.8,
            sleep_linear_threshold: 0.005,
            sleep_time: 0.5,
            contact_frequency: 120.0,
            static_contact_frequency: 240.0,
            linear_damping: 0.0,
            angular_damping: 0.0,
            perturbation_speed: 0.001,
            prediction_distance: 0.002,
            contact_recycling: true,
            contact_recycle_distance: 0.0005,
            max_relative_drift: 0.10,
            max_settle_rotation_deg: 30.0,
            max_rest_motion: 0.001,
            max_rest_rotation_deg: 1.0,
            max_rest_penetration: 0.001,
            max_initial_penetration: 0.001,
            support_distance: 0.002,
            support_release_margin: 0.001,
            support_min_normal_z: 0.1,
        }
    }
}

/// A pose as written in reports: translation (m) and unit quaternion (w, x, y, z).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PoseRecord {
    pub translation: [f64; 3],
    pub quaternion_wxyz: [f64; 4],
}

impl PoseRecord {
    pub fn from_isometry(iso: &Isometry3<f64>) -> Self {
        let q = iso.rotation.quaternion();
        let t = iso.translation.vector;
        PoseRecord {
            translation: [t.x, t.y, t.z],
            quaternion_wxyz: [q.w, q.i, q.j, q.k],
        }
    }

    pub fn isometry(&self) -> Isometry3<f64> {
        let [w, x, y, z] = self.quaternion_wxyz;
        Isometry3::from_parts(
            Translation3::from(Vector3::from(self.translation)),
            UnitQuaternion::new_normalize(Quaternion::new(w, x, y, z)),
        )
    }
}

/// The verdict on one body.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BodyReport {
    pub name: String,
    pub fixed: bool,
    /// Pose of the body frame after the settle phase.
    pub settled_pose: PoseRecord,
    /// Pose of the body frame after the rest phase.
    pub final_pose: PoseRecord,
    /// Diagonal of the body-frame bounding box of all hulls (m).
    pub bbox_diagonal: f64,
    /// Centre-of-mass displacement from the composed pose to the settled pose (m).
    pub settle_displacement: f64,
    /// Rotation angle from the composed pose to the settled pose (degrees).
    pub settle_rotation_deg: f64,
    /// When `settle_rotation_deg` exceeds the limit: how far that turn alone, about the centre
    /// of mass, moved the body's shape (m), the largest distance from a turned hull vertex to
    /// the unturned hulls or from an unturned vertex to the turned hulls. Small for a turn
    /// about an axis of near symmetry. `None` when the rotation is within the limit.
    pub settle_shape_shift: Option<f64>,
    /// `settle_displacement / bbox_diagonal`.
    pub relative_drift: f64,
    /// Largest centre-of-mass displacement from the settled pose during the rest phase (m).
    pub rest_displacement: f64,
    /// Largest rotation from the settled pose during the rest phase (degrees).
    pub rest_rotation_deg: f64,
    /// Deepest contact penetration involving this body during the rest phase (m, ≥ 0), exact.
    pub rest_max_penetration: f64,
    /// What it penetrated deepest during the rest phase (a body name or `floor`).
    pub rest_max_penetration_with: Option<String>,
    /// Deepest penetration at the composed pose (m, ≥ 0).
    pub initial_penetration: f64,
    pub initial_penetration_with: Option<String>,
    /// What the body rests in or on at the composed pose (`floor` and/or body names).
    pub supports_at_start: Vec<String>,
    /// Everything the body touches after settling (`floor` and/or body names).
    pub touching_after_settle: Vec<String>,
    /// It started on other bodies and touches none of them after settling.
    pub left_supports: bool,
    /// It started on other bodies (not the floor) and ended on the floor.
    pub ended_on_floor: bool,
    pub passed: bool,
    /// Why it failed (empty when it passed).
    pub reasons: Vec<String>,
    /// Observations that do not fail the body.
    pub notes: Vec<String>,
}

/// The outcome of [`settle`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SettleReport {
    pub passed: bool,
    pub bodies: Vec<BodyReport>,
    /// Simulated time until every dynamic body slept; `None` if they did not within the cap.
    pub time_to_sleep: Option<f64>,
    pub settle_steps: usize,
    pub rest_steps: usize,
    /// `settle_steps + rest_steps`.
    pub steps: usize,
    pub dt: f64,
    /// Scene-level observations that do not fail the scene.
    pub warnings: Vec<String>,
}

/// Poses of every body over time, from [`simulate`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Trajectory {
    pub names: Vec<String>,
    pub dt: f64,
    pub steps: usize,
    /// Simulated time of each frame (s).
    pub times: Vec<f64>,
    /// `frames[k][i]`: pose of body `i` at `times[k]`.
    pub frames: Vec<Vec<PoseRecord>>,
}

/// Why a scene cannot be simulated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PhysicsError {
    #[error("body '{body}': {message}")]
    InvalidBody { body: String, message: String },
    #[error("invalid settle options: {0}")]
    InvalidOptions(String),
}

fn body_error(body: &SimBody, message: impl Into<String>) -> PhysicsError {
    PhysicsError::InvalidBody {
        body: body.name.clone(),
        message: message.into(),
    }
}

/// Run the settle test (settle phase, then rest phase) on a scene.
pub fn settle(bodies: &[SimBody], opts: &SettleOptions) -> Result<SettleReport, PhysicsError> {
    let mut sim = Sim::new(bodies, opts)?;
    let n = bodies.len();
    let dynamic: Vec<usize> = (0..n).filter(|&i| !bodies[i].fixed).collect();

    // Composed pose: supports and initial penetration.
    let start = sim.contact_graph(opts.support_distance);
    let composed: Vec<Isometry3<f64>> = (0..n).map(|i| sim.pose(i)).collect();
    sim.kick();

    // Phase 1: settle until everything sleeps.
    let max_settle_steps = steps_for(opts.settle_max_time, opts.dt);
    let mut settle_steps = 0;
    let mut time_to_sleep = if dynamic.is_empty() { Some(0.0) } else { None };
    while time_to_sleep.is_none() && settle_steps < max_settle_steps {
        sim.world.step();
        settle_steps += 1;
        if dynamic
            .iter()
            .all(|&i| sim.world.bodies[sim.handles[i]].is_sleeping())
        {
            time_to_sleep = Some(settle_steps as f64 * opts.dt);
        }
    }
    let mut warnings = Vec::new();
    if time_to_sleep.is_none() {
        let awake: Vec<&str> = dynamic
            .iter()
            .filter(|&&i| !sim.world.bodies[sim.handles[i]].is_sleeping())
            .map(|&i| bodies[i].name.as_str())
            .collect();
        warnings.push(format!(
            "not everything slept within {} s (still moving: {})",
            opts.settle_max_time,
            awake.join(", ")
        ));
    }
    let settled: Vec<Isometry3<f64>> = (0..n).map(|i| sim.pose(i)).collect();
    let after = sim.contact_graph(opts.support_distance + opts.support_release_margin);

    // Phase 2: rest, everything awake and kept awake.
    for &i in &dynamic {
        let h = sim.handles[i];
        let act = sim.world.bodies[h].activation_mut();
        act.normalized_linear_threshold = -1.0;
        act.angular_threshold = -1.0;
        sim.world.wake_up(h, true);
    }
    let rest_steps = steps_for(opts.rest_time, opts.dt);
    let mut rest_disp = vec![0.0f64; n];
    let mut rest_rot = vec![0.0f64; n];
    let mut rest_pen = vec![(0.0f64, None::<usize>); n];
    for _ in 0..rest_steps {
        sim.world.step();
        for &i in &dynamic {
            let p = sim.pose(i);
            let (d, r) = drift(&settled[i], &p, &bodies[i].com);
            rest_disp[i] = rest_disp[i].max(d);
            rest_rot[i] = rest_rot[i].max(r);
        }
        for (i, pen) in sim.penetrations().into_iter().enumerate() {
            if pen.0 > rest_pen[i].0 {
                rest_pen[i] = pen;
            }
        }
    }
    let finals: Vec<Isometry3<f64>> = (0..n).map(|i| sim.pose(i)).collect();

    // Verdicts.
    let name_of = |k: Option<usize>| k.map(|k| sim.name(k).to_string());
    let mut reports = Vec::with_capacity(n);
    for i in 0..n {
        let b = &bodies[i];
        let diag = sim.bbox_diagonal[i];
        let (disp, rot) = drift(&composed[i], &settled[i], &b.com);
        let rel = if diag > 0.0 { disp / diag } else { 0.0 };
        let shape_shift = (!b.fixed && rot > opts.max_settle_rotation_deg)
            .then(|| sim.shape_shift(i, &composed[i], &settled[i]));
        let supports: Vec<usize> = start.supports[i].clone();
        let touching: Vec<usize> = after.touching[i].clone();
        let body_supports: Vec<usize> = supports.iter().copied().filter(|&k| k != n).collect();
        let left = !b.fixed
            && !body_supports.is_empty()
            && !body_supports.iter().any(|k| touching.contains(k));
        // Touching the floor is only "ending on the floor" when the body no longer touches what it
        // started on: an item resting in a thin-bottomed bowl is within millimetres of the floor.
        let ended_on_floor = !b.fixed
            && !body_supports.is_empty()
            && !supports.contains(&n)
            && touching.contains(&n)
            && left;
        let (init_pen, init_with) = start.penetration[i];
        let (pen, pen_with) = rest_pen[i];

        let mut reasons = Vec::new();
        let mut notes = Vec::new();
        let mm = |x: f64| x * 1e3;
        if init_pen > opts.max_initial_penetration {
            reasons.push(format!(
                "starts interpenetrating {} by {:.2} mm (> {:.2} mm)",
                quoted(sim.name(init_with.unwrap_or(n))),
                mm(init_pen),
                mm(opts.max_initial_penetration)
            ));
        }
        if !b.fixed {
            if rel > opts.max_relative_drift {
                reasons.push(format!(
                    "drifted {:.1} mm while settling ({:.1}% of its {:.1} mm bounding-box diagonal > {:.1}%)",
                    mm(disp),
                    rel * 100.0,
                    mm(diag),
                    opts.max_relative_drift * 100.0
                ));
            }
            if let Some(shift) = shape_shift {
                let what = format!(
                    "turned {:.1}° while settling (> {:.1}°)",
                    rot, opts.max_settle_rotation_deg
                );
                let by = format!(
                    "the turn moved its shape by {:.1} mm ({:.1}% of its diagonal",
                    mm(shift),
                    100.0 * shift / diag
                );
                if shift > opts.max_relative_drift * diag {
                    reasons.push(format!(
                        "{what}: {by} > {:.1}%)",
                        opts.max_relative_drift * 100.0
                    ));
                } else {
                    notes.push(format!(
                        "{what} about an axis it is nearly symmetric around: {by}), not counted"
                    ));
                }
            }
            if left {
                reasons.push(format!(
                    "left what it rested in or on ({}): no longer within {:.1} mm after settling",
                    names(&sim, &body_supports),
                    mm(opts.support_distance + opts.support_release_margin)
                ));
            }
            if ended_on_floor {
                reasons.push(format!(
                    "ended on the floor although it started on {}",
                    names(&sim, &body_supports)
                ));
            }
            if rest_disp[i] > opts.max_rest_motion {
                reasons.push(format!(
                    "moved {:.2} mm during the {} s rest check (> {:.2} mm)",
                    mm(rest_disp[i]),
                    opts.rest_time,
                    mm(opts.max_rest_motion)
                ));
            }
            if rest_rot[i] > opts.max_rest_rotation_deg {
                reasons.push(format!(
                    "turned {:.2}° during the {} s rest check (> {:.2}°)",
                    rest_rot[i], opts.rest_time, opts.max_rest_rotation_deg
                ));
            }
            if supports.is_empty() {
                notes.push(format!(
                    "starts unsupported: nothing below it within {:.1} mm",
                    mm(opts.support_distance)
                ));
            }
        }
        if pen > opts.max_rest_penetration {
            reasons.push(format!(
                "penetrates {} by {:.2} mm during the rest check (> {:.2} mm)",
                quoted(sim.name(pen_with.unwrap_or(n))),
                mm(pen),
                mm(opts.max_rest_penetration)
            ));
        }
        reports.push(BodyReport {
            name: b.name.clone(),
            fixed: b.fixed,
            settled_pose: PoseRecord::from_isometry(&settled[i]),
            final_pose: PoseRecord::from_isometry(&finals[i]),
            bbox_diagonal: diag,
            settle_displacement: disp,
            settle_rotation_deg: rot,
            settle_shape_shift: shape_shift,
            relative_drift: rel,
            rest_displacement: rest_disp[i],
            rest_rotation_deg: rest_rot[i],
            rest_max_penetration: pen,
            rest_max_penetration_with: name_of(pen_with),
            initial_penetration: init_pen,
            initial_penetration_with: name_of(init_with),
            supports_at_start: supports.iter().map(|&k| sim.name(k).to_string()).collect(),
            touching_after_settle: touching.iter().map(|&k| sim.name(k).to_string()).collect(),
            left_supports: left,
            ended_on_floor,
            passed: reasons.is_empty(),
            reasons,
            notes,
        });
    }
    Ok(SettleReport {
        passed: reports.iter().all(|r| r.passed),
        bodies: reports,
        time_to_sleep,
        settle_steps,
        rest_steps,
        steps: settle_steps + rest_steps,
        dt: opts.dt,
        warnings,
    })
}

/// Simulate the scene from its composed pose for `duration` seconds (sleeping allowed, no
/// checks) and record the poses every `record_every` steps (0: only the first and last frame).
pub fn simulate(
    bodies: &[SimBody],
    opts: &SettleOptions,
    duration: f64,
    record_every: usize,
) -> Result<Trajectory, PhysicsError> {
    let mut sim = Sim::new(bodies, opts)?;
    sim.kick();
    let steps = steps_for(duration, opts.dt);
    let frame = |sim: &Sim| -> Vec<PoseRecord> {
        (0..bodies.len())
            .map(|i| PoseRecord::from_isometry(&sim.pose(i)))
            .collect()
    };
    let mut times = vec![0.0];
    let mut frames = vec![frame(&sim)];
    for s in 1..=steps {
        sim.world.step();
        if (record_every > 0 && s % record_every == 0) || s == steps {
            times.push(s as f64 * opts.dt);
            frames.push(frame(&sim));
        }
    }
    Ok(Trajectory {
        names: bodies.iter().map(|b| b.name.clone()).collect(),
        dt: opts.dt,
        steps,
        times,
        frames,
    })
}

/// The mass properties Rapier gives a body built from `body` (for checks and debugging): the
/// reconstructed inertia tensor about the COM (body-frame axes), the COM and the mass.
pub fn rapier_mass_properties(body: &SimBody) -> Result<(f64, P3, Matrix3<f64>), PhysicsError> {
    let opts = SettleOptions::default();
    let mut sim = Sim::new(std::slice::from_ref(body), &opts)?;
    let w = &mut sim.world;
    // Mass properties are folded in at the first step; do it now.
    w.bodies[sim.handles[0]].recompute_mass_properties_from_colliders(&w.colliders);
    let mp = w.bodies[sim.handles[0]].mass_properties().local_mprops;
    let m = mp.reconstruct_inertia_matrix();
    let c = mp.local_com;
    Ok((
        mp.mass(),
        P3::new(c.x, c.y, c.z),
        Matrix3::from_fn(|r, k| m.col(k)[r]),
    ))
}

/// How far below z = 0 the floor's top face lies (m). Prepared scenes rest on z = 0, and a
/// hull's lowest vertex ends up there only to f64 rounding: 1.4e-17 m *above* it, say. At such
/// a separation, below GJK's tolerance, parry's contact query gave a hull touching the floor
/// at a sharp vertex (the apex of a basket floor's pie slice) a normal pointing up out
/// of the floor, in about half the cases; Rapier then slid the fixture basket 2.4 mm and rolled
/// its fruits out. Exactly at 0, below it, or 1e-12 m above it, the normals are right. 10 nm is
/// far above the rounding and far below anything the checks measure.
pub const FLOOR_GAP: f64 = 1e-8;

/// Number of whole steps of length `dt` covering `time` (rounded to nearest).
fn steps_for(time: f64, dt: f64) -> usize {
    (time / dt).round().max(0.0) as usize
}

/// Centre-of-mass displacement (m) and rotation angle (degrees) from pose `a` to pose `b`.
fn drift(a: &Isometry3<f64>, b: &Isometry3<f64>, com: &P3) -> (f64, f64) {
    let d = (b * com - a * com).norm();
    let r = b.rotation.angle_to(&a.rotation).to_degrees();
    (d, r)
}

fn quoted(name: &str) -> String {
    if name == FLOOR {
        "the floor".into()
    } else {
        format!("'{name}'")
    }
}

fn names(sim: &Sim, ks: &[usize]) -> String {
    ks.iter()
        .map(|&k| quoted(sim.name(k)))
        .collect::<Vec<_>>()
        .join(", ")
}

fn to_pose(iso: &Isometry3<f64>) -> Pose {
    let q = iso.rotation.quaternion();
    let t = iso.translation.vector;
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

fn from_pose(p: &Pose) -> Isometry3<f64> {
    let q = p.rotation;
    let t = p.translation;
    Isometry3::from_parts(
        Translation3::new(t.x, t.y, t.z),
        UnitQuaternion::new_normalize(Quaternion::new(q.w, q.x, q.y, q.z)),
    )
}

/// Principal inertia and its frame for Rapier, from a full symmetric tensor. Rejects tensors
/// that are not symmetric or not positive definite.
fn principal_inertia(body: &SimBody) -> Result<(Vector, Rotation), PhysicsError> {
    let i = body.inertia;
    if i.iter().any(|x| !x.is_finite()) {
        return Err(body_error(
            body,
            "inertia tensor has a NaN or infinite entry",
        ));
    }
    let scale = i.abs().max();
    if scale <= 0.0 {
        return Err(body_error(body, "inertia tensor is zero"));
    }
    let asym = (i - i.transpose()).abs().max();
    if asym > 1e-9 * scale {
        return Err(body_error(
            body,
            format!("inertia tensor is not symmetric (|I − Iᵀ| = {asym:.3e})"),
        ));
    }
    let sym = (i + i.transpose()) * 0.5;
    let eig = sym.symmetric_eigen();
    let mut vecs = eig.eigenvectors;
    let vals = eig.eigenvalues;
    if vals.min() <= 1e-12 * scale {
        return Err(body_error(
            body,
            format!(
                "inertia tensor is not positive definite (principal moments {:.3e}, {:.3e}, {:.3e})",
                vals[0], vals[1], vals[2]
            ),
        ));
    }
    if vecs.determinant() < 0.0 {
        vecs.column_mut(2).neg_mut();
    }
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(vecs));
    let q = q.quaternion();
    Ok((
        Vector::new(vals[0], vals[1], vals[2]),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w).normalize(),
    ))
}

/// Contacts of the scene at one instant. Index `n` (the number of bodies) stands for the floor.
struct ContactGraph {
    /// `supports[i]`: bodies (or the floor) within the distance whose contact normal towards `i`
    /// points up enough; sorted.
    supports: Vec<Vec<usize>>,
    /// `touching[i]`: everything within the distance; sorted.
    touching: Vec<Vec<usize>>,
    /// `penetration[i]`: deepest penetration (≥ 0) and with what.
    penetration: Vec<(f64, Option<usize>)>,
}

/// A Rapier world built from the scene, plus what the exact queries need.
struct Sim<'a> {
    bodies: &'a [SimBody],
    opts: &'a SettleOptions,
    world: PhysicsWorld,
    handles: Vec<RigidBodyHandle>,
    colliders: Vec<Vec<ColliderHandle>>,
    bbox_diagonal: Vec<f64>,
    /// Distance from the centre of mass to the farthest hull vertex.
    reach: Vec<f64>,
}

impl<'a> Sim<'a> {
    fn new(bodies: &'a [SimBody], opts: &'a SettleOptions) -> Result<Self, PhysicsError> {
        validate_options(opts)?;
        let mut world = PhysicsWorld::new();
        world.narrow_phase = NarrowPhase::with_query_dispatcher(fresh::Fresh);
        world.gravity = Vector::new(0.0, 0.0, -opts.gravity);
        let ip = &mut world.integration_parameters;
        ip.dt = opts.dt;
        ip.num_solver_iterations = opts.solver_iterations;
        ip.contact_recycling = opts.contact_recycling;
        ip.normalized_prediction_distance = opts.prediction_distance / ip.length_unit;
        ip.normalized_contact_recycle_distance = opts.contact_recycle_distance / ip.length_unit;
        ip.contact_softness.natural_frequency = opts.contact_frequency;
        ip.static_contact_softness.natural_frequency = opts.static_contact_frequency;

        let mut names = std::collections::BTreeSet::new();
        let mut scene_extent: f64 = 1.0;
        let mut handles = Vec::with_capacity(bodies.len());
        let mut colliders = Vec::with_capacity(bodies.len());
        let mut bbox_diagonal = Vec::with_capacity(bodies.len());
        let mut reach = Vec::with_capacity(bodies.len());
        for b in bodies {
            if b.name == FLOOR || !names.insert(b.name.as_str()) {
                return Err(body_error(
                    b,
                    "names must be unique and must not be 'floor'",
                ));
            }
            let (rb, diag) = body_builder(b, opts)?;
            let t = b.pose.translation.vector;
            scene_extent = scene_extent.max(t.abs().max() + diag);
            let h = world.insert_body(rb);
            let mut hs = Vec::with_capacity(b.hulls.len());
            for (k, hull) in b.hulls.iter().enumerate() {
                let (points, _) = hull.to_parry();
                let co = ColliderBuilder::convex_hull(&points)
                    .ok_or_else(|| {
                        body_error(
                            b,
                            format!(
                                "hull {k} ({} vertices) has no 3D convex hull (too few or coplanar points)",
                                points.len()
                            ),
                        )
                    })?
                    .density(0.0);
                let size = hull.aabb().map(|a| a.diagonal()).unwrap_or(0.0);
                let volume = co.shape.mass_properties(1.0).mass();
                if volume.is_nan() || volume <= 1e-9 * size * size * size {
                    return Err(body_error(
                        b,
                        format!(
                            "hull {k} is flat (volume {volume:.3e} m³ for a {:.3e} m extent)",
                            size
                        ),
                    ));
                }
                let co = co.friction(b.friction).restitution(opts.restitution);
                hs.push(world.insert_collider(co, Some(h)));
            }
            handles.push(h);
            colliders.push(hs);
            bbox_diagonal.push(diag);
            reach.push(
                b.hulls
                    .iter()
                    .flat_map(|h| h.vertices.iter())
                    .map(|v| (v - b.com).norm())
                    .fold(0.0, f64::max),
            );
        }
        // The floor: a large thin fixed box whose top face is `FLOOR_GAP` below z = 0 (its
        // contacts kept sound by `fresh::Fresh` like every pair's). Not a half-space: parry's
        // half-space manifold takes the hull face whose normal is closest to straight down,
        // whether or not it holds the lowest vertex, and a YCB fork (10 thin hulls, 20 g)
        // jittered up to 2.4 mm into it.
        let half = 10.0 * scene_extent;
        let floor = world.insert_body(RigidBodyBuilder::fixed().translation(Vector::new(
            0.0,
            0.0,
            -0.5 * scene_extent - FLOOR_GAP,
        )));
        world.insert_collider(
            ColliderBuilder::cuboid(half, half, 0.5 * scene_extent)
                .friction(opts.floor_friction)
                .restitution(opts.restitution),
            Some(floor),
        );
        Ok(Sim {
            bodies,
            opts,
            world,
            handles,
            colliders,
            bbox_diagonal,
            reach,
        })
    }

    /// The perturbation of [`SettleOptions::perturbation_speed`]: every dynamic body turns about
    /// the same oblique world axis so that its farthest point moves at that speed.
    fn kick(&mut self) {
        let axis = Vector::new(1.0, 2.0, 3.0).normalize();
        for i in 0..self.bodies.len() {
            if self.bodies[i].fixed || self.reach[i] <= 0.0 {
                continue;
            }
            let w = axis * (self.opts.perturbation_speed / self.reach[i]);
            self.world.bodies[self.handles[i]].set_angvel(w, true);
        }
    }

    fn name(&self, k: usize) -> &str {
        if k == self.bodies.len() {
            FLOOR
        } else {
            &self.bodies[k].name
        }
    }

    fn pose(&self, i: usize) -> Isometry3<f64> {
        from_pose(self.world.bodies[self.handles[i]].position())
    }

    /// World poses, shapes and AABBs (grown by `margin`) of every hull of every body.
    fn hull_states(&self, margin: f64) -> Vec<Vec<(Pose, &dyn Shape, Aabb)>> {
        (0..self.bodies.len())
            .map(|i| {
                let pose = *self.world.bodies[self.handles[i]].position();
                self.colliders[i]
                    .iter()
                    .map(|&c| {
                        let shape = self.world.colliders[c].shape();
                        let aabb = shape.compute_aabb(&pose).loosened(margin);
                        (pose, shape, aabb)
                    })
                    .collect()
            })
            .collect()
    }

    /// How far the turn from pose `a` to pose `b` moves body `i`'s shape, the translation
    /// left out (see [`BodyReport::settle_shape_shift`]). Hull vertices sample the shape: the
    /// distance to a convex hull is convex, so over each turned hull it peaks at a vertex.
    fn shape_shift(&self, i: usize, a: &Isometry3<f64>, b: &Isometry3<f64>) -> f64 {
        let body = &self.bodies[i];
        let shapes: Vec<&dyn Shape> = self.colliders[i]
            .iter()
            .map(|&c| self.world.colliders[c].shape())
            .collect();
        // The turn in the body frame: body point p at pose b sits where com + turn·(p − com)
        // sits at pose a, once the centres of mass are matched.
        let turn = a.rotation.inverse() * b.rotation;
        let gap = |turn: &UnitQuaternion<f64>| -> f64 {
            body.hulls
                .iter()
                .flat_map(|h| h.vertices.iter())
                .map(|p| {
                    let q = body.com + turn * (p - body.com);
                    shapes
                        .iter()
                        .map(|s| s.distance_to_local_point(Vector::new(q.x, q.y, q.z), true))
                        .fold(f64::INFINITY, f64::min)
                })
                .fold(0.0, f64::max)
        };
        gap(&turn).max(gap(&turn.inverse()))
    }

    /// Signed distance of a body's lowest hull vertex to the floor plane.
    fn floor_distance(&self, hulls: &[(Pose, &dyn Shape, Aabb)]) -> f64 {
        hulls
            .iter()
            .map(|(pose, shape, _)| {
                shape
                    .as_convex_polyhedron()
                    .map(|p| {
                        p.points()
                            .iter()
                            .map(|v| pose.transform_point(*v).z)
                            .fold(Real::INFINITY, Real::min)
                    })
                    .unwrap_or(Real::INFINITY)
            })
            .fold(Real::INFINITY, Real::min)
    }

    /// Exact contacts (f64 GJK/EPA between convex hulls, vertex heights for the floor) of every
    /// pair closer than `distance`.
    fn contact_graph(&self, distance: f64) -> ContactGraph {
        let n = self.bodies.len();
        let states = self.hull_states(distance);
        let mut supports = vec![Vec::new(); n];
        let mut touching = vec![Vec::new(); n];
        let mut penetration = vec![(0.0, None); n];
        let min_nz = self.opts.support_min_normal_z;
        let note_pen = |pen: &mut Vec<(f64, Option<usize>)>, i: usize, k: usize, d: f64| {
            if -d > pen[i].0 {
                pen[i] = (-d, Some(k));
            }
        };
        for i in 0..n {
            let fd = self.floor_distance(&states[i]);
            if fd <= distance {
                touching[i].push(n);
                supports[i].push(n);
                note_pen(&mut penetration, i, n, fd);
            }
        }
        for i in 0..n {
            for j in i + 1..n {
                let mut min_dist = Real::INFINITY;
                let (mut j_supports_i, mut i_supports_j) = (false, false);
                for (pi, si, ai) in &states[i] {
                    for (pj, sj, aj) in &states[j] {
                        if !ai.intersects(aj) {
                            continue;
                        }
                        // Shape 1 = j, shape 2 = i: normal1 points from j towards i.
                        if let Ok(Some(c)) = query::contact(pj, *sj, pi, *si, distance) {
                            min_dist = min_dist.min(c.dist);
                            j_supports_i |= c.normal1.z >= min_nz;
                            i_supports_j |= c.normal1.z <= -min_nz;
                        }
                    }
                }
                if min_dist <= distance {
                    touching[i].push(j);
                    touching[j].push(i);
                    note_pen(&mut penetration, i, j, min_dist);
                    note_pen(&mut penetration, j, i, min_dist);
                }
                if j_supports_i {
                    supports[i].push(j);
                }
                if i_supports_j {
                    supports[j].push(i);
                }
            }
        }
        for v in supports.iter_mut().chain(touching.iter_mut()) {
            v.sort_unstable();
        }
        ContactGraph {
            supports,
            touching,
            penetration,
        }
    }

    /// Deepest exact penetration of every body now (pairs of fixed bodies excluded).
    fn penetrations(&self) -> Vec<(f64, Option<usize>)> {
        let n = self.bodies.len();
        let states = self.hull_states(0.0);
        let mut pen = vec![(0.0, None); n];
        let body_aabb: Vec<Option<Aabb>> = states
            .iter()
            .map(|hs| hs.iter().map(|h| h.2).reduce(|a, b| a.merged(&b)))
            .collect();
        for i in 0..n {
            if self.bodies[i].fixed {
                continue;
            }
            let d = self.floor_distance(&states[i]);
            if -d > pen[i].0 {
                pen[i] = (-d, Some(n));
            }
        }
        for i in 0..n {
            for j in i + 1..n {
                if self.bodies[i].fixed && self.bodies[j].fixed {
                    continue;
                }
                match (&body_aabb[i], &body_aabb[j]) {
                    (Some(a), Some(b)) if a.intersects(b) => {}
                    _ => continue,
                }
                let mut deepest: Real = 0.0;
                for (pi, si, ai) in &states[i] {
                    for (pj, sj, aj) in &states[j] {
                        if !ai.intersects(aj) {
                            continue;
                        }
                        if let Ok(Some(c)) = query::contact(pj, *sj, pi, *si, 0.0) {
                            deepest = deepest.max(-c.dist);
                        }
                    }
                }
                if deepest > pen[i].0 {
                    pen[i] = (deepest, Some(j));
                }
                if deepest > pen[j].0 {
                    pen[j] = (deepest, Some(i));
                }
            }
        }
        pen
    }
}

fn validate_options(o: &SettleOptions) -> Result<(), PhysicsError> {
    let bad = |what: &str| Err(PhysicsError::InvalidOptions(what.to_string()));
    if !(o.dt.is_finite() && o.dt > 0.0 && o.dt <= 0.1) {
        return bad("dt must be in (0, 0.1] s");
    }
    if o.solver_iterations == 0 {
        return bad("solver_iterations must be at least 1");
    }
    let nonneg = [
        ("gravity", o.gravity),
        ("settle_max_time", o.settle_max_time),
        ("rest_time", o.rest_time),
        ("restitution", o.restitution),
        ("floor_friction", o.floor_friction),
        ("sleep_linear_threshold", o.sleep_linear_threshold),
        ("sleep_time", o.sleep_time),
        ("contact_frequency", o.contact_frequency),
        ("static_contact_frequency", o.static_contact_frequency),
        ("linear_damping", o.linear_damping),
        ("prediction_distance", o.prediction_distance),
        ("contact_recycle_distance", o.contact_recycle_distance),
        ("angular_damping", o.angular_damping),
        ("perturbation_speed", o.perturbation_speed),
        ("max_relative_drift", o.max_relative_drift),
        ("max_settle_rotation_deg", o.max_settle_rotation_deg),
        ("max_rest_motion", o.max_rest_motion),
        ("max_rest_rotation_deg", o.max_rest_rotation_deg),
        ("max_rest_penetration", o.max_rest_penetration),
        ("max_initial_penetration", o.max_initial_penetration),
        ("support_distance", o.support_distance),
        ("support_release_margin", o.support_release_margin),
    ];
    for (name, v) in nonneg {
        if !(v.is_finite() && v >= 0.0) {
            return Err(PhysicsError::InvalidOptions(format!(
                "{name} must be a finite number ≥ 0, got {v}"
            )));
        }
    }
    if !o.support_min_normal_z.is_finite() || o.support_min_normal_z.abs() > 1.0 {
        return bad("support_min_normal_z must be in [-1, 1]");
    }
    Ok(())
}

/// The Rapier body of a [`SimBody`] (validated) and its bounding-box diagonal.
fn body_builder(
    b: &SimBody,
    opts: &SettleOptions,
) -> Result<(rapier3d_f64::prelude::RigidBody, f64), PhysicsError> {
    if b.hulls.is_empty() {
        return Err(body_error(b, "has no collision hulls"));
    }
    let all = b.hulls.iter().flat_map(|h| h.vertices.iter());
    if b.hulls.iter().any(|h| {
        h.vertices
            .iter()
            .any(|p| !p.coords.iter().all(|x| x.is_finite()))
    }) {
        return Err(body_error(b, "a hull vertex is NaN or infinite"));
    }
    let diag = crate::mesh::Aabb::of_points(all)
        .map(|a| a.diagonal())
        .unwrap_or(0.0);
    let p = b.pose.translation.vector;
    let q = b.pose.rotation.quaternion();
    if !(p.iter().all(|x| x.is_finite()) && q.coords.iter().all(|x| x.is_finite())) {
        return Err(body_error(b, "pose is NaN or infinite"));
    }
    if !(b.friction.is_finite() && b.friction >= 0.0) {
        return Err(body_error(
            b,
            format!("friction must be ≥ 0, got {}", b.friction),
        ));
    }
    let pose = to_pose(&b.pose);
    if b.fixed {
        return Ok((RigidBodyBuilder::fixed().pose(pose).build(), diag));
    }
    if !(b.mass.is_finite() && b.mass > 0.0) {
        return Err(body_error(b, format!("mass must be > 0, got {}", b.mass)));
    }
    if !b.com.coords.iter().all(|x| x.is_finite()) {
        return Err(body_error(b, "centre of mass is NaN or infinite"));
    }
    let (principal, frame) = principal_inertia(b)?;
    let mp = MassProperties::with_principal_inertia_frame(
        Vector::new(b.com.x, b.com.y, b.com.z),
        b.mass,
        principal,
        frame,
    );
    let mut rb = RigidBodyBuilder::dynamic()
        .pose(pose)
        .additional_mass_properties(mp)
        .linear_damping(opts.linear_damping)
        .angular_damping(opts.angular_damping)
        .build();
    let act = rb.activation_mut();
    act.normalized_linear_threshold = opts.sleep_linear_threshold;
    act.time_until_sleep = opts.sleep_time;
    Ok((rb, diag))
}

mod fresh;
#[cfg(test)]
mod tests;
