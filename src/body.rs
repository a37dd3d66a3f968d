//! Bodies: what a simulator gets for each object. The frame of a body is at its centre of mass
//! with world-aligned axes at the composed pose; visual and collision geometry are expressed in it.

use crate::decompose::scene_aware::geom::Surface;
use crate::decompose::scene_aware::metrics::{self, TwoSided};
use crate::decompose::{scene_aware::SceneAware, vhacd::Vhacd, DecomposeOptions, Decomposer, Hull};
use crate::error::{Error, Result};
use crate::inertia::{self, Inertial, DEFAULT_DENSITY};
use crate::mesh::{Mesh, VisualMesh};
use crate::pose::Similarity;
use crate::prepare::{prepare, PrepareOptions, PreparedScene};
use crate::scene::Scene;
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use rayon::prelude::*;

/// Smallest principal moment of inertia (kg·m²) written: MuJoCo 3/4 refuses a `fullinertia`
/// whose eigenvalues are smaller ("inertia must have positive eigenvalues"; measured: 3e-15
/// refused, 1e-14 accepted). A 0.6 mm cube of water is at the limit.
pub const MIN_PRINCIPAL_INERTIA: f64 = 1e-14;

/// Default friction coefficient when the scene gives none.
pub const DEFAULT_FRICTION: f64 = 0.8;

/// One rigid body.
#[derive(Clone, Debug)]
pub struct Body {
    pub name: String,
    pub label: Option<String>,
    /// World pose of the body frame to start the simulation from (composed, or settled).
    pub pose: Isometry3<f64>,
    /// World pose of the body frame as composed.
    pub composed_pose: Isometry3<f64>,
    /// Original mesh frame → body frame.
    pub mesh_to_body: Similarity,
    /// Visual mesh in the body frame.
    pub visual: VisualMesh,
    /// Welded geometry in the body frame.
    pub geometry: Mesh,
    /// Convex collision hulls in the body frame.
    pub hulls: Vec<Hull>,
    /// Mass properties in the body frame (centre of mass at the origin).
    pub inertial: Inertial,
    pub friction: f64,
    pub fixed: bool,
    pub closed: bool,
    pub warnings: Vec<String>,
    /// How close the collision hulls lie to the mesh, both ways (see
    /// `decompose::scene_aware::metrics::two_sided`); `None` when not measured (an export
    /// folder read back).
    pub fidelity: Option<TwoSided>,
}

impl Body {
    /// Geometry at the composed pose, world frame.
    pub fn world_geometry(&self) -> Mesh {
        self.geometry
            .transformed(&self.composed_pose.to_homogeneous())
    }
    /// Hulls at the composed pose, world frame.
    pub fn world_hulls(&self) -> Vec<Hull> {
        self.hulls
            .iter()
            .map(|h| h.transformed(&self.composed_pose))
            .collect()
    }
}

/// A scene of bodies ready to export or simulate.
#[derive(Clone, Debug)]
pub struct Assembly {
    pub name: String,
    pub bodies: Vec<Body>,
    /// Decomposition engine used.
    pub decomposer: String,
    /// Scene-unit → world similarity applied by preparation.
    pub scene_to_world: Similarity,
    pub warnings: Vec<String>,
}

/// Which decomposition engine to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Engine {
    /// Scene-aware surface-patch hulls kept off the neighbours (see `decompose::scene_aware`).
    #[default]
    SceneAware,
    /// parry's V-HACD, each object alone.
    Vhacd,
}

impl Engine {
    pub fn decomposer(&self) -> Box<dyn Decomposer> {
        match self {
            Engine::SceneAware => Box::new(SceneAware::new()),
            Engine::Vhacd => Box::new(Vhacd),
        }
    }
}

/// Options of the whole build (prepare → decompose → inertia).
#[derive(Clone, Debug, Default)]
pub struct BuildOptions {
    pub prepare: PrepareOptions,
    pub decompose: DecomposeOptions,
    pub engine: Engine,
}

/// Load-to-bodies in one call.
pub fn build(scene: &Scene, opts: &BuildOptions) -> Result<Assembly> {
    let prepared = prepare(scene, &opts.prepare)?;
    assemble(
        &prepared,
        &*opts.engine.decomposer(),
        &opts.decompose,
        &scene.source,
    )
}

/// Each object's two-sided figures ([`metrics::two_sided`]), the objects side by side, on the
/// surfaces the engine built when it handed them over (`surfaces`, in order; an object
/// without one gets its surface built here, as [`metrics::two_sided_of`] does). `None` for an
/// object without hulls, which `assemble` refuses anyway.
fn fidelities(
    prepared: &PreparedScene,
    hull_sets: &[Vec<Hull>],
    surfaces: Vec<Option<Surface>>,
) -> Vec<Option<TwoSided>> {
    let mut surfaces = surfaces.into_iter();
    let jobs: Vec<(&Mesh, &[Hull], Option<Surface>)> = prepared
        .objects
        .iter()
        .zip(hull_sets)
        .map(|(o, h)| (&o.geometry, h.as_slice(), surfaces.next().flatten()))
        .collect();
    jobs.into_par_iter()
        .map(|(mesh, hulls, surface)| match surface {
            _ if hulls.is_empty() => None,
            Some(s) => metrics::two_sided(&s, hulls, metrics::TWO_SIDED_SAMPLES),
            None => metrics::two_sided_of(mesh, hulls),
        })
        .collect()
}

/// Decompose a prepared scene and compute its bodies.
pub fn assemble(
    prepared: &PreparedScene,
    engine: &dyn Decomposer,
    dopts: &DecomposeOptions,
    source: &std::path::Path,
) -> Result<Assembly> {
    let meshes: Vec<&Mesh> = prepared.objects.iter().map(|o| &o.geometry).collect();
    let mut hull_sets = engine.decompose(&meshes, &dopts.engine_budget())?;
    let legal = crate::decompose::physx_legal(&mut hull_sets, dopts);
    let mut scene_warnings = prepared.warnings.clone();
    if dopts.max_polygons > crate::decompose::PHYSX_MAX_POLYGONS {
        let n = crate::decompose::physx_recooked(&hull_sets);
        if n > 0 {
            scene_warnings.push(format!(
                "{n} of {} hulls have more than {} polygons: PhysX (Isaac Sim/Lab) re-cooks them \
                 from the USD into other shapes; export with --target isaac to keep every hull as written",
                hull_sets.iter().map(Vec::len).sum::<usize>(),
                crate::decompose::PHYSX_MAX_POLYGONS
            ));
        }
    }
    let notes = engine.object_warnings();
    let mut fidelities = fidelities(prepared, &hull_sets, engine.take_surfaces());
    let mut bodies = Vec::with_capacity(prepared.objects.len());
    for (k, (o, hulls)) in prepared.objects.iter().zip(hull_sets).enumerate() {
        let density = o.physical.density.unwrap_or(DEFAULT_DENSITY);
        let mut warnings = o.warnings.clone();
        warnings.extend(notes.get(k).into_iter().flatten().cloned());
        let l = legal[k];
        if l.dropped > 0 {
            warnings.push(format!(
                "{} sliver hull(s) dropped (extent/inner radius over {}: PhysX keeps them off the GPU)",
                l.dropped,
                crate::decompose::MAX_SLIVER_RATIO
            ));
        }
        if l.over > 0 {
            warnings.push(format!(
                "{} hull(s) could not be brought within {} vertices and {} polygons: PhysX will re-cook them",
                l.over, dopts.max_vertices, dopts.max_polygons
            ));
        }
        let smallest = o.geometry.aabb().map(|b| b.extents().min()).unwrap_or(0.0);
        if hulls.is_empty() && smallest > 0.0 && smallest < dopts.min_thickness {
            return Err(Error::input(
                source,
                format!(
                    "object {} is too small or too thin to simulate: its smallest extent is {smallest:.3e} m, \
                     under the {:.1e} m minimum collision hull thickness (MuJoCo refuses such meshes: \
                     \"mesh volume is too small\"); check the units or scale the scene with --size",
                    o.name, dopts.min_thickness
                ),
            ));
        }
        if hulls.is_empty() {
            return Err(Error::input(
                source,
                format!(
                    "object {}: no usable convex hull (the mesh is flat or degenerate)",
                    o.name
                ),
            ));
        }
        // Both directions, for every engine; the warning reads the headline figure.
        let fidelity = fidelities[k].take();
        if let Some(f) = &fidelity {
            warnings.extend(metrics::tolerance_warning(
                f,
                dopts.tolerance,
                hulls.len(),
                dopts.max_hulls,
            ));
        }
        let mut inertial = None;
        if o.closed {
            let m = inertia::of_closed_mesh(&o.geometry, density);
            if m.check().is_ok() && m.volume > 0.0 {
                inertial = Some(m);
            } else {
                warnings.push("closed mesh gave invalid mass properties (inward-facing or self-intersecting?): using the hull union".into());
            }
        }
        let mut inertial = match inertial {
            Some(m) => m,
            None => inertia::of_hull_union(&hulls, density, 96).ok_or_else(|| {
                Error::input(
                    source,
                    format!("object {}: collision hulls enclose no volume", o.name),
                )
            })?,
        };
        if let Some(mass) = o.physical.mass {
            inertial = inertial.with_mass(mass);
        }
        inertial
            .check()
            .map_err(|m| Error::input(source, format!("object {}: {m}", o.name)))?;
        let smallest_moment = inertial.inertia.symmetric_eigenvalues().min();
        if smallest_moment < MIN_PRINCIPAL_INERTIA {
            return Err(Error::input(
                source,
                format!(
                    "object {} is too small or too light to simulate: mass {:.3e} kg, smallest \
                     principal moment of inertia {smallest_moment:.3e} kg·m², under the \
                     {MIN_PRINCIPAL_INERTIA:.0e} MuJoCo accepts; check the units, scale the scene \
                     with --size, or give it a larger mass",
                    o.name, inertial.mass
                ),
            ));
        }
        let com = inertial.com;
        let to_body =
            Isometry3::from_parts(Translation3::from(-com.coords), UnitQuaternion::identity());
        let m = to_body.to_homogeneous();
        let mut visual = o.visual.clone();
        visual.transform(&m);
        let geometry = o.geometry.transformed(&m);
        let hulls: Vec<Hull> = hulls.iter().map(|h| h.transformed(&to_body)).collect();
        inertial.com = crate::mesh::P3::origin();
        let pose =
            Isometry3::from_parts(Translation3::from(com.coords), UnitQuaternion::identity());
        let mesh_to_body = Similarity {
            translation: o.to_world.translation - com.coords,
            ..o.to_world
        };
        bodies.push(Body {
            name: o.name.clone(),
            label: o.label.clone(),
            pose,
            composed_pose: pose,
            mesh_to_body,
            visual,
            geometry,
            hulls,
            inertial,
            friction: o.physical.friction.unwrap_or(DEFAULT_FRICTION),
            fixed: o.physical.fixed,
            closed: o.closed,
            warnings,
            fidelity,
        });
    }
    Ok(Assembly {
        name: prepared.name.clone(),
        bodies,
        decomposer: engine.name().to_string(),
        scene_to_world: prepared.scene_to_world,
        warnings: scene_warnings,
    })
}
