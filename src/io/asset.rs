//! Robot-description assets (URDF, MJCF) as authored: bodies with their geoms, authored
//! inertials and the file and line that define each, before anything is recomputed.
//!
//! Entry points: [`load`] (by extension: `.urdf`, `.xml`/`.mjcf`), [`Asset::to_assembly`] (the
//! same [`Assembly`] the export pipeline produces, so the physics and metrics run unchanged),
//! [`ReadOptions`] (`--package NAME=DIR`). Readers: [`crate::io::urdf`], [`crate::io::mjcf`].

use crate::body::{Assembly, Body, DEFAULT_FRICTION};
use crate::decompose::Hull;
use crate::error::{Error, Result};
use crate::inertia::{Inertial, VolumeSource, DEFAULT_DENSITY};
use crate::io::Limits;
use crate::mesh::{Material, Mesh, VisualMesh, VisualPart, P3, V3};
use crate::pose::Similarity;
use nalgebra::{Isometry3, Matrix3};
use std::path::{Path, PathBuf};

/// Where something is defined.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
pub struct Source {
    pub file: PathBuf,
    pub line: usize,
}

impl Source {
    pub fn of(e: &crate::io::xml::Element) -> Source {
        Source {
            file: (*e.file).clone(),
            line: e.line,
        }
    }
}

/// A geometric primitive or mesh, in its geom frame, metres.
#[derive(Clone, Debug)]
pub enum Shape {
    /// Half extents.
    Box(V3),
    Sphere(f64),
    /// Radius, half length of the cylindrical part (along z).
    Capsule(f64, f64),
    /// Radius, half length (along z).
    Cylinder(f64, f64),
    Ellipsoid(V3),
    /// A mesh file, scaled, split into the pieces an engine makes separate convex shapes of
    /// (OBJ objects/groups in a URDF for PyBullet; one piece for MuJoCo).
    Mesh {
        file: PathBuf,
        pieces: Vec<Mesh>,
    },
    /// An infinite plane (the floor), normal +z in its frame.
    Plane,
}

impl Shape {
    /// A closed triangle mesh of the shape (tessellated primitives), or the mesh pieces.
    pub fn meshes(&self) -> Vec<Mesh> {
        use crate::shapes;
        let scaled = |m: Mesh, s: V3| {
            Mesh::new(
                m.vertices
                    .iter()
                    .map(|v| P3::new(v.x * s.x, v.y * s.y, v.z * s.z))
                    .collect(),
                m.triangles,
            )
        };
        match self {
            Shape::Box(h) => vec![shapes::cuboid(h * 2.0)],
            Shape::Sphere(r) => vec![shapes::uv_sphere(*r, 16, 32)],
            Shape::Ellipsoid(r) => vec![scaled(shapes::uv_sphere(1.0, 16, 32), *r)],
            Shape::Cylinder(r, h) => {
                let m = shapes::cylinder(*r, 2.0 * h, 32);
                let (lo, hi) = z_range(&m);
                vec![shift_z(m, -(lo + hi) / 2.0)]
            }
            Shape::Capsule(r, h) => {
                let s = shapes::uv_sphere(*r, 16, 32);
                let v: Vec<P3> = s
                    .vertices
                    .iter()
                    .map(|p| P3::new(p.x, p.y, p.z + if p.z >= 0.0 { *h } else { -*h }))
                    .collect();
                vec![Mesh::new(v, s.triangles)]
            }
            Shape::Mesh { pieces, .. } => pieces.clone(),
            Shape::Plane => Vec::new(),
        }
    }
    /// Exact volume of a primitive (`None` for meshes and planes).
    pub fn volume(&self) -> Option<f64> {
        use std::f64::consts::PI;
        Some(match self {
            Shape::Box(h) => 8.0 * h.x * h.y * h.z,
            Shape::Sphere(r) => 4.0 / 3.0 * PI * r.powi(3),
            Shape::Ellipsoid(r) => 4.0 / 3.0 * PI * r.x * r.y * r.z,
            Shape::Cylinder(r, h) => PI * r * r * 2.0 * h,
            Shape::Capsule(r, h) => 4.0 / 3.0 * PI * r.powi(3) + PI * r * r * 2.0 * h,
            _ => return None,
        })
    }
    pub fn kind(&self) -> &'static str {
        match self {
            Shape::Box(_) => "box",
            Shape::Sphere(_) => "sphere",
            Shape::Capsule(..) => "capsule",
            Shape::Cylinder(..) => "cylinder",
            Shape::Ellipsoid(_) => "ellipsoid",
            Shape::Mesh { .. } => "mesh",
            Shape::Plane => "plane",
        }
    }
}

fn z_range(m: &Mesh) -> (f64, f64) {
    m.vertices
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v.z), b.max(v.z))
        })
}

fn shift_z(m: Mesh, dz: f64) -> Mesh {
    Mesh::new(
        m.vertices
            .iter()
            .map(|v| P3::new(v.x, v.y, v.z + dz))
            .collect(),
        m.triangles,
    )
}

/// One geom (MJCF) or one `<visual>`/`<collision>` (URDF).
#[derive(Clone, Debug)]
pub struct Geom {
    pub name: String,
    pub shape: Shape,
    /// Geom frame → body frame.
    pub pose: Isometry3<f64>,
    /// Collides (contype/conaffinity not both 0; a URDF `<collision>`).
    pub collision: bool,
    /// Drawn (a URDF `<visual>`; an MJCF geom in a visual group or that does not collide).
    pub visual: bool,
    /// MJCF: the density the geom's mass comes from (kg/m³), or its own mass.
    pub density: Option<f64>,
    pub mass: Option<f64>,
    pub friction: Option<f64>,
    pub src: Source,
}

impl Geom {
    /// The geom's meshes in the body frame.
    pub fn body_meshes(&self) -> Vec<Mesh> {
        let m = self.pose.to_homogeneous();
        self.shape
            .meshes()
            .into_iter()
            .map(|x| x.transformed(&m))
            .collect()
    }
}

/// Mass properties as written in the file.
#[derive(Clone, Debug)]
pub struct AuthoredInertial {
    pub mass: f64,
    /// Centre of mass in the body frame.
    pub com: P3,
    /// Inertia about the centre of mass, body axes (kg·m²).
    pub inertia: Matrix3<f64>,
    pub src: Source,
}

/// A body (MJCF) or link (URDF, after merging fixed joints).
#[derive(Clone, Debug)]
pub struct AssetBody {
    pub name: String,
    pub src: Source,
    /// World pose of the body frame.
    pub pose: Isometry3<f64>,
    /// Welded to the world (MJCF: no joint under the world; URDF: mass 0 root).
    pub fixed: bool,
    pub geoms: Vec<Geom>,
    pub inertial: Option<AuthoredInertial>,
    /// Names of the links or bodies merged into this one (fixed joints, welded children).
    pub merged: Vec<String>,
}

/// A problem found while reading (missing mesh, moving joint...), turned into a finding.
#[derive(Clone, Debug)]
pub struct ReadIssue {
    pub check: &'static str,
    pub subject: String,
    pub src: Source,
    pub message: String,
}

/// A URDF or MJCF file as read.
#[derive(Clone, Debug)]
pub struct Asset {
    pub name: String,
    pub file: PathBuf,
    pub format: &'static str,
    pub bodies: Vec<AssetBody>,
    /// Height of a floor plane the file defines (MJCF `<geom type="plane">` on the world).
    pub floor: Option<(f64, Source)>,
    pub issues: Vec<ReadIssue>,
}

/// Reader options.
#[derive(Clone, Debug, Default)]
pub struct ReadOptions {
    pub limits: Limits,
    /// `package://NAME/...` → `DIR/...` (URDF).
    pub packages: Vec<(String, PathBuf)>,
    /// MJCF: keep a lone welded body welded. By default an object model file (no joint at all,
    /// no floor, nothing on the world body but one body tree, as Google Scanned Objects and
    /// robosuite object files are written) is checked as the free object it is meant to be.
    pub keep_welded: bool,
}

/// Read a URDF or MJCF file (a xacro file is an error that says to run xacro first).
pub fn load(path: &Path, opts: &ReadOptions) -> Result<Asset> {
    let root = crate::io::xml::parse_file(path, &opts.limits)?;
    if let Some(line) = xacro_line(&root) {
        return Err(Error::input(
            path,
            format!(
                "line {line}: xacro macros are not expanded here: run `xacro {} > robot.urdf` (ROS xacro) first and validate that URDF",
                path.display()
            ),
        ));
    }
    match root.name.as_str() {
        "robot" => crate::io::urdf::read(path, &root, opts),
        "mujoco" => crate::io::mjcf::read(path, &root, opts),
        other => Err(Error::input(
            path,
            format!(
                "line {}: root element <{other}> is neither <robot> (URDF) nor <mujoco> (MJCF)",
                root.line
            ),
        )),
    }
}

/// The line of the first xacro element or `xmlns:xacro` declaration, if any.
fn xacro_line(e: &crate::io::xml::Element) -> Option<usize> {
    if e.name.starts_with("xacro:") || e.attrs.iter().any(|(k, _)| k == "xmlns:xacro") {
        return Some(e.line);
    }
    e.children.iter().find_map(xacro_line)
}

/// Numbers of an attribute: `n` floats, or an error naming the element's line.
pub fn floats(e: &crate::io::xml::Element, key: &str) -> Result<Option<Vec<f64>>> {
    let Some(v) = e.attr(key) else {
        return Ok(None);
    };
    let mut out = Vec::new();
    for t in v.split_whitespace() {
        let x: f64 = t
            .parse()
            .map_err(|_| e.error(format!("{key}={v:?}: {t:?} is not a number")))?;
        if !x.is_finite() {
            return Err(e.error(format!("{key}={v:?}: not finite")));
        }
        out.push(x);
    }
    Ok(Some(out))
}

/// Exactly `n` numbers, or an error.
pub fn floats_n(e: &crate::io::xml::Element, key: &str, n: usize) -> Result<Option<Vec<f64>>> {
    match floats(e, key)? {
        Some(v) if v.len() != n => {
            Err(e.error(format!("{key} has {} numbers, expected {n}", v.len())))
        }
        x => Ok(x),
    }
}

/// Mesh pieces of a mesh file (OBJ, STL, glTF, MuJoCo `.msh`), scaled; `split` keeps each OBJ
/// object/group as its own piece.
pub fn mesh_pieces(file: &Path, scale: V3, split: bool, limits: &Limits) -> Result<Vec<Mesh>> {
    let ext = file
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    let parts: Vec<Mesh> = if ext == "msh" {
        vec![crate::io::msh::load(file, limits)?]
    } else {
        let bytes = crate::io::read_file(file, limits)?;
        // Materials and textures do not matter to physics: read geometry only (an OBJ's
        // missing MTL does not stop PyBullet or MuJoCo either).
        let v = if ext == "obj" {
            crate::io::obj::load_geometry_bytes(file, &bytes, limits)?
        } else {
            crate::io::load_visual_bytes(
                file,
                &bytes,
                file.parent().unwrap_or(Path::new(".")),
                limits,
            )?
        };
        if split {
            v.parts
                .iter()
                .map(|p| Mesh::new(p.positions.clone(), p.triangles.clone()).welded(0.0))
                .collect()
        } else {
            vec![v.geometry()]
        }
    };
    Ok(parts
        .into_iter()
        .filter(|m| !m.triangles.is_empty())
        .map(|m| {
            let flip = scale.x * scale.y * scale.z < 0.0;
            let mut m = Mesh::new(
                m.vertices
                    .iter()
                    .map(|v| P3::new(v.x * scale.x, v.y * scale.y, v.z * scale.z))
                    .collect(),
                m.triangles,
            );
            if flip {
                for t in &mut m.triangles {
                    t.swap(1, 2);
                }
            }
            m
        })
        .collect())
}

/// Mass properties of a body computed from its collision geoms (MuJoCo's rule: each geom's
/// volume times its density, or its own mass); `None` without collision volume.
pub fn geometric_inertial(b: &AssetBody) -> Option<Inertial> {
    let mut parts: Vec<Inertial> = Vec::new();
    for g in b.geoms.iter().filter(|g| g.collision) {
        for m in g.body_meshes() {
            let density = g.density.unwrap_or(DEFAULT_DENSITY);
            let mut i = if m.is_closed() && m.signed_volume() > 0.0 {
                crate::inertia::of_closed_mesh(&m, density)
            } else {
                // Engines integrate the hull of an open mesh.
                let h = Hull::from_points(&m.vertices)?;
                crate::inertia::of_closed_mesh(&h.mesh(), density)
            };
            if let Some(mass) = g.mass {
                i = i.with_mass(mass);
            }
            parts.push(i);
        }
    }
    combine(&parts)
}

/// Sum of mass properties (parallel axis theorem), all in one frame.
pub fn combine(parts: &[Inertial]) -> Option<Inertial> {
    let mass: f64 = parts.iter().map(|p| p.mass).sum();
    if !(mass > 0.0) {
        return None;
    }
    let com = P3::from(
        parts
            .iter()
            .map(|p| p.com.coords * p.mass)
            .fold(V3::zeros(), |a, b| a + b)
            / mass,
    );
    let mut inertia = Matrix3::zeros();
    for p in parts {
        let d = p.com - com;
        inertia +=
            p.inertia + p.mass * (Matrix3::identity() * d.norm_squared() - d * d.transpose());
    }
    Some(Inertial {
        mass,
        com,
        inertia,
        volume: parts.iter().map(|p| p.volume).sum(),
        source: VolumeSource::ClosedMesh,
    })
}

impl AuthoredInertial {
    pub fn inertial(&self) -> Inertial {
        Inertial {
            mass: self.mass,
            com: self.com,
            inertia: self.inertia,
            volume: 0.0,
            source: VolumeSource::ClosedMesh,
        }
    }
}

impl AssetBody {
    /// Convex hulls of the collision geometry, body frame (what the engines collide).
    pub fn hulls(&self) -> Vec<Hull> {
        self.geoms
            .iter()
            .filter(|g| g.collision)
            .flat_map(|g| g.body_meshes())
            .filter_map(|m| Hull::from_points(&m.vertices))
            .collect()
    }
    /// The visual meshes, body frame (the collision meshes when nothing is drawn).
    pub fn visual_meshes(&self) -> Vec<Mesh> {
        let vis: Vec<Mesh> = self
            .geoms
            .iter()
            .filter(|g| g.visual)
            .flat_map(|g| g.body_meshes())
            .collect();
        if vis.is_empty() {
            self.collision_meshes()
        } else {
            vis
        }
    }
    pub fn collision_meshes(&self) -> Vec<Mesh> {
        self.geoms
            .iter()
            .filter(|g| g.collision)
            .flat_map(|g| g.body_meshes())
            .collect()
    }
    /// The mass properties the engines simulate: as authored when valid, else from geometry.
    pub fn effective_inertial(&self) -> Option<Inertial> {
        match &self.inertial {
            Some(a) if a.inertial().check().is_ok() => Some(a.inertial()),
            _ => geometric_inertial(self),
        }
    }
}

impl Asset {
    /// The bodies as an [`Assembly`] (body frames as authored, hulls of the collision geoms,
    /// the effective inertials). Bodies without collision geometry or mass are left out, and
    /// said so in the warnings.
    pub fn to_assembly(&self) -> Assembly {
        let mut bodies = Vec::new();
        let mut warnings = Vec::new();
        for b in &self.bodies {
            let hulls = b.hulls();
            let inertial = b.effective_inertial();
            let (Some(inertial), false) = (inertial, hulls.is_empty()) else {
                if !b.fixed || !hulls.is_empty() {
                    warnings.push(format!(
                        "body {}: no collision geometry or no usable mass; left out of the simulation",
                        b.name
                    ));
                }
                if hulls.is_empty() {
                    continue;
                }
                // A fixed body needs no mass.
                bodies.push(self.body(b, hulls, None));
                continue;
            };
            bodies.push(self.body(b, hulls, Some(inertial)));
        }
        Assembly {
            name: self.name.clone(),
            bodies,
            decomposer: format!("as authored ({})", self.format),
            scene_to_world: Similarity::identity(),
            warnings,
        }
    }

    fn body(&self, b: &AssetBody, hulls: Vec<Hull>, inertial: Option<Inertial>) -> Body {
        let vis = b.visual_meshes();
        let mut geometry = Mesh::default();
        for m in &b.collision_meshes() {
            geometry.append(m);
        }
        let visual = VisualMesh {
            parts: vis
                .iter()
                .map(|m| VisualPart {
                    positions: m.vertices.clone(),
                    uvs: None,
                    triangles: m.triangles.clone(),
                    material: Material::default(),
                })
                .collect(),
        };
        let inertial = inertial.unwrap_or(Inertial {
            mass: 1.0,
            com: P3::origin(),
            inertia: Matrix3::identity() * 1e-3,
            volume: 0.0,
            source: VolumeSource::ClosedMesh,
        });
        let friction = b
            .geoms
            .iter()
            .filter(|g| g.collision)
            .find_map(|g| g.friction)
            .unwrap_or(DEFAULT_FRICTION);
        Body {
            name: b.name.clone(),
            label: None,
            pose: b.pose,
            composed_pose: b.pose,
            mesh_to_body: Similarity::identity(),
            closed: geometry.is_closed(),
            visual,
            geometry,
            hulls,
            inertial,
            friction,
            fixed: b.fixed,
            warnings: Vec::new(),
            fidelity: None,
        }
    }
}
