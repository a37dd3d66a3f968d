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
//!    distances), must stay below a tolerance. A body that keeps creeping slowly (within
//!    [`SettleOptions::creep_max_motion`] / `creep_max_rotation_deg`) passes when its contacts
//!    hold it in static equilibrium inside their friction cones, without any solver (the
//!    `creep` module, [`equilibrium`]): Rapier keeps some leaning items moving where MuJoCo
//!    rests them.
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

mod creep;
pub mod equilibrium;
mod fresh;
pub mod load_ratio;
pub mod probe;
mod rolling;
mod settle;
mod world;

pub use settle::{settle, simulate};
#[cfg(test)]
use world::Sim;
pub use world::{rapier_mass_properties, shape_shift};

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

impl SimBody {
    /// A dynamic solid box of full extents `e` (m) and uniform density, centred on its body
    /// frame, at `pose`, with friction `friction` (the tests' blocks, plates and walls).
    pub fn cuboid(
        name: &str,
        e: crate::mesh::V3,
        mass: f64,
        pose: Isometry3<f64>,
        friction: f64,
    ) -> Self {
        SimBody {
            name: name.into(),
            pose,
            hulls: vec![crate::shapes::cuboid(e)],
            mass,
            com: P3::origin(),
            inertia: box_inertia(mass, e),
            friction,
            fixed: false,
        }
    }
}

/// The inertia tensor about its centre of a solid cylinder of radius `r`, length `l` (m) and
/// `mass` (kg), its axis along the frame's z.
pub fn cylinder_inertia(mass: f64, r: f64, l: f64) -> Matrix3<f64> {
    let across = mass * (3.0 * r * r + l * l) / 12.0;
    Matrix3::from_diagonal(&Vector3::new(across, across, mass * r * r / 2.0))
}

/// The inertia tensor about its centre of a solid box of full extents `e` (m) and `mass` (kg),
/// in the box's frame.
pub fn box_inertia(mass: f64, e: crate::mesh::V3) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(
        mass / 12.0 * (e.y * e.y + e.z * e.z),
        mass / 12.0 * (e.x * e.x + e.z * e.z),
        mass / 12.0 * (e.x * e.x + e.y * e.y),
    ))
}

/// Simulation parameters and pass/fail thresholds. Distances in metres, angles in degrees.
#[derive(Clone, Debug, Serialize)]
pub struct SettleOptions {
    /// Fixed time step (s).
    pub dt: f64,
    /// Rapier solver iterations per step (Rapier's default 4). In Rapier 0.36 each is a substep
    /// (velocity solve, position integration, stabilization), so the soft contacts' substep `h`
    /// is `dt / solver_iterations`. 8 substeps × 4 PGS sweeps ([`Self::pgs_iterations`]) hold
    /// a light item loaded by a heavy one (a dice under a shoe) as MuJoCo and PhysX do, but
    /// everywhere they flipped as many other verdicts the other way (a lemon rocking past the
    /// settle cap, drifts within 0.1 mm of the 10 % rule; docs/agreement.md, "Fourth pass"), so
    /// only the islands of such loads get them ([`Self::load_ratio`]).
    pub solver_iterations: usize,
    /// Projected Gauss-Seidel sweeps over the contacts within each substep (Rapier's
    /// `num_internal_pgs_iterations`, default 1). More sweeps converge the impulses of coupled
    /// contacts at the same positions without changing the substep, i.e. the contacts'
    /// softness.
    pub pgs_iterations: usize,
    /// Unbiased (stabilization) sweeps after each substep's position update (Rapier's
    /// `num_internal_stabilization_iterations`, default 1); friction acts here.
    pub stabilization_iterations: usize,
    /// A dynamic body that supports, at the world's start, a dynamic body at least this many
    /// times heavier is *heavily loaded*: its contact island runs
    /// [`Self::loaded_solver_iterations`] substeps × [`Self::loaded_pgs_iterations`] sweeps
    /// (see [`load_ratio`]). 10: PGS convergence degrades with the mass ratio across a contact,
    /// and at an order of magnitude 4 × 1 no longer holds a light item under a heavy one.
    /// 0 (or anything ≤ 1, or infinite) turns it off.
    pub load_ratio: f64,
    /// Substeps per step of an island with a heavily loaded body (at least `solver_iterations`).
    pub loaded_solver_iterations: usize,
    /// PGS sweeps per substep of an island with a heavily loaded body (at least
    /// `pgs_iterations`).
    pub loaded_pgs_iterations: usize,
    /// A heavily loaded body's contacts are recomputed every step, never recycled (see
    /// [`Self::contact_recycling`] and [`load_ratio`]): a recycled contact keeps its points and
    /// normal while the pair moves up to `contact_recycle_distance`, and under a load of
    /// `load_ratio` times its own weight that stale lever decides whether the light body tips.
    /// Pairs without a loaded body recycle as before. `false`: recycled like every pair.
    pub loaded_fresh_contacts: bool,
    /// A world with a heavily loaded body runs its contacts stiffer, by the ratio
    /// `loaded_solver_iterations / solver_iterations`, dynamic and static alike. Rapier's
    /// contact is a spring normalised by the constraint's effective mass, which the light body
    /// dominates: under a load `k` times its weight it rests `k` times deeper, of the order of
    /// `k·g / (2ω²)`; a teapot on a 10-hull fork sat 1.16 mm deep where MuJoCo's contact sits
    /// 0.45 mm (docs/agreement.md, "Tenth stop"). Scaling ω with the substep count keeps `hω`
    /// (the spring's stiffness per substep, its stability) what the unloaded world has and
    /// divides the depth by the ratio squared. Only contact softness changes, and only in
    /// worlds with a loaded body. Off by default: measured, it fixes that teapot and turns a
    /// rest agreement into a disagreement (437), see the doc.
    pub loaded_stiff_contacts: bool,
    /// Gravitational acceleration along −z (m/s²).
    pub gravity: f64,
    /// Cap on the settle phase (s): it ends earlier when every dynamic body sleeps. 6 s: a
    /// faceted lemon tilted a few degrees on the floor was still rocking at 3 s (Rapier has no
    /// rolling resistance) and failed the rest check that followed, where MuJoCo holds it; with
    /// 6 s it sleeps first (issue #33: 3 of 300 generated scenes).
    pub settle_max_time: f64,
    /// Length of the rest phase (s).
    pub rest_time: f64,
    /// Rapier's friction model: `true` solves one Coulomb friction constraint per contact
    /// point (`FrictionModel::Coulomb`, what MuJoCo and PhysX do); `false` is Rapier's default
    /// `Simplified` model, one friction constraint at the centre of each group of four contact
    /// points plus a twist constraint.
    pub coulomb_friction: bool,
    /// Rapier's contact clustering: manifolds of one collider pair with nearly the same normal
    /// are merged into one cluster of at most four points before the solver sees them.
    pub contact_clustering: bool,
    /// Rapier's `friction_in_bias_pass`: friction also acts while the solver pushes
    /// interpenetrating contacts apart (its bias pass). Rapier's default is off.
    pub friction_in_bias_pass: bool,
    /// Fastest speed (m/s) at which the solver pushes an interpenetration apart (Rapier's
    /// `max_corrective_velocity`; its default 3 m/s).
    pub max_corrective_velocity: f64,
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
    /// Damping ratio of both kinds of soft contacts (Rapier's default 10). With a solver
    /// substep `h = dt / solver_iterations` and `ω = 2π·frequency`, a contact is pushed out at
    /// `ω / (hω + 2ζ)` per second of depth, so the depth an item rests at under its weight
    /// shrinks with a smaller ζ.
    pub contact_damping_ratio: f64,
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
    /// A contact manifold's points and normal are kept from one step to the next (parry's
    /// coherence, see the `fresh` module) only while its normal turned less than this (degrees)
    /// since it was computed. parry's own limit is 1°; 1 or more keeps it. Below it, a body
    /// rocking on a rim no longer pushes along a normal that turns with it: a 32-sided cylinder
    /// released tilted 4° on the floor rocks up to 7.3° in 4 s with 1°, and comes to rest with
    /// 0.01° (`tests/contact_statics.rs`). Every moving contact is recomputed more often.
    /// The kept normal is also an accidental rolling resistance; 0.01° with
    /// [`SettleOptions::rolling_friction`] 0.1 mm was measured as a default over 0..700 and
    /// not kept (docs/agreement.md "Thirteenth stop", and with the resistance's `N` corrected
    /// "Fourteenth stop": verdict 684, rest 372 of 376, against main's 687 and 376 of 377; with
    /// the resistance held within the step, "Fifteenth stop": verdicts 313, 396, 654 fixed, 402
    /// lost, the rests of 137, 233, 460 lost, so not kept either; with the hold's bound shared
    /// with sliding as in MuJoCo's elliptic cone, "Sixteenth stop": verdict 687 as main, rest
    /// 372 of 379, not kept).
    pub contact_reuse_max_turn_deg: f64,
    /// Rolling friction (m, MuJoCo's third `friction` value): two bodies in contact (or a body
    /// and the floor) resist rolling on each other with a torque of at most this times their
    /// contacts' normal force (the `rolling` module); a ball of radius r on an incline stays
    /// while tan θ ≤ rolling_friction / r. 0 (the default): none, Rapier's own contacts. When
    /// the default is above 0 the MJCF export writes it (`condim="6"`); MuJoCo's own default
    /// coefficient is 0.1 mm.
    pub rolling_friction: f64,
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
    /// The creep rule ([`creep`]): a body that moved past `max_rest_motion` /
    /// `max_rest_rotation_deg` in the rest check, but by at most this (m)...
    pub creep_max_motion: f64,
    /// ...and at most this (degrees), passes the rest check when its contacts at the settled
    /// and the final pose hold it (and what it touches) in static equilibrium within their
    /// friction cones (see [`equilibrium`]). 3 mm and 3°, three times the rest limits: Rapier's
    /// creep of a leaning item was traced at 0.07–2.5 mm and 0.04–2.5° per second, steady for
    /// 20 s; a body that falls, tips or rolls leaves that band within the second. 0 for either
    /// disables the rule.
    pub creep_max_rotation_deg: f64,
    /// Contact points closer than this (m) take part in the creep rule's equilibrium (0.2 mm:
    /// ten times the depth a soft contact sinks to under an item's weight here, far below the
    /// 2 mm at which the support graph calls two bodies touching).
    pub creep_contact_distance: f64,
    /// The equilibrium holds when the unbalanced wrench is at most this fraction of the group's
    /// weight. 1e-5: a body accelerated by that fraction of g moves 0.05 mm in the 1 s rest
    /// check, a twentieth of its limit; a network that truly balances leaves round-off (1e-15).
    pub creep_max_imbalance: f64,
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
    /// The marginal probe ([`probe`]): after the rest phase each dynamic body is rolled by this
    /// angle (degrees) about a horizontal axis through its lowest point, in four directions; it
    /// is marginal when it ends turned more than half of it from its rest pose. 0 disables it.
    pub probe_angle_deg: f64,
    /// How long (s) each of the four probes runs before the body's turn from its rest pose is
    /// measured.
    pub probe_time: f64,
}

impl Default for SettleOptions {
    fn default() -> Self {
        SettleOptions {
            dt: 1.0 / 240.0,
            solver_iterations: 4,
            pgs_iterations: 1,
            stabilization_iterations: 1,
            load_ratio: 10.0,
            loaded_solver_iterations: 8,
            loaded_pgs_iterations: 4,
            loaded_fresh_contacts: true,
            loaded_stiff_contacts: false,
            gravity: 9.81,
            settle_max_time: 6.0,
            rest_time: 1.0,
            coulomb_friction: false,
            contact_clustering: true,
            friction_in_bias_pass: false,
            max_corrective_velocity: 3.0,
            restitution: 0.0,
            floor_friction: 0.8,
            sleep_linear_threshold: 0.005,
            sleep_time: 0.5,
            contact_frequency: 120.0,
            static_contact_frequency: 240.0,
            contact_damping_ratio: 10.0,
            linear_damping: 0.0,
            angular_damping: 0.0,
            perturbation_speed: 0.001,
            prediction_distance: 0.002,
            contact_reuse_max_turn_deg: 1.0,
            rolling_friction: 0.0,
            contact_recycling: true,
            contact_recycle_distance: 0.0005,
            max_relative_drift: 0.10,
            max_settle_rotation_deg: 30.0,
            max_rest_motion: 0.001,
            max_rest_rotation_deg: 1.0,
            creep_max_motion: 0.003,
            creep_max_rotation_deg: 3.0,
            creep_contact_distance: 0.0002,
            creep_max_imbalance: 1e-5,
            max_rest_penetration: 0.001,
            max_initial_penetration: 0.001,
            support_distance: 0.002,
            support_release_margin: 0.001,
            support_min_normal_z: 0.1,
            probe_angle_deg: 0.5,
            probe_time: 0.3,
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
    /// The rest pose is only balanced: rolled 0.5° off it, the body did not come back (see
    /// [`probe`]). Other engines may not hold it; it does not fail the body.
    pub marginal: bool,
    /// Largest drift from the rest pose at the end of the four probes (m, degrees); 0 with the
    /// probe off.
    pub probe_displacement: f64,
    pub probe_rotation_deg: f64,
    /// Set when the creep rule ([`SettleOptions::creep_max_motion`]) looked at this body: the
    /// unbalanced wrench of its contacts as a fraction of its group's weight (the worse of the
    /// settled and the final pose). Absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub creep_imbalance: Option<f64>,
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
    /// Names of the bodies whose rest pose is marginal (see [`BodyReport::marginal`]).
    pub marginal: Vec<String>,
    /// Names of the heavily loaded bodies (see [`SettleOptions::load_ratio`]) whose contact
    /// islands ran the loaded substeps and sweeps.
    pub heavily_loaded: Vec<String>,
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

/// How far below z = 0 the floor's top face lies (m). Prepared scenes rest on z = 0, and a
/// hull's lowest vertex ends up there only to f64 rounding: 1.4e-17 m *above* it, say. At such
/// a separation, below GJK's tolerance, parry's contact query gave a hull touching the floor
/// at a sharp vertex (the apex of a basket floor's pie slice) a normal pointing up out
/// of the floor, in about half the cases; Rapier then slid the fixture basket 2.4 mm and rolled
/// its fruits out. Exactly at 0, below it, or 1e-12 m above it, the normals are right. 10 nm is
/// far above the rounding and far below anything the checks measure.
pub const FLOOR_GAP: f64 = 1e-8;

#[cfg(test)]
mod tests;
