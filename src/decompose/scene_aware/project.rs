//! Bounded closest-point queries on a [`Surface`] that give parry's unbounded answer, to the
//! bit (issue #37). Entry point: [`Surface::project_until`], used by
//! [`Surface::max_distance_until`].

use super::geom::{Surface, WITHIN_MARGIN};
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query::{PointProjection, PointQuery};

impl Surface {
    /// parry's projection of `q` onto the surface, searched first only within `reach` plus a
    /// margin (`project_point_with_max_dist`, as [`Surface::farther`] does): parry's
    /// `find_best` then starts with that bound as its best cost and prunes every box beyond
    /// it, otherwise walking the same boxes in the same order, so a projection found within
    /// it is the unbounded search's, to the bit. None found: the unbounded search, as before.
    /// [`Surface::max_distance_until`] needs exact distances only up to `max(stop, seam)`,
    /// and beyond it only for the first point found there, where it stops.
    pub(super) fn project_until(&self, q: Vector, reach: f64) -> PointProjection {
        let id = Pose::identity();
        if reach > 0.0 && reach.is_finite() && q.is_finite() {
            let bound = reach * (1.0 + WITHIN_MARGIN);
            if let Some(proj) = self.tri.project_point_with_max_dist(&id, q, false, bound) {
                return proj;
            }
        }
        self.tri.project_point(&id, q, false)
    }
}
