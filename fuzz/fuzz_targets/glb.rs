#![no_main]
//! Fuzz the glTF/GLB reader through the library's byte-level entry point (`io::load_visual_bytes`,
//! which also runs the mesh checks). Any panic is a bug: bad input must be an `Err`.
use libfuzzer_sys::fuzz_target;
include!("common.rs");

fuzz_target!(|data: &[u8]| {
    load("fuzz.glb", data);
});
