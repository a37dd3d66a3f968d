//! The mesh model every stage shares.
//!
//! * [`Mesh`]: welded triangle geometry in `f64` (positions + triangles). All geometry
//!   (decomposition, inertia, metrics, physics) works on it.
//! * [`VisualMesh`]: what is rendered: parts with UVs and a material each, kept apart so textures
//!   survive the round trip to OBJ/MTL.

use nalgebra::{Matrix4, Point3, Vector3};
use std::collections::HashMap;
use std::sync::Arc;

/// A point in 3D, `f64`.
pub type P3 = Point3<f64>;
/// A vector in 3D, `f64`.
pub type V3 = Vector3<f64>;

/// Axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: P3,
    pub max: P3,
}

impl Aabb {
    /// The box of a set of points; `None` when there are none.
    pub fn of_points<'a>(points: impl IntoIterator<Item = &'a P3>) -> Option<Aabb> {
        let mut it = points.into_iter();
        let first = *it.next()?;
        let mut b = Aabb {
            min: first,
            max: first,
        };
        for p in it {
            b.include(p);
        }
        Some(b)
    }
    /// Grow to contain `p`.
    pub fn include(&mut self, p: &P3) {
        self.min = self.min.inf(p);
        self.max = self.max.sup(p);
    }
    /// Smallest box containing both.
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb {
            min: self.min.inf(&o.min),
            max: self.max.sup(&o.max),
        }
    }
    /// Extents along x, y, z.
    pub fn extents(&self) -> V3 {
        self.max - self.min
    }
    /// Length of the diagonal.
    pub fn diagonal(&self) -> f64 {
        self.extents().norm()
    }
    /// Centre of the box.
    pub fn center(&self) -> P3 {
        nalgebra::center(&self.min, &self.max)
    }
    /// Whether the two boxes overlap (touching counts), after growing `self` by `margin`.
    pub fn intersects(&self, o: &Aabb, margin: f64) -> bool {
        (0..3).all(|i| self.min[i] - margin <= o.max[i] && o.min[i] <= self.max[i] + margin)
    }
}

/// Welded triangle geometry. Triangles are counter-clockwise seen from outside for closed meshes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub vertices: Vec<P3>,
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    pub fn new(vertices: Vec<P3>, triangles: Vec<[u32; 3]>) -> Self {
        Mesh {
            vertices,
            triangles,
        }
    }

    /// Bounding box; `None` for an empty mesh.
    pub fn aabb(&self) -> Option<Aabb> {
        Aabb::of_points(&self.vertices)
    }

    /// The three corners of triangle `i`.
    pub fn triangle(&self, i: usize) -> [P3; 3] {
        let t = self.triangles[i];
        [
            self.vertices[t[0] as usize],
            self.vertices[t[1] as usize],
            self.vertices[t[2] as usize],
        ]
    }

    /// Total surface area.
    pub fn area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|i| triangle_area(&self.triangle(i)))
            .sum()
    }

    /// Signed enclosed volume (divergence theorem); positive for outward-facing closed meshes.
    pub fn signed_volume(&self) -> f64 {
        (0..self.triangles.len())
            .map(|i| {
                let [a, b, c] = self.triangle(i);
                a.coords.dot(&b.coords.cross(&c.coords)) / 6.0
            })
            .sum()
    }

    /// Closed (watertight and consistently oriented): every directed edge appears once and its
    /// reverse appears once, i.e. no [`Mesh::edge_defects`].
    pub fn is_closed(&self) -> bool {
        !self.triangles.is_empty() && self.edge_defects() == (0, 0)
    }

    /// Whether every edge is run as often one way as the other: the surface is closed and
    /// consistently oriented, though more than two triangles may meet on an edge, as in scans
    /// (the YCB bowl, mug and soup can, the GSO teapot: a few such edges each). Such a surface
    /// bounds a solid, and the divergence theorem gives its volume and inertia exactly.
    /// Stricter [`Mesh::is_closed`] also wants each directed edge used once.
    pub fn bounds_solid(&self) -> bool {
        if self.triangles.is_empty() {
            return false;
        }
        let edges = self.directed_edges();
        let count =
            |e: (u32, u32)| edges.partition_point(|&x| x <= e) - edges.partition_point(|&x| x < e);
        edges
            .chunk_by(|a, b| a == b)
            .all(|run| run[0].0 != run[0].1 && count((run[0].1, run[0].0)) == run.len())
    }

    /// Edge defects, as `(doubled, open)`: directed edges used by more than one triangle (0
    /// when the mesh is consistently oriented: two triangles sharing an edge run it in
    /// opposite directions) and directed edges that no triangle runs the other way (0 when
    /// every edge is shared: no hole). Scans have a few doubled edges where more than two
    /// triangles meet on an edge (YCB mug: 6 of 49,128 directed edges, none open).
    pub fn edge_defects(&self) -> (usize, usize) {
        let edges = self.directed_edges();
        let doubled = edges.windows(2).filter(|w| w[0] == w[1]).count();
        let open = edges
            .iter()
            .filter(|&&(a, b)| edges.binary_search(&(b, a)).is_err())
            .count();
        (doubled, open)
    }

    /// Every triangle's three directed edges `(from, to)`, sorted.
    fn directed_edges(&self) -> Vec<(u32, u32)> {
        let mut edges: Vec<(u32, u32)> = self
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
            .collect();
        edges.sort_unstable();
        edges
    }

    /// Apply a 4x4 affine transform to every vertex. A transform with negative determinant
    /// flips the triangle winding back so outward normals stay outward.
    pub fn transformed(&self, m: &Matrix4<f64>) -> Mesh {
        let vertices = self.vertices.iter().map(|p| m.transform_point(p)).collect();
        let flip = m.fixed_view::<3, 3>(0, 0).determinant() < 0.0;
        let triangles = if flip {
            self.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect()
        } else {
            self.triangles.clone()
        };
        Mesh {
            vertices,
            triangles,
        }
    }

    /// Append another mesh (indices shifted).
    pub fn append(&mut self, other: &Mesh) {
        let off = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| [t[0] + off, t[1] + off, t[2] + off]),
        );
    }

    /// Merge vertices whose positions are equal to within `tolerance` (a grid of that size;
    /// 0 merges only bit-identical positions) and drop triangles that become degenerate.
    /// Deterministic: the first occurrence of a position keeps its place.
    pub fn welded(&self, tolerance: f64) -> Mesh {
        let key = |p: &P3| -> [i64; 3] {
            if tolerance > 0.0 {
                [
                    (p.x / tolerance).round() as i64,
                    (p.y / tolerance).round() as i64,
                    (p.z / tolerance).round() as i64,
                ]
            } else {
                [
                    p.x.to_bits() as i64,
                    p.y.to_bits() as i64,
                    p.z.to_bits() as i64,
                ]
            }
        };
        let mut map: HashMap<[i64; 3], u32> = HashMap::with_capacity(self.vertices.len());
        let mut vertices = Vec::new();
        let remap: Vec<u32> = self
            .vertices
            .iter()
            .map(|p| {
                *map.entry(key(p)).or_insert_with(|| {
                    vertices.push(*p);
                    (vertices.len() - 1) as u32
                })
            })
            .collect();
        let triangles = self
            .triangles
            .iter()
            .map(|t| {
                [
                    remap[t[0] as usize],
                    remap[t[1] as usize],
                    remap[t[2] as usize],
                ]
            })
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
            .collect();
        Mesh {
            vertices,
            triangles,
        }
    }

    /// Vertices and triangles in parry's types (`glam::DVec3`).
    pub fn to_parry(&self) -> (Vec<parry3d_f64::math::Vector>, Vec<[u32; 3]>) {
        (
            self.vertices.iter().map(to_dvec).collect(),
            self.triangles.clone(),
        )
    }
}

/// Area of a triangle.
pub fn triangle_area(t: &[P3; 3]) -> f64 {
    0.5 * (t[1] - t[0]).cross(&(t[2] - t[0])).norm()
}

/// nalgebra point to parry's vector type.
pub fn to_dvec(p: &P3) -> parry3d_f64::math::Vector {
    parry3d_f64::math::Vector::new(p.x, p.y, p.z)
}

/// parry's vector type to a nalgebra point.
pub fn from_dvec(v: parry3d_f64::math::Vector) -> P3 {
    P3::new(v.x, v.y, v.z)
}

/// Encoded image data of a texture, kept as read (PNG or JPEG), decoded only when written.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Where it came from (a file path, or `file.glb#image3`), for error messages.
    pub origin: String,
    /// The encoded bytes.
    pub bytes: Arc<Vec<u8>>,
    /// Pixel size, read from the header at load time.
    pub width: u32,
    pub height: u32,
}

/// A material: base colour factor (linear RGBA) and an optional base-colour texture.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    pub base_color: [f64; 4],
    pub texture: Option<Texture>,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            name: "default".into(),
            base_color: [0.8, 0.8, 0.8, 1.0],
            texture: None,
        }
    }
}

/// One part of a visual mesh: a triangle list with its own vertices, optional UVs and a material.
#[derive(Clone, Debug, PartialEq)]
pub struct VisualPart {
    pub positions: Vec<P3>,
    /// One UV per position when present (glTF convention: v grows downwards).
    pub uvs: Option<Vec<[f64; 2]>>,
    pub triangles: Vec<[u32; 3]>,
    pub material: Material,
}

/// A renderable mesh: one or more parts with materials.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VisualMesh {
    pub parts: Vec<VisualPart>,
}

impl VisualMesh {
    /// The geometry of all parts together, vertices welded exactly (UV seams joined).
    pub fn geometry(&self) -> Mesh {
        let mut m = Mesh::default();
        for p in &self.parts {
            m.append(&Mesh::new(p.positions.clone(), p.triangles.clone()));
        }
        m.welded(0.0)
    }

    /// Total surface area of all parts (triangles summed in order, parts in order).
    pub fn area(&self) -> f64 {
        self.parts
            .iter()
            .flat_map(|p| {
                p.triangles
                    .iter()
                    .map(|t| triangle_area(&t.map(|k| p.positions[k as usize])))
            })
            .sum()
    }

    /// Number of triangles over all parts.
    pub fn triangle_count(&self) -> usize {
        self.parts.iter().map(|p| p.triangles.len()).sum()
    }

    /// Apply an affine transform to every position (winding flipped for mirroring transforms).
    pub fn transform(&mut self, m: &Matrix4<f64>) {
        let flip = m.fixed_view::<3, 3>(0, 0).determinant() < 0.0;
        for p in &mut self.parts {
            for v in &mut p.positions {
                *v = m.transform_point(v);
            }
            if flip {
                for t in &mut p.triangles {
                    t.swap(1, 2);
                }
            }
        }
    }
}
