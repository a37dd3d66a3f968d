//! The settle test itself: [`settle`] (settle phase, rest phase, verdicts) and [`simulate`]
//! (a plain run that records poses).

use super::load_ratio::heavily_loaded;
use super::world::Sim;
use super::*;

/// Run the settle test (settle phase, then rest phase) on a scene.
pub fn settle(bodies: &[SimBody], opts: &SettleOptions) -> Result<SettleReport, PhysicsError> {
    let mut sim = Sim::new(bodies, opts)?;
    let n = bodies.len();
    let dynamic: Vec<usize> = (0..n).filter(|&i| !bodies[i].fixed).collect();

    // Composed pose: supports and initial penetration.
    let start = sim.contact_graph(opts.support_distance);
    let loaded = heavily_loaded(bodies, &start.supports, opts.load_ratio);
    sim.load_extra_iterations(&loaded);
    let composed: Vec<Isometry3<f64>> = (0..n).map(|i| sim.pose(i)).collect();
    sim.kick();

    // Phase 1: settle until everything sleeps.
    let max_settle_steps = steps_for(opts.settle_max_time, opts.dt);
    let mut settle_steps = 0;
    let mut time_to_sleep = if dynamic.is_empty() { Some(0.0) } else { None };
    while time_to_sleep.is_none() && settle_steps < max_settle_steps {
        sim.step();
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
        sim.step();
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
    // The creep rule: only when some body moved past the rest limits within the creep band.
    let creeping = |i: usize| {
        (rest_disp[i] > opts.max_rest_motion || rest_rot[i] > opts.max_rest_rotation_deg)
            && rest_disp[i] <= opts.creep_max_motion
            && rest_rot[i] <= opts.creep_max_rotation_deg
    };
    let imbalance = if dynamic.iter().any(|&i| creeping(i)) {
        super::creep::creep_balance(&sim, &settled, &finals, opts.creep_contact_distance)
    } else {
        vec![f64::INFINITY; n]
    };
    let probed = super::probe::probe(bodies, &finals, &loaded, opts)?;

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
            let crept = creeping(i) && imbalance[i] <= opts.creep_max_imbalance;
            if crept {
                notes.push(format!(
                    "crept {:.2} mm / {:.2}° during the {} s rest check, but its contacts hold it at rest (unbalanced {:.1e} of its weight): the solver's creep, not counted",
                    mm(rest_disp[i]),
                    rest_rot[i],
                    opts.rest_time,
                    imbalance[i]
                ));
            }
            if rest_disp[i] > opts.max_rest_motion && !crept {
                reasons.push(format!(
                    "moved {:.2} mm during the {} s rest check (> {:.2} mm)",
                    mm(rest_disp[i]),
                    opts.rest_time,
                    mm(opts.max_rest_motion)
                ));
            }
            if rest_rot[i] > opts.max_rest_rotation_deg && !crept {
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
        let (probe_displacement, probe_rotation_deg) = probed[i];
        let marginal = !b.fixed && probe_rotation_deg > 0.5 * opts.probe_angle_deg;
        if marginal {
            notes.push(format!(
                "marginal rest: rolled {}° off its rest pose, it did not come back (still {:.2} mm / {:.2}° off after {} s; other engines may not hold this pose)",
                opts.probe_angle_deg,
                mm(probe_displacement),
                probe_rotation_deg,
                opts.probe_time
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
            marginal,
            probe_displacement,
            probe_rotation_deg,
            creep_imbalance: (!b.fixed && creeping(i)).then_some(imbalance[i]),
        });
    }
    let marginal: Vec<String> = reports
        .iter()
        .filter(|r| r.marginal)
        .map(|r| r.name.clone())
        .collect();
    if !marginal.is_empty() {
        warnings.push(format!(
            "marginal rest pose (balanced, not stable; other engines may roll it away): {}",
            marginal.join(", ")
        ));
    }
    Ok(SettleReport {
        passed: reports.iter().all(|r| r.passed),
        marginal,
        heavily_loaded: (0..n)
            .filter(|&i| loaded[i])
            .map(|i| bodies[i].name.clone())
            .collect(),
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
    let start = sim.contact_graph(opts.support_distance);
    sim.load_extra_iterations(&heavily_loaded(bodies, &start.supports, opts.load_ratio));
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
        sim.step();
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

/// Number of whole steps of length `dt` covering `time` (rounded to nearest).
pub(super) fn steps_for(time: f64, dt: f64) -> usize {
    (time / dt).round().max(0.0) as usize
}

/// Centre-of-mass displacement (m) and rotation angle (degrees) from pose `a` to pose `b`.
pub(super) fn drift(a: &Isometry3<f64>, b: &Isometry3<f64>, com: &P3) -> (f64, f64) {
    let d = (b * com - a * com).norm();
    let r = b.rotation.angle_to(&a.rotation).to_degrees();
    (d, r)
}

pub(super) fn quoted(name: &str) -> String {
    if name == FLOOR {
        "the floor".into()
    } else {
        format!("'{name}'")
    }
}

pub(super) fn names(sim: &Sim, ks: &[usize]) -> String {
    ks.iter()
        .map(|&k| quoted(sim.name(k)))
        .collect::<Vec<_>>()
        .join(", ")
}
