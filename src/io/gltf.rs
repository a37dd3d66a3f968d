//! glTF 2.0 reader (`.glb` and `.gltf` with embedded, external or `data:` buffers).
//!
//! All nodes of the default scene (or of every scene when none is marked default) are walked
//! with their transforms composed; every triangle primitive becomes a [`VisualPart`] with its
//! UVs and base-colour material. Buffer and image URIs are resolved by us, not by the `gltf`
//! crate, so that none can reach outside the scene folder.

use crate::error::{Error, Result};
use crate::io::{resolve_inside, texture, Limits};
use crate::mesh::{Material, Texture, VisualMesh, VisualPart, P3};
use base64::Engine;
use gltf::mesh::Mode;
use nalgebra::Matrix4;
use std::collections::BTreeMap;
use std::path::Path;

/// Extensions whose data we cannot decode: a file that requires one is refused by name.
const UNSUPPORTED_REQUIRED: &[(&str, &str)] = &[
    ("KHR_draco_mesh_compression", "Draco mesh compression"),
    ("EXT_meshopt_compression", "meshopt compression"),
    ("KHR_mesh_quantization", "quantized vertex attributes"),
    ("KHR_texture_basisu", "Basis Universal textures"),
    ("EXT_texture_webp", "WebP textures"),
];

/// Load a `.glb` or `.gltf` file.
pub fn load(path: &Path, limits: &Limits) -> Result<VisualMesh> {
    let bytes = crate::io::read_file(path, limits)?;
    load_bytes(
        path,
        &bytes,
        path.parent().unwrap_or(Path::new(".")),
        limits,
    )
}

/// Load glTF from bytes; `path` names the file in errors and is where relative URIs start from;
/// `root` is the folder no URI may leave.
pub fn load_bytes(path: &Path, bytes: &[u8], root: &Path, limits: &Limits) -> Result<VisualMesh> {
    let err = |m: String| Error::input(path, m);
    let is_glb_name = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    if bytes.starts_with(b"glTF") {
        check_glb_container(bytes).map_err(err)?;
    } else if is_glb_name {
        let head = &bytes[..bytes.len().min(4)];
        return Err(err(format!(
            "not a GLB file: it starts with {:?}, not the magic \"glTF\"",
            String::from_utf8_lossy(head)
        )));
    }
    // The JSON is checked for extensions before the gltf crate validates (it rejects Draco with
    // a less helpful message).
    let gltf = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| err(describe(e)))?;
    for ext in gltf.document.extensions_required() {
        if let Some((_, what)) = UNSUPPORTED_REQUIRED.iter().find(|(n, _)| *n == ext) {
            return Err(err(format!(
                "requires the glTF extension {ext} ({what}), which interact3d does not support; \
                 re-export the file without it"
            )));
        }
    }
    // gltf-json 1.4.1's validation indexes `accessors` with the POSITION index unchecked (found
    // by fuzzing: a POSITION of 5 with 4 accessors panicked): check it first.
    {
        let root = gltf.document.as_json();
        for (m, mesh) in root.meshes.iter().enumerate() {
            for (p, prim) in mesh.primitives.iter().enumerate() {
                for (semantic, index) in &prim.attributes {
                    if index.value() >= root.accessors.len() {
                        return Err(err(format!(
                            "mesh {m} primitive {p}: attribute {} refers to accessor {}, but there are {} accessors",
                            match semantic {
                                gltf::json::validation::Checked::Valid(s) => s.to_string(),
                                gltf::json::validation::Checked::Invalid => "(invalid)".into(),
                            },
                            index.value(),
                            root.accessors.len()
                        )));
                    }
                }
            }
        }
    }
    let gltf = gltf::Gltf::from_slice(bytes).map_err(|e| err(describe(e)))?;
    let doc = &gltf.document;
    // `gltf::Image::source` unwraps these (found by fuzzing: a misspelt mimeType panicked).
    for (k, image) in doc.as_json().images.iter().enumerate() {
        let why = match (&image.buffer_view, &image.uri, &image.mime_type) {
            (Some(_), None, None) => "is stored in a buffer view but has no mimeType",
            (Some(_), Some(_), _) => "has both a uri and a bufferView",
            (None, None, _) => "has neither a uri nor a bufferView",
            _ => continue,
        };
        return Err(err(format!("image {k} {why}")));
    }

    // Buffers.
    let mut blob = gltf.blob.clone();
    let mut buffers: Vec<Vec<u8>> = Vec::new();
    for buffer in doc.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                err("buffer refers to the GLB binary chunk, which is missing".into())
            })?,
            gltf::buffer::Source::Uri(uri) => read_uri(path, root, uri, limits)?,
        };
        if data.len() < buffer.length() {
            return Err(err(format!(
                "buffer {} is {} bytes, shorter than its declared length {}",
                buffer.index(),
                data.len(),
                buffer.length()
            )));
        }
        buffers.push(data);
    }
    // Every accessor must fit inside its buffer view and buffer before the reader touches it.
    for acc in doc.accessors() {
        check_accessor(&acc, &buffers)
            .map_err(|m| err(format!("accessor {}: {m}", acc.index())))?;
    }

    let scenes: Vec<_> = match doc.default_scene() {
        Some(s) => vec![s],
        None => doc.scenes().collect(),
    };
    // The node hierarchy must be a forest (glTF 2.0, 5.25): one parent at most, scene roots
    // without one. Checked up front, so the walk below visits each node once per scene and a
    // cycle is an error, not a million visits.
    let mut parent: Vec<Option<usize>> = vec![None; doc.nodes().len()];
    for n in doc.nodes() {
        for c in n.children() {
            if c.index() == n.index() || parent[c.index()].replace(n.index()).is_some() {
                return Err(err(format!(
                    "node {} has more than one parent or is its own child: the node hierarchy must be a tree",
                    c.index()
                )));
            }
        }
    }
    for scene in &scenes {
        for n in scene.nodes() {
            if let Some(p) = parent[n.index()] {
                return Err(err(format!(
                    "scene root node {} is also a child of node {p}: the node hierarchy must be a tree",
                    n.index()
                )));
            }
        }
    }
    let mut textures: BTreeMap<usize, Texture> = BTreeMap::new();
    let mut parts = Vec::new();
    let mut stack: Vec<(gltf::Node, Matrix4<f64>)> = Vec::new();
    for scene in &scenes {
        for node in scene.nodes() {
            stack.push((node, Matrix4::identity()));
        }
    }
    let mut visited = 0usize;
    // Triangles and vertices counted from the accessors before anything is read: a small file
    // that instances a mesh a million times cannot make us allocate gigabytes.
    let mut budget = Budget::default();
    while let Some((node, parent)) = stack.pop() {
        visited += 1;
        if visited > 1_000_000 {
            return Err(err("node hierarchy too deep or cyclic".into()));
        }
        let local = Matrix4::from_fn(|i, j| node.transform().matrix()[j][i] as f64);
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                if let Some(part) = read_primitive(
                    path,
                    root,
                    &prim,
                    &buffers,
                    &world,
                    &mut textures,
                    &mut budget,
                    limits,
                )? {
                    parts.push(part);
                }
            }
        }
        for child in node.children() {
            stack.push((child, world));
        }
    }
    Ok(VisualMesh { parts })
}

/// Check the GLB header and chunk table before the `gltf` crate reads them (it subtracts
/// without checking and its messages are terse): version 2, declared length within the file,
/// a JSON chunk first, every chunk inside the declared length.
fn check_glb_container(bytes: &[u8]) -> std::result::Result<(), String> {
    let n = bytes.len() as u64;
    if n < 12 {
        return Err(format!(
            "truncated GLB: {n} bytes, shorter than the 12-byte header"
        ));
    }
    let u32_at = |o: u64| -> u64 {
        let o = o as usize;
        u32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]) as u64
    };
    let version = u32_at(4);
    if version != 2 {
        return Err(format!(
            "unsupported GLB version {version} (only glTF 2.0 is read)"
        ));
    }
    let length = u32_at(8);
    if length > n {
        return Err(format!(
            "truncated GLB: the header declares {length} bytes but the file has {n}"
        ));
    }
    if length < 20 {
        return Err(format!(
            "corrupt GLB: the header declares {length} bytes, too few for a JSON chunk"
        ));
    }
    let mut offset = 12u64;
    let mut k = 0;
    while offset < length {
        if offset + 8 > length {
            return Err(format!(
                "corrupt GLB: chunk {k} header at byte {offset} runs past the declared length {length}"
            ));
        }
        let chunk_len = u32_at(offset);
        let ty = &bytes[offset as usize + 4..offset as usize + 8];
        let name = match ty {
            b"JSON" => "JSON",
            b"BIN\0" => "BIN",
            _ => "unknown",
        };
        if k == 0 && name != "JSON" {
            return Err("corrupt GLB: the first chunk is not the JSON chunk".into());
        }
        if k == 1 && name != "BIN" {
            return Err(format!(
                "corrupt GLB: the second chunk has type {:?}, not BIN",
                String::from_utf8_lossy(ty)
            ));
        }
        let left = length - offset - 8;
        if chunk_len > left {
            return Err(format!(
                "corrupt GLB: chunk {k} ({name}) declares {chunk_len} bytes but only {left} remain (truncated or corrupt)"
            ));
        }
        offset += 8 + chunk_len;
        k += 1;
    }
    Ok(())
}

/// Triangles and vertices taken so far, over all primitive instances.
#[derive(Default)]
struct Budget {
    triangles: usize,
    vertices: usize,
}

fn describe(e: gltf::Error) -> String {
    match e {
        gltf::Error::Validation(v) => {
            let list: Vec<String> = v.iter().take(3).map(|(p, e)| format!("{p}: {e}")).collect();
            format!("invalid glTF: {}", list.join("; "))
        }
        gltf::Error::Binary(b) => format!("corrupt GLB container: {b:?}"),
        gltf::Error::Deserialize(d) => format!("corrupt glTF JSON: {d}"),
        other => format!("cannot read glTF: {other}"),
    }
}

fn read_uri(path: &Path, root: &Path, uri: &str, limits: &Limits) -> Result<Vec<u8>> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest
            .split_once(";base64,")
            .ok_or_else(|| Error::input(path, "data: URI is not base64-encoded"))?;
        if data.len() as u64 / 4 * 3 > limits.max_file_bytes {
            return Err(Error::input(
                path,
                "data: URI is over the file size limit (--max-file-bytes)",
            ));
        }
        return base64::engine::general_purpose::STANDARD
            .decode(data.trim())
            .map_err(|e| Error::input(path, format!("data: URI is not valid base64: {e}")));
    }
    let decoded = percent_decode(uri);
    let file = resolve_inside(root, path, &decoded)?;
    crate::io::read_file(&file, limits)
}

fn percent_decode(s: &str) -> String {
    // On bytes: a `%` followed by anything but two hex digits is kept as it is (slicing the
    // `str` there could split a multi-byte character).
    let b = s.as_bytes();
    let hex = |c: u8| (c as char).to_digit(16).map(|d| d as u8);
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push(h * 16 + l);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn check_accessor(acc: &gltf::Accessor, buffers: &[Vec<u8>]) -> std::result::Result<(), String> {
    if acc.count() == 0 {
        return Err("count is 0 (glTF requires at least 1)".into());
    }
    if acc.sparse().is_some() {
        return Err("sparse accessors are not supported".into());
    }
    let Some(view) = acc.view() else {
        return Ok(());
    };
    let buf_len = buffers
        .get(view.buffer().index())
        .map(|b| b.len())
        .ok_or("buffer index out of range")?;
    let view_end = view
        .offset()
        .checked_add(view.length())
        .ok_or("view size overflows")?;
    if view_end > buf_len {
        return Err(format!(
            "buffer view {} runs past the end of its buffer ({view_end} > {buf_len})",
            view.index()
        ));
    }
    let elem = acc.size();
    let stride = view.stride().unwrap_or(elem);
    if stride < elem {
        return Err(format!(
            "buffer view {} has byteStride {stride}, smaller than one {elem}-byte element",
            view.index()
        ));
    }
    if acc.count() > 0 {
        let need = acc
            .offset()
            .checked_add(
                (acc.count() - 1)
                    .checked_mul(stride)
                    .ok_or("count overflows")?,
            )
            .and_then(|x| x.checked_add(elem))
            .ok_or("size overflows")?;
        if need > view.length() {
            return Err(format!(
                "{} elements need {need} bytes, more than its buffer view's {}",
                acc.count(),
                view.length()
            ));
        }
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn read_primitive(
    path: &Path,
    root: &Path,
    prim: &gltf::Primitive,
    buffers: &[Vec<u8>],
    world: &Matrix4<f64>,
    textures: &mut BTreeMap<usize, Texture>,
    budget: &mut Budget,
    limits: &Limits,
) -> Result<Option<VisualPart>> {
    let err = |m: String| Error::input(path, m);
    let mode = prim.mode();
    if !matches!(
        mode,
        Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
    ) {
        return Ok(None); // points and lines carry no surface
    }
    // The gltf crate's readers assume these layouts (and panic or misread otherwise).
    use gltf::accessor::{DataType, Dimensions};
    let kind = |acc: &gltf::Accessor, what: &str, dims: Dimensions, types: &[DataType]| {
        if acc.dimensions() == dims && types.contains(&acc.data_type()) {
            Ok(())
        } else {
            Err(err(format!(
                "accessor {} ({what}) is {:?} {:?}; glTF requires {dims:?} of {types:?}",
                acc.index(),
                acc.dimensions(),
                acc.data_type()
            )))
        }
    };
    let Some(pos) = prim.get(&gltf::Semantic::Positions) else {
        return Err(err("primitive has no POSITION attribute".into()));
    };
    kind(&pos, "POSITION", Dimensions::Vec3, &[DataType::F32])?;
    if let Some(ix) = prim.indices() {
        kind(
            &ix,
            "indices",
            Dimensions::Scalar,
            &[DataType::U8, DataType::U16, DataType::U32],
        )?;
    }
    if let Some(info) = prim
        .material()
        .pbr_metallic_roughness()
        .base_color_texture()
    {
        if let Some(tc) = prim.get(&gltf::Semantic::TexCoords(info.tex_coord())) {
            kind(
                &tc,
                "TEXCOORD",
                Dimensions::Vec2,
                &[DataType::F32, DataType::U8, DataType::U16],
            )?;
        }
    }
    let vertex_count = pos.count();
    let index_count = prim.indices().map(|a| a.count()).unwrap_or(vertex_count);
    let tris = match mode {
        Mode::Triangles => index_count / 3,
        _ => index_count.saturating_sub(2),
    };
    budget.triangles = budget.triangles.saturating_add(tris);
    budget.vertices = budget.vertices.saturating_add(vertex_count);
    if budget.triangles > limits.max_triangles
        || budget.vertices > limits.max_triangles.saturating_mul(3)
    {
        return Err(err(format!(
            "mesh has more than {} triangles (or 3x as many vertices), over the limit (--max-triangles)",
            limits.max_triangles
        )));
    }
    let reader = prim.reader(|b| buffers.get(b.index()).map(|d| d.as_slice()));
    let positions: Vec<P3> = reader
        .read_positions()
        .ok_or_else(|| err("primitive has no POSITION attribute".into()))?
        .map(|p| world.transform_point(&P3::new(p[0] as f64, p[1] as f64, p[2] as f64)))
        .collect();
    let n = positions.len() as u32;
    let flat: Vec<u32> = match reader.read_indices() {
        Some(ix) => ix.into_u32().collect(),
        None => (0..n).collect(),
    };
    if let Some(bad) = flat.iter().find(|&&i| i >= n) {
        return Err(err(format!("index {bad} past the vertex count {n}")));
    }
    let mut triangles: Vec<[u32; 3]> = match mode {
        Mode::Triangles => flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        Mode::TriangleStrip => (2..flat.len())
            .map(|i| {
                if i % 2 == 0 {
                    [flat[i - 2], flat[i - 1], flat[i]]
                } else {
                    [flat[i - 1], flat[i - 2], flat[i]]
                }
            })
            .collect(),
        _ => (2..flat.len())
            .map(|i| [flat[0], flat[i - 1], flat[i]])
            .collect(),
    };
    if world.fixed_view::<3, 3>(0, 0).determinant() < 0.0 {
        for t in &mut triangles {
            t.swap(1, 2);
        }
    }
    let mat = prim.material();
    let pbr = mat.pbr_metallic_roughness();
    let f = pbr.base_color_factor();
    let mut material = Material {
        name: mat
            .name()
            .map(str::to_string)
            .unwrap_or_else(|| match mat.index() {
                Some(i) => format!("material_{i}"),
                None => "default".into(),
            }),
        base_color: [f[0] as f64, f[1] as f64, f[2] as f64, f[3] as f64],
        texture: None,
    };
    let mut uvs = None;
    if let Some(info) = pbr.base_color_texture() {
        let set = info.tex_coord();
        if let Some(tc) = reader.read_tex_coords(set) {
            let mut uv: Vec<[f64; 2]> = tc.into_f32().map(|t| [t[0] as f64, t[1] as f64]).collect();
            if uv.len() != positions.len() {
                return Err(err("TEXCOORD count does not match POSITION count".into()));
            }
            if let Some(tt) = info.texture_transform() {
                apply_texture_transform(&mut uv, tt.offset(), tt.rotation(), tt.scale());
            }
            let image = info.texture().source();
            let tex = match textures.get(&image.index()) {
                Some(t) => t.clone(),
                None => {
                    let t = read_image(path, root, &image, buffers, limits)?;
                    textures.insert(image.index(), t.clone());
                    t
                }
            };
            material.texture = Some(tex);
            uvs = Some(uv);
        }
    }
    Ok(Some(VisualPart {
        positions,
        uvs,
        triangles,
        material,
    }))
}

fn apply_texture_transform(uv: &mut [[f64; 2]], offset: [f32; 2], rotation: f32, scale: [f32; 2]) {
    let (s, c) = (rotation as f64).sin_cos();
    for t in uv.iter_mut() {
        let (u, v) = (t[0] * scale[0] as f64, t[1] * scale[1] as f64);
        *t = [
            c * u + s * v + offset[0] as f64,
            -s * u + c * v + offset[1] as f64,
        ];
    }
}

fn read_image(
    path: &Path,
    root: &Path,
    image: &gltf::Image,
    buffers: &[Vec<u8>],
    limits: &Limits,
) -> Result<Texture> {
    let origin = format!("{}#image{}", path.display(), image.index());
    let bytes = match image.source() {
        gltf::image::Source::View { view, .. } => {
            let buf = buffers
                .get(view.buffer().index())
                .ok_or_else(|| Error::input(&origin, "image refers to a missing buffer"))?;
            let end = view.offset().saturating_add(view.length());
            if end > buf.len() {
                return Err(Error::input(
                    &origin,
                    "image buffer view runs past the end of its buffer",
                ));
            }
            buf[view.offset()..end].to_vec()
        }
        gltf::image::Source::Uri { uri, .. } => read_uri(path, root, uri, limits)?,
    };
    texture::from_bytes(&origin, bytes, limits)
}
