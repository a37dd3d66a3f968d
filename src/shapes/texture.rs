//! Texture coordinates, materials and procedural textures for the visual meshes.
//!
//! Entry points: [`with_uvs`], [`visual`], [`png_texture`], [`checker_texture`],
//! [`stripes_texture`], [`textured_material`].

use crate::mesh::{Material, Mesh, Texture, VisualMesh, VisualPart, P3};
use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::Arc;

// Texture coordinates, materials and procedural textures.

/// How [`with_uvs`] maps positions to texture coordinates (glTF convention: v grows downwards, so
/// the top of the image is at the top of the object). Ranges come from the mesh's bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum UvProjection {
    /// Seen from above: u along x, v along −y, both scaled by the larger xy extent.
    PlanarZ,
    /// Around the z axis: u = angle / 2π (`repeat` times), v from the top (max z) down.
    Cylindrical { repeat: f64 },
    /// Around the z axis: u = angle / 2π (`repeat` times), v = polar angle / π from +z.
    Spherical { repeat: f64 },
    /// Per triangle, the axis its normal points most along chooses the plane to project on;
    /// `tile` metres per texture repeat.
    Box { tile: f64 },
}

/// Give a welded mesh UVs by `projection`: vertices are split where the UVs of their triangles
/// disagree (the seam of the cylindrical map, the edges of the box map), otherwise shared.
/// Returns positions, UVs and triangles of one [`VisualPart`]. Deterministic.
pub fn with_uvs(mesh: &Mesh, projection: UvProjection) -> (Vec<P3>, Vec<[f64; 2]>, Vec<[u32; 3]>) {
    let bb = mesh.aabb().expect("with_uvs needs a non-empty mesh");
    let ext = bb.extents();
    let centre = bb.center();
    let span = |d: f64| if d > 0.0 { d } else { 1.0 };
    let angle_u = |p: &P3| -> Option<f64> {
        let (x, y) = (p.x - centre.x, p.y - centre.y);
        if x.hypot(y) <= 1e-12 * (1.0 + ext.x.max(ext.y)) {
            None
        } else {
            Some(y.atan2(x).rem_euclid(2.0 * PI) / (2.0 * PI))
        }
    };
    let mut positions = Vec::new();
    let mut uvs: Vec<[f64; 2]> = Vec::new();
    let mut triangles = Vec::with_capacity(mesh.triangles.len());
    let mut seen: HashMap<(u32, u64, u64), u32> = HashMap::new();
    for t in &mesh.triangles {
        let ps = [
            mesh.vertices[t[0] as usize],
            mesh.vertices[t[1] as usize],
            mesh.vertices[t[2] as usize],
        ];
        let mut uv = [[0.0f64; 2]; 3];
        match projection {
            UvProjection::PlanarZ => {
                let s = span(ext.x.max(ext.y));
                for k in 0..3 {
                    uv[k] = [(ps[k].x - bb.min.x) / s, (bb.max.y - ps[k].y) / s];
                }
            }
            UvProjection::Cylindrical { repeat } | UvProjection::Spherical { repeat } => {
                let mut us: [Option<f64>; 3] = [angle_u(&ps[0]), angle_u(&ps[1]), angle_u(&ps[2])];
                // Unwrap across the seam at angle 0.
                let known: Vec<f64> = us.iter().flatten().copied().collect();
                if let (Some(lo), Some(hi)) = (
                    known.iter().copied().reduce(f64::min),
                    known.iter().copied().reduce(f64::max),
                ) {
                    if hi - lo > 0.5 {
                        for u in us.iter_mut().flatten() {
                            if *u < 0.5 {
                                *u += 1.0;
                            }
                        }
                    }
                }
                let mean = {
                    let k: Vec<f64> = us.iter().flatten().copied().collect();
                    if k.is_empty() {
                        0.0
                    } else {
                        k.iter().sum::<f64>() / k.len() as f64
                    }
                };
                for k in 0..3 {
                    let u = us[k].unwrap_or(mean) * repeat;
                    let v = match projection {
                        UvProjection::Spherical { .. } => {
                            let d = ps[k] - centre;
                            let r = d.norm();
                            if r > 0.0 {
                                (d.z / r).clamp(-1.0, 1.0).acos() / PI
                            } else {
                                0.5
                            }
                        }
                        _ => (bb.max.z - ps[k].z) / span(ext.z),
                    };
                    uv[k] = [u, v];
                }
            }
            UvProjection::Box { tile } => {
                let n = (ps[1] - ps[0]).cross(&(ps[2] - ps[0]));
                let axis = n.iamax();
                for k in 0..3 {
                    let d = ps[k] - bb.min;
                    let (a, b) = match axis {
                        0 => (d.y, ext.z - d.z),
                        1 => (d.x, ext.z - d.z),
                        _ => (d.x, ext.y - d.y),
                    };
                    uv[k] = [a / tile, b / tile];
                }
            }
        }
        let mut tri = [0u32; 3];
        for k in 0..3 {
            let key = (t[k], uv[k][0].to_bits(), uv[k][1].to_bits());
            tri[k] = *seen.entry(key).or_insert_with(|| {
                positions.push(ps[k]);
                uvs.push(uv[k]);
                (positions.len() - 1) as u32
            });
        }
        triangles.push(tri);
    }
    (positions, uvs, triangles)
}

/// [`visual`] with box-projected UVs (tile 1) and the default material: an untextured object,
/// as the registration tests sample it.
pub fn plain_visual(mesh: &Mesh) -> VisualMesh {
    visual(mesh, UvProjection::Box { tile: 1.0 }, Material::default())
}

/// A one-part [`VisualMesh`] of `mesh` with UVs by `projection` and `material`.
pub fn visual(mesh: &Mesh, projection: UvProjection, material: Material) -> VisualMesh {
    let (positions, uvs, triangles) = with_uvs(mesh, projection);
    VisualMesh {
        parts: vec![VisualPart {
            positions,
            uvs: Some(uvs),
            triangles,
            material,
        }],
    }
}

/// Encode an RGB image as PNG (deterministic bytes for the same pixels) and wrap it as a
/// [`Texture`] named `origin`.
pub fn png_texture(img: &image::RgbImage, origin: &str) -> Texture {
    use image::ImageEncoder;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgb8,
        )
        .expect("PNG encoding into memory cannot fail");
    Texture {
        origin: origin.to_string(),
        bytes: Arc::new(bytes),
        width: img.width(),
        height: img.height(),
    }
}

/// A `size`×`size` checkerboard of `cells`×`cells` squares in colours `a` and `b`, with a thin
/// darker line along the top row so orientation mistakes (v flipped) show.
pub fn checker_texture(size: u32, cells: u32, a: [u8; 3], b: [u8; 3], origin: &str) -> Texture {
    let cell = (size / cells.max(1)).max(1);
    let img = image::RgbImage::from_fn(size, size, |x, y| {
        if y < (size / 32).max(1) {
            return image::Rgb([a[0] / 3, a[1] / 3, a[2] / 3]);
        }
        if ((x / cell) + (y / cell)) % 2 == 0 {
            image::Rgb(a)
        } else {
            image::Rgb(b)
        }
    });
    png_texture(&img, origin)
}

/// A `size`×`size` image of `stripes` vertical stripes (constant along v, so a cylindrical or
/// spherical map gives meridian bands) alternating `a` and `b`.
pub fn stripes_texture(size: u32, stripes: u32, a: [u8; 3], b: [u8; 3], origin: &str) -> Texture {
    let w = (size / stripes.max(1)).max(1);
    let img = image::RgbImage::from_fn(size, size, |x, _| {
        if (x / w) % 2 == 0 {
            image::Rgb(a)
        } else {
            image::Rgb(b)
        }
    });
    png_texture(&img, origin)
}

/// A material showing `texture` unmodified (base colour factor white).
pub fn textured_material(name: &str, texture: Texture) -> Material {
    Material {
        name: name.to_string(),
        base_color: [1.0, 1.0, 1.0, 1.0],
        texture: Some(texture),
    }
}
