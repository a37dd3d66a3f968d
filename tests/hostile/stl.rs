//! Hostile inputs: STL.

use super::*;

#[test]
fn stl_triangle_count_not_matching_the_size() {
    let t = tempfile::tempdir().unwrap();
    let m = cuboid(0.1, 0.2, 0.3);
    for (case, declared, problem) in [
        (
            "more",
            11,
            "declares 11 triangles (634 bytes) but the file has 684 bytes",
        ),
        ("huge", u32::MAX, "declares 4294967295 triangles"),
    ] {
        let d = manifest(
            t.path(),
            case,
            &[("box.stl", &stl_bytes(&m, declared))],
            "box.stl",
        );
        rejects(&d, "box.stl", problem);
    }
    let d = manifest(t.path(), "short", &[("box.stl", &[7u8; 40])], "box.stl");
    rejects(&d, "box.stl", "40 bytes is too short for a binary STL");
    let ascii = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n";
    let d = manifest(
        t.path(),
        "ascii",
        &[("box.stl", ascii.as_bytes())],
        "box.stl",
    );
    rejects(&d, "box.stl", "ends inside a facet (truncated)");
}
