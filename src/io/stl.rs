//! STL reader, binary and ASCII. STL has no materials or UVs: one grey part.

use crate::error::{Error, Result};
use crate::io::Limits;
use crate::mesh::{Material, Mesh, VisualMesh, VisualPart, P3};
use std::path::Path;

/// Load an STL file (binary or ASCII, told apart by size and content, not by the `solid` word).
pub fn load(path: &Path, limits: &Limits) -> Result<VisualMesh> {
    let bytes = crate::io::read_file(path, limits)?;
    load_bytes(path, &bytes, limits)
}

/// Parse STL bytes; `path` names the file in errors.
pub fn load_bytes(path: &Path, bytes: &[u8], limits: &Limits) -> Result<VisualMesh> {
    let soup = parse(bytes, limits).map_err(|m| Error::input(path, m))?;
    // STL stores every triangle's corners separately: weld exact duplicates.
    let n = soup.len();
    let mesh = Mesh::new(
        soup,
        (0..n as u32 / 3)
            .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect(),
    )
    .welded(0.0);
    Ok(VisualMesh {
        parts: vec![VisualPart {
            positions: mesh.vertices,
            uvs: None,
            triangles: mesh.triangles,
            material: Material::default(),
        }],
    })
}

/// Triangle corners, three per triangle.
pub fn parse(bytes: &[u8], limits: &Limits) -> std::result::Result<Vec<P3>, String> {
    if bytes.len() >= 84 {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        let expected = 84 + 50 * count;
        if expected == bytes.len() as u64 {
            return parse_binary(bytes, count as usize, limits);
        }
        let looks_ascii = bytes.starts_with(b"solid")
            && bytes[..bytes.len().min(1024)].iter().all(|b| b.is_ascii());
        if !looks_ascii {
            return Err(format!(
                "binary STL declares {count} triangles ({expected} bytes) but the file has {} bytes (truncated or corrupt)",
                bytes.len()
            ));
        }
    } else if !bytes.starts_with(b"solid") {
        return Err(format!(
            "file of {} bytes is too short for a binary STL",
            bytes.len()
        ));
    }
    parse_ascii(bytes, limits)
}

fn parse_binary(
    bytes: &[u8],
    count: usize,
    limits: &Limits,
) -> std::result::Result<Vec<P3>, String> {
    if count > limits.max_triangles {
        return Err(format!(
            "STL has {count} triangles, over the limit of {} (--max-triangles)",
            limits.max_triangles
        ));
    }
    let mut out = Vec::with_capacity(count * 3);
    for t in 0..count {
        let base = 84 + 50 * t + 12;
        for k in 0..3 {
            let o = base + 12 * k;
            let f = |j: usize| {
                f32::from_le_bytes(bytes[o + 4 * j..o + 4 * j + 4].try_into().unwrap()) as f64
            };
            out.push(P3::new(f(0), f(1), f(2)));
        }
    }
    Ok(out)
}

fn parse_ascii(bytes: &[u8], limits: &Limits) -> std::result::Result<Vec<P3>, String> {
    let text = std::str::from_utf8(bytes).map_err(|_| "ASCII STL is not valid text".to_string())?;
    let mut out = Vec::new();
    let mut in_facet = 0;
    for (lineno, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("vertex") => {
                let mut c = [0.0f64; 3];
                for v in &mut c {
                    *v = it
                        .next()
                        .and_then(|s| s.parse().ok())
                        .ok_or_else(|| format!("line {}: bad vertex", lineno + 1))?;
                }
                out.push(P3::new(c[0], c[1], c[2]));
                in_facet += 1;
            }
            Some("endfacet") => {
                if in_facet != 3 {
                    return Err(format!(
                        "line {}: facet with {in_facet} vertices (3 expected)",
                        lineno + 1
                    ));
                }
                in_facet = 0;
            }
            _ => {}
        }
        if out.len() / 3 > limits.max_triangles {
            return Err(format!(
                "STL has more than {} triangles, over the limit (--max-triangles)",
                limits.max_triangles
            ));
        }
    }
    if out.len() % 3 != 0 {
        return Err("ASCII STL ends inside a facet (truncated)".into());
    }
    Ok(out)
}
