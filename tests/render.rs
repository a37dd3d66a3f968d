//! `interact3d render` and `--render`: pictures checked against the analytic scene they show,
//! and the report pages opened in a real browser.
//!
//! The fixture `fail_interpenetrating` is two boxes: base 0.2 × 0.2 × 0.1 m on the ground, top a
//! 0.1 m cube centred at (0.02, 0.01, 0.147), sunk 3 mm into the base. Everything expected below
//! follows from those numbers, not from the renderer.

mod common;

use common::{root, run};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn fixture() -> PathBuf {
    root().join("fixtures/fail_interpenetrating")
}

fn render(out: &Path, extra: &[&str]) -> Value {
    let scene = fixture();
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--engine",
        "vhacd",
        "--force",
    ];
    args.extend_from_slice(extra);
    let (code, _, err) = run(&args);
    assert_eq!(code, 0, "render failed: {err}");
    serde_json::from_slice(&std::fs::read(out.join("views.json")).unwrap()).unwrap()
}

fn png(path: &Path) -> image::RgbImage {
    image::open(path).unwrap().to_rgb8()
}

fn image_of<'a>(views: &'a Value, file: &str) -> &'a Value {
    views["images"]
        .as_array()
        .unwrap()
        .iter()
        .find(|i| i["file"] == file)
        .unwrap_or_else(|| panic!("{file} not in views.json"))
}

/// Pinhole projection from the matrices recorded in views.json (what a consumer would do).
fn project(cam: &Value, p: [f64; 3]) -> (f64, f64) {
    let m = |r: usize, c: usize| cam["world_to_camera"][r][c].as_f64().unwrap();
    let k = |r: usize, c: usize| cam["intrinsics"][r][c].as_f64().unwrap();
    let c: Vec<f64> = (0..3)
        .map(|r| m(r, 0) * p[0] + m(r, 1) * p[1] + m(r, 2) * p[2] + m(r, 3))
        .collect();
    (
        k(0, 0) * c[0] / c[2] + k(0, 2),
        k(1, 1) * c[1] / c[2] + k(1, 2),
    )
}

#[test]
fn pictures_match_the_analytic_scene_and_are_deterministic() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("r");
    let views = render(&out, &["--image-size", "256", "--section-size", "256"]);

    // Top view: the top box's upper face (z = 0.197, x ∈ [-0.03, 0.07], y ∈ [-0.04, 0.06]) is
    // the one flat region of the top box's colour; its pixels' bounding box is the projection of
    // its corners, to a pixel.
    let top = image_of(&views, "views/top.png");
    let corners = [[-0.03, -0.04], [0.07, -0.04], [0.07, 0.06], [-0.03, 0.06]]
        .map(|[x, y]| project(&top["camera"], [x, y, 0.197]));
    let (u0, u1) = (
        corners.iter().map(|c| c.0).fold(f64::INFINITY, f64::min),
        corners
            .iter()
            .map(|c| c.0)
            .fold(f64::NEG_INFINITY, f64::max),
    );
    let (v0, v1) = (
        corners.iter().map(|c| c.1).fold(f64::INFINITY, f64::min),
        corners
            .iter()
            .map(|c| c.1)
            .fold(f64::NEG_INFINITY, f64::max),
    );
    let img = png(&out.join("views/top.png"));
    let centre = img
        .get_pixel(((u0 + u1) / 2.0) as u32, ((v0 + v1) / 2.0) as u32)
        .0;
    // The top box is orange (Kd 0.8 0.4 0.2): red channel well above blue.
    assert!(centre[0] as i32 - centre[2] as i32 > 60, "{centre:?}");
    let (mut bx0, mut bx1, mut by0, mut by1) = (u32::MAX, 0, u32::MAX, 0);
    for (x, y, p) in img.enumerate_pixels() {
        if p.0 == centre {
            bx0 = bx0.min(x);
            bx1 = bx1.max(x);
            by0 = by0.min(y);
            by1 = by1.max(y);
        }
    }
    // With 2 × 2 supersampling a pixel keeps the face's exact colour when all four samples
    // (at +0.25 and +0.75) fall inside: columns ceil(u0 − 0.25) ..= ceil(u1 − 0.75) − 1.
    let first = |lo: f64| (lo - 0.25).ceil() as u32;
    let last = |hi: f64| (hi - 0.75).ceil() as u32 - 1;
    assert_eq!((bx0, bx1), (first(u0), last(u1)), "u: projected {u0}..{u1}");
    assert_eq!((by0, by1), (first(v0), last(v1)), "v: projected {v0}..{v1}");

    // Sections: the centre lies in the analytic overlap box, and the red area of each plane is
    // the overlap's cross-section: z-plane 0.1 × 0.1 m, x-plane 0.1 (y) × 3 mm, y-plane 0.1 (x) × 3 mm.
    for (normal, want, perimeter) in [
        ("z", 0.01, 0.4),
        ("x", 1e-4 * 3.0, 0.206),
        ("y", 1e-4 * 3.0, 0.206),
    ] {
        let file = format!("sections/base__top__{normal}.png");
        let rec = &image_of(&views, &file)["section"];
        let c: Vec<f64> = (0..3).map(|k| rec["center"][k].as_f64().unwrap()).collect();
        assert!(
            c[0] > -0.03 && c[0] < 0.07 && c[1] > -0.04 && c[1] < 0.06,
            "{c:?}"
        );
        assert!(c[2] > 0.097 && c[2] < 0.1, "{c:?}");
        let px = rec["pixel_size_m"].as_f64().unwrap();
        let img = png(&out.join(&file));
        let red = img.pixels().filter(|p| p.0 == [255, 0, 0]).count() as f64 * px * px;
        // Pixel centres sample the region: the error is at most a pixel row along the outline.
        assert!(
            (red - want).abs() <= perimeter * px,
            "{normal}: red {red:.3e} m² vs {want:.3e} (pixel {px:.2e})"
        );
    }

    // Same input, same bytes.
    let again = tmp.path().join("r2");
    render(&again, &["--image-size", "256", "--section-size", "256"]);
    for i in views["images"].as_array().unwrap() {
        let f = i["file"].as_str().unwrap();
        assert_eq!(
            std::fs::read(out.join(f)).unwrap(),
            std::fs::read(again.join(f)).unwrap(),
            "{f} differs between two runs"
        );
    }
    assert_eq!(
        std::fs::read(out.join("views.json")).unwrap(),
        std::fs::read(again.join("views.json")).unwrap()
    );
}

#[test]
fn bad_input_is_a_clear_error_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("r");
    let (code, _, err) = run(&["render", "/nonexistent/scene", "-o", out.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("/nonexistent/scene"), "{err}");
    assert!(!out.exists());
    // A folder that is not ours is not replaced.
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("keep.txt"), "mine").unwrap();
    let (code, _, err) = run(&[
        "render",
        fixture().to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--engine",
        "vhacd",
    ]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(
        std::fs::read_to_string(out.join("keep.txt")).unwrap(),
        "mine"
    );
}

/// Headless Chromium, if installed (Debian's `chromium`); `None` when absent outside CI.
fn chromium() -> Option<PathBuf> {
    for c in ["chromium", "chromium-browser", "google-chrome"] {
        if let Ok(o) = std::process::Command::new("which").arg(c).output() {
            if o.status.success() {
                return Some(PathBuf::from(String::from_utf8_lossy(&o.stdout).trim()));
            }
        }
    }
    assert!(
        std::env::var("CI").as_deref() != Ok("true"),
        "chromium is required in CI (apt-get install chromium)"
    );
    eprintln!("SKIPPED: chromium not installed; the page test did not run");
    None
}

fn browser(bin: &Path, page: &Path, extra: &[String]) -> String {
    let profile = tempfile::tempdir().unwrap();
    let mut args: Vec<String> = [
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--allow-file-access-from-files",
        "--virtual-time-budget=5000",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    args.push(format!("--user-data-dir={}", profile.path().display()));
    args.extend_from_slice(extra);
    args.push(format!("file://{}", page.display()));
    let o = std::process::Command::new(bin)
        .args(&args)
        .output()
        .unwrap();
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn selfcheck(dom: &str) -> (usize, usize, usize) {
    let i = dom
        .find("id=\"selfcheck\"")
        .unwrap_or_else(|| panic!("no self-check in {dom}"));
    let tag = &dom[i..dom[i..].find('>').unwrap() + i];
    let attr = |k: &str| -> usize {
        let key = format!("data-{k}=\"");
        let s = tag
            .find(&key)
            .unwrap_or_else(|| panic!("page script did not run: {tag}"))
            + key.len();
        tag[s..s + tag[s..].find('"').unwrap()].parse().unwrap()
    };
    (attr("images"), attr("broken"), attr("errors"))
}

#[test]
fn batch_index_and_scene_pages_load_in_a_browser() {
    let Some(bin) = chromium() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let data = tmp.path().join("data");
    for f in ["fail_interpenetrating", "box_tray"] {
        let d = data.join(f);
        std::fs::create_dir_all(d.join("meshes")).unwrap();
        for e in std::fs::read_dir(root().join("fixtures").join(f).join("meshes")).unwrap() {
            let e = e.unwrap();
            std::fs::copy(e.path(), d.join("meshes").join(e.file_name())).unwrap();
        }
        std::fs::copy(
            root().join("fixtures").join(f).join("scene.json"),
            d.join("scene.json"),
        )
        .unwrap();
    }
    let out = tmp.path().join("out");
    let (code, _, err) = run(&[
        "batch",
        data.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--render",
        "--image-size",
        "128",
        "--section-size",
        "128",
        "--points",
        "20000",
        "--engine",
        "vhacd",
        "--progress",
        "quiet",
    ]);
    assert!(code == 0 || code == 1, "batch failed: {err}");
    let index = out.join("index.html");
    let dom = browser(&bin, &index, &["--dump-dom".into()]);
    let (images, broken, errors) = selfcheck(&dom);
    assert_eq!(images, 2, "one thumbnail per scene");
    assert_eq!((broken, errors), (0, 0), "{dom}");
    for f in ["fail_interpenetrating", "box_tray"] {
        let page = out.join(f).join("render/index.html");
        let dom = browser(&bin, &page, &["--dump-dom".into()]);
        let (images, broken, errors) = selfcheck(&dom);
        let views: Value =
            serde_json::from_slice(&std::fs::read(out.join(f).join("render/views.json")).unwrap())
                .unwrap();
        assert_eq!(images, views["images"].as_array().unwrap().len(), "{f}");
        assert_eq!((broken, errors), (0, 0), "{f}: {dom}");
        assert!(dom.contains("static_penetration"), "{f}: findings missing");
    }
    // Keep a screenshot of the scene page for people.
    let shot = root().join("target/render-page.png");
    browser(
        &bin,
        &out.join("fail_interpenetrating/render/index.html"),
        &[
            format!("--screenshot={}", shot.display()),
            "--window-size=1200,1600".into(),
        ],
    );
    assert!(shot.is_file(), "no screenshot at {}", shot.display());
    eprintln!("screenshot: {}", shot.display());
}

#[test]
fn export_and_validate_take_render() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = fixture();
    // validate --render DIR: the page carries this validation's failed check.
    let pics = tmp.path().join("pics");
    let (code, _, err) = run(&[
        "validate",
        scene.to_str().unwrap(),
        "--engine",
        "vhacd",
        "--points",
        "20000",
        "--render",
        pics.to_str().unwrap(),
        "--image-size",
        "64",
        "--section-size",
        "64",
    ]);
    assert_eq!(code, 1, "the sunk box fails validation: {err}");
    let page = std::fs::read_to_string(pics.join("index.html")).unwrap();
    assert!(page.contains("\"passed\":false") && page.contains("static_penetration"));
    let views: Value =
        serde_json::from_slice(&std::fs::read(pics.join("views.json")).unwrap()).unwrap();
    // 6 views + 6 hull views + 3 sections of the one pair.
    assert_eq!(views["images"].as_array().unwrap().len(), 15);
    for i in views["images"].as_array().unwrap() {
        let img = png(&pics.join(i["file"].as_str().unwrap()));
        assert_eq!(img.dimensions(), (64, 64));
    }
    // export --render: the same pictures inside the export, beside report.json.
    let out = tmp.path().join("exp");
    let code = common::export(
        &scene,
        &out,
        &[
            "--engine",
            "vhacd",
            "--points",
            "20000",
            "--render",
            "--image-size",
            "64",
            "--section-size",
            "64",
        ],
    );
    assert_eq!(code, 1);
    for i in views["images"].as_array().unwrap() {
        let f = i["file"].as_str().unwrap();
        assert_eq!(
            std::fs::read(out.join("render").join(f)).unwrap(),
            std::fs::read(pics.join(f)).unwrap(),
            "{f}: export and validate draw the same composed scene"
        );
    }
}
