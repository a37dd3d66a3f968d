//! Realistic guidance for the benchmark and tests (issue #34): what segmenting a dense,
//! generated scene mesh gives for a pair of real objects, one resting on or in the other.
//!
//! Entry points:
//! - [`load_object`]: one of the shared scanned objects, Y-up, normalised like a generator's
//!   output (centred, longest extent 1), with its true size in metres;
//! - [`pair_scene`]: a support/container and an item, the support at a random yaw on the
//!   floor, the item at its own random yaw dropped onto (into) the support until its mesh is
//!   [`REST_CLEARANCE`] of its diagonal above the support's mesh;
//! - [`make`]: the guidance parts: a dense reconstruction (20k–70k triangles, by subdividing the
//!   placed object — not the decimation of [`super::synth`]), a hole around the contact, three
//!   random holes each of radius 12 % of the object's diagonal, Gaussian vertex noise of 0.3 % of
//!   the object's diagonal and a colour tint, in a random guidance frame;
//! - [`add_s`]: ADD-S of an estimated pose against the truth, as a fraction of the object's
//!   (true) diagonal.
//!
//! Every random draw comes from the generator's own stream (its seed is the caller's; the
//! pipeline's seed is another), and true poses are drawn without reference to any bounding box
//! axis: the registration's assumptions are not built into its test data.

use super::cloud::Cloud;
use super::kdtree::KdTree;
use super::synth::{Synthetic, TruthObject};
use super::ObjectInput;
use crate::error::{Error, Result};
use crate::io::Limits;
use crate::mesh::{triangle_area, VisualMesh, VisualPart, P3, V3};
use crate::pose::Similarity;
use crate::rng::Rng;
use nalgebra::{UnitQuaternion, Vector3};
use std::path::Path;

/// A shared object, ready to compose.
#[derive(Clone, Debug)]
pub struct SourceObject {
    /// The id in `index.json` (`ycb/029_plate`).
    pub id: String,
    /// Y-up, centred on its bounding box, longest extent 1.
    pub visual: VisualMesh,
    /// Longest extent in metres: the true scale of [`SourceObject::visual`].
    pub size: f64,
}

/// Load `objects/<id>` through `index.json` (mesh path, up axis, scale to metres).
pub fn load_object(objects: &Path, id: &str) -> Result<SourceObject> {
    let index_path = objects.join("index.json");
    let text = std::fs::read_to_string(&index_path).map_err(|e| Error::io(&index_path, e))?;
    let index: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| Error::Usage(format!("{}: {e}", index_path.display())))?;
    let entry = index
        .as_array()
        .and_then(|a| a.iter().find(|o| o["id"] == id))
        .ok_or_else(|| Error::Usage(format!("{}: no object {id:?}", index_path.display())))?;
    let mesh = entry["mesh"].as_str().unwrap_or_default();
    let mut visual = crate::io::load_visual(&objects.join(mesh), &Limits::default())?;
    let scale = entry["scale_to_m"].as_f64().unwrap_or(1.0);
    let z_up = entry["up_axis"].as_str().unwrap_or("+Z").starts_with("+Z");
    let mut m = nalgebra::Matrix4::new_scaling(scale);
    if z_up {
        m = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), -std::f64::consts::FRAC_PI_2)
            .to_homogeneous()
            * m;
    }
    visual.transform(&m);
    Ok(normalised(id, visual))
}

/// `visual` (metres, Y-up) centred and scaled to a longest extent of 1.
pub fn normalised(id: &str, mut visual: VisualMesh) -> SourceObject {
    let bb = visual.geometry().aabb().expect("object has geometry");
    let size = bb.extents().max();
    visual.transform(
        &(nalgebra::Matrix4::new_scaling(1.0 / size)
            * nalgebra::Translation3::from(-bb.center().coords).to_homogeneous()),
    );
    SourceObject {
        id: id.to_string(),
        visual,
        size,
    }
}

/// A printed box (cereal box, milk carton) of `extents` metres with a texture that no symmetry
/// of the box maps onto itself.
pub fn printed_box(id: &str, extents: V3, hue: u8) -> SourceObject {
    let v = crate::shapes::visual(
        &crate::shapes::cuboid(extents),
        crate::shapes::UvProjection::Box {
            tile: extents.max(),
        },
        crate::shapes::textured_material(
            &format!("print{hue}"),
            super::synth::asymmetric_texture(hue, "generated"),
        ),
    );
    normalised(id, v)
}

fn yaw(rng: &mut Rng) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::y_axis(), rng.range(0.0, std::f64::consts::TAU))
}

/// Clearance of a true item above what it rests on, as a fraction of its diagonal: the contact
/// tolerance of [`super::contact_scale::ContactOptions`] (a gap below it is contact), so the
/// truth is in contact by the pipeline's own measure at every object size (a fixed 0.5 mm would
/// be 1.6 % of a Duplo brick's diagonal and 0.1 % of a board's).
pub const REST_CLEARANCE: f64 = 1e-3;

/// The support at a random yaw with its lowest point on y = 0; the item upright at its own
/// random yaw, offset at random within `spread` of the support's half footprint, dropped onto
/// the support's column height field and then lowered along gravity until its exact distance to
/// the support's mesh (or the floor) is [`REST_CLEARANCE`] of its diagonal
/// ([`super::rest::lower_to_clearance`]). Names: `support`, `item`.
pub fn pair_scene(
    support: &SourceObject,
    item: &SourceObject,
    spread: f64,
    rng: &mut Rng,
) -> Vec<TruthObject> {
    let place = |o: &SourceObject, q: UnitQuaternion<f64>, t: V3| Similarity {
        scale: o.size,
        rotation: q,
        translation: t,
    };
    let mut s_pose = place(support, yaw(rng), V3::zeros());
    let s_cloud = Cloud::sample(&support.visual, 30_000, 0x5u64).transformed(&s_pose.matrix());
    let s_bb = crate::mesh::Aabb::of_points(&s_cloud.points).unwrap();
    s_pose.translation.y -= s_bb.min.y;
    let s_pts: Vec<P3> = s_cloud
        .points
        .iter()
        .map(|p| P3::new(p.x, p.y - s_bb.min.y, p.z))
        .collect();
    let c = s_bb.center();
    let half = s_bb.extents() / 2.0;
    let dx = rng.range(-spread, spread) * half.x;
    let dz = rng.range(-spread, spread) * half.z;
    let mut i_pose = place(item, yaw(rng), V3::new(c.x + dx, 0.0, c.z + dz));
    let i_pts: Vec<P3> = Cloud::sample(&item.visual, 12_000, 0x6u64)
        .transformed(&i_pose.matrix())
        .points;
    // Columns of the support's top surface, as fine as the item's size allows.
    let i_bb = crate::mesh::Aabb::of_points(&i_pts).unwrap();
    let cell = (i_bb.extents().x.min(i_bb.extents().z) / 25.0).max(1e-4);
    let key = |p: &P3| ((p.x / cell).floor() as i64, (p.z / cell).floor() as i64);
    let mut top: std::collections::HashMap<(i64, i64), f64> = Default::default();
    for p in &s_pts {
        let k = key(p);
        let e = top.entry(k).or_insert(f64::NEG_INFINITY);
        *e = e.max(p.y);
    }
    // Lift so that every item point clears the support's top in its own and the 8 neighbouring
    // columns (the samples are ~a cell apart).
    let mut lift = f64::NEG_INFINITY;
    for p in &i_pts {
        let (kx, kz) = key(p);
        for ax in -1..=1 {
            for az in -1..=1 {
                if let Some(&h) = top.get(&(kx + ax, kz + az)) {
                    lift = lift.max(h - p.y);
                }
            }
        }
    }
    if !lift.is_finite() {
        // Off the support: on the floor.
        lift = -i_bb.min.y;
    }
    i_pose.translation.y += lift + 5e-4;
    // The columns clear the support conservatively (up to 4 % of the item's diagonal): lower
    // the item along gravity to an exact clearance above the support's mesh or the floor.
    let s_mesh = support.visual.geometry().transformed(&s_pose.matrix());
    let i_mesh = item.visual.geometry().transformed(&i_pose.matrix());
    let diagonal =
        crate::mesh::Aabb::of_points(&i_mesh.vertices).map_or(0.0, |b| b.extents().norm());
    let (drop, _) = super::rest::lower_to_clearance(&s_mesh, &i_mesh, REST_CLEARANCE * diagonal);
    i_pose.translation.y -= drop;
    vec![
        TruthObject {
            name: "support".into(),
            visual: support.visual.clone(),
            pose: s_pose,
        },
        TruthObject {
            name: "item".into(),
            visual: item.visual.clone(),
            pose: i_pose,
        },
    ]
}

/// Knobs of the realistic guidance (lengths as fractions of each object's diagonal).
#[derive(Clone, Debug)]
pub struct RealisticOptions {
    /// Triangle count of the dense reconstruction, drawn uniformly in this range.
    pub triangles: [usize; 2],
    /// Radius of the hole around the contact point.
    pub contact_hole: f64,
    /// Surface within this distance of the other object is lost too (hidden by it).
    pub contact_band: f64,
    pub random_holes: usize,
    pub random_hole_radius: f64,
    pub noise: f64,
    pub max_tilt_deg: f64,
    pub scale: [f64; 2],
    pub colour_gain: f64,
}

impl Default for RealisticOptions {
    fn default() -> Self {
        RealisticOptions {
            triangles: [20_000, 70_000],
            contact_hole: 0.12,
            contact_band: 0.02,
            random_holes: 3,
            random_hole_radius: 0.12,
            noise: 0.003,
            max_tilt_deg: 10.0,
            scale: [0.5, 2.0],
            colour_gain: 0.1,
        }
    }
}

/// Split the largest triangles (1 → 4 at edge midpoints, UVs interpolated) until the part has
/// at least `target` triangles: a dense reconstruction's vertex density.
fn densify(part: &mut VisualPart, target: usize) {
    while part.triangles.len() < target {
        let n = part.triangles.len();
        let needed = (target - n).div_ceil(3);
        let mut order: Vec<(f64, usize)> = part
            .triangles
            .iter()
            .enumerate()
            .map(|(i, t)| (triangle_area(&t.map(|k| part.positions[k as usize])), i))
            .collect();
        order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let mut split = vec![false; n];
        for &(_, i) in order.iter().take(needed.min(n)) {
            split[i] = true;
        }
        let mut mids: std::collections::HashMap<(u32, u32), u32> = Default::default();
        let tris = std::mem::take(&mut part.triangles);
        let mut out = Vec::with_capacity(n + 3 * needed.min(n));
        for (ti, t) in tris.into_iter().enumerate() {
            if !split[ti] {
                out.push(t);
                continue;
            }
            let mut mid = |i: u32, j: u32| -> u32 {
                let k = (i.min(j), i.max(j));
                if let Some(&m) = mids.get(&k) {
                    return m;
                }
                let p = nalgebra::center(&part.positions[i as usize], &part.positions[j as usize]);
                part.positions.push(p);
                if let Some(uv) = &mut part.uvs {
                    let (x, y) = (uv[i as usize], uv[j as usize]);
                    uv.push([(x[0] + y[0]) / 2.0, (x[1] + y[1]) / 2.0]);
                }
                let m = (part.positions.len() - 1) as u32;
                mids.insert(k, m);
                m
            };
            let ab = mid(t[0], t[1]);
            let bc = mid(t[1], t[2]);
            let ca = mid(t[2], t[0]);
            out.extend([[t[0], ab, ca], [ab, t[1], bc], [ca, bc, t[2]], [ab, bc, ca]]);
        }
        part.triangles = out;
    }
}

fn hash3(p: &P3, seed: u64) -> u64 {
    let mut r = Rng::new(
        seed ^ p.x.to_bits().rotate_left(7)
            ^ p.y.to_bits().rotate_left(19)
            ^ p.z.to_bits().rotate_left(37),
    );
    r.next_u64()
}

/// Guidance parts for a ground-truth scene (see the module doc).
pub fn make(objects: &[TruthObject], seed: u64, o: &RealisticOptions) -> Synthetic {
    let mut rng = Rng::new(seed ^ 0x0BAD_5EED_1234_5678);
    let scene_bb = super::synth::scene_box(objects);
    let diag = scene_bb.diagonal();
    let tilt_axis = Vector3::new(rng.range(-1.0, 1.0), 0.0, rng.range(-1.0, 1.0));
    let tilt = UnitQuaternion::from_axis_angle(
        &nalgebra::Unit::new_normalize(tilt_axis + Vector3::new(1e-9, 0.0, 0.0)),
        rng.range(0.0, o.max_tilt_deg).to_radians(),
    );
    let frame = Similarity {
        scale: rng.range(o.scale[0].ln(), o.scale[1].ln()).exp(),
        rotation: tilt * yaw(&mut rng),
        translation: V3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        ) * diag,
    };
    let truth: Vec<Similarity> = objects.iter().map(|t| frame.then_after(&t.pose)).collect();
    let placed = super::synth::placed(objects, &truth);
    let clouds: Vec<Cloud> = placed
        .iter()
        .enumerate()
        .map(|(i, v)| Cloud::sample(v, 20_000, seed ^ (i as u64 + 31)))
        .collect();
    let trees: Vec<KdTree> = clouds.iter().map(|c| KdTree::new(&c.points)).collect();
    let mut inputs = Vec::new();
    let mut removed = Vec::new();
    for (i, t) in objects.iter().enumerate() {
        let d_i = clouds[i].diagonal();
        let mut parts = placed[i].parts.clone();
        let total_tris: usize = parts.iter().map(|p| p.triangles.len()).sum();
        let target = o.triangles[0] + rng.below(o.triangles[1] - o.triangles[0] + 1);
        if total_tris < target {
            for p in &mut parts {
                let share = (target as f64 * p.triangles.len() as f64 / total_tris as f64) as usize;
                densify(p, share);
            }
        }
        // The contact: this object's sample closest to another object.
        let mut contact: Option<(f64, P3)> = None;
        for p in clouds[i].points.iter().step_by(4) {
            for (j, tr) in trees.iter().enumerate() {
                if j != i {
                    if let Some((_, d2)) = tr.nearest(p) {
                        if contact.is_none_or(|c| d2 < c.0) {
                            contact = Some((d2, *p));
                        }
                    }
                }
            }
        }
        let mut holes: Vec<(P3, f64)> = Vec::new();
        if let Some((_, c)) = contact {
            holes.push((c, o.contact_hole * d_i));
        }
        for _ in 0..o.random_holes {
            let c = clouds[i].points[rng.below(clouds[i].len())];
            holes.push((c, o.random_hole_radius * d_i));
        }
        let band = o.contact_band * d_i;
        let mut total = 0.0;
        let mut gone = 0.0;
        let mut out: Vec<VisualPart> = Vec::new();
        for p in &parts {
            let mut kept = Vec::with_capacity(p.triangles.len());
            for tr in &p.triangles {
                let v = tr.map(|k| p.positions[k as usize]);
                let a = triangle_area(&v);
                total += a;
                let c = P3::from((v[0].coords + v[1].coords + v[2].coords) / 3.0);
                // Ragged rims: each triangle's radius varies by up to 30 %.
                let jag = 1.0 + 0.3 * ((hash3(&c, seed) >> 11) as f64 / (1u64 << 53) as f64);
                let in_hole = holes.iter().any(|(h, r)| (c - h).norm() * jag < *r);
                let hidden = (0..objects.len()).any(|j| {
                    j != i
                        && trees[j]
                            .nearest(&c)
                            .is_some_and(|(_, d2)| d2.sqrt() * jag < band)
                });
                if in_hole || hidden {
                    gone += a;
                } else {
                    kept.push(*tr);
                }
            }
            let mut q = VisualPart {
                positions: p.positions.clone(),
                uvs: p.uvs.clone(),
                triangles: kept,
                material: p.material.clone(),
            };
            let sigma = o.noise * d_i;
            for v in &mut q.positions {
                let mut r = Rng::new(hash3(v, seed ^ 0xA5));
                *v += V3::new(r.normal(), r.normal(), r.normal()) * sigma;
            }
            // Its own copy of the texture, as when read from its own file.
            if let Some(tex) = &mut q.material.texture {
                tex.bytes = std::sync::Arc::new(tex.bytes.as_ref().clone());
            }
            for k in 0..3 {
                q.material.base_color[k] = (q.material.base_color[k]
                    * (1.0 + rng.range(-o.colour_gain, o.colour_gain)))
                .clamp(0.0, 1.0);
            }
            if !q.triangles.is_empty() {
                out.push(q);
            }
        }
        removed.push(gone / total.max(1e-300));
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

/// Points of an object for [`add_s`]: the estimate's samples and a dense truth set with normals.
pub struct AddS {
    model: Vec<P3>,
    dense: Cloud,
    tree: KdTree,
    spacing: f64,
}

impl AddS {
    /// 2,000 model samples and 40,000 truth samples of `visual` (object frame).
    pub fn new(visual: &VisualMesh) -> AddS {
        let model = Cloud::sample(visual, 2000, 0xADD5).points;
        let dense = Cloud::sample(visual, 40_000, 0xADD6);
        let tree = KdTree::new(&dense.points);
        let area = visual.area();
        AddS {
            model,
            dense,
            tree,
            spacing: (area / 40_000.0).sqrt(),
        }
    }

    /// Mean over the model samples placed by `est` of the distance to the surface placed by
    /// `truth`, over the diagonal of the object placed by `truth`. The distance to the truth
    /// surface is the point-to-plane distance of the nearest dense sample when the point lies
    /// within two sample spacings of it along the surface, else the distance to that sample.
    pub fn eval(&self, est: &Similarity, truth: &Similarity) -> f64 {
        // Work in the truth's object frame: est_in_truth = truth⁻¹ ∘ est.
        let inv = truth
            .matrix()
            .try_inverse()
            .expect("similarity is invertible");
        let m = inv * est.matrix();
        let mut sum = 0.0;
        for p in &self.model {
            let q = m.transform_point(p);
            let (j, d2) = self.tree.nearest(&q).expect("dense samples");
            let delta = q - self.dense.points[j];
            let n = self.dense.normals[j];
            let along = delta.dot(&n);
            let tangential = (d2 - along * along).max(0.0).sqrt();
            sum += if tangential < 2.0 * self.spacing {
                along.abs()
            } else {
                d2.sqrt()
            };
        }
        let diag = self.dense.diagonal();
        sum / self.model.len() as f64 / diag.max(1e-300)
    }
}

/// ADD-S of `est` against `truth` for an object (a fraction of its diagonal); see [`AddS`].
pub fn add_s(visual: &VisualMesh, est: &Similarity, truth: &Similarity) -> f64 {
    AddS::new(visual).eval(est, truth)
}
