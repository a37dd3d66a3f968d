// Shared by the fuzz targets (included with `include!`): small limits so a hostile input is
// refused by a limit instead of exhausting the fuzzer's memory, and an empty folder as the scene
// root so no fuzzed URI or MTL path reaches a real file.
use std::path::PathBuf;

fn limits() -> interact3d::io::Limits {
    interact3d::io::Limits {
        max_file_bytes: 1 << 20,
        max_triangles: 200_000,
        max_texture_pixels: 4096 * 4096,
    }
}

fn empty_root() -> PathBuf {
    let d = std::env::temp_dir().join("interact3d-fuzz-root");
    let _ = std::fs::create_dir_all(&d);
    d
}

fn load(file: &str, data: &[u8]) {
    let root = empty_root();
    let path = root.join(file);
    let _ = interact3d::io::load_visual_bytes(&path, data, &root, &limits());
}
