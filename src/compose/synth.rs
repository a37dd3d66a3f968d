//! Guidance parts from ground-truth scenes, for tests and the benchmark: what segmenting a
//! generated, fused scene mesh gives. Each object is placed by its true pose, the whole scene
//! is moved by a random similarity (the guidance frame: yaw, a small tilt, scale, shift), and
//! each object's surface then loses 20–40% of its area as ragged holes centred on the contact
//! region and a random spot, gains a strip of its neighbour near the contact (fused
//! segmentation), gets vertex noise, vertex-clustering decimation and a tinted colour.
//! The truth of object i is `frame ∘ pose_i`: object frame → guidance frame.

use super::kdtree::KdTree;
use super::ObjectInput;
use crate::error::Result;
use crate::io::Limits;
use crate::mesh::{triangle_area, VisualMesh, VisualPart, P3, V3};
use crate::pose::Similarity;
use crate::rng::Rng;
use nalgebra::{UnitQuaternion, Vector3};
use std::collections::BTreeMap;
use std::path::Path;

/// An object of a ground-truth scene.
#[derive(Clone, Debug)]
pub struct TruthObject {
    pub name: String,
    pub visual: VisualMesh,
    /// Object frame → scene frame.
    pub pose: Similarity,
}

/// Knobs of the generator (fractions of each object's diagonal where lengths).
#[derive(Clone, Debug)]
pub struct SynthOptions {
    pub hole_fraction: [f64; 2],
    pub noise: f64,
    pub cluster: f64,
    /// Neighbour surface within this distance of the object near the contact is fused in.
    pub fuse: f64,
    pub max_tilt_deg: f64,
    pub scale: [f64; 2],
    /// Per-channel colour gain spread (±).
    pub colour_gain: f64,
}

impl Default for SynthOptions {
    fn default() -> Self {
        SynthOptions {
            hole_fraction: [0.2, 0.4],
            noise: 0.002,
            cluster: 1.0 / 90.0,
            fuse: 0.03,
            max_tilt_deg: 10.0,
            scale: [0.5, 2.0],
            colour_gain: 0.1,
        }
    }
}

/// Guidance parts with their truth.
pub struct Synthetic {
    pub inputs: Vec<ObjectInput>,
    /// Object frame → guidance frame, per input.
    pub truth: Vec<Similarity>,
    /// Scene frame → guidance frame.
    pub frame: Similarity,
    /// Fraction of each object's surface area removed.
    pub removed: Vec<f64>,
}

/// A composed pose against its truth, by the benchmark's success thresholds.
#[derive(Clone, Copy, Debug)]
pub struct Judged {
    pub success: bool,
    /// Rotation error (degrees), translation error (guidance units), relative scale error.
    pub rot_deg: f64,
    pub trans: f64,
    pub scale: f64,
}

impl Synthetic {
    /// Diagonal of the true composed scene's bounding box, in guidance units: the unit of the
    /// translation threshold in [`Synthetic::judge`].
    pub fn diagonal(&self) -> f64 {
        self.inputs
            .iter()
            .zip(&self.truth)
            .filter_map(|(i, t)| i.visual.geometry().transformed(&t.matrix()).aabb())
            .reduce(|a, b| a.union(&b))
            .map_or(0.0, |b| b.diagonal())
    }

    /// Input `k` composed at `est`: a success when the rotation error is below 5° (or the pose
    /// looks the same, see [`appearance_equivalent`]), the translation error below 2 % of
    /// `diag` (from [`Synthetic::diagonal`]) and the scale error below 3 %.
    pub fn judge(&self, k: usize, est: &Similarity, diag: f64) -> Judged {
        let truth = &self.truth[k];
        let (rot_deg, trans, scale) = errors(est, truth);
        let rot_ok = rot_deg < 5.0 || appearance_equivalent(&self.inputs[k].visual, est, truth);
        Judged {
            success: rot_ok && trans < 0.02 * diag && scale < 0.03,
            rot_deg,
            trans,
            scale,
        }
    }
}

/// The box of a ground-truth scene: every object at its true pose. The guidance generators
/// size their frame, holes and noise from it.
pub fn scene_box(objects: &[TruthObject]) -> crate::mesh::Aabb {
    objects
        .iter()
        .filter_map(|t| t.visual.geometry().transformed(&t.pose.matrix()).aabb())
        .reduce(|a, b| a.union(&b))
        .expect("scene has geometry")
}

/// Read a ground-truth sample folder (objects + their poses in metadata.json).
pub fn load_truth(dir: &Path) -> Result<Vec<TruthObject>> {
    let scene = crate::scene::sample::load(dir, &Limits::default())?;
    Ok(scene
        .objects
        .into_iter()
        .map(|o| TruthObject {
            // The file's id (`object_b`), not the label-derived name: guidance parts are
            // `guidance_<id>.glb`.
            name: o.aliases.into_iter().next().unwrap_or(o.name),
            visual: o.visual,
            pose: o.pose,
        })
        .collect())
}

fn hash3(p: &P3, seed: u64) -> u64 {
    let mut r = Rng::new(
        seed ^ p.x.to_bits().rotate_left(7)
            ^ p.y.to_bits().rotate_left(19)
            ^ p.z.to_bits().rotate_left(37),
    );
    r.next_u64()
}

/// Split every triangle with an edge longer than `max_edge` into four (up to `rounds` times).
fn subdivide(part: &mut VisualPart, max_edge: f64, rounds: usize) {
    for _ in 0..rounds {
        let mut out = Vec::with_capacity(part.triangles.len());
        let mut split_any = false;
        let tris = std::mem::take(&mut part.triangles);
        for t in tris {
            let [a, b, c] = t.map(|i| part.positions[i as usize]);
            let longest = (a - b).norm().max((b - c).norm()).max((c - a).norm());
            if longest <= max_edge {
                out.push(t);
                continue;
            }
            split_any = true;
            let mut mid = |i: u32, j: u32| -> u32 {
                let p = nalgebra::center(&part.positions[i as usize], &part.positions[j as usize]);
                part.positions.push(p);
                if let Some(uv) = &mut part.uvs {
                    let (x, y) = (uv[i as usize], uv[j as usize]);
                    uv.push([(x[0] + y[0]) / 2.0, (x[1] + y[1]) / 2.0]);
                }
                (part.positions.len() - 1) as u32
            };
            let ab = mid(t[0], t[1]);
            let bc = mid(t[1], t[2]);
            let ca = mid(t[2], t[0]);
            out.extend([[t[0], ab, ca], [ab, t[1], bc], [ca, bc, t[2]], [ab, bc, ca]]);
        }
        part.triangles = out;
        if !split_any {
            break;
        }
    }
}

/// Vertex clustering: one vertex per cell of size `cell` (the first), degenerate triangles dropped.
fn cluster(part: &mut VisualPart, cell: f64) {
    let mut map: BTreeMap<[i64; 3], u32> = BTreeMap::new();
    let mut pos = Vec::new();
    let mut uvs = part.uvs.as_ref().map(|_| Vec::new());
    let remap: Vec<u32> = (0..part.positions.len())
        .map(|i| {
            let p = part.positions[i];
            let key = [
                (p.x / cell).floor() as i64,
                (p.y / cell).floor() as i64,
                (p.z / cell).floor() as i64,
            ];
            *map.entry(key).or_insert_with(|| {
                pos.push(p);
                if let (Some(u), Some(src)) = (&mut uvs, &part.uvs) {
                    u.push(src[i]);
                }
                (pos.len() - 1) as u32
            })
        })
        .collect();
    part.triangles = part
        .triangles
        .iter()
        .map(|t| t.map(|i| remap[i as usize]))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .collect();
    part.positions = pos;
    part.uvs = uvs;
}

fn keep_triangles(part: &VisualPart, keep: &[bool]) -> VisualPart {
    VisualPart {
        positions: part.positions.clone(),
        uvs: part.uvs.clone(),
        triangles: part
            .triangles
            .iter()
            .zip(keep)
            .filter(|(_, &k)| k)
            .map(|(t, _)| *t)
            .collect(),
        material: part.material.clone(),
    }
}

/// Make guidance parts for a ground-truth scene.
pub fn make(objects: &[TruthObject], seed: u64, o: &SynthOptions) -> Synthetic {
    let mut rng = Rng::new(seed);
    // The guidance frame.
    let scene_bb = scene_box(objects);
    let diag = scene_bb.diagonal();
    let yaw =
        UnitQuaternion::from_axis_angle(&Vector3::y_axis(), rng.range(0.0, std::f64::consts::TAU));
    let tilt_axis = Vector3::new(rng.range(-1.0, 1.0), 0.0, rng.range(-1.0, 1.0));
    let tilt = if tilt_axis.norm() > 1e-9 {
        UnitQuaternion::from_axis_angle(
            &nalgebra::Unit::new_normalize(tilt_axis),
            rng.range(0.0, o.max_tilt_deg).to_radians(),
        )
    } else {
        UnitQuaternion::identity()
    };
    let frame = Similarity {
        scale: (rng.range(o.scale[0].ln(), o.scale[1].ln())).exp(),
        rotation: tilt * yaw,
        translation: V3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        ) * diag,
    };
    let truth: Vec<Similarity> = objects.iter().map(|t| frame.then_after(&t.pose)).collect();
    let placed = placed(objects, &truth);
    // Dense points of every placed object, for contact and fusing.
    let clouds: Vec<super::cloud::Cloud> = placed
        .iter()
        .enumerate()
        .map(|(i, v)| super::cloud::Cloud::sample(v, 4000, seed ^ (i as u64 + 17)))
        .collect();
    let trees: Vec<KdTree> = clouds.iter().map(|c| KdTree::new(&c.points)).collect();
    let mut inputs = Vec::new();
    let mut removed = Vec::new();
    for (i, t) in objects.iter().enumerate() {
        let geo_bb = placed[i].geometry().aabb().expect("object has geometry");
        let d_i = geo_bb.diagonal();
        let mut parts: Vec<VisualPart> = placed[i].parts.clone();
        for p in &mut parts {
            subdivide(p, d_i / 20.0, 4);
        }
        // The contact: this object's sample closest to any other object.
        let mut contact: Option<(f64, P3)> = None;
        for p in clouds[i].points.iter().step_by(4) {
            for (j, tr) in trees.iter().enumerate() {
                if j == i {
                    continue;
                }
                if let Some((_, d2)) = tr.nearest(p) {
                    if contact.is_none_or(|c| d2 < c.0) {
                        contact = Some((d2, *p));
                    }
                }
            }
        }
        let mut centres: Vec<P3> = Vec::new();
        let random_point = |rng: &mut Rng| clouds[i].points[rng.below(clouds[i].len())];
        centres.push(
            contact
                .map(|c| c.1)
                .unwrap_or_else(|| random_point(&mut rng)),
        );
        centres.push(random_point(&mut rng));
        // Ragged holes: remove triangles by (noisy) distance to the nearest centre.
        let frac = rng.range(o.hole_fraction[0], o.hole_fraction[1]);
        let mut tri_list: Vec<(f64, usize, usize, f64)> = Vec::new(); // (key, part, tri, area)
        let mut total = 0.0;
        for (pi, p) in parts.iter().enumerate() {
            for (ti, tr) in p.triangles.iter().enumerate() {
                let v = tr.map(|k| p.positions[k as usize]);
                let a = triangle_area(&v);
                total += a;
                let c = P3::from((v[0].coords + v[1].coords + v[2].coords) / 3.0);
                let jag = 1.0 + 0.5 * ((hash3(&c, seed) >> 11) as f64 / (1u64 << 53) as f64);
                // The second hole is smaller (weight 1.6 makes it grow slower).
                let d = centres
                    .iter()
                    .enumerate()
                    .map(|(k, q)| (c - q).norm() * if k == 0 { 1.0 } else { 1.6 })
                    .fold(f64::INFINITY, f64::min);
                tri_list.push((d * jag, pi, ti, a));
            }
        }
        tri_list.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let mut keep: Vec<Vec<bool>> = parts
            .iter()
            .map(|p| vec![true; p.triangles.len()])
            .collect();
        let mut gone = 0.0;
        for &(_, pi, ti, a) in &tri_list {
            if gone >= frac * total {
                break;
            }
            keep[pi][ti] = false;
            gone += a;
        }
        removed.push(gone / total.max(1e-300));
        let mut out: Vec<VisualPart> = parts
            .iter()
            .zip(&keep)
            .map(|(p, k)| keep_triangles(p, k))
            .collect();
        // Fused segmentation: neighbour triangles near this object and near the contact.
        if let Some((_, cpt)) = contact {
            let mut budget = 0.08 * total;
            for (j, other) in placed.iter().enumerate() {
                if j == i {
                    continue;
                }
                for p in &other.parts {
                    let mut k = vec![false; p.triangles.len()];
                    for (ti, tr) in p.triangles.iter().enumerate() {
                        let v = tr.map(|q| p.positions[q as usize]);
                        let c = P3::from((v[0].coords + v[1].coords + v[2].coords) / 3.0);
                        if (c - cpt).norm() > 0.3 * d_i {
                            continue;
                        }
                        if let Some((_, d2)) = trees[i].nearest(&c) {
                            let a = triangle_area(&v);
                            if d2.sqrt() < o.fuse * d_i && a <= budget {
                                k[ti] = true;
                                budget -= a;
                            }
                        }
                    }
                    if k.iter().any(|&x| x) {
                        out.push(keep_triangles(p, &k));
                    }
                }
            }
        }
        // Noise (the same offset for the same position, so seams stay closed), decimation, tint.
        let sigma = o.noise * d_i;
        for p in &mut out {
            for v in &mut p.positions {
                let mut r = Rng::new(hash3(v, seed ^ 0xA5));
                *v += V3::new(r.normal(), r.normal(), r.normal()) * sigma;
            }
            cluster(p, o.cluster * d_i);
            for k in 0..3 {
                p.material.base_color[k] = (p.material.base_color[k]
                    * (1.0 + rng.range(-o.colour_gain, o.colour_gain)))
                .clamp(0.0, 1.0);
            }
        }
        out.retain(|p| !p.triangles.is_empty());
        inputs.push(ObjectInput {
            name: t.name.clone(),
            visual: t.visual.clone(),
            guidance: VisualMesh { parts: out },
        });
    }
    Synthetic {
        inputs,
        truth,
        frame,
        removed,
    }
}

/// Write a synthetic sample folder: the original object GLBs (copied from `source` when given,
/// else written), `guidance_<name>.glb`, and `ground_truth_compose.json` with the truths.
pub fn write_sample(s: &Synthetic, source: Option<&Path>, dir: &Path) -> Result<()> {
    crate::fsutil::create_dir(dir)?;
    for (inp, t) in s.inputs.iter().zip(&s.truth) {
        let f = format!("{}.glb", inp.name);
        match source {
            Some(src) if src.join(&f).is_file() => {
                std::fs::copy(src.join(&f), dir.join(&f))
                    .map_err(|e| crate::Error::io(src.join(&f), e))?;
            }
            _ => crate::io::write_glb(&inp.visual, &dir.join(&f))?,
        }
        crate::io::write_glb(&inp.guidance, &dir.join(format!("guidance_{}", f)))?;
        let _ = t;
    }
    let truth: BTreeMap<String, Vec<Vec<f64>>> = s
        .inputs
        .iter()
        .zip(&s.truth)
        .map(|(i, t)| {
            let m = t.matrix();
            (
                i.name.clone(),
                (0..4)
                    .map(|a| (0..4).map(|b| m[(a, b)]).collect())
                    .collect(),
            )
        })
        .collect();
    crate::fsutil::write(
        &dir.join("ground_truth_compose.json"),
        &crate::fsutil::json_bytes(&serde_json::json!({
            "convention": "p_guidance = matrix · p_object (row-major 4x4)",
            "removed_area_fraction": s.removed,
            "transforms": truth,
        }))?,
    )?;
    if let Some(src) = source {
        if src.join("metadata.json").is_file() {
            // Copy the descriptive fields, not the registration (that is what compose finds).
            let text = std::fs::read_to_string(src.join("metadata.json"))
                .map_err(|e| crate::Error::io(src, e))?;
            if let Ok(serde_json::Value::Object(mut m)) =
                serde_json::from_str::<serde_json::Value>(&text)
            {
                m.remove("registration");
                crate::fsutil::write(
                    &dir.join("metadata.json"),
                    &crate::fsutil::json_bytes(&serde_json::Value::Object(m))?,
                )?;
            }
        }
    }
    Ok(())
}

/// Errors of a pose against its truth: rotation (degrees), translation (guidance units) and
/// relative scale.
pub fn errors(est: &Similarity, truth: &Similarity) -> (f64, f64, f64) {
    (
        est.rotation.angle_to(&truth.rotation).to_degrees(),
        (est.translation - truth.translation).norm(),
        (est.scale / truth.scale - 1.0).abs(),
    )
}

/// Whether the object placed by `est` looks the same as placed by `truth`: for 90% of 2,000
/// coloured surface samples placed by `est`, one of 40,000 samples placed by `truth` lies within
/// 2% of the object's diagonal with a similar colour (the dense set keeps the share of pairs
/// straddling a colour edge small). True for the symmetries a pose cannot observe (a plain
/// sphere spun, a checkered bowl turned by one period); false for a printed box upside down.
pub fn appearance_equivalent(visual: &VisualMesh, est: &Similarity, truth: &Similarity) -> bool {
    let a = super::cloud::Cloud::sample(visual, 2000, 98).transformed(&est.matrix());
    let b = super::cloud::Cloud::sample(visual, 40_000, 99).transformed(&truth.matrix());
    let tol = 0.02 * b.diagonal();
    let tree = KdTree::new(&b.points);
    let mut near = Vec::new();
    let good = a
        .points
        .iter()
        .zip(&a.colours)
        .filter(|(p, col)| {
            tree.within(p, tol, &mut near);
            near.iter().any(|&j| {
                let dc: f64 = (0..3)
                    .map(|k| (col[k] - b.colours[j][k]).powi(2))
                    .sum::<f64>();
                dc.sqrt() < 0.2
            })
        })
        .count();
    good as f64 >= 0.9 * a.len() as f64
}

/// A texture whose colour is unique at every texel (a smooth gradient plus a diagonal wave), so
/// no symmetry of a box or a cylinder maps it onto itself.
pub fn asymmetric_texture(hue: u8, origin: &str) -> crate::mesh::Texture {
    let img = image::RgbImage::from_fn(64, 64, |x, y| {
        let w = ((x as f64 + 2.0 * y as f64) / 9.0).sin();
        image::Rgb([
            (x * 4) as u8,
            (y * 4) as u8,
            (hue as f64 * 0.5 + 60.0 * (1.0 + w)) as u8,
        ])
    });
    crate::shapes::png_texture(&img, origin)
}

fn unit_visual(
    mesh: &crate::mesh::Mesh,
    proj: crate::shapes::UvProjection,
    hue: u8,
    z_to_y: bool,
) -> (VisualMesh, f64) {
    let mut v = crate::shapes::visual(
        mesh,
        proj,
        crate::shapes::textured_material(
            &format!("print{hue}"),
            asymmetric_texture(hue, "generated"),
        ),
    );
    if z_to_y {
        v.transform(
            &UnitQuaternion::from_axis_angle(&Vector3::x_axis(), -std::f64::consts::FRAC_PI_2)
                .to_homogeneous(),
        );
    }
    // Normalise like a generator: centred, longest extent 1.
    let bb = v.geometry().aabb().unwrap();
    let s = bb.extents().max();
    let c = bb.center();
    v.transform(
        &(nalgebra::Matrix4::new_scaling(1.0 / s)
            * nalgebra::Translation3::from(-c.coords).to_homogeneous()),
    );
    (v, s)
}

/// Scenes of symmetric objects with printed (asymmetric) textures, resting 1 mm above their
/// support, in metres, Y-up: a box on a board, a book on a box, a can on a board.
pub fn symmetric_scenes() -> Vec<(String, Vec<TruthObject>)> {
    use crate::shapes::{cuboid, cylinder, UvProjection};
    let yaw = |deg: f64| UnitQuaternion::from_axis_angle(&Vector3::y_axis(), deg.to_radians());
    let support = |ext: V3, hue: u8| -> TruthObject {
        let (v, s) = unit_visual(
            &cuboid(ext),
            UvProjection::Box { tile: ext.max() },
            hue,
            false,
        );
        TruthObject {
            name: "object_a".into(),
            visual: v,
            pose: Similarity {
                scale: s,
                rotation: UnitQuaternion::identity(),
                translation: V3::new(0.0, ext.y / 2.0, 0.0),
            },
        }
    };
    let on_top = |mesh: crate::mesh::Mesh,
                  proj,
                  hue,
                  z_to_y,
                  half_height: f64,
                  top: f64,
                  deg: f64,
                  dx: f64| {
        let (v, s) = unit_visual(&mesh, proj, hue, z_to_y);
        TruthObject {
            name: "object_b".into(),
            visual: v,
            pose: Similarity {
                scale: s,
                rotation: yaw(deg),
                translation: V3::new(dx, top + 0.001 + half_height, -0.01),
            },
        }
    };
    vec![
        (
            "sym_box_board".into(),
            vec![
                support(V3::new(0.40, 0.024, 0.30), 40),
                on_top(
                    cuboid(V3::new(0.12, 0.06, 0.08)),
                    UvProjection::Box { tile: 0.12 },
                    200,
                    false,
                    0.03,
                    0.024,
                    30.0,
                    0.02,
                ),
            ],
        ),
        (
            "sym_book_box".into(),
            vec![
                support(V3::new(0.30, 0.10, 0.25), 90),
                on_top(
                    cuboid(V3::new(0.21, 0.03, 0.15)),
                    UvProjection::Box { tile: 0.21 },
                    250,
                    false,
                    0.015,
                    0.10,
                    15.0,
                    0.0,
                ),
            ],
        ),
        (
            "sym_can_board".into(),
            vec![
                support(V3::new(0.30, 0.024, 0.24), 140),
                on_top(
                    cylinder(0.033, 0.10, 48),
                    UvProjection::Cylindrical { repeat: 1.0 },
                    10,
                    true,
                    0.05,
                    0.024,
                    70.0,
                    0.03,
                ),
            ],
        ),
    ]
}

/// Each object's visual mesh moved by its truth (object frame → guidance frame).
pub(crate) fn placed(objects: &[TruthObject], truth: &[Similarity]) -> Vec<VisualMesh> {
    objects
        .iter()
        .zip(truth)
        .map(|(t, s)| {
            let mut v = t.visual.clone();
            v.transform(&s.matrix());
            v
        })
        .collect()
}
