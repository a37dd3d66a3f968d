//! A rolling resistance for the settle ([`SettleOptions::rolling_friction`]): Rapier has none.
//!
//! Entry point: [`Rolling::update`], called by `Sim::step` after every Rapier step.
//!
//! Between two bodies in contact (or a body and the floor) it bounds the angular impulse that
//! opposes their relative rolling (the part of `ω₁ − ω₂` perpendicular to the contact normal)
//! by `μ_r·J`, `J` the normal impulse of the pair's contacts in the step and `μ_r` a length,
//! MuJoCo's rolling friction (a geom's third `friction` value, active with `condim="6"`), which
//! the MJCF export writes with the same value. A ball on an incline with `tan θ ≤ μ_r / r`
//! stays, exactly; above it rolls and decelerates by `μ_r g cos θ / r` over its inertia.
//!
//! It acts twice per step, as a solver would (a warm start, then an iteration):
//! - the pair's hold of the last step is applied again during the next as a torque (through
//!   Rapier's user torques), so a body held last step is held through this one without moving;
//! - after the step, whatever the pair still rolls is cancelled at once, before the next
//!   position update, by an angular impulse about the contact point (the body turning there
//!   without slipping, so the contact's friction does not hand the rolling back) that keeps
//!   the step's total within `μ_r·J`; Gauss–Seidel over the pairs, a body's pairs sharing it.
//!
//! `J` is shared with sliding as in MuJoCo's elliptic cone (`cone="elliptic"`, the export's):
//! each manifold's normal impulse is scaled by `√(1 − (f_t / μ N)²)` ([`cone_share`]), so a
//! contact near its sliding limit has little rolling left (`tests/contact_statics.rs`, the
//! incline with μ 0.1 and 0.15, against MuJoCo's own verdict; docs/agreement.md "Sixteenth stop").
//!
//! The torque alone, corrected one step late (session 17's), crept 2–30 µm in 2 s on the
//! incline below θ_c where MuJoCo holds still (docs/agreement.md "Fifteenth stop").
//! Spin about the normal is not included (Rapier's contacts carry a twist friction already).

use super::*;
use nalgebra::{Matrix3, Vector3};
use rapier3d_f64::prelude::RigidBodyHandle;
use std::collections::{BTreeMap, HashMap};

/// The torques kept between steps, by body pair (indices into the scene's bodies; the scene's
/// body count stands for the floor).
pub(super) struct Rolling {
    /// Rolling friction (m); 0: off.
    mu: Real,
    /// Coulomb friction per contact point (Rapier's `FrictionModel::Coulomb`): each solver point
    /// stores its own friction impulse; else (the twist model) the manifold's one friction
    /// impulse is stored on every point of it.
    coulomb: bool,
    /// Body index of each rigid-body handle (the floor's absent); only looked up, never iterated.
    index: HashMap<RigidBodyHandle, usize>,
    /// Torque on the pair's first body (its opposite on the second), by pair `(a, b)`, `a < b`.
    torques: BTreeMap<(usize, usize), Vector>,
}

/// One pair's contacts at the last step.
#[derive(Default)]
struct PairContact {
    /// Sum of the contacts' normal impulses (N·s).
    impulse: Real,
    /// The part of `impulse` the shared cone leaves to rolling (N·s): each manifold's normal
    /// impulse times `√(1 − (|f_t| / μ N)²)` ([`cone_share`]).
    budget: Real,
    /// Impulse-weighted sum of the normals, from the pair's first body towards its second.
    normal: Vector,
    /// Impulse-weighted sum of the contact points (world, midway between the two surfaces).
    point: Vector,
}

impl Rolling {
    pub(super) fn new(mu: Real, coulomb: bool, handles: &[RigidBodyHandle]) -> Self {
        Rolling {
            mu,
            coulomb,
            index: handles.iter().enumerate().map(|(i, &h)| (h, i)).collect(),
            torques: BTreeMap::new(),
        }
    }

    /// After a step of `world` (bodies `handles`, `n` of them): the pairs' torques for the next.
    pub(super) fn update(&mut self, world: &mut PhysicsWorld, handles: &[RigidBodyHandle]) {
        if self.mu <= 0.0 {
            return;
        }
        let n = handles.len();
        let dt = world.integration_parameters.dt;
        let mut pairs: BTreeMap<(usize, usize), PairContact> = BTreeMap::new();
        for cp in world.narrow_phase.contact_pairs() {
            for m in cp.manifolds() {
                let idx = |h: Option<RigidBodyHandle>| {
                    h.and_then(|h| self.index.get(&h).copied()).unwrap_or(n)
                };
                let (i, j) = (idx(m.data.rigid_body1), idx(m.data.rigid_body2));
                if i == j {
                    continue;
                }
                // Only the points handed to the solver this step: a manifold point left out of
                // it (parry's manifold has up to one more) keeps the impulse it inherited from
                // the point it was matched to, stale; on the 0.01° incline those made `N`
                // 1.41–1.54× the weight (docs/agreement.md "Fourteenth stop").
                let (Some(c1), Some(c2)) = (
                    world.colliders.get(cp.collider1),
                    world.colliders.get(cp.collider2),
                ) else {
                    continue;
                };
                let (pos1, pos2) = (*c1.position(), *c2.position());
                let mut impulse = 0.0;
                let mut point = Vector::ZERO;
                // The last substep's normal and friction impulses (the shared cone's load).
                let (mut last, mut friction) = (0.0, Vector::ZERO);
                let mut budget = 0.0;
                for c in &m.data.solver_contacts {
                    if let Some(p) = m.points.get(c.contact_indices()[0] as usize) {
                        impulse += p.data.impulse;
                        let at = 0.5
                            * (pos1.transform_point(p.local_p1) + pos2.transform_point(p.local_p2));
                        point += at * p.data.impulse;
                        if self.coulomb {
                            let share = cone_share(
                                p.data.warmstart_tangent_world.length(),
                                m.data.friction * p.data.warmstart_impulse,
                            );
                            budget += p.data.impulse * share;
                        } else {
                            last += p.data.warmstart_impulse;
                            friction = p.data.warmstart_tangent_world;
                        }
                    }
                }
                if impulse <= 0.0 {
                    continue;
                }
                if !self.coulomb {
                    budget = impulse * cone_share(friction.length(), m.data.friction * last);
                }
                // The manifold's normal points from its first collider towards its second.
                let (key, sign) = if i < j { ((i, j), 1.0) } else { ((j, i), -1.0) };
                let e = pairs.entry(key).or_default();
                e.impulse += impulse;
                e.budget += budget;
                e.normal += m.data.normal * (sign * impulse);
                e.point += point;
            }
        }
        let awake: Vec<bool> = (0..=n)
            .map(|k| {
                k < n && {
                    let rb = &world.bodies[handles[k]];
                    rb.is_dynamic() && !rb.is_sleeping()
                }
            })
            .collect();
        let moving = |k: usize| awake[k];
        // The pairs that act: a body of the pair moving, a normal and a point.
        let acting: Vec<((usize, usize), Vector, Vector, Real)> = pairs
            .iter()
            .filter(|(&(a, b), _)| moving(a) || moving(b))
            .filter_map(|(&key, c)| Some((key, unit(c.normal)?, c.point / c.impulse, c.budget)))
            .collect();
        // The hold, within the step: the rolling that the step left is cancelled now, before
        // the next position update, by an angular impulse about the contact point that keeps
        // each pair's total for the step (the kept torque's share included) within μ_r·J, J
        // the step's normal impulse, less what the contacts' friction takes of the shared cone
        // (`budget`). Gauss–Seidel over the pairs (a body's pairs share it).
        let mut held: BTreeMap<(usize, usize), Vector> = acting
            .iter()
            .map(|&(key, nrm, _, _)| {
                let t = self.torques.get(&key).copied().unwrap_or(Vector::ZERO);
                (key, (t - nrm * nrm.dot(t)) * dt)
            })
            .collect();
        for _ in 0..HOLD_SWEEPS {
            for &((a, b), nrm, at, budget) in &acting {
                let w = angvel(world, handles, n, a) - angvel(world, handles, n, b);
                let roll = w - nrm * nrm.dot(w);
                let Some(d) = unit(roll) else {
                    continue;
                };
                let pa = moving(a).then(|| Pivot::new(&world.bodies[handles[a]], at));
                let pb = moving(b).then(|| Pivot::new(&world.bodies[handles[b]], at));
                let k: Real = [&pa, &pb]
                    .iter()
                    .filter_map(|p| p.as_ref().map(|p| d.dot(p.turn(d))))
                    .sum();
                if k <= 0.0 {
                    continue;
                }
                let acc = held.entry((a, b)).or_insert(Vector::ZERO);
                let mut next = *acc - roll / k;
                next -= nrm * nrm.dot(next);
                let limit = self.mu * budget;
                let size = next.length();
                if size > limit {
                    next *= limit / size;
                }
                let applied = next - *acc;
                *acc = next;
                if let Some(p) = pa {
                    p.apply(&mut world.bodies[handles[a]], applied);
                }
                if let Some(p) = pb {
                    p.apply(&mut world.bodies[handles[b]], -applied);
                }
            }
        }
        // The next step's torque: the step's total hold, warm-starting the next step. It is
        // clamped to this step's μ_r·J only when the pair still rolled after the step (a pair
        // held still keeps last step's torque, which was within last step's bound).
        let torques: BTreeMap<(usize, usize), Vector> =
            held.into_iter().map(|(key, h)| (key, h / dt)).collect();
        for &h in handles {
            let rb = &mut world.bodies[h];
            if rb.is_dynamic() {
                rb.reset_torques(false);
            }
        }
        for (&(a, b), &t) in &torques {
            if moving(a) {
                world.bodies[handles[a]].add_torque(t, false);
            }
            if moving(b) {
                world.bodies[handles[b]].add_torque(-t, false);
            }
        }
        self.torques = torques;
    }
}

/// The share of a contact's normal force that MuJoCo's elliptic cone (`cone="elliptic"`, as the
/// MJCF export writes) leaves to rolling when the contact's friction carries `tangent` against
/// a sliding limit `limit` (μ N, the same substep's): the cone is one bound over every friction
/// dimension, `(f_t / μ)² + (τ_r / μ_r)² ≤ N²`, so `|τ_r| ≤ μ_r N √(1 − (f_t / μ N)²)`.
/// (MuJoCo's cone has the torsion `τ_n / μ_t` in it too; Rapier's twist friction is bounded
/// by its own rule, not MuJoCo's `μ_t`, so it is left out.)
fn cone_share(tangent: Real, limit: Real) -> Real {
    if limit <= 0.0 {
        return 1.0;
    }
    let load = (tangent / limit).min(1.0);
    (1.0 - load * load).sqrt()
}

/// Gauss–Seidel sweeps of the hold over a step's pairs.
const HOLD_SWEEPS: usize = 4;

/// Body `k`'s angular velocity (the floor's is zero).
fn angvel(world: &PhysicsWorld, handles: &[RigidBodyHandle], n: usize, k: usize) -> Vector {
    if k < n {
        world.bodies[handles[k]].angvel()
    } else {
        Vector::ZERO
    }
}

/// A body turning about a contact point without slipping there: an angular impulse `h` turns
/// it by `I_P⁻¹ h` (`I_P` its inertia about the point) and moves its centre of mass with the
/// turn, the way rolling friction stops a ball whose contact friction keeps it from sliding.
struct Pivot {
    /// Inverse inertia about the point (world).
    inv: Matrix3<Real>,
    /// Centre of mass from the point.
    arm: Vector3<Real>,
}

impl Pivot {
    fn new(rb: &rapier3d_f64::prelude::RigidBody, at: Vector) -> Self {
        let v = |x: Vector| Vector3::new(x.x, x.y, x.z);
        let inv_com = rb.mass_properties().effective_world_inv_inertia;
        let cols = [Vector::X, Vector::Y, Vector::Z].map(|e| v(inv_com * e));
        let inv_com = Matrix3::from_columns(&cols);
        let arm = v(rb.center_of_mass() - at);
        let shift = (Matrix3::identity() * arm.norm_squared() - arm * arm.transpose()) * rb.mass();
        let inv = inv_com
            .try_inverse()
            .and_then(|i| (i + shift).try_inverse())
            .unwrap_or(inv_com);
        Pivot { inv, arm }
    }

    /// The turn an angular impulse `h` gives.
    fn turn(&self, h: Vector) -> Vector {
        let t = self.inv * Vector3::new(h.x, h.y, h.z);
        Vector::new(t.x, t.y, t.z)
    }

    /// Gives the body the angular impulse `h` about the point.
    fn apply(&self, rb: &mut rapier3d_f64::prelude::RigidBody, h: Vector) {
        let dw = self.turn(h);
        let arm = Vector::new(self.arm.x, self.arm.y, self.arm.z);
        let w = rb.angvel() + dw;
        let v = rb.linvel() + dw.cross(arm);
        rb.set_angvel(w, false);
        rb.set_linvel(v, false);
    }
}

/// `v` scaled to length 1, or `None` when it is (nearly) zero.
fn unit(v: Vector) -> Option<Vector> {
    let l = v.length();
    (l > 1e-12).then(|| v / l)
}
