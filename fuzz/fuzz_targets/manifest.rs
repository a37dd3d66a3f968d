#![no_main]
//! Fuzz the scene descriptions: the same bytes as a `scene.json` manifest (parse, units, poses,
//! physical values, names) and as an Interact3D `metadata.json` (every registration transform).
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = interact3d::scene::manifest::parse(Path::new("scene.json"), data);
    let _ = interact3d::scene::sample::transforms_from_bytes(Path::new("metadata.json"), data);
});
