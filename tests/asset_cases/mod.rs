//! Planted asset cases and engine judges shared by tests/assets/ and tests/asset_judges.rs:
//! one-link URDFs around exact boxes, the mug with a ball inside or beside its hull, two boxes on
//! a floor, the half-cylinder rocker; and how an engine's motion reads as a verdict.
#![allow(dead_code)]

use super::common::*;
use interact3d::validate::asset::{check_path, AssetCheckOptions};
use interact3d::validate::finding::{AssetReport, Finding};
use std::path::{Path, PathBuf};

pub fn pybullet_data() -> PathBuf {
    let out = std::process::Command::new(python())
        .args([
            "-c",
            "import pybullet_data;print(pybullet_data.getDataPath())",
        ])
        .output()
        .expect("python3 with pybullet (tests/python/requirements.txt)");
    assert!(out.status.success(), "pybullet_data not installed");
    PathBuf::from(String::from_utf8_lossy(&out.stdout).trim())
}

pub fn check(p: &Path) -> AssetReport {
    check_path(p, p.to_str().unwrap(), &AssetCheckOptions::default())
}

pub fn find<'a>(r: &'a AssetReport, id: &str) -> Vec<&'a Finding> {
    r.findings.iter().filter(|f| f.check == id).collect()
}

pub fn ids(r: &AssetReport) -> Vec<&str> {
    r.findings.iter().map(|f| f.check.as_str()).collect()
}

pub fn apple() -> String {
    shared()
        .join("datasets/objects/ycb/013_apple/textured.obj")
        .canonicalize()
        .unwrap()
        .display()
        .to_string()
}

pub fn mug() -> PathBuf {
    shared()
        .join("datasets/objects/gso/ACE_Coffee_Mug_Kristen_16_oz_cup/model.obj")
        .canonicalize()
        .unwrap()
}

pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// A one-link URDF: `inertial` and `geometry` blocks as given.
/// A closed box of half-extents `h` centred at the origin as OBJ text (8 vertices, 12 outward
/// triangles).
pub fn box_obj(h: [f64; 3]) -> String {
    let v: String = [
        (-1, -1, -1),
        (1, -1, -1),
        (1, 1, -1),
        (-1, 1, -1),
        (-1, -1, 1),
        (1, -1, 1),
        (1, 1, 1),
        (-1, 1, 1),
    ]
    .iter()
    .map(|(x, y, z)| {
        format!(
            "v {} {} {}\n",
            *x as f64 * h[0],
            *y as f64 * h[1],
            *z as f64 * h[2]
        )
    })
    .collect();
    v + "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n"
}

pub fn urdf(inertial: &str, visual: &str, collision: &str) -> String {
    format!(
        "<?xml version=\"1.0\"?>\n<robot name=\"t\">\n  <link name=\"obj\">\n{inertial}\n    <visual><geometry>{visual}</geometry></visual>\n    <collision><geometry>{collision}</geometry></collision>\n  </link>\n</robot>\n"
    )
}

pub fn inertial(mass: f64, i: [f64; 3], com: [f64; 3]) -> String {
    format!(
        "    <inertial>\n      <origin xyz=\"{} {} {}\"/>\n      <mass value=\"{mass}\"/>\n      <inertia ixx=\"{}\" iyy=\"{}\" izz=\"{}\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>\n    </inertial>",
        com[0], com[1], com[2], i[0], i[1], i[2]
    )
}

/// Exact inertia of a solid box of mass `m` and full extents `e` about its centre.
pub fn box_inertia(m: f64, e: [f64; 3]) -> [f64; 3] {
    [
        m * (e[1] * e[1] + e[2] * e[2]) / 12.0,
        m * (e[0] * e[0] + e[2] * e[2]) / 12.0,
        m * (e[0] * e[0] + e[1] * e[1]) / 12.0,
    ]
}

/// The mug (a concave collision mesh, welded) and a 1 cm ball placed in its cavity or beside it.
pub fn mug_scene(dir: &Path, name: &str, inside: bool) -> PathBuf {
    let m = interact3d::io::load_visual(&mug(), &Default::default())
        .unwrap()
        .geometry();
    let b = m.aabb().unwrap();
    let top: Vec<_> = m
        .vertices
        .iter()
        .filter(|v| v.z > b.max.z - 0.004)
        .collect();
    let cx = top.iter().map(|v| v.x).sum::<f64>() / top.len() as f64;
    let cy = top.iter().map(|v| v.y).sum::<f64>() / top.len() as f64;
    let (x, y, z) = if inside {
        (cx, cy, b.min.z + 0.5 * (b.max.z - b.min.z))
    } else {
        (b.max.x + 0.05, cy, b.min.z + 0.0101)
    };
    let xml = format!(
        r#"<mujoco model="{name}">
  <compiler angle="radian"/>
  <asset>
    <mesh name="mug" file="{}"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="1 1 0.1" pos="0 0 {}"/>
    <body name="mug">
      <geom name="mug_collision" type="mesh" mesh="mug"/>
    </body>
    <body name="ball" pos="{x} {y} {z}">
      <freejoint/>
      <inertial pos="0 0 0" mass="0.01" diaginertia="4e-7 4e-7 4e-7"/>
      <geom name="ball_collision" type="sphere" size="0.01"/>
    </body>
  </worldbody>
</mujoco>
"#,
        mug().display(),
        b.min.z
    );
    write(dir, &format!("{name}.xml"), &xml)
}

/// Two boxes (MJCF) `gap` apart along x (negative: overlapping), the lower `sink` below the floor.
pub fn boxes(dir: &Path, name: &str, gap: f64, sink: f64, tilt_deg: f64) -> PathBuf {
    let h = 0.025;
    let xml = format!(
        r#"<mujoco model="{name}">
  <worldbody>
    <geom name="floor" type="plane" size="1 1 0.1"/>
    <body name="a" pos="0 0 {}">
      <freejoint/>
      <geom type="box" size="{h} {h} {h}" density="500"/>
    </body>
    <body name="b" pos="{} 0 {}" euler="0 {tilt_deg} 0">
      <freejoint/>
      <geom type="box" size="0.01 0.01 0.1" density="500"/>
    </body>
  </worldbody>
</mujoco>
"#,
        h - sink,
        2.0 * h + gap + 0.3,
        if tilt_deg == 0.0 {
            0.1
        } else {
            0.1 * tilt_deg.to_radians().cos() + 0.01 * tilt_deg.to_radians().sin()
        }
    );
    let _ = 2.0 * h;
    write(dir, &format!("{name}.xml"), &xml)
}

/// A half-cylinder rocker (radius 5 cm, 20 cm long, round side down, 64 segments), density
/// 500 kg/m³, as a one-link URDF whose geometry is turned `tilt_deg` about the cylinder's axis,
/// with its exact inertial. At 0° it rests on its lowest line; tilted it rocks like a pendulum
/// (period 2π·sqrt((I_c + m(R−d)²)/(m g d)) = 0.55 s, d = 4R/3π) and, rolling without slipping
/// on a rigid floor, keeps its energy: it never comes to rest.
pub fn rocker(dir: &Path, name: &str, tilt_deg: f64) -> PathBuf {
    let (r, l, n) = (0.05f64, 0.2f64, 64usize);
    let mut obj = String::new();
    for x in [-l / 2.0, l / 2.0] {
        for k in 0..=n {
            let a = std::f64::consts::PI * (1.0 + k as f64 / n as f64);
            obj += &format!("v {x} {} {}\n", r * a.cos(), r * a.sin());
        }
    }
    let m1 = n + 1;
    let mut f = |a: usize, b: usize, c: usize| obj += &format!("f {} {} {}\n", a + 1, b + 1, c + 1);
    for k in 0..n {
        f(k, m1 + k, m1 + k + 1);
        f(k, m1 + k + 1, k + 1);
    }
    f(0, m1 + n, m1);
    f(0, n, m1 + n);
    for k in 1..n {
        f(0, k + 1, k);
        f(m1, m1 + k, m1 + k + 1);
    }
    write(dir, "rocker.obj", &obj);
    let mass = 500.0 * std::f64::consts::PI * r * r / 2.0 * l;
    let d = 4.0 * r / (3.0 * std::f64::consts::PI);
    let i = [
        mass * (r * r / 2.0 - d * d),
        mass * (l * l / 12.0 + r * r / 4.0 - d * d),
        mass * (l * l / 12.0 + r * r / 4.0),
    ];
    let t = tilt_deg.to_radians();
    let text = format!(
        "<robot name=\"{name}\">\n  <link name=\"rocker\">\n    <inertial>\n      <origin xyz=\"0 {} {}\" rpy=\"{t} 0 0\"/>\n      <mass value=\"{mass}\"/>\n      <inertia ixx=\"{}\" iyy=\"{}\" izz=\"{}\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>\n    </inertial>\n    <visual><origin rpy=\"{t} 0 0\"/><geometry><mesh filename=\"rocker.obj\"/></geometry></visual>\n    <collision><origin rpy=\"{t} 0 0\"/><geometry><mesh filename=\"rocker.obj\"/></geometry></collision>\n  </link>\n</robot>\n",
        d * t.sin(),
        -d * t.cos(),
        i[0],
        i[1],
        i[2]
    );
    write(dir, &format!("{name}.urdf"), &text)
}

/// The lift `validate` gives a file without a floor (its lowest collision point onto z = 0),
/// and each body's collision bounding-box diagonal.
pub fn placement(p: &Path) -> (f64, Vec<(String, f64)>) {
    let a = interact3d::io::asset::load(p, &Default::default()).unwrap();
    let mut low = f64::INFINITY;
    let mut diags = Vec::new();
    for b in &a.bodies {
        let pts: Vec<_> = b
            .hulls()
            .iter()
            .flat_map(|h| h.vertices.clone())
            .map(|v| b.pose * v)
            .collect();
        low = pts.iter().map(|v| v.z).fold(low, f64::min);
        if let Some(bb) = interact3d::mesh::Aabb::of_points(pts.iter()) {
            diags.push((b.name.clone(), bb.diagonal()));
        }
    }
    (if a.floor.is_some() { 0.0 } else { -low }, diags)
}

/// An engine's verdict from its motion: it moved as our settle test fails (over 10 % of the
/// body's diagonal, or turned over 30°) or still moved in the last second as our rest test
/// fails (over 1 mm or 1°).
pub fn engine_moves(motion: &serde_json::Value, window: &serde_json::Value, diag: f64) -> bool {
    let f = |v: &serde_json::Value, k: &str| v[k].as_f64().unwrap();
    f(motion, "moved") > 0.1 * diag
        || f(motion, "turned_deg") > 30.0
        || f(window, "moved") > 1e-3
        || f(window, "turned_deg") > 1.0
}

/// Our verdict on a body: a physics.settle or physics.rest finding about it.
pub fn we_say_moves(r: &AssetReport, body: &str) -> bool {
    r.findings
        .iter()
        .any(|f| (f.check == "physics.settle" || f.check == "physics.rest") && f.subject == body)
}
