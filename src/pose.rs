//! Poses: the 4x4 similarity matrices of Interact3D (`p_world = s * R * p_local + t`), quaternions
//! and the checks that reject what is not a proper similarity (shear, mirror, zero scale, NaN).

use nalgebra::{Isometry3, Matrix3, Matrix4, Rotation3, Translation3, UnitQuaternion, Vector3};

/// A similarity transform: uniform scale, then rotation, then translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Similarity {
    pub scale: f64,
    pub rotation: UnitQuaternion<f64>,
    pub translation: Vector3<f64>,
}

impl Default for Similarity {
    fn default() -> Self {
        Similarity::identity()
    }
}

/// Relative tolerance on orthonormality of `M3 / s` before a matrix is called a similarity.
pub const SIMILARITY_TOLERANCE: f64 = 1e-3;

impl Similarity {
    pub fn identity() -> Self {
        Similarity {
            scale: 1.0,
            rotation: UnitQuaternion::identity(),
            translation: Vector3::zeros(),
        }
    }

    /// Split a 4x4 matrix (row-major rows) into scale, rotation and translation, or say why it is
    /// not a similarity: non-finite entries, a projective last row, zero or negative scale
    /// (a mirror), shear or non-uniform scale.
    pub fn from_matrix(m: &Matrix4<f64>) -> Result<Similarity, String> {
        if m.iter().any(|x| !x.is_finite()) {
            return Err("matrix has a NaN or infinite entry".into());
        }
        let last = m.row(3);
        if last[0].abs() > 1e-9
            || last[1].abs() > 1e-9
            || last[2].abs() > 1e-9
            || (last[3] - 1.0).abs() > 1e-9
        {
            return Err(format!(
                "last row must be [0, 0, 0, 1], got [{}, {}, {}, {}]",
                last[0], last[1], last[2], last[3]
            ));
        }
        let a: Matrix3<f64> = m.fixed_view::<3, 3>(0, 0).into_owned();
        let det = a.determinant();
        if det.abs() < 1e-300 || !det.is_finite() {
            return Err("matrix is singular (zero scale)".into());
        }
        if det < 0.0 {
            return Err(format!(
                "matrix mirrors (determinant {det:.6e} < 0): a similarity needs a positive scale and a proper rotation"
            ));
        }
        let scale = det.cbrt();
        let r = a / scale;
        let err = (r.transpose() * r - Matrix3::identity()).abs().max();
        if err > SIMILARITY_TOLERANCE {
            return Err(format!(
                "matrix is not a similarity (shear or non-uniform scale: |RᵀR − I| = {err:.3e} after removing scale {scale:.6e})"
            ));
        }
        // Project onto the nearest rotation so downstream math is exact.
        let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(&r));
        Ok(Similarity {
            scale,
            rotation,
            translation: Vector3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]),
        })
    }

    /// From rows as written in JSON (`[[..4], [..4], [..4], [..4]]`).
    pub fn from_rows(rows: &[Vec<f64>]) -> Result<Similarity, String> {
        if rows.len() != 4 || rows.iter().any(|r| r.len() != 4) {
            return Err("matrix must be 4x4 (a list of four rows of four numbers)".into());
        }
        let m = Matrix4::from_fn(|i, j| rows[i][j]);
        Similarity::from_matrix(&m)
    }

    /// Translation + quaternion (w, x, y, z; normalised here, must not be zero) + scale.
    pub fn from_parts(
        translation: [f64; 3],
        quaternion_wxyz: [f64; 4],
        scale: f64,
    ) -> Result<Similarity, String> {
        if translation
            .iter()
            .chain(quaternion_wxyz.iter())
            .any(|x| !x.is_finite())
            || !scale.is_finite()
        {
            return Err("pose has a NaN or infinite value".into());
        }
        if scale <= 0.0 {
            return Err(format!("scale must be positive, got {scale}"));
        }
        let q = nalgebra::Quaternion::new(
            quaternion_wxyz[0],
            quaternion_wxyz[1],
            quaternion_wxyz[2],
            quaternion_wxyz[3],
        );
        if q.norm() < 1e-9 {
            return Err("quaternion has zero length".into());
        }
        Ok(Similarity {
            scale,
            rotation: UnitQuaternion::from_quaternion(q),
            translation: Vector3::from(translation),
        })
    }

    /// The 4x4 matrix.
    pub fn matrix(&self) -> Matrix4<f64> {
        let mut m = Matrix4::identity();
        m.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(self.rotation.to_rotation_matrix().matrix() * self.scale));
        m.fixed_view_mut::<3, 1>(0, 3).copy_from(&self.translation);
        m
    }

    /// Composition `self ∘ other` (apply `other` first).
    pub fn then_after(&self, other: &Similarity) -> Similarity {
        Similarity {
            scale: self.scale * other.scale,
            rotation: self.rotation * other.rotation,
            translation: self.translation + self.rotation * (other.translation * self.scale),
        }
    }

    /// The rigid part (rotation and translation), scale dropped.
    pub fn isometry(&self) -> Isometry3<f64> {
        Isometry3::from_parts(Translation3::from(self.translation), self.rotation)
    }
}

/// glTF is Y-up; robotics is Z-up. The rotation taking a Y-up frame to Z-up: +90° about +X
/// (so +Y becomes +Z and +Z becomes −Y).
pub fn y_up_to_z_up() -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2)
}

/// The rotation angle (radians) of a unit quaternion, in [0, π].
pub fn rotation_angle(q: &UnitQuaternion<f64>) -> f64 {
    q.angle()
}

/// parry's pose of an isometry (the same rotation and translation; parry's own math types).
pub fn parry_pose(iso: &Isometry3<f64>) -> parry3d_f64::math::Pose {
    use parry3d_f64::math::{Pose, Rotation, Vector};
    let q = iso.rotation.quaternion();
    let t = iso.translation.vector;
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_similarity() {
        let s = Similarity {
            scale: 0.25,
            rotation: UnitQuaternion::from_euler_angles(0.3, -1.1, 2.0),
            translation: Vector3::new(1.0, -2.0, 0.5),
        };
        let back = Similarity::from_matrix(&s.matrix()).unwrap();
        assert!((back.scale - 0.25).abs() < 1e-12);
        assert!(back.rotation.angle_to(&s.rotation) < 1e-9);
        assert!((back.translation - s.translation).norm() < 1e-12);
    }

    #[test]
    fn rejects_non_similarities() {
        let mut shear = Matrix4::identity();
        shear[(0, 1)] = 0.3;
        assert!(Similarity::from_matrix(&shear)
            .unwrap_err()
            .contains("not a similarity"));
        let mirror = Matrix4::from_diagonal(&nalgebra::Vector4::new(-1.0, 1.0, 1.0, 1.0));
        assert!(Similarity::from_matrix(&mirror)
            .unwrap_err()
            .contains("mirror"));
        let zero = Matrix4::from_diagonal(&nalgebra::Vector4::new(0.0, 0.0, 0.0, 1.0));
        assert!(Similarity::from_matrix(&zero)
            .unwrap_err()
            .contains("singular"));
        let nonuni = Matrix4::from_diagonal(&nalgebra::Vector4::new(1.0, 2.0, 1.0, 1.0));
        assert!(Similarity::from_matrix(&nonuni).is_err());
        let mut nan = Matrix4::identity();
        nan[(2, 3)] = f64::NAN;
        assert!(Similarity::from_matrix(&nan).unwrap_err().contains("NaN"));
        let mut proj = Matrix4::identity();
        proj[(3, 0)] = 0.1;
        assert!(Similarity::from_matrix(&proj)
            .unwrap_err()
            .contains("last row"));
    }

    #[test]
    fn y_up_becomes_z_up() {
        let q = y_up_to_z_up();
        let y = q * Vector3::y();
        assert!((y - Vector3::z()).norm() < 1e-12);
        let z = q * Vector3::z();
        assert!((z + Vector3::y()).norm() < 1e-12);
    }

    #[test]
    fn composition_matches_matrix_product() {
        let a = Similarity::from_parts([1.0, 2.0, 3.0], [0.9, 0.1, -0.3, 0.2], 2.0).unwrap();
        let b = Similarity::from_parts([-1.0, 0.5, 0.0], [0.2, 0.7, 0.1, -0.4], 0.5).unwrap();
        let c = a.then_after(&b);
        assert!((c.matrix() - a.matrix() * b.matrix()).abs().max() < 1e-12);
    }
}
