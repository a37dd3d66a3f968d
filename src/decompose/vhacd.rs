//! parry's V-HACD (a port of V-HACD 2.x): the baseline engine. It looks at each object alone.

use super::{finish_with, DecomposeOptions, Decomposer, Hull};
use crate::error::Result;
use crate::mesh::{from_dvec, Mesh};
use parry3d_f64::transformation::vhacd::{VHACDParameters, VHACD};
use rayon::prelude::*;

/// V-HACD per object, objects in parallel.
#[derive(Clone, Copy, Debug, Default)]
pub struct Vhacd;

impl Decomposer for Vhacd {
    fn name(&self) -> &'static str {
        "vhacd"
    }

    fn decompose(&self, objects: &[&Mesh], opts: &DecomposeOptions) -> Result<Vec<Vec<Hull>>> {
        Ok(objects.par_iter().map(|m| decompose_one(m, opts)).collect())
    }
}

/// V-HACD of one mesh, brought within the limits.
pub fn decompose_one(mesh: &Mesh, opts: &DecomposeOptions) -> Vec<Hull> {
    decompose_one_with(mesh, opts, Hull::simplified)
}

/// [`decompose_one`] with another way (`reduce`) to bring a hull down to `max_vertices`.
pub fn decompose_one_with(
    mesh: &Mesh,
    opts: &DecomposeOptions,
    reduce: impl Fn(Hull, usize) -> Option<Hull> + Copy,
) -> Vec<Hull> {
    let params = VHACDParameters {
        resolution: opts.resolution,
        concavity: opts.concavity,
        max_convex_hulls: 1024,
        ..VHACDParameters::default()
    };
    let (v, t) = mesh.to_parry();
    let raw: Vec<Vec<crate::mesh::P3>> = std::panic::catch_unwind(|| {
        let d = VHACD::decompose(&params, &v, &t, true);
        d.compute_exact_convex_hulls(&v, &t)
            .into_iter()
            .map(|(pts, _)| pts.into_iter().map(from_dvec).collect())
            .collect()
    })
    .unwrap_or_default();
    let mut hulls = finish_with(raw, opts, reduce);
    if hulls.is_empty() {
        // V-HACD found nothing usable (thin or tiny object): fall back to the convex hull.
        hulls = finish_with(vec![mesh.vertices.clone()], opts, reduce);
    }
    hulls
}
