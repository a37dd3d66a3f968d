//! Our scene manifest, `scene.json` (schema: `schema/scene.schema.json`, documented in the
//! README). Mesh paths are relative to the manifest and must stay inside its folder.

use super::{check_names, Physical, Scene, SceneObject, UpAxis};
use crate::error::{Error, Result};
use crate::io::{resolve_inside, Limits};
use crate::pose::Similarity;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The `format` value every manifest carries.
pub const FORMAT: &str = "interact3d-scene";

/// The manifest as stored.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    #[serde(default = "default_format")]
    pub format: String,
    #[serde(default = "default_version")]
    pub version: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    #[serde(default)]
    pub units: Units,
    #[serde(default = "default_up")]
    pub up_axis: UpAxis,
    pub objects: Vec<ManifestObject>,
}

fn default_format() -> String {
    FORMAT.into()
}
fn default_version() -> u32 {
    1
}
fn default_up() -> UpAxis {
    UpAxis::Z
}

/// Length unit: a name or metres per unit.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum Units {
    Named(String),
    MetersPerUnit(f64),
}

impl Default for Units {
    fn default() -> Self {
        Units::Named("m".into())
    }
}

impl Units {
    /// Metres per unit, or why the value is not a unit.
    pub fn meters(&self) -> std::result::Result<f64, String> {
        match self {
            Units::Named(n) => match n.as_str() {
                "m" | "meter" | "meters" | "metre" | "metres" => Ok(1.0),
                "cm" => Ok(0.01),
                "mm" => Ok(0.001),
                "in" | "inch" | "inches" => Ok(0.0254),
                other => Err(format!(
                    "unknown units {other:?} (m, cm, mm, in, or metres per unit as a number)"
                )),
            },
            Units::MetersPerUnit(x) if x.is_finite() && *x > 0.0 => Ok(*x),
            Units::MetersPerUnit(x) => Err(format!(
                "units must be a positive number of metres, got {x}"
            )),
        }
    }
}

/// One object of the manifest.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ManifestObject {
    pub name: String,
    /// Mesh file (GLB, glTF, OBJ, STL), relative to the manifest.
    pub mesh: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pose: Option<PoseSpec>,
    /// The pose the scene was composed at, when `pose` is a settled pose (written by export).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub composed_pose: Option<PoseSpec>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub fixed: bool,
    /// Convex collision hulls (OBJ files relative to the manifest), written by export.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub collision: Vec<String>,
    /// Mass properties in the mesh frame, written by export.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertial: Option<InertialSpec>,
}

/// A pose: a 4x4 matrix, or translation + quaternion + uniform scale. The quaternion may be
/// given in either order, `quaternion_wxyz` (MuJoCo's, scalar first) or `quaternion_xyzw`
/// (PyBullet's and ROS's, scalar last); export writes both, and when both are given they must
/// be the same rotation. Neither: the identity.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(untagged, deny_unknown_fields)]
pub enum PoseSpec {
    Matrix {
        matrix: Vec<Vec<f64>>,
    },
    Parts {
        #[serde(default = "zero3")]
        translation: [f64; 3],
        #[serde(default, skip_serializing_if = "Option::is_none")]
        quaternion_wxyz: Option<[f64; 4]>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        quaternion_xyzw: Option<[f64; 4]>,
        #[serde(default = "one")]
        scale: f64,
    },
}

fn zero3() -> [f64; 3] {
    [0.0; 3]
}
fn one() -> f64 {
    1.0
}

impl PoseSpec {
    pub fn to_similarity(&self) -> std::result::Result<Similarity, String> {
        match self {
            PoseSpec::Matrix { matrix } => Similarity::from_rows(matrix),
            PoseSpec::Parts {
                translation,
                quaternion_wxyz,
                quaternion_xyzw,
                scale,
            } => {
                let from_xyzw = quaternion_xyzw.map(|[x, y, z, w]| [w, x, y, z]);
                let q = match (quaternion_wxyz, from_xyzw) {
                    (Some(a), Some(b)) => {
                        let (sa, sb) = (
                            Similarity::from_parts(*translation, *a, *scale)?,
                            Similarity::from_parts(*translation, b, *scale)?,
                        );
                        if sa.rotation.angle_to(&sb.rotation) > 1e-6 {
                            return Err(format!(
                                "quaternion_wxyz {a:?} and quaternion_xyzw {:?} are different rotations (xyzw is the same four numbers with w last)",
                                quaternion_xyzw.unwrap_or_default()
                            ));
                        }
                        *a
                    }
                    (Some(a), None) => *a,
                    (None, Some(b)) => b,
                    (None, None) => [1.0, 0.0, 0.0, 0.0],
                };
                Similarity::from_parts(*translation, q, *scale)
            }
        }
    }

    /// The pose as parts, its quaternion in both orders.
    pub fn from_similarity(s: &Similarity) -> PoseSpec {
        let q = s.rotation.quaternion();
        PoseSpec::Parts {
            translation: [s.translation.x, s.translation.y, s.translation.z],
            quaternion_wxyz: Some([q.w, q.i, q.j, q.k]),
            quaternion_xyzw: Some([q.i, q.j, q.k, q.w]),
            scale: s.scale,
        }
    }
}

/// Mass properties as stored by export: mass (kg), centre of mass and the inertia tensor about
/// it (kg·m², row-major 3x3), both in the mesh frame.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct InertialSpec {
    pub mass: f64,
    pub com: [f64; 3],
    pub inertia: [[f64; 3]; 3],
}

/// Read and check a manifest without loading its meshes.
pub fn read(path: &Path) -> Result<Manifest> {
    read_with(path, &Limits::default())
}

/// [`read`] with the file size limit of `limits`.
pub fn read_with(path: &Path, limits: &Limits) -> Result<Manifest> {
    parse(path, &crate::io::read_file(path, limits)?)
}

/// Parse and check manifest bytes (`path` names the file in errors): the JSON, its format and
/// version, units, poses and physical values. Meshes are not touched.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<Manifest> {
    let m: Manifest = serde_json::from_slice(bytes)
        .map_err(|e| Error::input(path, format!("invalid scene manifest: {e}")))?;
    if m.format != FORMAT {
        return Err(Error::input(
            path,
            format!("format must be {FORMAT:?}, got {:?}", m.format),
        ));
    }
    if m.version != 1 {
        return Err(Error::input(
            path,
            format!("unsupported manifest version {}", m.version),
        ));
    }
    m.units.meters().map_err(|e| Error::input(path, e))?;
    for o in &m.objects {
        let ctx = |msg: String| Error::input(path, format!("object {:?}: {msg}", o.name));
        if let Some(p) = &o.pose {
            p.to_similarity().map_err(ctx)?;
        }
        for (what, v) in [
            ("density", o.density),
            ("mass", o.mass),
            ("friction", o.friction),
        ] {
            if let Some(x) = v {
                if !x.is_finite() || x < 0.0 || (x == 0.0 && what != "friction") {
                    return Err(ctx(format!("{what} must be a positive number, got {x}")));
                }
            }
        }
    }
    // Names are checked before any mesh is read: a hostile name never reaches a file name.
    check_names(path, m.objects.iter().map(|o| o.name.as_str()))?;
    Ok(m)
}

/// Load a manifest and its meshes.
pub fn load(path: &Path, limits: &Limits) -> Result<Scene> {
    let m = read_with(path, limits)?;
    let root = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let root = if root.as_os_str().is_empty() {
        Path::new(".").to_path_buf()
    } else {
        root
    };
    let meters_per_unit = m.units.meters().map_err(|e| Error::input(path, e))?;
    let mut objects = Vec::with_capacity(m.objects.len());
    for o in &m.objects {
        let pose = match &o.pose {
            Some(p) => p
                .to_similarity()
                .map_err(|e| Error::input(path, format!("object {:?}: {e}", o.name)))?,
            None => Similarity::identity(),
        };
        let mesh_path = resolve_inside(&root, path, &o.mesh)?;
        let visual = crate::io::load_visual(&mesh_path, limits)?;
        // The mesh file's stem as an alias (a composed sample's `object_b.glb` stays
        // `object_b` on the command line when the object is called `lemon`).
        let stem = Path::new(&o.mesh)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .filter(|s| super::is_valid_name(s) && s != &o.name);
        objects.push(SceneObject {
            name: o.name.clone(),
            aliases: stem.into_iter().collect(),
            label: o.label.clone(),
            mesh_path,
            visual,
            pose,
            physical: Physical {
                density: o.density,
                mass: o.mass,
                friction: o.friction,
                fixed: o.fixed,
            },
        });
    }
    super::drop_ambiguous_aliases(&mut objects);
    let name = m.name.clone().unwrap_or_else(|| {
        root.canonicalize()
            .ok()
            .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_else(|| "scene".into())
    });
    Ok(Scene {
        name,
        source: path.to_path_buf(),
        meters_per_unit,
        up_axis: m.up_axis,
        objects,
        warnings: Vec::new(),
    })
}
