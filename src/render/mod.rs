//! Pictures of a scene, on the CPU, with no GPU and no display; the same input gives the same
//! PNG bytes.
//!
//! For an [`Assembly`] at its composed pose (world frame: metres, Z up, front facing −Y):
//! * `views/<view>.png`: the textured scene from the six [`camera::VIEWS`], flat-shaded, on a
//!   checkered floor, supersampled;
//! * `hulls/<view>.png`: the same views of the collision hulls, one colour per object, drawn
//!   translucent with each hull outlined over the visual meshes in grey;
//! * `sections/<a>__<b>__<x|y|z>.png`: for each pair of objects whose hulls come near, three
//!   axis-aligned planes through their deepest overlap or closest approach
//!   ([`section::contacts`]); each object's interior in its colour, any point inside two
//!   objects bright red ([`OVERLAP`]);
//! * `index.html`: all of it on one page with the metrics and findings ([`page`]);
//! * `views.json`: every image's camera (intrinsics, extrinsics) or plane (pixel ↔ world map),
//!   and the colour legend.
//!
//! Entry points: [`render`] (images in memory), [`write`] (into a folder), [`render_to_dir`]
//! (a whole output folder, atomically), [`colour_of`] (the object palette).
//! Modules: [`camera`] (pinhole model), [`raster`] (z-buffer rasteriser), [`section`].

pub mod camera;
pub mod page;
pub mod raster;
pub mod section;

use crate::body::Assembly;
use crate::error::{Error, Result};
use crate::mesh::{Aabb, P3};
use camera::{Camera, CameraRecord, VIEWS};
use raster::{Frame, RMaterial, RenderMesh};
use section::Plane;
use serde::Serialize;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// Colour of a point inside two or more objects in a section.
pub const OVERLAP: [u8; 3] = [255, 0, 0];
/// Colour of a section pixel inside no object.
pub const SECTION_EMPTY: [u8; 3] = [255, 255, 255];
/// Grey of the visual meshes under the hulls.
const HULL_UNDERLAY: [f32; 3] = [0.78, 0.78, 0.78];

/// Object colours (Tableau 10 without its red, which means overlap).
const PALETTE: [[u8; 3]; 9] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];

/// The colour of object `i` in hull views and sections.
pub fn colour_of(i: usize) -> [u8; 3] {
    PALETTE[i % PALETTE.len()]
}

/// What to draw.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Width and height of the views (pixels).
    pub size: u32,
    /// Samples per pixel along each axis (2: four samples per pixel).
    pub supersample: u32,
    /// Width and height of the cross-sections (pixels).
    pub section_size: u32,
    /// Objects whose hull boxes are farther apart than this fraction of the smaller object's
    /// diagonal get no section.
    pub section_margin: f64,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            size: 512,
            supersample: 2,
            section_size: 512,
            section_margin: 0.1,
        }
    }
}

/// One picture.
pub struct Picture {
    /// Path relative to the output folder (`views/front.png`).
    pub file: String,
    pub image: image::RgbImage,
    pub record: ImageRecord,
}

/// An image as `views.json` describes it.
#[derive(Clone, Debug, Serialize)]
pub struct ImageRecord {
    pub file: String,
    /// `view`, `hulls` or `section`.
    pub kind: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub view: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera: Option<CameraRecord>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub section: Option<SectionRecord>,
}

/// A cross-section's plane and pair.
#[derive(Clone, Debug, Serialize)]
pub struct SectionRecord {
    /// The two objects the plane passes between.
    pub pair: [String; 2],
    /// Penetration depth (> 0) or gap (< 0) of their hulls at the section centre (m).
    pub hull_depth_m: f64,
    /// `x`, `y` or `z`: the plane is `world[normal] = center[normal]`.
    pub normal: &'static str,
    pub center: [f64; 3],
    /// World axis (`x`, `y`, `z`) pointing right and up in the image.
    pub right: &'static str,
    pub up: &'static str,
    pub pixel_size_m: f64,
    /// world[right] = center[right] + (col + 0.5 − width/2)·pixel;
    /// world[up] = center[up] − (row + 0.5 − height/2)·pixel.
    pub pixel_to_world: &'static str,
}

/// The whole `views.json`.
#[derive(Clone, Debug, Serialize)]
pub struct ViewsJson {
    pub tool: &'static str,
    pub version: &'static str,
    pub scene: String,
    pub conventions: Conventions,
    pub legend: Legend,
    pub images: Vec<ImageRecord>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Conventions {
    pub world: &'static str,
    pub camera: &'static str,
    pub pixel: &'static str,
    pub floor_z_m: f64,
    pub floor_cell_m: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Legend {
    pub objects: Vec<LegendObject>,
    pub overlap: [u8; 3],
    pub section_empty: [u8; 3],
    pub background: [u8; 3],
    pub views: &'static str,
    pub hulls: &'static str,
    pub sections: &'static str,
}

#[derive(Clone, Debug, Serialize)]
pub struct LegendObject {
    pub name: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
    pub colour: [u8; 3],
}

/// All pictures of a scene and their description.
pub struct Renders {
    pub pictures: Vec<Picture>,
    pub views: ViewsJson,
    /// Seconds spent per stage (`meshes`, `views`, `hulls`, `sections`), for benchmarks; not
    /// written anywhere.
    pub timings: Vec<(&'static str, f64)>,
}

fn decode(tex: &crate::mesh::Texture) -> Result<Arc<image::RgbaImage>> {
    let img = image::load_from_memory(&tex.bytes)
        .map_err(|e| Error::input(&tex.origin, format!("corrupt texture image: {e}")))?;
    Ok(Arc::new(img.to_rgba8()))
}

/// The visual meshes at the composed pose (tag = object index + 1), and the hulls (tag = hull
/// number + 1) with the object of each hull tag.
fn meshes(a: &Assembly) -> Result<(RenderMesh, RenderMesh, Vec<usize>)> {
    let mut vis = RenderMesh::default();
    let mut textures: HashMap<*const Vec<u8>, Arc<image::RgbaImage>> = HashMap::new();
    for (i, b) in a.bodies.iter().enumerate() {
        let m = b.composed_pose.to_homogeneous();
        for part in &b.visual.parts {
            let texture = match &part.material.texture {
                Some(t) => Some(match textures.get(&Arc::as_ptr(&t.bytes)) {
                    Some(img) => img.clone(),
                    None => {
                        let img = decode(t)?;
                        textures.insert(Arc::as_ptr(&t.bytes), img.clone());
                        img
                    }
                }),
                None => None,
            };
            let c = part.material.base_color;
            vis.materials.push(RMaterial {
                colour: [
                    raster::linear_to_srgb(c[0]),
                    raster::linear_to_srgb(c[1]),
                    raster::linear_to_srgb(c[2]),
                ],
                texture: if part.uvs.is_some() { texture } else { None },
            });
            let verts: Vec<P3> = part
                .positions
                .iter()
                .map(|p| m.transform_point(p))
                .collect();
            vis.push(
                &verts,
                part.uvs.as_deref(),
                &part.triangles,
                (vis.materials.len() - 1) as u32,
                i as u32 + 1,
            );
        }
    }
    let mut hulls = RenderMesh::default();
    hulls.materials.push(RMaterial {
        colour: [1.0; 3],
        texture: None,
    });
    let mut owner = vec![usize::MAX];
    for (i, b) in a.bodies.iter().enumerate() {
        for h in b.world_hulls() {
            hulls.push(&h.vertices, None, &h.triangles, 0, owner.len() as u32);
            owner.push(i);
        }
    }
    Ok((vis, hulls, owner))
}

fn bounds(mesh: &RenderMesh) -> Option<Aabb> {
    Aabb::of_points(&mesh.verts)
}

fn to_f32(c: [u8; 3]) -> [f32; 3] {
    c.map(|v| v as f32 / 255.0)
}

/// Render every picture of `a` (see the module documentation).
pub fn render(a: &Assembly, opts: &RenderOptions) -> Result<Renders> {
    if opts.size == 0 || opts.supersample == 0 || opts.section_size == 0 {
        return Err(Error::Usage("image sizes must be positive".into()));
    }
    let mut clock = std::time::Instant::now();
    let mut timings = Vec::new();
    let mut lap = |name: &'static str, timings: &mut Vec<(&'static str, f64)>| {
        let now = std::time::Instant::now();
        timings.push((name, (now - clock).as_secs_f64()));
        clock = now;
    };
    let (vis, hull_mesh, owner) = meshes(a)?;
    lap("meshes", &mut timings);
    let (mut t_views, mut t_hulls) = (0.0, 0.0);
    let bb = bounds(&vis)
        .or_else(|| bounds(&hull_mesh))
        .ok_or_else(|| Error::input(&a.name, "nothing to render: the scene has no triangles"))?;
    let center = bb.center();
    let radius = 0.5 * bb.diagonal().max(1e-6);
    let floor_z = bb.min.z;
    let cell = 10f64.powf((radius / 3.0).log10().round());
    let k = opts.supersample as usize;
    let mut pictures = Vec::new();
    for view in VIEWS {
        let cam =
            Camera::framing(view, center, radius, opts.size, opts.size).expect("a known view");
        let hi = cam.scaled(opts.supersample);
        let (w, h) = (hi.width as usize, hi.height as usize);
        let mut f = Frame::new(w, h);
        f.floor(&hi, floor_z, &center, cell, 3.0 * radius);
        let t0 = std::time::Instant::now();
        let floor_rgb = f.rgb.clone();
        f.draw(&hi, &vis, None);
        pictures.push(Picture {
            file: format!("views/{view}.png"),
            image: f.downsample(k),
            record: ImageRecord {
                file: format!("views/{view}.png"),
                kind: "view",
                view: Some(view),
                camera: Some(cam.record()),
                section: None,
            },
        });
        let t1 = std::time::Instant::now();
        t_views += (t1 - t0).as_secs_f64();
        if !hull_mesh.tris.is_empty() {
            // The visual in grey (its shading kept from the textured pass), then the hulls in a
            // frame of their own, blended and outlined.
            let g = &f;
            let mut rgb: Vec<[f32; 3]> = (0..w * h)
                .map(|i| {
                    if g.tag[i] == 0 {
                        floor_rgb[i]
                    } else {
                        HULL_UNDERLAY.map(|c| c * g.light[i])
                    }
                })
                .collect();
            let under = rgb.clone();
            let mut hf = Frame::new(w, h);
            let col = |t: u32| to_f32(colour_of(owner[t as usize]));
            hf.draw(&hi, &hull_mesh, Some(&col));
            for y in 0..h {
                for x in 0..w {
                    let i = y * w + x;
                    let t = hf.tag[i];
                    if t == 0 || !(hf.depth[i] <= g.depth[i] * (1.0 + 1e-9)) {
                        continue;
                    }
                    let edge = (x + 1 < w && hf.tag[i + 1] != t)
                        || (x > 0 && hf.tag[i - 1] != t)
                        || (y + 1 < h && hf.tag[i + w] != t)
                        || (y > 0 && hf.tag[i - w] != t);
                    rgb[i] = if edge {
                        [0.08, 0.08, 0.08]
                    } else {
                        std::array::from_fn(|c| 0.6 * hf.rgb[i][c] + 0.4 * under[i][c])
                    };
                }
            }
            pictures.push(Picture {
                file: format!("hulls/{view}.png"),
                image: raster::downsample(&rgb, w, h, k),
                record: ImageRecord {
                    file: format!("hulls/{view}.png"),
                    kind: "hulls",
                    view: Some(view),
                    camera: Some(cam.record()),
                    section: None,
                },
            });
        }
        t_hulls += t1.elapsed().as_secs_f64();
    }
    lap("views+hulls", &mut timings);
    timings.pop();
    timings.push(("views", t_views));
    timings.push(("hulls", t_hulls));
    pictures.extend(sections(a, opts)?);
    lap("sections", &mut timings);
    let views = ViewsJson {
        tool: "interact3d",
        version: env!("CARGO_PKG_VERSION"),
        scene: a.name.clone(),
        conventions: Conventions {
            world: "metres, Z up, the scene's front faces -Y; objects at their composed poses",
            camera: "pinhole, OpenCV axes: x right, y down, z forward; pixel = K (R X + t)",
            pixel: "pixel (u, v) covers [u, u+1) x [v, v+1); its centre is (u + 0.5, v + 0.5)",
            floor_z_m: floor_z,
            floor_cell_m: cell,
        },
        legend: Legend {
            objects: a
                .bodies
                .iter()
                .enumerate()
                .map(|(i, b)| LegendObject {
                    name: b.name.clone(),
                    label: b.label.clone(),
                    colour: colour_of(i),
                })
                .collect(),
            overlap: OVERLAP,
            section_empty: SECTION_EMPTY,
            background: raster::BACKGROUND.map(|c| (c * 255.0 + 0.5) as u8),
            views: "textured visual meshes, flat-shaded (key light + headlight), on a grey checkered floor",
            hulls: "collision hulls in their object's colour, 60 % over the visual meshes in grey; each hull outlined in near-black; grey alone where a visual mesh is outside every hull",
            sections: "each object's interior (visual mesh) in its colour; inside two or more objects: overlap colour; inside none: section_empty",
        },
        images: pictures.iter().map(|p| p.record.clone()).collect(),
    };
    Ok(Renders {
        pictures,
        views,
        timings,
    })
}

/// The three cross-sections of each pair of nearby objects.
fn sections(a: &Assembly, opts: &RenderOptions) -> Result<Vec<Picture>> {
    let hulls: Vec<Vec<crate::decompose::Hull>> =
        a.bodies.iter().map(|b| b.world_hulls()).collect();
    let geoms: Vec<crate::mesh::Mesh> = a.bodies.iter().map(|b| b.world_geometry()).collect();
    let diag: Vec<f64> = geoms
        .iter()
        .map(|g| g.aabb().map(|b| b.diagonal()).unwrap_or(0.0))
        .collect();
    let min_diag = diag
        .iter()
        .cloned()
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    let margin = if min_diag.is_finite() {
        opts.section_margin * min_diag
    } else {
        0.0
    };
    let contacts = section::contacts(&hulls, margin);
    // Metrics' inside test, built only for a mesh whose slice needs it (an open scan).
    let prepared: Vec<std::sync::OnceLock<crate::metrics::Prepared>> =
        geoms.iter().map(|_| std::sync::OnceLock::new()).collect();
    let n = opts.section_size;
    let mut out = Vec::new();
    for c in &contacts {
        let half = 0.6 * diag[c.a].min(diag[c.b]).max(1e-6);
        for (axis, name) in [(0usize, "x"), (1, "y"), (2, "z")] {
            let plane = Plane {
                axis,
                center: c.point,
                pixel: 2.0 * half / n as f64,
                size: n,
            };
            let mut count = vec![0u8; (n * n) as usize];
            let mut which = vec![0usize; (n * n) as usize];
            for (i, g) in geoms.iter().enumerate() {
                let Some(gb) = g.aabb() else { continue };
                let (ua, va) = plane.uv_axes();
                let lo = [plane.u_of(0.0), plane.v_of(n as f64 - 1.0)];
                let hi = [plane.u_of(n as f64 - 1.0), plane.v_of(0.0)];
                if gb.max[ua] < lo[0]
                    || gb.min[ua] > hi[0]
                    || gb.max[va] < lo[1]
                    || gb.min[va] > hi[1]
                {
                    continue;
                }
                let inside = |p: &P3| {
                    prepared[i]
                        .get_or_init(|| {
                            crate::metrics::Prepared::new(crate::metrics::Solid::Mesh(g))
                        })
                        .contains(p)
                };
                let mask = section::slice(g, &plane, &inside);
                for (j, m) in mask.iter().enumerate() {
                    if *m {
                        count[j] = count[j].saturating_add(1);
                        which[j] = i;
                    }
                }
            }
            let mut img = image::RgbImage::new(n, n);
            for (j, px) in img.pixels_mut().enumerate() {
                px.0 = match count[j] {
                    0 => SECTION_EMPTY,
                    1 => colour_of(which[j]),
                    _ => OVERLAP,
                };
            }
            let (ua, va) = plane.uv_axes();
            let axis_name = ["x", "y", "z"];
            let (na, nb) = (&a.bodies[c.a].name, &a.bodies[c.b].name);
            let file = format!("sections/{na}__{nb}__{name}.png");
            out.push(Picture {
                file: file.clone(),
                image: img,
                record: ImageRecord {
                    file,
                    kind: "section",
                    view: None,
                    camera: None,
                    section: Some(SectionRecord {
                        pair: [na.clone(), nb.clone()],
                        hull_depth_m: c.depth,
                        normal: name,
                        center: [c.point.x, c.point.y, c.point.z],
                        right: axis_name[ua],
                        up: axis_name[va],
                        pixel_size_m: plane.pixel,
                        pixel_to_world: "world[right] = center[right] + (col + 0.5 - width/2) * pixel_size_m; world[up] = center[up] - (row + 0.5 - height/2) * pixel_size_m; world[normal] = center[normal]",
                    }),
                },
            });
        }
    }
    Ok(out)
}

/// PNG bytes of an image (fast deflate, adaptive filters: deterministic).
pub fn png_bytes(img: &image::RgbImage) -> Result<Vec<u8>> {
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    use image::ImageEncoder;
    let mut out = Vec::new();
    PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Adaptive)
        .write_image(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| Error::Internal(format!("PNG encoding: {e}")))?;
    Ok(out)
}

/// Write the pictures, `views.json` and the scene's page `index.html` (with the validation's
/// metrics and findings when given) into the existing folder `dir`.
pub fn write(r: &Renders, dir: &Path, validation: Option<&serde_json::Value>) -> Result<()> {
    for p in &r.pictures {
        let path = dir.join(&p.file);
        if let Some(parent) = path.parent() {
            crate::fsutil::create_dir(parent)?;
        }
        crate::fsutil::write(&path, &png_bytes(&p.image)?)?;
    }
    crate::fsutil::write(
        &dir.join("views.json"),
        &crate::fsutil::json_bytes(&r.views)?,
    )?;
    crate::fsutil::write(
        &dir.join("index.html"),
        page::page(&r.views, validation)?.as_bytes(),
    )
}

/// Render `a` into the folder `out`, replaced atomically (an earlier render folder, one with a
/// `views.json` of ours, is replaced; anything else only with `force`).
pub fn render_to_dir(
    a: &Assembly,
    out: &Path,
    opts: &RenderOptions,
    validation: Option<&serde_json::Value>,
    force: bool,
) -> Result<Renders> {
    let r = render(a, opts)?;
    let ours = std::fs::read_to_string(out.join("views.json"))
        .map(|s| s.contains("\"tool\": \"interact3d\""))
        .unwrap_or(false);
    crate::fsutil::write_dir_atomically(out, force || ours, |dir| write(&r, dir, validation))?;
    Ok(r)
}
