//! MJCF reader (MuJoCo object files: Menagerie, robosuite, Google Scanned Objects) into an
//! [`Asset`].
//!
//! Entry point: [`read`] (called by [`crate::io::asset::load`]).
//!
//! Read: `<include>` (recursively, relative to the main file), `<frame>` and `<replicate>`
//! ([`crate::io::mjcf_frames`]; `<attach>` is a `file.unsupported` finding), mesh `refpos`/
//! `refquat`, `<default>` classes with
//! `class` and `childclass`, `<compiler angle meshdir assetdir eulerseq>` (angles in degrees
//! unless `angle="radian"`), mesh assets (`file`, `scale`, inline `vertex`; OBJ, STL, glTF and
//! legacy `.msh`), bodies (`pos`, `quat`, `euler`, `axisangle`, `xyaxes`, `zaxis`), `<inertial>`
//! (`diaginertia`/`fullinertia`, `pos`, orientation), geoms (box, sphere, capsule, cylinder,
//! ellipsoid, mesh, plane; `size` or `fromto`; `contype`/`conaffinity` for collision, `group`
//! ≥ 3 hidden), `density`/`mass`, `friction`, joints (`freejoint` or `type="free"`; other joints
//! make an `asset.articulated` finding), `<keyframe>`'s first key (`qpos` of free joints).
//! A body without joints is welded to its parent: under the world it is fixed, under another
//! body it is merged into that body; a file whose world holds one such body tree and nothing
//! else (no joint, no floor: an object model file) is checked as a free object, unless
//! [`ReadOptions::keep_welded`]. A plane on the world body is the floor.

use crate::error::Result;
use crate::io::asset::{
    combine, floats, mesh_pieces, Asset, AssetBody, AuthoredInertial, Geom, ReadIssue, ReadOptions,
    Shape, Source,
};
use crate::io::xml::Element;
use crate::mesh::{P3, V3};
use nalgebra::{Isometry3, Matrix3, Quaternion, Translation3, Unit, UnitQuaternion, Vector3};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Inline `<include file>` recursively (children of the included root take its place).
fn expand(e: &Element, base: &Path, opts: &ReadOptions, depth: usize) -> Result<Element> {
    let mut out = e.clone();
    out.children.clear();
    for c in &e.children {
        if c.name == "include" {
            if depth > 16 {
                return Err(c.error("includes nested more than 16 deep"));
            }
            let f = c
                .attr("file")
                .ok_or_else(|| c.error("include without file"))?;
            let p = base.join(f);
            if !p.is_file() {
                return Err(c.error(format!("included file {} not found", p.display())));
            }
            let inc = crate::io::xml::parse_file(&p, &opts.limits)?;
            let inc = expand(&inc, base, opts, depth + 1)?;
            out.children.extend(inc.children);
        } else {
            out.children.push(expand(c, base, opts, depth)?);
        }
    }
    Ok(out)
}

pub(crate) struct Compiler {
    degrees: bool,
    eulerseq: String,
    meshdir: PathBuf,
}

/// Default classes: class → (parent class, element name → attributes).
type Defaults = BTreeMap<String, (Option<String>, BTreeMap<String, Vec<(String, String)>>)>;

fn collect_defaults(e: &Element, parent: Option<&str>, out: &mut Defaults) {
    let class = e.attr("class").unwrap_or("main").to_string();
    let mut own = BTreeMap::new();
    for c in &e.children {
        if c.name != "default" {
            own.insert(c.name.clone(), c.attrs.clone());
        }
    }
    out.insert(class.clone(), (parent.map(str::to_string), own));
    for c in e.children_named("default") {
        collect_defaults(c, Some(&class), out);
    }
}

/// The element with its class defaults applied (the element's own attributes win).
fn with_defaults(e: &Element, class: &str, defaults: &Defaults) -> Element {
    let class = e.attr("class").unwrap_or(class);
    let mut chain = Vec::new();
    let mut cur = Some(class.to_string());
    while let Some(c) = cur {
        let Some((p, own)) = defaults.get(&c) else {
            break;
        };
        chain.push(own.get(&e.name).cloned().unwrap_or_default());
        cur = p.clone();
        if chain.len() > 64 {
            break;
        }
    }
    let mut out = e.clone();
    for attrs in chain.iter() {
        for (k, v) in attrs {
            if out.attr(k).is_none() {
                out.attrs.push((k.clone(), v.clone()));
            }
        }
    }
    out
}

fn axis_rot(axis: char, a: f64) -> UnitQuaternion<f64> {
    let ax = match axis.to_ascii_lowercase() {
        'x' => Vector3::x_axis(),
        'y' => Vector3::y_axis(),
        _ => Vector3::z_axis(),
    };
    UnitQuaternion::from_axis_angle(&ax, a)
}

/// Orientation of an element from quat / euler / axisangle / xyaxes / zaxis.
fn orientation(e: &Element, c: &Compiler) -> Result<UnitQuaternion<f64>> {
    let ang = |x: f64| if c.degrees { x.to_radians() } else { x };
    if let Some(q) = floats(e, "quat")? {
        if q.len() != 4 || q.iter().all(|x| *x == 0.0) {
            return Err(e.error("quat needs 4 numbers, not all zero"));
        }
        return Ok(UnitQuaternion::new_normalize(Quaternion::new(
            q[0], q[1], q[2], q[3],
        )));
    }
    if let Some(v) = floats(e, "euler")? {
        if v.len() != 3 {
            return Err(e.error("euler needs 3 numbers"));
        }
        let mut r = UnitQuaternion::identity();
        for (k, ch) in c.eulerseq.chars().take(3).enumerate() {
            let q = axis_rot(ch, ang(v[k]));
            // Lower case: axes that move with the frame (intrinsic); upper case: fixed axes.
            r = if ch.is_ascii_lowercase() {
                r * q
            } else {
                q * r
            };
        }
        return Ok(r);
    }
    if let Some(v) = floats(e, "axisangle")? {
        if v.len() != 4 {
            return Err(e.error("axisangle needs 4 numbers"));
        }
        let ax = Vector3::new(v[0], v[1], v[2]);
        if ax.norm() == 0.0 {
            return Err(e.error("axisangle with a zero axis"));
        }
        return Ok(UnitQuaternion::from_axis_angle(
            &Unit::new_normalize(ax),
            ang(v[3]),
        ));
    }
    if let Some(v) = floats(e, "xyaxes")? {
        if v.len() != 6 {
            return Err(e.error("xyaxes needs 6 numbers"));
        }
        let x = Vector3::new(v[0], v[1], v[2]).normalize();
        let y0 = Vector3::new(v[3], v[4], v[5]);
        let y = (y0 - x * x.dot(&y0)).normalize();
        let z = x.cross(&y);
        if !z.iter().all(|c| c.is_finite()) {
            return Err(e.error("xyaxes are parallel or zero"));
        }
        let m = Matrix3::from_columns(&[x, y, z]);
        return Ok(UnitQuaternion::from_matrix(&m));
    }
    if let Some(v) = floats(e, "zaxis")? {
        if v.len() != 3 {
            return Err(e.error("zaxis needs 3 numbers"));
        }
        let z = Vector3::new(v[0], v[1], v[2]);
        return UnitQuaternion::rotation_between(&Vector3::z(), &z)
            .or_else(|| {
                (z.z < 0.0).then(|| {
                    UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
                })
            })
            .ok_or_else(|| e.error("zaxis is zero"));
    }
    Ok(UnitQuaternion::identity())
}

pub(crate) fn frame(e: &Element, c: &Compiler) -> Result<Isometry3<f64>> {
    let p = match floats(e, "pos")? {
        Some(p) if p.len() == 3 => p,
        Some(_) => return Err(e.error("pos needs 3 numbers")),
        None => vec![0.0; 3],
    };
    Ok(Isometry3::from_parts(
        Translation3::new(p[0], p[1], p[2]),
        orientation(e, c)?,
    ))
}

struct MeshAsset {
    src: Source,
    file: Option<PathBuf>,
    scale: V3,
    vertex: Option<Vec<f64>>,
    /// `refpos`/`refquat`: the frame the vertices are written in (MuJoCo subtracts refpos
    /// and turns by the conjugate of refquat, in the file's units, before `scale`).
    reference: Isometry3<f64>,
}

struct Ctx<'a> {
    c: Compiler,
    defaults: Defaults,
    meshes: BTreeMap<String, MeshAsset>,
    opts: &'a ReadOptions,
    issues: Vec<ReadIssue>,
    /// Loaded mesh pieces, by asset name.
    cache: BTreeMap<String, Option<Vec<crate::mesh::Mesh>>>,
}

fn num(e: &Element, k: &str) -> Result<Option<f64>> {
    Ok(floats(e, k)?.and_then(|v| v.first().copied()))
}

impl Ctx<'_> {
    fn geom(&mut self, raw: &Element, class: &str, body: &str) -> Result<Option<Geom>> {
        let g = with_defaults(raw, class, &self.defaults);
        let ty = g.attr("type").unwrap_or("sphere");
        let size = floats(&g, "size")?.unwrap_or_default();
        let mut pose = frame(&g, &self.c)?;
        let sz = |k: usize| -> Result<f64> {
            size.get(k)
                .copied()
                .ok_or_else(|| g.error(format!("{ty} needs size[{k}]")))
        };
        let mut half_from_to = None;
        if let Some(ft) = floats(&g, "fromto")? {
            if ft.len() != 6 {
                return Err(g.error("fromto needs 6 numbers"));
            }
            let a = V3::new(ft[0], ft[1], ft[2]);
            let b = V3::new(ft[3], ft[4], ft[5]);
            let d = b - a;
            let rot = UnitQuaternion::rotation_between(&Vector3::z(), &d).unwrap_or_else(|| {
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
            });
            pose = Isometry3::from_parts(Translation3::from((a + b) / 2.0), rot);
            half_from_to = Some(d.norm() / 2.0);
        }
        let shape = match ty {
            "sphere" => Shape::Sphere(sz(0)?),
            "capsule" => Shape::Capsule(sz(0)?, half_from_to.map_or_else(|| sz(1), Ok)?),
            "cylinder" => Shape::Cylinder(sz(0)?, half_from_to.map_or_else(|| sz(1), Ok)?),
            "box" => Shape::Box(V3::new(
                sz(0)?,
                sz(1)?,
                half_from_to.map_or_else(|| sz(2), Ok)?,
            )),
            "ellipsoid" => Shape::Ellipsoid(V3::new(
                sz(0)?,
                sz(1)?,
                half_from_to.map_or_else(|| sz(2), Ok)?,
            )),
            "plane" => Shape::Plane,
            "mesh" => {
                let name = g
                    .attr("mesh")
                    .ok_or_else(|| g.error("mesh geom without mesh"))?;
                match self.mesh(name, &g)? {
                    Some((file, pieces)) => Shape::Mesh { file, pieces },
                    None => return Ok(None),
                }
            }
            other => {
                self.issues.push(ReadIssue {
                    check: "file.unsupported",
                    subject: body.to_string(),
                    src: Source::of(raw),
                    message: format!("geom type {other:?} is not read; left out"),
                });
                return Ok(None);
            }
        };
        let contype = num(&g, "contype")?.unwrap_or(1.0);
        let conaff = num(&g, "conaffinity")?.unwrap_or(1.0);
        let group = num(&g, "group")?.unwrap_or(0.0);
        let collision = contype != 0.0 || conaff != 0.0;
        Ok(Some(Geom {
            name: g
                .attr("name")
                .map(str::to_string)
                .unwrap_or_else(|| format!("{body}/geom@{}", raw.line)),
            shape,
            pose,
            collision,
            visual: group < 3.0,
            density: Some(num(&g, "density")?.unwrap_or(crate::inertia::DEFAULT_DENSITY)),
            mass: num(&g, "mass")?,
            friction: Some(num(&g, "friction")?.unwrap_or(1.0)),
            src: Source::of(raw),
        }))
    }

    fn mesh(
        &mut self,
        name: &str,
        g: &Element,
    ) -> Result<Option<(PathBuf, Vec<crate::mesh::Mesh>)>> {
        let Some(a) = self.meshes.get(name) else {
            return Err(g.error(format!("mesh {name:?} is not defined in <asset>")));
        };
        let key = name.to_string();
        if !self.cache.contains_key(&key) {
            let got = if let Some(v) = &a.vertex {
                let pts: Vec<P3> = v
                    .chunks_exact(3)
                    .map(|c| P3::new(c[0] * a.scale.x, c[1] * a.scale.y, c[2] * a.scale.z))
                    .collect();
                crate::decompose::Hull::from_points(&pts).map(|h| vec![h.mesh()])
            } else {
                let file = a.file.clone().unwrap_or_default();
                if !file.is_file() {
                    self.issues.push(ReadIssue {
                        check: "file.mesh_missing",
                        subject: name.to_string(),
                        src: a.src.clone(),
                        message: format!("mesh file {} not found", file.display()),
                    });
                    None
                } else {
                    match mesh_pieces(&file, a.scale, false, &self.opts.limits) {
                        Ok(p) => Some(p),
                        Err(e) => {
                            self.issues.push(ReadIssue {
                                check: "file.mesh_unreadable",
                                subject: name.to_string(),
                                src: a.src.clone(),
                                message: format!("mesh cannot be read: {e}"),
                            });
                            None
                        }
                    }
                }
            };
            // MuJoCo moves the file's vertices into the reference frame, then scales them.
            let back = a.reference.inverse();
            let s = a.scale;
            let got = got.map(|pieces| {
                if a.reference == Isometry3::identity() || s.iter().any(|x| *x == 0.0) {
                    return pieces;
                }
                pieces
                    .into_iter()
                    .map(|m| {
                        let v = m
                            .vertices
                            .iter()
                            .map(|v| back * P3::from(v.coords.component_div(&s)))
                            .map(|v| P3::from(v.coords.component_mul(&s)))
                            .collect();
                        crate::mesh::Mesh::new(v, m.triangles)
                    })
                    .collect::<Vec<_>>()
            });
            self.cache.insert(key.clone(), got);
        }
        let file = a.file.clone().unwrap_or_default();
        Ok(self.cache[&key].clone().map(|p| (file, p)))
    }
}

/// One body of the tree, flattened.
struct Flat {
    name: String,
    src: Source,
    world: Isometry3<f64>,
    /// Index of the rigid group it belongs to (its own index when it starts one).
    group: usize,
    starts_group: bool,
    free: bool,
    fixed: bool,
    geoms: Vec<Geom>,
    inertial: Option<AuthoredInertial>,
    /// qpos index of its free joint.
    qpos: Option<usize>,
}

/// Read a parsed MJCF.
pub fn read(path: &Path, root: &Element, opts: &ReadOptions) -> Result<Asset> {
    let base = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let root = expand(root, &base, opts, 0)?;
    let mut c = Compiler {
        degrees: true,
        eulerseq: "xyz".into(),
        meshdir: base.clone(),
    };
    for comp in root.children_named("compiler") {
        if let Some(a) = comp.attr("angle") {
            c.degrees = match a {
                "degree" => true,
                "radian" => false,
                _ => return Err(comp.error(format!("angle={a:?}: expected degree or radian"))),
            };
        }
        if let Some(s) = comp.attr("eulerseq") {
            if s.len() != 3 || !s.chars().all(|ch| "xyzXYZ".contains(ch)) {
                return Err(comp.error(format!("eulerseq={s:?}: expected 3 of xyzXYZ")));
            }
            c.eulerseq = s.to_string();
        }
        if let Some(d) = comp.attr("assetdir") {
            c.meshdir = base.join(d);
        }
        if let Some(d) = comp.attr("meshdir") {
            c.meshdir = base.join(d);
        }
    }
    let mut early_issues = Vec::new();
    let root = crate::io::mjcf_frames::unfold(&root, &c, &mut early_issues)?;
    let mut defaults = Defaults::new();
    for d in root.children_named("default") {
        collect_defaults(d, None, &mut defaults);
    }
    let mut meshes = BTreeMap::new();
    for a in root.children_named("asset") {
        for m in a.children_named("mesh") {
            let m = with_defaults(m, "main", &defaults);
            let file = m.attr("file").map(|f| c.meshdir.join(f));
            let name = match (m.attr("name"), &file) {
                (Some(n), _) => n.to_string(),
                (None, Some(f)) => f
                    .file_stem()
                    .and_then(|s| s.to_str())
                    .unwrap_or("")
                    .to_string(),
                (None, None) => return Err(m.error("mesh without name or file")),
            };
            let s = floats(&m, "scale")?.unwrap_or(vec![1.0; 3]);
            if s.len() != 3 {
                return Err(m.error("scale needs 3 numbers"));
            }
            let vertex = floats(&m, "vertex")?;
            let refpos = match floats(&m, "refpos")? {
                Some(p) if p.len() == 3 => V3::new(p[0], p[1], p[2]),
                Some(_) => return Err(m.error("refpos needs 3 numbers")),
                None => V3::zeros(),
            };
            let refquat = match floats(&m, "refquat")? {
                Some(q) if q.len() == 4 && q.iter().any(|x| *x != 0.0) => {
                    UnitQuaternion::new_normalize(Quaternion::new(q[0], q[1], q[2], q[3]))
                }
                Some(_) => return Err(m.error("refquat needs 4 numbers, not all zero")),
                None => UnitQuaternion::identity(),
            };
            meshes.insert(
                name,
                MeshAsset {
                    src: Source::of(&m),
                    file,
                    scale: V3::new(s[0], s[1], s[2]),
                    vertex,
                    reference: Isometry3::from_parts(Translation3::from(refpos), refquat),
                },
            );
        }
    }
    let mut ctx = Ctx {
        c,
        defaults,
        meshes,
        opts,
        issues: early_issues,
        cache: BTreeMap::new(),
    };
    let mut flats: Vec<Flat> = Vec::new();
    let mut floor = None;
    let mut world_geoms = Vec::new();
    let mut nq = 0usize;
    for wb in root.children_named("worldbody") {
        for g in wb.children_named("geom") {
            if let Some(geom) = ctx.geom(g, "main", "world")? {
                if let Shape::Plane = geom.shape {
                    floor.get_or_insert((geom.pose.translation.z, geom.src.clone()));
                } else {
                    world_geoms.push(geom);
                }
            }
        }
        for b in wb.children_named("body") {
            walk(
                b,
                &Isometry3::identity(),
                None,
                "main",
                &mut ctx,
                &mut flats,
                &mut nq,
            )?;
        }
    }
    // Keyframe 0: free joints' qpos.
    if let Some(key) = root
        .children_named("keyframe")
        .flat_map(|k| k.children_named("key"))
        .next()
    {
        if let Some(q) = floats(key, "qpos")? {
            if q.len() != nq {
                return Err(key.error(format!("qpos has {} numbers, the model has {nq}", q.len())));
            }
            for f in flats.iter_mut().filter(|f| f.free) {
                let k = f.qpos.unwrap_or(0);
                f.world = Isometry3::from_parts(
                    Translation3::new(q[k], q[k + 1], q[k + 2]),
                    UnitQuaternion::new_normalize(Quaternion::new(
                        q[k + 3],
                        q[k + 4],
                        q[k + 5],
                        q[k + 6],
                    )),
                );
            }
        }
    }
    let mut bodies = Vec::new();
    if !world_geoms.is_empty() {
        bodies.push(AssetBody {
            name: "world".into(),
            src: Source::of(root.child("worldbody").unwrap_or(&root)),
            pose: Isometry3::identity(),
            fixed: true,
            geoms: world_geoms,
            inertial: None,
            merged: Vec::new(),
        });
    }
    // Merge welded children into their group's first body.
    for gi in 0..flats.len() {
        if !flats[gi].starts_group {
            continue;
        }
        let head = flats[gi].world;
        let mut geoms = Vec::new();
        let mut parts = Vec::new();
        let mut merged = Vec::new();
        let mut authored_any = false;
        let mut first_src = None;
        for f in flats.iter().filter(|f| f.group == gi) {
            let rel = head.inverse() * f.world;
            let own: Vec<Geom> = f
                .geoms
                .iter()
                .map(|g| {
                    let mut g = g.clone();
                    g.pose = rel * g.pose;
                    g
                })
                .collect();
            let tmp = AssetBody {
                name: f.name.clone(),
                src: f.src.clone(),
                pose: Isometry3::identity(),
                fixed: false,
                geoms: own.clone(),
                inertial: None,
                merged: Vec::new(),
            };
            match &f.inertial {
                Some(a) => {
                    authored_any = true;
                    first_src.get_or_insert(a.src.clone());
                    let r = rel.rotation.to_rotation_matrix();
                    parts.push(crate::inertia::Inertial {
                        com: rel * a.com,
                        inertia: r.matrix() * a.inertia * r.matrix().transpose(),
                        ..a.inertial()
                    });
                }
                None => parts.extend(crate::io::asset::geometric_inertial(&tmp)),
            }
            geoms.extend(own);
            if !std::ptr::eq(f, &flats[gi]) {
                merged.push(f.name.clone());
            }
        }
        let inertial = if authored_any {
            if parts.len() == 1 {
                flats[gi].inertial.clone()
            } else {
                combine(&parts).map(|i| AuthoredInertial {
                    mass: i.mass,
                    com: i.com,
                    inertia: i.inertia,
                    src: first_src.clone().unwrap_or(flats[gi].src.clone()),
                })
            }
        } else {
            None
        };
        bodies.push(AssetBody {
            name: flats[gi].name.clone(),
            src: flats[gi].src.clone(),
            pose: head,
            fixed: flats[gi].fixed,
            geoms,
            inertial,
            merged,
        });
    }
    // An object model file: one welded body tree and nothing else in the world. MuJoCo welds
    // it, but it is written to be placed into a scene: check it as a free object.
    let lone = bodies.len() == 1 && bodies[0].fixed && nq == 0 && floor.is_none();
    if lone && !opts.keep_welded {
        let b = &mut bodies[0];
        b.fixed = false;
        ctx.issues.push(ReadIssue {
            check: "asset.free_object",
            subject: b.name.clone(),
            src: b.src.clone(),
            message: format!(
                "body {} has no joint and is alone in the world: checked as a free object resting on a ground plane (MuJoCo alone would weld it; --keep-welded checks it welded)",
                b.name
            ),
        });
    }
    Ok(Asset {
        name: root.attr("model").unwrap_or("MuJoCo Model").to_string(),
        file: path.to_path_buf(),
        format: "mjcf",
        bodies,
        floor,
        issues: ctx.issues,
    })
}

fn walk(
    b: &Element,
    parent: &Isometry3<f64>,
    parent_group: Option<usize>,
    class: &str,
    ctx: &mut Ctx,
    flats: &mut Vec<Flat>,
    nq: &mut usize,
) -> Result<()> {
    let childclass = b.attr("childclass").unwrap_or(class).to_string();
    let name = b
        .attr("name")
        .map(str::to_string)
        .unwrap_or_else(|| format!("body@{}", b.line));
    let world = parent * frame(b, &ctx.c)?;
    let mut free = false;
    let mut qpos = None;
    let mut moving = None;
    for j in &b.children {
        let ty = match j.name.as_str() {
            "freejoint" => "free".to_string(),
            "joint" => with_defaults(j, &childclass, &ctx.defaults)
                .attr("type")
                .unwrap_or("hinge")
                .to_string(),
            _ => continue,
        };
        match ty.as_str() {
            "free" => {
                free = true;
                qpos = Some(*nq);
                *nq += 7;
            }
            "ball" => {
                moving.get_or_insert((ty.clone(), Source::of(j)));
                *nq += 4
            }
            _ => {
                moving.get_or_insert((ty.clone(), Source::of(j)));
                *nq += 1
            }
        }
    }
    if let Some((ty, src)) = &moving {
        ctx.issues.push(ReadIssue {
            check: "asset.articulated",
            subject: name.clone(),
            src: src.clone(),
            message: format!(
                "body has a {ty} joint: an articulated mechanism is out of scope; it is checked as welded to its parent"
            ),
        });
    }
    let idx = flats.len();
    let starts_group = free || parent_group.is_none();
    let group = if starts_group {
        idx
    } else {
        parent_group.unwrap_or(idx)
    };
    let mut geoms = Vec::new();
    for g in b.children_named("geom") {
        if let Some(x) = ctx.geom(g, &childclass, &name)? {
            if let Shape::Plane = x.shape {
                continue;
            }
            geoms.push(x);
        }
    }
    let inertial = match b.child("inertial") {
        Some(i) => {
            let f = frame(i, &ctx.c)?;
            let mass = num(i, "mass")?.ok_or_else(|| i.error("inertial without mass"))?;
            let m = if let Some(d) = floats(i, "diaginertia")? {
                if d.len() != 3 {
                    return Err(i.error("diaginertia needs 3 numbers"));
                }
                Matrix3::from_diagonal(&Vector3::new(d[0], d[1], d[2]))
            } else if let Some(d) = floats(i, "fullinertia")? {
                if d.len() != 6 {
                    return Err(i.error("fullinertia needs 6 numbers"));
                }
                Matrix3::new(d[0], d[3], d[4], d[3], d[1], d[5], d[4], d[5], d[2])
            } else {
                return Err(i.error("inertial without diaginertia or fullinertia"));
            };
            let r = f.rotation.to_rotation_matrix();
            Some(AuthoredInertial {
                mass,
                com: P3::from(f.translation.vector),
                inertia: r.matrix() * m * r.matrix().transpose(),
                src: Source::of(i),
            })
        }
        None => None,
    };
    flats.push(Flat {
        name,
        src: Source::of(b),
        world,
        group,
        starts_group,
        free,
        fixed: !free,
        geoms,
        inertial,
        qpos,
    });
    for c in b.children_named("body") {
        walk(c, &world, Some(group), &childclass, ctx, flats, nq)?;
    }
    Ok(())
}
