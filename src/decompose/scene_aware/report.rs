//! The engine's report: per object, what the engine did (shortcut, splits, cuts, dropped
//! hulls, remaining overlaps) and its warnings ([`ObjectReport::warnings`]); per scene,
//! [`SceneAwareReport`]. How close the hulls lie to the mesh is measured for every engine
//! alike and warned about by `body::assemble` (see [`super::metrics::tolerance_warning`]).

use serde::{Deserialize, Serialize};
/// What happened to one object.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ObjectReport {
    /// Hulls produced.
    pub hulls: usize,
    /// The object's own (simplified) convex hull was close enough to be used alone.
    pub convex_shortcut: bool,
    /// Patch splits made to meet the tolerance.
    pub quality_splits: usize,
    /// Moves of the rebalancing (see `rebalance.rs`) that lowered the worst deviation once the
    /// budget was spent.
    #[serde(default)]
    pub rebalance_rounds: usize,
    /// Moves of the polishing (see `polish.rs`) that brought the far tail of
    /// the surface distance closer once the budget was spent, and patches it trimmed first.
    #[serde(default)]
    pub polish_rounds: usize,
    #[serde(default)]
    pub trimmed_patches: usize,
    /// Wall segments grown towards the patch vertices they left out once the patches were
    /// final (see `refit.rs`).
    #[serde(default)]
    pub refitted: usize,
    /// Patch hulls that filled a concavity, split with a hull freed by a merge elsewhere
    /// (see `unfill.rs`).
    #[serde(default)]
    pub unfilled: usize,
    /// Mesh vertices left deep outside every hull that a hull was grown to take in, last
    /// (see `cover.rs`).
    #[serde(default)]
    pub covered: usize,
    /// The patches were found top-down, with plane cuts normal to the scene axes, which
    /// measured closer to the surface than the bottom-up patches (see `Strategy`).
    #[serde(default)]
    pub top_down: bool,
    /// The object is filled by cones from its centre over the surface as seen from there
    /// (see `star`), which lay closer to it than the surface patches.
    #[serde(default)]
    pub star_pieces: bool,
    /// Of the star pieces, one-sided surface patches laid first where a neighbour rests (see
    /// `star_on_slabs`).
    #[serde(default)]
    pub slabs: usize,
    /// Of the star pieces, surface patches over what rays from the centre do not see (see
    /// `star_with_patches`).
    #[serde(default)]
    pub unseen_patches: usize,
    /// The object is a solid the patches left hollow and its centre does not see whole: it
    /// took parry's V-HACD hulls, which lay closer to it (see `voxel_parts`).
    #[serde(default)]
    pub voxel_hulls: bool,
    /// Patch splits made because a hull met a neighbour.
    pub neighbour_splits: usize,
    /// Hulls added after the neighbour refinement, from what it left of the budget (see
    /// `top_up`).
    #[serde(default)]
    pub topped_up: usize,
    /// Plane cuts against neighbours that removed only bulge (no surface vertex).
    pub clean_cuts: usize,
    /// Plane cuts that had to remove some surface (the neighbour is too close or the meshes
    /// interpenetrate).
    pub lossy_cuts: usize,
    /// Hulls dropped because a cut left them thinner than `min_thickness`.
    pub dropped_hulls: usize,
    /// Hulls a cut would have left too thin, built again from what the cut leaves of their
    /// patch (see `fit::kept_side`).
    #[serde(default)]
    pub rebuilt_hulls: usize,
    /// Sampled one-sided distance from the hull surfaces to the mesh, 95th percentile and
    /// maximum, relative to the bounding-box diagonal (what the engine chooses by; the
    /// two-sided figures and their warning are `body::assemble`'s, for every engine).
    pub distance_p95: f64,
    pub distance_max: f64,
    /// Pairs (this hull, a neighbour's hull) still closer than the clearance, and how many of
    /// them overlap; deepest overlap (m).
    pub under_clearance: usize,
    pub overlaps: usize,
    pub max_overlap: f64,
    /// Neighbours whose mesh interpenetrates this one: (object index, depth in m).
    pub mesh_penetration: Vec<(usize, f64)>,
    /// The tolerance asked for (relative to the diagonal, see `DecomposeOptions::tolerance`)
    /// and the hull budget (`max_hulls`).
    #[serde(default)]
    pub tolerance: f64,
    #[serde(default)]
    pub max_hulls: usize,
}

impl ObjectReport {
    /// Human-readable notes for warnings.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        for (o, d) in &self.mesh_penetration {
            w.push(format!(
                "mesh interpenetrates object #{o} by {:.2} mm (input geometry); collision hulls were cut apart there",
                d * 1e3
            ));
        }
        if self.overlaps > 0 {
            w.push(format!(
                "{} collision hull pair(s) still overlap a neighbour, deepest {:.3} mm",
                self.overlaps,
                self.max_overlap * 1e3
            ));
        }
        if self.lossy_cuts > 0 || self.dropped_hulls > 0 {
            w.push(format!(
                "{} hull cut(s) against neighbours removed some surface coverage ({} hull(s) dropped)",
                self.lossy_cuts, self.dropped_hulls
            ));
        }
        w
    }
}

/// Report of one scene decomposition.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SceneAwareReport {
    pub objects: Vec<ObjectReport>,
    /// Refinement rounds run.
    pub rounds: usize,
    /// Served from the cache.
    pub cached: bool,
}
