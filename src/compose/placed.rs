//! What the stages after an item's registration share: the item as they see it ([`Item`]: its
//! mesh, sample, tree, guidance and the placed objects' field) and the pose they hand on
//! ([`Placed`]: the pose, the stage that gave it and every stage's fit), so that the support
//! sweep ([`super::support`]), the contact's size ([`super::contact_scale`]) and the colour's
//! refused size ([`super::colour_rest`]) each take one item and one pose to fold their guard
//! back into.
//!
//! Entry points: [`Item`] (`offset_max`, `dense`), [`Placed`] (`take`).

use super::cloud::Cloud;
use super::contact_scale::DENSE;
use super::guard::{Guard, StageFit};
use super::kdtree::KdTree;
use super::plane_icp::scale_offset_correlation;
use super::sdf::AnchorField;
use crate::mesh::{VisualMesh, P3};
use crate::pose::Similarity;

/// An item placed after the anchor, as the stages after its registration see it.
#[derive(Clone, Copy)]
pub struct Item<'a> {
    pub visual: &'a VisualMesh,
    /// The item's surface sample (object frame) and its tree.
    pub object: &'a Cloud,
    pub tree: &'a KdTree,
    /// The sample's spacing ([`super::guard::spacing`]).
    pub spacing: f64,
    pub guidance: &'a Cloud,
    /// The signed distance of the objects placed before it.
    pub field: &'a AnchorField,
}

impl<'a> Item<'a> {
    /// The normal offset a guard may take out of its fits ([`Guard::measure_offsets`]), where
    /// the item's shape lets an offset and a scale be told apart; `None` where it does not.
    pub fn offset_max(&self) -> Option<f64> {
        (scale_offset_correlation(self.object) < super::OFFSET_CORRELATION_MAX)
            .then_some(super::OFFSET_MAX)
    }

    /// The dense surface sample the gap probes measure contact with (the same seed for every
    /// stage, so each stage sees the same points).
    pub fn dense(&self) -> Vec<P3> {
        Cloud::sample(self.visual, DENSE, 0x6a70).points
    }

    /// A guard over 1,000 of the guidance's points, started from `start` (stage `stage`).
    pub fn guard(&self, start: Similarity, stage: &str) -> Guard<'a> {
        let probe = self.guidance.subsample(1000).points;
        Guard::new(self.object, self.tree, self.spacing, probe, start, stage)
    }
}

/// An item's pose as the stages hand it on.
#[derive(Clone, Debug)]
pub struct Placed {
    pub pose: Similarity,
    /// The stage whose pose is current.
    pub stage: String,
    /// Every stage's offer, in order.
    pub log: Vec<StageFit>,
}

impl Placed {
    /// Take what `guard` (started from this pose) kept: its pose and stage, and its log after
    /// the start, which is this pose's entry already.
    pub fn take(&mut self, guard: &Guard) {
        self.pose = guard.pose();
        self.stage = guard.stage().to_string();
        self.log.extend(guard.log().iter().skip(1).cloned());
    }
}

/// For the stages' tests: the field of a slab `width` × 0.2 × `width` whose top face is the plane
/// y = 0.
#[cfg(test)]
pub(super) fn slab_field(width: f64) -> AnchorField {
    let slab = crate::shapes::cuboid(crate::mesh::V3::new(width, 0.2, width)).transformed(
        &Similarity {
            translation: crate::mesh::V3::new(0.0, -0.1, 0.0),
            ..Similarity::identity()
        }
        .matrix(),
    );
    AnchorField::new(&[slab], 32)
}
