//! Scale chosen by fit, not by ICP alone. Trimmed ICP under-estimates the scale of a part whose
//! guidance has holes at its rim (a thin board, a book): at a too-small scale the rim points are
//! the worst pairs and are trimmed, so nothing pulls the scale back up. Here a few scales around
//! the ICP estimate are each fitted with the scale held fixed and ranked both ways
//! ([`super::global::Fit::rank`]); a step is taken only when it strictly improves the rank.

use super::cloud::Cloud;
use super::global::{fit, Problem};
use super::icp::{trimmed_icp, IcpOptions, Matcher};
use crate::pose::Similarity;

/// `t` with scale `s`, the object's centre `c` (object frame) kept in place.
pub fn rescaled(t: &Similarity, s: f64, c: &crate::mesh::P3) -> Similarity {
    Similarity {
        scale: s,
        translation: t.translation + (t.scale - s) * (t.rotation * c.coords),
        ..*t
    }
}

/// Search the scale around `t` in relative steps of ±3% and ±6%, then ±1.5% around the best,
/// each candidate refined by a short fixed-scale ICP. Returns the best pose and its rank.
#[allow(clippy::too_many_arguments)]
pub fn search(
    p: &Problem,
    matcher: &Matcher,
    guidance: &Cloud,
    t: Similarity,
    icp: &IcpOptions,
    colour: bool,
    probe_g: &[usize],
    probe_o: &[usize],
) -> (Similarity, f64) {
    use rayon::prelude::*;
    let c = p.object_obb.center;
    let mut best = (t, fit(p, &t, probe_g, probe_o).rank(colour));
    for steps in [&[-0.06, -0.03, 0.03, 0.06][..], &[-0.015, 0.015][..]] {
        let base = best.0;
        let tried: Vec<(Similarity, f64)> = steps
            .par_iter()
            .map(|f| {
                let s = (base.scale * (1.0 + f)).clamp(icp.scale_lo, icp.scale_hi);
                let fixed = IcpOptions {
                    iterations: 20,
                    scale_lo: s,
                    scale_hi: s,
                    ..*icp
                };
                let (r, _) = trimmed_icp(
                    &p.object.points,
                    matcher,
                    guidance,
                    rescaled(&base, s, &c),
                    &fixed,
                );
                (r, fit(p, &r, probe_g, probe_o).rank(colour))
            })
            .collect();
        for cand in tried {
            if cand.1 > best.1 {
                best = cand;
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{P3, V3};
    use nalgebra::UnitQuaternion;

    #[test]
    fn rescaling_keeps_the_centre_and_scales_offsets() {
        let t = Similarity {
            scale: 2.0,
            rotation: UnitQuaternion::from_euler_angles(0.3, -0.2, 1.1),
            translation: V3::new(1.0, -2.0, 0.5),
        };
        let c = P3::new(0.2, 0.1, -0.3);
        let r = rescaled(&t, 2.5, &c);
        let m0 = t.matrix();
        let m1 = r.matrix();
        assert!((m0.transform_point(&c) - m1.transform_point(&c)).norm() < 1e-12);
        // A point 1 away from the centre ends 2.5 away from the centre's image.
        let q = c + V3::new(0.0, 1.0, 0.0);
        let d = (m1.transform_point(&q) - m1.transform_point(&c)).norm();
        assert!((d - 2.5).abs() < 1e-12);
    }

    #[test]
    fn recovers_the_scale_of_a_thin_board_with_a_ragged_rim() {
        use crate::compose::kdtree::KdTree;
        use crate::compose::obb::Obb;
        // A 1 × 0.6 × 0.03 board; its guidance is the board at scale 2 with a hole in the middle
        // and half the points of a ragged strip along one long rim missing.
        let mesh = crate::shapes::cuboid(V3::new(1.0, 0.6, 0.03));
        let vis = crate::shapes::plain_visual(&mesh);
        let object = Cloud::sample(&vis, 5000, 1);
        let truth = Similarity {
            scale: 2.0,
            rotation: UnitQuaternion::from_euler_angles(0.2, -0.1, 0.7),
            translation: V3::new(0.5, 1.0, -0.3),
        };
        let kept = Cloud::sample(&vis, 2500, 2);
        let mut guidance = Cloud::default();
        for (i, q) in kept.points.iter().enumerate() {
            let hole = q.x.abs() < 0.2 && q.y.abs() < 0.15;
            let ragged = q.y > 0.22 && i % 2 == 0;
            if !hole && !ragged {
                guidance.points.push(truth.matrix().transform_point(q));
                guidance.normals.push(V3::z());
                guidance.colours.push([0.5; 3]);
            }
        }
        let (ot, gt) = (KdTree::new(&object.points), KdTree::new(&guidance.points));
        let p = Problem {
            object: &object,
            object_tree: &ot,
            guidance: &guidance,
            guidance_tree: &gt,
            object_obb: Obb::of_points(&object.points),
            guidance_obb: Obb::of_points(&guidance.points),
            scale0: 2.0,
            seed: 3,
            occlusion: None,
        };
        let icp = IcpOptions {
            iterations: 60,
            keep: 0.8,
            scale_lo: 2.0 / 1.4,
            scale_hi: 2.0 * 1.4,
            tolerance: 1e-7,
        };
        // Start 7% too small, right pose otherwise.
        let start = rescaled(&truth, 1.86, &P3::origin());
        let probe_g = crate::compose::global::probes(guidance.len(), 700);
        let probe_o = crate::compose::global::probes(object.len(), 700);
        let m = Matcher::Geometry(&ot);
        let (t, _) = search(&p, &m, &guidance, start, &icp, false, &probe_g, &probe_o);
        // The rank is measured within τ = 2% of the diagonal, so it separates scales a few per
        // cent apart, not finer: from 7% low the search must end within the benchmark's 3%.
        assert!((t.scale / 2.0 - 1.0).abs() < 0.03, "scale {}", t.scale);
        assert!(t.rotation.angle_to(&truth.rotation).to_degrees() < 1.0);
        // At the truth every guidance point has an object sample within τ (up to the sampling).
        let f = fit(&p, &truth, &probe_g, &probe_o);
        assert!(f.guidance_explained > 0.98, "{f:?}");
        // Object points are covered except in the middle hole: 0.4 × 0.3 on both faces of a
        // surface of 2·0.6 + 2·1.6·0.03 = 1.296, so 1 − 0.24 / 1.296 = 0.815 (the hole's rim
        // within τ of the guidance adds a little, the sampling takes a little).
        assert!((f.object_covered - 0.815).abs() < 0.02, "{f:?}");
    }
}
