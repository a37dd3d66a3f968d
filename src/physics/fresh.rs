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
/// when they miss the deepest interpenetration (see [`stale`]).
pub(super) struct Fresh;

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
            if stale(pos12, g1, g2, m) {
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
        if stale(pos12, g1, g2, manifold) {
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
