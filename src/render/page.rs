//! `render/index.html`: one scene's pictures (views, hull views, cross-sections), its legend,
//! metrics and findings on one self-contained page that works from `file://` (inline CSS and
//! script, images by relative path, no network).
//!
//! The page checks itself once loaded: it counts the images that decoded and the script errors
//! and writes them into `#selfcheck` (`data-images`, `data-broken`, `data-errors`), so a headless
//! browser's `--dump-dom` shows whether the page works.
//!
//! Entry point: [`page`].

use super::ViewsJson;
use crate::error::{Error, Result};

/// The page of a scene: `views` (what [`super::render`] drew) and, when validation ran, the
/// validation as JSON (`pairs`, `checks`, `warnings`).
pub fn page(views: &ViewsJson, validation: Option<&serde_json::Value>) -> Result<String> {
    let data = serde_json::json!({ "views": views, "validation": validation });
    let data = serde_json::to_string(&data)
        .map_err(|e| Error::Internal(format!("JSON: {e}")))?
        .replace('<', "\\u003c")
        .replace('>', "\\u003e")
        .replace('&', "\\u0026");
    Ok(TEMPLATE
        .replace("/*SELFCHECK*/", SELFCHECK_JS)
        .replace("/*DATA*/null", &data))
}

/// The self-check block every page of ours carries (also used by the batch index).
pub const SELFCHECK_JS: &str = r#"
window.__errors = [];
window.addEventListener("error", e => window.__errors.push(String(e.message || e)));
window.addEventListener("load", () => {
  const imgs = [...document.images];
  const broken = imgs.filter(i => !i.complete || i.naturalWidth === 0).map(i => i.getAttribute("src"));
  const s = document.getElementById("selfcheck");
  s.dataset.images = imgs.length;
  s.dataset.broken = broken.length;
  s.dataset.errors = window.__errors.length;
  s.textContent = "self-check: " + imgs.length + " images, " + broken.length + " broken"
    + (broken.length ? " (" + broken.join(", ") + ")" : "") + ", " + window.__errors.length
    + " script errors" + (window.__errors.length ? ": " + window.__errors.join("; ") : "");
});
"#;

const TEMPLATE: &str = r##"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>interact3d scene</title>
<style>
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.3em; margin: 0 0 .3em; } h2 { font-size: 1.1em; margin: 1.2em 0 .4em; }
.grid { display: grid; grid-template-columns: repeat(auto-fill, minmax(220px, 1fr)); gap: 8px; }
figure { margin: 0; } figure img { width: 100%; border: 1px solid #ddd; image-rendering: auto; }
figcaption { font-size: .85em; color: #555; }
.legend span { display: inline-block; margin-right: 1em; }
.sw { display: inline-block; width: .9em; height: .9em; border: 1px solid #888; vertical-align: -2px; margin-right: .3em; }
table { border-collapse: collapse; } th, td { padding: 2px 8px; border-bottom: 1px solid #e3e3e3; text-align: left; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
.pass { color: #17803d; font-weight: 600; } .fail { color: #b45309; font-weight: 600; }
#selfcheck { color: #888; font-size: .8em; margin-top: 2em; }
</style>
</head>
<body>
<h1 id="title"></h1>
<div class="legend" id="legend"></div>
<h2>Views</h2><div class="grid" id="views"></div>
<h2>Collision hulls</h2><div class="grid" id="hulls"></div>
<h2>Cross-sections</h2><div id="sections"></div>
<h2>Metrics</h2><div id="metrics"></div>
<h2>Findings</h2><div id="findings"></div>
<div id="selfcheck">self-check: not run</div>
<script>
/*SELFCHECK*/
"use strict";
const DATA = /*DATA*/null;
const el = (tag, props, kids) => {
  const e = document.createElement(tag);
  Object.assign(e, props || {});
  (kids || []).forEach(k => e.append(k));
  return e;
};
const rgb = c => "rgb(" + c.join(",") + ")";
const fig = (img, caption) => el("figure", {}, [
  el("a", { href: img.file }, [el("img", { src: img.file, alt: caption, width: 256, height: 256 })]),
  el("figcaption", { textContent: caption })]);
const V = DATA.views;
document.title = "interact3d: " + V.scene;
document.getElementById("title").textContent = V.scene;
document.getElementById("legend").append(
  ...V.legend.objects.map(o => el("span", {}, [el("span", { className: "sw", style: "background:" + rgb(o.colour) }),
    o.name + (o.label ? " (" + o.label + ")" : "")])),
  el("span", {}, [el("span", { className: "sw", style: "background:" + rgb(V.legend.overlap) }), "inside two objects"]));
for (const kind of ["view", "hulls"]) {
  document.getElementById(kind === "view" ? "views" : "hulls").append(
    ...V.images.filter(i => i.kind === kind).map(i => fig(i, i.view.replace("_", " "))));
}
const pairs = new Map();
for (const i of V.images.filter(i => i.kind === "section")) {
  const k = i.section.pair.join(" / ");
  if (!pairs.has(k)) pairs.set(k, []);
  pairs.get(k).push(i);
}
const sec = document.getElementById("sections");
if (!pairs.size) sec.textContent = "no pair of objects comes near another";
for (const [k, imgs] of pairs) {
  const d = imgs[0].section.hull_depth_m;
  sec.append(el("h3", { textContent: k + ": hulls " + (d > 0 ? "overlap " + (d * 1000).toPrecision(3) + " mm"
    : "apart " + (-d * 1000).toPrecision(3) + " mm") }),
    el("div", { className: "grid" }, imgs.map(i => fig(i, "plane " + i.section.normal + " = "
      + i.section.center[{ x: 0, y: 1, z: 2 }[i.section.normal]].toFixed(4) + " m (right " + i.section.right
      + ", up " + i.section.up + ")"))));
}
const val = DATA.validation;
const met = document.getElementById("metrics"), fin = document.getElementById("findings");
if (!val) {
  met.textContent = "not validated";
  fin.textContent = "not validated";
} else {
  const num = (v, k) => el("td", { className: "num", textContent: v === undefined || v === null ? "" : (v * k).toPrecision(3) });
  met.append(el("table", {}, [el("tr", {}, ["pair", "R_volume", "R_surface", "max penetration (mm)", "hull penetration (mm)", "clearance (mm)"]
    .map(h => el("th", { textContent: h })))].concat(val.pairs.map(p => {
      const m = p.visual || p.collision;
      return el("tr", {}, [el("td", { textContent: p.a + " / " + p.b }), num(m.r_volume, 1), num(m.r_surface, 1),
        num(m.max_penetration_depth, 1000), num(p.collision.max_penetration_depth, 1000), num(m.min_clearance, 1000)]);
    }))));
  fin.append(el("p", { className: val.passed ? "pass" : "fail", textContent: val.passed ? "pass" : "fail" }),
    el("table", {}, [el("tr", {}, ["check", "subject", "value", "limit", "", "message"].map(h => el("th", { textContent: h })))]
      .concat(val.checks.filter(c => !c.passed).concat(val.checks.filter(c => c.passed)).map(c => el("tr", {}, [
        el("td", { textContent: c.name }), el("td", { textContent: c.subject }), num(c.value, 1), num(c.limit, 1),
        el("td", { className: c.passed ? "pass" : "fail", textContent: c.passed ? "pass" : "fail" }),
        el("td", { textContent: c.message })])))),
    el("ul", {}, (val.warnings || []).map(w => el("li", { textContent: w }))));
}
</script>
</body>
</html>
"##;
