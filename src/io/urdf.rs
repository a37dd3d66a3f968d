//! URDF reader (PyBullet / ROS style rigid objects) into an [`Asset`].
//!
//! Entry point: [`read`] (called by [`crate::io::asset::load`]).
//!
//! Read: links with `<inertial>` (origin xyz/rpy, mass, inertia), `<visual>` and `<collision>`
//! (origin; box, cylinder, sphere, mesh with scale), `<contact><lateral_friction>`, joints.
//! Fixed joints merge the child link into its parent (mass properties summed). A moving joint
//! makes the file an articulated robot: one `asset.articulated` finding, and its links are
//! merged as if welded so their geometry and mass can still be checked. A root link of mass 0
//! is static (PyBullet's rule). Mesh paths: `package://NAME/...` from `--package NAME=DIR`, else
//! from a folder called NAME above the file, else the file's own folder; `file://` and relative
//! paths as written. No ROS tools are run.

use crate::error::Result;
use crate::io::asset::{
    floats_n, mesh_pieces, Asset, AssetBody, AuthoredInertial, Geom, ReadIssue, ReadOptions, Shape,
    Source,
};
use crate::io::xml::Element;
use crate::mesh::{P3, V3};
use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// `<origin xyz rpy>` of an element (identity when absent).
fn origin(e: &Element) -> Result<Isometry3<f64>> {
    let Some(o) = e.child("origin") else {
        return Ok(Isometry3::identity());
    };
    let xyz = floats_n(o, "xyz", 3)?.unwrap_or(vec![0.0; 3]);
    let rpy = floats_n(o, "rpy", 3)?.unwrap_or(vec![0.0; 3]);
    Ok(Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    ))
}

/// Resolve a mesh `filename` of a URDF.
pub fn resolve(file: &Path, name: &str, opts: &ReadOptions) -> Option<PathBuf> {
    let dir = file.parent().unwrap_or(Path::new("."));
    if let Some(rest) = name.strip_prefix("package://") {
        let (pkg, rel) = rest.split_once('/').unwrap_or((rest, ""));
        let mut cands: Vec<PathBuf> = opts
            .packages
            .iter()
            .filter(|(n, _)| n == pkg)
            .map(|(_, d)| d.join(rel))
            .collect();
        for a in dir.ancestors() {
            if a.file_name().and_then(|n| n.to_str()) == Some(pkg) {
                cands.push(a.join(rel));
            }
        }
        cands.push(dir.join(rel));
        return cands.into_iter().find(|c| c.is_file());
    }
    let p = match name.strip_prefix("file://") {
        Some(abs) => PathBuf::from(abs),
        None if Path::new(name).is_absolute() => PathBuf::from(name),
        None => dir.join(name),
    };
    p.is_file().then_some(p)
}

struct Link {
    geoms: Vec<Geom>,
    inertial: Option<AuthoredInertial>,
    src: Source,
}

/// Read a parsed URDF.
pub fn read(path: &Path, root: &Element, opts: &ReadOptions) -> Result<Asset> {
    let mut issues = Vec::new();
    let mut links: BTreeMap<String, Link> = BTreeMap::new();
    let mut order = Vec::new();
    for l in root.children_named("link") {
        let name = l
            .attr("name")
            .ok_or_else(|| l.error("link without a name"))?
            .to_string();
        let mut geoms = Vec::new();
        let friction = l
            .child("contact")
            .and_then(|c| c.child("lateral_friction"))
            .map(|f| floats_n(f, "value", 1))
            .transpose()?
            .flatten()
            .map(|v| v[0]);
        for (tag, collision) in [("visual", false), ("collision", true)] {
            for (k, g) in l.children_named(tag).enumerate() {
                let pose = origin(g)?;
                let Some(geo) = g.child("geometry").and_then(|x| x.children.first()) else {
                    return Err(g.error("no <geometry>"));
                };
                let shape = match geo.name.as_str() {
                    "box" => {
                        let s = floats_n(geo, "size", 3)?
                            .ok_or_else(|| geo.error("box without size"))?;
                        Shape::Box(V3::new(s[0], s[1], s[2]) / 2.0)
                    }
                    "sphere" => Shape::Sphere(
                        floats_n(geo, "radius", 1)?
                            .ok_or_else(|| geo.error("sphere without radius"))?[0],
                    ),
                    "cylinder" => {
                        let r = floats_n(geo, "radius", 1)?
                            .ok_or_else(|| geo.error("cylinder without radius"))?[0];
                        let h = floats_n(geo, "length", 1)?
                            .ok_or_else(|| geo.error("cylinder without length"))?[0];
                        Shape::Cylinder(r, h / 2.0)
                    }
                    "mesh" => {
                        let fname = geo
                            .attr("filename")
                            .ok_or_else(|| geo.error("mesh without filename"))?;
                        let s = floats_n(geo, "scale", 3)?.unwrap_or(vec![1.0; 3]);
                        let Some(file) = resolve(path, fname, opts) else {
                            issues.push(ReadIssue {
                                check: "file.mesh_missing",
                                subject: name.clone(),
                                src: Source::of(geo),
                                message: format!(
                                    "mesh {fname:?} not found (package:// paths need --package NAME=DIR)"
                                ),
                            });
                            continue;
                        };
                        match mesh_pieces(&file, V3::new(s[0], s[1], s[2]), true, &opts.limits) {
                            Ok(pieces) => Shape::Mesh { file, pieces },
                            Err(e) => {
                                issues.push(ReadIssue {
                                    check: "file.mesh_unreadable",
                                    subject: name.clone(),
                                    src: Source::of(geo),
                                    message: format!("mesh {fname:?} cannot be read: {e}"),
                                });
                                continue;
                            }
                        }
                    }
                    other => return Err(geo.error(format!("unknown geometry <{other}>"))),
                };
                geoms.push(Geom {
                    name: g
                        .attr("name")
                        .map(str::to_string)
                        .unwrap_or_else(|| format!("{name}/{tag}{k}")),
                    shape,
                    pose,
                    collision,
                    visual: !collision,
                    density: None,
                    mass: None,
                    friction,
                    src: Source::of(g),
                });
            }
        }
        let inertial = match l.child("inertial") {
            Some(i) => {
                let o = origin(i)?;
                let mass = i
                    .child("mass")
                    .map(|m| floats_n(m, "value", 1))
                    .transpose()?
                    .flatten()
                    .map(|v| v[0])
                    .unwrap_or(0.0);
                let it = i.child("inertia");
                let get = |k: &str| -> Result<f64> {
                    Ok(match it {
                        Some(e) => floats_n(e, k, 1)?.map(|v| v[0]).unwrap_or(0.0),
                        None => 0.0,
                    })
                };
                let (xx, xy, xz, yy, yz, zz) = (
                    get("ixx")?,
                    get("ixy")?,
                    get("ixz")?,
                    get("iyy")?,
                    get("iyz")?,
                    get("izz")?,
                );
                let m = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
                let r = o.rotation.to_rotation_matrix();
                Some(AuthoredInertial {
                    mass,
                    com: P3::from(o.translation.vector),
                    inertia: r.matrix() * m * r.matrix().transpose(),
                    src: Source::of(i),
                })
            }
            None => None,
        };
        order.push(name.clone());
        links.insert(
            name,
            Link {
                geoms,
                inertial,
                src: Source::of(l),
            },
        );
    }
    if links.is_empty() {
        return Err(root.error("no <link>"));
    }
    // Joints: child → (parent, origin, type).
    let mut parent: BTreeMap<String, (String, Isometry3<f64>)> = BTreeMap::new();
    let mut moving = Vec::new();
    for j in root.children_named("joint") {
        let ty = j.attr("type").unwrap_or("fixed");
        let p = j.child("parent").and_then(|e| e.attr("link"));
        let c = j.child("child").and_then(|e| e.attr("link"));
        let (Some(p), Some(c)) = (p, c) else {
            return Err(j.error("joint without parent or child link"));
        };
        if !links.contains_key(p) || !links.contains_key(c) {
            return Err(j.error(format!("joint between unknown links {p:?} and {c:?}")));
        }
        if ty != "fixed" {
            moving.push((
                j.attr("name").unwrap_or("?").to_string(),
                ty.to_string(),
                Source::of(j),
            ));
        }
        parent.insert(c.to_string(), (p.to_string(), origin(j)?));
    }
    let roots: Vec<&String> = order.iter().filter(|n| !parent.contains_key(*n)).collect();
    let [root_name] = roots.as_slice() else {
        return Err(root.error(format!(
            "links must form one tree; roots: {}",
            roots
                .iter()
                .map(|s| s.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    };
    let root_name = (*root_name).clone();
    if !moving.is_empty() {
        let (jn, ty, src) = &moving[0];
        issues.push(ReadIssue {
            check: "asset.articulated",
            subject: root_name.clone(),
            src: src.clone(),
            message: format!(
                "{} moving joint(s) (first: {jn:?}, {ty}): an articulated robot is out of scope; its links are checked as one rigid part",
                moving.len()
            ),
        });
    }
    // Every link's pose relative to the root (joints at zero), then merge into the root.
    let mut rel = BTreeMap::new();
    for n in &order {
        let mut t = Isometry3::identity();
        let mut cur = n.clone();
        let mut depth = 0;
        while let Some((p, o)) = parent.get(&cur) {
            t = o * t;
            cur = p.clone();
            depth += 1;
            if depth > order.len() {
                return Err(root.error("joints form a cycle"));
            }
        }
        rel.insert(n.clone(), t);
    }
    let mut geoms = Vec::new();
    let mut parts = Vec::new();
    let mut merged = Vec::new();
    for n in &order {
        let l = &links[n];
        let t = rel[n];
        for g in &l.geoms {
            let mut g = g.clone();
            g.pose = t * g.pose;
            geoms.push(g);
        }
        if let Some(i) = &l.inertial {
            let r = t.rotation.to_rotation_matrix();
            parts.push(AuthoredInertial {
                mass: i.mass,
                com: t * i.com,
                inertia: r.matrix() * i.inertia * r.matrix().transpose(),
                src: i.src.clone(),
            });
        }
        if n != &root_name {
            merged.push(n.clone());
        }
    }
    let total: f64 = parts.iter().map(|p| p.mass).sum();
    let inertial = match parts.len() {
        0 => None,
        1 => Some(parts.remove(0)),
        _ => {
            let ins: Vec<_> = parts
                .iter()
                .filter(|p| p.mass > 0.0)
                .map(|p| p.inertial())
                .collect();
            crate::io::asset::combine(&ins).map(|c| AuthoredInertial {
                mass: c.mass,
                com: c.com,
                inertia: c.inertia,
                src: parts[0].src.clone(),
            })
        }
    };
    let root_link = &links[&root_name];
    let fixed = root_name == "world" || (inertial.is_some() && total == 0.0);
    let body = AssetBody {
        name: root_name.clone(),
        src: root_link.src.clone(),
        pose: Isometry3::identity(),
        fixed,
        geoms,
        inertial: if fixed { None } else { inertial },
        merged,
    };
    Ok(Asset {
        name: root
            .attr("name")
            .map(str::to_string)
            .unwrap_or_else(|| root_name.clone()),
        file: path.to_path_buf(),
        format: "urdf",
        bodies: vec![body],
        floor: None,
        issues,
    })
}
