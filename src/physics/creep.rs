//! The creep rule of the rest check: a body that keeps moving slowly in Rapier passes the rest
//! check when its contacts at rest can hold it without any solver (static equilibrium).
//!
//! Entry points: [`Sim::contacts_at`] (the exact contact points of every body at given poses,
//! as [`Contact`]s) and [`creep_balance`] (the relative unbalanced wrench of each dynamic body's
//! group at the settled and final poses, see [`super::equilibrium::balance`]).
//!
//! Why: Rapier keeps an item leaning on an inclined contact (a box leaning in a pitcher, a spoon
//! in a mug) moving at 0.1–2.5 mm/s and up to a few degrees per second for as long as it is
//! simulated, where MuJoCo brings the same item to rest within 2–5 s (docs/agreement.md,
//! "Seventh pass"). A steady slow motion of that kind is the solver's, not the scene's, when
//! the contacts the body ends on can carry its weight (and what it carries) inside their
//! friction cones; a falling, tipping or rolling body has no such forces.

use super::equilibrium::{balance, Contact, Load};
use super::world::Sim;
use super::*;
use crate::pose::parry_pose;
use nalgebra::Vector3;
use rapier3d_f64::parry::query::{
    ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher,
};

fn v3(v: Vector) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

impl Sim<'_> {
    /// Contact points of every dynamic body at `poses` (body frames), closer than `distance`
    /// (m): hull–hull manifold points (parry's, computed from these poses, nothing kept) with
    /// the friction Rapier combines (the average of the two coefficients), and hull vertices
    /// at or below the floor plane plus `distance`. Pairs of fixed bodies are left out.
    pub(super) fn contacts_at(&self, poses: &[Isometry3<f64>], distance: f64) -> Vec<Contact> {
        let n = self.bodies.len();
        let hulls: Vec<Vec<(Pose, &dyn Shape, Aabb)>> = (0..n)
            .map(|i| {
                let pose = parry_pose(&poses[i]);
                self.colliders[i]
                    .iter()
                    .map(|&c| {
                        let shape = self.world.colliders[c].shape();
                        (pose, shape, shape.compute_aabb(&pose).loosened(distance))
                    })
                    .collect()
            })
            .collect();
        let mut out = Vec::new();
        for i in 0..n {
            let b = &self.bodies[i];
            if b.fixed {
                continue;
            }
            let mu = 0.5 * (b.friction + self.opts.floor_friction);
            for (pose, shape, _) in &hulls[i] {
                let Some(poly) = shape.as_convex_polyhedron() else {
                    continue;
                };
                for v in poly.points() {
                    let p = pose.transform_point(*v);
                    if p.z <= distance {
                        out.push(Contact {
                            a: i,
                            b: None,
                            point: v3(p),
                            normal: Vector3::z(),
                            mu,
                        });
                    }
                }
            }
        }
        let mut manifolds: Vec<ContactManifold<(), ()>> = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                let (fi, fj) = (self.bodies[i].fixed, self.bodies[j].fixed);
                if fi && fj {
                    continue;
                }
                let mu = 0.5 * (self.bodies[i].friction + self.bodies[j].friction);
                for (pi, si, ai) in &hulls[i] {
                    for (pj, sj, aj) in &hulls[j] {
                        if !ai.intersects(aj) {
                            continue;
                        }
                        manifolds.clear();
                        let pos12 = pi.inverse() * *pj;
                        if DefaultQueryDispatcher
                            .contact_manifolds(
                                &pos12,
                                *si,
                                *sj,
                                distance,
                                &mut manifolds,
                                &mut None,
                            )
                            .is_err()
                        {
                            continue;
                        }
                        for m in &manifolds {
                            // Shape 1 is i's: its normal points from i towards j.
                            let nrm = v3(pi.rotation * m.local_n1);
                            for pt in m.points.iter().filter(|pt| pt.dist <= distance) {
                                let point = 0.5
                                    * (v3(pi.transform_point(pt.local_p1))
                                        + v3(pj.transform_point(pt.local_p2)));
                                let (a, b, normal) = if fj {
                                    (i, None, -nrm)
                                } else if fi {
                                    (j, None, nrm)
                                } else {
                                    (j, Some(i), nrm)
                                };
                                out.push(Contact {
                                    a,
                                    b,
                                    point,
                                    normal,
                                    mu,
                                });
                            }
                        }
                    }
                }
            }
        }
        out
    }
}

/// For each body, the larger of its group's relative unbalanced wrench at `settled` and at
/// `finals` (0 for fixed bodies): both the pose we export and the one the rest phase ended on
/// must be held by their contacts.
pub(super) fn creep_balance(
    sim: &Sim,
    settled: &[Isometry3<f64>],
    finals: &[Isometry3<f64>],
    distance: f64,
) -> Vec<f64> {
    let n = sim.bodies.len();
    let dynamic: Vec<usize> = (0..n).filter(|&i| !sim.bodies[i].fixed).collect();
    let index = |i: usize| dynamic.iter().position(|&d| d == i);
    let mut worst = vec![0.0f64; n];
    for poses in [settled, finals] {
        let loads: Vec<Load> = dynamic
            .iter()
            .map(|&i| Load {
                mass: sim.bodies[i].mass,
                com: {
                    let c = poses[i] * sim.bodies[i].com;
                    Vector3::new(c.x, c.y, c.z)
                },
                length: sim.reach[i].max(1e-6),
            })
            .collect();
        let contacts: Vec<Contact> = sim
            .contacts_at(poses, distance)
            .into_iter()
            .filter_map(|c| {
                Some(Contact {
                    a: index(c.a)?,
                    b: match c.b {
                        Some(b) => Some(index(b)?),
                        None => None,
                    },
                    ..c
                })
            })
            .collect();
        let r = balance(&loads, &contacts, sim.opts.gravity);
        for (k, &i) in dynamic.iter().enumerate() {
            worst[i] = worst[i].max(r[k]);
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::V3;
    use crate::shapes::cuboid;

    /// A 10 × 10 × 5 cm box of 1 kg (friction 0.6) resting on a fixed 50 × 50 × 2 cm plate
    /// tilted by `deg` about y, 30 cm above the floor (friction 0.6: Rapier's average is 0.6).
    fn box_on_plate(deg: f64) -> Vec<SimBody> {
        let rot = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), deg.to_radians());
        let normal = rot * Vector3::z();
        let top = Vector3::new(0.0, 0.0, 0.3);
        let make = |name: &str, e: V3, mass: f64, centre: Vector3<f64>, fixed: bool| SimBody {
            name: name.into(),
            pose: Isometry3::from_parts(Translation3::from(centre), rot),
            hulls: vec![cuboid(e)],
            mass,
            com: P3::origin(),
            inertia: Matrix3::identity() * (mass * 0.01 / 6.0),
            friction: 0.6,
            fixed,
        };
        vec![
            make(
                "plate",
                V3::new(0.5, 0.5, 0.02),
                1.0,
                top - normal * 0.01,
                true,
            ),
            make(
                "box",
                V3::new(0.1, 0.1, 0.05),
                1.0,
                top + normal * 0.025,
                false,
            ),
        ]
    }

    fn imbalance(bodies: &[SimBody]) -> f64 {
        let opts = SettleOptions::default();
        let sim = Sim::new(bodies, &opts).unwrap();
        let poses: Vec<Isometry3<f64>> = bodies.iter().map(|b| b.pose).collect();
        creep_balance(&sim, &poses, &poses, opts.creep_contact_distance)[1]
    }

    #[test]
    fn a_box_on_a_fixed_incline_is_held_iff_tan_angle_is_within_mu() {
        // mu = 0.6: atan(0.6) = 30.96°; the inscribed pyramid keeps at least 98.1 % of it
        // (30.5°).
        for (deg, held) in [
            (0.0, true),
            (15.0, true),
            (29.0, true),
            (32.0, false),
            (45.0, false),
        ] {
            let r = imbalance(&box_on_plate(deg));
            let limit = SettleOptions::default().creep_max_imbalance;
            assert_eq!(r <= limit, held, "{deg}°: imbalance {r}");
            if !held {
                // At least what the exact cone leaves: (sin a − mu cos a) / sqrt(1 + mu²).
                let a = deg.to_radians();
                assert!(
                    r >= (a.sin() - 0.6 * a.cos()) / (1.0f64 + 0.36).sqrt() - 1e-9,
                    "{r}"
                );
            }
        }
    }

    #[test]
    fn a_box_on_the_floor_is_held_and_one_in_the_air_is_not() {
        let mut bodies = box_on_plate(0.0);
        bodies.remove(0);
        bodies.insert(0, {
            let mut far = bodies[0].clone();
            far.name = "far".into();
            far.pose = Isometry3::translation(1.0, 0.0, 0.025);
            far
        });
        // "far" sits on the floor; the box floats at 32.5 cm.
        let opts = SettleOptions::default();
        let sim = Sim::new(&bodies, &opts).unwrap();
        let poses: Vec<Isometry3<f64>> = bodies.iter().map(|b| b.pose).collect();
        let r = creep_balance(&sim, &poses, &poses, opts.creep_contact_distance);
        assert!(r[0] < 1e-12, "{r:?}");
        assert!((r[1] - 1.0).abs() < 1e-12, "{r:?}");
    }
}
