//! Point clouds sampled from visual meshes: area-uniform surface points with face normals and
//! colours (texture looked up at the point's UV, times the material's base colour).

use crate::mesh::{triangle_area, VisualMesh, P3, V3};
use crate::rng::Rng;
use nalgebra::Matrix4;
use std::sync::{Arc, Mutex};

/// Surface samples of one mesh.
#[derive(Clone, Debug, Default)]
pub struct Cloud {
    pub points: Vec<P3>,
    /// Unit face normals (the winding of the source triangle).
    pub normals: Vec<V3>,
    /// Linear-ish RGB in [0, 1] (texture texel × base colour).
    pub colours: Vec<[f64; 3]>,
}

/// A decoded texture, for colour look-ups.
struct Image {
    w: u32,
    h: u32,
    px: Vec<u8>,
}

impl Image {
    fn at(&self, uv: [f64; 2]) -> [f64; 3] {
        let u = uv[0] - uv[0].floor();
        let v = uv[1] - uv[1].floor();
        let x = ((u * self.w as f64) as u32).min(self.w - 1);
        let y = ((v * self.h as f64) as u32).min(self.h - 1);
        let i = 3 * (y as usize * self.w as usize + x as usize);
        [
            self.px[i] as f64 / 255.0,
            self.px[i + 1] as f64 / 255.0,
            self.px[i + 2] as f64 / 255.0,
        ]
    }
}

/// Decoded textures of the last few meshes sampled, by their shared bytes: composing samples
/// an object, its guidance part (the same texture) and the object again, and a 4096² JPEG
/// takes ~0.2 s to decode. The cache holds a clone of each key, so an address is never reused
/// while cached.
type Cached = Vec<(Arc<Vec<u8>>, Arc<Image>)>;
static DECODED: Mutex<Cached> = Mutex::new(Vec::new());
const DECODED_KEEP: usize = 4;

fn decoded(bytes: &Arc<Vec<u8>>) -> Option<Arc<Image>> {
    if let Some(hit) = DECODED
        .lock()
        .ok()?
        .iter()
        .find(|(k, _)| Arc::ptr_eq(k, bytes))
        .map(|(_, img)| img.clone())
    {
        return Some(hit);
    }
    let img = image::load_from_memory(bytes).ok()?.into_rgb8();
    let img = Arc::new(Image {
        w: img.width(),
        h: img.height(),
        px: img.into_raw(),
    });
    if let Ok(mut cache) = DECODED.lock() {
        if cache.len() >= DECODED_KEEP {
            cache.remove(0);
        }
        cache.push((bytes.clone(), img.clone()));
    }
    Some(img)
}

/// Empty the decoded-texture cache (benchmarks time a cold start with it).
pub fn forget_decoded() {
    if let Ok(mut c) = DECODED.lock() {
        c.clear();
    }
}

impl Cloud {
    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// `n` points uniform over the surface area (stratified along the cumulative area, so the
    /// sample is even), deterministic for a seed.
    pub fn sample(mesh: &VisualMesh, n: usize, seed: u64) -> Cloud {
        let mut rng = Rng::new(seed);
        // (part, triangle, cumulative area)
        let mut tris: Vec<(usize, usize)> = Vec::new();
        let mut cum: Vec<f64> = Vec::new();
        let mut total = 0.0;
        for (pi, part) in mesh.parts.iter().enumerate() {
            for (ti, t) in part.triangles.iter().enumerate() {
                let a = triangle_area(&t.map(|i| part.positions[i as usize]));
                if a > 0.0 && a.is_finite() {
                    total += a;
                    tris.push((pi, ti));
                    cum.push(total);
                }
            }
        }
        let mut out = Cloud::default();
        if tris.is_empty() || n == 0 {
            return out;
        }
        let images: Vec<Option<Arc<Image>>> = mesh
            .parts
            .iter()
            .map(|p| {
                let tex = p.material.texture.as_ref()?;
                p.uvs.as_ref()?;
                decoded(&tex.bytes)
            })
            .collect();
        out.points.reserve(n);
        for k in 0..n {
            let target = (k as f64 + rng.next_f64()) / n as f64 * total;
            let j = cum.partition_point(|&c| c < target).min(tris.len() - 1);
            let (pi, ti) = tris[j];
            let part = &mesh.parts[pi];
            let t = part.triangles[ti];
            let [a, b, c] = t.map(|i| part.positions[i as usize]);
            let (mut r1, mut r2) = (rng.next_f64(), rng.next_f64());
            if r1 + r2 > 1.0 {
                r1 = 1.0 - r1;
                r2 = 1.0 - r2;
            }
            let w = [1.0 - r1 - r2, r1, r2];
            let p = P3::from(a.coords * w[0] + b.coords * w[1] + c.coords * w[2]);
            let nrm = (b - a).cross(&(c - a));
            let nrm = if nrm.norm() > 0.0 {
                nrm.normalize()
            } else {
                V3::z()
            };
            let base = part.material.base_color;
            let mut col = [base[0], base[1], base[2]];
            if let (Some(img), Some(uvs)) = (&images[pi], &part.uvs) {
                let uv = [0, 1].map(|d| {
                    w[0] * uvs[t[0] as usize][d]
                        + w[1] * uvs[t[1] as usize][d]
                        + w[2] * uvs[t[2] as usize][d]
                });
                let tc = img.at(uv);
                col = [col[0] * tc[0], col[1] * tc[1], col[2] * tc[2]];
            }
            out.points.push(p);
            out.normals.push(nrm);
            out.colours.push(col);
        }
        out
    }

    /// The cloud moved by a 4x4 similarity (normals rotated, colours kept).
    pub fn transformed(&self, m: &Matrix4<f64>) -> Cloud {
        let r = m.fixed_view::<3, 3>(0, 0).into_owned();
        Cloud {
            points: self.points.iter().map(|p| m.transform_point(p)).collect(),
            normals: self.normals.iter().map(|n| (r * n).normalize()).collect(),
            colours: self.colours.clone(),
        }
    }

    /// Every `k`-th point (deterministic subsample of at most `n` points).
    pub fn subsample(&self, n: usize) -> Cloud {
        if self.len() <= n {
            return self.clone();
        }
        let step = self.len() as f64 / n as f64;
        let idx: Vec<usize> = (0..n).map(|i| (i as f64 * step) as usize).collect();
        Cloud {
            points: idx.iter().map(|&i| self.points[i]).collect(),
            normals: idx.iter().map(|&i| self.normals[i]).collect(),
            colours: idx.iter().map(|&i| self.colours[i]).collect(),
        }
    }

    /// Whether the colours vary enough to carry information (not one flat colour).
    pub fn has_colour_variation(&self) -> bool {
        if self.colours.len() < 2 {
            return false;
        }
        let n = self.colours.len() as f64;
        let mut mean = [0.0; 3];
        for c in &self.colours {
            for k in 0..3 {
                mean[k] += c[k] / n;
            }
        }
        let var: f64 = self
            .colours
            .iter()
            .map(|c| (0..3).map(|k| (c[k] - mean[k]).powi(2)).sum::<f64>())
            .sum::<f64>()
            / n;
        var.sqrt() > 0.03
    }

    /// Axis-aligned diagonal of the points.
    pub fn diagonal(&self) -> f64 {
        crate::mesh::Aabb::of_points(&self.points)
            .map(|b| b.diagonal())
            .unwrap_or(0.0)
    }

    pub fn centroid(&self) -> P3 {
        let n = self.points.len().max(1) as f64;
        P3::from(self.points.iter().fold(V3::zeros(), |a, p| a + p.coords) / n)
    }
}
