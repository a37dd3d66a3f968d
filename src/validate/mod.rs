//! Validation: is the scene free of interpenetration, and does it stay put when simulated?
//!
//! 1. **Static**, at the composed pose: for every pair of objects the Interact3D metrics
//!    (R_volume, R_surface, max penetration depth, min clearance) on the visual meshes and on the
//!    collision hulls. Gate: collision hulls of different objects penetrate by at most
//!    `max_collision_penetration` (0.1 mm). Visual interpenetration is reported, and warned about.
//! 2. **Dynamic**, in Rapier ([`crate::physics`]): settle from the composed pose (drift, turn, left
//!    its support), then rest 1 s (motion, turn, contact penetration).
//! 3. **Nudge check** ([`nudge`]), only where the one settle's drift or turn says the verdict
//!    may be fragile: the firing bodies turned 0.5° four ways and settled again; split verdicts
//!    make the scene [`Verdict::Undetermined`], gated by [`ValidateOptions::undetermined`].
//!
//! Every check is a [`Check`] with its value and limit, so a report, a table and JUnit XML all
//! come from the same list.
//!
//! Entry points: [`validate`] (a built or exported scene), [`table`], [`junit`]; for URDF/MJCF
//! assets written by anyone: [`asset::check_path`] (findings with check ids, severities, file
//! and line), [`finding`] (the finding model), [`ci`] (the many-asset run and its outputs:
//! table, JSON, SARIF, GitHub annotations, JUnit, baselines).

pub mod asset;
pub mod ci;
pub mod contact;
pub mod finding;
pub mod nudge;

use crate::body::Assembly;
use crate::error::{Error, Result};
use crate::metrics::{scene_metrics, MetricsOptions, PairMetrics, ScenePair, Solid};
use crate::physics::{settle, SettleOptions, SettleReport, SimBody};
use serde::Serialize;

/// Thresholds and settings of the validation.
#[derive(Clone, Debug, Serialize)]
pub struct ValidateOptions {
    pub metrics: MetricsOptions,
    pub settle: SettleOptions,
    /// Largest penetration between collision hulls of different objects at the composed pose (m).
    pub max_collision_penetration: f64,
    /// Also compute the metrics on the visual meshes (the paper's numbers).
    pub visual_metrics: bool,
    /// Largest penetration between the visual meshes of different objects (m). The scene-aware
    /// decomposition cuts hulls apart even where the meshes overlap, so the meshes are gated too.
    pub max_visual_penetration: f64,
    /// The run-time nudge check: when one settle suggests its verdict may flip under a 0.5 mm /
    /// 0.5° nudge, settle the nudged starts too ([`nudge`]).
    pub nudge: nudge::NudgeOptions,
    /// What an undetermined verdict does to `passed` (the exit code, and whether `export`
    /// starts from the settled pose).
    pub undetermined: Undetermined,
}

/// What a gate does with an undetermined scene (its nudged verdicts split).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum Undetermined {
    /// It fails: a verdict a 0.5 mm / 0.5° nudge flips is not one to certify.
    Fail,
    /// It keeps the unnudged verdict, with a warning.
    Warn,
}

/// A scene's verdict: `undetermined` when the nudged starts of the run-time nudge check split.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    Pass,
    Fail,
    Undetermined,
}

impl Default for ValidateOptions {
    fn default() -> Self {
        ValidateOptions {
            metrics: MetricsOptions::default(),
            settle: SettleOptions::default(),
            max_collision_penetration: 1e-4,
            visual_metrics: true,
            max_visual_penetration: 1e-4,
            nudge: nudge::NudgeOptions::default(),
            undetermined: Undetermined::Warn,
        }
    }
}

/// The metrics of one pair of objects.
#[derive(Clone, Debug, Serialize)]
pub struct PairReport {
    pub a: String,
    pub b: String,
    /// On the visual meshes (absent with `visual_metrics` off).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub visual: Option<PairMetrics>,
    /// On the collision hulls (what the simulator sees).
    pub collision: PairMetrics,
}

/// One pass/fail check.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Check {
    /// `static_penetration`, `settle`, `rest`.
    pub name: String,
    /// The object (or `a/b` pair) it is about.
    pub subject: String,
    pub passed: bool,
    /// The measured value and its limit, in the check's unit (m, or deg, or a ratio).
    pub value: f64,
    pub limit: f64,
    pub message: String,
}

impl Check {
    /// A check that passes when `value` is at most `limit`.
    fn at_most(name: &str, subject: String, value: f64, limit: f64, message: String) -> Check {
        Check {
            name: name.into(),
            subject,
            passed: value <= limit,
            value,
            limit,
            message,
        }
    }
}

/// The validation of one scene.
#[derive(Clone, Debug, Serialize)]
pub struct Validation {
    /// The gate: the checks of the one settle, and, for an undetermined scene, what
    /// [`ValidateOptions::undetermined`] says.
    pub passed: bool,
    /// `pass` or `fail` by the one settle's checks, `undetermined` when the run-time nudge check
    /// ran and its verdicts split.
    pub verdict: Verdict,
    /// The run-time nudge check, when a signal fired.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nudge: Option<nudge::NudgeReport>,
    pub checks: Vec<Check>,
    pub pairs: Vec<PairReport>,
    pub settle: SettleReport,
    pub options: ValidateOptions,
    pub warnings: Vec<String>,
}

/// The bodies as the physics module takes them, at their initial poses (the composed pose for a
/// scene just built; the shipped, usually settled, pose for an export folder read back).
pub fn sim_bodies(a: &Assembly) -> Vec<SimBody> {
    a.bodies
        .iter()
        .map(|b| SimBody {
            name: b.name.clone(),
            pose: b.pose,
            hulls: b.hulls.iter().map(|h| h.mesh()).collect(),
            mass: b.inertial.mass,
            com: b.inertial.com,
            inertia: b.inertial.inertia,
            friction: b.friction,
            fixed: b.fixed,
        })
        .collect()
}

/// The Interact3D metrics of every pair, on the collision hulls and (with `visual_metrics`) on
/// the visual meshes, world frame at the composed pose; the two sets side by side.
fn static_metrics(
    a: &Assembly,
    opts: &ValidateOptions,
) -> (Vec<ScenePair>, Option<Vec<ScenePair>>) {
    rayon::join(
        || {
            let world_hulls: Vec<Vec<crate::mesh::Mesh>> = a
                .bodies
                .iter()
                .map(|b| b.world_hulls().iter().map(|h| h.mesh()).collect())
                .collect();
            scene_metrics(
                &world_hulls
                    .iter()
                    .map(|h| Solid::Hulls(h))
                    .collect::<Vec<_>>(),
                &opts.metrics,
            )
        },
        || {
            opts.visual_metrics.then(|| {
                let world: Vec<crate::mesh::Mesh> =
                    a.bodies.iter().map(|b| b.world_geometry()).collect();
                scene_metrics(
                    &world.iter().map(Solid::Mesh).collect::<Vec<_>>(),
                    &opts.metrics,
                )
            })
        },
    )
}

/// Run every check on an assembly.
pub fn validate(a: &Assembly, opts: &ValidateOptions) -> Result<Validation> {
    let mut warnings = Vec::new();
    // The static metrics and the settle are independent computations on the same bodies: run
    // side by side (the settle is one serial Rapier world; the metrics spread over the rest of
    // the pool). Each gives the bits it gives alone.
    let sims = sim_bodies(a);
    let ((collision, visual), settled) =
        rayon::join(|| static_metrics(a, opts), || settle(&sims, &opts.settle));
    let mut checks = Vec::new();
    let mut pairs = Vec::new();
    for (k, c) in collision.iter().enumerate() {
        let (na, nb) = (&a.bodies[c.a].name, &a.bodies[c.b].name);
        let v = visual.as_ref().map(|v| v[k].metrics);
        if let Some(v) = &v {
            let depth = v.max_penetration_depth;
            checks.push(Check::at_most(
                "visual_penetration",
                format!("{na}/{nb}"),
                depth,
                opts.max_visual_penetration,
                format!(
                    "visual meshes interpenetrate by {:.3} mm (R_volume {:.2e}, R_surface {:.2e}; limit {:.3} mm)",
                    depth * 1e3,
                    v.r_volume,
                    v.r_surface,
                    opts.max_visual_penetration * 1e3
                ),
            ));
        }
        let depth = c.metrics.max_penetration_depth;
        checks.push(Check::at_most(
            "static_penetration",
            format!("{na}/{nb}"),
            depth,
            opts.max_collision_penetration,
            format!(
                "collision hulls penetrate by {:.3} mm at the composed pose (limit {:.3} mm)",
                depth * 1e3,
                opts.max_collision_penetration * 1e3
            ),
        ));
        pairs.push(PairReport {
            a: na.clone(),
            b: nb.clone(),
            visual: v,
            collision: c.metrics,
        });
    }
    // Dynamics.
    let settle = settled.map_err(|e| Error::Input {
        path: a.name.clone().into(),
        message: format!("cannot simulate: {e}"),
    })?;
    // The nudge check only asks about the settle: a scene failing a static check (the checks so
    // far) fails anyway.
    let statics_pass = checks.iter().all(|c| c.passed);
    checks.extend(dynamic_checks(&settle, &opts.settle));
    warnings.extend(settle.warnings.iter().cloned());
    let unnudged = checks.iter().all(|c| c.passed) && settle.passed;
    let signals = if opts.nudge.enabled && statics_pass {
        nudge::signals(&settle, &opts.settle, &opts.nudge)
    } else {
        Vec::new()
    };
    let nudged = (!signals.is_empty()).then(|| {
        let mut which = vec![false; sims.len()];
        for (i, _) in &signals {
            which[*i] = true;
        }
        let verdicts = nudge::nudged_verdicts(&sims, &which, &opts.settle, opts.nudge.starts);
        nudge::NudgeReport {
            signals: signals.into_iter().map(|(_, why)| why).collect(),
            runs: verdicts.len(),
            passed: verdicts.iter().filter(|&&v| v).count(),
            verdicts,
        }
    });
    let (passed, verdict, warning) = nudge::gate(unnudged, nudged.as_ref(), opts.undetermined);
    warnings.extend(warning);
    Ok(Validation {
        passed,
        verdict,
        nudge: nudged,
        checks,
        pairs,
        settle,
        options: opts.clone(),
        warnings,
    })
}

/// Move every body to its settled pose (the composed pose is kept in `composed_pose`).
pub fn apply_settled_poses(a: &mut Assembly, v: &Validation) {
    for b in &mut a.bodies {
        if let Some(r) = v.settle.bodies.iter().find(|r| r.name == b.name) {
            if !b.fixed {
                b.pose = r.settled_pose.isometry();
            }
        }
    }
}

/// A compact table for people: object, moved, turned, penetration, verdict.
pub fn table(v: &Validation) -> String {
    let mut s = format!(
        "{:<20} {:>10} {:>10} {:>12}  verdict\n",
        "object", "moved mm", "turned °", "penetr. mm"
    );
    for b in &v.settle.bodies {
        let pen = v
            .pairs
            .iter()
            .filter(|p| p.a == b.name || p.b == b.name)
            .map(|p| p.collision.max_penetration_depth)
            .fold(b.rest_max_penetration, f64::max);
        let ok = v
            .checks
            .iter()
            .filter(|c| c.subject == b.name || c.subject.split('/').any(|x| x == b.name))
            .all(|c| c.passed);
        s += &format!(
            "{:<20} {:>10.3} {:>10.2} {:>12.3}  {}\n",
            b.name,
            (b.settle_displacement + b.rest_displacement) * 1e3,
            b.settle_rotation_deg + b.rest_rotation_deg,
            pen * 1e3,
            if b.fixed {
                "fixed"
            } else if ok {
                "pass"
            } else {
                "FAIL"
            }
        );
    }
    for c in v.checks.iter().filter(|c| !c.passed) {
        s += &format!("  FAIL {} {}: {}\n", c.name, c.subject, c.message);
    }
    s += &format!("verdict: {}\n", verdict_line(v));
    s
}

/// The verdict in words: `PASS`, `FAIL`, or `UNDETERMINED (k of n nudged starts pass): PASS|FAIL`
/// (the gate's outcome after [`ValidateOptions::undetermined`]).
pub fn verdict_line(v: &Validation) -> String {
    let gate = if v.passed { "PASS" } else { "FAIL" };
    match (&v.verdict, &v.nudge) {
        (Verdict::Undetermined, Some(n)) => format!(
            "UNDETERMINED ({} of {} nudged starts pass): {gate}",
            n.passed, n.runs
        ),
        _ => gate.into(),
    }
}

/// JUnit XML, one test case per check (for CI systems).
pub fn junit(scene: &str, v: &Validation) -> String {
    let esc = |s: &str| {
        s.replace('&', "&amp;")
            .replace('<', "&lt;")
            .replace('>', "&gt;")
            .replace('"', "&quot;")
    };
    let failures = v.checks.iter().filter(|c| !c.passed).count();
    let mut s = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites>\n  <testsuite name=\"{}\" tests=\"{}\" failures=\"{failures}\">\n",
        esc(scene),
        v.checks.len()
    );
    for c in &v.checks {
        s += &format!(
            "    <testcase classname=\"{}.{}\" name=\"{}\">",
            esc(scene),
            esc(&c.name),
            esc(&c.subject)
        );
        if !c.passed {
            s += &format!(
                "<failure message=\"{}\">value {} limit {}</failure>",
                esc(&c.message),
                c.value,
                c.limit
            );
        }
        s += "</testcase>\n";
    }
    s += "  </testsuite>\n</testsuites>\n";
    s
}

/// The settle and rest checks of every dynamic body of a settle report.
pub fn dynamic_checks(settle: &SettleReport, s: &crate::physics::SettleOptions) -> Vec<Check> {
    let mut checks = Vec::new();
    for b in &settle.bodies {
        if b.fixed {
            continue;
        }
        let settle_ok = b.relative_drift <= s.max_relative_drift
            && b.settle_shape_shift
                .is_none_or(|shift| shift <= s.max_relative_drift * b.bbox_diagonal)
            && !b.left_supports
            && !b.ended_on_floor;
        let settle_reasons: Vec<&String> = b
            .reasons
            .iter()
            .filter(|r| !r.contains("rest check"))
            .collect();
        checks.push(Check {
            name: "settle".into(),
            subject: b.name.clone(),
            passed: settle_ok && b.initial_penetration <= s.max_initial_penetration,
            value: b.settle_displacement,
            limit: s.max_relative_drift * b.bbox_diagonal,
            message: if settle_reasons.is_empty() {
                format!(
                    "moved {:.3} mm, turned {:.2}° while settling",
                    b.settle_displacement * 1e3,
                    b.settle_rotation_deg
                )
            } else {
                settle_reasons
                    .iter()
                    .map(|r| r.as_str())
                    .collect::<Vec<_>>()
                    .join("; ")
            },
        });
        // A body the creep rule let through (physics::creep) has no "rest check" reason.
        let crept = b
            .creep_imbalance
            .is_some_and(|r| r <= s.creep_max_imbalance);
        let rest_ok = ((b.rest_displacement <= s.max_rest_motion
            && b.rest_rotation_deg <= s.max_rest_rotation_deg)
            || crept)
            && b.rest_max_penetration <= s.max_rest_penetration;
        checks.push(Check {
            name: "rest".into(),
            subject: b.name.clone(),
            passed: rest_ok,
            value: b.rest_displacement,
            limit: s.max_rest_motion,
            message: match b
                .reasons
                .iter()
                .filter(|r| r.contains("rest check"))
                .cloned()
                .collect::<Vec<_>>()
            {
                r if !r.is_empty() => r.join("; "),
                _ => format!(
                    "at rest: moved {:.3} mm, turned {:.3}°, contact penetration {:.3} mm",
                    b.rest_displacement * 1e3,
                    b.rest_rotation_deg,
                    b.rest_max_penetration * 1e3
                ),
            },
        });
    }
    checks
}
