//! Timing of the interpenetration metrics on ~16k-triangle pairs (and two YCB scans when the
//! dataset is present). Run: `cargo run --release --example bench_metrics`.

use interact3d::mesh::{Mesh, P3, V3};
use interact3d::metrics::{
    max_penetration_depth, min_clearance, r_surface, r_volume, MetricsOptions, Prepared, Solid,
};
use interact3d::shapes::{cuboid, uv_sphere};
use nalgebra::Matrix4;
use std::time::Instant;

fn moved(m: &Mesh, x: f64, y: f64, z: f64) -> Mesh {
    m.transformed(&Matrix4::new_translation(&V3::new(x, y, z)))
}

/// OBJ positions (metres in YCB) welded exactly; `None` when the file is absent.
fn load_obj(path: &str) -> Option<Mesh> {
    let (models, _) = tobj::load_obj(
        path,
        &tobj::LoadOptions {
            triangulate: true,
            ..Default::default()
        },
    )
    .ok()?;
    let mut m = Mesh::default();
    for model in models {
        let p = &model.mesh.positions;
        let verts = p.chunks(3).map(|c| P3::new(c[0], c[1], c[2])).collect();
        let tris = model
            .mesh
            .indices
            .chunks(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        m.append(&Mesh::new(verts, tris));
    }
    Some(m.welded(0.0))
}

fn ms<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t = Instant::now();
    let r = f();
    (r, t.elapsed().as_secs_f64() * 1e3)
}

fn row(name: &str, a: Solid, b: Solid, opts: &MetricsOptions, one: &rayon::ThreadPool) {
    let tris = |s: &Solid| match s {
        Solid::Mesh(m) => m.triangles.len(),
        Solid::Hulls(h) => h.iter().map(|m| m.triangles.len()).sum(),
    };
    let ((pa, pb), t_prep) = ms(|| one.install(|| (Prepared::new(a), Prepared::new(b))));
    let (v1, t_vol1) = ms(|| one.install(|| r_volume(&pa, &pb, opts)));
    let (v, t_vol) = ms(|| r_volume(&pa, &pb, opts));
    assert_eq!(v, v1, "thread count changed the result");
    let (rs, t_surf) = ms(|| one.install(|| r_surface(&pa, &pb)));
    let (d, t_depth) = ms(|| one.install(|| max_penetration_depth(&pa, &pb, opts)));
    let (c, t_clear) = ms(|| one.install(|| min_clearance(&pa, &pb)));
    println!(
        "| {name} | {} / {} | {:.0} | {:.0} | {:.0} | {:.1} | {:.1} | {:.1} | {:.4} | {:.4} | {:.3} | {:.3} |",
        tris(&a),
        tris(&b),
        t_prep,
        t_vol1,
        t_vol,
        t_surf,
        t_depth,
        t_clear,
        v.r_volume,
        rs,
        d * 1e3,
        c * 1e3,
    );
}

fn main() {
    let opts = MetricsOptions::default();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    println!(
        "N = {} points, {} per column, seed {:#x}; times in ms, 1 thread unless 'all' ({} threads)\n",
        opts.points,
        opts.points_per_column,
        opts.seed,
        rayon::current_num_threads()
    );
    println!("| pair | triangles | prepare | R_vol 1 thr | R_vol all | R_surf | depth | clearance | R_volume | R_surface | depth mm | clearance mm |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");

    let s = uv_sphere(0.05, 64, 128);
    let s2 = moved(&s, 0.024, 0.032, 0.0);
    row(
        "spheres 5 cm, centres 4 cm apart",
        Solid::Mesh(&s),
        Solid::Mesh(&s2),
        &opts,
        &one,
    );
    let s3 = moved(&s, 0.08, 0.08, 0.0);
    row(
        "spheres, disjoint (boxes overlap)",
        Solid::Mesh(&s),
        Solid::Mesh(&s3),
        &opts,
        &one,
    );
    let b = moved(&cuboid(V3::new(0.2, 0.2, 0.02)), 0.0, 0.0, -0.058);
    row(
        "sphere 2 mm into a slab",
        Solid::Mesh(&s),
        Solid::Mesh(&b),
        &opts,
        &one,
    );

    let hulls_a: Vec<Mesh> = (0..8)
        .map(|i| {
            moved(
                &cuboid(V3::new(0.03, 0.03, 0.03)),
                0.02 * i as f64,
                0.0,
                0.0,
            )
        })
        .collect();
    let hulls_b: Vec<Mesh> = (0..8)
        .map(|i| {
            moved(
                &cuboid(V3::new(0.03, 0.03, 0.03)),
                0.06,
                0.02 * i as f64 - 0.07,
                0.01,
            )
        })
        .collect();
    row(
        "8 hulls vs 8 hulls",
        Solid::Hulls(&hulls_a),
        Solid::Hulls(&hulls_b),
        &opts,
        &one,
    );
    row(
        "sphere mesh vs 8 hulls",
        Solid::Mesh(&s),
        Solid::Hulls(&hulls_b),
        &opts,
        &one,
    );

    let root = "/work/shared/datasets/objects/ycb";
    if let (Some(lemon), Some(orange)) = (
        load_obj(&format!("{root}/014_lemon/textured.obj")),
        load_obj(&format!("{root}/017_orange/textured.obj")),
    ) {
        let (la, oa) = (lemon.aabb().unwrap(), orange.aabb().unwrap());
        // Put the orange's centre 5 cm from the lemon's along x.
        let d = la.center() - oa.center() + V3::new(0.05, 0.0, 0.0);
        let orange = moved(&orange, d.x, d.y, d.z);
        println!(
            "\nYCB scans: lemon {} tris (closed: {}), orange {} tris (closed: {})",
            lemon.triangles.len(),
            lemon.is_closed(),
            orange.triangles.len(),
            orange.is_closed()
        );
        row(
            "YCB lemon vs orange (scans)",
            Solid::Mesh(&lemon),
            Solid::Mesh(&orange),
            &opts,
            &one,
        );
    }

    // Spread of the estimator over seeds, against the spread of independent uniform points
    // (binomial: sqrt(R (1 - R) / #either)).
    let pa = Prepared::new(Solid::Mesh(&s));
    let pb = Prepared::new(Solid::Mesh(&s2));
    let n = 100_000;
    let rs: Vec<(f64, u64)> = (0..32)
        .map(|seed| {
            let v = r_volume(
                &pa,
                &pb,
                &MetricsOptions {
                    points: n,
                    seed,
                    ..opts.clone()
                },
            );
            (v.r_volume, v.inside_a + v.inside_b - v.inside_both)
        })
        .collect();
    let mean = rs.iter().map(|r| r.0).sum::<f64>() / rs.len() as f64;
    let sd = (rs.iter().map(|r| (r.0 - mean).powi(2)).sum::<f64>() / (rs.len() - 1) as f64).sqrt();
    let either = rs.iter().map(|r| r.1 as f64).sum::<f64>() / rs.len() as f64;
    let iid = (mean * (1.0 - mean) / either).sqrt();
    println!(
        "
R_volume spread, spheres pair, N = {n}, 32 seeds: mean {mean:.5}, sd {sd:.5}; \
         independent points would give sd {iid:.5}"
    );
}
