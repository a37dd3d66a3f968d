//! interact3d: turn composed 3D scenes into simulation-ready assets and prove they are
//! physically sound.
//!
//! The modules follow the data through the pipeline:
//! [`mesh`] (the model) → [`io`] (file formats) → [`scene`] (sample folders and manifests) →
//! [`prepare`] (metres, Z-up, on the ground) → [`decompose`] (convex hulls) → [`inertia`] →
//! [`export`] (MJCF, URDF, USD) → [`metrics`] and [`physics`] (validation) → [`render`] (pictures).
//! [`pipeline`] runs a scene through them, [`batch`] a dataset; [`cli`] is the command line
//! (`main.rs` only parses and calls [`cli::run`]).

// `!(x > 0.0)` is written on purpose throughout: unlike `x <= 0.0` it is also true for NaN,
// so a guard written that way rejects NaN input too.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Coordinate loops (`for k in 0..3`) index several arrays in step; that reads better than zips.
#![allow(clippy::needless_range_loop)]

pub mod agreement;
pub mod batch;
pub mod body;
pub mod cli;
pub mod compose;
pub mod decompose;
pub mod error;
pub mod export;
pub mod fsutil;
pub mod inertia;
pub mod io;
pub mod mesh;
pub mod metrics;
pub mod physics;
pub mod pipeline;
pub mod pose;
pub mod prepare;
pub mod render;
pub mod report;
pub mod rng;
pub mod scene;
pub mod shapes;
pub mod validate;

pub use error::{Error, Result};
