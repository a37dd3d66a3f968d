//! Tests of the scene-aware engine against independent expectations: analytic shapes and the
//! generated fixtures (0.75 mm gaps), real scenes when `../shared` is present.
//!
//! One file per subject: [`scenes`] (whole scenes), [`refine`] (after the quality loop),
//! [`star`] (star pieces), [`pins`] (what a neighbour pins), [`kernels`] (the kernels against
//! their definitions). Shared helpers live here.

use super::metrics;
use super::*;
use crate::decompose::Decomposer;
use crate::mesh::{Mesh, P3, V3};
use crate::shapes;
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::shape::ConvexPolyhedron;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

mod kernels;
mod pins;
mod refine;
mod scenes;
mod star;

fn opts() -> DecomposeOptions {
    DecomposeOptions::default()
}

/// `m` moved by `d`.
fn moved(m: &Mesh, d: V3) -> Mesh {
    m.transformed(&nalgebra::Translation3::from(d).to_homogeneous())
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name)
}

/// `shared/` beside the repository, or beside the worktree's parent.
fn shared() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    [root.join("../shared"), root.join("../../shared")]
        .into_iter()
        .find(|p| p.join("datasets/scenes").is_dir())
}

/// The geometry of a shared object, `rel` under `shared/datasets/objects`.
fn shared_object(sh: &Path, rel: &str) -> Mesh {
    let p = sh.join("datasets/objects").join(rel);
    crate::io::load_visual(&p, &crate::io::Limits::default())
        .unwrap()
        .geometry()
}

fn world_meshes(path: &Path) -> Vec<Mesh> {
    let scene = crate::scene::load(path, &crate::io::Limits::default()).expect("scene loads");
    let prep = crate::prepare::prepare(&scene, &Default::default()).expect("scene prepares");
    prep.objects.into_iter().map(|o| o.geometry).collect()
}

/// A shared scene's world meshes and their decomposition at [`opts`]; `None` (the test is
/// skipped) without `shared/`.
fn shared_scene(name: &str) -> Option<(Vec<Mesh>, Vec<Vec<Hull>>, SceneAwareReport)> {
    let Some(sh) = shared() else {
        eprintln!("shared datasets not present: skipped");
        return None;
    };
    let meshes = world_meshes(&sh.join("datasets/scenes").join(name));
    let refs: Vec<&Mesh> = meshes.iter().collect();
    let (hulls, rep) = decompose_scene(&refs, &opts());
    Some((meshes, hulls, rep))
}

/// Independent check of the limits every hull must meet.
fn assert_limits(hulls: &[Hull], o: &DecomposeOptions) {
    assert!(
        !hulls.is_empty() && hulls.len() <= o.max_hulls,
        "{} hulls",
        hulls.len()
    );
    for h in hulls {
        assert!(
            h.vertices.len() <= o.max_vertices,
            "{} vertices",
            h.vertices.len()
        );
        assert!(
            h.thickness() >= o.min_thickness,
            "thickness {}",
            h.thickness()
        );
        assert!(h.volume > 0.0);
    }
}

/// Deepest overlap between hulls of different objects, by parry (built from the vertices
/// alone, independently of the engine's own triangles); 0 when all are apart.
fn deepest_cross_overlap(hulls: &[Vec<Hull>]) -> f64 {
    let poly = |h: &Hull| {
        let v: Vec<Vector> = h.vertices.iter().map(crate::mesh::to_dvec).collect();
        ConvexPolyhedron::from_convex_hull(&v).unwrap()
    };
    let id = Pose::identity();
    let mut worst = 0.0f64;
    for a in 0..hulls.len() {
        for b in a + 1..hulls.len() {
            for ha in &hulls[a] {
                for hb in &hulls[b] {
                    if !ha.aabb.intersects(&hb.aabb, 0.0) {
                        continue;
                    }
                    let c =
                        parry3d_f64::query::contact(&id, &poly(ha), &id, &poly(hb), 0.0).unwrap();
                    if let Some(c) = c {
                        worst = worst.max(-c.dist);
                    }
                }
            }
        }
    }
    worst
}

fn bowl() -> Mesh {
    shapes::bowl(0.08, 0.055, 0.004, 48, 10)
}
