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
    let img = Arc::new(jpeg_reduced(bytes).or_else(|| {
        let img = image::load_from_memory(bytes).ok()?.into_rgb8();
        Some(Image {
            w: img.width(),
            h: img.height(),
            px: img.into_raw(),
        })
    })?);
    if let Ok(mut cache) = DECODED.lock() {
        if cache.len() >= DECODED_KEEP {
            cache.remove(0);
        }
        cache.push((bytes.clone(), img.clone()));
    }
    Some(img)
}

/// The side a JPEG texture is decoded down to (at least, on one axis): compose reads one texel
/// per sample point and asks at most 5,000 points of a mesh, so a 512² decode still has ~50
/// texels a sample (the atlas' empty space aside) — finer detail is never seen by the sampling.
const JPEG_MIN_SIDE: u16 = 512;

/// A JPEG decoded at 1/2, 1/4 or 1/8 scale in the IDCT (`jpeg_decoder::Decoder::scale`: the
/// smallest factor that keeps one side ≥ [`JPEG_MIN_SIDE`]); each texel is then close to the
/// mean of the full texels it covers. Entropy decoding is still whole, the IDCT and colour
/// conversion shrink with the output: a 4096² texture costs a fraction of its full decode.
/// `None` (the caller decodes in full) for anything but an 8-bit grey or RGB JPEG or on any
/// decoder error. Deterministic: single-threaded integer IDCT.
fn jpeg_reduced(bytes: &[u8]) -> Option<Image> {
    if !bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        return None;
    }
    let mut dec = jpeg_decoder::Decoder::new(bytes);
    dec.scale(JPEG_MIN_SIDE, JPEG_MIN_SIDE).ok()?;
    let px = dec.decode().ok()?;
    let info = dec.info()?;
    let (w, h) = (u32::from(info.width), u32::from(info.height));
    let n = w as usize * h as usize;
    if n == 0 {
        return None;
    }
    let px = match info.pixel_format {
        jpeg_decoder::PixelFormat::RGB24 if px.len() == 3 * n => px,
        jpeg_decoder::PixelFormat::L8 if px.len() == n => {
            px.iter().flat_map(|&l| [l, l, l]).collect()
        }
        _ => return None,
    };
    Some(Image { w, h, px })
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

#[cfg(test)]
mod tests {
    use super::*;
    use image::codecs::jpeg::JpegEncoder;
    use image::{ImageEncoder, ImageFormat};

    /// A colour field: slow gradients, a soft disc, and red stripes one texel wide (+60 on odd
    /// columns), so a texel that is not the mean of the ones it covers (a skipped or shifted
    /// one) is off by ~30 in red.
    fn field(w: u32, h: u32) -> image::RgbImage {
        image::RgbImage::from_fn(w, h, |x, y| {
            let (u, v) = (x as f64 / w as f64, y as f64 / h as f64);
            let d = ((u - 0.4).powi(2) + (v - 0.6).powi(2)).sqrt();
            let disc = 1.0 / (1.0 + (40.0 * (d - 0.25)).exp());
            image::Rgb([
                (40.0 + 140.0 * u + 60.0 * (x % 2) as f64) as u8,
                (30.0 + 150.0 * disc) as u8,
                (200.0 - 120.0 * v) as u8,
            ])
        })
    }

    fn jpeg(img: &image::RgbImage) -> Vec<u8> {
        let mut out = Vec::new();
        JpegEncoder::new_with_quality(&mut out, 92)
            .write_image(
                img,
                img.width(),
                img.height(),
                image::ExtendedColorType::Rgb8,
            )
            .unwrap();
        out
    }

    /// The reduced decode has the size the rule asks (the smallest of 1/2, 1/4, 1/8 keeping a
    /// side ≥ 512) and each texel is the mean of the full decode's texels it covers, to the
    /// rounding of an 8-bit JPEG.
    #[test]
    fn reduced_jpeg_texels_are_the_means_of_the_full_ones() {
        for (side, factor) in [(2048u32, 4u32), (1024, 2), (600, 1)] {
            let bytes = jpeg(&field(side, side));
            let small = jpeg_reduced(&bytes).expect("an RGB JPEG decodes");
            assert_eq!(
                (small.w, small.h),
                (side / factor, side / factor),
                "side {side}"
            );
            let full = image::load_from_memory(&bytes).unwrap().into_rgb8();
            let (mut worst, mut sum, mut count) = (0.0f64, 0.0, 0usize);
            for y in 0..small.h {
                for x in 0..small.w {
                    for c in 0..3 {
                        let mut mean = 0.0;
                        for dy in 0..factor {
                            for dx in 0..factor {
                                mean += full.get_pixel(x * factor + dx, y * factor + dy)[c as usize]
                                    as f64;
                            }
                        }
                        mean /= (factor * factor) as f64;
                        let got = small.px[3 * (y * small.w + x) as usize + c] as f64;
                        worst = worst.max((got - mean).abs());
                        sum += (got - mean).abs();
                        count += 1;
                    }
                }
            }
            let mean_err = sum / count as f64;
            assert!(
                mean_err < 4.0,
                "side {side}: mean |Δ| {mean_err}, worst {worst}"
            );
            assert!(worst < 40.0, "side {side}: worst |Δ| {worst}");
        }
    }

    /// A grey JPEG comes back as RGB with equal channels; a PNG and bytes that are not an image
    /// are not handled here (the caller decodes them in full, or reads no colour).
    #[test]
    fn grey_jpeg_expands_and_other_bytes_fall_through() {
        let grey = image::GrayImage::from_fn(1024, 1024, |x, _| image::Luma([(x / 4) as u8]));
        let mut bytes = Vec::new();
        JpegEncoder::new_with_quality(&mut bytes, 92)
            .write_image(&grey, 1024, 1024, image::ExtendedColorType::L8)
            .unwrap();
        let img = jpeg_reduced(&bytes).expect("a grey JPEG decodes");
        assert_eq!((img.w, img.h), (512, 512));
        let texel = &img.px[3 * (10 * 512 + 300)..3 * (10 * 512 + 300) + 3];
        assert_eq!(texel[0], texel[1]);
        assert_eq!(texel[1], texel[2]);
        // Texel 300 covers full columns 600–601, grey 150.
        assert!((texel[0] as i32 - 150).abs() <= 2, "{texel:?}");

        let mut png = Vec::new();
        field(64, 64)
            .write_to(&mut std::io::Cursor::new(&mut png), ImageFormat::Png)
            .unwrap();
        assert!(jpeg_reduced(&png).is_none());
        let png = decoded(&Arc::new(png)).expect("a PNG decodes in full");
        assert_eq!((png.w, png.h), (64, 64));

        let mut broken = jpeg(&field(256, 256));
        broken.truncate(40);
        assert!(jpeg_reduced(&broken).is_none());
        assert!(decoded(&Arc::new(broken)).is_none());
    }
}
