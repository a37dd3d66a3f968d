//! MJCF tree rewriting before the bodies are read: `<frame>` and `<replicate>` are unfolded into
//! the poses of the elements they hold, and `<attach>` (a body from another model) is named as
//! not read.
//!
//! Entry point: [`unfold`] (called by [`crate::io::mjcf::read`] once the compiler's angle unit
//! and Euler sequence are known).
//!
//! A frame's pose is composed into the `pos`/`quat` of each body, geom, site, camera and light
//! it holds (a geom's `fromto` end points are moved instead), and its `childclass` becomes the
//! `childclass` of those bodies and the `class` of those geoms that name none. A replicate's
//! copy `i` (0-based) sits at `T^i`, `T` its `offset` and `euler` (MuJoCo's accumulation), and
//! every `name` under it gets `sep` and `i` appended, as MuJoCo names them. Positions that come
//! from a default class are not moved by an enclosing frame.

use super::asset::{floats, ReadIssue, Source};
use super::mjcf::{frame, Compiler};
use crate::error::Result;
use crate::io::xml::Element;
use nalgebra::{Isometry3, Point3};

const POSED: &[&str] = &["body", "geom", "site", "camera", "light"];

fn set(e: &mut Element, k: &str, v: String) {
    e.attrs.retain(|(a, _)| a != k);
    e.attrs.push((k.to_string(), v));
}

/// Move an element (and, for a geom with `fromto`, its end points) by `t`.
fn place(e: &mut Element, t: &Isometry3<f64>, c: &Compiler) -> Result<()> {
    if let Some(ft) = floats(e, "fromto")? {
        if ft.len() == 6 {
            let a = t * Point3::new(ft[0], ft[1], ft[2]);
            let b = t * Point3::new(ft[3], ft[4], ft[5]);
            set(
                e,
                "fromto",
                format!(
                    "{:?} {:?} {:?} {:?} {:?} {:?}",
                    a.x, a.y, a.z, b.x, b.y, b.z
                ),
            );
            return Ok(());
        }
    }
    let f = t * frame(e, c)?;
    e.attrs
        .retain(|(a, _)| !["euler", "axisangle", "xyaxes", "zaxis", "quat"].contains(&a.as_str()));
    let p = f.translation.vector;
    let q = f.rotation.quaternion();
    set(e, "pos", format!("{:?} {:?} {:?}", p.x, p.y, p.z));
    set(
        e,
        "quat",
        format!("{:?} {:?} {:?} {:?}", q.w, q.i, q.j, q.k),
    );
    Ok(())
}

fn rename(e: &mut Element, suffix: &str) {
    if let Some((_, n)) = e.attrs.iter_mut().find(|(k, _)| k == "name") {
        n.push_str(suffix);
    }
    for c in &mut e.children {
        rename(c, suffix);
    }
}

/// `e` with every `<frame>` and `<replicate>` under it unfolded; `<attach>` elements are left
/// out, each with a `file.unsupported` issue at its line.
pub(crate) fn unfold(e: &Element, c: &Compiler, issues: &mut Vec<ReadIssue>) -> Result<Element> {
    let mut out = e.clone();
    out.children.clear();
    for ch in &e.children {
        match ch.name.as_str() {
            "frame" => {
                let t = frame(ch, c)?;
                let class = ch.attr("childclass");
                for mut g in unfold(ch, c, issues)?.children {
                    if POSED.contains(&g.name.as_str()) {
                        place(&mut g, &t, c)?;
                    }
                    if let Some(cl) = class {
                        let key = if g.name == "body" { "childclass" } else { "class" };
                        if g.attr(key).is_none() && g.name != "frame" {
                            set(&mut g, key, cl.to_string());
                        }
                    }
                    out.children.push(g);
                }
            }
            "replicate" => {
                let count = floats(ch, "count")?
                    .and_then(|v| v.first().copied())
                    .ok_or_else(|| ch.error("replicate without count"))?;
                if !((1.0..=10_000.0).contains(&count) && count.fract() == 0.0) {
                    return Err(ch.error(format!("replicate count {count} is not 1..10000")));
                }
                let off = floats(ch, "offset")?.unwrap_or(vec![0.0; 3]);
                if off.len() != 3 {
                    return Err(ch.error("offset needs 3 numbers"));
                }
                let mut step_el = ch.clone();
                step_el.attrs = vec![(
                    "pos".into(),
                    format!("{:?} {:?} {:?}", off[0], off[1], off[2]),
                )];
                if let Some(eu) = ch.attr("euler") {
                    step_el.attrs.push(("euler".into(), eu.to_string()));
                }
                let step = frame(&step_el, c)?;
                let sep = ch.attr("sep").unwrap_or("");
                let inner = unfold(ch, c, issues)?;
                let mut t = Isometry3::identity();
                for i in 0..count as usize {
                    for g in &inner.children {
                        let mut g = g.clone();
                        rename(&mut g, &format!("{sep}{i}"));
                        if POSED.contains(&g.name.as_str()) {
                            place(&mut g, &t, c)?;
                        }
                        out.children.push(g);
                    }
                    t *= step;
                }
            }
            "attach" => issues.push(ReadIssue {
                check: "file.unsupported",
                subject: ch.attr("body").unwrap_or("attach").to_string(),
                src: Source::of(ch),
                message: format!(
                    "<attach model={:?} body={:?}> is not read: the attached subtree is left out of the checks",
                    ch.attr("model").unwrap_or(""),
                    ch.attr("body").unwrap_or("")
                ),
            }),
            _ => out.children.push(unfold(ch, c, issues)?),
        }
    }
    Ok(out)
}
