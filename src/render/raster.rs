//! A z-buffer rasteriser on the CPU: triangles with flat shading, perspective-correct texture
//! lookups (nearest texel, wrapping), a checkered floor traced per pixel, supersampling by a box
//! filter. Everything is `f64` in a fixed order, so the same input gives the same bytes.
//!
//! Entry points: [`RenderMesh`] (world triangles with materials, built once per scene),
//! [`Frame::new`] / [`Frame::floor`] / [`Frame::draw`], [`Frame::downsample`].

use super::camera::Camera;
use crate::mesh::{P3, V3};
use image::{RgbImage, RgbaImage};
use std::sync::Arc;

/// Background colour (sRGB, 0..1) where neither floor nor geometry is seen.
pub const BACKGROUND: [f32; 3] = [0.96, 0.97, 0.99];

/// A material as the rasteriser uses it: display-space colour and an optional decoded texture.
#[derive(Clone)]
pub struct RMaterial {
    pub colour: [f32; 3],
    pub texture: Option<Arc<RgbaImage>>,
}

/// World-space triangles of a whole scene, each with a material and a tag (for the hull view:
/// which hull it belongs to; `tag_object[tag]` says which object).
#[derive(Clone, Default)]
pub struct RenderMesh {
    pub verts: Vec<P3>,
    /// One UV per vertex (zero when the part has none).
    pub uvs: Vec<[f64; 2]>,
    pub tris: Vec<[u32; 3]>,
    pub tri_material: Vec<u32>,
    /// Tag of each triangle, ≥ 1 (0 marks "nothing" in a frame).
    pub tri_tag: Vec<u32>,
    pub materials: Vec<RMaterial>,
}

impl RenderMesh {
    /// Append triangles (`uvs` parallel to `verts` when given) with one material and tag.
    pub fn push(
        &mut self,
        verts: &[P3],
        uvs: Option<&[[f64; 2]]>,
        tris: &[[u32; 3]],
        material: u32,
        tag: u32,
    ) {
        let off = self.verts.len() as u32;
        self.verts.extend_from_slice(verts);
        match uvs {
            Some(u) if u.len() == verts.len() => self.uvs.extend_from_slice(u),
            _ => self
                .uvs
                .extend(std::iter::repeat_n([0.0, 0.0], verts.len())),
        }
        for t in tris {
            if t.iter().all(|&i| (i as usize) < verts.len()) {
                self.tris.push(t.map(|i| i + off));
                self.tri_material.push(material);
                self.tri_tag.push(tag);
            }
        }
    }
}

/// A render target: per pixel depth (camera z), colour (display space, 0..1) and tag.
pub struct Frame {
    pub width: usize,
    pub height: usize,
    pub depth: Vec<f64>,
    pub rgb: Vec<[f32; 3]>,
    pub tag: Vec<u32>,
    /// Shading factor of the triangle seen (colour = material × light).
    pub light: Vec<f32>,
}

/// Light directions (world, towards the light): a key light from above front-left.
fn key_light() -> V3 {
    V3::new(-0.4, -0.6, 0.8).normalize()
}

impl Frame {
    pub fn new(width: usize, height: usize) -> Frame {
        Frame {
            width,
            height,
            depth: vec![f64::INFINITY; width * height],
            rgb: vec![BACKGROUND; width * height],
            tag: vec![0; width * height],
            light: vec![1.0; width * height],
        }
    }

    /// Trace the floor plane `z = z0` (a checkerboard of `cell`-sized squares that fades out
    /// beyond `radius` of `center`) into every pixel that sees it.
    pub fn floor(&mut self, cam: &Camera, z0: f64, center: &P3, cell: f64, radius: f64) {
        let eye = cam.eye();
        if !(eye.z > z0) {
            return;
        }
        // Unnormalised ray d = Rᵀ((u − cx)/fx, (v − cy)/fy, 1): its camera z is 1, so the hit
        // parameter t is the depth itself.
        let rt = cam.rotation.transpose();
        let du = rt.column(0) / cam.fx;
        let dv = rt.column(1) / cam.fy;
        let d0 = rt.column(2) - du * cam.cx - dv * cam.cy;
        for y in 0..self.height {
            let row = d0 + dv * (y as f64 + 0.5);
            for x in 0..self.width {
                let d = row + du * (x as f64 + 0.5);
                if !(d.z < 0.0) {
                    continue;
                }
                let t = (z0 - eye.z) / d.z;
                let (px, py) = (eye.x + d.x * t, eye.y + d.y * t);
                let r = ((px - center.x).powi(2) + (py - center.y).powi(2)).sqrt();
                let fade = (1.0 - (r / radius - 1.0).clamp(0.0, 1.0)) as f32;
                if fade <= 0.0 {
                    continue;
                }
                let i = y * self.width + x;
                let checker = ((px / cell).floor() as i64 + (py / cell).floor() as i64) & 1;
                let c: f32 = if checker == 0 { 0.80 } else { 0.72 };
                self.rgb[i] = std::array::from_fn(|k| BACKGROUND[k] + (c - BACKGROUND[k]) * fade);
                self.depth[i] = t;
            }
        }
    }

    /// Draw a mesh: z-buffered, flat-shaded (two-sided: a key light plus a headlight),
    /// textured. `colour_of_tag`, when given, replaces the material colour and texture.
    pub fn draw(
        &mut self,
        cam: &Camera,
        mesh: &RenderMesh,
        colour_of_tag: Option<&dyn Fn(u32) -> [f32; 3]>,
    ) {
        let eye = cam.eye();
        let near = 1e-6 * (eye.coords.norm() + 1.0);
        let proj: Vec<(f64, f64, f64)> = mesh.verts.iter().map(|p| cam.project(p)).collect();
        let key = key_light();
        let (w, h) = (self.width as f64, self.height as f64);
        for (ti, t) in mesh.tris.iter().enumerate() {
            let [a, b, c] = t.map(|i| proj[i as usize]);
            if a.2 < near || b.2 < near || c.2 < near {
                continue;
            }
            let area = (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0);
            if !(area.abs() > 1e-12) {
                continue;
            }
            let x0 = a.0.min(b.0).min(c.0).floor().max(0.0);
            let x1 = a.0.max(b.0).max(c.0).ceil().min(w);
            let y0 = a.1.min(b.1).min(c.1).floor().max(0.0);
            let y1 = a.1.max(b.1).max(c.1).ceil().min(h);
            if !(x0 < x1 && y0 < y1) {
                continue;
            }
            // Flat shading from the world face normal, turned towards the camera.
            let [pa, pb, pc] = t.map(|i| mesh.verts[i as usize]);
            let mut n = (pb - pa).cross(&(pc - pa));
            let len = n.norm();
            if !(len > 0.0) {
                continue;
            }
            n /= len;
            let to_eye = (eye - pa).normalize();
            if n.dot(&to_eye) < 0.0 {
                n = -n;
            }
            let light = (0.32 + 0.5 * n.dot(&key).max(0.0) + 0.28 * n.dot(&to_eye).max(0.0)) as f32;
            let tag = mesh.tri_tag[ti];
            let mat = &mesh.materials[mesh.tri_material[ti] as usize];
            let (base, tex) = match colour_of_tag {
                Some(f) => (f(tag), None),
                None => (mat.colour, mat.texture.as_deref()),
            };
            let uv = t.map(|i| mesh.uvs[i as usize]);
            let inv = 1.0 / area;
            let iz = [1.0 / a.2, 1.0 / b.2, 1.0 / c.2];
            // Per-column slopes of the barycentric weights, to find each row's span.
            let s0 = (b.1 - c.1) * inv;
            let s1 = (c.1 - a.1) * inv;
            let slopes = [s0, s1, -(s0 + s1)];
            for y in y0 as usize..y1 as usize {
                let py = y as f64 + 0.5;
                let px0 = x0 + 0.5;
                let w00 = ((b.0 - px0) * (c.1 - py) - (b.1 - py) * (c.0 - px0)) * inv;
                let w10 = ((c.0 - px0) * (a.1 - py) - (c.1 - py) * (a.0 - px0)) * inv;
                let start = [w00, w10, 1.0 - w00 - w10];
                // Columns k (from x0) where all three weights are ≥ 0, widened by one on each
                // side for rounding; every pixel is still tested exactly below.
                let (mut lo, mut hi) = (0.0f64, x1 - x0 - 1.0);
                for (w, s) in start.iter().zip(slopes) {
                    if s > 0.0 {
                        lo = lo.max((-w / s).ceil() - 1.0);
                    } else if s < 0.0 {
                        hi = hi.min((-w / s).floor() + 1.0);
                    } else if *w < -1e-12 {
                        hi = -1.0;
                    }
                }
                if !(lo <= hi) {
                    continue;
                }
                for x in (x0 + lo) as usize..=(x0 + hi) as usize {
                    let px = x as f64 + 0.5;
                    let w0 = ((b.0 - px) * (c.1 - py) - (b.1 - py) * (c.0 - px)) * inv;
                    let w1 = ((c.0 - px) * (a.1 - py) - (c.1 - py) * (a.0 - px)) * inv;
                    let w2 = 1.0 - w0 - w1;
                    if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                        continue;
                    }
                    let izp = w0 * iz[0] + w1 * iz[1] + w2 * iz[2];
                    let z = 1.0 / izp;
                    let i = y * self.width + x;
                    if !(z < self.depth[i]) {
                        continue;
                    }
                    self.depth[i] = z;
                    self.tag[i] = tag;
                    self.light[i] = light;
                    let mut col = base;
                    if let Some(img) = tex {
                        let u =
                            (w0 * uv[0][0] * iz[0] + w1 * uv[1][0] * iz[1] + w2 * uv[2][0] * iz[2])
                                * z;
                        let v =
                            (w0 * uv[0][1] * iz[0] + w1 * uv[1][1] * iz[1] + w2 * uv[2][1] * iz[2])
                                * z;
                        let tx = ((u - u.floor()) * img.width() as f64) as u32;
                        let ty = ((v - v.floor()) * img.height() as f64) as u32;
                        let p = img
                            .get_pixel(tx.min(img.width() - 1), ty.min(img.height() - 1))
                            .0;
                        for k in 0..3 {
                            col[k] *= p[k] as f32 / 255.0;
                        }
                    }
                    self.rgb[i] = col.map(|c| (c * light).min(1.0));
                }
            }
        }
    }

    /// Average `k × k` blocks into an 8-bit image (`width` and `height` multiples of `k`).
    pub fn downsample(&self, k: usize) -> RgbImage {
        downsample(&self.rgb, self.width, self.height, k)
    }
}

/// Average `k × k` blocks of a colour buffer into an 8-bit image.
pub fn downsample(rgb: &[[f32; 3]], width: usize, height: usize, k: usize) -> RgbImage {
    let (w, h) = (width / k, height / k);
    let mut out = RgbImage::new(w as u32, h as u32);
    let norm = 1.0 / (k * k) as f32;
    for y in 0..h {
        for x in 0..w {
            let mut s = [0f32; 3];
            for dy in 0..k {
                let row = (y * k + dy) * width + x * k;
                for c in &rgb[row..row + k] {
                    for j in 0..3 {
                        s[j] += c[j];
                    }
                }
            }
            out.put_pixel(
                x as u32,
                y as u32,
                image::Rgb(s.map(|v| (v * norm * 255.0 + 0.5).clamp(0.0, 255.0) as u8)),
            );
        }
    }
    out
}

/// Linear colour component → sRGB display value (materials store linear base colours).
pub fn linear_to_srgb(c: f64) -> f32 {
    let c = c.clamp(0.0, 1.0);
    (if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(z: f64, half: f64) -> (Vec<P3>, Vec<[u32; 3]>) {
        (
            vec![
                P3::new(-half, -half, z),
                P3::new(half, -half, z),
                P3::new(half, half, z),
                P3::new(-half, half, z),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    #[test]
    fn a_square_covers_its_projected_area_and_the_nearer_one_wins() {
        // Looking down -z from (0,0,10) with f = 100 px: a 2×2 square at z=0 spans 20×20 px.
        let cam = Camera::look_at(
            P3::new(0.0, 0.0, 10.0),
            P3::origin(),
            V3::y(),
            2.0 * (1.0f64).atan().to_degrees(),
            200,
            200,
        );
        assert!((cam.fx - 100.0).abs() < 1e-9);
        let mut m = RenderMesh::default();
        m.materials.push(RMaterial {
            colour: [1.0, 1.0, 1.0],
            texture: None,
        });
        let (v, t) = quad(0.0, 1.0);
        m.push(&v, None, &t, 0, 1);
        let (v, t) = quad(5.0, 0.25); // 0.5×0.5 at depth 5: 10×10 px, in front
        m.push(&v, None, &t, 0, 2);
        let mut f = Frame::new(200, 200);
        f.draw(&cam, &m, None);
        let count = |tag| f.tag.iter().filter(|&&g| g == tag).count();
        assert_eq!(count(2), 100);
        assert_eq!(count(1), 400 - 100);
        // Depth of the far square is its distance along the axis.
        assert!((f.depth[100 * 200 + 90] - 10.0).abs() < 1e-9);
    }
}
