//! Scale from the overlap of surfaces, both ways.
//!
//! The guard's fit ([`super::plane_icp::surface_fit`]) measures guidance → object only. A pose
//! too large explains every guidance point as well as the true one (the guidance lies on the
//! larger surface's inside, within the noise, and its ends are still covered), so that measure
//! cannot see an object grown past the guidance's ends; the hypothesis rank ([`super::global::
//! fit`]) counts inliers within τ = 2 % of the diagonal, coarser than the few per cent of
//! length a scale error moves an end by. Here the scale is chosen by the mean truncated
//! distance both ways: guidance → object plus object → guidance, where object points that the
//! other objects hide ([`super::occlusion::Occlusion`]: a contact, inside a container) and that
//! have no guidance near them are left out, as their missing guidance has a physical reason.
//!
//! Entry points:
//! - [`object_to_guidance`]: the object → guidance half.
//! - [`two_sided`]: both halves.
//! - [`scale_by_overlap`]: a 1-d search of the scale about a pose, each candidate refitted at
//!   its fixed scale by point-to-plane ICP and ranked by [`two_sided`].

use super::cloud::Cloud;
use super::global::Problem;
use super::icp::Matcher;
use super::kdtree::KdTree;
use super::plane_icp::{plane_icp, surface_fit, PlaneIcpOptions};
use super::scale::rescaled;
use crate::mesh::P3;
use crate::pose::Similarity;

/// The guidance side of the measure: its points (a probe subset), their tree, their normals and
/// their mean spacing.
pub struct GuidanceProbe {
    pub points: Vec<P3>,
    pub normals: Vec<crate::mesh::V3>,
    pub tree: KdTree,
    pub spacing: f64,
}

impl GuidanceProbe {
    /// From the whole guidance cloud (its spacing from its nearest-neighbour distances).
    pub fn new(guidance: &Cloud) -> GuidanceProbe {
        let tree = KdTree::new(&guidance.points);
        // Median distance from the even points to the odd ones (a sample without itself), over
        // a few hundred points: the spacing of the half cloud, about √2 × the whole one's.
        let odd: Vec<P3> = guidance.points.iter().skip(1).step_by(2).copied().collect();
        let half = KdTree::new(&odd);
        let step = 2 * (guidance.len() / 600).max(1);
        let mut nn: Vec<f64> = (0..guidance.len())
            .step_by(step)
            .filter_map(|i| half.nearest(&guidance.points[i]).map(|(_, d2)| d2.sqrt()))
            .collect();
        nn.sort_by(f64::total_cmp);
        let spacing = nn.get(nn.len() / 2).copied().unwrap_or(0.0) / std::f64::consts::SQRT_2;
        GuidanceProbe {
            points: guidance.points.clone(),
            normals: guidance.normals.clone(),
            tree,
            spacing,
        }
    }
}

/// Mean over the object probe points `probe_o` placed by `t` of their distance to the guidance
/// (point to the nearest guidance point's plane when within two guidance spacings of it along
/// the surface, else point distance), truncated at `cap`. A point farther than `tau` from the
/// guidance that the other objects hide is left out. Guidance units.
pub fn object_to_guidance(
    p: &Problem,
    g: &GuidanceProbe,
    t: &Similarity,
    probe_o: &[usize],
    cap: f64,
    tau: f64,
) -> f64 {
    let m = t.matrix();
    let (mut sum, mut n) = (0.0, 0.0);
    for &oi in probe_o {
        let q = m.transform_point(&p.object.points[oi]);
        let d = match g.tree.nearest(&q) {
            Some((j, d2)) => {
                let nrm = g.normals[j];
                let along = (q - g.points[j]).dot(&nrm);
                let tangential = (d2 - along * along).max(0.0).sqrt();
                if tangential < 2.0 * g.spacing {
                    along.abs()
                } else {
                    d2.sqrt()
                }
            }
            None => cap,
        };
        if d > tau
            && p
                .occlusion
                .is_some_and(|o| o.hidden(&q, &(t.rotation * p.object.normals[oi])))
        {
            continue;
        }
        sum += d.min(cap);
        n += 1.0;
    }
    if n > 0.0 {
        sum / n
    } else {
        cap
    }
}

/// Both halves: [`surface_fit`] of the guidance points `probe_g` plus [`object_to_guidance`],
/// truncated at 3 % of the posed object's diagonal (guidance units, lower is better).
pub fn two_sided(
    p: &Problem,
    g: &GuidanceProbe,
    object_spacing: f64,
    t: &Similarity,
    probe_g: &[P3],
    probe_o: &[usize],
) -> f64 {
    let cap = 0.03 * t.scale * p.object.diagonal();
    let tau = 0.01 * t.scale * p.object.diagonal();
    surface_fit(p.object, p.object_tree, object_spacing, probe_g, t, cap)
        + object_to_guidance(p, g, t, probe_o, cap, tau)
}

/// Search the scale about `t`: relative steps `steps` (e.g. −12 % … +12 %), each candidate
/// rescaled about the object's centre and refitted at its fixed scale by point-to-plane ICP
/// (`fit_guidance`, `matcher`), then ranked by [`two_sided`]; then the same about the best with
/// a third of the step. Returns the best pose and its measure.
#[allow(clippy::too_many_arguments)]
pub fn scale_by_overlap(
    p: &Problem,
    g: &GuidanceProbe,
    object_spacing: f64,
    matcher: &Matcher,
    fit_guidance: &Cloud,
    t: Similarity,
    steps: &[f64],
    probe_g: &[P3],
    probe_o: &[usize],
    lo: f64,
    hi: f64,
) -> (Similarity, f64) {
    use rayon::prelude::*;
    let c = p.object_obb.center;
    let fixed = PlaneIcpOptions {
        iterations: 12,
        scale: false,
        tolerance: 1e-6 * p.guidance_diagonal(),
        ..Default::default()
    };
    let eval = |base: &Similarity, f: f64| {
        let s = (base.scale * (1.0 + f)).clamp(lo, hi);
        let (r, _) = plane_icp(p.object, matcher, fit_guidance, rescaled(base, s, &c), &fixed);
        (r, two_sided(p, g, object_spacing, &r, probe_g, probe_o))
    };
    let mut best = (t, two_sided(p, g, object_spacing, &t, probe_g, probe_o));
    let fine: Vec<f64> = steps.iter().map(|f| f / 3.0).collect();
    for round in [steps, &fine[..]] {
        let base = best.0;
        let tried: Vec<(Similarity, f64)> = round
            .par_iter()
            .filter(|f| f.abs() > 0.0)
            .map(|&f| eval(&base, f))
            .collect();
        for cand in tried {
            if cand.1 < best.1 {
                best = cand;
            }
        }
    }
    best
}

/// Development aid: the two-sided measure and its halves over a sweep of scales about `t`.
pub fn sweep(
    p: &Problem,
    g: &GuidanceProbe,
    object_spacing: f64,
    matcher: &Matcher,
    fit_guidance: &Cloud,
    t: Similarity,
    probe_g: &[P3],
    probe_o: &[usize],
) {
    let c = p.object_obb.center;
    let fixed = PlaneIcpOptions {
        iterations: 12,
        scale: false,
        ..Default::default()
    };
    for k in -8..=8 {
        let f = 0.025 * k as f64;
        let s = t.scale * (1.0 + f);
        let (r, _) = plane_icp(p.object, matcher, fit_guidance, rescaled(&t, s, &c), &fixed);
        let cap = 0.03 * r.scale * p.object.diagonal();
        let tau = 0.01 * r.scale * p.object.diagonal();
        let gf = surface_fit(p.object, p.object_tree, object_spacing, probe_g, &r, cap);
        let of = object_to_guidance(p, g, &r, probe_o, cap, tau);
        eprintln!(
            "        sweep {:+6.1} %: g->o {:.3e} o->g {:.3e} sum {:.3e}",
            100.0 * f,
            gf,
            of,
            gf + of
        );
    }
}
