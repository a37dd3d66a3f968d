//! The pinhole camera of every view, in the OpenCV convention: camera x right, y down, z forward
//! (into the scene); a pixel `(u, v)` covers `[u, u+1) × [v, v+1)`, so its centre is at
//! `u + 0.5`. A world point `X` projects to `K · (R X + t)` with `K = [[fx,0,cx],[0,fy,cy],[0,0,1]]`.
//!
//! Entry points: [`Camera::look_at`], [`Camera::framing`] (a named view of a bounding sphere),
//! [`Camera::project`], [`Camera::ray`].

use crate::mesh::{P3, V3};
use nalgebra::{Matrix3, Matrix4};
use serde::Serialize;

/// A pinhole camera: intrinsics and a world→camera rigid transform.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub width: u32,
    pub height: u32,
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
    /// World → camera rotation (rows: camera x, y, z axes in world coordinates).
    pub rotation: Matrix3<f64>,
    /// World → camera translation.
    pub translation: V3,
}

/// The six named views of a scene.
pub const VIEWS: [&str; 6] = ["front", "back", "left", "right", "top", "three_quarter"];

impl Camera {
    /// A camera at `eye` looking at `target`, `up` roughly up in the image, vertical field of
    /// view `fov_y_deg`, square pixels.
    pub fn look_at(eye: P3, target: P3, up: V3, fov_y_deg: f64, width: u32, height: u32) -> Camera {
        let z = (target - eye).normalize();
        let x = z.cross(&up).normalize(); // right = forward × up (y down)
        let y = z.cross(&x);
        let rotation = Matrix3::from_rows(&[x.transpose(), y.transpose(), z.transpose()]);
        let f = 0.5 * height as f64 / (0.5 * fov_y_deg.to_radians()).tan();
        Camera {
            width,
            height,
            fx: f,
            fy: f,
            cx: 0.5 * width as f64,
            cy: 0.5 * height as f64,
            rotation,
            translation: -(rotation * eye.coords),
        }
    }

    /// The named view (one of [`VIEWS`]) of a sphere (`center`, `radius`) in a Z-up world
    /// whose front faces -Y: front/back/left/right from 20° above the horizon, top straight
    /// down (image up = +Y), three-quarter from front-right, 35° up. The sphere fills the
    /// image with a 5 % margin.
    pub fn framing(view: &str, center: P3, radius: f64, width: u32, height: u32) -> Option<Camera> {
        const FOV: f64 = 40.0;
        let (azimuth, elevation): (f64, f64) = match view {
            "front" => (-90.0, 20.0),
            "back" => (90.0, 20.0),
            "left" => (180.0, 20.0),
            "right" => (0.0, 20.0),
            "top" => (-90.0, 90.0),
            "three_quarter" => (-45.0, 35.0),
            _ => return None,
        };
        let half = 0.5 * FOV.to_radians() * (width.min(height) as f64 / height as f64);
        let dist = 1.05 * radius.max(1e-9) / half.sin();
        let (a, e) = (azimuth.to_radians(), elevation.to_radians());
        let dir = V3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin());
        let up = if elevation >= 89.0 { V3::y() } else { V3::z() };
        Some(Camera::look_at(
            center + dir * dist,
            center,
            up,
            FOV,
            width,
            height,
        ))
    }

    /// Camera centre in the world.
    pub fn eye(&self) -> P3 {
        P3::from(-(self.rotation.transpose() * self.translation))
    }

    /// World point → camera coordinates.
    pub fn to_camera(&self, p: &P3) -> V3 {
        self.rotation * p.coords + self.translation
    }

    /// World point → (pixel u, pixel v, depth along the optical axis). Points behind the
    /// camera have depth ≤ 0 and meaningless pixel coordinates.
    pub fn project(&self, p: &P3) -> (f64, f64, f64) {
        let c = self.to_camera(p);
        (
            self.fx * c.x / c.z + self.cx,
            self.fy * c.y / c.z + self.cy,
            c.z,
        )
    }

    /// The viewing ray through image position `(u, v)` (pixel units): unit world direction.
    pub fn ray(&self, u: f64, v: f64) -> V3 {
        let d = V3::new((u - self.cx) / self.fx, (v - self.cy) / self.fy, 1.0);
        (self.rotation.transpose() * d).normalize()
    }

    /// Optical axis (world).
    pub fn forward(&self) -> V3 {
        self.rotation.row(2).transpose()
    }

    /// The same camera at another resolution (`k` times finer), for supersampling.
    pub fn scaled(&self, k: u32) -> Camera {
        let s = k as f64;
        Camera {
            width: self.width * k,
            height: self.height * k,
            fx: self.fx * s,
            fy: self.fy * s,
            cx: self.cx * s,
            cy: self.cy * s,
            ..self.clone()
        }
    }

    /// What `views.json` records of it.
    pub fn record(&self) -> CameraRecord {
        let mut m = Matrix4::identity();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.rotation);
        m.fixed_view_mut::<3, 1>(0, 3).copy_from(&self.translation);
        let rows = |k: usize| -> [f64; 4] { [m[(k, 0)], m[(k, 1)], m[(k, 2)], m[(k, 3)]] };
        let eye = self.eye();
        CameraRecord {
            width: self.width,
            height: self.height,
            intrinsics: [
                [self.fx, 0.0, self.cx],
                [0.0, self.fy, self.cy],
                [0.0, 0.0, 1.0],
            ],
            world_to_camera: [rows(0), rows(1), rows(2), rows(3)],
            eye: [eye.x, eye.y, eye.z],
            fov_y_deg: 2.0 * (0.5 * self.height as f64 / self.fy).atan().to_degrees(),
        }
    }
}

/// A camera as written to `views.json`.
#[derive(Clone, Debug, Serialize)]
pub struct CameraRecord {
    pub width: u32,
    pub height: u32,
    /// K (pixels; pixel centres at integer + 0.5).
    pub intrinsics: [[f64; 3]; 3],
    /// Extrinsics [R t; 0 1], world (metres, Z up) → camera (x right, y down, z forward).
    pub world_to_camera: [[f64; 4]; 4],
    pub eye: [f64; 3],
    pub fov_y_deg: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_matches_the_pinhole_model() {
        // Camera at (0,-5,0) looking at the origin, Z up: world x → image right, world z → up.
        let c = Camera::look_at(
            P3::new(0.0, -5.0, 0.0),
            P3::origin(),
            V3::z(),
            90.0,
            100,
            100,
        );
        // f = 50 / tan(45°) = 50 px; the point (1, 0, 0.5) is at depth 5.
        let (u, v, d) = c.project(&P3::new(1.0, 0.0, 0.5));
        assert!((d - 5.0).abs() < 1e-12);
        assert!((u - (50.0 + 50.0 * 1.0 / 5.0)).abs() < 1e-9, "u {u}");
        assert!((v - (50.0 - 50.0 * 0.5 / 5.0)).abs() < 1e-9, "v {v}");
        // The ray through that pixel passes through the point.
        let r = c.ray(u, v);
        let p = c.eye() + r * (P3::new(1.0, 0.0, 0.5) - c.eye()).norm();
        assert!((p - P3::new(1.0, 0.0, 0.5)).norm() < 1e-9);
    }

    #[test]
    fn framing_fits_the_sphere_in_every_view() {
        for v in VIEWS {
            let c = Camera::framing(v, P3::new(1.0, 2.0, 0.5), 0.3, 64, 64).unwrap();
            // The sphere's centre projects to the image centre, and its silhouette stays inside.
            let (u, w, _) = c.project(&P3::new(1.0, 2.0, 0.5));
            assert!((u - 32.0).abs() < 1e-9 && (w - 32.0).abs() < 1e-9, "{v}");
            let dist = (c.eye() - P3::new(1.0, 2.0, 0.5)).norm();
            let half_angle = (0.3 / dist).asin();
            let half_fov = (32.0 / c.fy).atan();
            assert!(half_angle < half_fov && half_angle > 0.9 * half_fov, "{v}");
        }
    }
}
