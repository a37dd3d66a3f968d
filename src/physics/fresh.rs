//! Floor contacts that do not miss the lowest point of a hull.
//!
//! parry's manifold between two convex polyhedra (`contact_manifold_pfm_pfm`, which Rapier uses
//! for hull–hull and hull–box pairs) first tries to keep last step's contact points: while the
//! normal turned less than 1° and each point slid less than 1 mm (a squared distance of 1e-6,
//! in absolute units), it only updates their distances. Our objects are centimetres across:
//! a hull rocking on a nearly flat bottom of many small faces keeps contacts at the vertices it
//! first touched while others sink through. The GSO cardboard package (one 64-vertex hull,
//! 0.7 kg) sank 1–3.7 mm into the floor and failed the rest check at 7.5 mm, where MuJoCo
//! holds it within 1.2 mm; the LEGO suitcase (3.7 mm) and the porcelain pitcher (1.0 mm)
//! likewise. [`FreshFloor`] checks every manifold with the floor before handing the pair to
//! parry's default dispatcher: when the hull's lowest point lies deeper under the floor's face
//! than every kept point (see [`stale`]), the manifold is marked deformed and parry computes
//! it from the current poses (its points then include the deepest one). The package rests
//! within 0.01 mm.
//!
//! Hull–hull pairs keep parry's reuse: there is no face to measure "lowest" against. They can
//! sink the same way (the package on a fixed box hull: 1–4 mm); recomputing all their
//! manifolds at every step fixed that, but moved the pen of the `pen_mug` fixture to a rest
//! pose from which MuJoCo rolls it 12° about its axis (1.2 mm), beyond the agreement test's
//! 1 mm and 1°.

use rapier3d_f64::geometry::{ContactData, ContactManifoldData};
use rapier3d_f64::math::{Pose, Real, Vector};
use rapier3d_f64::parry::query::details::{NormalConstraints, ShapeCastOptions};
use rapier3d_f64::parry::query::{
    ClosestPoints, Contact, ContactManifold, ContactManifoldsWorkspace, DefaultQueryDispatcher,
    NonlinearRigidMotion, PersistentQueryDispatcher, QueryDispatcher, ShapeCastHit, ShapeDistance,
    ShapeIntersection, TrackedContact, Unsupported,
};
use rapier3d_f64::parry::shape::Shape;

/// parry's default dispatcher, but the floor's contact points kept from the last step are
/// recomputed when they miss the hull's lowest point (see [`stale`]).
pub(super) struct FreshFloor;

type Manifold = ContactManifold<ContactManifoldData, ContactData>;

/// Below the deepest contact kept from the last step, how much deeper a hull's lowest point
/// under the floor's face may lie before the floor's contacts are recomputed (m).
const MISSED: Real = 1e-5;

/// Whether `m`, a manifold between the floor (the only box of the world: hulls are convex
/// polyhedra) and a hull, kept contact points that miss the hull's lowest point: that point
/// lies more than [`MISSED`] deeper under the floor's face than every kept point. Recomputing
/// the floor's contacts at every step instead let resting bodies jitter (a ball in a dynamic
/// bowl of box hulls turned 1.5° during the rest check).
fn stale(pos12: &Pose, g1: &dyn Shape, g2: &dyn Shape, m: &Manifold) -> bool {
    if m.points.is_empty() {
        return false;
    }
    // The floor's frame f, its face normal there, the hull h and the pose of h in f.
    let (hull, n, pos_fh, floor_first) = if g1.as_cuboid().is_some() {
        (g2, m.local_n1, *pos12, true)
    } else if g2.as_cuboid().is_some() {
        (g1, m.local_n2, pos12.inverse(), false)
    } else {
        return false;
    };
    let Some(support) = hull.as_support_map() else {
        return false;
    };
    // Each kept point: (point on the floor, point on the hull), both in f.
    let pair = |pt: &TrackedContact<ContactData>| {
        if floor_first {
            (pt.local_p1, pos_fh * pt.local_p2)
        } else {
            (pt.local_p2, pos_fh * pt.local_p1)
        }
    };
    let kept = m
        .points
        .iter()
        .map(|pt| {
            let (on_floor, on_hull) = pair(pt);
            (on_hull - on_floor).dot(n)
        })
        .fold(Real::INFINITY, Real::min);
    let face = pair(&m.points[0]).0;
    let lowest = pos_fh * support.local_support_point(pos_fh.rotation.inverse() * -n);
    (lowest - face).dot(n) < kept - MISSED
}

impl QueryDispatcher for FreshFloor {
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

impl PersistentQueryDispatcher<ContactManifoldData, ContactData> for FreshFloor {
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
