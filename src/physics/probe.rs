//! The marginal probe: is a rest pose stable, or only balanced? Engines legitimately differ on
//! a body resting in neutral balance or within a hair of a facet edge (a ball on a plane, a
//! faceted fruit on the edge of the facet it rests on): Rapier keeps it still at 0.000 mm while
//! another engine's contacts tip it onto the next facet. After the rest phase, each dynamic body
//! is rolled by [`SettleOptions::probe_angle_deg`] about a horizontal axis through the lowest
//! point of its hulls (then lifted so that point stays where it was), in four directions
//! (±x, ±y), one probe each, and simulated for [`SettleOptions::probe_time`]. A stable body
//! (a box on a face, a hull on a facet it rests on well inside) rolls back; a body that ends
//! turned more than half the nudge from its rest pose did not come back: it is `marginal`.
//! Analytically: a sphere on a plane is neutral (it stays where nudged: marginal), a box on its
//! face comes back (stable).
//!
//! Entry point: [`probe`].

use super::settle::{drift, steps_for};
use super::world::Sim;
use super::*;
use rayon::prelude::*;

/// Worst (displacement m, rotation degrees) of each body from `rest` at the end of a probe
/// (zeros for fixed bodies, and for every body when the probe is off). `loaded`: the settle
/// test's heavily loaded bodies, which keep their extra iterations in the probes.
pub(super) fn probe(
    bodies: &[SimBody],
    rest: &[Isometry3<f64>],
    loaded: &[bool],
    opts: &SettleOptions,
) -> Result<Vec<(f64, f64)>, PhysicsError> {
    let n = bodies.len();
    let mut worst = vec![(0.0f64, 0.0f64); n];
    if opts.probe_angle_deg <= 0.0 || opts.probe_time <= 0.0 {
        return Ok(worst);
    }
    let at_rest: Vec<SimBody> = bodies
        .iter()
        .zip(rest)
        .map(|(b, p)| SimBody {
            pose: *p,
            ..b.clone()
        })
        .collect();
    let angle = opts.probe_angle_deg.to_radians();
    // The four probes are four worlds that share nothing: simulated side by side, each to
    // the bits it reaches alone, their drifts folded in the order ±x, ±y (the first error in
    // that order is the one returned).
    let axes = [Vector3::x(), Vector3::y(), -Vector3::x(), -Vector3::y()];
    let ends: Vec<Result<Vec<(f64, f64)>, PhysicsError>> = axes
        .par_iter()
        .map(|axis| probe_one(bodies, &at_rest, rest, loaded, opts, axis, angle))
        .collect();
    for end in ends {
        for (i, (d, r)) in end?.into_iter().enumerate() {
            if !bodies[i].fixed {
                worst[i].0 = worst[i].0.max(d);
                worst[i].1 = worst[i].1.max(r);
            }
        }
    }
    Ok(worst)
}

/// One probe: every dynamic body rolled by `angle` about `axis` through its lowest point,
/// simulated for `probe_time`; each body's (displacement, rotation) from `rest` at the end
/// (zeros for fixed bodies).
fn probe_one(
    bodies: &[SimBody],
    at_rest: &[SimBody],
    rest: &[Isometry3<f64>],
    loaded: &[bool],
    opts: &SettleOptions,
    axis: &Vector3<f64>,
    angle: f64,
) -> Result<Vec<(f64, f64)>, PhysicsError> {
    let n = bodies.len();
    let nudged: Vec<SimBody> = at_rest
        .iter()
        .map(|b| {
            if b.fixed {
                return b.clone();
            }
            let lowest = |pose: &Isometry3<f64>| {
                b.hulls
                    .iter()
                    .flat_map(|h| h.vertices.iter())
                    .map(|v| pose * v)
                    .min_by(|p, q| p.z.total_cmp(&q.z))
                    .unwrap_or(pose * b.com)
            };
            let p = lowest(&b.pose);
            let turn =
                UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_unchecked(*axis), angle);
            let about = Translation3::from(p.coords);
            let mut pose = about * turn * about.inverse() * b.pose;
            pose.translation.vector.z += p.z - lowest(&pose).z;
            SimBody { pose, ..b.clone() }
        })
        .collect();
    let mut sim = Sim::new(&nudged, opts)?;
    sim.load_extra_iterations(loaded);
    for i in (0..n).filter(|&i| !bodies[i].fixed) {
        let act = sim.world.bodies[sim.handles[i]].activation_mut();
        act.normalized_linear_threshold = -1.0;
        act.angular_threshold = -1.0;
    }
    for _ in 0..steps_for(opts.probe_time, opts.dt) {
        sim.step();
    }
    Ok((0..n)
        .map(|i| {
            if bodies[i].fixed {
                (0.0, 0.0)
            } else {
                drift(&rest[i], &sim.pose(i), &bodies[i].com)
            }
        })
        .collect())
}
