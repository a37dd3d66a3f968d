//! File formats: mesh readers (glTF/GLB, OBJ+MTL, STL, MuJoCo `.msh`), texture reading,
//! robot-description readers (URDF, MJCF → [`asset::Asset`]) and the writers the export and the
//! fixtures use. Readers check what they read and name the file (and line) in every error.

pub mod asset;
pub mod glb_write;
pub mod gltf;
pub mod mjcf;
pub mod mjcf_frames;
pub mod msh;
pub mod obj;
pub mod stl;
pub mod texture;
pub mod urdf;
pub mod xml;

pub use glb_write::{to_glb_bytes, to_glb_bytes_with, write_glb, write_glb_with, GlbOptions};

use crate::error::{Error, Result};
use crate::mesh::VisualMesh;
use std::path::{Component, Path, PathBuf};

/// Size limits applied while reading, so a hostile file cannot make us allocate gigabytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Largest file read, bytes.
    pub max_file_bytes: u64,
    /// Most triangles in one mesh file.
    pub max_triangles: usize,
    /// Most pixels in one texture.
    pub max_texture_pixels: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_file_bytes: 2 << 30,
            max_triangles: 20_000_000,
            max_texture_pixels: 16384 * 16384,
        }
    }
}

/// Read a whole file, refusing files over the limit.
pub fn read_file(path: &Path, limits: &Limits) -> Result<Vec<u8>> {
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if !meta.is_file() {
        return Err(Error::input(path, "not a regular file"));
    }
    if meta.len() > limits.max_file_bytes {
        return Err(Error::input(
            path,
            format!(
                "file is {} bytes, over the limit of {} bytes (--max-file-bytes)",
                meta.len(),
                limits.max_file_bytes
            ),
        ));
    }
    std::fs::read(path).map_err(|e| Error::io(path, e))
}

/// Load a visual mesh by extension: `.glb`, `.gltf`, `.obj`, `.stl`. References inside the
/// file (buffers, images, MTL, textures) must stay inside the file's own folder.
pub fn load_visual(path: &Path, limits: &Limits) -> Result<VisualMesh> {
    format_of(path)?;
    let bytes = read_file(path, limits)?;
    load_visual_bytes(
        path,
        &bytes,
        path.parent().unwrap_or(Path::new(".")),
        limits,
    )
}

/// Load a visual mesh from bytes already read (the byte-level entry point, also what the fuzz
/// targets call): `path` names the file in errors and gives its format by extension, relative
/// references start from its folder and may not leave `root`. Runs [`check_visual`].
pub fn load_visual_bytes(
    path: &Path,
    bytes: &[u8],
    root: &Path,
    limits: &Limits,
) -> Result<VisualMesh> {
    if bytes.len() as u64 > limits.max_file_bytes {
        return Err(Error::input(
            path,
            format!(
                "file is {} bytes, over the limit of {} bytes (--max-file-bytes)",
                bytes.len(),
                limits.max_file_bytes
            ),
        ));
    }
    let mesh = match format_of(path)? {
        "gltf" => gltf::load_bytes(path, bytes, root, limits)?,
        "obj" => obj::load_bytes(path, bytes, root, limits)?,
        _ => stl::load_bytes(path, bytes, limits)?,
    };
    check_visual(path, &mesh, limits)?;
    Ok(mesh)
}

/// The reader for a file name: "gltf" (`.glb`, `.gltf`), "obj" or "stl".
fn format_of(path: &Path) -> Result<&'static str> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "glb" | "gltf" => Ok("gltf"),
        "obj" => Ok("obj"),
        "stl" => Ok("stl"),
        _ => Err(Error::input(
            path,
            "unsupported mesh format (expected .glb, .gltf, .obj or .stl)",
        )),
    }
}

/// The checks every loaded mesh passes: finite, sane coordinates, valid indices, not empty.
pub fn check_visual(path: &Path, mesh: &VisualMesh, limits: &Limits) -> Result<()> {
    let tris = mesh.triangle_count();
    if tris == 0 {
        return Err(Error::input(path, "mesh has no triangles"));
    }
    if tris > limits.max_triangles {
        return Err(Error::input(
            path,
            format!(
                "mesh has {tris} triangles, over the limit of {} (--max-triangles)",
                limits.max_triangles
            ),
        ));
    }
    for part in &mesh.parts {
        if let Some(p) = part
            .positions
            .iter()
            .find(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(Error::input(
                path,
                format!("vertex with a NaN or infinite coordinate: {p:?}"),
            ));
        }
        if let Some(p) = part
            .positions
            .iter()
            .find(|p| p.iter().any(|c| c.abs() > 1e12))
        {
            return Err(Error::input(
                path,
                format!(
                    "vertex coordinate out of range (|x| > 1e12): [{}, {}, {}]",
                    p.x, p.y, p.z
                ),
            ));
        }
        let n = part.positions.len() as u32;
        if let Some(t) = part.triangles.iter().find(|t| t.iter().any(|&i| i >= n)) {
            return Err(Error::input(
                path,
                format!("triangle index {t:?} past the vertex count {n}"),
            ));
        }
        if let Some(uvs) = &part.uvs {
            if uvs.len() != part.positions.len() {
                return Err(Error::input(
                    path,
                    "texture coordinates do not match vertex count",
                ));
            }
        }
    }
    if mesh.geometry().area() <= 0.0 {
        return Err(Error::input(
            path,
            "mesh has only degenerate (zero-area) triangles",
        ));
    }
    Ok(())
}

/// Resolve `rel` (a path found inside `from_file`) against the folder of `from_file`, refusing
/// anything that leaves `root`: absolute paths, `..` that climbs out, URIs with a scheme, and
/// symbolic links that point outside.
pub fn resolve_inside(root: &Path, from_file: &Path, rel: &str) -> Result<PathBuf> {
    let bad = |why: &str| Error::input(from_file, format!("reference {rel:?} {why}"));
    if rel.is_empty() {
        return Err(bad("is empty"));
    }
    if rel.contains("://") || rel.starts_with("file:") {
        return Err(bad(
            "is a URI; only relative paths inside the scene folder are allowed",
        ));
    }
    let relp = Path::new(rel);
    if relp.is_absolute() || rel.starts_with('/') || rel.starts_with('\\') || rel.contains(':') {
        return Err(bad(
            "is an absolute path; only relative paths inside the scene folder are allowed",
        ));
    }
    let base = from_file.parent().unwrap_or(Path::new("."));
    let mut joined = base.to_path_buf();
    for c in relp.components() {
        match c {
            Component::Normal(s) => joined.push(s),
            Component::CurDir => {}
            Component::ParentDir => {
                if !joined.pop() {
                    return Err(bad("climbs out of the scene folder"));
                }
            }
            _ => return Err(bad("is not a plain relative path")),
        }
    }
    let root_c = root.canonicalize().map_err(|e| Error::io(root, e))?;
    // Lexical check first (clear message), then the real one through symlinks.
    let lexical = normalize(&joined);
    if !lexical.starts_with(normalize(root)) && !lexical.starts_with(&root_c) {
        return Err(bad("points outside the scene folder"));
    }
    match joined.canonicalize() {
        Ok(real) if !real.starts_with(&root_c) => {
            Err(bad("resolves (through a link) outside the scene folder"))
        }
        Ok(real) => Ok(real),
        Err(e) => Err(Error::input(
            from_file,
            format!("reference {rel:?}: cannot open {}: {e}", joined.display()),
        )),
    }
}

fn normalize(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out
}
