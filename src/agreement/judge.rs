//! The other engine's side: `tests/python/agreement_mujoco.py` replays every exported scene in
//! MuJoCo (`scene.xml`), `tests/python/agreement_physx.py` in PhysX (`scene.usda`, ovphysx on
//! the CPU), one process for a batch, and this module compares their answers with ours.
//!
//! The engine's scene verdict ([`RULES`]) is the settle test's rule replayed from the composed
//! pose (MJCF keyframe `composed`; the USD's `customData` composed pose): after as long as our
//! settle phase may take (`SettleOptions::settle_max_time`, 6 s) every free body's centre of
//! mass has moved at most 10 % of its bounding-box diagonal, and over the next 1 s it moves at
//! most 1 mm and turns at most 1°. The engine gets the same settle time as Rapier: with 2 s, a
//! soup can MuJoCo was still rocking and a spoon still sliding into a mug counted as failures
//! where both come to rest (seeds 83 and 93 of 0..300; docs/agreement.md). The engine's rest answer: from the exported
//! (settled) pose, every body stays within 1 mm and 1° for 2 s.
//!
//! Entry points: [`judge`], [`Judge`] (`run` with another settle time, `nudged`: the engine's
//! verdict from our nudged composed poses as well, PhysX only), [`summary`].

use super::{Generated, Ours};
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The engine's verdict rule, as written into the results.
pub const RULES: &str = "from the composed pose: COM drift <= 10% of the bbox diagonal after the settle cap (6 s) and no turn > 30 deg that moves the shape by > 10% of the diagonal, then <= 1 mm and <= 1 deg over 1 s; rest: <= 1 mm and <= 1 deg for 2 s from the settled pose";
/// Rest agreement thresholds.
pub const REST_MM: f64 = 1.0;
pub const REST_DEG: f64 = 1.0;

/// What the engine reported on one body.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MjBody {
    /// Composed-pose run: COM drift after the settle part (m), then the rest part's worst
    /// displacement (m) and turn (degrees).
    pub settle_m: f64,
    /// Turn over the settle part (degrees) and the orientations it went between (w, x, y, z).
    #[serde(default)]
    pub settle_deg: f64,
    #[serde(default)]
    pub settle_q0: Option<[f64; 4]>,
    #[serde(default)]
    pub settle_q1: Option<[f64; 4]>,
    /// The settle test's large-turn rule applied to that turn: how far it moved the body's
    /// shape (m), when the turn passed the limit (filled in here, not by the script).
    #[serde(default)]
    pub settle_shape_shift: Option<f64>,
    pub rest_m: f64,
    pub rest_deg: f64,
    /// Settled-pose run: worst displacement (m) and turn (degrees) over 2 s.
    pub from_settled_m: f64,
    pub from_settled_deg: f64,
}

/// What the engine reported on one scene.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MjScene {
    pub dir: PathBuf,
    pub passed: bool,
    pub finite: bool,
    pub bodies: BTreeMap<String, MjBody>,
    pub seconds: f64,
    /// The engine's own verdict from the composed pose nudged as our validator nudges it
    /// (`validate::nudge::nudged_poses`' starts and order), when asked ([`Judge::nudged`]).
    #[serde(default)]
    pub nudged: Option<Vec<bool>>,
}

/// One scene, both engines.
#[derive(Clone, Debug, Serialize)]
pub struct Judged {
    /// The other engine's name (`MuJoCo`, `PhysX`).
    pub engine: String,
    pub seed: u64,
    pub kind: super::Kind,
    pub objects: Vec<String>,
    pub tilt_deg: f64,
    pub ours: Ours,
    pub mujoco: MjScene,
    pub verdict_agrees: bool,
    /// `None` when we fail the scene (no rest pose claimed).
    pub rest_agrees: Option<bool>,
    /// Bodies of a scene we pass (marginal ones included) that the engine moves past 1 mm / 1°
    /// (name, mm, degrees).
    pub rest_drifts: Vec<(String, f64, f64)>,
    /// Our own honesty flag: the scene had a body our probe calls marginal.
    pub marginal: bool,
}

/// Run a judge script (`engine` names it in causes) on exported scenes (`scenes[i].2` holds
/// the export of `scenes[i].0`), the engine's settle part as long as ours by default.
pub fn judge(
    engine: &str,
    python: &str,
    script: &Path,
    scenes: &[(Generated, Ours, PathBuf)],
) -> Result<Vec<Judged>> {
    Judge::new(engine, python, script).run(scenes)
}

/// A judge script and how it runs: `engine` names it in causes, `python` runs `script`, and
/// the engine's settle part lasts `settle_s` seconds (our settle cap, when experiments change
/// it).
#[derive(Clone, Copy, Debug)]
pub struct Judge<'a> {
    pub engine: &'a str,
    pub python: &'a str,
    pub script: &'a Path,
    pub settle_s: f64,
}

impl<'a> Judge<'a> {
    /// The judge with our default settle cap ([`crate::physics::SettleOptions`]).
    pub fn new(engine: &'a str, python: &'a str, script: &'a Path) -> Self {
        Judge {
            engine,
            python,
            script,
            settle_s: crate::physics::SettleOptions::default().settle_max_time,
        }
    }

    /// The engine's answers on exported scenes (`scenes[i].2` holds the export of
    /// `scenes[i].0`).
    pub fn run(&self, scenes: &[(Generated, Ours, PathBuf)]) -> Result<Vec<Judged>> {
        run_judge(self, scenes, false)
    }

    /// [`Judge::run`], and the engine's verdict from every nudged composed pose as well
    /// ([`MjScene::nudged`]; 8 more runs a free body: for verdict disagreements, to tell a
    /// verdict the engine itself flips under a 0.5 mm / 0.5° nudge from one it holds). Only
    /// the PhysX script answers it.
    pub fn nudged(&self, scenes: &[(Generated, Ours, PathBuf)]) -> Result<Vec<Judged>> {
        run_judge(self, scenes, true)
    }
}

fn run_judge(j: &Judge, scenes: &[(Generated, Ours, PathBuf)], nudge: bool) -> Result<Vec<Judged>> {
    let Judge {
        engine,
        python,
        script,
        settle_s,
    } = *j;
    let list: Vec<serde_json::Value> = scenes
        .iter()
        .map(|(_, o, d)| {
            let mut e = serde_json::json!({
                "dir": d,
                "diagonals": o.bodies.iter().map(|b| (b.name.clone(), b.diagonal)).collect::<BTreeMap<_, _>>(),
                "settled": o.passed,
                "settle_s": settle_s,
            });
            if nudge {
                e["nudge"] = true.into();
            }
            e
        })
        .collect();
    let input = std::env::temp_dir().join(format!(
        "interact3d-agreement-{}-{}.json",
        std::process::id(),
        scenes.first().map(|s| s.0.seed).unwrap_or(0)
    ));
    std::fs::write(&input, serde_json::to_vec(&list).unwrap_or_default())
        .map_err(|e| Error::input(&input, e.to_string()))?;
    let out = std::process::Command::new(python)
        .arg(script)
        .arg(&input)
        .output()
        .map_err(|e| Error::input(script, format!("cannot run {python}: {e}")))?;
    let _ = std::fs::remove_file(&input);
    if !out.status.success() {
        return Err(Error::input(
            script,
            format!("judge failed: {}", String::from_utf8_lossy(&out.stderr)),
        ));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let results: Vec<MjScene> = text
        .lines()
        .filter(|l| l.starts_with('{'))
        .map(serde_json::from_str)
        .collect::<std::result::Result<_, _>>()
        .map_err(|e| Error::input(script, format!("judge output: {e}")))?;
    if results.len() != scenes.len() {
        return Err(Error::input(
            script,
            format!(
                "judge answered {} of {} scenes",
                results.len(),
                scenes.len()
            ),
        ));
    }
    Ok(scenes
        .iter()
        .zip(results)
        .map(|((g, ours, _), mj)| compare(engine, g, ours, mj))
        .collect())
}

/// The settle test's large-turn rule on the engine's settle part: a body that turned more than
/// the limit fails when the turn moved its shape by more than the drift limit (a pen rolling
/// about its own axis does not). The scripts report the turn; the hulls are here.
fn large_turns(g: &Generated, ours: &Ours, mj: &mut MjScene) {
    let o = crate::physics::SettleOptions::default();
    let sims = crate::validate::sim_bodies(&g.assembly);
    let quat = |q: [f64; 4]| {
        nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]))
    };
    for (name, b) in mj.bodies.iter_mut() {
        let (Some(q0), Some(q1)) = (b.settle_q0, b.settle_q1) else {
            continue;
        };
        if b.settle_deg <= o.max_settle_rotation_deg {
            continue;
        }
        let (Some(sim), Some(ob)) = (
            sims.iter().find(|s| &s.name == name),
            ours.bodies.iter().find(|s| &s.name == name),
        ) else {
            continue;
        };
        if let Ok(shift) = crate::physics::shape_shift(sim, &quat(q0), &quat(q1)) {
            b.settle_shape_shift = Some(shift);
            if shift > o.max_relative_drift * ob.diagonal {
                mj.passed = false;
            }
        }
    }
}

fn compare(engine: &str, g: &Generated, ours: &Ours, mut mj: MjScene) -> Judged {
    large_turns(g, ours, &mut mj);
    let mut rest_drifts = Vec::new();
    if ours.passed {
        // Every body of a scene we pass counts, marginal or not: export ships that pose either
        // way (the marginal flag is only a warning; the summary counts how well it predicts).
        for b in &ours.bodies {
            if let Some(m) = mj.bodies.get(&b.name) {
                let (mm, deg) = (m.from_settled_m * 1e3, m.from_settled_deg);
                if !(mm <= REST_MM && deg <= REST_DEG) {
                    rest_drifts.push((b.name.clone(), mm, deg));
                }
            }
        }
    }
    Judged {
        engine: engine.to_string(),
        seed: g.seed,
        kind: g.kind,
        objects: g.objects.clone(),
        tilt_deg: g.tilt_deg,
        verdict_agrees: ours.passed == mj.passed,
        rest_agrees: ours.passed.then_some(rest_drifts.is_empty()),
        rest_drifts,
        marginal: ours.bodies.iter().any(|b| b.marginal),
        ours: ours.clone(),
        mujoco: mj,
    }
}

/// Totals over a run.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Summary {
    pub scenes: usize,
    pub we_pass: usize,
    pub mujoco_pass: usize,
    pub verdict_agree: usize,
    /// Scenes whose verdict is undetermined (our run-time nudge check split; they stay in
    /// `scenes` and `verdict_agree` with their gate verdict, `passed`).
    pub undetermined: usize,
    /// Of the other (determined) scenes, those whose verdict agrees.
    pub determined_agree: usize,
    pub rest_judged: usize,
    pub rest_agree: usize,
    pub marginal: usize,
    /// Bodies of scenes we pass that our probe calls marginal, and how many of them the engine
    /// moved past 1 mm / 1° from the exported pose; the same for the bodies it calls stable.
    pub marginal_bodies: usize,
    pub marginal_bodies_moved: usize,
    pub stable_bodies: usize,
    pub stable_bodies_moved: usize,
    /// Disagreements by cause (a short key: direction and what moved).
    pub causes: BTreeMap<String, usize>,
    /// Mean and worst settle (validation) time per scene (s).
    pub settle_mean_s: f64,
    pub settle_worst_s: f64,
    /// Mean and worst cross-engine drift (mm, degrees) of bodies we call at rest.
    pub drift_mean_mm: f64,
    pub drift_worst_mm: f64,
    pub drift_mean_deg: f64,
    pub drift_worst_deg: f64,
}

/// A short name of why a scene disagrees (empty when it agrees).
pub fn cause(j: &Judged) -> Option<String> {
    if !j.verdict_agrees {
        return Some(if j.ours.passed {
            let worst = j
                .mujoco
                .bodies
                .iter()
                .map(|(n, b)| (n, b.rest_m.max(b.settle_m)))
                .max_by(|a, b| a.1.total_cmp(&b.1));
            format!(
                "verdict: we pass, {} fails ({:?}; {})",
                j.engine,
                j.kind,
                worst.map(|w| w.0.as_str()).unwrap_or("?")
            )
        } else {
            let first: String = j
                .ours
                .reasons
                .first()
                .map(|r| {
                    r.split(':')
                        .nth(1)
                        .unwrap_or(r)
                        .trim()
                        .chars()
                        .take(40)
                        .collect()
                })
                .unwrap_or_default();
            format!(
                "verdict: we fail, {} passes ({:?}; {first})",
                j.engine, j.kind
            )
        });
    }
    if j.rest_agrees == Some(false) {
        let (name, _, _) = &j.rest_drifts[0];
        return Some(format!("rest: {name} moves in {} ({:?})", j.engine, j.kind));
    }
    None
}

/// Totals of judged scenes.
pub fn summary(js: &[Judged]) -> Summary {
    let mut s = Summary {
        scenes: js.len(),
        ..Default::default()
    };
    let mut drift_mm = Vec::new();
    let mut drift_deg = Vec::new();
    for j in js {
        s.we_pass += j.ours.passed as usize;
        s.mujoco_pass += j.mujoco.passed as usize;
        s.verdict_agree += j.verdict_agrees as usize;
        if j.ours.verdict == crate::validate::Verdict::Undetermined {
            s.undetermined += 1;
        } else {
            s.determined_agree += j.verdict_agrees as usize;
        }
        s.marginal += j.marginal as usize;
        if let Some(a) = j.rest_agrees {
            s.rest_judged += 1;
            s.rest_agree += a as usize;
            for b in &j.ours.bodies {
                if let Some(m) = j.mujoco.bodies.get(&b.name) {
                    drift_mm.push(m.from_settled_m * 1e3);
                    drift_deg.push(m.from_settled_deg);
                    let moved = j.rest_drifts.iter().any(|d| d.0 == b.name) as usize;
                    if b.marginal {
                        s.marginal_bodies += 1;
                        s.marginal_bodies_moved += moved;
                    } else {
                        s.stable_bodies += 1;
                        s.stable_bodies_moved += moved;
                    }
                }
            }
        }
        if let Some(c) = cause(j) {
            *s.causes.entry(c).or_default() += 1;
        }
        s.settle_mean_s += j.ours.seconds / js.len().max(1) as f64;
        s.settle_worst_s = s.settle_worst_s.max(j.ours.seconds);
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let worst = |v: &[f64]| v.iter().cloned().fold(0.0, f64::max);
    s.drift_mean_mm = mean(&drift_mm);
    s.drift_worst_mm = worst(&drift_mm);
    s.drift_mean_deg = mean(&drift_deg);
    s.drift_worst_deg = worst(&drift_deg);
    s
}
