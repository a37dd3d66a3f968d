//! glTF 2.0 binary (GLB) writer for [`VisualMesh`]: one node, one mesh, one primitive per part
//! (POSITION with min/max, NORMAL, TEXCOORD_0 when the part has UVs, u32 indices), one PBR
//! material per part (`baseColorFactor`, the texture embedded as a buffer-view image when there
//! is one). Output bytes are deterministic: the JSON keys are written in a fixed order and every
//! chunk and buffer view is padded to 4 bytes as the specification asks.

use crate::error::{Error, Result};
use crate::mesh::{VisualMesh, VisualPart, P3, V3};
use serde_json::{json, Map, Value};
use std::collections::HashMap;
use std::path::Path;

/// Optional content of the written file beyond the geometry.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GlbOptions {
    /// Name of the node and the mesh (default `"mesh"`).
    pub name: Option<String>,
    /// `asset.copyright`.
    pub copyright: Option<String>,
    /// `asset.extras` (any JSON value, e.g. provenance or normalisation records).
    pub extras: Option<Value>,
}

/// `mesh` as GLB bytes with default options. See [`to_glb_bytes_with`].
pub fn to_glb_bytes(mesh: &VisualMesh) -> Result<Vec<u8>> {
    to_glb_bytes_with(mesh, &GlbOptions::default())
}

/// Write `mesh` to `path` as GLB, atomically.
pub fn write_glb(mesh: &VisualMesh, path: &Path) -> Result<()> {
    write_glb_with(mesh, path, &GlbOptions::default())
}

/// Write `mesh` to `path` as GLB with `options`, atomically.
pub fn write_glb_with(mesh: &VisualMesh, path: &Path, options: &GlbOptions) -> Result<()> {
    let bytes = to_glb_bytes_with(mesh, options)
        .map_err(|e| Error::Internal(format!("cannot write {}: {e}", path.display())))?;
    crate::fsutil::write_atomically(path, &bytes)
}

/// The MIME type of encoded image bytes, from their signature.
pub fn image_mime_type(bytes: &[u8]) -> Option<&'static str> {
    if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        Some("image/png")
    } else if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        Some("image/jpeg")
    } else {
        None
    }
}

const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// The binary chunk under construction and its buffer views.
struct Bin {
    data: Vec<u8>,
    views: Vec<Value>,
}

impl Bin {
    fn push_view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while self.data.len() % 4 != 0 {
            self.data.push(0);
        }
        let mut view = Map::new();
        view.insert("buffer".into(), json!(0));
        view.insert("byteOffset".into(), json!(self.data.len()));
        view.insert("byteLength".into(), json!(bytes.len()));
        if let Some(t) = target {
            view.insert("target".into(), json!(t));
        }
        self.data.extend_from_slice(bytes);
        self.views.push(Value::Object(view));
        self.views.len() - 1
    }
}

/// Smooth vertex normals of a part: area-weighted face normals summed per vertex, then shared
/// between vertices at the same position (UV seams) whose own normals are within 45°, so seams
/// do not show while hard edges that were split stay hard.
fn part_normals(part: &VisualPart) -> Vec<V3> {
    let n = part.positions.len();
    let mut acc = vec![V3::zeros(); n];
    for t in &part.triangles {
        let [a, b, c] = t.map(|i| part.positions[i as usize]);
        let f = (b - a).cross(&(c - a)); // length = 2·area
        for &i in t {
            acc[i as usize] += f;
        }
    }
    let mut groups: HashMap<[u64; 3], Vec<usize>> = HashMap::new();
    for (i, p) in part.positions.iter().enumerate() {
        groups
            .entry([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
            .or_default()
            .push(i);
    }
    let cos45 = std::f64::consts::FRAC_1_SQRT_2;
    (0..n)
        .map(|i| {
            let p = part.positions[i];
            let group = &groups[&[p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]];
            let own = acc[i];
            let mut sum = own;
            if own.norm() > 0.0 {
                for &j in group {
                    if j != i
                        && acc[j].norm() > 0.0
                        && own.normalize().dot(&acc[j].normalize()) > cos45
                    {
                        sum += acc[j];
                    }
                }
            }
            let len = sum.norm();
            if len > 0.0 && len.is_finite() {
                sum / len
            } else {
                V3::z()
            }
        })
        .collect()
}

fn f32_bytes(values: impl Iterator<Item = f32>) -> Vec<u8> {
    values.flat_map(|v| v.to_le_bytes()).collect()
}

fn check_part(k: usize, part: &VisualPart) -> std::result::Result<(), String> {
    let n = part.positions.len();
    if n > u32::MAX as usize {
        return Err(format!("part {k}: too many vertices"));
    }
    let finite_f32 = |x: f64| x.is_finite() && x.abs() <= f32::MAX as f64;
    if let Some(p) = part
        .positions
        .iter()
        .find(|p: &&P3| !p.iter().all(|&x| finite_f32(x)))
    {
        return Err(format!(
            "part {k}: position {p:?} is not a finite 32-bit float"
        ));
    }
    if let Some(t) = part
        .triangles
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(format!(
            "part {k}: triangle {t:?} indexes past the {n} vertices"
        ));
    }
    if let Some(uv) = &part.uvs {
        if uv.len() != n {
            return Err(format!("part {k}: {} UVs for {n} positions", uv.len()));
        }
        if uv.iter().flatten().any(|&x| !finite_f32(x)) {
            return Err(format!("part {k}: a UV is not a finite 32-bit float"));
        }
    }
    if part.material.base_color.iter().any(|x| !x.is_finite()) {
        return Err(format!("part {k}: base colour is not finite"));
    }
    Ok(())
}

/// `mesh` as GLB bytes. Parts without triangles are skipped; a mesh with none left, a
/// non-finite coordinate, an index out of range, a UV count different from the position count
/// or a texture that is neither PNG nor JPEG is an error (`Error::Internal`: such a
/// [`VisualMesh`] should not have been built).
pub fn to_glb_bytes_with(mesh: &VisualMesh, options: &GlbOptions) -> Result<Vec<u8>> {
    build(mesh, options).map_err(Error::Internal)
}

fn build(mesh: &VisualMesh, options: &GlbOptions) -> std::result::Result<Vec<u8>, String> {
    let mut bin = Bin {
        data: Vec::new(),
        views: Vec::new(),
    };
    let mut accessors: Vec<Value> = Vec::new();
    let mut primitives: Vec<Value> = Vec::new();
    let mut materials: Vec<Value> = Vec::new();
    let mut textures: Vec<Value> = Vec::new();
    let mut images: Vec<Value> = Vec::new();
    // Encoded image bytes already embedded → texture index (identical textures shared).
    let mut embedded: Vec<(std::sync::Arc<Vec<u8>>, usize)> = Vec::new();

    for (k, part) in mesh.parts.iter().enumerate() {
        check_part(k, part)?;
        if part.triangles.is_empty() {
            continue;
        }
        // POSITION with min/max of the values as stored (f32).
        let pos32: Vec<[f32; 3]> = part
            .positions
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        let mut min = [f32::INFINITY; 3];
        let mut max = [f32::NEG_INFINITY; 3];
        for p in &pos32 {
            for i in 0..3 {
                min[i] = min[i].min(p[i]);
                max[i] = max[i].max(p[i]);
            }
        }
        let view = bin.push_view(
            &f32_bytes(pos32.iter().flatten().copied()),
            Some(ARRAY_BUFFER),
        );
        accessors.push(json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": pos32.len(),
            "type": "VEC3",
            "min": min.map(|x| x as f64),
            "max": max.map(|x| x as f64),
        }));
        let mut attributes = Map::new();
        attributes.insert("POSITION".into(), json!(accessors.len() - 1));

        let normals = part_normals(part);
        let view = bin.push_view(
            &f32_bytes(
                normals
                    .iter()
                    .flat_map(|n| [n.x as f32, n.y as f32, n.z as f32]),
            ),
            Some(ARRAY_BUFFER),
        );
        accessors.push(json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": normals.len(),
            "type": "VEC3",
        }));
        attributes.insert("NORMAL".into(), json!(accessors.len() - 1));

        if let Some(uvs) = &part.uvs {
            let view = bin.push_view(
                &f32_bytes(uvs.iter().flat_map(|uv| [uv[0] as f32, uv[1] as f32])),
                Some(ARRAY_BUFFER),
            );
            accessors.push(json!({
                "bufferView": view,
                "componentType": FLOAT,
                "count": uvs.len(),
                "type": "VEC2",
            }));
            attributes.insert("TEXCOORD_0".into(), json!(accessors.len() - 1));
        }

        let idx: Vec<u8> = part
            .triangles
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let view = bin.push_view(&idx, Some(ELEMENT_ARRAY_BUFFER));
        accessors.push(json!({
            "bufferView": view,
            "componentType": UNSIGNED_INT,
            "count": part.triangles.len() * 3,
            "type": "SCALAR",
        }));
        let indices = accessors.len() - 1;

        // Material.
        let m = &part.material;
        let mut pbr = Map::new();
        pbr.insert("baseColorFactor".into(), json!(m.base_color));
        if let Some(tex) = &m.texture {
            let texture_index = match embedded.iter().find(|(b, _)| **b == *tex.bytes) {
                Some(&(_, t)) => t,
                None => {
                    let mime = image_mime_type(&tex.bytes).ok_or_else(|| {
                        format!("part {k}: texture {} is neither PNG nor JPEG", tex.origin)
                    })?;
                    let view = bin.push_view(&tex.bytes, None);
                    images.push(json!({
                        "bufferView": view,
                        "mimeType": mime,
                        "name": format!("{}_baseColor", m.name),
                    }));
                    textures.push(json!({ "sampler": 0, "source": images.len() - 1 }));
                    embedded.push((tex.bytes.clone(), textures.len() - 1));
                    textures.len() - 1
                }
            };
            pbr.insert(
                "baseColorTexture".into(),
                json!({ "index": texture_index, "texCoord": 0 }),
            );
        }
        pbr.insert("metallicFactor".into(), json!(0.0));
        pbr.insert("roughnessFactor".into(), json!(0.9));
        let mut mat = Map::new();
        mat.insert("name".into(), json!(m.name));
        mat.insert("pbrMetallicRoughness".into(), Value::Object(pbr));
        if m.base_color[3] < 1.0 {
            mat.insert("alphaMode".into(), json!("BLEND"));
        }
        mat.insert("doubleSided".into(), json!(false));
        materials.push(Value::Object(mat));

        primitives.push(json!({
            "attributes": Value::Object(attributes),
            "indices": indices,
            "material": materials.len() - 1,
            "mode": 4,
        }));
    }
    if primitives.is_empty() {
        return Err("the mesh has no triangles".into());
    }
    while bin.data.len() % 4 != 0 {
        bin.data.push(0);
    }

    let name = options.name.clone().unwrap_or_else(|| "mesh".into());
    let mut asset = Map::new();
    asset.insert("version".into(), json!("2.0"));
    asset.insert("generator".into(), json!("interact3d"));
    if let Some(c) = &options.copyright {
        asset.insert("copyright".into(), json!(c));
    }
    if let Some(x) = &options.extras {
        asset.insert("extras".into(), x.clone());
    }
    let mut root = Map::new();
    root.insert("asset".into(), Value::Object(asset));
    root.insert("scene".into(), json!(0));
    root.insert("scenes".into(), json!([{ "nodes": [0] }]));
    root.insert("nodes".into(), json!([{ "mesh": 0, "name": name }]));
    root.insert(
        "meshes".into(),
        json!([{ "name": name, "primitives": primitives }]),
    );
    root.insert("materials".into(), json!(materials));
    if !textures.is_empty() {
        root.insert("textures".into(), json!(textures));
        root.insert(
            "samplers".into(),
            json!([{ "magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497 }]),
        );
        root.insert("images".into(), json!(images));
    }
    root.insert("accessors".into(), json!(accessors));
    root.insert("bufferViews".into(), json!(bin.views));
    root.insert("buffers".into(), json!([{ "byteLength": bin.data.len() }]));

    let mut json_bytes = serde_json::to_vec(&Value::Object(root)).map_err(|e| e.to_string())?;
    while json_bytes.len() % 4 != 0 {
        json_bytes.push(b' ');
    }
    let total = 12 + 8 + json_bytes.len() + 8 + bin.data.len();
    if total > u32::MAX as usize {
        return Err(format!("{total} bytes exceed the 4 GiB GLB limit"));
    }
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_bytes);
    out.extend_from_slice(&(bin.data.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin.data);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Material, Texture};
    use crate::shapes;
    use std::sync::Arc;

    fn sample() -> VisualMesh {
        let bowl = shapes::visual(
            &shapes::bowl(0.08, 0.05, 0.004, 16, 4),
            shapes::UvProjection::Cylindrical { repeat: 2.0 },
            shapes::textured_material(
                "bowl",
                shapes::checker_texture(32, 4, [200, 40, 40], [250, 250, 250], "checker"),
            ),
        );
        let mut box_part = shapes::visual(
            &shapes::cuboid(V3::new(0.1, 0.05, 0.02)),
            shapes::UvProjection::Box { tile: 0.1 },
            Material {
                name: "plain".into(),
                base_color: [0.2, 0.4, 0.6, 0.5],
                texture: None,
            },
        )
        .parts
        .remove(0);
        box_part.uvs = None;
        let mut m = bowl;
        m.parts.push(box_part);
        m
    }

    #[test]
    fn round_trip_through_gltf_crate() {
        let m = sample();
        let bytes = to_glb_bytes(&m).unwrap();
        assert_eq!(bytes.len() % 4, 0);
        assert_eq!(&bytes[0..4], b"glTF");
        let (doc, buffers, images) = gltf::import_slice(&bytes).unwrap();
        let gmesh = doc.meshes().next().unwrap();
        let prims: Vec<_> = gmesh.primitives().collect();
        assert_eq!(prims.len(), 2);
        for (part, prim) in m.parts.iter().zip(&prims) {
            let r = prim.reader(|b| Some(&buffers[b.index()]));
            let pos: Vec<[f32; 3]> = r.read_positions().unwrap().collect();
            assert_eq!(pos.len(), part.positions.len());
            for (a, b) in pos.iter().zip(&part.positions) {
                for i in 0..3 {
                    assert!((a[i] as f64 - b[i]).abs() < 1e-7);
                }
            }
            let idx: Vec<u32> = r.read_indices().unwrap().into_u32().collect();
            let want: Vec<u32> = part.triangles.iter().flatten().copied().collect();
            assert_eq!(idx, want);
            let normals: Vec<[f32; 3]> = r.read_normals().unwrap().collect();
            assert!(normals
                .iter()
                .all(|n| ((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() < 1e-5));
            match &part.uvs {
                Some(uvs) => {
                    let got: Vec<[f32; 2]> = r.read_tex_coords(0).unwrap().into_f32().collect();
                    for (a, b) in got.iter().zip(uvs) {
                        assert!((a[0] as f64 - b[0]).abs() < 1e-6);
                        assert!((a[1] as f64 - b[1]).abs() < 1e-6);
                    }
                }
                None => assert!(r.read_tex_coords(0).is_none()),
            }
            let mat = prim.material();
            assert_eq!(mat.name(), Some(part.material.name.as_str()));
            let f = mat.pbr_metallic_roughness().base_color_factor();
            for (got, want) in f.iter().zip(part.material.base_color) {
                assert!((*got as f64 - want).abs() < 1e-7);
            }
            let info = mat.pbr_metallic_roughness().base_color_texture();
            assert_eq!(info.is_some(), part.material.texture.is_some());
        }
        // Texture bytes embedded verbatim, and decodable.
        let glb = gltf::Gltf::from_slice(&bytes).unwrap();
        let blob = glb.blob.as_ref().unwrap();
        let img = glb.images().next().unwrap();
        match img.source() {
            gltf::image::Source::View { view, mime_type } => {
                assert_eq!(mime_type, "image/png");
                let got = &blob[view.offset()..view.offset() + view.length()];
                assert_eq!(
                    got,
                    m.parts[0]
                        .material
                        .texture
                        .as_ref()
                        .unwrap()
                        .bytes
                        .as_slice()
                );
            }
            _ => panic!("image not in a buffer view"),
        }
        assert_eq!(images.len(), 1);
        assert_eq!((images[0].width, images[0].height), (32, 32));
        // POSITION min/max present and right.
        let acc = prims[0].get(&gltf::Semantic::Positions).unwrap();
        let max = acc.max().unwrap();
        assert!((max[0].as_f64().unwrap() - 0.08).abs() < 1e-7);
    }

    #[test]
    fn deterministic_and_validated() {
        let m = sample();
        let opts = GlbOptions {
            name: Some("object_a".into()),
            copyright: Some("CC0".into()),
            extras: Some(json!({"z": 1, "a": [1, 2]})),
        };
        let a = to_glb_bytes_with(&m, &opts).unwrap();
        let b = to_glb_bytes_with(&m.clone(), &opts).unwrap();
        assert_eq!(a, b);
        let glb = gltf::Gltf::from_slice(&a).unwrap();
        let json = serde_json::to_value(glb.document.clone().into_json()).unwrap();
        assert_eq!(json["asset"]["generator"], "interact3d");
        assert_eq!(json["asset"]["version"], "2.0");
        assert_eq!(json["nodes"][0]["name"], "object_a");

        let mut bad = m.clone();
        bad.parts[0].positions[0].x = f64::NAN;
        assert!(to_glb_bytes(&bad)
            .unwrap_err()
            .to_string()
            .contains("finite"));
        let mut bad = m.clone();
        bad.parts[0].triangles[0][1] = 1_000_000;
        assert!(to_glb_bytes(&bad)
            .unwrap_err()
            .to_string()
            .contains("indexes past"));
        let mut bad = m.clone();
        bad.parts[0].material.texture = Some(Texture {
            origin: "x.gif".into(),
            bytes: Arc::new(b"GIF89a".to_vec()),
            width: 1,
            height: 1,
        });
        assert!(to_glb_bytes(&bad)
            .unwrap_err()
            .to_string()
            .contains("neither PNG"));
        assert!(to_glb_bytes(&VisualMesh::default()).is_err());
    }

    #[test]
    fn writes_atomically() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.glb");
        write_glb(&sample(), &path).unwrap();
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("a.glb")]);
        assert_eq!(
            std::fs::read(&path).unwrap(),
            to_glb_bytes(&sample()).unwrap()
        );
        let err = write_glb(&sample(), &dir.path().join("missing/a.glb")).unwrap_err();
        assert!(err.to_string().contains("missing"));
    }
}
