//! `compose`: the Interact3D registration pipeline on a CPU, without learned weights.
//!
//! Each high-quality object mesh (its own frame) is registered onto its guidance part, a
//! segment of a generated scene mesh with holes and artefacts (guidance frame):
//!
//! 1. anchor: the object whose guidance part has the larger silhouette (front view, along −Z of
//!    the Y-up guidance frame), unless named;
//! 2. scale initialised from the ratio of sorted OBB extents ([`obb`]);
//! 3. global registration ([`global`]): hypotheses from the 24 OBB axis permutations and from
//!    FPFH + RANSAC ([`features`]), each refined by a short trimmed ICP and scored (colour-
//!    weighted when both meshes carry colour, [`colour`]);
//! 4. scale-aware trimmed ICP with Umeyama and a bounded scale ([`icp`]), on the guidance part
//!    without the placed objects' surface (segmentation bleed, [`bleed`]);
//!    for an elongated object with colour, the size its colour along the long axis gives,
//!    kept only when the guard finds it fits not worse ([`colour_axis`]);
//! 5. an item's size from its resting contact ([`contact_scale`]; optionally first among
//!    resting poses, [`support`], off by default); the colour's refused size taken where the
//!    item floats and that size rests ([`colour_rest`]);
//! 6. collision-aware refinement of every further object against the fixed, already composed
//!    objects' signed distance field ([`sdf`], [`refine`](mod@refine)); objects are added one
//!    at a time, the composed scene becoming the new anchor.
//!
//! Everything is deterministic for a seed. [`synth`] makes guidance parts from ground-truth
//! scenes for tests and the benchmark; [`folder`] reads sample folders and writes the output.

pub mod agent;
pub mod bleed;
pub mod cloud;
pub mod colour;
pub mod colour_axis;
pub mod colour_rest;
pub mod contact_scale;
pub mod features;
pub mod folder;
pub mod global;
pub mod guard;
pub mod icp;
pub mod kdtree;
pub mod obb;
pub mod occlusion;
pub mod placed;
pub mod plane_icp;
pub mod realistic;
pub mod reconstruction;
pub mod refine;
pub mod rest;
pub mod scale;
pub mod sdf;
mod silhouette;
pub mod support;
pub mod sweep;
pub mod synth;

use crate::error::{Error, Result};
use crate::mesh::{Mesh, VisualMesh, P3};
use crate::pose::Similarity;
use cloud::Cloud;
use global::{best_hypothesis, FpfhRansac, GlobalRegistration, ObbHypotheses, Problem};
use icp::{trimmed_icp, IcpOptions};
pub use silhouette::silhouette_area;

/// Weight of a unit of (gain-normalised) colour difference in colour-aware correspondences, as a
/// fraction of the object's diagonal.
pub const COLOUR_WEIGHT: f64 = 0.1;

/// Largest normal offset of a guidance part the offset fit takes out, as a fraction of the
/// object's diagonal (the bench's reconstructions fatten or erode by up to 1.2 %).
const OFFSET_MAX: f64 = 0.03;

/// The offset is fitted only on shapes where it can be told apart from scale: a squared
/// correlation of the two estimates below this ([`plane_icp::scale_offset_correlation`]; 1 for
/// a sphere or a cube, 0.79 for a 1 × 0.6 × 0.3 box). On a rounded cube (the die) the blur's
/// rounding of its edges reads as a smaller cube fattened, and the fit shrank it by 4–7 %.
const OFFSET_CORRELATION_MAX: f64 = 0.85;
use kdtree::KdTree;
use obb::Obb;
use occlusion::Occlusion;
use placed::{Item, Placed};
use refine::{refine, RefineOptions, Refined, Target};
use sdf::AnchorField;
use serde::Serialize;

/// Which stages run (the rows of the ablation table).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// OBB alignment (one hypothesis, no permutations) + ICP.
    IcpOnly,
    /// FPFH + RANSAC (its best pose) + ICP.
    RansacIcp,
    /// All hypotheses (OBB permutations + RANSAC), scored, + ICP.
    GlobalIcp,
    /// Global + ICP + collision-aware refinement.
    Full,
    /// Full, with colour in the hypothesis score when both meshes carry colour.
    FullColour,
}

impl Method {
    pub const ALL: [Method; 5] = [
        Method::IcpOnly,
        Method::RansacIcp,
        Method::GlobalIcp,
        Method::Full,
        Method::FullColour,
    ];
    pub fn label(&self) -> &'static str {
        match self {
            Method::IcpOnly => "ICP only",
            Method::RansacIcp => "RANSAC+ICP",
            Method::GlobalIcp => "global+ICP",
            Method::Full => "full",
            Method::FullColour => "full + colour",
        }
    }
    fn refines(&self) -> bool {
        matches!(self, Method::Full | Method::FullColour)
    }
}

/// Options of the pipeline.
#[derive(Clone, Debug)]
pub struct ComposeOptions {
    pub method: Method,
    pub seed: u64,
    /// Anchor object by name (default: the larger guidance silhouette).
    pub anchor: Option<String>,
    /// Surface samples of each object and each guidance part.
    pub object_samples: usize,
    pub guidance_samples: usize,
    pub refine: RefineOptions,
    /// The contact-scale stage's settings; `None` switches the stage off. The default is
    /// [`contact_scale::ContactOptions::grow`], the variant measured best on the whole
    /// realistic benchmark (docs/compose.md, "Session 12").
    pub contact: Option<contact_scale::ContactOptions>,
    /// The support sweep's settings ([`support`]); `None` (the default) switches it off. On
    /// the realistic benchmark (seeds 0–4) it gained the die s1 and lost the teapot s4 at 2 %,
    /// the same counts as without it: docs/compose.md, "Twelfth stop".
    pub support: Option<support::SupportOptions>,
}

impl Default for ComposeOptions {
    fn default() -> Self {
        ComposeOptions {
            method: Method::FullColour,
            seed: 0,
            anchor: None,
            object_samples: 5000,
            guidance_samples: 2500,
            refine: RefineOptions::default(),
            contact: Some(contact_scale::ContactOptions::grow()),
            support: None,
        }
    }
}

/// One object to compose: its mesh (own frame) and its guidance part (guidance frame).
#[derive(Clone, Debug)]
pub struct ObjectInput {
    pub name: String,
    pub visual: VisualMesh,
    pub guidance: VisualMesh,
}

/// The registration of one object.
#[derive(Clone, Debug, Serialize)]
pub struct ObjectResult {
    pub name: String,
    #[serde(skip)]
    pub transform: Similarity,
    /// Stages that produced the transform, e.g. `obb+fpfh_ransac+trimmed_icp+collision_refine`.
    pub method: String,
    /// The stage whose pose was returned (the last stage that did not make the fit worse).
    pub pose_stage: String,
    /// Every stage's fit (mean truncated guidance-to-surface distance) and whether its pose
    /// was taken ([`guard`]).
    pub stages: Vec<guard::StageFit>,
    /// Silhouette area of the guidance part (guidance units²).
    pub silhouette_area: f64,
    pub initial_scale: f64,
    /// Hypothesis score of the chosen pose (fraction of guidance explained + ½ object covered).
    pub score: f64,
    /// RMS of the kept ICP correspondences (guidance units).
    pub icp_rms: f64,
    pub hypotheses: usize,
    pub colour_used: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub refinement: Option<RefineReport>,
    /// The contact-scale stage on an item placed after the anchor ([`contact_scale`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact: Option<contact_scale::ContactReport>,
    /// The support sweep on an item placed after the anchor ([`support`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub support: Option<support::SupportReport>,
    /// The colour's refused size judged by the support ([`colour_rest`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub colour_rest: Option<colour_rest::ColourRestReport>,
}

#[derive(Clone, Copy, Debug, Serialize)]
pub struct RefineReport {
    pub penetration_before: f64,
    pub penetration_after: f64,
    pub moved: f64,
    pub beta_doublings: usize,
}

impl From<&Refined> for RefineReport {
    fn from(r: &Refined) -> Self {
        RefineReport {
            penetration_before: r.penetration_before,
            penetration_after: r.penetration_after,
            moved: r.moved,
            beta_doublings: r.continuation,
        }
    }
}

/// The composed scene.
#[derive(Clone, Debug, Serialize)]
pub struct Composition {
    pub anchor: String,
    /// Objects in the order they were composed (anchor first).
    pub objects: Vec<ObjectResult>,
    /// Diagonal of all guidance parts together (the length unit of the refinement).
    pub scene_diagonal: f64,
}

impl Composition {
    pub fn get(&self, name: &str) -> Option<&ObjectResult> {
        self.objects.iter().find(|o| o.name == name)
    }
}

fn name_seed(seed: u64, name: &str) -> u64 {
    // FNV-1a of the name, mixed with the seed: stable across runs and platforms.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in name.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x100_0000_01b3);
    }
    h ^ seed.wrapping_mul(0x9E37_79B9_7F4A_7C15)
}

/// Register one object onto its guidance part (steps 2–4). `occlusion` holds the other objects
/// of the scene, which hide parts of this one ([`Occlusion`]).
#[allow(clippy::too_many_arguments)]
fn register(
    object: &Cloud,
    object_tree: &KdTree,
    spacing: f64,
    guidance: &Cloud,
    occlusion: Option<&Occlusion<'_>>,
    method: Method,
    seed: u64,
) -> Registered {
    let guidance_tree = KdTree::new(&guidance.points);
    let object_obb = Obb::of_points(&object.points);
    let guidance_obb = Obb::of_points(&guidance.points);
    let scale0 = obb::scale_ratio(&object_obb, &guidance_obb);
    let p = Problem {
        object,
        object_tree,
        guidance,
        guidance_tree: &guidance_tree,
        object_obb,
        guidance_obb,
        scale0,
        seed,
        occlusion,
    };
    let icp = IcpOptions {
        iterations: 60,
        keep: 0.8,
        scale_lo: scale0 / 1.4,
        scale_hi: scale0 * 1.4,
        tolerance: 1e-5 * p.guidance_diagonal(),
    };
    let use_colour = method == Method::FullColour && colour::usable(object, guidance);
    let (hyps, stages): (Vec<Similarity>, &str) = match method {
        Method::IcpOnly => (
            ObbHypotheses {
                all_permutations: false,
            }
            .hypotheses(&p),
            "obb",
        ),
        Method::RansacIcp => {
            let mut h = FpfhRansac {
                keep: 1,
                ..Default::default()
            }
            .hypotheses(&p);
            if h.is_empty() {
                h = ObbHypotheses {
                    all_permutations: false,
                }
                .hypotheses(&p);
            }
            (h, "fpfh_ransac")
        }
        _ => {
            let mut h = ObbHypotheses {
                all_permutations: true,
            }
            .hypotheses(&p);
            h.extend(FpfhRansac::default().hypotheses(&p));
            (h, "obb_permutations+fpfh_ransac")
        }
    };
    let n_hyp = hyps.len();
    let colour_tree;
    let matcher = if use_colour {
        colour_tree = icp::Matcher::colour_tree(object, COLOUR_WEIGHT * object.diagonal());
        icp::Matcher::Colour {
            tree: &colour_tree,
            weight: COLOUR_WEIGHT * object.diagonal(),
        }
    } else {
        icp::Matcher::Geometry(object_tree)
    };
    let init = if hyps.len() == 1 {
        hyps[0]
    } else {
        best_hypothesis(&p, &hyps, &matcher, use_colour, &icp)
            .map(|(t, _)| t)
            .unwrap_or(hyps[0])
    };
    let g_icp = guidance.subsample(1500);
    // The guard: every stage starts from the best pose so far and is kept only when it fits the
    // guidance at least as well ([`guard`]).
    let mut guard = guard::Guard::new(
        object,
        object_tree,
        spacing,
        guidance.subsample(1000).points,
        init,
        if n_hyp == 1 { stages } else { "global" },
    );
    let (t, rms) = trimmed_icp(&object.points, &matcher, &g_icp, guard.pose(), &icp);
    guard.offer("trimmed_icp", t);
    let mut rms = rms;
    let mut colour_refused = None;
    let probe_g = global::probes(guidance.len(), 700);
    let probe_o = global::probes(object.len(), 700);
    if !matches!(method, Method::IcpOnly | Method::RansacIcp) {
        let (t, _) = scale::search(
            &p,
            &matcher,
            &g_icp,
            guard.pose(),
            &icp,
            use_colour,
            &probe_g,
            &probe_o,
        );
        // Free ICP again, its scale now held within ±1.5% of the chosen one.
        let near = IcpOptions {
            scale_lo: t.scale / 1.015,
            scale_hi: t.scale * 1.015,
            ..icp
        };
        let (t, r) = trimmed_icp(&object.points, &matcher, &g_icp, t, &near);
        if guard.offer("scale_search", t) {
            rms = r;
        }
        // The local fit all the way in: robust point-to-plane ICP, the scale from how the
        // surfaces overlap (within ±5 % of the current one, inside the global bounds).
        let s0 = guard.pose().scale;
        let pl = plane_icp::PlaneIcpOptions {
            iterations: 30,
            keep: 0.85,
            huber: 1.5,
            scale: true,
            scale_lo: (s0 / 1.05).max(icp.scale_lo),
            scale_hi: (s0 * 1.05).min(icp.scale_hi),
            tolerance: 1e-6 * p.guidance_diagonal(),
            ..Default::default()
        };
        let (t, r) = plane_icp::plane_icp(object, &matcher, &g_icp, guard.pose(), &pl);
        if guard.offer("point_to_plane", t) {
            rms = r;
        }
        // The same fit with a normal offset beside the scale: a reconstruction's blur fattens or
        // erodes the guidance by a roughly constant depth, which a similarity alone reads as
        // scale. Judged by the guard with each pose's own offset taken out.
        if plane_icp::scale_offset_correlation(object) < OFFSET_CORRELATION_MAX {
            plane_icp::offset_stage(object, &matcher, &g_icp, &pl, &icp, &mut guard, &mut rms);
            // Then the scale swept ±40 %, judged by the same offset-aware fit ([`sweep`]).
            let (o, bounds) = (sweep::SweepOptions::default(), (icp.scale_lo, icp.scale_hi));
            let m = &matcher;
            let (ot, g) = (object_tree, &mut guard);
            if let Some(r) = sweep::sweep(object, ot, m, &g_icp, &pl, bounds, OFFSET_MAX, g, &o) {
                rms = r;
            }
        }
        // The size the colour along the long axis gives, judged by the guard ([`colour_axis`]).
        if use_colour {
            let bounds = (icp.scale_lo, icp.scale_hi);
            let (m, g) = (&matcher, &mut guard);
            match colour_axis::stage(object, guidance, m, &g_icp, &pl, bounds, OFFSET_MAX, g) {
                Some(c) if c.taken => rms = c.rms,
                Some(c) => colour_refused = Some(c.pose),
                None => {}
            }
        }
    }
    let t = guard.pose();
    let score = global::score(&p, &t, use_colour, &probe_g, &probe_o);
    Registered {
        transform: t,
        method: format!(
            "{stages}+trimmed_icp{}{}",
            if use_colour { "+colour" } else { "" },
            if matches!(method, Method::IcpOnly | Method::RansacIcp) {
                ""
            } else {
                "+scale_search+point_to_plane"
            }
        ),
        scale0,
        score,
        rms,
        hypotheses: n_hyp,
        colour_used: use_colour,
        pose_stage: guard.stage().to_string(),
        stages: guard.log().to_vec(),
        colour_refused,
    }
}

/// What [`register`] found for one object.
struct Registered {
    transform: Similarity,
    method: String,
    scale0: f64,
    score: f64,
    rms: f64,
    hypotheses: usize,
    colour_used: bool,
    pose_stage: String,
    stages: Vec<guard::StageFit>,
    /// The colour's pose the guard refused ([`colour_axis::stage`]).
    colour_refused: Option<Similarity>,
}

/// Compose the objects (steps 1–5). Errors only on unusable input (an empty mesh).
pub fn compose(inputs: &[ObjectInput], o: &ComposeOptions) -> Result<Composition> {
    if inputs.is_empty() {
        return Err(Error::Usage("compose needs at least one object".into()));
    }
    for i in inputs {
        if i.visual.triangle_count() == 0 || i.guidance.triangle_count() == 0 {
            return Err(Error::Usage(format!(
                "object {:?}: mesh or guidance part has no triangles",
                i.name
            )));
        }
    }
    // Silhouettes on a common window.
    let mut bb: Option<crate::mesh::Aabb> = None;
    for i in inputs {
        if let Some(b) = i.guidance.geometry().aabb() {
            bb = Some(bb.map_or(b, |a| a.union(&b)));
        }
    }
    let bb = bb.ok_or_else(|| Error::Usage("guidance meshes are empty".into()))?;
    let window = ([bb.min.x, bb.min.y], [bb.max.x, bb.max.y]);
    let areas: Vec<f64> = inputs
        .iter()
        .map(|i| silhouette_area(&i.guidance, window, 256))
        .collect();
    let mut order: Vec<usize> = (0..inputs.len()).collect();
    order.sort_by(|&a, &b| areas[b].total_cmp(&areas[a]).then(a.cmp(&b)));
    if let Some(name) = &o.anchor {
        let k = inputs
            .iter()
            .position(|i| &i.name == name)
            .ok_or_else(|| Error::Usage(format!("--anchor {name}: no such object")))?;
        order.retain(|&i| i != k);
        order.insert(0, k);
    }
    let unit = bb.diagonal();
    // Every guidance part is sampled up front: the others' parts are what hides an object until
    // they are placed ([`Occlusion`]).
    let guidances: Vec<Cloud> = inputs
        .iter()
        .map(|inp| {
            let seed = name_seed(o.seed, &inp.name);
            let mut g = Cloud::sample(&inp.guidance, o.guidance_samples, seed ^ 1);
            colour::normalise(&mut g);
            g
        })
        .collect();
    // Surface samples of the objects placed so far, at their composed poses.
    let mut placed_samples: Vec<Option<Vec<P3>>> = vec![None; inputs.len()];
    let mut field: Option<AnchorField> = None;
    let mut results = Vec::new();
    for (rank, &i) in order.iter().enumerate() {
        let inp = &inputs[i];
        let seed = name_seed(o.seed, &inp.name);
        let mut object = Cloud::sample(&inp.visual, o.object_samples, seed);
        // The placed objects' surface in this part is segmentation bleed ([`bleed`]): within
        // 1.5 % of the part's diagonal, or 1 % of the scene's (the placed part's own noise and
        // pose error, for a small object next to a large one), of a placed object, a point
        // belongs to that object.
        let stripped = field.as_ref().and_then(|f| {
            let d = crate::mesh::Aabb::of_points(&guidances[i].points)?.diagonal();
            bleed::without_placed(&guidances[i], f, (0.015 * d).max(0.01 * unit), 0.5)
        });
        let guidance = stripped.as_ref().unwrap_or(&guidances[i]);
        colour::normalise(&mut object);
        // What hides this object: the placed meshes of the objects composed before it
        // (complete surfaces), the guidance parts of the others (holey).
        let occlusion = crate::mesh::Aabb::of_points(&guidance.points).map(|b| {
            let d = b.diagonal();
            // Blockers more than a diagonal away hide little; the cells are 2τ wide.
            let blockers: Vec<P3> = (0..inputs.len())
                .filter(|&j| j != i)
                .flat_map(|j| match &placed_samples[j] {
                    Some(pts) => pts.clone(),
                    None => guidances[j].subsample(800).points,
                })
                .filter(|p| b.intersects(&crate::mesh::Aabb { min: *p, max: *p }, d))
                .collect();
            let o = Occlusion::new(blockers, &b, 0.25 * d, 0.04 * d);
            match &field {
                Some(f) => o.with_solids(f, 0.02 * d),
                None => o,
            }
        });
        let object_tree = KdTree::new(&object.points);
        let spacing = guard::spacing(&inp.visual, object.len());
        let reg = register(
            &object,
            &object_tree,
            spacing,
            guidance,
            occlusion.as_ref(),
            o.method,
            seed,
        );
        let (mut method, colour_used) = (reg.method.clone(), reg.colour_used);
        let mut placed = Placed {
            pose: reg.transform,
            stage: reg.pose_stage.clone(),
            log: reg.stages.clone(),
        };
        let mut refinement = None;
        let mut contact = None;
        let mut support = None;
        let mut colour_rest = None;
        if let (Some(field), true) = (&field, rank > 0 && o.method.refines()) {
            let item = Item {
                visual: &inp.visual,
                object: &object,
                tree: &object_tree,
                spacing,
                guidance,
                field,
            };
            // An item that does not rest on the placed objects: its size among resting poses.
            if let Some(so) = &o.support {
                support = Some(support::apply(&item, so, &mut placed));
            }
            // An item's size from its resting contact with the placed objects, where the
            // guidance does not show it ([`contact_scale`]); the guard decides, within the
            // guidance's noise.
            if let Some(c) = &o.contact {
                contact = Some(contact_scale::apply(&item, c, &mut placed));
            }
            // The colour's refused size, where the item floats and that size rests
            // ([`colour_rest`]).
            if let Some(c) = reg.colour_refused {
                colour_rest = Some(colour_rest::apply(&item, c, &mut placed));
            }
        }
        // The object's welded mesh, built once for the dense check and the anchor field.
        let geometry = std::cell::OnceCell::new();
        let geometry = || geometry.get_or_init(|| inp.visual.geometry());
        if rank > 0 && o.method.refines() {
            if let Some(f) = &field {
                let g = guidance.subsample(600);
                let sub = object.subsample(700);
                let sub_tree = KdTree::new(&sub.points);
                let colour_sub;
                let matcher = if colour_used {
                    let w = COLOUR_WEIGHT * object.diagonal();
                    colour_sub = icp::Matcher::colour_tree(&sub, w);
                    icp::Matcher::Colour {
                        tree: &colour_sub,
                        weight: w,
                    }
                } else {
                    icp::Matcher::Geometry(&sub_tree)
                };
                let target = Target::Guidance {
                    points: &g.points,
                    colours: &g.colours,
                    matcher: &matcher,
                    keep: 0.8,
                };
                let start = placed.pose;
                let mut r = refine(&sub.points, &target, start, f, unit, &o.refine);
                // Dense check: 700 samples miss thin parts between them (a shoe's edge stayed
                // 1.5 mm inside the tray). The object's vertices within the clearance band join
                // the samples for a second pass that removes what is left while moving the
                // object as little as possible from the refined pose (as `--fix-penetration`
                // does); pulling towards the guidance again let a round fruit drift 70°.
                let m = r.transform.matrix();
                let band = o.refine.epsilon * unit;
                let near: Vec<(P3, f64)> = geometry()
                    .vertices
                    .iter()
                    .filter_map(|&v| {
                        let phi = f.eval(&m.transform_point(&v)).0;
                        (phi < band).then_some((v, phi))
                    })
                    .collect();
                let deepest = near.iter().map(|x| -x.1).fold(0.0, f64::max);
                if deepest > o.refine.tolerance * unit {
                    let mut pts = sub.points.clone();
                    pts.extend(near.iter().map(|x| x.0));
                    let r2 = refine(&pts, &Target::InitialPose, r.transform, f, unit, &o.refine);
                    r = Refined {
                        penetration_before: r.penetration_before.max(deepest),
                        ..r2
                    };
                }
                // The guard: leaving the anchor may cost the fit what the move out of it costs
                // (the depth plus the clearance), no more. A refinement that drifts further is
                // replaced by the smallest move out of collision from the registered pose; if
                // that too fits worse, the registered pose stays.
                let mut guard = guard::Guard::new(
                    &object,
                    &object_tree,
                    spacing,
                    guidance.subsample(1000).points,
                    start,
                    &placed.stage,
                );
                guard.with_allowance(r.penetration_before + 2.0 * o.refine.epsilon * unit);
                if !guard.offer("collision_refine", r.transform) {
                    let m = start.matrix();
                    let mut pts = sub.points.clone();
                    pts.extend(
                        geometry()
                            .vertices
                            .iter()
                            .filter(|&&v| f.eval(&m.transform_point(&v)).0 < band),
                    );
                    let r2 = refine(&pts, &Target::InitialPose, start, f, unit, &o.refine);
                    if guard.offer("collision_minimal", r2.transform) {
                        r = r2;
                    }
                }
                placed.take(&guard);
                method.push_str("+collision_refine");
                refinement = Some(RefineReport::from(&r));
            }
        }
        if o.method.refines() && rank + 1 < order.len() {
            let mesh: Mesh = geometry().transformed(&placed.pose.matrix());
            let fld = field.get_or_insert_with(|| AnchorField::new(&[], 32));
            fld.push(&mesh, 32);
        }
        if rank + 1 < order.len() {
            placed_samples[i] = Some(
                Cloud::sample(&inp.visual, 800, seed ^ 2)
                    .transformed(&placed.pose.matrix())
                    .points,
            );
        }
        results.push(ObjectResult {
            name: inp.name.clone(),
            transform: placed.pose,
            pose_stage: placed.stage,
            stages: placed.log,
            method,
            silhouette_area: areas[i],
            initial_scale: reg.scale0,
            score: reg.score,
            icp_rms: reg.rms,
            hypotheses: reg.hypotheses,
            colour_used,
            refinement,
            contact,
            support,
            colour_rest,
        });
    }
    Ok(Composition {
        anchor: inputs[order[0]].name.clone(),
        objects: results,
        scene_diagonal: unit,
    })
}

/// What [`fix_penetration`] did to one object.
#[derive(Clone, Debug, Serialize)]
pub struct FixReport {
    pub name: String,
    /// Largest penetration of the object's surface samples into the objects placed before it,
    /// before and after (scene units).
    pub penetration_before: f64,
    pub penetration_after: f64,
    /// Largest displacement of a surface sample (scene units).
    pub moved: f64,
}

/// Remove slight interpenetration from a scene's given poses while keeping every object as
/// close as possible to its pose: the collision-aware refinement (step 5) with the data term
/// pulling each surface sample back to where the given pose put it. Objects are taken in order
/// (fixed objects first, then by decreasing bounding-box volume); the first stays put and each
/// next one is refined against all those before it. Objects that do not penetrate are untouched.
pub fn fix_penetration(scene: &mut crate::scene::Scene, o: &RefineOptions) -> Vec<FixReport> {
    let placed: Vec<Mesh> = scene
        .objects
        .iter()
        .map(|ob| ob.visual.geometry().transformed(&ob.pose.matrix()))
        .collect();
    let vol = |m: &Mesh| m.aabb().map(|b| b.extents().product()).unwrap_or(0.0);
    let mut order: Vec<usize> = (0..placed.len()).collect();
    order.sort_by(|&a, &b| {
        scene.objects[b]
            .physical
            .fixed
            .cmp(&scene.objects[a].physical.fixed)
            .then(vol(&placed[b]).total_cmp(&vol(&placed[a])))
            .then(a.cmp(&b))
    });
    let unit = placed
        .iter()
        .filter_map(|m| m.aabb())
        .reduce(|a, b| a.union(&b))
        .map(|b| b.diagonal())
        .unwrap_or(1.0);
    let mut field = AnchorField::new(&[], 40);
    let mut out = Vec::new();
    for (rank, &i) in order.iter().enumerate() {
        if rank > 0 {
            let ob = &scene.objects[i];
            let pts = Cloud::sample(&ob.visual, 1500, 0x5EED).points;
            let r = refine(&pts, &Target::InitialPose, ob.pose, &field, unit, o);
            let report = FixReport {
                name: ob.name.clone(),
                penetration_before: r.penetration_before,
                penetration_after: if r.penetration_before > 0.0 {
                    r.penetration_after
                } else {
                    0.0
                },
                moved: if r.penetration_before > 0.0 {
                    r.moved
                } else {
                    0.0
                },
            };
            if r.penetration_before > 0.0 {
                scene.objects[i].pose = r.transform;
            }
            out.push(report);
        }
        if rank + 1 < order.len() {
            let ob = &scene.objects[i];
            field.push(&ob.visual.geometry().transformed(&ob.pose.matrix()), 40);
        }
    }
    out
}
