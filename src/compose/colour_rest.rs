//! The colour's size where the item floats: the size [`super::colour_axis`] read from the
//! item's colour along its long axis, refused there because the guidance's geometry fits it
//! worse, is taken when a second, independent cue agrees with it: the registered pose floats
//! above the objects placed before it and the colour's pose rests on them.
//!
//! A guidance part that shows only an item's top (a screwdriver in a tray) can fit a size 26 %
//! too small better than the truth: a smaller item has less surface to explain the part's
//! outliers with. Its colour may still show where the handle ends and the shaft begins, and the
//! contact shows the rest: at a wrong small size the item's hidden underside hangs above the
//! support it lies on. Neither cue alone is trusted against the geometry (the colour's size is
//! wrong by 20–54 % on several objects, docs/compose.md "Thirteenth stop"; a floating pose is
//! often the composed support's own error); both together are. The guard still judges, with
//! the guidance's own noise (the robust σ of its point-to-plane residuals) as the allowance, as
//! for the contact stage ([`super::contact_scale`]): the move may cost the fit no more than the
//! guidance's noise.
//!
//! It runs on an item placed after the anchor whose colour candidate was refused, only when
//! * the registered pose floats: its closest approach to the placed objects (min Φ, the dense
//!   [`GapProbe`]) exceeds [`REST_TOLERANCE`] of the item's diagonal (the truth's own gap to the
//!   *composed* support reads up to 1.64 % on the screwdriver, "Twelfth stop");
//! * the support is below: Φ's gradient there within 60° of the scene's up (+Y);
//! * the colour's pose rests: its |min Φ| within [`REST_TOLERANCE`] of its diagonal.
//!
//! Entry points: [`judge`] (the gates, the guard, a [`ColourRestReport`]), [`apply`] (how
//! `compose` calls it).

use super::contact_scale::{visible, GapProbe};
use super::guard::Guard;
use super::placed::{Item, Placed};
use crate::pose::Similarity;
use serde::Serialize;

/// A pose rests when its gap to the placed objects is within this fraction of its diagonal.
pub const REST_TOLERANCE: f64 = 0.02;

/// Φ's gradient at the closest approach must have at least this +Y component (60° from up).
const UP_MIN: f64 = 0.5;

/// What [`judge`] did.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ColourRestReport {
    /// Why the candidate was not offered (`resting`, `not_below`, `candidate_not_resting`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skipped: Option<&'static str>,
    /// The gaps of the registered pose and of the colour's pose, in fractions of each pose's
    /// diagonal (< 0: penetrating); the candidate's is NaN when not measured.
    pub gap_before: f64,
    pub gap_candidate: f64,
    /// Φ's gradient's +Y component at the registered pose's closest approach.
    pub normal_up: f64,
    /// The guard's allowance (guidance units; 0 when not offered).
    pub noise: f64,
    pub taken: bool,
}

/// The gates and, when they pass, the item's guard ([`Item::guard`], from `start` of stage
/// `stage`, the normal offsets measured when `offsets`) offered `candidate` as `colour_rest`
/// with the guidance's noise as the allowance. `gaps` measures min Φ of the item.
pub fn judge<'a>(
    item: &Item<'a>,
    gaps: &GapProbe,
    (start, stage): (Similarity, &str),
    candidate: Similarity,
    offsets: Option<f64>,
) -> (Guard<'a>, ColourRestReport) {
    let (object, field) = (item.object, item.field);
    let mut guard = item.guard(start, stage);
    let diag = object.diagonal();
    let g0 = gaps.gap(&start, field);
    let mut report = ColourRestReport {
        skipped: None,
        gap_before: g0.value / (start.scale * diag),
        gap_candidate: f64::NAN,
        normal_up: g0.normal.y,
        noise: 0.0,
        taken: false,
    };
    // A NaN gap is no cue either.
    if report.gap_before.is_nan() || report.gap_before <= REST_TOLERANCE {
        report.skipped = Some("resting");
        return (guard, report);
    }
    if g0.normal.y.is_nan() || g0.normal.y < UP_MIN {
        report.skipped = Some("not_below");
        return (guard, report);
    }
    report.gap_candidate = gaps.gap(&candidate, field).value / (candidate.scale * diag);
    if report.gap_candidate.is_nan() || report.gap_candidate.abs() > REST_TOLERANCE {
        report.skipped = Some("candidate_not_resting");
        return (guard, report);
    }
    if let Some(f) = offsets {
        guard.measure_offsets(f);
    }
    report.noise = visible(object, item.tree, &item.guidance.subsample(1500), &start).1;
    guard.with_allowance(report.noise);
    report.taken = guard.offer("colour_rest", candidate);
    (guard, report)
}

/// [`judge`] as `compose` calls it on an item placed after the anchor whose colour candidate
/// the registration refused: the guard's pose, stage and log folded back into `placed`.
pub(super) fn apply(item: &Item, candidate: Similarity, placed: &mut Placed) -> ColourRestReport {
    let gaps = GapProbe::new(item.object.subsample(1000).points, &item.dense());
    let (g, report) = judge(
        item,
        &gaps,
        (placed.pose, placed.stage.as_str()),
        candidate,
        item.offset_max(),
    );
    placed.take(&g);
    report
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compose::cloud::Cloud;
    use crate::compose::contact_scale::DENSE;
    use crate::compose::guard::spacing;
    use crate::compose::kdtree::KdTree;
    use crate::compose::placed::slab_field;
    use crate::mesh::V3;

    /// A bar 1 × 0.2 × 0.2 lying on a slab (its bottom at y = 0, the slab's top) at scale 1; the
    /// guidance: noisy points (σ = 0.003 along the normals) on the middle of its top face only,
    /// which a bar 20 % smaller with the same top explains as well. That smaller bar floats 0.04
    /// (4.8 % of its diagonal) above the slab. Offered the true size as the colour's candidate,
    /// the judge must take it (the scale 1 known by construction); it must leave a resting
    /// start alone, refuse a candidate that penetrates by 3.2 % of its diagonal, and let the
    /// guard refuse a resting candidate the guidance does not fit (moved 0.5 along the bar).
    #[test]
    fn a_floating_bar_takes_the_resting_size_and_nothing_else() {
        let field = slab_field(4.0);
        let vis = crate::shapes::plain_visual(&crate::shapes::cuboid(V3::new(1.0, 0.2, 0.2)));
        let obj = Cloud::sample(&vis, 4000, 1);
        let tree = KdTree::new(&obj.points);
        let sp = spacing(&vis, 4000);
        // A pose of scale `s` whose top face is at y = 0.2 (the truth's), moved `dx` along x.
        let pose = |s: f64, dx: f64| Similarity {
            scale: s,
            translation: V3::new(dx, 0.2 - 0.1 * s, 0.0),
            ..Similarity::identity()
        };
        let truth = pose(1.0, 0.0);
        let all = Cloud::sample(&vis, 20_000, 2).transformed(&truth.matrix());
        let mut rng = crate::rng::Rng::new(5);
        let keep: Vec<usize> = (0..all.len())
            .filter(|&i| {
                let p = all.points[i];
                p.y > 0.199 && p.x.abs() < 0.35 && p.z.abs() < 0.07
            })
            .collect();
        let g = Cloud {
            points: keep
                .iter()
                .map(|&i| all.points[i] + all.normals[i] * (0.003 * rng.normal()))
                .collect(),
            normals: keep.iter().map(|&i| all.normals[i]).collect(),
            colours: keep.iter().map(|&i| all.colours[i]).collect(),
        };
        assert!(g.len() > 500, "{} guidance points", g.len());
        let dense = Cloud::sample(&vis, DENSE, 3).points;
        let gaps = GapProbe::new(obj.subsample(1000).points, &dense);
        let item = Item {
            visual: &vis,
            object: &obj,
            tree: &tree,
            spacing: sp,
            guidance: &g,
            field: &field,
        };
        let run = |start: Similarity, cand: Similarity| {
            let (guard, r) = judge(&item, &gaps, (start, "s"), cand, None);
            (guard.pose(), guard.stage().to_string(), r)
        };
        let small = pose(0.8, 0.0);

        let (t, stage, r) = run(small, truth);
        assert!(r.taken && stage == "colour_rest", "{r:?}");
        assert!((t.scale - 1.0).abs() < 1e-12);
        assert!(
            (r.gap_before - 0.04 / (0.8 * 1.08f64.sqrt())).abs() < 2e-3,
            "{r:?}"
        );
        assert!(r.gap_candidate.abs() < 2e-3, "{r:?}");
        assert!(r.normal_up > 0.99);
        // The guidance's noise as the allowance: σ within 20 %.
        assert!((r.noise / 0.003 - 1.0).abs() < 0.2, "noise {}", r.noise);

        let (t, stage, r) = run(truth, pose(0.8, 0.0));
        assert_eq!(
            (r.skipped, stage.as_str(), t.scale),
            (Some("resting"), "s", 1.0)
        );

        let (t, _, r) = run(small, pose(1.2, 0.0));
        assert_eq!(r.skipped, Some("candidate_not_resting"), "{r:?}");
        assert!((r.gap_candidate + 0.04 / (1.2 * 1.08f64.sqrt())).abs() < 2e-3);
        assert_eq!(t.scale, 0.8);

        let (t, stage, r) = run(small, pose(1.0, 0.5));
        assert!(r.skipped.is_none() && !r.taken && stage == "s", "{r:?}");
        assert_eq!(t.scale, 0.8);
    }
}
