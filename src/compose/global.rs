//! Global registration without learned weights: pose hypotheses from OBB axis permutations and
//! from FPFH + RANSAC, each refined by a short ICP and scored against the guidance. The
//! [`GlobalRegistration`] trait is where a learned matcher (GeoTransformer) would plug in.

use super::cloud::Cloud;
use super::features::{fpfh, match_features};
use super::icp::{trimmed_icp, umeyama, IcpOptions, Matcher};
use super::kdtree::KdTree;
use super::obb::{axis_permutations, Obb};
use crate::mesh::P3;
use crate::pose::Similarity;
use crate::rng::Rng;
use nalgebra::{Rotation3, UnitQuaternion};

/// One registration problem: the object's samples (its own frame) and the guidance part's
/// samples (guidance frame), with their trees and boxes.
pub struct Problem<'a> {
    pub object: &'a Cloud,
    pub object_tree: &'a KdTree,
    pub guidance: &'a Cloud,
    pub guidance_tree: &'a KdTree,
    pub object_obb: Obb,
    pub guidance_obb: Obb,
    /// Scale from the OBB extents.
    pub scale0: f64,
    pub seed: u64,
}

impl Problem<'_> {
    pub fn guidance_diagonal(&self) -> f64 {
        self.guidance_obb.extents.norm()
    }
}

/// A source of initial poses (object frame → guidance frame).
pub trait GlobalRegistration: Sync {
    fn name(&self) -> &'static str;
    fn hypotheses(&self, p: &Problem) -> Vec<Similarity>;
}

/// Align the object's OBB with the guidance part's, under all 24 axis permutations and flips
/// (or only the identity one: what plain ICP starts from).
pub struct ObbHypotheses {
    pub all_permutations: bool,
}

impl GlobalRegistration for ObbHypotheses {
    fn name(&self) -> &'static str {
        "obb"
    }
    fn hypotheses(&self, p: &Problem) -> Vec<Similarity> {
        let perms = if self.all_permutations {
            axis_permutations()
        } else {
            vec![nalgebra::Matrix3::identity()]
        };
        perms
            .iter()
            .map(|perm| {
                let r = p.guidance_obb.axes * perm * p.object_obb.axes.transpose();
                let rotation =
                    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
                let t = p.guidance_obb.center.coords
                    - p.scale0 * (rotation * p.object_obb.center.coords);
                Similarity {
                    scale: p.scale0,
                    rotation,
                    translation: t,
                }
            })
            .collect()
    }
}

/// FPFH correspondences + 3-point RANSAC; returns the best few distinct poses.
pub struct FpfhRansac {
    pub iterations: usize,
    /// Distinct hypotheses returned (best inlier counts first).
    pub keep: usize,
    /// Keypoint voxel as a fraction of the guidance diagonal.
    pub voxel_fraction: f64,
}

impl Default for FpfhRansac {
    fn default() -> Self {
        FpfhRansac {
            iterations: 3000,
            keep: 4,
            voxel_fraction: 1.0 / 30.0,
        }
    }
}

impl GlobalRegistration for FpfhRansac {
    fn name(&self) -> &'static str {
        "fpfh_ransac"
    }
    fn hypotheses(&self, p: &Problem) -> Vec<Similarity> {
        let voxel = p.guidance_diagonal() * self.voxel_fraction;
        // The object pre-scaled by the OBB estimate, so both clouds share a unit.
        let scaled = p
            .object
            .transformed(&nalgebra::Matrix4::new_scaling(p.scale0));
        let fo = fpfh(&scaled, voxel, 5.0 * voxel);
        let fg = fpfh(p.guidance, voxel, 5.0 * voxel);
        let corr = match_features(&fo, &fg);
        if corr.len() < 3 {
            return Vec::new();
        }
        let mut rng = Rng::new(p.seed ^ 0xF9F4);
        let inlier_d2 = (1.5 * voxel).powi(2);
        let mut found: Vec<(usize, Similarity)> = Vec::new();
        for _ in 0..self.iterations {
            let idx = [
                rng.below(corr.len()),
                rng.below(corr.len()),
                rng.below(corr.len()),
            ];
            if idx[0] == idx[1] || idx[1] == idx[2] || idx[0] == idx[2] {
                continue;
            }
            let xs: Vec<P3> = idx.iter().map(|&k| fo.points[corr[k].0]).collect();
            let ys: Vec<P3> = idx.iter().map(|&k| fg.points[corr[k].1]).collect();
            // Edge-length consistency (scale is already normalised to ~1).
            let ok = (0..3).all(|a| {
                let b = (a + 1) % 3;
                let lx = (xs[a] - xs[b]).norm();
                let ly = (ys[a] - ys[b]).norm();
                lx > 2.0 * voxel && ly > 0.0 && (lx / ly) > 0.8 && (lx / ly) < 1.25
            });
            if !ok {
                continue;
            }
            let Some(t) = umeyama(&xs, &ys, 0.8, 1.25) else {
                continue;
            };
            let m = t.matrix();
            let inliers = corr
                .iter()
                .filter(|&&(i, j)| {
                    (m.transform_point(&fo.points[i]) - fg.points[j]).norm_squared() < inlier_d2
                })
                .count();
            if inliers < 3 {
                continue;
            }
            found.push((inliers, t));
        }
        found.sort_by(|a, b| b.0.cmp(&a.0));
        let mut out: Vec<Similarity> = Vec::new();
        for (_, t) in found {
            if out.len() >= self.keep {
                break;
            }
            if out.iter().any(|o| o.rotation.angle_to(&t.rotation) < 0.2) {
                continue;
            }
            out.push(t);
        }
        // Undo the pre-scaling: object → scaled object → guidance.
        out.into_iter()
            .map(|t| Similarity {
                scale: t.scale * p.scale0,
                ..t
            })
            .collect()
    }
}

/// The three parts of a pose's fit, over probe subsets of the guidance and object samples.
#[derive(Clone, Copy, Debug, Default)]
pub struct Fit {
    /// Fraction of guidance points with an object point within τ.
    pub guidance_explained: f64,
    /// The same, each inlier weighted by colour agreement (Gaussian, σ = 0.12 per channel).
    pub colour_explained: f64,
    /// Fraction of object points with a guidance point within τ.
    pub object_covered: f64,
}

impl Fit {
    /// Fraction of the guidance explained (colour-weighted when `colour`) plus half the fraction
    /// of the object covered: the score reported per object.
    pub fn score(&self, colour: bool) -> f64 {
        let fwd = if colour {
            self.colour_explained
        } else {
            self.guidance_explained
        };
        fwd + 0.5 * self.object_covered
    }

    /// What hypotheses are ranked by: the geometric score plus, with colour, the colour score.
    /// Colour alone is a noisy judge of scale (a lit, tinted print matches itself slightly
    /// shifted almost as well), geometry alone cannot tell a symmetric shape's twins apart; the
    /// sum needs both to agree.
    pub fn rank(&self, colour: bool) -> f64 {
        self.score(false) + if colour { self.score(true) } else { 0.0 }
    }
}

/// The fit of pose `t` within τ = 2% of the guidance diagonal, both ways: guidance → object
/// (does the object explain the guidance?) and object → guidance (does the pose put object
/// surface where the guidance is empty?).
pub fn fit(p: &Problem, t: &Similarity, probe_g: &[usize], probe_o: &[usize]) -> Fit {
    let tau = 0.02 * p.guidance_diagonal();
    let m = t.matrix();
    let inv = m.try_inverse().unwrap_or_else(nalgebra::Matrix4::identity);
    let (mut geo, mut col) = (0.0, 0.0);
    for &gi in probe_g {
        let q = inv.transform_point(&p.guidance.points[gi]);
        if let Some((oi, d2)) = p.object_tree.nearest(&q) {
            if d2.sqrt() * t.scale < tau {
                geo += 1.0;
                let a = p.guidance.colours[gi];
                let b = p.object.colours[oi];
                let d2c: f64 = (0..3).map(|k| (a[k] - b[k]).powi(2)).sum();
                col += (-d2c / (2.0 * 0.12 * 0.12)).exp();
            }
        }
    }
    let mut back = 0.0;
    for &oi in probe_o {
        let q = m.transform_point(&p.object.points[oi]);
        if let Some((_, d2)) = p.guidance_tree.nearest(&q) {
            if d2.sqrt() < tau {
                back += 1.0;
            }
        }
    }
    let ng = probe_g.len().max(1) as f64;
    Fit {
        guidance_explained: geo / ng,
        colour_explained: col / ng,
        object_covered: back / probe_o.len().max(1) as f64,
    }
}

/// How well a pose explains the guidance: the fraction of guidance points with an object point
/// within `tau` (colour-weighted when `colour`), plus half the fraction of object points with a
/// guidance point within `tau` (penalises poses that push the object where the guidance is empty).
pub fn score(
    p: &Problem,
    t: &Similarity,
    colour: bool,
    probe_g: &[usize],
    probe_o: &[usize],
) -> f64 {
    fit(p, t, probe_g, probe_o).score(colour)
}

/// Every `len / n`-th index: a deterministic probe subset of about `n` of `len` points.
pub fn probes(len: usize, n: usize) -> Vec<usize> {
    (0..len).step_by((len / n.max(1)).max(1)).collect()
}

/// `t` preceded by the rotation `spin` about the object-frame point `c`: the object turned in
/// place, its centre staying where `t` put it.
pub fn spun(t: &Similarity, spin: &UnitQuaternion<f64>, c: &P3) -> Similarity {
    let rotation = t.rotation * spin;
    let translation = t.translation + t.scale * (t.rotation * (c.coords - spin * c.coords));
    Similarity {
        rotation,
        translation,
        ..*t
    }
}

/// Turns of the object about its own centre tried around the best hypotheses: every 30° about
/// each of its OBB axes (the turns a spheroid, a cylinder or a box cannot show by shape), plus
/// `random` rotations spread over SO(3) (for shapes, like a ball, that show no axis at all).
pub fn spins(obb: &Obb, random: usize, seed: u64) -> Vec<UnitQuaternion<f64>> {
    let mut out = Vec::new();
    for k in 0..3 {
        let axis = nalgebra::Unit::new_normalize(obb.axes.column(k).into_owned());
        for step in 1..12 {
            out.push(UnitQuaternion::from_axis_angle(
                &axis,
                step as f64 * std::f64::consts::PI / 6.0,
            ));
        }
    }
    let mut rng = Rng::new(seed ^ 0x5B1A);
    out.extend((0..random).map(|_| rng.rotation()));
    out
}

/// Refine every hypothesis with a short ICP and rank it ([`Fit::rank`]); then turn the best
/// few in place ([`spins`]), rank the turned poses as they are, refine the best of those too,
/// and return the best (pose, rank) of all.
pub fn best_hypothesis(
    p: &Problem,
    hyps: &[Similarity],
    matcher: &Matcher,
    colour: bool,
    icp: &IcpOptions,
) -> Option<(Similarity, f64)> {
    use rayon::prelude::*;
    let g_short = p.guidance.subsample(500);
    let probe_g = probes(p.guidance.len(), 700);
    let probe_o = probes(p.object.len(), 700);
    let short = IcpOptions {
        iterations: 20,
        ..*icp
    };
    let refine_and_rank = |h: &Similarity| {
        let (t, _) = trimmed_icp(&p.object.points, matcher, &g_short, *h, &short);
        (t, fit(p, &t, &probe_g, &probe_o).rank(colour))
    };
    let mut results: Vec<(Similarity, f64)> = hyps.par_iter().map(refine_and_rank).collect();
    // The best few distinct poses, turned in place and ranked on coarse probes.
    let mut order: Vec<usize> = (0..results.len()).collect();
    order.sort_by(|&a, &b| results[b].1.total_cmp(&results[a].1).then(a.cmp(&b)));
    let mut bases: Vec<Similarity> = Vec::new();
    for &i in &order {
        let t = results[i].0;
        if bases.len() < 2 && bases.iter().all(|b| b.rotation.angle_to(&t.rotation) > 0.2) {
            bases.push(t);
        }
    }
    let turns = spins(&p.object_obb, 60, p.seed);
    let coarse_g = probes(p.guidance.len(), 300);
    let coarse_o = probes(p.object.len(), 300);
    let c = p.object_obb.center;
    let mut turned: Vec<(Similarity, f64)> = bases
        .iter()
        .flat_map(|b| turns.iter().map(move |s| spun(b, s, &c)))
        .collect::<Vec<_>>()
        .par_iter()
        .map(|t| (*t, fit(p, t, &coarse_g, &coarse_o).rank(colour)))
        .collect();
    turned.sort_by(|a, b| b.1.total_cmp(&a.1));
    turned.truncate(6);
    let more: Vec<(Similarity, f64)> = turned.par_iter().map(|(t, _)| refine_and_rank(t)).collect();
    results.extend(more);
    results
        .into_iter()
        .enumerate()
        .max_by(|a, b| a.1 .1.total_cmp(&b.1 .1).then(b.0.cmp(&a.0)))
        .map(|(_, r)| r)
}
