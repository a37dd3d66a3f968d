//! `report.json`: what export computed for each object, and the validation verdict.
//! Field names and order are part of the documented schema (README).
//!
//! Entry points: [`Report::new`], [`Report::warning_lines`] (what `export` and `validate` print
//! under their table).

use crate::body::Assembly;
use crate::decompose::scene_aware::metrics::TwoSided;
use crate::export::format::round;
use crate::inertia::VolumeSource;
use serde::Serialize;

/// The whole report.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Always "interact3d".
    pub tool: &'static str,
    pub version: &'static str,
    pub scene: String,
    /// Convex decomposition engine.
    pub decomposer: String,
    /// Metres per scene unit applied by preparation (units and `--size`).
    pub scale: f64,
    pub objects: Vec<ObjectReport>,
    pub warnings: Vec<String>,
    /// Present when validation ran.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub validation: Option<serde_json::Value>,
}

/// One object.
#[derive(Clone, Debug, Serialize)]
pub struct ObjectReport {
    pub name: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
    /// kg
    pub mass: f64,
    /// Centre of mass in the world at the composed pose (m).
    pub com: [f64; 3],
    /// Inertia tensor about the centre of mass, world axes (kg·m²).
    pub inertia: [[f64; 3]; 3],
    /// m³
    pub volume: f64,
    pub volume_source: VolumeSource,
    pub closed: bool,
    pub triangles: usize,
    /// World bounding box extents at the composed pose (m).
    pub extents: [f64; 3],
    pub hull_count: usize,
    pub hull_vertex_counts: Vec<usize>,
    /// How close the collision hulls lie to the mesh, as fractions of its bounding-box
    /// diagonal: `p95` = max(`hull_to_mesh_p95`, `mesh_to_hull_p95`) is the figure the
    /// tolerance warning reads; `outside_p99`/`outside_max`: how far mesh surface lies
    /// outside every hull. Absent for an export folder read back.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub collision_fit: Option<TwoSided>,
    pub fixed: bool,
    pub friction: f64,
    pub warnings: Vec<String>,
}

impl Report {
    /// Every warning of the report and of `validation`, one line each, in a fixed order: the
    /// scene's, then each object's (prefixed with its name), then the validation's. Repeats are
    /// listed once.
    pub fn warning_lines(&self, validation: Option<&crate::validate::Validation>) -> Vec<String> {
        let mut lines: Vec<String> = self.warnings.clone();
        for o in &self.objects {
            lines.extend(o.warnings.iter().map(|w| format!("{}: {w}", o.name)));
        }
        if let Some(v) = validation {
            lines.extend(v.warnings.iter().cloned());
        }
        let mut seen = std::collections::BTreeSet::new();
        lines
            .into_iter()
            .map(|l| l.replace(['\n', '\r'], " "))
            .filter(|l| seen.insert(l.clone()))
            .collect()
    }

    /// The report of an assembly (no validation yet).
    pub fn new(a: &Assembly) -> Report {
        let objects = a
            .bodies
            .iter()
            .map(|b| {
                let com = b.composed_pose.translation.vector;
                let ext = b.geometry.aabb().map(|x| x.extents()).unwrap_or_default();
                ObjectReport {
                    name: b.name.clone(),
                    label: b.label.clone(),
                    mass: round(b.inertial.mass),
                    com: [round(com.x), round(com.y), round(com.z)],
                    inertia: std::array::from_fn(|r| {
                        std::array::from_fn(|c| round(b.inertial.inertia[(r, c)]))
                    }),
                    volume: round(b.inertial.volume),
                    volume_source: b.inertial.source,
                    closed: b.closed,
                    triangles: b.visual.triangle_count(),
                    extents: [round(ext.x), round(ext.y), round(ext.z)],
                    hull_count: b.hulls.len(),
                    hull_vertex_counts: b.hulls.iter().map(|h| h.vertices.len()).collect(),
                    collision_fit: b.fidelity.map(|f| TwoSided {
                        p95: round(f.p95),
                        hull_to_mesh_p95: round(f.hull_to_mesh_p95),
                        mesh_to_hull_p95: round(f.mesh_to_hull_p95),
                        outside_p99: round(f.outside_p99),
                        outside_max: round(f.outside_max),
                    }),
                    fixed: b.fixed,
                    friction: round(b.friction),
                    warnings: b.warnings.clone(),
                }
            })
            .collect();
        Report {
            tool: "interact3d",
            version: env!("CARGO_PKG_VERSION"),
            scene: a.name.clone(),
            decomposer: a.decomposer.clone(),
            scale: round(a.scene_to_world.scale),
            objects,
            warnings: a.warnings.clone(),
            validation: None,
        }
    }
}
