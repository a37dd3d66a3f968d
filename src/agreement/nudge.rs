//! Is a scene's verdict a property of the scene, or of the path one engine happened to take?
//! The verdict compares a body's settle drift from the composed pose with a hard limit (10 % of
//! its bounding-box diagonal). A composed pose on a tipping edge between two facets, or a body
//! whose drift lands near the limit, gets a verdict that flips under a nudge far below any
//! composer's placement error, and then no second engine can agree with it better than chance.
//! This module re-runs our own verdict from the composed pose nudged by [`NUDGE_M`] (0.5 mm) or
//! [`NUDGE_DEG`] (0.5°, the marginal probe's nudge), each free body in turn, ±x and ±y (8 runs a
//! free body), and reports how many of those verdicts pass: when they split, the verdict is
//! **undetermined** at that resolution, whatever the other engine says.
//!
//! Entry points: [`nudged_poses`] (the nudged starts), [`Spread`] (the verdicts over them),
//! [`spread`] (our validator over the nudged starts of a generated scene).

use super::Generated;
use crate::error::Result;
use serde::Serialize;

pub use crate::validate::nudge::{nudged_poses, NUDGE_DEG, NUDGE_M};

/// Our verdicts over the nudged starts of one scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Spread {
    /// Nudged runs.
    pub runs: usize,
    /// Of them, the runs our validator passes.
    pub passed: usize,
}

impl Spread {
    /// The verdicts split: some nudged starts pass, some fail.
    pub fn undetermined(&self) -> bool {
        self.passed > 0 && self.passed < self.runs
    }

    /// Some nudged start gets `verdict` (another engine's verdict is within our own spread).
    pub fn includes(&self, verdict: bool) -> bool {
        if verdict {
            self.passed > 0
        } else {
            self.passed < self.runs
        }
    }
}

/// Our validator (as the agreement run uses it: `run_scene_with`'s options, no export) over
/// every nudged start of a generated scene.
pub fn spread(g: &Generated, settle: &crate::physics::SettleOptions) -> Result<Spread> {
    let v = verdicts(g, settle)?;
    Ok(Spread {
        runs: v.len(),
        passed: v.iter().filter(|&&p| p).count(),
    })
}

/// Our validator's verdict from each nudged start of a generated scene, in
/// [`nudged_poses`]' order.
pub fn verdicts(g: &Generated, settle: &crate::physics::SettleOptions) -> Result<Vec<bool>> {
    let a = &g.assembly;
    let poses: Vec<_> = a.bodies.iter().map(|b| b.composed_pose).collect();
    let coms: Vec<_> = a.bodies.iter().map(|b| b.inertial.com).collect();
    let fixed: Vec<_> = a.bodies.iter().map(|b| b.fixed).collect();
    let mut opts = crate::validate::ValidateOptions {
        visual_metrics: false,
        settle: settle.clone(),
        ..Default::default()
    };
    // Each start's own verdict, one settle each (no run-time nudge check inside a nudge).
    opts.nudge.enabled = false;
    let mut out = Vec::new();
    for p in nudged_poses(&poses, &coms, &fixed) {
        let mut n = a.clone();
        for (b, q) in n.bodies.iter_mut().zip(p) {
            b.pose = q;
            b.composed_pose = q;
        }
        out.push(crate::validate::validate(&n, &opts)?.passed);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{settle, SettleOptions, SimBody};
    use crate::validate::nudge::tests::leaning_cube;
    use nalgebra::{Isometry3, Point3};

    /// Our settle verdict over the nudged starts of one leaning cube.
    fn cube_spread(theta: f64) -> Spread {
        let b = leaning_cube(0.05, theta);
        let opts = SettleOptions {
            probe_angle_deg: 0.0,
            ..Default::default()
        };
        let mut s = Spread::default();
        for p in nudged_poses(&[b.pose], &[b.com], &[false]) {
            let r = settle(
                &[SimBody {
                    pose: p[0],
                    ..b.clone()
                }],
                &opts,
            )
            .expect("settle");
            s.runs += 1;
            s.passed += r.passed as usize;
        }
        s
    }

    #[test]
    fn nudges_turn_about_the_centre_of_mass_and_shift_each_free_body() {
        let poses = [
            Isometry3::translation(0.0, 0.0, 0.5),
            Isometry3::translation(1.0, 0.0, 0.5),
        ];
        let coms = [Point3::new(0.0, 0.0, 0.1), Point3::origin()];
        let n = nudged_poses(&poses, &coms, &[true, false]);
        assert_eq!(n.len(), 8, "8 starts for the one free body");
        for p in &n {
            assert_eq!(p[0], poses[0], "a fixed body is never nudged");
            let c0 = poses[1] * coms[1];
            let c1 = p[1] * coms[1];
            let turn = (p[1].rotation * poses[1].rotation.inverse())
                .angle()
                .to_degrees();
            let moved = (c1 - c0).norm();
            // A turn leaves the centre of mass where it was; a shift does not turn.
            assert!(
                (turn - NUDGE_DEG).abs() < 1e-9 && moved < 1e-12
                    || turn < 1e-9 && (moved - NUDGE_M).abs() < 1e-12,
                "{turn} deg, {moved} m"
            );
        }
    }

    /// Analytic: a cube of side s leaning at θ on an edge falls back onto its face, its centre
    /// of mass moving √2 s sin(θ/2) (radius s/√2 about the edge); the settle rule's limit is
    /// 10 % of the diagonal √3 s, crossed at θ* = 2 asin(0.1 √3 / √2) = 14.07°. Far from θ*
    /// every nudged start gets the same verdict (pass at 5°, fail at 25°); near it the ±0.5°
    /// nudges about the edge straddle the limit and the verdicts split.
    #[test]
    fn a_verdict_splits_only_where_the_drift_meets_the_limit() {
        let star = 2.0 * (0.1 * 3f64.sqrt() / 2f64.sqrt()).asin().to_degrees();
        assert!((star - 14.07).abs() < 0.01, "{star}");
        let low = cube_spread(5.0);
        assert_eq!(low.passed, low.runs, "5°: {low:?}");
        let high = cube_spread(25.0);
        assert_eq!(high.passed, 0, "25°: {high:?}");
        assert!(!low.undetermined() && !high.undetermined());
        // Within ±1.5° of θ* (the nudge is ±0.5°; the rest is Rapier's landing against the
        // analytic pivot), some angle splits; none of ±5° splits outside ±3°.
        let split: Vec<f64> = (-10..=10)
            .map(|k| star + 0.5 * k as f64)
            .filter(|&t| cube_spread(t).undetermined())
            .collect();
        assert!(
            split.iter().any(|t| (t - star).abs() <= 1.5),
            "no split near {star}: {split:?}"
        );
        assert!(split.iter().all(|t| (t - star).abs() <= 3.0), "{split:?}");
    }
}
