//! The reconstruction's blur as a depth that follows the surface's curvature (issue #34).
//!
//! A reconstruction that blurs a signed distance field φ by a Gaussian of σ moves its surface
//! inward by σ²·H, H the mean curvature (positive where convex): on the surface Δφ = κ₁ + κ₂ = 2H,
//! and the blur adds σ²/2·Δφ to φ. Convex parts erode, concave ones dilate, flat ones stay. On a
//! near-sphere a uniform erosion and a smaller size are one parameter (the offset stage is off
//! there, [`super::OFFSET_CORRELATION_MAX`]), so the fit reads the erosion as size. σ² is not
//! the item's but the scene's, and the anchor, whose curvature varies, measures it.
//!
//! Entry points:
//! - [`mean_curvature`]: H at each sample of an object (object units⁻¹), from the signed plane
//!   distances of a stencil around it;
//! - [`from_anchor`]: σ² (guidance units²) from the anchor at its placed pose, the robust slope
//!   of the guidance's signed offset against −H, with its standard error;
//! - [`apply`]: a near-sphere item refitted with the erosion σ²·H held, taken when it fits the
//!   guidance with that erosion taken out not worse than the current pose does.

use super::cloud::Cloud;
use super::guard::StageFit;
use super::icp::Matcher;
use super::kdtree::KdTree;
use super::placed::{Item, Placed};
use super::plane_icp::{plane_distance, plane_icp_biased, PlaneIcpOptions};
use crate::mesh::{P3, V3};
use crate::pose::Similarity;
use serde::Serialize;

/// The stencil's half-width, as a fraction of the object's diagonal: the scale at which the
/// curvature is measured (the bench's blurs are 1–5 % of an item's diagonal).
pub const STENCIL: f64 = 0.05;

/// Anchor samples with another wall within this fraction of the diagonal behind them are left
/// out of the blur's measure ([`thin_at`]).
pub const THIN: f64 = 0.06;

/// The blur is used only when its σ² is this many standard errors above 0.
pub const Z_MIN: f64 = 3.0;

/// What [`apply`] did to one item.
#[derive(Clone, Debug, Serialize)]
pub struct BlurReport {
    /// σ² of the scene (guidance units²) and its standard error, from the anchor.
    pub sigma2: f64,
    pub sigma2_se: f64,
    /// Why it did not run, if it did not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skipped: Option<&'static str>,
    /// The fit with the erosion taken out (guidance units) at the current pose and the refit's.
    pub fit_before: f64,
    pub fit_after: f64,
    pub scale_ratio: f64,
    pub taken: bool,
}

/// Mean curvature at sample `i` of `object` (object units⁻¹, convex > 0): the least-squares
/// fit of h = −H·ρ²/2 + g·x to the neighbours within `a` on the same side (normals within 60°),
/// x their offset along the sample's tangent plane (ρ = |x|; g takes a tilt of the sample's
/// normal, a facet's against the smooth surface's) and h their height over it; a sphere of
/// radius R gives 1/R. 0 with fewer than six neighbours.
fn curvature_at(object: &Cloud, tree: &KdTree, a: f64, i: usize, near: &mut Vec<usize>) -> f64 {
    let (p, n) = (object.points[i], object.normals[i]);
    let t1 = if n.x.abs() < 0.9 { V3::x() } else { V3::y() };
    let t1 = (t1 - n * n.dot(&t1)).normalize();
    let t2 = n.cross(&t1);
    tree.within(&p, a, near);
    let mut ata = nalgebra::Matrix3::<f64>::zeros();
    let mut atb = V3::zeros();
    let mut k = 0;
    for &j in near.iter() {
        if object.normals[j].dot(&n) < 0.5 {
            continue;
        }
        let d = object.points[j] - p;
        let (x, y, h) = (d.dot(&t1), d.dot(&t2), d.dot(&n));
        let row = V3::new(-(x * x + y * y) / 2.0, x, y);
        ata += row * row.transpose();
        atb += row * h;
        k += 1;
    }
    if k < 6 {
        return 0.0;
    }
    ata.try_inverse().map_or(0.0, |m| (m * atb).x)
}

/// [`curvature_at`] of every sample of `object`.
pub fn mean_curvature(object: &Cloud, tree: &KdTree, a: f64) -> Vec<f64> {
    let mut near = Vec::new();
    (0..object.len())
        .map(|i| curvature_at(object, tree, a, i, &mut near))
        .collect()
}

/// Whether sample `i` faces another wall of `object` within `depth` behind it (a sample whose
/// normal opposes its own, less than `depth` along −n): a wall thinner than the blur's reach,
/// which the reconstruction thickens instead of eroding by σ²·H.
fn thin_at(object: &Cloud, tree: &KdTree, depth: f64, i: usize, near: &mut Vec<usize>) -> bool {
    let (p, n) = (object.points[i], object.normals[i]);
    tree.within(&(p - n * (depth / 2.0)), depth / 2.0, near);
    near.iter().any(|&j| object.normals[j].dot(&n) < -0.5)
}

/// The guidance points within a plane's reach of the object posed by `t`: (signed distance
/// along the normal in guidance units, guidance outside > 0; the paired sample's index).
fn signed_pairs(
    object: &Cloud,
    tree: &KdTree,
    spacing: f64,
    guidance: &[P3],
    t: &Similarity,
    cap: f64,
) -> Vec<(f64, usize)> {
    let Some(inv) = t.matrix().try_inverse() else {
        return Vec::new();
    };
    guidance
        .iter()
        .filter_map(|q| {
            let x = inv.transform_point(q);
            let (v, plane) = plane_distance(object, tree, spacing, &x)?;
            let d = t.scale * v;
            (plane && d.abs() < cap).then(|| (d, tree.nearest(&x).map_or(0, |(j, _)| j)))
        })
        .collect()
}

/// σ² of the scene's blur (guidance units²) and its standard error, from the anchor placed by
/// `t`: the guidance's signed offsets d against each paired sample's −H/s, d = c − σ²·H/s, fitted
/// by Huber-weighted least squares (c takes a uniform offset the pose kept). Samples whose radius
/// of curvature is under twice the stencil (rims, edges, thin parts) are left out: there the
/// stencil is no second-order measure. `None` with fewer than 50 pairs.
pub fn from_anchor(
    object: &Cloud,
    tree: &KdTree,
    spacing: f64,
    guidance: &[P3],
    t: &Similarity,
) -> Option<(f64, f64)> {
    let a = STENCIL * object.diagonal();
    let cap = 0.03 * t.scale * object.diagonal();
    let (mut near, mut near2) = (Vec::new(), Vec::new());
    let rows: Vec<(f64, f64)> = signed_pairs(object, tree, spacing, guidance, t, cap)
        .into_iter()
        .filter(|&(_, j)| !thin_at(object, tree, THIN * object.diagonal(), j, &mut near))
        .filter_map(|(d, j)| {
            let h = curvature_at(object, tree, a, j, &mut near2);
            (h.abs() * a < 0.5).then_some((-h / t.scale, d))
        })
        .collect();
    if rows.len() < 50 {
        return None;
    }
    let (mut c, mut beta, mut se) = (0.0, 0.0, f64::INFINITY);
    let mut w = vec![1.0; rows.len()];
    for _ in 0..10 {
        let sw: f64 = w.iter().sum();
        let mu = rows.iter().zip(&w).map(|(r, w)| w * r.0).sum::<f64>() / sw;
        let md = rows.iter().zip(&w).map(|(r, w)| w * r.1).sum::<f64>() / sw;
        let sxx: f64 = rows
            .iter()
            .zip(&w)
            .map(|(r, w)| w * (r.0 - mu).powi(2))
            .sum();
        let sxy: f64 = rows
            .iter()
            .zip(&w)
            .map(|(r, w)| w * (r.0 - mu) * (r.1 - md))
            .sum();
        if sxx <= 0.0 {
            return None;
        }
        beta = sxy / sxx;
        c = md - beta * mu;
        let res: Vec<f64> = rows.iter().map(|r| r.1 - c - beta * r.0).collect();
        let mut abs: Vec<f64> = res.iter().map(|r| r.abs()).collect();
        let half = abs.len() / 2;
        let sigma = 1.4826 * super::icp::nth_smallest(&mut abs, half);
        let thr = (1.5 * sigma).max(1e-300);
        let s2 = res.iter().zip(&w).map(|(r, w)| w * r * r).sum::<f64>() / (sw - 2.0).max(1.0);
        se = (s2 / sxx).sqrt();
        for (wi, r) in w.iter_mut().zip(&res) {
            *wi = if r.abs() <= thr { 1.0 } else { thr / r.abs() };
        }
    }
    let _ = c;
    Some((beta, se))
}

/// The mean over `guidance` of |d + σ²·H/s| (the erosion taken out) for points within a plane's
/// reach, else the point distance, each truncated at `cap` (guidance units).
fn eroded_fit(
    object: &Cloud,
    tree: &KdTree,
    spacing: f64,
    guidance: &[P3],
    t: &Similarity,
    bias: &[f64],
    cap: f64,
) -> f64 {
    let Some(inv) = t.matrix().try_inverse() else {
        return f64::INFINITY;
    };
    let sum: f64 = guidance
        .iter()
        .map(|q| {
            let x = inv.transform_point(q);
            let d = match plane_distance(object, tree, spacing, &x) {
                Some((v, true)) => {
                    let j = tree.nearest(&x).map_or(0, |(j, _)| j);
                    (t.scale * v + bias[j] / t.scale).abs()
                }
                Some((v, false)) => t.scale * v,
                None => cap,
            };
            d.min(cap)
        })
        .sum();
    sum / guidance.len().max(1) as f64
}

/// Refit a near-sphere item (one whose shape cannot tell a uniform offset from scale,
/// [`Item::offset_max`] `None`) with the blur's erosion σ²·H held, σ² from the anchor
/// ([`from_anchor`], used only `Z_MIN` standard errors above 0): point-to-plane with scale
/// within ±10 %. Taken when its fit with the erosion taken out is not worse than the current
/// pose's under the same measure (the distances truncated at 3 % of the current pose's
/// diagonal for both).
pub fn apply(item: &Item, sigma2: (f64, f64), placed: &mut Placed) -> BlurReport {
    let (s2, se) = sigma2;
    let mut report = BlurReport {
        sigma2: s2,
        sigma2_se: se,
        skipped: None,
        fit_before: 0.0,
        fit_after: 0.0,
        scale_ratio: 1.0,
        taken: false,
    };
    if item.offset_max().is_some() {
        report.skipped = Some("offset_separable");
        return report;
    }
    if !(s2 > Z_MIN * se) {
        report.skipped = Some("no_blur");
        return report;
    }
    let (object, tree) = (item.object, item.tree);
    let a = STENCIL * object.diagonal();
    let bias: Vec<f64> = mean_curvature(object, tree, a)
        .into_iter()
        .map(|h| s2 * h)
        .collect();
    let start = placed.pose;
    let g_icp = item.guidance.subsample(1500);
    let pl = PlaneIcpOptions {
        iterations: 30,
        keep: 0.85,
        huber: 1.5,
        scale: true,
        scale_lo: start.scale / 1.10,
        scale_hi: start.scale * 1.10,
        tolerance: 1e-6 * item.guidance.diagonal(),
        ..Default::default()
    };
    let m = Matcher::Geometry(tree);
    let (t, _, _) = plane_icp_biased(object, &m, &g_icp, start, &pl, &bias);
    let probe = item.guidance.subsample(1000).points;
    let cap = 0.03 * start.scale * object.diagonal();
    let sp = item.spacing;
    report.fit_before = eroded_fit(object, tree, sp, &probe, &start, &bias, cap);
    report.fit_after = eroded_fit(object, tree, sp, &probe, &t, &bias, cap);
    report.scale_ratio = t.scale / start.scale;
    report.taken = report.fit_after.is_finite() && report.fit_after <= report.fit_before;
    placed.log.push(StageFit {
        stage: "blur_fit".into(),
        fit: report.fit_after,
        scale: t.scale,
        accepted: report.taken,
        offset: 0.0,
    });
    if report.taken {
        placed.pose = t;
        placed.stage = "blur_fit".into();
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compose::sdf::AnchorField;
    use crate::rng::Rng;
    use nalgebra::UnitQuaternion;

    fn sampled(mesh: &crate::mesh::Mesh, n: usize, seed: u64) -> Cloud {
        Cloud::sample(&crate::shapes::plain_visual(mesh), n, seed)
    }

    /// Analytic: a sphere of radius R has H = 1/R everywhere; a box's face centres H = 0.
    #[test]
    fn mean_curvature_of_a_sphere_is_one_over_r() {
        let r = 0.7;
        let s = sampled(&crate::shapes::uv_sphere(r, 128, 256), 6000, 1);
        let tree = KdTree::new(&s.points);
        let h = mean_curvature(&s, &tree, STENCIL * s.diagonal());
        let mean = h.iter().sum::<f64>() / h.len() as f64;
        assert!((mean * r - 1.0).abs() < 0.03, "H·R = {}", mean * r);
    }

    /// A sphere eroded as a blur of σ erodes it (radius R − σ²/R), posed by a known similarity,
    /// with noise, σ² given. The plain fit reads the erosion as a size 2.25 % small; the stage
    /// returns the size within 1 %.
    #[test]
    fn an_eroded_sphere_is_sized_with_a_known_blur() {
        let sigma = 0.15f64;
        let truth = Similarity {
            scale: 1.3,
            rotation: UnitQuaternion::from_euler_angles(0.3, -0.5, 0.9),
            translation: V3::new(0.2, 0.4, -0.3),
        };
        let mut rng = Rng::new(9);
        let noisy = |c: &Cloud, depth: &dyn Fn(&P3, &V3) -> Option<f64>, rng: &mut Rng| {
            let pts: Vec<P3> = c
                .points
                .iter()
                .zip(&c.normals)
                .filter_map(|(p, n)| {
                    let e = depth(p, n)?;
                    let q = p - n * e;
                    let noise = V3::new(rng.normal(), rng.normal(), rng.normal()) * 0.002;
                    Some(truth.matrix().transform_point(&q) + noise)
                })
                .collect();
            let k = pts.len();
            Cloud {
                points: pts,
                normals: vec![V3::z(); k],
                colours: vec![[0.5; 3]; k],
            }
        };
        // σ² of the scene in guidance units (the anchor's measure, `from_anchor`, is not tested
        // here: on the bench it was not usable, docs/compose.md "Sixteenth stop").
        let (s2, se) = ((sigma * truth.scale).powi(2), 0.0);
        let rs = 1.0;
        let sph_mesh = crate::shapes::uv_sphere(rs, 48, 96);
        let vis = crate::shapes::plain_visual(&sph_mesh);
        let obj = Cloud::sample(&vis, 5000, 4);
        let tree = KdTree::new(&obj.points);
        let g = noisy(
            &sampled(&sph_mesh, 2500, 5),
            &|_, _| Some(sigma * sigma / rs),
            &mut rng,
        );
        // The plain fit from the truth: the erosion read as size.
        let pl = PlaneIcpOptions {
            iterations: 50,
            keep: 0.9,
            scale_lo: 0.5,
            scale_hi: 3.0,
            tolerance: 1e-9,
            ..Default::default()
        };
        let (plain, _, _) = plane_icp_biased(&obj, &Matcher::Geometry(&tree), &g, truth, &pl, &[]);
        let plain_err = plain.scale / truth.scale - 1.0;
        assert!(
            plain_err < -0.02,
            "premise: plain fit scale error {plain_err}"
        );
        let field = AnchorField::new(&[], 8);
        let item = Item {
            visual: &vis,
            object: &obj,
            tree: &tree,
            spacing: (sph_mesh.area() / 5000.0).sqrt(),
            guidance: &g,
            field: &field,
        };
        let mut placed = Placed {
            pose: plain,
            stage: "point_to_plane".into(),
            log: Vec::new(),
        };
        let rep = apply(&item, (s2, se), &mut placed);
        assert!(rep.taken, "{rep:?}");
        let err = placed.pose.scale / truth.scale - 1.0;
        assert!(err.abs() < 0.01, "scale error {err} (plain {plain_err})");
        // The same stage does not act on a shape whose offset the offset stage separates.
        let bar = sampled(&crate::shapes::cuboid(V3::new(1.0, 0.3, 0.2)), 3000, 6);
        let btree = KdTree::new(&bar.points);
        let bar_item = Item {
            object: &bar,
            tree: &btree,
            ..item
        };
        let mut p2 = placed.clone();
        let rep = apply(&bar_item, (s2, se), &mut p2);
        assert_eq!(rep.skipped, Some("offset_separable"));
        assert_eq!(p2.pose.scale, placed.pose.scale);
    }
}
