//! Global registration without learned weights: pose hypotheses from OBB axis permutations and
//! from FPFH + RANSAC, each refined by a short ICP and scored against the guidance. The
//! [`GlobalRegistration`] trait is where a learned matcher (GeoTransformer) would plug in.

use super::cloud::Cloud;
use super::features::{fpfh, match_features};
use super::icp::{trimmed_icp, umeyama, IcpOptions, Matcher};
use super::kdtree::KdTree;
use super::obb::{axis_permutations, Obb};
use super::occlusion::Occlusion;
use crate::mesh::{P3, V3};
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
    /// The other objects of the scene, which hide parts of this one ([`Occlusion`]).
    pub occlusion: Option<&'a Occlusion<'a>>,
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
        found.sort_by_key(|f| std::cmp::Reverse(f.0));
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
    /// Fraction of object points with a guidance point within τ, over the points whose guidance
    /// could be there: an uncovered point that the other objects hide ([`Occlusion`]) is left
    /// out, as contact or occlusion explains its missing guidance.
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
    // Only pairs within τ count, so the searches are bounded by τ (with a margin far above
    // rounding; the test below still decides): the same answers as unbounded ones, found
    // sooner on the many poses that are far off.
    let slack = 1.0 + 1e-6;
    let r2_object = if t.scale > 0.0 {
        (tau / t.scale).powi(2) * slack
    } else {
        f64::INFINITY
    };
    let (mut geo, mut col) = (0.0, 0.0);
    for &gi in probe_g {
        let q = inv.transform_point(&p.guidance.points[gi]);
        if let Some((oi, d2)) = p.object_tree.nearest_within(&q, r2_object) {
            if d2.sqrt() * t.scale < tau {
                geo += 1.0;
                let a = p.guidance.colours[gi];
                let b = p.object.colours[oi];
                let d2c: f64 = (0..3).map(|k| (a[k] - b[k]).powi(2)).sum();
                col += (-d2c / (2.0 * 0.12 * 0.12)).exp();
            }
        }
    }
    let (mut back, mut seen) = (0.0, 0.0);
    for &oi in probe_o {
        let q = m.transform_point(&p.object.points[oi]);
        let covered = p
            .guidance_tree
            .nearest_within(&q, tau * tau * slack)
            .is_some_and(|(_, d2)| d2.sqrt() < tau);
        if covered {
            back += 1.0;
            seen += 1.0;
        } else if !p
            .occlusion
            .is_some_and(|o| o.hidden(&q, &(t.rotation * p.object.normals[oi])))
        {
            seen += 1.0;
        }
    }
    let ng = probe_g.len().max(1) as f64;
    Fit {
        guidance_explained: geo / ng,
        colour_explained: col / ng,
        object_covered: if seen > 0.0 { back / seen } else { 0.0 },
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

/// `t` shifted so the object sits on the guidance: `iterations` translation-only ICP steps
/// (guidance probe → nearest object sample, the worst 20% of pairs dropped, mean residual). A
/// turned pose keeps its centre where the untouched pose had it, which for a shape that is not
/// centred on its own middle (a fruit's flat spot, a pen's clip) is off by a few per cent.
pub fn recentred(p: &Problem, t: &Similarity, probe_g: &[usize], iterations: usize) -> Similarity {
    let mut t = *t;
    // (squared residual, order found, residual); the order breaks ties as a stable sort would.
    let mut res: Vec<(f64, usize, V3)> = Vec::with_capacity(probe_g.len());
    // Each probe point's partner in the previous step: the next search starts there (the same
    // answer, found sooner). Not a certified warm start (`KdTreeN::nearest_warm_n`): a turned
    // pose's points move too far between steps for its certificate to hold, and keeping one
    // cost 17 % more here (1.17 → 1.37 G instructions on a plate + apple pair).
    let mut prev = vec![usize::MAX; probe_g.len()];
    for _ in 0..iterations {
        let m = t.matrix();
        let Some(inv) = m.try_inverse() else { break };
        res.clear();
        for (&gi, hint) in probe_g.iter().zip(prev.iter_mut()) {
            let g = p.guidance.points[gi];
            if let Some((oi, _)) = p.object_tree.nearest_from(&inv.transform_point(&g), *hint) {
                *hint = oi;
                let d = g - m.transform_point(&p.object.points[oi]);
                res.push((d.norm_squared(), res.len(), d));
            }
        }
        if res.is_empty() {
            break;
        }
        let k = (res.len() * 4 / 5).max(1);
        super::icp::smallest_sorted(&mut res, k, |r| (r.0, r.1));
        t.translation += res[..k].iter().fold(V3::zeros(), |a, r| a + r.2) / k as f64;
    }
    t
}

/// Pattern search on the rank over turns of the object about its centre: ±15°, ±7.5°, ±3.75°
/// about the object's x, y and z axes, each step size until no turn improves the rank (at most
/// three rounds). Returns the best pose found and its rank.
pub fn climb_rotation(
    p: &Problem,
    t: Similarity,
    rank: f64,
    probe_g: &[usize],
    probe_o: &[usize],
    colour: bool,
) -> (Similarity, f64) {
    let c = p.object_obb.center;
    let mut best = (t, rank);
    for deg in [15.0f64, 7.5, 3.75] {
        for _ in 0..3 {
            let base = best;
            for axis in [V3::x_axis(), V3::y_axis(), V3::z_axis()] {
                for sign in [-1.0, 1.0] {
                    let turn = UnitQuaternion::from_axis_angle(&axis, sign * deg.to_radians());
                    let cand = spun(&base.0, &turn, &c);
                    let r = fit(p, &cand, probe_g, probe_o).rank(colour);
                    if r > best.1 {
                        best = (cand, r);
                    }
                }
            }
            if best.1 <= base.1 {
                break;
            }
        }
    }
    best
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
    // Axis turns around both bases; the SO(3) samples around the best one only (about its
    // centre they already cover every orientation).
    let axis_turns = spins(&p.object_obb, 0, p.seed);
    let random_turns =
        spins(&p.object_obb, if colour { 500 } else { 240 }, p.seed)[axis_turns.len()..].to_vec();
    let coarse_g = probes(p.guidance.len(), 200);
    let coarse_o = probes(p.object.len(), 200);
    let c = p.object_obb.center;
    let mut candidates: Vec<Similarity> = bases
        .iter()
        .flat_map(|b| axis_turns.iter().map(move |s| spun(b, s, &c)))
        .collect();
    if let Some(b) = bases.first() {
        candidates.extend(random_turns.iter().map(|s| spun(b, s, &c)));
    }
    let mut turned: Vec<(Similarity, f64)> = candidates
        .par_iter()
        .map(|t| {
            let t = recentred(p, t, &coarse_g, 2);
            (t, fit(p, &t, &coarse_g, &coarse_o).rank(colour))
        })
        .collect();
    turned.sort_by(|a, b| b.1.total_cmp(&a.1));
    // The best eight that differ by more than 20° (neighbours of one good pose rank alike).
    let mut distinct: Vec<(Similarity, f64)> = Vec::new();
    for &(t, r) in &turned {
        if distinct.len() == 8 {
            break;
        }
        if distinct
            .iter()
            .all(|d| d.0.rotation.angle_to(&t.rotation) > 20f64.to_radians())
        {
            distinct.push((t, r));
        }
    }
    let more: Vec<(Similarity, f64)> = distinct
        .par_iter()
        .map(|(t, _)| refine_and_rank(t))
        .collect();
    results.extend(more);
    results
        .into_iter()
        .enumerate()
        .max_by(|a, b| a.1 .1.total_cmp(&b.1 .1).then(b.0.cmp(&a.0)))
        .map(|(_, r)| r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turning_in_place_keeps_the_centre_and_composes_the_rotation() {
        let t = Similarity {
            scale: 1.7,
            rotation: UnitQuaternion::from_euler_angles(-0.4, 0.9, 0.2),
            translation: V3::new(3.0, 0.0, -1.0),
        };
        let c = P3::new(0.1, -0.2, 0.3);
        let spin = UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2);
        let s = spun(&t, &spin, &c);
        let (m0, m1) = (t.matrix(), s.matrix());
        assert!((m0.transform_point(&c) - m1.transform_point(&c)).norm() < 1e-12);
        // A point turned by the spin about c first, then placed by t.
        let q = P3::new(1.0, 0.5, -0.5);
        let turned = c + spin * (q - c);
        assert!((m1.transform_point(&q) - m0.transform_point(&turned)).norm() < 1e-12);
        // 33 axis turns (11 per OBB axis) plus the random ones, none the identity.
        let obb = crate::compose::obb::Obb {
            center: P3::origin(),
            axes: nalgebra::Matrix3::identity(),
            extents: V3::new(3.0, 2.0, 1.0),
        };
        let turns = spins(&obb, 5, 1);
        assert_eq!(turns.len(), 38);
        assert!(turns.iter().all(|r| r.angle() > 0.1));
    }
}
