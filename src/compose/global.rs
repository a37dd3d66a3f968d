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
    let tau = 0.02 * p.guidance_diagonal();
    let m = t.matrix();
    let inv = m.try_inverse().unwrap_or_else(nalgebra::Matrix4::identity);
    let mut fwd = 0.0;
    for &gi in probe_g {
        let q = inv.transform_point(&p.guidance.points[gi]);
        if let Some((oi, d2)) = p.object_tree.nearest(&q) {
            if d2.sqrt() * t.scale < tau {
                fwd += if colour {
                    let a = p.guidance.colours[gi];
                    let b = p.object.colours[oi];
                    let d2c: f64 = (0..3).map(|k| (a[k] - b[k]).powi(2)).sum();
                    (-d2c / (2.0 * 0.12 * 0.12)).exp()
                } else {
                    1.0
                };
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
    fwd / probe_g.len().max(1) as f64 + 0.5 * back / probe_o.len().max(1) as f64
}

/// Refine every hypothesis with a short ICP, score it, return the best (pose, score) and how many
/// hypotheses were tried.
pub fn best_hypothesis(
    p: &Problem,
    hyps: &[Similarity],
    matcher: &Matcher,
    colour: bool,
    icp: &IcpOptions,
) -> Option<(Similarity, f64)> {
    use rayon::prelude::*;
    let g_short = p.guidance.subsample(500);
    let probe_g: Vec<usize> = (0..p.guidance.len())
        .step_by((p.guidance.len() / 700).max(1))
        .collect();
    let probe_o: Vec<usize> = (0..p.object.len())
        .step_by((p.object.len() / 700).max(1))
        .collect();
    let short = IcpOptions {
        iterations: 20,
        ..*icp
    };
    let results: Vec<(Similarity, f64)> = hyps
        .par_iter()
        .map(|h| {
            let (t, _) = trimmed_icp(&p.object.points, matcher, &g_short, *h, &short);
            let s = score(p, &t, colour, &probe_g, &probe_o);
            (t, s)
        })
        .collect();
    results
        .into_iter()
        .enumerate()
        .max_by(|a, b| a.1 .1.total_cmp(&b.1 .1).then(b.0.cmp(&a.0)))
        .map(|(_, r)| r)
}
