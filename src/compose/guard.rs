//! The guard: a stage's pose replaces the current one only when it does not fit the guidance
//! worse ([`super::plane_icp::surface_fit`], the mean truncated distance of guidance points to
//! the posed object's surface). Each offer is logged, so the report says which stage's pose won
//! and what every stage's fit was.
//!
//! Entry point: [`Guard`] (`new` with the first pose, `offer` each later stage's pose, then
//! `pose`, `stage`, `log`).

use super::cloud::Cloud;
use super::kdtree::KdTree;
use super::plane_icp::{offset_distances, offset_fit, surface_distances, surface_fit};
use crate::mesh::{VisualMesh, P3};
use crate::pose::Similarity;
use serde::Serialize;

/// One stage's offer.
#[derive(Clone, Debug, Serialize)]
pub struct StageFit {
    pub stage: String,
    /// Mean truncated guidance-to-surface distance at the stage's pose (guidance units).
    pub fit: f64,
    /// The stage pose's scale (object to guidance units).
    pub scale: f64,
    pub accepted: bool,
    /// The normal offset taken out of the fit (guidance units; 0 before the guard measures
    /// offsets, see [`Guard::measure_offsets`]).
    #[serde(skip_serializing_if = "is_zero")]
    pub offset: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// Keeps the best-fitting pose of the stages offered to it.
pub struct Guard<'a> {
    object: &'a Cloud,
    tree: &'a KdTree,
    spacing: f64,
    /// `object.diagonal()`, measured once (every fit scales its cap by it).
    diagonal: f64,
    probe: Vec<P3>,
    /// Distances are truncated at `cap_fraction` × the object's diagonal at the pose's scale.
    cap_fraction: f64,
    /// A later pose may be worse by this much (guidance units) and still be taken.
    allowance: f64,
    /// When set, fits take out each pose's own normal offset, up to this fraction of the
    /// object's diagonal at the pose's scale ([`offset_fit`]).
    offset_fraction: Option<f64>,
    /// When set, the truncation in guidance units, the same for every pose ([`Guard::fix_cap`]).
    cap_fixed: Option<f64>,
    best: Similarity,
    best_fit: f64,
    stage: String,
    log: Vec<StageFit>,
}

/// Mean sample spacing of `n` samples on `visual`'s surface (object units).
pub fn spacing(visual: &VisualMesh, n: usize) -> f64 {
    let area = visual.area();
    (area / n.max(1) as f64).sqrt()
}

impl<'a> Guard<'a> {
    /// A guard over `object` (samples with normals, its tree, their `spacing`) and the guidance
    /// points `probe`, starting from the pose `start` of stage `stage`.
    pub fn new(
        object: &'a Cloud,
        tree: &'a KdTree,
        spacing: f64,
        probe: Vec<P3>,
        start: Similarity,
        stage: &str,
    ) -> Guard<'a> {
        let mut g = Guard {
            object,
            tree,
            spacing,
            diagonal: object.diagonal(),
            probe,
            cap_fraction: 0.03,
            allowance: 0.0,
            offset_fraction: None,
            cap_fixed: None,
            best: start,
            best_fit: f64::INFINITY,
            stage: stage.to_string(),
            log: Vec::new(),
        };
        g.best_fit = g.fit(&start);
        g.log.push(StageFit {
            stage: stage.to_string(),
            fit: g.best_fit,
            scale: start.scale,
            accepted: true,
            offset: 0.0,
        });
        g
    }

    /// The fit of pose `t` (lower is better).
    pub fn fit(&self, t: &Similarity) -> f64 {
        self.fit_offset(t).0
    }

    /// The fit of pose `t` and the normal offset taken out of it (0 unless measuring offsets).
    fn fit_offset(&self, t: &Similarity) -> (f64, f64) {
        let diag = t.scale * self.diagonal;
        let cap = self.cap_fixed.unwrap_or(self.cap_fraction * diag);
        match self.offset_fraction {
            None => (
                surface_fit(self.object, self.tree, self.spacing, &self.probe, t, cap),
                0.0,
            ),
            Some(f) => offset_fit(
                self.object,
                self.tree,
                self.spacing,
                &self.probe,
                t,
                cap,
                f * diag,
            ),
        }
    }

    /// From now on every fit, the current pose's included, takes out the pose's own uniform
    /// normal offset (up to `fraction` of the object's diagonal): a stage that fits an offset
    /// beside the scale is then judged against the current pose on the same terms.
    pub fn measure_offsets(&mut self, fraction: f64) -> &mut Self {
        self.offset_fraction = Some(fraction);
        self.best_fit = self.fit(&self.best);
        self
    }

    /// Each probe point's truncated distance at pose `t`, as [`Guard::fit`] averages them.
    fn distances(&self, t: &Similarity) -> Vec<f64> {
        let diag = t.scale * self.diagonal;
        let cap = self.cap_fixed.unwrap_or(self.cap_fraction * diag);
        match self.offset_fraction {
            None => surface_distances(self.object, self.tree, self.spacing, &self.probe, t, cap),
            Some(f) => {
                let (o, tr, sp) = (self.object, self.tree, self.spacing);
                offset_distances(o, tr, sp, &self.probe, t, cap, f * diag).0
            }
        }
    }

    /// Whether `t` fits better than the current pose beyond the probe's sampling error: the
    /// mean of the per-point differences (same probe points, paired) is below −`z` standard
    /// errors. A search that picks the best of many candidates by the fit also picks the
    /// sampling noise; this keeps a gain that noise alone would not give.
    pub fn clearly_better(&self, t: &Similarity, z: f64) -> bool {
        let (a, b) = (self.distances(t), self.distances(&self.best));
        let n = a.len().max(2) as f64;
        let diff: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
        let mean = diff.iter().sum::<f64>() / n;
        let var = diff.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (n - 1.0);
        mean < -z * (var / n).sqrt()
    }

    /// From now on every pose's distances are truncated at the current pose's cap (guidance
    /// units), not at a fraction of each pose's own size: poses of different scales are then
    /// charged the same for the guidance points no pose explains (bleed, blur), where a cap
    /// proportional to the scale charges a smaller pose less for each of them.
    pub fn fix_cap(&mut self) -> &mut Self {
        self.cap_fixed = Some(self.cap_fraction * self.best.scale * self.diagonal);
        self.best_fit = self.fit(&self.best);
        self
    }

    /// Allow the next offers to be worse by `allowance` (guidance units): a stage with another
    /// aim (moving out of collision) may cost a little fit, never more.
    pub fn with_allowance(&mut self, allowance: f64) -> &mut Self {
        self.allowance = allowance;
        self
    }

    /// Offer stage `stage`'s pose; taken when its fit is not worse than the current pose's (plus
    /// the allowance). Returns whether it was taken.
    pub fn offer(&mut self, stage: &str, t: Similarity) -> bool {
        let (f, offset) = self.fit_offset(&t);
        let ok = f.is_finite() && f <= self.best_fit + self.allowance;
        self.log.push(StageFit {
            stage: stage.to_string(),
            fit: f,
            scale: t.scale,
            accepted: ok,
            offset,
        });
        if ok {
            self.best = t;
            self.best_fit = f;
            self.stage = stage.to_string();
        }
        ok
    }

    pub fn pose(&self) -> Similarity {
        self.best
    }
    pub fn best_fit(&self) -> f64 {
        self.best_fit
    }
    /// The stage whose pose is current.
    pub fn stage(&self) -> &str {
        &self.stage
    }
    pub fn log(&self) -> &[StageFit] {
        &self.log
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compose::icp::Matcher;
    use crate::compose::plane_icp::{plane_icp, PlaneIcpOptions};
    use crate::mesh::V3;
    use crate::rng::Rng;
    use nalgebra::UnitQuaternion;

    /// A refinement that diverges: the guidance is a box's surface plus a dense cluster of
    /// outliers off one corner, and the ICP runs without trimming or robust weights, so it is
    /// dragged towards the cluster. The guard must keep the start, whose fit it measures better,
    /// and never hold a pose worse than the start.
    #[test]
    fn guard_never_returns_a_worse_fit_when_refinement_diverges() {
        let mesh = crate::shapes::cuboid(V3::new(1.0, 0.6, 0.3));
        let vis = crate::shapes::plain_visual(&mesh);
        let obj = Cloud::sample(&vis, 4000, 1);
        let tree = KdTree::new(&obj.points);
        let truth = Similarity {
            scale: 1.5,
            rotation: UnitQuaternion::from_euler_angles(0.2, 0.5, -0.3),
            translation: V3::new(1.0, 2.0, -1.0),
        };
        let mut g = Cloud::sample(&vis, 1500, 2).transformed(&truth.matrix());
        let mut rng = Rng::new(9);
        let corner = truth.matrix().transform_point(&P3::new(1.2, 0.8, 0.6));
        for _ in 0..900 {
            g.points
                .push(corner + V3::new(rng.normal(), rng.normal(), rng.normal()) * 0.1);
        }
        g.colours = vec![[0.5; 3]; g.points.len()];
        g.normals = vec![V3::z(); g.points.len()];
        let start = truth;
        let o = PlaneIcpOptions {
            keep: 1.0,
            huber: 1e12,
            scale_lo: 0.5,
            scale_hi: 3.0,
            ..Default::default()
        };
        let (diverged, _) = plane_icp(&obj, &Matcher::Geometry(&tree), &g, start, &o);
        // It did diverge (the premise of the test), by an independent measure: the pose error.
        let err = (diverged.translation - truth.translation).norm();
        assert!(err > 0.05, "the unguarded ICP did not diverge ({err})");
        let mut guard = Guard::new(
            &obj,
            &tree,
            spacing(&vis, 4000),
            g.points.clone(),
            start,
            "start",
        );
        let f0 = guard.best_fit();
        let taken = guard.offer("plane_icp", diverged);
        assert!(!taken, "a worse pose was taken");
        assert_eq!(guard.stage(), "start");
        assert_eq!(guard.pose().translation, start.translation);
        assert!(guard.best_fit() <= f0);
        // A better pose is taken: from a start 2 cm off, the guard moves to the truth.
        let off = Similarity {
            translation: truth.translation + V3::new(0.02, 0.0, 0.0),
            ..truth
        };
        let mut guard = Guard::new(
            &obj,
            &tree,
            spacing(&vis, 4000),
            g.points.clone(),
            off,
            "start",
        );
        assert!(guard.offer("icp", truth));
        assert_eq!(guard.stage(), "icp");
        assert_eq!(guard.log().len(), 2);
    }
}
