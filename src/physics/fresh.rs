//! Contact points that do not miss where two shapes interpenetrate most.
//!
//! parry's manifold between two convex polyhedra (`contact_manifold_pfm_pfm`, which Rapier uses
//! for hull–hull and hull–box pairs) first tries to keep last step's contact points: while the
//! normal turned less than 1° and each point slid less than 1 mm (a squared distance of 1e-6,
//! in absolute units), it only updates their distances. Our objects are centimetres across:
//! a hull rocking on a nearly flat bottom of many small faces keeps contacts at the vertices it
//! first touched while others sink through. The GSO cardboard package (one 64-vertex hull,
//! 0.7 kg) sank 1–3.7 mm into the floor and failed the rest check at 7.5 mm, where MuJoCo
//! holds it within 1.2 mm (the LEGO suitcase 3.7 mm, the porcelain pitcher 1.0 mm likewise),
//! and 1–4 mm into a fixed box hull under it. [`Fresh`] checks every manifold before handing
//! the pair to parry's default dispatcher: when the kept points miss the deepest
//! interpenetration (see [`stale`]), the manifold is marked deformed and parry computes it
//! from the current poses, the deepest point among its points. The package rests within
//! 0.01 mm of the floor and of the box; the settle benchmark runs as fast as before.
//!
//! parry also keeps the manifold's **normal** while it turned less than 1°: the normal is stored
//! in each shape's frame, so a body rocking on a rim pushes along a normal that turns with it,
//! up to 1° off the floor's, a force that follows the body and does work on it. A 32-sided
//! cylinder released tilted 4° on the floor rocks itself up to 7.3° in 4 s that way (seed 313's
//! bottle, docs/agreement.md "Twelfth stop"). [`Fresh::max_turn_cos`] recomputes a manifold
//! whose normal turned more than
//! [`SettleOptions::contact_reuse_max_turn_deg`](super::SettleOptions::contact_reuse_max_turn_deg)
//! since it was computed; at parry's own 1° (the default) nothing changes. The kept normal is
//! also an accidental rolling resistance; the `rolling` module has a deliberate one.

use rapier3d_f64::geometry::{ContactData, ContactManifoldData};
use rapier3d_f64::math::{Pose, Real, Vector};
use rapier3d_f64::parry::query::details::{NormalConstraints, ShapeCastOptions};
use rapier3d_f64::parry::query::{
    ClosestPoints, Contact, ContactManifold, ContactManifoldsWorkspace, DefaultQueryDispatcher,
    NonlinearRigidMotion, PersistentQueryDispatcher, QueryDispatcher, ShapeCastHit, ShapeDistance,
    ShapeIntersection, Unsupported,
};
use rapier3d_f64::parry::shape::Shape;

/// parry's default dispatcher, but contact points kept from the last step are recomputed
/// when they miss the deepest interpenetration (see [`stale`]) or when the manifold's normal
/// turned more than `acos(max_turn_cos)` since it was computed.
pub(super) struct Fresh {
    /// Cosine of the largest turn of a kept normal; `None`: parry's own 1° decides.
    pub(super) max_turn_cos: Option<Real>,
}

impl Fresh {
    /// The dispatcher for a kept normal's largest turn `deg` (degrees); at 1° or more parry's
    /// own check (1°) is the only one.
    pub(super) fn new(deg: Real) -> Self {
        Fresh {
            max_turn_cos: (deg < 1.0).then(|| deg.to_radians().cos()),
        }
    }

    /// [`stale`], or the normal kept in `m` turned more than the limit.
    fn stale(&self, pos12: &Pose, g1: &dyn Shape, g2: &dyn Shape, m: &Manifold) -> bool {
        if let Some(c) = self.max_turn_cos {
            // parry's own coherence test (`try_update_contacts_eps`), with our angle.
            if !m.points.is_empty() && -m.local_n1.dot(pos12.rotation * m.local_n2) < c {
                return true;
            }
        }
        stale(pos12, g1, g2, m)
    }
}

type Manifold = ContactManifold<ContactManifoldData, ContactData>;

/// How much deeper than every contact point kept from the last step two shapes may
/// interpenetrate before their manifold is recomputed (m).
const MISSED: Real = 1e-5;

/// Whether `m` kept contact points that miss where the shapes interpenetrate most: their
/// exact penetration depth (parry's GJK/EPA contact query) is more than [`MISSED`] deeper
/// than every kept point. Recomputing every manifold at every step instead moved bodies at
/// rest (a ball in a dynamic bowl of box hulls turned 1.5° during the rest check with the
/// floor's manifolds recomputed; the pen of `pen_mug` came to a rest pose from which MuJoCo
/// rolls it 12° with all of them).
fn stale(pos12: &Pose, g1: &dyn Shape, g2: &dyn Shape, m: &Manifold) -> bool {
    if m.points.is_empty() {
        return false;
    }
    // Last step's points at the current poses, as parry's reuse would measure them.
    let kept = m
        .points
        .iter()
        .map(|pt| (*pos12 * pt.local_p2 - pt.local_p1).dot(m.local_n1))
        .fold(Real::INFINITY, Real::min);
    DefaultQueryDispatcher
        .contact(pos12, g1, g2, 0.0)
        .ok()
        .flatten()
        .is_some_and(|c| c.dist < 0.0 && c.dist < kept - MISSED)
}

impl QueryDispatcher for Fresh {
    fn intersection_test(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
    ) -> Result<ShapeIntersection, Unsupported> {
        DefaultQueryDispatcher.intersection_test(pos12, g1, g2)
    }

    fn distance(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
    ) -> Result<ShapeDistance, Unsupported> {
        DefaultQueryDispatcher.distance(pos12, g1, g2)
    }

    fn contact(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        prediction: Real,
    ) -> Result<Option<Contact>, Unsupported> {
        DefaultQueryDispatcher.contact(pos12, g1, g2, prediction)
    }

    fn closest_points(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        max_dist: Real,
    ) -> Result<ClosestPoints, Unsupported> {
        DefaultQueryDispatcher.closest_points(pos12, g1, g2, max_dist)
    }

    fn cast_shapes(
        &self,
        pos12: &Pose,
        local_vel12: Vector,
        g1: &dyn Shape,
        g2: &dyn Shape,
        options: ShapeCastOptions,
    ) -> Result<Option<ShapeCastHit>, Unsupported> {
        DefaultQueryDispatcher.cast_shapes(pos12, local_vel12, g1, g2, options)
    }

    fn cast_shapes_nonlinear(
        &self,
        motion1: &NonlinearRigidMotion,
        g1: &dyn Shape,
        motion2: &NonlinearRigidMotion,
        g2: &dyn Shape,
        start_time: Real,
        end_time: Real,
        stop_at_penetration: bool,
    ) -> Result<Option<ShapeCastHit>, Unsupported> {
        DefaultQueryDispatcher.cast_shapes_nonlinear(
            motion1,
            g1,
            motion2,
            g2,
            start_time,
            end_time,
            stop_at_penetration,
        )
    }
}

impl PersistentQueryDispatcher<ContactManifoldData, ContactData> for Fresh {
    fn contact_manifolds(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        prediction: Real,
        manifolds: &mut Vec<Manifold>,
        workspace: &mut Option<ContactManifoldsWorkspace>,
    ) -> Result<(), Unsupported> {
        for m in manifolds.iter_mut() {
            if self.stale(pos12, g1, g2, m) {
                m.mark_shapes_deformed();
            }
        }
        DefaultQueryDispatcher.contact_manifolds(pos12, g1, g2, prediction, manifolds, workspace)
    }

    fn contact_manifold_convex_convex(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        normal_constraints1: Option<&dyn NormalConstraints>,
        normal_constraints2: Option<&dyn NormalConstraints>,
        prediction: Real,
        manifold: &mut Manifold,
    ) -> Result<(), Unsupported> {
        if self.stale(pos12, g1, g2, manifold) {
            manifold.mark_shapes_deformed();
        }
        DefaultQueryDispatcher.contact_manifold_convex_convex(
            pos12,
            g1,
            g2,
            normal_constraints1,
            normal_constraints2,
            prediction,
            manifold,
        )
    }
}
