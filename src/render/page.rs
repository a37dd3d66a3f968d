//! `render/index.html`: one scene's pictures (views, hull views, cross-sections), its legend,
//! metrics and findings on one self-contained page that works from `file://` (inline CSS and
//! script, images by relative path, no network).
//!
//! The page checks itself once loaded: it counts the images that decoded and the script errors
//! and writes them into `#selfcheck` (`data-images`, `data-broken`, `data-errors`), so a headless
//! browser's `--dump-dom` shows whether the page works.
//!
//! The page itself is `templates/report.html` (the self-check block `templates/selfcheck.js`),
//! built into the binary. Entry point: [`page`].

use super::ViewsJson;
use crate::error::{Error, Result};

/// The page of a scene: `views` (what [`super::render`] drew) and, when validation ran, the
/// validation as JSON (`pairs`, `checks`, `warnings`).
pub fn page(views: &ViewsJson, validation: Option<&serde_json::Value>) -> Result<String> {
    let data = serde_json::json!({ "views": views, "validation": validation });
    fill(TEMPLATE, &data)
}

/// `template` (one of our self-contained pages) with the self-check block and `data` as JSON in
/// place of `/*SELFCHECK*/` and `/*DATA*/null`. `<`, `>` and `&` are escaped so no string in
/// the data can close the script element.
pub(crate) fn fill(template: &str, data: &impl serde::Serialize) -> Result<String> {
    let data = serde_json::to_string(data)
        .map_err(|e| Error::Internal(format!("JSON: {e}")))?
        .replace('<', "\\u003c")
        .replace('>', "\\u003e")
        .replace('&', "\\u0026");
    Ok(template
        .replace("/*SELFCHECK*/", SELFCHECK_JS)
        .replace("/*DATA*/null", &data))
}

/// The self-check block every page of ours carries (also used by the batch index).
const SELFCHECK_JS: &str = include_str!("../../templates/selfcheck.js");

const TEMPLATE: &str = include_str!("../../templates/report.html");
