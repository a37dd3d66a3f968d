//! The last local fit: robust point-to-plane ICP with scale, and the fit measure of the guard.
//!
//! Entry points:
//! - [`plane_icp`]: Gauss–Newton on the point-to-plane distances of the guidance points to the
//!   object's surface (the object's sample normals), over rotation, translation and (bounded)
//!   scale, with trimming and Huber weights. After the trimmed point-to-point ICP
//!   ([`super::icp`]) stops a little short on noisy guidance (its pairs are sample to sample, so
//!   the sample spacing and the noise pull the pose), the plane distances let the surface slide
//!   along itself and go all the way in; the scale comes from how the surfaces overlap.
//! - [`plane_icp_offset`]: the same fit with a normal offset δ shared by the whole object
//!   (residual n·(sRx + t − g) + δ): a reconstruction that fattens or erodes the guidance by a
//!   roughly constant depth then stops reading as scale; [`offset_stage`] runs it in the
//!   pipeline and offers its pose to the guard.
//! - [`offset_fit`]: the guard's fit with the pose's own best offset taken out.
//! - [`scale_offset_correlation`]: how far an object's shape lets scale and offset be told
//!   apart (1 for a sphere or a cube: not at all).
//! - [`surface_fit`]: the mean truncated distance from guidance points to the posed object's
//!   surface; the guard in [`super::compose`] keeps a stage's pose only when this does not grow.

use super::cloud::Cloud;
use super::icp::Matcher;
use super::kdtree::KdTree;
use crate::mesh::{P3, V3};
use crate::pose::Similarity;
use nalgebra::{SMatrix, SVector, UnitQuaternion};

/// Options of [`plane_icp`].
#[derive(Clone, Copy, Debug)]
pub struct PlaneIcpOptions {
    pub iterations: usize,
    /// Fraction of the pairs kept (the closest by point distance).
    pub keep: f64,
    /// Huber threshold in robust standard deviations (1.4826 × median |residual|).
    pub huber: f64,
    /// Estimate the scale (else it stays).
    pub scale: bool,
    pub scale_lo: f64,
    pub scale_hi: f64,
    /// Stop when a step moves the pairs by less than this (guidance units).
    pub tolerance: f64,
    /// Fit a normal offset δ (guidance outside the object's surface by δ), |δ| ≤ `offset_max`
    /// (guidance units).
    pub offset: bool,
    pub offset_max: f64,
    /// Prior on δ: the cost gains `offset_prior × Σw × δ²`, so where scale and offset cannot be
    /// told apart (a cube about its centre) the scale keeps it and δ stays 0.
    pub offset_prior: f64,
}

impl Default for PlaneIcpOptions {
    fn default() -> Self {
        PlaneIcpOptions {
            iterations: 30,
            keep: 0.85,
            huber: 1.5,
            scale: true,
            scale_lo: 0.0,
            scale_hi: f64::INFINITY,
            tolerance: 0.0,
            offset: false,
            offset_max: 0.0,
            offset_prior: 0.05,
        }
    }
}

/// `c + e^σ·R(ω)·(x − c) + τ` after `t`: the increment of a Gauss–Newton step about `c`.
fn apply(t: &Similarity, omega: &V3, tau: &V3, sigma: f64, c: &P3, lo: f64, hi: f64) -> Similarity {
    let r = UnitQuaternion::from_scaled_axis(*omega);
    let f = (t.scale * sigma.exp()).clamp(lo, hi) / t.scale;
    Similarity {
        scale: t.scale * f,
        rotation: r * t.rotation,
        translation: c.coords + f * (r * (t.translation - c.coords)) + tau,
    }
}

/// Robust point-to-plane ICP of `object` (points and normals, object frame) onto the guidance
/// points, from `init`. Pairs: each guidance point with the object sample `matcher` gives for
/// it (geometry or geometry + colour). Returns the pose and the robust RMS of the plane
/// distances of the kept pairs (guidance units).
pub fn plane_icp(
    object: &Cloud,
    matcher: &Matcher,
    guidance: &Cloud,
    init: Similarity,
    o: &PlaneIcpOptions,
) -> (Similarity, f64) {
    let (t, rms, _) = plane_icp_offset(object, matcher, guidance, init, o);
    (t, rms)
}

/// [`plane_icp`] that also returns the normal offset δ it fitted (0 unless `o.offset`): the
/// guidance lies δ outside the posed object's surface (δ < 0: inside, an eroded part).
pub fn plane_icp_offset(
    object: &Cloud,
    matcher: &Matcher,
    guidance: &Cloud,
    init: Similarity,
    o: &PlaneIcpOptions,
) -> (Similarity, f64, f64) {
    let mut t = init;
    let mut delta = 0.0f64;
    let mut rms = f64::INFINITY;
    let n = guidance.len();
    // (point distance², plane residual, guidance index, object index)
    let mut pairs: Vec<(f64, usize, usize)> = Vec::with_capacity(n);
    // Each guidance point's partner in the previous iteration and its certificate: the next
    // search starts there, or is not needed.
    let mut prev = vec![super::kdtree::Warm::default(); n];
    for _ in 0..o.iterations {
        let Some(inv) = t.matrix().try_inverse() else {
            break;
        };
        let m = t.matrix();
        pairs.clear();
        for gi in 0..n {
            let q = inv.transform_point(&guidance.points[gi]);
            if let Some((oi, _)) = matcher.nearest_warm(&q, &guidance.colours[gi], &mut prev[gi]) {
                let p = m.transform_point(&object.points[oi]);
                pairs.push(((p - guidance.points[gi]).norm_squared(), gi, oi));
            }
        }
        let dof = 6 + o.scale as usize + o.offset as usize;
        if pairs.len() < dof + 1 {
            break;
        }
        let k = ((pairs.len() as f64 * o.keep) as usize).clamp(dof + 1, pairs.len());
        super::icp::smallest_sorted(&mut pairs, k, |p| (p.0, p.1));
        let kept = &pairs[..k];
        // Residuals in the guidance frame.
        let rows: Vec<(P3, V3, f64)> = kept
            .iter()
            .map(|&(_, gi, oi)| {
                let p = m.transform_point(&object.points[oi]);
                let nrm = t.rotation * object.normals[oi];
                (p, nrm, nrm.dot(&(p - guidance.points[gi])) + delta)
            })
            .collect();
        let mut abs: Vec<f64> = rows.iter().map(|r| r.2.abs()).collect();
        let half = abs.len() / 2;
        let sigma = 1.4826 * super::icp::nth_smallest(&mut abs, half);
        rms = (rows.iter().map(|r| r.2 * r.2).sum::<f64>() / k as f64).sqrt();
        let thr = (o.huber * sigma).max(1e-300);
        let w = |r: f64| if r.abs() <= thr { 1.0 } else { thr / r.abs() };
        let wsum: f64 = rows.iter().map(|r| w(r.2)).sum();
        let c = P3::from(
            rows.iter()
                .fold(V3::zeros(), |a, r| a + w(r.2) * r.0.coords)
                / wsum,
        );
        let mut h = SMatrix::<f64, 8, 8>::zeros();
        let mut g = SVector::<f64, 8>::zeros();
        for (p, nrm, r) in &rows {
            let j = jacobian_row(p - c, nrm, o.scale, o.offset);
            let wi = w(*r);
            h += wi * j * j.transpose();
            g += wi * *r * j;
        }
        // Directions the surface does not constrain (a sphere's spin, a plane's slide) stay put:
        // a tiny damping relative to the largest curvature of the problem.
        let damp = 1e-9 * (0..8).map(|i| h[(i, i)]).fold(0.0, f64::max);
        for i in 0..8 {
            h[(i, i)] += damp.max(1e-300);
        }
        if !o.scale {
            h[(6, 6)] = 1.0;
            g[6] = 0.0;
        }
        if o.offset {
            // The prior μ·δ² on the offset itself (not on the step).
            let mu = o.offset_prior * wsum;
            h[(7, 7)] += mu;
            g[7] += mu * delta;
        } else {
            h[(7, 7)] = 1.0;
            g[7] = 0.0;
        }
        let Some(chol) = h.cholesky() else {
            break;
        };
        let x = -chol.solve(&g);
        let omega = V3::new(x[0], x[1], x[2]);
        let tau = V3::new(x[3], x[4], x[5]);
        let next = apply(&t, &omega, &tau, x[6], &c, o.scale_lo, o.scale_hi);
        let next_delta = (delta + x[7]).clamp(-o.offset_max, o.offset_max);
        let nm = next.matrix();
        let moved = kept
            .iter()
            .step_by((k / 64).max(1))
            .map(|&(_, _, oi)| {
                let p = &object.points[oi];
                (nm.transform_point(p) - m.transform_point(p)).norm()
            })
            .fold(0.0, f64::max)
            .max((next_delta - delta).abs());
        t = next;
        delta = next_delta;
        if moved <= o.tolerance {
            break;
        }
    }
    (t, rms, delta)
}

/// Mean over `guidance` of the distance to the surface of the object placed by `t`, each
/// truncated at `cap` (guidance units): the point-to-plane distance to the nearest object
/// sample when the point lies within `2 × spacing` of it along the surface (so the sample
/// spacing is no floor), else the point distance. Lower is better.
pub fn surface_fit(
    object: &Cloud,
    tree: &KdTree,
    spacing: f64,
    guidance: &[P3],
    t: &Similarity,
    cap: f64,
) -> f64 {
    let d = surface_distances(object, tree, spacing, guidance, t, cap);
    d.iter().sum::<f64>() / guidance.len().max(1) as f64
}

/// A point's distance to the object's surface near its nearest object point `j` (object
/// units): the signed distance along `j`'s normal and `true` when the point lies within two
/// spacings of `j`'s tangent plane's foot, else the distance to `j` itself and `false`; `None`
/// for an empty tree. Shared by [`surface_distances`] and [`offset_distances`].
fn plane_distance(object: &Cloud, tree: &KdTree, spacing: f64, x: &P3) -> Option<(f64, bool)> {
    let (j, d2) = tree.nearest(x)?;
    let along = (x - object.points[j]).dot(&object.normals[j]);
    let tangential = (d2 - along * along).max(0.0).sqrt();
    Some(if tangential < 2.0 * spacing {
        (along, true)
    } else {
        (d2.sqrt(), false)
    })
}

/// The truncated distances [`surface_fit`] averages, one per guidance point.
pub fn surface_distances(
    object: &Cloud,
    tree: &KdTree,
    spacing: f64,
    guidance: &[P3],
    t: &Similarity,
    cap: f64,
) -> Vec<f64> {
    let Some(inv) = t.matrix().try_inverse() else {
        return vec![cap; guidance.len()];
    };
    guidance
        .iter()
        .map(|q| {
            let d = match plane_distance(object, tree, spacing, &inv.transform_point(q)) {
                Some((v, true)) => t.scale * v.abs(),
                Some((v, false)) => t.scale * v,
                None => cap,
            };
            d.min(cap)
        })
        .collect()
}

/// [`surface_fit`] with the pose's own normal offset taken out: δ* is the median signed
/// distance (guidance outside the surface > 0) of the points that pair with a plane within
/// `cap`, held within ±`offset_max`; each of those points then counts |distance − δ*|. A
/// guidance part fattened or eroded by a uniform depth fits its object at the true scale as well
/// as an exact part would, and no longer favours the scale that absorbs the depth. Returns the
/// fit and δ* (guidance units).
pub fn offset_fit(
    object: &Cloud,
    tree: &KdTree,
    spacing: f64,
    guidance: &[P3],
    t: &Similarity,
    cap: f64,
    offset_max: f64,
) -> (f64, f64) {
    let (d, delta) = offset_distances(object, tree, spacing, guidance, t, cap, offset_max);
    (d.iter().sum::<f64>() / guidance.len().max(1) as f64, delta)
}

/// The truncated distances [`offset_fit`] averages, one per guidance point, and δ*.
pub fn offset_distances(
    object: &Cloud,
    tree: &KdTree,
    spacing: f64,
    guidance: &[P3],
    t: &Similarity,
    cap: f64,
    offset_max: f64,
) -> (Vec<f64>, f64) {
    let Some(inv) = t.matrix().try_inverse() else {
        return (vec![cap; guidance.len()], 0.0);
    };
    // (distance, signed along the normal?) per point.
    let d: Vec<(f64, bool)> = guidance
        .iter()
        .map(
            |q| match plane_distance(object, tree, spacing, &inv.transform_point(q)) {
                Some((v, plane)) => (t.scale * v, plane),
                None => (cap, false),
            },
        )
        .collect();
    let mut signed: Vec<f64> = d
        .iter()
        .filter(|x| x.1 && x.0.abs() < cap)
        .map(|x| x.0)
        .collect();
    let delta = if signed.is_empty() {
        0.0
    } else {
        let half = signed.len() / 2;
        super::icp::nth_smallest(&mut signed, half).clamp(-offset_max, offset_max)
    };
    let out = d
        .iter()
        .map(|&(v, plane)| if plane { (v - delta).abs() } else { v }.min(cap))
        .collect();
    (out, delta)
}

/// One point's row of the point-to-plane Jacobian about the centroid, `d = p − c`: rotation
/// (d × n), translation (n), scale (n·d, or 0 when scale is held) and normal offset (1, or 0
/// when it is held).
fn jacobian_row(d: V3, nrm: &V3, scale: bool, offset: bool) -> SVector<f64, 8> {
    let a = d.cross(nrm);
    SVector::<f64, 8>::from_column_slice(&[
        a.x,
        a.y,
        a.z,
        nrm.x,
        nrm.y,
        nrm.z,
        if scale { nrm.dot(&d) } else { 0.0 },
        if offset { 1.0 } else { 0.0 },
    ])
}

/// The squared correlation of the scale and offset estimates of a point-to-plane fit on the
/// whole of `object`'s surface (samples with normals), rotation and translation free: 1 where
/// a scale change and a uniform normal offset move the surface alike (a sphere, a cube about its
/// centre), lower the more the support distances n·(p − c) vary over the surface (an elongated
/// box ≈ 0.8, a hollow part with inner walls lower). A property of the shape alone.
pub fn scale_offset_correlation(object: &Cloud) -> f64 {
    let n = object.points.len().max(1) as f64;
    let c = P3::from(object.points.iter().fold(V3::zeros(), |a, p| a + p.coords) / n);
    let mut h = SMatrix::<f64, 8, 8>::zeros();
    for (p, nrm) in object.points.iter().zip(&object.normals) {
        let j = jacobian_row(p - c, nrm, true, true);
        h += j * j.transpose();
    }
    let damp = 1e-9 * (0..8).map(|i| h[(i, i)]).fold(0.0, f64::max);
    for i in 0..8 {
        h[(i, i)] += damp.max(1e-300);
    }
    match h.try_inverse() {
        Some(cov) => {
            let v = cov[(6, 6)] * cov[(7, 7)];
            if v > 0.0 {
                (cov[(6, 7)] * cov[(6, 7)] / v).min(1.0)
            } else {
                1.0
            }
        }
        None => 1.0,
    }
}

/// The point-to-plane fit with a normal offset beside the scale (see [`super::OFFSET_MAX`]): a
/// reconstruction's blur fattens or erodes the guidance by a roughly constant depth, which a
/// similarity alone reads as scale. From then on the guard judges every pose with its own
/// offset taken out.
pub(super) fn offset_stage(
    object: &Cloud,
    matcher: &Matcher,
    g_icp: &Cloud,
    pl: &PlaneIcpOptions,
    icp: &super::icp::IcpOptions,
    guard: &mut super::guard::Guard,
    rms: &mut f64,
) {
    let s0 = guard.pose().scale;
    let po = PlaneIcpOptions {
        scale_lo: (s0 / 1.10).max(icp.scale_lo),
        scale_hi: (s0 * 1.10).min(icp.scale_hi),
        offset: true,
        offset_max: super::OFFSET_MAX * s0 * object.diagonal(),
        ..*pl
    };
    let (t, r, _) = plane_icp_offset(object, matcher, g_icp, guard.pose(), &po);
    guard.measure_offsets(super::OFFSET_MAX);
    if guard.offer("point_to_plane_offset", t) {
        *rms = r;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn sampled(mesh: &crate::mesh::Mesh, n: usize) -> Cloud {
        let vis = crate::shapes::plain_visual(mesh);
        Cloud::sample(&vis, n, 3)
    }

    /// Analytic case: the guidance is the object's own samples moved by a known motion (so the
    /// true pairs have zero residual); from a start 6° and 2–3 % of the size away, point-to-plane
    /// ICP must recover it to 1e-6 relative. `axis_only`: the object is a prism about z, which a
    /// turn about z by one facet maps onto itself, so the start turns about an axis ⟂ z and only
    /// the axis direction (with translation and scale) is compared.
    fn recovers(mesh: crate::mesh::Mesh, scale: bool, axis_only: bool) {
        let obj = sampled(&mesh, 3000);
        let truth = Similarity {
            scale: if scale { 1.3 } else { 1.0 },
            rotation: UnitQuaternion::from_euler_angles(0.7, -0.4, 1.1),
            translation: V3::new(0.3, -0.8, 1.7),
        };
        let g = obj.transformed(&truth.matrix());
        let mut rng = Rng::new(5);
        let mut axis = V3::new(rng.normal(), rng.normal(), rng.normal());
        if axis_only {
            axis.z = 0.0;
        }
        let turn = UnitQuaternion::from_scaled_axis(axis.normalize() * 6f64.to_radians());
        let init = Similarity {
            scale: truth.scale * if scale { 1.02 } else { 1.0 },
            rotation: truth.rotation * turn,
            translation: truth.translation + V3::new(0.02, -0.01, 0.015),
        };
        let tree = KdTree::new(&obj.points);
        let o = PlaneIcpOptions {
            iterations: 100,
            keep: 1.0,
            scale,
            scale_lo: 0.5,
            scale_hi: 2.0,
            tolerance: 1e-14,
            ..Default::default()
        };
        let (t, rms) = plane_icp(&obj, &Matcher::Geometry(&tree), &g, init, &o);
        let size = g.diagonal();
        let angle = if axis_only {
            (t.rotation * V3::z()).angle(&(truth.rotation * V3::z()))
        } else {
            t.rotation.angle_to(&truth.rotation)
        };
        let dt = (t.translation - truth.translation).norm() / truth.translation.norm();
        assert!(angle < 1e-6, "rotation error {angle:e} rad");
        assert!(dt < 1e-6, "translation error {dt:e} relative");
        assert!(
            (t.scale / truth.scale - 1.0).abs() < 1e-6,
            "scale {}",
            t.scale
        );
        assert!(rms < 1e-6 * size, "rms {rms:e}");
    }

    #[test]
    fn point_to_plane_recovers_a_box_motion_to_1e_6() {
        recovers(crate::shapes::cuboid(V3::new(1.0, 0.6, 0.3)), false, false);
    }

    #[test]
    fn point_to_plane_recovers_a_box_similarity_to_1e_6() {
        recovers(crate::shapes::cuboid(V3::new(1.0, 0.6, 0.3)), true, false);
    }

    #[test]
    fn point_to_plane_recovers_a_cylinder_motion_and_scale_to_1e_6() {
        recovers(crate::shapes::cylinder(0.3, 1.0, 48), true, true);
    }

    /// Analytic case for the offset: the guidance is a box's samples pushed out along their
    /// normals by δ = 1 % of the diagonal (a fattened reconstruction), then moved by a known
    /// similarity. A box fattened by δ has half-extents a + δ, so a similarity alone must read a
    /// wrong scale (checked: > 2 % off); the offset fit must return the true scale to 1e-4 and
    /// δ to 1 %; the guard's `offset_fit` must measure δ and prefer the true pose.
    #[test]
    fn offset_fit_separates_a_fattened_part_from_scale() {
        let obj = sampled(&crate::shapes::cuboid(V3::new(1.0, 0.6, 0.3)), 4000);
        let diag = obj.diagonal();
        let delta = 0.01 * diag;
        let truth = Similarity {
            scale: 1.3,
            rotation: UnitQuaternion::from_euler_angles(0.7, -0.4, 1.1),
            translation: V3::new(0.3, -0.8, 1.7),
        };
        let mut fat = sampled(&crate::shapes::cuboid(V3::new(1.0, 0.6, 0.3)), 2500);
        for (p, n) in fat.points.iter_mut().zip(&fat.normals) {
            *p += n * delta;
        }
        let g = fat.transformed(&truth.matrix());
        let tree = KdTree::new(&obj.points);
        let base = PlaneIcpOptions {
            iterations: 100,
            keep: 0.9,
            scale_lo: 0.5,
            scale_hi: 2.0,
            tolerance: 1e-12,
            ..Default::default()
        };
        let (plain, _) = plane_icp(&obj, &Matcher::Geometry(&tree), &g, truth, &base);
        assert!(
            (plain.scale / truth.scale - 1.0).abs() > 0.02,
            "premise: a similarity alone reads the fattening as scale ({})",
            plain.scale / truth.scale
        );
        let start = Similarity {
            scale: truth.scale * 1.05,
            ..truth
        };
        let o = PlaneIcpOptions {
            offset: true,
            offset_max: 0.05 * truth.scale * diag,
            offset_prior: 0.0,
            ..base
        };
        let (t, _, d) = plane_icp_offset(&obj, &Matcher::Geometry(&tree), &g, start, &o);
        assert!(
            (t.scale / truth.scale - 1.0).abs() < 1e-3,
            "scale {}",
            t.scale / truth.scale
        );
        let want = delta * truth.scale;
        assert!((d / want - 1.0).abs() < 0.05, "offset {d} vs {want}");
        let spacing = (2.0 * (0.6 + 0.3 + 0.18) / 4000.0f64).sqrt();
        let cap = 0.03 * truth.scale * diag;
        let (f_true, d_true) = offset_fit(&obj, &tree, spacing, &g.points, &truth, cap, cap);
        let (f_plain, _) = offset_fit(&obj, &tree, spacing, &g.points, &plain, cap, cap);
        assert!(
            (d_true / want - 1.0).abs() < 0.1,
            "guard offset {d_true} vs {want}"
        );
        assert!(f_true < f_plain, "{f_true} vs {f_plain}");
    }

    /// Analytic values: a cube about its centre cannot tell scale from offset (n·(p − c) is the
    /// half-side on every face: 1); a 1 × 0.6 × 0.3 box has support distances 0.5, 0.3, 0.15
    /// over face areas 0.36, 0.6, 1.2 (each ×2), so corr² = E[x]²/E[x²] = 0.25²/0.0792 = 0.789.
    #[test]
    fn scale_offset_correlation_matches_the_support_distances() {
        let cube = sampled(&crate::shapes::cuboid(V3::new(1.0, 1.0, 1.0)), 6000);
        let box_ = sampled(&crate::shapes::cuboid(V3::new(1.0, 0.6, 0.3)), 6000);
        let c = scale_offset_correlation(&cube);
        let b = scale_offset_correlation(&box_);
        assert!(c > 0.99, "cube {c}");
        let want = 0.25f64.powi(2) / ((0.09 + 0.054 + 0.027) / 2.16);
        assert!((b - want).abs() < 0.02, "box {b} vs {want}");
    }

    #[test]
    fn surface_fit_is_zero_at_the_truth_and_grows_off_it() {
        let obj = sampled(&crate::shapes::cuboid(V3::new(1.0, 0.6, 0.3)), 4000);
        let other = sampled(&crate::shapes::cuboid(V3::new(1.0, 0.6, 0.3)), 500);
        let tree = KdTree::new(&obj.points);
        let spacing = (2.0 * (0.6 + 0.3 + 0.18) / 4000.0f64).sqrt();
        let at = surface_fit(
            &obj,
            &tree,
            spacing,
            &other.points,
            &Similarity::identity(),
            1.0,
        );
        // Not quite 0: a point near an edge may pair with a sample across it.
        assert!(at < 5e-4, "{at}");
        let off = Similarity {
            translation: V3::new(0.0, 0.0, 0.01),
            ..Similarity::identity()
        };
        let moved: Vec<P3> = other
            .points
            .iter()
            .map(|p| off.matrix().transform_point(p))
            .collect();
        let f = surface_fit(&obj, &tree, spacing, &moved, &Similarity::identity(), 1.0);
        // The ±z faces (area 2 × 0.6 of 2.16) are 1 cm off; the others slide along themselves.
        assert!(f > 0.002 && f < 0.01 && f > 10.0 * at, "{f} vs {at}");
    }
}
