//! A rolling resistance for the settle ([`SettleOptions::rolling_friction`]): Rapier has none.
//!
//! Entry point: [`Rolling::update`], called by `Sim::step` after every Rapier step.
//!
//! Between two bodies in contact (or a body and the floor) it keeps one torque, applied to the
//! first body and its opposite to the second, that opposes their relative rolling: the part of
//! `ω₁ − ω₂` perpendicular to the contact normal. Its size is at most `μ_r·N`, `N` the normal
//! force of the pair's contacts at the last step and `μ_r` a length, MuJoCo's rolling friction
//! (a geom's third `friction` value, active with `condim="6"`, the torque bounded by `μ_r` times
//! the normal force), which the MJCF export writes with the same value. Below that bound the
//! torque holds the pair from rolling (a ball on an incline with `tan θ ≤ μ_r / r` stays), at it
//! the pair rolls and decelerates. The torque is kept from step to step and corrected by what
//! still rolled, the way the solver warm-starts its impulses: after a step in which the pair
//! rolled at `w`, the torque changes by the one that would stop `w` in one step about the
//! centres of mass (shared among the pairs of the busier body); the contacts' own friction adds
//! inertia to that rolling, so the correction converges from below without overshoot.
//! Spin about the normal is not included (Rapier's contacts carry a twist friction already).

use super::*;
use rapier3d_f64::prelude::RigidBodyHandle;
use std::collections::{BTreeMap, HashMap};

/// The torques kept between steps, by body pair (indices into the scene's bodies; the scene's
/// body count stands for the floor).
pub(super) struct Rolling {
    /// Rolling friction (m); 0: off.
    mu: Real,
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
    /// Impulse-weighted sum of the normals, from the pair's first body towards its second.
    normal: Vector,
}

impl Rolling {
    pub(super) fn new(mu: Real, handles: &[RigidBodyHandle]) -> Self {
        Rolling {
            mu,
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
                let impulse: Real = m
                    .data
                    .solver_contacts
                    .iter()
                    .filter_map(|c| m.points.get(c.contact_indices()[0] as usize))
                    .map(|p| p.data.impulse)
                    .sum();
                if impulse <= 0.0 {
                    continue;
                }
                // The manifold's normal points from its first collider towards its second.
                let (key, sign) = if i < j { ((i, j), 1.0) } else { ((j, i), -1.0) };
                let e = pairs.entry(key).or_default();
                e.impulse += impulse;
                e.normal += m.data.normal * (sign * impulse);
            }
        }
        let mut count = vec![0usize; n + 1];
        for &(a, b) in pairs.keys() {
            count[a] += 1;
            count[b] += 1;
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
        let mut torques = BTreeMap::new();
        for (&(a, b), c) in &pairs {
            if !(moving(a) || moving(b)) {
                continue;
            }
            let Some(nrm) = unit(c.normal) else {
                continue;
            };
            let angvel = |k: usize| {
                if k < n {
                    world.bodies[handles[k]].angvel()
                } else {
                    Vector::ZERO
                }
            };
            let inv_inertia = |k: usize, d: Vector| -> Real {
                if moving(k) {
                    let mp = world.bodies[handles[k]].mass_properties();
                    d.dot(mp.effective_world_inv_inertia * d)
                } else {
                    0.0
                }
            };
            let w = angvel(a) - angvel(b);
            let roll = w - nrm * nrm.dot(w);
            let mut t = self.torques.get(&(a, b)).copied().unwrap_or(Vector::ZERO);
            t -= nrm * nrm.dot(t);
            if let Some(d) = unit(roll) {
                let k = inv_inertia(a, d) + inv_inertia(b, d);
                if k > 0.0 {
                    let share = count[a].max(count[b]).max(1) as Real;
                    t -= roll / (k * dt * share);
                }
            }
            let limit = self.mu * c.impulse / dt;
            let size = t.length();
            if size > limit {
                t *= limit / size;
            }
            torques.insert((a, b), t);
        }
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

/// `v` scaled to length 1, or `None` when it is (nearly) zero.
fn unit(v: Vector) -> Option<Vector> {
    let l = v.length();
    (l > 1e-12).then(|| v / l)
}
