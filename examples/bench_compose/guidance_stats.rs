//! How much a guidance part says about its object's scale, measured against the truth: it tells
//! a registration miss from a guidance part whose surface itself is off (issue #34's diagnosis).

use interact3d::compose::cloud::Cloud;
use interact3d::compose::kdtree::KdTree;
use interact3d::compose::obb::Obb;
use interact3d::compose::ObjectInput;
use interact3d::mesh::P3;
use interact3d::pose::Similarity;

/// One guidance part against its object at the true pose (lengths in % of the posed object's
/// diagonal).
#[derive(Clone, Copy, Debug, Default)]
pub struct GuidanceStats {
    /// Guidance points farther than 2 % from the true surface (bleed, blur, noise tails).
    pub outliers: f64,
    /// Object surface with no guidance point within 2 % (holes, contact, lost thin parts).
    pub uncovered: f64,
    /// Mean signed distance of the other guidance points along the true outward normal: > 0 a
    /// part fattened by the reconstruction, < 0 one eroded.
    pub offset: f64,
    /// Median over the object's principal axes of (extent of those guidance points) / (extent
    /// of the object): the scale the guidance part shows, 1 when it is the object's own size.
    pub extent_ratio: f64,
}

pub fn measure(inp: &ObjectInput, truth: &Similarity) -> GuidanceStats {
    let obj = Cloud::sample(&inp.visual, 20_000, 11).transformed(&truth.matrix());
    let g = Cloud::sample(&inp.guidance, 5_000, 12);
    let diag = obj.diagonal();
    let tau = 0.02 * diag;
    let tree = KdTree::new(&obj.points);
    let mut near: Vec<P3> = Vec::new();
    let mut signed = 0.0;
    for p in &g.points {
        if let Some((j, d2)) = tree.nearest(p) {
            if d2.sqrt() < tau {
                near.push(*p);
                signed += (p - obj.points[j]).dot(&obj.normals[j]);
            }
        }
    }
    let gt = KdTree::new(&g.points);
    let uncovered = obj
        .points
        .iter()
        .filter(|p| !gt.nearest(p).is_some_and(|(_, d2)| d2.sqrt() < tau))
        .count() as f64
        / obj.len().max(1) as f64;
    let box_ = Obb::of_points(&obj.points);
    // Extent along an axis between the 0.5th and 99.5th percentiles (noise tails left out).
    let extent = |pts: &[P3], a: usize| {
        let ax = box_.axes.column(a);
        let mut v: Vec<f64> = pts.iter().map(|p| (p - box_.center).dot(&ax)).collect();
        if v.len() < 10 {
            return f64::NAN;
        }
        v.sort_by(f64::total_cmp);
        v[(v.len() as f64 * 0.995) as usize] - v[(v.len() as f64 * 0.005) as usize]
    };
    let mut ratios: Vec<f64> = (0..3)
        .map(|a| extent(&near, a) / extent(&obj.points, a))
        .collect();
    ratios.sort_by(f64::total_cmp);
    GuidanceStats {
        outliers: 100.0 * (1.0 - near.len() as f64 / g.len().max(1) as f64),
        uncovered: 100.0 * uncovered,
        offset: 100.0 * signed / near.len().max(1) as f64 / diag,
        extent_ratio: ratios[1],
    }
}
