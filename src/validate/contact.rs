//! Contact depths of an asset at its initial pose, on the shapes the engines collide: parry's
//! exact primitives for boxes, spheres, capsules and cylinders (no tessellation error), the
//! convex hull for mesh pieces and ellipsoids (parry has no ellipsoid; a 16×32 tessellation).
//!
//! Entry points: [`exact_primitive`] (a geom's exact shape in its body frame), [`Collider`],
//! [`pair_depth`] (deepest penetration between two bodies), [`lowest_z`] (floor contact).
//!
//! A capsule is its core segment plus a radius: segment queries are polytope queries, which GJK
//! solves to round-off, where the capsule's curved support map would leave EPA's tolerance in
//! the depth.

use crate::decompose::Hull;
use crate::io::asset::{Geom, Shape};
use crate::pose::parry_pose;
use nalgebra::{Isometry3, UnitQuaternion, Vector3};
use parry3d_f64::bounding_volume::BoundingVolume;
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query;
use parry3d_f64::shape::{ConvexPolyhedron, Segment, SharedShape};

/// One convex collision shape placed in the world: a core and the radius swept around it.
#[derive(Clone)]
pub struct Collider {
    pub core: SharedShape,
    pub pose: Pose,
    /// Radius added around the core (a capsule's; 0 otherwise).
    pub radius: f64,
}

/// A geom's exact shape (core, radius) and its pose in the body frame; `None` for meshes,
/// ellipsoids and planes (those collide as hulls).
pub fn exact_primitive(g: &Geom) -> Option<(SharedShape, f64, Isometry3<f64>)> {
    Some(match &g.shape {
        Shape::Box(h) => (SharedShape::cuboid(h.x, h.y, h.z), 0.0, g.pose),
        Shape::Sphere(r) => (SharedShape::ball(*r), 0.0, g.pose),
        Shape::Capsule(r, h) => (
            SharedShape::new(Segment::new(
                Vector::new(0.0, 0.0, -h),
                Vector::new(0.0, 0.0, *h),
            )),
            *r,
            g.pose,
        ),
        // parry's cylinder axis is y; ours is z: +90° about x takes y to z.
        Shape::Cylinder(r, h) => (
            SharedShape::cylinder(*h, *r),
            0.0,
            g.pose
                * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2),
        ),
        _ => return None,
    })
}

impl Collider {
    /// A primitive in its body placed at `body` (world).
    pub fn primitive(
        core: SharedShape,
        radius: f64,
        local: &Isometry3<f64>,
        body: &Isometry3<f64>,
    ) -> Collider {
        Collider {
            core,
            pose: parry_pose(&(body * local)),
            radius,
        }
    }
    /// A hull already in world coordinates.
    pub fn hull(h: &Hull) -> Option<Collider> {
        let pts: Vec<_> = h.vertices.iter().map(crate::mesh::to_dvec).collect();
        Some(Collider {
            core: SharedShape::new(ConvexPolyhedron::from_convex_hull(&pts)?),
            pose: Pose::IDENTITY,
            radius: 0.0,
        })
    }
    /// The lowest world z of the shape.
    pub fn lowest_z(&self) -> f64 {
        let s = self
            .core
            .as_support_map()
            .expect("primitives and convex polyhedra are support maps");
        s.support_point(&self.pose, Vector::new(0.0, 0.0, -1.0)).z - self.radius
    }
    /// Penetration depth with another collider (0 when apart or touching).
    pub fn depth(&self, other: &Collider) -> f64 {
        let margin = self.radius + other.radius;
        let a = self.core.compute_aabb(&self.pose).loosened(self.radius);
        let b = other.core.compute_aabb(&other.pose).loosened(other.radius);
        if !a.intersects(&b) {
            return 0.0;
        }
        match query::contact(&self.pose, &*self.core, &other.pose, &*other.core, margin) {
            Ok(Some(c)) => (margin - c.dist).max(0.0),
            _ => 0.0,
        }
    }
}

/// Deepest penetration between any shape of one body and any shape of another (m, ≥ 0).
pub fn pair_depth(a: &[Collider], b: &[Collider]) -> f64 {
    a.iter()
        .flat_map(|x| b.iter().map(move |y| x.depth(y)))
        .fold(0.0, f64::max)
}

/// The lowest world z of a body's shapes (+∞ without shapes).
pub fn lowest_z(c: &[Collider]) -> f64 {
    c.iter()
        .map(Collider::lowest_z)
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::asset::{load, ReadOptions};

    /// Each body's colliders from an MJCF text, and the tessellated hulls the depths used
    /// before (for the comparison printed beside the exact value).
    fn read(xml: &str) -> (Vec<Vec<Collider>>, Vec<Vec<Collider>>) {
        let t = tempfile::tempdir().unwrap();
        let p = t.path().join("t.xml");
        std::fs::write(&p, xml).unwrap();
        let a = load(&p, &ReadOptions::default()).unwrap();
        let mut exact = Vec::new();
        let mut tess = Vec::new();
        for b in &a.bodies {
            let (mut e, mut h) = (Vec::new(), Vec::new());
            for g in b.geoms.iter().filter(|g| g.collision) {
                let (core, r, local) = exact_primitive(g).expect("a primitive");
                e.push(Collider::primitive(core, r, &local, &b.pose));
                for m in g.body_meshes() {
                    let hull = Hull::from_points(&m.vertices).unwrap().transformed(&b.pose);
                    h.push(Collider::hull(&hull).unwrap());
                }
            }
            exact.push(e);
            tess.push(h);
        }
        (exact, tess)
    }

    fn mjcf(bodies: &str) -> String {
        format!(
            r#"<mujoco><worldbody><geom type="plane" size="1 1 0.1"/>{bodies}</worldbody></mujoco>"#
        )
    }

    #[test]
    fn sphere_through_the_floor_is_r_minus_h() {
        // A sphere turned so that no tessellation vertex sits at its lowest point.
        for (r, h) in [(0.05, 0.047), (0.02, 0.0195), (0.1, 0.06)] {
            let (e, t) = read(&mjcf(&format!(
                r#"<body pos="0.1 0.2 {h}"><freejoint/><geom type="sphere" size="{r}" euler="13 7 29"/></body>"#
            )));
            let got = -lowest_z(&e[0]);
            eprintln!(
                "sphere r={r} h={h}: exact {got:.12} tessellated {:.12} analytic {:.12}",
                -lowest_z(&t[0]),
                r - h
            );
            assert!((got - (r - h)).abs() < 1e-9, "{got} vs {}", r - h);
        }
    }

    #[test]
    fn two_spheres_overlapping_by_d() {
        let (r1, r2) = (0.03, 0.02);
        let dir = Vector3::new(1.0, 2.0, 2.0) / 3.0;
        for d in [1e-4, 2e-3, 0.015] {
            let c = dir * (r1 + r2 - d);
            let (e, t) = read(&mjcf(&format!(
                r#"<body pos="0 0 0.5"><freejoint/><geom type="sphere" size="{r1}"/></body>
                   <body pos="{} {} {}"><freejoint/><geom type="sphere" size="{r2}" euler="31 -11 5"/></body>"#,
                c.x,
                c.y,
                0.5 + c.z
            )));
            let got = pair_depth(&e[0], &e[1]);
            eprintln!(
                "spheres d={d}: exact {got:.12} tessellated {:.12}",
                pair_depth(&t[0], &t[1])
            );
            assert!((got - d).abs() < 1e-9, "{got} vs {d}");
        }
        // Apart by 1 mm: no depth.
        let c = dir * (r1 + r2 + 1e-3);
        let (e, _) = read(&mjcf(&format!(
            r#"<body pos="0 0 0.5"><freejoint/><geom type="sphere" size="{r1}"/></body>
               <body pos="{} {} {}"><freejoint/><geom type="sphere" size="{r2}"/></body>"#,
            c.x,
            c.y,
            0.5 + c.z
        )));
        assert_eq!(pair_depth(&e[0], &e[1]), 0.0);
    }

    #[test]
    fn tilted_capsule_into_a_box_top() {
        // Box top at z = 0.1; a capsule (r 2 cm, half length 5 cm) tilted θ from vertical: its
        // lowest point is cz − h·cosθ − r, the depth 0.1 minus that.
        let (r, h) = (0.02, 0.05);
        for (deg, d) in [(20.0f64, 0.003), (55.0, 1e-4), (0.0, 0.01), (90.0, 0.005)] {
            let th = deg.to_radians();
            let cz = 0.1 - d + h * th.cos() + r;
            let (e, t) = read(&mjcf(&format!(
                r#"<body pos="0 0 0"><geom type="box" size="0.2 0.2 0.1"/></body>
                   <body pos="0.01 -0.02 {cz}"><freejoint/><geom type="capsule" size="{r} {h}" euler="0 {deg} 0"/></body>"#
            )));
            let got = pair_depth(&e[0], &e[1]);
            eprintln!(
                "capsule {deg}°: exact {got:.12} tessellated {:.12} analytic {d}",
                pair_depth(&t[0], &t[1])
            );
            assert!((got - d).abs() < 1e-9, "{deg}°: {got} vs {d}");
        }
    }

    #[test]
    fn tilted_cylinder_through_the_floor() {
        // Cylinder (r 4 cm, half length 6 cm) tilted θ about x: lowest point cz − h·cosθ − r·sinθ.
        let (r, h) = (0.04, 0.06);
        for deg in [0.0f64, 30.0, 90.0] {
            let th = deg.to_radians();
            let cz = 0.05;
            let want = -(cz - h * th.cos() - r * th.sin());
            let (e, t) = read(&mjcf(&format!(
                r#"<body pos="0 0 {cz}"><freejoint/><geom type="cylinder" size="{r} {h}" euler="{deg} 0 5"/></body>"#
            )));
            let got = -lowest_z(&e[0]);
            eprintln!(
                "cylinder {deg}°: exact {got:.12} tessellated {:.12} analytic {want:.12}",
                -lowest_z(&t[0])
            );
            assert!((got - want).abs() < 1e-9, "{deg}°: {got} vs {want}");
        }
    }
}
