//! `OUT/index.html`: one self-contained page (inline CSS and JavaScript, no network) to browse a
//! batch: counts, a sortable table, filters by verdict and category, a text filter, and links to
//! each scene's files; with `--render`, a thumbnail per scene linking to its page
//! (`<scene>/render/index.html`, see [`crate::render::page`]). The time column shows conversion
//! times; a scene reused from an earlier run says "reused" (the run only checked its hash).
//! The page itself is `templates/batch.html`, built into the binary. Entry point: [`page`].

use super::summary::Summary;
use crate::error::Result;

/// The page for `summary`, the rows embedded as JSON (see [`crate::render::page`]'s `fill`).
pub fn page(summary: &Summary) -> Result<String> {
    crate::render::page::fill(TEMPLATE, summary)
}

const TEMPLATE: &str = include_str!("../../templates/batch.html");
