//! Scenes as they come in: an Interact3D sample folder or our own `scene.json` manifest, each
//! loaded into the same [`Scene`]: named objects, each a visual mesh in its own frame plus the
//! similarity that places it in the scene.
//!
//! Entry points: [`load`], [`single_mesh`], [`Scene::find`] (by name or alias), [`sanitize_name`],
//! [`is_valid_name`]; the formats in [`sample`] and [`manifest`].

pub mod manifest;
pub mod sample;

use crate::error::{Error, Result};
use crate::io::Limits;
use crate::mesh::VisualMesh;
use crate::pose::Similarity;
use std::path::{Path, PathBuf};

/// Which axis points up in a scene's frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum UpAxis {
    Y,
    Z,
}

/// Physical properties given for an object (all optional but `fixed`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Physical {
    /// kg/m³; the default density applies when neither this nor `mass` is given.
    pub density: Option<f64>,
    /// kg; overrides density.
    pub mass: Option<f64>,
    pub friction: Option<f64>,
    /// A static object (no free joint, not moved by the simulation).
    pub fixed: bool,
}

/// One object of a scene.
#[derive(Clone, Debug)]
pub struct SceneObject {
    /// Identifier, unique in the scene: `[A-Za-z_][A-Za-z0-9_-]*`. Output files are named by it.
    pub name: String,
    /// Other names the command line may use for it (`--size`, `--density`, `--mass`): a sample's
    /// `object_b` when it is named from its label, a manifest object's mesh file stem. Never
    /// another object's name or alias.
    pub aliases: Vec<String>,
    /// Human label (e.g. "bowl") when the input has one.
    pub label: Option<String>,
    /// The mesh file it was read from.
    pub mesh_path: PathBuf,
    /// Geometry and materials in the mesh's own frame.
    pub visual: VisualMesh,
    /// Mesh frame → scene frame (scene units, scene up axis).
    pub pose: Similarity,
    pub physical: Physical,
}

/// A scene as read from disk, before any preparation.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Name (the folder or manifest name).
    pub name: String,
    /// The folder or manifest it came from.
    pub source: PathBuf,
    /// Metres per scene unit.
    pub meters_per_unit: f64,
    pub up_axis: UpAxis,
    pub objects: Vec<SceneObject>,
    /// Notes from loading that do not stop it.
    pub warnings: Vec<String>,
}

impl Scene {
    /// The object `name` designates: its name, else one of its aliases.
    pub fn find(&self, name: &str) -> Option<&SceneObject> {
        self.objects.iter().find(|o| o.name == name).or_else(|| {
            self.objects
                .iter()
                .find(|o| o.aliases.iter().any(|a| a == name))
        })
    }

    /// The objects' names, each with its aliases in brackets (`lemon (object_b)`), for messages.
    pub fn names_listed(&self) -> String {
        self.objects
            .iter()
            .map(|o| {
                if o.aliases.is_empty() {
                    o.name.clone()
                } else {
                    format!("{} ({})", o.name, o.aliases.join(", "))
                }
            })
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Whether the format fixes the up axis: glTF is Y-up by its specification, so a sample
    /// folder or a lone `.glb`/`.gltf` file takes no `--up`. The reason, when it does.
    pub fn up_axis_fixed(&self) -> Option<&'static str> {
        let src = &self.source;
        let ext = src
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let sample = if src.is_dir() {
            !src.join("scene.json").is_file()
        } else {
            src.file_name().is_some_and(|n| n == "metadata.json")
        };
        if sample {
            Some("an Interact3D sample folder holds glTF, which is Y-up by its specification")
        } else if matches!(ext.as_deref(), Some("glb" | "gltf")) {
            Some("glTF is Y-up by its specification")
        } else {
            None
        }
    }
}

/// Drop every alias that is another object's name or that several objects share, so an alias
/// designates one object or none.
pub(crate) fn drop_ambiguous_aliases(objects: &mut [SceneObject]) {
    let names: Vec<String> = objects.iter().map(|o| o.name.clone()).collect();
    let all: Vec<String> = objects.iter().flat_map(|o| o.aliases.clone()).collect();
    for o in objects.iter_mut() {
        o.aliases.retain(|a| {
            a != &o.name && !names.contains(a) && all.iter().filter(|x| *x == a).count() == 1
        });
    }
}

/// Load a scene from a sample folder (with `metadata.json`), a folder with `scene.json`, or a
/// manifest file.
pub fn load(path: &Path, limits: &Limits) -> Result<Scene> {
    if path.is_dir() {
        if path.join("scene.json").is_file() {
            manifest::load(&path.join("scene.json"), limits)
        } else if path.join("metadata.json").is_file() {
            sample::load(path, limits)
        } else {
            Err(Error::input(
                path,
                "not a scene: the folder has neither scene.json nor metadata.json",
            ))
        }
    } else if path.is_file() {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        match (path.file_name().and_then(|n| n.to_str()), ext.as_deref()) {
            (Some("metadata.json"), _) => {
                sample::load(path.parent().unwrap_or(Path::new(".")), limits)
            }
            (_, Some("glb" | "gltf" | "obj" | "stl")) => single_mesh(path, limits),
            _ => manifest::load(path, limits),
        }
    } else {
        Err(Error::input(path, "no such file or folder"))
    }
}

/// A lone mesh file as a one-object scene: identity pose, metres, Y-up for glTF (its
/// convention), Z-up otherwise (OBJ/STL from robotics and scanning usually are).
pub fn single_mesh(path: &Path, limits: &Limits) -> Result<Scene> {
    let visual = crate::io::load_visual(path, limits)?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    // Scanned-object datasets call every file model.obj or textured.obj: use the folder's name.
    let generic = ["model", "textured", "mesh", "scene", "visual"]
        .contains(&stem.to_ascii_lowercase().as_str());
    let folder = path.canonicalize().ok().and_then(|p| {
        p.parent()
            .and_then(|d| d.file_name())
            .map(|n| n.to_string_lossy().into_owned())
    });
    let name = sanitize_name(match (&folder, generic) {
        (Some(f), true) => f,
        _ => &stem,
    });
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    Ok(Scene {
        name: name.clone(),
        source: path.to_path_buf(),
        meters_per_unit: 1.0,
        up_axis: if matches!(ext.as_deref(), Some("glb" | "gltf")) {
            UpAxis::Y
        } else {
            UpAxis::Z
        },
        objects: vec![SceneObject {
            name,
            aliases: Vec::new(),
            label: None,
            mesh_path: path.to_path_buf(),
            visual,
            pose: Similarity::identity(),
            physical: Physical::default(),
        }],
        warnings: Vec::new(),
    })
}

/// Turn any text into a valid object name (used for names taken from file names).
pub fn sanitize_name(s: &str) -> String {
    let mut out: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .take(64)
        .collect();
    if !out.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') {
        out.insert(0, '_');
        out.truncate(64);
    }
    out
}

/// Whether `name` is usable as an identifier in MJCF, URDF and file names.
pub fn is_valid_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        && name.len() <= 64
}

/// Check names: valid and unique, and at least one.
pub(crate) fn check_names<'a>(
    source: &Path,
    names: impl IntoIterator<Item = &'a str>,
) -> Result<()> {
    let mut seen = std::collections::BTreeSet::new();
    for name in names {
        if !is_valid_name(name) {
            return Err(Error::input(
                source,
                format!(
                    "object name {name:?} is not a valid identifier (letters, digits, '_' and '-', starting with a letter or '_', at most 64)"
                ),
            ));
        }
        if !seen.insert(name) {
            return Err(Error::input(
                source,
                format!("duplicate object name {name:?}"),
            ));
        }
    }
    if seen.is_empty() {
        return Err(Error::input(source, "scene has no objects"));
    }
    Ok(())
}
