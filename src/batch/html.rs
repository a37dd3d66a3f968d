//! `OUT/index.html`: one self-contained page (inline CSS and JavaScript, no network) to browse a
//! batch: counts, a sortable table, filters by verdict and category, a text filter, and links to
//! each scene's files; with `--render`, a thumbnail per scene linking to its page
//! (`<scene>/render/index.html`, see [`crate::render::page`]). The time column shows conversion
//! times; a scene reused from an earlier run says "reused" (the run only checked its hash).
//! Entry point: [`page`].

use super::summary::Summary;
use crate::error::{Error, Result};

/// The page for `summary`. The rows are embedded as JSON; `<` is escaped so no string in the
/// data can close the script element.
pub fn page(summary: &Summary) -> Result<String> {
    let data = serde_json::to_string(summary)
        .map_err(|e| Error::Internal(format!("JSON: {e}")))?
        .replace('<', "\\u003c")
        .replace('>', "\\u003e")
        .replace('&', "\\u0026");
    Ok(TEMPLATE
        .replace("/*SELFCHECK*/", crate::render::page::SELFCHECK_JS)
        .replace("/*DATA*/null", &data))
}

const TEMPLATE: &str = r##"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>interact3d batch</title>
<style>
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.3em; margin: 0 0 .3em; }
#meta { color: #555; margin-bottom: 1em; }
.counts span { margin-right: 1.2em; font-weight: 600; }
.controls { margin: .8em 0; display: flex; gap: 1em; flex-wrap: wrap; align-items: center; }
table { border-collapse: collapse; width: 100%; }
th, td { padding: 3px 8px; border-bottom: 1px solid #e3e3e3; text-align: left; vertical-align: top; }
th { cursor: pointer; user-select: none; background: #f5f5f5; position: sticky; top: 0; white-space: nowrap; }
th.sorted-asc::after { content: " \25B2"; font-size: .7em; }
th.sorted-desc::after { content: " \25BC"; font-size: .7em; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
.pass { color: #17803d; font-weight: 600; }
.fail { color: #b45309; font-weight: 600; }
.error { color: #b91c1c; font-weight: 600; }
.msg { color: #555; font-size: .9em; max-width: 40em; }
a { color: #1d4ed8; }
</style>
</head>
<body>
<h1>interact3d batch</h1>
<div id="meta"></div>
<div class="counts" id="counts"></div>
<div class="controls">
  <label>verdict <select id="verdict"><option value="">all</option><option>pass</option><option>fail</option><option>error</option></select></label>
  <label>category <select id="category"><option value="">all</option></select></label>
  <label>path contains <input id="text" type="search" size="24"></label>
  <label>metric <select id="metric"></select> &ge; <input id="min" type="number" step="any" size="8"></label>
  <span id="shown"></span>
</div>
<table>
<thead><tr id="head"></tr></thead>
<tbody id="rows"></tbody>
</table>
<div id="selfcheck" style="color:#888;font-size:.8em;margin-top:2em">self-check: not run</div>
<script>
/*SELFCHECK*/
"use strict";
const DATA = /*DATA*/null;
const COLS = [
  ["rendered", "view", "thumb"], ["path", "scene", "text"], ["category", "category", "text"], ["objects", "objects", "num"],
  ["verdict", "verdict", "text"], ["r_volume", "R_volume", "num"],
  ["max_penetration_m", "max penetration (mm)", "mm"], ["collision_penetration_m", "hull penetration (mm)", "mm"],
  ["max_displacement_m", "max displacement (mm)", "mm"], ["hulls", "hulls", "list"],
  ["time_s", "conversion time (s)", "time"], ["files", "files", "files"], ["error", "error / failed checks", "msg"]
];
let sortKey = "path", sortDir = 1;
const el = (tag, props, kids) => {
  const e = document.createElement(tag);
  Object.assign(e, props || {});
  (kids || []).forEach(k => e.append(k));
  return e;
};
function fmt(v, kind) {
  if (v === null || v === undefined) return "";
  if (kind === "mm") return (v * 1000).toPrecision(3);
  if (kind === "num" && typeof v === "number" && !Number.isInteger(v)) return v.toPrecision(3);
  return String(v);
}
function value(r, key) {
  if (key === "hulls") return r.hulls.reduce((a, b) => a + b, 0);
  if (key === "error") return r.error || r.failed_checks.join("; ");
  if (key === "time_s" && r.reused) return null;
  return r[key];
}
function cmp(a, b) {
  const x = value(a, sortKey), y = value(b, sortKey);
  if (x === y) return a.path < b.path ? -1 : 1;
  if (x === null || x === undefined) return 1;
  if (y === null || y === undefined) return -1;
  return (x < y ? -1 : 1) * sortDir;
}
function render() {
  const v = document.getElementById("verdict").value;
  const c = document.getElementById("category").value;
  const t = document.getElementById("text").value.toLowerCase();
  const mk = document.getElementById("metric").value;
  const mc = COLS.find(x => x[0] === mk);
  const minRaw = document.getElementById("min").value;
  const min = minRaw === "" ? null : Number(minRaw) / (mc && mc[2] === "mm" ? 1000 : 1);
  const rows = DATA.scenes.filter(r => (!v || r.verdict === v) && (!c || r.category === c)
    && (!t || r.path.toLowerCase().includes(t))
    && (min === null || (value(r, mk) !== null && value(r, mk) !== undefined && value(r, mk) >= min))).sort(cmp);
  const body = document.getElementById("rows");
  body.replaceChildren(...rows.map(r => el("tr", {}, COLS.map(([key, , kind]) => {
    if (kind === "thumb") {
      if (!r.rendered) return el("td");
      const base = r.path.split("/").map(encodeURIComponent).join("/") + "/render/";
      return el("td", {}, [el("a", { href: base + "index.html" }, [el("img", {
        src: base + "views/three_quarter.png", width: 96, height: 96, alt: r.path })])]);
    }
    if (kind === "files") {
      if (r.verdict === "error") return el("td");
      const base = r.path.split("/").map(encodeURIComponent).join("/") + "/";
      return el("td", {}, ["scene.xml", "report.json", "batch.json"].flatMap((f, i) =>
        [i ? " " : "", el("a", { href: base + f, textContent: f.replace(/\.\w+$/, "") })]
      ).concat([" ", el("a", { href: base, textContent: "folder" })]));
    }
    const td = el("td", { textContent: kind === "list" ? r[key].join(" ")
      : kind === "time" && r.reused ? "reused" : fmt(value(r, key), kind === "time" ? "num" : kind) });
    if (kind === "num" || kind === "mm" || kind === "time") td.className = "num";
    if (key === "verdict") td.className = r.verdict;
    if (kind === "msg") td.className = "msg";
    return td;
  }))));
  document.getElementById("shown").textContent = rows.length + " of " + DATA.scenes.length + " shown";
  document.querySelectorAll("#head th").forEach(th => {
    th.className = th.dataset.key === sortKey ? (sortDir > 0 ? "sorted-asc" : "sorted-desc") : "";
  });
}
document.getElementById("meta").textContent = "root " + DATA.root + " \u00b7 interact3d " + DATA.version
  + " \u00b7 options " + DATA.options_hash;
document.getElementById("counts").append(
  el("span", { textContent: DATA.counts.scenes + " scenes" }),
  el("span", { className: "pass", textContent: DATA.counts.pass + " pass" }),
  el("span", { className: "fail", textContent: DATA.counts.fail + " fail" }),
  el("span", { className: "error", textContent: DATA.counts.error + " error" }));
const cats = [...new Set(DATA.scenes.map(r => r.category))].sort();
document.getElementById("category").append(...cats.map(c => el("option", { value: c, textContent: c || "(none)" })));
document.getElementById("head").append(...COLS.map(([key, label, kind]) => {
  const th = el("th", { textContent: label });
  th.dataset.key = key;
  if (kind !== "files" && kind !== "thumb") th.onclick = () => {
    sortDir = sortKey === key ? -sortDir : 1;
    sortKey = key;
    render();
  };
  return th;
}));
document.getElementById("metric").append(...COLS.filter(c => c[2] === "num" || c[2] === "mm")
  .map(([key, label]) => el("option", { value: key, textContent: label })));
["verdict", "category", "text", "metric", "min"].forEach(id => document.getElementById(id).addEventListener("input", render));
render();
</script>
</body>
</html>
"##;
