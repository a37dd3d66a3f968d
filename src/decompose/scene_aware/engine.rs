//! The engine as a [`Decomposer`]: [`SceneAware`] runs [`super::decompose_scene`] through the
//! cache, keeps the report of its last run ([`SceneAware::last_report`]) and hands over the
//! objects' [`Surface`]s it built ([`Decomposer::take_surfaces`]), so that the fidelity
//! measure does not build them again.

use super::{
    decompose_scene_with, DecomposeOptions, Hull, SceneAwareReport, Surface, NAME, VERSION,
};
use crate::decompose::{cache, Decomposer};
use crate::error::Result;
use crate::mesh::Mesh;
use std::sync::Mutex;

/// The scene-aware engine. Holds the report of its last run (see [`SceneAware::last_report`])
/// and the objects' surfaces it built (see [`Decomposer::take_surfaces`]).
#[derive(Debug, Default)]
pub struct SceneAware {
    last: Mutex<Option<SceneAwareReport>>,
    surfaces: Mutex<Surfaces>,
}

/// A run's hulls, report and objects' surfaces.
type Run = (Vec<Vec<Hull>>, SceneAwareReport, Vec<Option<Surface>>);

/// The surfaces of the last run's objects, in order (empty after a cache hit).
#[derive(Default)]
struct Surfaces(Vec<Option<Surface>>);

impl std::fmt::Debug for Surfaces {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Surfaces({})", self.0.len())
    }
}

impl SceneAware {
    pub fn new() -> Self {
        Self::default()
    }

    /// The report of the last `decompose` call.
    pub fn last_report(&self) -> Option<SceneAwareReport> {
        self.last.lock().ok().and_then(|g| g.clone())
    }

    /// Decompose a scene and return the hulls with the report.
    pub fn run(
        &self,
        objects: &[&Mesh],
        opts: &DecomposeOptions,
    ) -> Result<(Vec<Vec<Hull>>, SceneAwareReport)> {
        self.run_keeping_surfaces(objects, opts)
            .map(|(h, r, _)| (h, r))
    }

    /// [`SceneAware::run`], with the objects' surfaces when they were built (not on a cache
    /// hit: empty then).
    fn run_keeping_surfaces(&self, objects: &[&Mesh], opts: &DecomposeOptions) -> Result<Run> {
        let key = opts
            .cache_dir
            .as_ref()
            .map(|_| cache::key(NAME, VERSION, opts, objects));
        if let (Some(dir), Some(key)) = (&opts.cache_dir, &key) {
            if let Some(c) = cache::load(dir, key, NAME, VERSION) {
                if let (Some(h), Ok(mut r)) = (
                    cache::hulls(&c),
                    serde_json::from_value::<SceneAwareReport>(c.report.clone()),
                ) {
                    if h.len() == objects.len() {
                        r.cached = true;
                        return Ok((h, r, Vec::new()));
                    }
                }
            }
        }
        let (hulls, report, surfaces) = decompose_scene_with(objects, opts, true);
        if let (Some(dir), Some(key)) = (&opts.cache_dir, key) {
            let scene = cache::CachedScene {
                key,
                engine: NAME.into(),
                version: VERSION,
                objects: hulls
                    .iter()
                    .map(|o| o.iter().map(cache::CachedHull::from_hull).collect())
                    .collect(),
                report: serde_json::to_value(&report)
                    .map_err(|e| crate::error::Error::Internal(e.to_string()))?,
            };
            cache::store(dir, &scene)?;
        }
        Ok((hulls, report, surfaces))
    }
}

impl Decomposer for SceneAware {
    fn name(&self) -> &'static str {
        NAME
    }

    fn decompose(&self, objects: &[&Mesh], opts: &DecomposeOptions) -> Result<Vec<Vec<Hull>>> {
        let (h, r, surfaces) = self.run_keeping_surfaces(objects, opts)?;
        if let Ok(mut g) = self.last.lock() {
            *g = Some(r);
        }
        if let Ok(mut g) = self.surfaces.lock() {
            g.0 = surfaces;
        }
        Ok(h)
    }

    fn take_surfaces(&self) -> Vec<Option<Surface>> {
        self.surfaces
            .lock()
            .map(|mut g| std::mem::take(&mut g.0))
            .unwrap_or_default()
    }

    fn object_warnings(&self) -> Vec<Vec<String>> {
        self.last_report()
            .map(|r| r.objects.iter().map(|o| o.warnings()).collect())
            .unwrap_or_default()
    }
}
