//! The Rapier world built from [`SimBody`]s ([`Sim`]): bodies, colliders, the floor, the exact
//! contact queries the checks use, and [`rapier_mass_properties`].

use super::rolling;
use super::*;
use crate::pose::parry_pose;
use rapier3d_f64::dynamics::FrictionModel;

/// The mass properties Rapier gives a body built from `body` (for checks and debugging): the
/// reconstructed inertia tensor about the COM (body-frame axes), the COM and the mass.
pub fn rapier_mass_properties(body: &SimBody) -> Result<(f64, P3, Matrix3<f64>), PhysicsError> {
    let opts = SettleOptions::default();
    let mut sim = Sim::new(std::slice::from_ref(body), &opts)?;
    let w = &mut sim.world;
    // Mass properties are folded in at the first step; do it now.
    w.bodies[sim.handles[0]].recompute_mass_properties_from_colliders(&w.colliders);
    let mp = w.bodies[sim.handles[0]].mass_properties().local_mprops;
    let m = mp.reconstruct_inertia_matrix();
    let c = mp.local_com;
    Ok((
        mp.mass(),
        P3::new(c.x, c.y, c.z),
        Matrix3::from_fn(|r, k| m.col(k)[r]),
    ))
}

pub(super) fn from_pose(p: &Pose) -> Isometry3<f64> {
    let q = p.rotation;
    let t = p.translation;
    Isometry3::from_parts(
        Translation3::new(t.x, t.y, t.z),
        UnitQuaternion::new_normalize(Quaternion::new(q.w, q.x, q.y, q.z)),
    )
}

/// Principal inertia and its frame for Rapier, from a full symmetric tensor. Rejects tensors
/// that are not symmetric or not positive definite.
pub(super) fn principal_inertia(body: &SimBody) -> Result<(Vector, Rotation), PhysicsError> {
    let i = body.inertia;
    if i.iter().any(|x| !x.is_finite()) {
        return Err(body_error(
            body,
            "inertia tensor has a NaN or infinite entry",
        ));
    }
    let scale = i.abs().max();
    if scale <= 0.0 {
        return Err(body_error(body, "inertia tensor is zero"));
    }
    let asym = (i - i.transpose()).abs().max();
    if asym > 1e-9 * scale {
        return Err(body_error(
            body,
            format!("inertia tensor is not symmetric (|I − Iᵀ| = {asym:.3e})"),
        ));
    }
    let sym = (i + i.transpose()) * 0.5;
    let eig = sym.symmetric_eigen();
    let mut vecs = eig.eigenvectors;
    let vals = eig.eigenvalues;
    if vals.min() <= 1e-12 * scale {
        return Err(body_error(
            body,
            format!(
                "inertia tensor is not positive definite (principal moments {:.3e}, {:.3e}, {:.3e})",
                vals[0], vals[1], vals[2]
            ),
        ));
    }
    if vecs.determinant() < 0.0 {
        vecs.column_mut(2).neg_mut();
    }
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(vecs));
    let q = q.quaternion();
    Ok((
        Vector::new(vals[0], vals[1], vals[2]),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w).normalize(),
    ))
}

/// Contacts of the scene at one instant. Index `n` (the number of bodies) stands for the floor.
pub(super) struct ContactGraph {
    /// `supports[i]`: bodies (or the floor) within the distance whose contact normal towards `i`
    /// points up enough; sorted.
    pub(super) supports: Vec<Vec<usize>>,
    /// `touching[i]`: everything within the distance; sorted.
    pub(super) touching: Vec<Vec<usize>>,
    /// `penetration[i]`: deepest penetration (≥ 0) and with what.
    pub(super) penetration: Vec<(f64, Option<usize>)>,
}

/// A Rapier world built from the scene, plus what the exact queries need.
pub(super) struct Sim<'a> {
    pub(super) bodies: &'a [SimBody],
    pub(super) opts: &'a SettleOptions,
    pub(super) world: PhysicsWorld,
    pub(super) handles: Vec<RigidBodyHandle>,
    pub(super) colliders: Vec<Vec<ColliderHandle>>,
    pub(super) bbox_diagonal: Vec<f64>,
    /// Distance from the centre of mass to the farthest hull vertex.
    pub(super) reach: Vec<f64>,
    /// The rolling resistance's torques ([`SettleOptions::rolling_friction`]).
    rolling: rolling::Rolling,
}

impl<'a> Sim<'a> {
    pub(super) fn new(
        bodies: &'a [SimBody],
        opts: &'a SettleOptions,
    ) -> Result<Self, PhysicsError> {
        validate_options(opts)?;
        let mut world = PhysicsWorld::new();
        world.narrow_phase =
            NarrowPhase::with_query_dispatcher(fresh::Fresh::new(opts.contact_reuse_max_turn_deg));
        world.gravity = Vector::new(0.0, 0.0, -opts.gravity);
        let ip = &mut world.integration_parameters;
        ip.dt = opts.dt;
        ip.num_solver_iterations = opts.solver_iterations;
        ip.num_internal_pgs_iterations = opts.pgs_iterations;
        ip.num_internal_stabilization_iterations = opts.stabilization_iterations;
        ip.contact_recycling = opts.contact_recycling;
        ip.contact_clustering = opts.contact_clustering;
        ip.friction_in_bias_pass = opts.friction_in_bias_pass;
        ip.normalized_max_corrective_velocity = opts.max_corrective_velocity / ip.length_unit;
        ip.friction_model = if opts.coulomb_friction {
            FrictionModel::Coulomb
        } else {
            FrictionModel::Simplified
        };
        ip.normalized_prediction_distance = opts.prediction_distance / ip.length_unit;
        ip.normalized_contact_recycle_distance = opts.contact_recycle_distance / ip.length_unit;
        ip.contact_softness.natural_frequency = opts.contact_frequency;
        ip.static_contact_softness.natural_frequency = opts.static_contact_frequency;
        ip.contact_softness.damping_ratio = opts.contact_damping_ratio;
        ip.static_contact_softness.damping_ratio = opts.contact_damping_ratio;

        let mut names = std::collections::BTreeSet::new();
        let mut scene_extent: f64 = 1.0;
        let mut handles = Vec::with_capacity(bodies.len());
        let mut colliders = Vec::with_capacity(bodies.len());
        let mut bbox_diagonal = Vec::with_capacity(bodies.len());
        let mut reach = Vec::with_capacity(bodies.len());
        for b in bodies {
            if b.name == FLOOR || !names.insert(b.name.as_str()) {
                return Err(body_error(
                    b,
                    "names must be unique and must not be 'floor'",
                ));
            }
            let (rb, diag) = body_builder(b, opts)?;
            let t = b.pose.translation.vector;
            scene_extent = scene_extent.max(t.abs().max() + diag);
            let h = world.insert_body(rb);
            let mut hs = Vec::with_capacity(b.hulls.len());
            for (k, hull) in b.hulls.iter().enumerate() {
                let (points, _) = hull.to_parry();
                let co = ColliderBuilder::convex_hull(&points)
                    .ok_or_else(|| {
                        body_error(
                            b,
                            format!(
                                "hull {k} ({} vertices) has no 3D convex hull (too few or coplanar points)",
                                points.len()
                            ),
                        )
                    })?
                    .density(0.0);
                let size = hull.aabb().map(|a| a.diagonal()).unwrap_or(0.0);
                let volume = co.shape.mass_properties(1.0).mass();
                if volume.is_nan() || volume <= 1e-9 * size * size * size {
                    return Err(body_error(
                        b,
                        format!(
                            "hull {k} is flat (volume {volume:.3e} m³ for a {:.3e} m extent)",
                            size
                        ),
                    ));
                }
                let co = co.friction(b.friction).restitution(opts.restitution);
                hs.push(world.insert_collider(co, Some(h)));
            }
            handles.push(h);
            colliders.push(hs);
            bbox_diagonal.push(diag);
            reach.push(
                b.hulls
                    .iter()
                    .flat_map(|h| h.vertices.iter())
                    .map(|v| (v - b.com).norm())
                    .fold(0.0, f64::max),
            );
        }
        // The floor: a large thin fixed box whose top face is `FLOOR_GAP` below z = 0 (its
        // contacts kept sound by `fresh::Fresh` like every pair's). Not a half-space: parry's
        // half-space manifold takes the hull face whose normal is closest to straight down,
        // whether or not it holds the lowest vertex, and a YCB fork (10 thin hulls, 20 g)
        // jittered up to 2.4 mm into it.
        let half = 10.0 * scene_extent;
        let floor = world.insert_body(RigidBodyBuilder::fixed().translation(Vector::new(
            0.0,
            0.0,
            -0.5 * scene_extent - FLOOR_GAP,
        )));
        world.insert_collider(
            ColliderBuilder::cuboid(half, half, 0.5 * scene_extent)
                .friction(opts.floor_friction)
                .restitution(opts.restitution),
            Some(floor),
        );
        let rolling = rolling::Rolling::new(opts.rolling_friction, opts.coulomb_friction, &handles);
        Ok(Sim {
            rolling,
            bodies,
            opts,
            world,
            handles,
            colliders,
            bbox_diagonal,
            reach,
        })
    }

    /// One Rapier step, then the rolling resistance's torques for the next
    /// ([`SettleOptions::rolling_friction`]).
    pub(super) fn step(&mut self) {
        self.world.step();
        self.rolling.update(&mut self.world, &self.handles);
    }

    /// The perturbation of [`SettleOptions::perturbation_speed`]: every dynamic body turns about
    /// the same oblique world axis so that its farthest point moves at that speed.
    pub(super) fn kick(&mut self) {
        let axis = Vector::new(1.0, 2.0, 3.0).normalize();
        for i in 0..self.bodies.len() {
            if self.bodies[i].fixed || self.reach[i] <= 0.0 {
                continue;
            }
            let w = axis * (self.opts.perturbation_speed / self.reach[i]);
            self.world.bodies[self.handles[i]].set_angvel(w, true);
        }
    }

    pub(super) fn name(&self, k: usize) -> &str {
        if k == self.bodies.len() {
            FLOOR
        } else {
            &self.bodies[k].name
        }
    }

    pub(super) fn pose(&self, i: usize) -> Isometry3<f64> {
        from_pose(self.world.bodies[self.handles[i]].position())
    }

    /// World poses, shapes and AABBs (grown by `margin`) of every hull of every body.
    pub(super) fn hull_states(&self, margin: f64) -> Vec<Vec<(Pose, &dyn Shape, Aabb)>> {
        (0..self.bodies.len())
            .map(|i| {
                let pose = *self.world.bodies[self.handles[i]].position();
                self.colliders[i]
                    .iter()
                    .map(|&c| {
                        let shape = self.world.colliders[c].shape();
                        let aabb = shape.compute_aabb(&pose).loosened(margin);
                        (pose, shape, aabb)
                    })
                    .collect()
            })
            .collect()
    }

    /// How far the turn from pose `a` to pose `b` moves body `i`'s shape, the translation
    /// left out (see [`BodyReport::settle_shape_shift`]). Hull vertices sample the shape: the
    /// distance to a convex hull is convex, so over each turned hull it peaks at a vertex.
    pub(super) fn shape_shift(&self, i: usize, a: &Isometry3<f64>, b: &Isometry3<f64>) -> f64 {
        let body = &self.bodies[i];
        let shapes: Vec<&dyn Shape> = self.colliders[i]
            .iter()
            .map(|&c| self.world.colliders[c].shape())
            .collect();
        // The turn in the body frame: body point p at pose b sits where com + turn·(p − com)
        // sits at pose a, once the centres of mass are matched.
        let turn = a.rotation.inverse() * b.rotation;
        let gap = |turn: &UnitQuaternion<f64>| -> f64 {
            body.hulls
                .iter()
                .flat_map(|h| h.vertices.iter())
                .map(|p| {
                    let q = body.com + turn * (p - body.com);
                    shapes
                        .iter()
                        .map(|s| s.distance_to_local_point(Vector::new(q.x, q.y, q.z), true))
                        .fold(f64::INFINITY, f64::min)
                })
                .fold(0.0, f64::max)
        };
        gap(&turn).max(gap(&turn.inverse()))
    }

    /// Signed distance of a body's lowest hull vertex to the floor plane.
    pub(super) fn floor_distance(&self, hulls: &[(Pose, &dyn Shape, Aabb)]) -> f64 {
        hulls
            .iter()
            .map(|(pose, shape, _)| {
                shape
                    .as_convex_polyhedron()
                    .map(|p| {
                        p.points()
                            .iter()
                            .map(|v| pose.transform_point(*v).z)
                            .fold(Real::INFINITY, Real::min)
                    })
                    .unwrap_or(Real::INFINITY)
            })
            .fold(Real::INFINITY, Real::min)
    }

    /// Exact contacts (f64 GJK/EPA between convex hulls, vertex heights for the floor) of every
    /// pair closer than `distance`.
    pub(super) fn contact_graph(&self, distance: f64) -> ContactGraph {
        let n = self.bodies.len();
        let states = self.hull_states(distance);
        let mut supports = vec![Vec::new(); n];
        let mut touching = vec![Vec::new(); n];
        let mut penetration = vec![(0.0, None); n];
        let min_nz = self.opts.support_min_normal_z;
        let note_pen = |pen: &mut Vec<(f64, Option<usize>)>, i: usize, k: usize, d: f64| {
            if -d > pen[i].0 {
                pen[i] = (-d, Some(k));
            }
        };
        for i in 0..n {
            let fd = self.floor_distance(&states[i]);
            if fd <= distance {
                touching[i].push(n);
                supports[i].push(n);
                note_pen(&mut penetration, i, n, fd);
            }
        }
        for i in 0..n {
            for j in i + 1..n {
                let mut min_dist = Real::INFINITY;
                let (mut j_supports_i, mut i_supports_j) = (false, false);
                for (pi, si, ai) in &states[i] {
                    for (pj, sj, aj) in &states[j] {
                        if !ai.intersects(aj) {
                            continue;
                        }
                        // Shape 1 = j, shape 2 = i: normal1 points from j towards i.
                        if let Ok(Some(c)) = query::contact(pj, *sj, pi, *si, distance) {
                            min_dist = min_dist.min(c.dist);
                            j_supports_i |= c.normal1.z >= min_nz;
                            i_supports_j |= c.normal1.z <= -min_nz;
                        }
                    }
                }
                if min_dist <= distance {
                    touching[i].push(j);
                    touching[j].push(i);
                    note_pen(&mut penetration, i, j, min_dist);
                    note_pen(&mut penetration, j, i, min_dist);
                }
                if j_supports_i {
                    supports[i].push(j);
                }
                if i_supports_j {
                    supports[j].push(i);
                }
            }
        }
        for v in supports.iter_mut().chain(touching.iter_mut()) {
            v.sort_unstable();
        }
        ContactGraph {
            supports,
            touching,
            penetration,
        }
    }

    /// Deepest exact penetration of every body now (pairs of fixed bodies excluded).
    pub(super) fn penetrations(&self) -> Vec<(f64, Option<usize>)> {
        let n = self.bodies.len();
        let states = self.hull_states(0.0);
        let mut pen = vec![(0.0, None); n];
        let body_aabb: Vec<Option<Aabb>> = states
            .iter()
            .map(|hs| hs.iter().map(|h| h.2).reduce(|a, b| a.merged(&b)))
            .collect();
        for i in 0..n {
            if self.bodies[i].fixed {
                continue;
            }
            let d = self.floor_distance(&states[i]);
            if -d > pen[i].0 {
                pen[i] = (-d, Some(n));
            }
        }
        for i in 0..n {
            for j in i + 1..n {
                if self.bodies[i].fixed && self.bodies[j].fixed {
                    continue;
                }
                match (&body_aabb[i], &body_aabb[j]) {
                    (Some(a), Some(b)) if a.intersects(b) => {}
                    _ => continue,
                }
                let mut deepest: Real = 0.0;
                for (pi, si, ai) in &states[i] {
                    for (pj, sj, aj) in &states[j] {
                        if !ai.intersects(aj) {
                            continue;
                        }
                        if let Ok(Some(c)) = query::contact(pj, *sj, pi, *si, 0.0) {
                            deepest = deepest.max(-c.dist);
                        }
                    }
                }
                if deepest > pen[i].0 {
                    pen[i] = (deepest, Some(j));
                }
                if deepest > pen[j].0 {
                    pen[j] = (deepest, Some(i));
                }
            }
        }
        pen
    }
}

pub(super) fn validate_options(o: &SettleOptions) -> Result<(), PhysicsError> {
    let bad = |what: &str| Err(PhysicsError::InvalidOptions(what.to_string()));
    if !(o.dt.is_finite() && o.dt > 0.0 && o.dt <= 0.1) {
        return bad("dt must be in (0, 0.1] s");
    }
    if o.solver_iterations == 0 {
        return bad("solver_iterations must be at least 1");
    }
    if o.pgs_iterations == 0 {
        return bad("pgs_iterations must be at least 1");
    }
    if o.load_ratio.is_nan() || o.load_ratio < 0.0 {
        return bad("load_ratio must be >= 0 (0: off)");
    }
    let nonneg = [
        ("gravity", o.gravity),
        ("settle_max_time", o.settle_max_time),
        ("rest_time", o.rest_time),
        ("restitution", o.restitution),
        ("floor_friction", o.floor_friction),
        ("sleep_linear_threshold", o.sleep_linear_threshold),
        ("sleep_time", o.sleep_time),
        ("contact_frequency", o.contact_frequency),
        ("static_contact_frequency", o.static_contact_frequency),
        ("contact_damping_ratio", o.contact_damping_ratio),
        ("linear_damping", o.linear_damping),
        ("prediction_distance", o.prediction_distance),
        ("contact_reuse_max_turn_deg", o.contact_reuse_max_turn_deg),
        ("rolling_friction", o.rolling_friction),
        ("contact_recycle_distance", o.contact_recycle_distance),
        ("angular_damping", o.angular_damping),
        ("perturbation_speed", o.perturbation_speed),
        ("max_relative_drift", o.max_relative_drift),
        ("max_settle_rotation_deg", o.max_settle_rotation_deg),
        ("max_rest_motion", o.max_rest_motion),
        ("max_rest_rotation_deg", o.max_rest_rotation_deg),
        ("creep_max_motion", o.creep_max_motion),
        ("creep_max_rotation_deg", o.creep_max_rotation_deg),
        ("creep_contact_distance", o.creep_contact_distance),
        ("creep_max_imbalance", o.creep_max_imbalance),
        ("max_rest_penetration", o.max_rest_penetration),
        ("max_initial_penetration", o.max_initial_penetration),
        ("support_distance", o.support_distance),
        ("support_release_margin", o.support_release_margin),
    ];
    for (name, v) in nonneg {
        if !(v.is_finite() && v >= 0.0) {
            return Err(PhysicsError::InvalidOptions(format!(
                "{name} must be a finite number ≥ 0, got {v}"
            )));
        }
    }
    if !o.support_min_normal_z.is_finite() || o.support_min_normal_z.abs() > 1.0 {
        return bad("support_min_normal_z must be in [-1, 1]");
    }
    if !(o.probe_angle_deg.is_finite() && o.probe_angle_deg >= 0.0 && o.probe_angle_deg <= 10.0) {
        return bad("probe_angle_deg must be in [0, 10]");
    }
    if !(o.probe_time.is_finite() && o.probe_time >= 0.0) {
        return bad("probe_time must be finite and >= 0");
    }
    Ok(())
}

/// The Rapier body of a [`SimBody`] (validated) and its bounding-box diagonal.
pub(super) fn body_builder(
    b: &SimBody,
    opts: &SettleOptions,
) -> Result<(rapier3d_f64::prelude::RigidBody, f64), PhysicsError> {
    if b.hulls.is_empty() {
        return Err(body_error(b, "has no collision hulls"));
    }
    let all = b.hulls.iter().flat_map(|h| h.vertices.iter());
    if b.hulls.iter().any(|h| {
        h.vertices
            .iter()
            .any(|p| !p.coords.iter().all(|x| x.is_finite()))
    }) {
        return Err(body_error(b, "a hull vertex is NaN or infinite"));
    }
    let diag = crate::mesh::Aabb::of_points(all)
        .map(|a| a.diagonal())
        .unwrap_or(0.0);
    let p = b.pose.translation.vector;
    let q = b.pose.rotation.quaternion();
    if !(p.iter().all(|x| x.is_finite()) && q.coords.iter().all(|x| x.is_finite())) {
        return Err(body_error(b, "pose is NaN or infinite"));
    }
    if !(b.friction.is_finite() && b.friction >= 0.0) {
        return Err(body_error(
            b,
            format!("friction must be ≥ 0, got {}", b.friction),
        ));
    }
    let pose = parry_pose(&b.pose);
    if b.fixed {
        return Ok((RigidBodyBuilder::fixed().pose(pose).build(), diag));
    }
    if !(b.mass.is_finite() && b.mass > 0.0) {
        return Err(body_error(b, format!("mass must be > 0, got {}", b.mass)));
    }
    if !b.com.coords.iter().all(|x| x.is_finite()) {
        return Err(body_error(b, "centre of mass is NaN or infinite"));
    }
    let (principal, frame) = principal_inertia(b)?;
    let mp = MassProperties::with_principal_inertia_frame(
        Vector::new(b.com.x, b.com.y, b.com.z),
        b.mass,
        principal,
        frame,
    );
    let mut rb = RigidBodyBuilder::dynamic()
        .pose(pose)
        .additional_mass_properties(mp)
        .linear_damping(opts.linear_damping)
        .angular_damping(opts.angular_damping)
        .build();
    let act = rb.activation_mut();
    act.normalized_linear_threshold = opts.sleep_linear_threshold;
    act.time_until_sleep = opts.sleep_time;
    Ok((rb, diag))
}

/// How far turning `body` from orientation `from` to orientation `to` about its centre of mass
/// moves its shape (m): the settle test's measure of a large turn ([`BodyReport::settle_shape_shift`]),
/// for a turn another engine reports.
pub fn shape_shift(
    body: &SimBody,
    from: &UnitQuaternion<f64>,
    to: &UnitQuaternion<f64>,
) -> Result<f64, PhysicsError> {
    let opts = SettleOptions::default();
    let alone = SimBody {
        pose: Isometry3::identity(),
        ..body.clone()
    };
    let sim = Sim::new(std::slice::from_ref(&alone), &opts)?;
    let at = |q: &UnitQuaternion<f64>| Isometry3::from_parts(Translation3::identity(), *q);
    Ok(sim.shape_shift(0, &at(from), &at(to)))
}
