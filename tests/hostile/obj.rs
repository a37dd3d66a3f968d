//! Hostile inputs: OBJ / MTL.

use super::*;

#[test]
fn obj_index_zero() {
    let t = tempfile::tempdir().unwrap();
    let d = obj_scene(t.path(), "zero", &(box_obj() + "f 0 1 2\n"));
    rejects(&d, "box.obj", "face vertex index 0 out of range");
    // Negative but reaching before the first vertex.
    let d = obj_scene(t.path(), "neg", &(box_obj() + "f -1 -2 -9\n"));
    rejects(&d, "box.obj", "face vertex index -9 out of range");
    // The most negative 64-bit index (its negation overflowed).
    let d = obj_scene(
        t.path(),
        "min",
        &(box_obj() + "f 1 2 -9223372036854775808\n"),
    );
    rejects(
        &d,
        "box.obj",
        "face vertex index -9223372036854775808 out of range",
    );
}

#[test]
fn obj_negative_relative_indices_and_ngons_read_correctly() {
    let t = tempfile::tempdir().unwrap();
    let m = cuboid(0.1, 0.2, 0.3);
    // Relative indices: each face given after all 8 vertices, counted from the end.
    let mut neg = String::new();
    for v in &m.vertices {
        neg += &format!("v {} {} {}\n", v.x, v.y, v.z);
    }
    for tri in &m.triangles {
        let r = |i: u32| i as i64 - 8;
        neg += &format!("f {} {} {}\n", r(tri[0]), r(tri[1]), r(tri[2]));
    }
    let a = export_ok(&obj_scene(t.path(), "neg", &neg), &t.path().join("out_neg"));
    let b = export_ok(
        &obj_scene(t.path(), "pos", &box_obj()),
        &t.path().join("out_pos"),
    );
    // Quads and a hexagon-free prism: the same box written with 6 quads.
    let quads = "v -0.05 -0.1 -0.15\nv 0.05 -0.1 -0.15\nv 0.05 0.1 -0.15\nv -0.05 0.1 -0.15\n\
                 v -0.05 -0.1 0.15\nv 0.05 -0.1 0.15\nv 0.05 0.1 0.15\nv -0.05 0.1 0.15\n\
                 f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    let c = export_ok(
        &obj_scene(t.path(), "quads", quads),
        &t.path().join("out_quads"),
    );
    let mass = 1000.0 * 0.1 * 0.2 * 0.3;
    for r in [&a, &b, &c] {
        let o = &r["objects"][0];
        assert!((o["mass"].as_f64().unwrap() - mass).abs() < 1e-9, "{o}");
        assert_eq!(o["volume_source"], "closed_mesh");
        assert_eq!(o["triangles"], 12);
    }
    // An octagon fan: one n-gon face closing a prism top and bottom.
    let n = 8;
    let mut s = String::new();
    for z in [0.0, 0.1] {
        for k in 0..n {
            let a = k as f64 * std::f64::consts::TAU / n as f64;
            s += &format!("v {} {} {z}\n", 0.05 * a.cos(), 0.05 * a.sin());
        }
    }
    s += &format!(
        "f {}\n",
        (1..=n)
            .rev()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    );
    s += &format!(
        "f {}\n",
        (n + 1..=2 * n)
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    );
    for k in 0..n {
        let (a, b) = (k + 1, (k + 1) % n + 1);
        s += &format!("f {a} {b} {} {}\n", b + n, a + n);
    }
    let r = export_ok(
        &obj_scene(t.path(), "octagon", &s),
        &t.path().join("out_oct"),
    );
    let o = &r["objects"][0];
    assert_eq!(o["volume_source"], "closed_mesh", "{o}");
    let area = 0.5 * n as f64 * 0.05f64.powi(2) * (std::f64::consts::TAU / n as f64).sin();
    assert!(
        (o["volume"].as_f64().unwrap() - area * 0.1).abs() < 1e-9,
        "{o}"
    );
}

#[test]
fn obj_missing_or_escaping_mtl_and_texture() {
    let t = tempfile::tempdir().unwrap();
    let d = obj_scene(
        t.path(),
        "mtl",
        &("mtllib missing.mtl\n".to_string() + &box_obj()),
    );
    rejects(&d, "box.obj", "\"missing.mtl\": cannot open");
    fs::write(t.path().join("evil.mtl"), "newmtl m\nKd 1 0 0\n").unwrap();
    let d = obj_scene(
        t.path(),
        "mtl_up",
        &("mtllib ../../../evil.mtl\n".to_string() + &box_obj()),
    );
    rejects(&d, "box.obj", "outside the scene folder");
    let d = manifest(
        t.path(),
        "tex_abs",
        &[
            (
                "meshes/box.obj",
                ("mtllib box.mtl\nusemtl m\n".to_string() + &box_obj()).as_bytes(),
            ),
            (
                "meshes/box.mtl",
                b"newmtl m\nKd 1 1 1\nmap_Kd /etc/passwd\n",
            ),
        ],
        "meshes/box.obj",
    );
    rejects(&d, "box.obj", "is an absolute path");
    // A texture that is not an image.
    let d = manifest(
        t.path(),
        "tex_bad",
        &[
            (
                "meshes/box.obj",
                ("mtllib box.mtl\nusemtl m\n".to_string() + &box_obj()).as_bytes(),
            ),
            ("meshes/box.mtl", b"newmtl m\nKd 1 1 1\nmap_Kd skin.png\n"),
            ("meshes/skin.png", b"\x89PNG\r\n\x1a\nthis is not a png"),
        ],
        "meshes/box.obj",
    );
    rejects(&d, "skin.png", "corrupt texture image");
}

#[test]
fn obj_infinite_and_absurd_coordinates() {
    let t = tempfile::tempdir().unwrap();
    let d = obj_scene(
        t.path(),
        "inf",
        &box_obj()
            .replacen("v ", "v inf ", 1)
            .replacen("inf -0.05", "inf", 1),
    );
    rejects(&d, "box.obj", "NaN or infinite");
    let d = obj_scene(
        t.path(),
        "overflow",
        &box_obj().replacen("v -0.05", "v 1e999", 1),
    );
    rejects(&d, "box.obj", "NaN or infinite");
    let d = obj_scene(
        t.path(),
        "absurd",
        &box_obj().replacen("v -0.05", "v 1e30", 1),
    );
    rejects(&d, "box.obj", "out of range (|x| > 1e12)");
}
