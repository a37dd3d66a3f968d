//! The scene model: an object (mesh, textured visual, pose), contacts a scene is built around, small pose and JSON helpers.

use super::*;

/// One object: its mesh in its own frame (Z-up, metres), the textured visual of the same mesh,
/// and its pose in the Z-up world (scale 1).
pub(crate) struct Obj {
    pub(crate) key: String,
    pub(crate) label: String,
    pub(crate) description: String,
    pub(crate) mesh: Mesh,
    pub(crate) visual: VisualMesh,
    pub(crate) pose: Similarity,
}

impl Obj {
    pub(crate) fn new(
        key: &str,
        label: &str,
        description: String,
        mesh: Mesh,
        proj: UvProjection,
        texture: interact3d::mesh::Texture,
        pose: Similarity,
    ) -> Obj {
        let visual = shapes::visual(&mesh, proj, shapes::textured_material(label, texture));
        Obj {
            key: key.into(),
            label: label.into(),
            description,
            mesh,
            visual,
            pose,
        }
    }
    pub(crate) fn world_z(&self) -> Mesh {
        self.mesh.transformed(&self.pose.matrix())
    }
}

pub(crate) fn pose(t: V3, q: UnitQuaternion<f64>) -> Similarity {
    Similarity {
        scale: 1.0,
        rotation: q,
        translation: t,
    }
}

pub(crate) fn yaw(deg: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), deg.to_radians())
}

/// Rotation taking the Z-up frame to the Y-up frame: (x, y, z) ↦ (x, z, −y).
pub(crate) fn z_to_y() -> Matrix3<f64> {
    Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0)
}

pub(crate) fn r6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

pub(crate) fn mm(x: f64) -> String {
    format!("{:.3}", x * 1000.0)
}

pub(crate) fn rows3(m: &Matrix3<f64>) -> Value {
    json!((0..3)
        .map(|i| (0..3).map(|j| m[(i, j)]).collect::<Vec<_>>())
        .collect::<Vec<_>>())
}

pub(crate) fn rows4(m: &Matrix4<f64>) -> Value {
    json!((0..4)
        .map(|i| (0..4).map(|j| m[(i, j)]).collect::<Vec<_>>())
        .collect::<Vec<_>>())
}

pub(crate) fn write_text(path: &Path, text: &str) {
    write_atomic(path, text.as_bytes()).unwrap_or_else(|e| panic!("{e}"));
}

pub(crate) fn write_json(path: &Path, v: &Value) {
    let mut s = serde_json::to_string_pretty(v).unwrap();
    s.push('\n');
    write_text(path, &s);
}

/// A contact the scene is built around: objects `a` and `b` (indices), the triangles of `b`
/// that make it (a filter on the Y-up world triangle), and what it is.
pub(crate) struct Contact {
    pub(crate) a: usize,
    pub(crate) b: usize,
    pub(crate) what: &'static str,
    pub(crate) filter: TriFilter,
}

pub(crate) type TriFilter = Box<dyn Fn(&[P3; 3]) -> bool>;

/// A triangle filter on Y-up world triangles that tests each vertex in the own (Z-up) frame of
/// the object posed by `pose_z` in the Z-up world.
pub(crate) fn local_filter(pose_z: &Similarity, f: impl Fn(&P3) -> bool + 'static) -> TriFilter {
    let mut a4 = Matrix4::identity();
    a4.fixed_view_mut::<3, 3>(0, 0).copy_from(&z_to_y());
    let inv = (a4 * pose_z.matrix()).try_inverse().unwrap();
    Box::new(move |t: &[P3; 3]| t.iter().all(|p| f(&inv.transform_point(p))))
}

/// What a written scene measured.
pub(crate) struct Measured {
    /// Per pair (i, j): exact minimum distance between the world meshes as written.
    pub(crate) pairs: Vec<(usize, usize, f64)>,
    /// Per designed contact: exact gap.
    pub(crate) contacts: Vec<(String, f64)>,
}
