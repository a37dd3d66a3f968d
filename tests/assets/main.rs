//! `validate` on URDF and MJCF assets written by others: real pybullet_data files, planted
//! defects (one defect per file, each with a clean twin) around ../shared meshes, MuJoCo's own
//! verdict on the MJCF cases, our own exports read back, and the CI outputs.
//! Needs Python with `pybullet` (for pybullet_data) and `mujoco` (tests/python/requirements.txt).
//!
//! One file per source of the asset: [`third_party`] (files written by others), [`planted`]
//! (planted defects and their twins), [`ours`] (our exports, the CI outputs).

#[path = "../asset_cases/mod.rs"]
mod cases;
#[path = "../common/mod.rs"]
mod common;
use cases::*;
use common::*;
use interact3d::validate::asset::{check_path, AssetCheckOptions};
use std::path::Path;

mod ours;
mod planted;
mod third_party;
