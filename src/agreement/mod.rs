//! Cross-engine rest agreement (issue #33): does a rest pose we export stay a rest pose in
//! another engine? A seeded generator composes random resting scenes from a folder of real
//! objects (`../shared/datasets/objects`: an item in or on a container or support, on another
//! item, or on the floor; random yaw, a small random tilt), settles them in Rapier with the
//! validator, exports them, and an independent engine (MuJoCo, through
//! `tests/python/agreement_mujoco.py`) judges the same files.
//!
//! Entry points: [`Catalog::load`] (objects decomposed once each, through the content-addressed
//! decomposition cache), [`Catalog::compose`] (one seeded scene), [`run_scene`] (settle +
//! export), [`judge`] (the MuJoCo side, in [`judge`]), [`summary`], [`nudge::spread`] (our
//! verdict over nudged composed poses: is a disagreement within our own spread?).
//!
//! Definitions (what the table counts):
//! - **verdict**: our validator's pass/fail against MuJoCo's, where MuJoCo's scene verdict is
//!   the settle test's own rule replayed from the composed pose ([`judge::RULES`]);
//! - **rest**: every body of a scene we pass stays within 1 mm and 1° for 2 s in MuJoCo,
//!   started from the exported (settled) pose.

pub mod judge;
pub mod nudge;
mod place;

use crate::body::{build, Assembly, Body, BuildOptions};
use crate::error::{Error, Result};
use crate::io::Limits;
use crate::rng::Rng;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

pub use judge::{judge, summary, Judged, Summary};
pub use place::Placer;

/// What an object is for, from the dataset's `index.json`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    Container,
    Support,
    Item,
}

/// One object, decomposed once, resting upright on the floor at the origin (body frame at its
/// centre of mass, axes world-aligned).
#[derive(Clone, Debug)]
pub struct CatalogObject {
    pub id: String,
    pub role: Role,
    pub body: Body,
}

/// The objects scenes are drawn from.
pub struct Catalog {
    pub objects: Vec<CatalogObject>,
    placer: Placer,
    decomposer: String,
}

#[derive(Deserialize)]
struct IndexEntry {
    id: String,
    role: Role,
    mesh: String,
}

/// How a generated scene is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// An item dropped into or onto a container or support.
    OnSupport,
    /// An item on another item on the floor.
    OnItem,
    /// An item on the floor.
    OnFloor,
}

/// A generated scene: which objects, how they were placed.
#[derive(Clone, Debug, Serialize)]
pub struct Generated {
    pub seed: u64,
    pub kind: Kind,
    /// Catalog ids, bottom first.
    pub objects: Vec<String>,
    /// Tilt of the top item from its upright pose (degrees).
    pub tilt_deg: f64,
    #[serde(skip)]
    pub assembly: Assembly,
}

/// Largest tilt (degrees) of a placed item from its upright pose: items rest upright in the
/// dataset, and a few degrees is what a composer's error leaves.
pub const MAX_TILT_DEG: f64 = 8.0;
/// Vertical gap (m) left under a placed item: it drops onto its support.
pub const DROP_GAP: f64 = 5e-4;

impl Catalog {
    /// Read `dir/index.json` and decompose each object alone (ids filtered by `keep` when
    /// given). Decompositions are cached in `cache` by content, so a second run costs reading.
    pub fn load(dir: &Path, keep: Option<&[&str]>, cache: Option<PathBuf>) -> Result<Catalog> {
        Catalog::load_with(dir, keep, cache, usize::MAX)
    }

    /// [`Catalog::load`] with a polygon budget per hull (`export --max-hull-polygons`;
    /// `usize::MAX`: none): the hulls a user exporting for Isaac/PhysX gets
    /// ([`crate::decompose::PHYSX_MAX_POLYGONS`]), so the PhysX judge sees what PhysX cooks as
    /// written instead of hulls it re-cooks smaller.
    pub fn load_with(
        dir: &Path,
        keep: Option<&[&str]>,
        cache: Option<PathBuf>,
        max_polygons: usize,
    ) -> Result<Catalog> {
        let index = dir.join("index.json");
        let bytes = std::fs::read(&index).map_err(|e| Error::input(&index, e.to_string()))?;
        let entries: Vec<IndexEntry> =
            serde_json::from_slice(&bytes).map_err(|e| Error::input(&index, e.to_string()))?;
        let mut opts = BuildOptions::default();
        opts.decompose.cache_dir = cache;
        opts.decompose.max_polygons = max_polygons;
        let limits = Limits::default();
        let mut objects = Vec::new();
        let mut decomposer = String::new();
        for e in entries {
            if keep.is_some_and(|k| !k.contains(&e.id.as_str())) {
                continue;
            }
            let scene = crate::scene::single_mesh(&dir.join(&e.mesh), &limits)?;
            let mut a = build(&scene, &opts)?;
            decomposer = a.decomposer.clone();
            let mut body = a.bodies.remove(0);
            // Cheap exports: the judge needs the collision hulls, not 4096² textures.
            for p in &mut body.visual.parts {
                p.material.texture = None;
                p.uvs = None;
            }
            let lowest = lowest_z(&body, &UnitQuaternion::identity());
            body.pose = Isometry3::translation(0.0, 0.0, -lowest);
            body.composed_pose = body.pose;
            objects.push(CatalogObject {
                id: e.id,
                role: e.role,
                body,
            });
        }
        if objects.is_empty() {
            return Err(Error::input(&index, "no objects selected"));
        }
        let placer = Placer::new(&objects);
        Ok(Catalog {
            objects,
            placer,
            decomposer,
        })
    }

    fn pick(&self, rng: &mut Rng, roles: &[Role]) -> Option<usize> {
        let ks: Vec<usize> = (0..self.objects.len())
            .filter(|&k| roles.contains(&self.objects[k].role))
            .collect();
        (!ks.is_empty()).then(|| ks[rng.below(ks.len())])
    }

    /// The scene of one seed (same seed, same scene).
    pub fn compose(&self, seed: u64) -> Generated {
        let mut rng = Rng::new(seed);
        let r = rng.next_f64();
        let item = self.pick(&mut rng, &[Role::Item]);
        let support = self.pick(&mut rng, &[Role::Container, Role::Support]);
        let (kind, stack) = match (item, support) {
            (Some(i), Some(s)) if r < 0.5 => (Kind::OnSupport, vec![s, i]),
            (Some(i), _) if r < 0.75 => {
                let j = self.pick(&mut rng, &[Role::Item]).unwrap_or(i);
                (Kind::OnItem, vec![j, i])
            }
            (Some(i), _) => (Kind::OnFloor, vec![i]),
            (None, Some(s)) => (Kind::OnFloor, vec![s]),
            (None, None) => unreachable!("a catalog is never empty"),
        };
        let mut bodies: Vec<Body> = Vec::new();
        let mut placed: Vec<(usize, Isometry3<f64>)> = Vec::new();
        let mut tilt_deg = 0.0;
        for (level, &k) in stack.iter().enumerate() {
            let o = &self.objects[k];
            let yaw = UnitQuaternion::from_axis_angle(
                &Vector3::z_axis(),
                rng.range(0.0, 360.0).to_radians(),
            );
            let top = level + 1 == stack.len();
            let tilt = if top && level > 0 || stack.len() == 1 {
                let t = rng.range(0.0, MAX_TILT_DEG);
                let phi = rng.range(0.0, 2.0 * std::f64::consts::PI);
                let axis = nalgebra::Unit::new_normalize(Vector3::new(phi.cos(), phi.sin(), 0.0));
                tilt_deg = t;
                UnitQuaternion::from_axis_angle(&axis, t.to_radians())
            } else {
                UnitQuaternion::identity()
            };
            let rot = tilt * yaw;
            // Over the body below: its centre, shifted by up to a quarter of its extents.
            let (x, y) = match placed.last() {
                Some((below, pose)) => {
                    let e = self.objects[*below]
                        .body
                        .geometry
                        .aabb()
                        .map(|b| b.extents());
                    let e = e.unwrap_or_default();
                    (
                        pose.translation.x + rng.range(-0.25, 0.25) * e.x,
                        pose.translation.y + rng.range(-0.25, 0.25) * e.y,
                    )
                }
                None => (0.0, 0.0),
            };
            let z = self.placer.drop_height(k, &rot, x, y, &placed) + DROP_GAP;
            let pose = Isometry3::from_parts(Translation3::new(x, y, z), rot);
            placed.push((k, pose));
            let mut b = o.body.clone();
            b.name = format!(
                "b{level}_{}",
                crate::scene::sanitize_name(o.id.rsplit('/').next().unwrap_or(&o.id))
            );
            b.pose = pose;
            b.composed_pose = pose;
            bodies.push(b);
        }
        let objects = stack.iter().map(|&k| self.objects[k].id.clone()).collect();
        Generated {
            seed,
            kind,
            objects,
            tilt_deg,
            assembly: Assembly {
                name: format!("agreement_{seed}"),
                bodies,
                decomposer: self.decomposer.clone(),
                scene_to_world: crate::pose::Similarity::identity(),
                warnings: Vec::new(),
            },
        }
    }
}

/// Lowest z of a body's hulls turned by `rot` about its centre of mass.
fn lowest_z(b: &Body, rot: &UnitQuaternion<f64>) -> f64 {
    b.hulls
        .iter()
        .flat_map(|h| h.vertices.iter())
        .map(|v| (rot * v).z)
        .fold(f64::INFINITY, f64::min)
}

/// Bounding-box diagonal of a body's hulls (the settle test's size).
pub fn diagonal(b: &Body) -> f64 {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for v in b.hulls.iter().flat_map(|h| h.vertices.iter()) {
        lo = lo.inf(&v.coords);
        hi = hi.sup(&v.coords);
    }
    (hi - lo).norm()
}

/// Our side of one scene: validated (settle + rest in Rapier), exported to `out`.
#[derive(Clone, Debug, Serialize)]
pub struct Ours {
    pub passed: bool,
    /// `pass`, `fail`, or `undetermined` (the run-time nudge check's verdicts split).
    pub verdict: crate::validate::Verdict,
    /// The run-time nudge check, when it ran: (starts that passed, starts).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nudged: Option<(usize, usize)>,
    /// Failed checks and body reasons, when it failed.
    pub reasons: Vec<String>,
    /// Wall time of the validation (s).
    pub seconds: f64,
    /// Bodies: name, bounding-box diagonal (m), marginal by our probe.
    pub bodies: Vec<OurBody>,
    /// Bodies whose contact islands ran the loaded solver iterations
    /// ([`crate::physics::SettleOptions::load_ratio`]); empty: the scene ran the plain solver.
    pub heavily_loaded: Vec<String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct OurBody {
    pub name: String,
    pub diagonal: f64,
    pub rest_displacement: f64,
    pub rest_rotation_deg: f64,
    /// Deepest exact contact penetration during our rest phase, which starts from the
    /// exported (settled) pose (m): what another engine starting there must push out.
    pub rest_max_penetration: f64,
    pub marginal: bool,
}

/// Validate a generated scene as `export` does (static collision penetration + settle test;
/// the visual-mesh metrics are left out since no engine sees visual meshes) and export it.
pub fn run_scene(g: &Generated, out: &Path) -> Result<Ours> {
    run_scene_with(g, out, &crate::physics::SettleOptions::default())
}

/// [`run_scene`] with other settle options (experiments on the settle test).
pub fn run_scene_with(
    g: &Generated,
    out: &Path,
    settle: &crate::physics::SettleOptions,
) -> Result<Ours> {
    let mut a = g.assembly.clone();
    // The nudge check is on here (it is off by default): the harness reports which verdicts
    // are undetermined beside the strict agreement.
    let opts = crate::validate::ValidateOptions {
        visual_metrics: false,
        settle: settle.clone(),
        nudge: crate::validate::nudge::NudgeOptions {
            enabled: true,
            ..Default::default()
        },
        ..Default::default()
    };
    let t = std::time::Instant::now();
    let v = crate::validate::validate(&a, &opts)?;
    let seconds = t.elapsed().as_secs_f64();
    let mut report = crate::report::Report::new(&a);
    if v.passed {
        crate::validate::apply_settled_poses(&mut a, &v);
    }
    report.validation = Some(serde_json::to_value(&v).map_err(|e| Error::Internal(e.to_string()))?);
    crate::export::export(
        &a,
        &report,
        out,
        &crate::export::ExportOptions {
            templates: None,
            force: true,
        },
    )?;
    let mut reasons: Vec<String> = v
        .checks
        .iter()
        .filter(|c| !c.passed)
        .map(|c| format!("{} {}: {}", c.name, c.subject, c.message))
        .collect();
    for b in &v.settle.bodies {
        reasons.extend(b.reasons.iter().map(|r| format!("{}: {r}", b.name)));
    }
    let nudged = v.nudge.as_ref().map(|n| (n.passed, n.runs));
    let bodies = a
        .bodies
        .iter()
        .map(|b| {
            let r = v.settle.bodies.iter().find(|r| r.name == b.name);
            OurBody {
                name: b.name.clone(),
                diagonal: diagonal(b),
                rest_displacement: r.map(|r| r.rest_displacement).unwrap_or(0.0),
                rest_rotation_deg: r.map(|r| r.rest_rotation_deg).unwrap_or(0.0),
                rest_max_penetration: r.map(|r| r.rest_max_penetration).unwrap_or(0.0),
                marginal: r.map(|r| r.marginal).unwrap_or(false),
            }
        })
        .collect();
    Ok(Ours {
        passed: v.passed,
        verdict: v.verdict,
        nudged,
        reasons,
        seconds,
        bodies,
        heavily_loaded: v.settle.heavily_loaded.clone(),
    })
}
