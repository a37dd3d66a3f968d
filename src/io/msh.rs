//! MuJoCo's legacy binary mesh format `.msh` (still read by MuJoCo 4, used by robosuite's
//! object files). Entry point: [`load`], [`load_bytes`].
//!
//! Layout, little endian: four `i32` counts (vertices, normals, texture coordinates, faces),
//! then `f32` positions (3 each), normals (3 each), texture coordinates (2 each) and `i32` face
//! indices (3 each). The file size must match the counts exactly. A file without faces is a
//! point cloud whose convex hull MuJoCo uses; so do we.

use crate::error::{Error, Result};
use crate::io::Limits;
use crate::mesh::{Mesh, P3};
use std::path::Path;

/// Read a `.msh` file.
pub fn load(path: &Path, limits: &Limits) -> Result<Mesh> {
    let bytes = crate::io::read_file(path, limits)?;
    load_bytes(path, &bytes, limits)
}

/// Parse `.msh` bytes; `path` names the file in errors.
pub fn load_bytes(path: &Path, b: &[u8], limits: &Limits) -> Result<Mesh> {
    if b.len() < 16 {
        return Err(Error::input(
            path,
            "MuJoCo .msh: shorter than its 16-byte header",
        ));
    }
    let int = |k: usize| i32::from_le_bytes([b[4 * k], b[4 * k + 1], b[4 * k + 2], b[4 * k + 3]]);
    let (nv, nn, nt, nf) = (int(0), int(1), int(2), int(3));
    if nv < 4 || nn < 0 || nt < 0 || nf < 0 {
        return Err(Error::input(
            path,
            format!(
                "MuJoCo .msh: bad counts (vertices {nv}, normals {nn}, texcoords {nt}, faces {nf})"
            ),
        ));
    }
    let (nv, nn, nt, nf) = (nv as u64, nn as u64, nt as u64, nf as u64);
    if nf as usize > limits.max_triangles {
        return Err(Error::input(
            path,
            format!(
                "mesh has {nf} triangles, over the limit of {} (--max-triangles)",
                limits.max_triangles
            ),
        ));
    }
    let expected = 16 + 4 * (3 * nv + 3 * nn + 2 * nt + 3 * nf);
    if b.len() as u64 != expected {
        return Err(Error::input(
            path,
            format!(
                "MuJoCo .msh: {} bytes, but its counts (vertices {nv}, normals {nn}, texcoords {nt}, faces {nf}) need {expected}",
                b.len()
            ),
        ));
    }
    let f = |k: usize| f32::from_le_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]) as f64;
    let vertices: Vec<P3> = (0..nv as usize)
        .map(|i| P3::new(f(16 + 12 * i), f(20 + 12 * i), f(24 + 12 * i)))
        .collect();
    if let Some(p) = vertices.iter().find(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(Error::input(
            path,
            format!("vertex with a NaN or infinite coordinate: {p:?}"),
        ));
    }
    let face0 = 16 + 4 * (3 * nv + 3 * nn + 2 * nt) as usize;
    let mut triangles = Vec::with_capacity(nf as usize);
    for i in 0..nf as usize {
        let mut t = [0u32; 3];
        for (k, x) in t.iter_mut().enumerate() {
            let o = face0 + 12 * i + 4 * k;
            let v = i32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
            if v < 0 || v as u64 >= nv {
                return Err(Error::input(
                    path,
                    format!("MuJoCo .msh: face {i} has vertex index {v}, outside 0..{nv}"),
                ));
            }
            *x = v as u32;
        }
        triangles.push(t);
    }
    if triangles.is_empty() {
        let hull = crate::decompose::Hull::from_points(&vertices).ok_or_else(|| {
            Error::input(path, "MuJoCo .msh: points without faces span no volume")
        })?;
        return Ok(hull.mesh());
    }
    Ok(Mesh::new(vertices, triangles))
}

/// Write a `.msh` (positions and faces only), for tests and fixtures.
pub fn to_bytes(mesh: &Mesh) -> Vec<u8> {
    let mut out = Vec::new();
    for n in [mesh.vertices.len(), 0, 0, mesh.triangles.len()] {
        out.extend_from_slice(&(n as i32).to_le_bytes());
    }
    for v in &mesh.vertices {
        for c in v.iter() {
            out.extend_from_slice(&(*c as f32).to_le_bytes());
        }
    }
    for t in &mesh.triangles {
        for i in t {
            out.extend_from_slice(&(*i as i32).to_le_bytes());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_bad_sizes() {
        let m = crate::shapes::cuboid(crate::mesh::V3::new(0.1, 0.2, 0.3));
        let b = to_bytes(&m);
        let r = load_bytes(Path::new("a.msh"), &b, &Limits::default()).unwrap();
        assert!((r.signed_volume() - 0.006).abs() < 1e-9);
        let e = load_bytes(Path::new("a.msh"), &b[..b.len() - 1], &Limits::default()).unwrap_err();
        assert!(e.to_string().contains("need"), "{e}");
    }
}
