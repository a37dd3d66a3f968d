//! Content-addressed cache of decompositions: a SHA-256 of the engine name, its version, the
//! options that change the result and the geometry of every object of the scene keys one small
//! JSON file in the cache folder. Hull vertices and triangles are stored as written (JSON
//! floats round-trip exactly), so a cache hit gives bit-identical hulls. Files are written
//! atomically; a corrupt or foreign file is ignored (recomputed and overwritten).

use super::{DecomposeOptions, Hull};
use crate::error::Result;
use crate::mesh::{Mesh, P3};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// One hull as stored. Coordinates are the IEEE-754 bit patterns of the f64 values (JSON
/// integers are exact; decimal floats would need serde_json's `float_roundtrip`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CachedHull {
    pub vertices: Vec<[u64; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

impl CachedHull {
    pub fn from_hull(h: &Hull) -> Self {
        CachedHull {
            vertices: h
                .vertices
                .iter()
                .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                .collect(),
            triangles: h.triangles.clone(),
        }
    }
    /// The hull back (planes and volume recomputed the same way as when it was built).
    pub fn to_hull(&self) -> Option<Hull> {
        let v: Vec<P3> = self
            .vertices
            .iter()
            .map(|p| {
                P3::new(
                    f64::from_bits(p[0]),
                    f64::from_bits(p[1]),
                    f64::from_bits(p[2]),
                )
            })
            .collect();
        if self
            .triangles
            .iter()
            .any(|t| t.iter().any(|&i| i as usize >= v.len()))
        {
            return None;
        }
        Hull::from_mesh(Mesh::new(v, self.triangles.clone()))
    }
}

/// A cached scene decomposition.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CachedScene {
    pub key: String,
    pub engine: String,
    pub version: u32,
    /// Hulls of every object, in order.
    pub objects: Vec<Vec<CachedHull>>,
    /// Engine-specific report.
    pub report: serde_json::Value,
}

/// The cache key of a scene: hex SHA-256 over engine, version, the result-relevant options
/// (not `cache_dir`) and every object's vertices and triangles (little-endian bytes).
pub fn key(engine: &str, version: u32, opts: &DecomposeOptions, objects: &[&Mesh]) -> String {
    let mut h = Sha256::new();
    h.update(b"interact3d-decompose\0");
    h.update(engine.as_bytes());
    h.update([0u8]);
    h.update(version.to_le_bytes());
    h.update((opts.max_hulls as u64).to_le_bytes());
    h.update((opts.max_vertices as u64).to_le_bytes());
    h.update(opts.min_thickness.to_le_bytes());
    h.update(opts.resolution.to_le_bytes());
    h.update(opts.concavity.to_le_bytes());
    h.update(opts.tolerance.to_le_bytes());
    h.update(opts.clearance.to_le_bytes());
    // Only with a polygon budget (the engine then builds for PhysX), so keys without one are
    // what they were.
    if opts.max_polygons != usize::MAX {
        h.update(b"max_polygons");
        h.update((opts.max_polygons as u64).to_le_bytes());
    }
    // Only without the race (it may then keep another strategy), so keys with it are what
    // they were.
    if !opts.race {
        h.update(b"no_race");
    }
    h.update((objects.len() as u64).to_le_bytes());
    for m in objects {
        h.update((m.vertices.len() as u64).to_le_bytes());
        for p in &m.vertices {
            for c in p.iter() {
                h.update(c.to_le_bytes());
            }
        }
        h.update((m.triangles.len() as u64).to_le_bytes());
        for t in &m.triangles {
            for i in t {
                h.update(i.to_le_bytes());
            }
        }
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// Path of the cache file of `key`.
pub fn path(dir: &Path, key: &str) -> PathBuf {
    dir.join(format!("{key}.json"))
}

/// The cached decomposition of `key`, if present, readable and made by `engine` `version`.
pub fn load(dir: &Path, key: &str, engine: &str, version: u32) -> Option<CachedScene> {
    let bytes = std::fs::read(path(dir, key)).ok()?;
    let c: CachedScene = serde_json::from_slice(&bytes).ok()?;
    (c.key == key && c.engine == engine && c.version == version).then_some(c)
}

/// Store a decomposition (folder created when missing; atomic write).
pub fn store(dir: &Path, scene: &CachedScene) -> Result<()> {
    crate::fsutil::create_dir(dir)?;
    let bytes = serde_json::to_vec(scene)
        .map_err(|e| crate::error::Error::Internal(format!("cache serialisation: {e}")))?;
    crate::fsutil::write_atomically(&path(dir, &scene.key), &bytes)
}

/// All hulls of a cached scene; `None` when any hull is invalid.
pub fn hulls(scene: &CachedScene) -> Option<Vec<Vec<Hull>>> {
    scene
        .objects
        .iter()
        .map(|o| o.iter().map(|h| h.to_hull()).collect::<Option<Vec<_>>>())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;

    #[test]
    fn key_depends_on_geometry_and_options_not_on_cache_dir() {
        let a = shapes::cuboid(crate::mesh::V3::new(0.1, 0.1, 0.1));
        let mut b = a.clone();
        b.vertices[0].x += 1e-9;
        let o = DecomposeOptions::default();
        let k = key("e", 1, &o, &[&a]);
        assert_eq!(k.len(), 64);
        assert_eq!(k, key("e", 1, &o, &[&a]));
        assert_ne!(k, key("e", 1, &o, &[&b]));
        assert_ne!(k, key("e", 2, &o, &[&a]));
        let o2 = DecomposeOptions {
            max_hulls: 8,
            ..o.clone()
        };
        assert_ne!(k, key("e", 1, &o2, &[&a]));
        let o3 = DecomposeOptions {
            cache_dir: Some("/tmp/x".into()),
            ..o.clone()
        };
        assert_eq!(k, key("e", 1, &o3, &[&a]));
    }

    #[test]
    fn stored_hulls_round_trip_bit_identically() {
        let s = shapes::uv_sphere(0.037, 7, 11);
        let h = Hull::from_points(&s.vertices).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let scene = CachedScene {
            key: "k".into(),
            engine: "e".into(),
            version: 3,
            objects: vec![vec![CachedHull::from_hull(&h)]],
            report: serde_json::Value::Null,
        };
        store(dir.path(), &scene).unwrap();
        let back = load(dir.path(), "k", "e", 3).unwrap();
        assert!(load(dir.path(), "k", "e", 4).is_none());
        assert!(
            hulls(&back).unwrap() == vec![vec![h]],
            "hulls differ after the round trip"
        );
    }
}
