//! `--colour-probe`: the scale the colour along the long axis alone gives each object (no
//! `compose`), against the truth (`colour_profile.rs` beside it): the model's colour profile
//! along its OBB's long axis matched onto the guidance's, the guidance's axis either the model's
//! mapped by the true rotation (`truth axis`, the most favourable case) or the guidance part's
//! own OBB axis (`own axis`). Colours gain-normalised per cloud as `compose::colour` does.
//! `COLOUR_DUMP=1` prints the two profiles' brightness side by side, the guidance mapped back to
//! object units by the truth.

use interact3d::compose::cloud::Cloud;
use interact3d::compose::colour;
use interact3d::compose::colour_axis::{
    fit, fit_edges, ColourProfile, FitOptions, ProfileFit, GUIDANCE_BINS, MODEL_BINS,
};
use interact3d::compose::obb::{self, Obb};
use interact3d::compose::ObjectInput;
use interact3d::pose::Similarity;

pub fn print(id: &str, seed: u64, inp: &ObjectInput, truth: &Similarity) {
    let mut oc = Cloud::sample(&inp.visual, 8000, 11);
    let mut gc = Cloud::sample(&inp.guidance, 8000, 12);
    let usable = colour::usable(&oc, &gc);
    colour::normalise(&mut oc);
    colour::normalise(&mut gc);
    let ob = Obb::of_points(&oc.points);
    let ax = ob.axes.column(0).into_owned();
    let model = ColourProfile::along(&oc.points, &oc.colours, &ob.center, &ax, MODEL_BINS);
    let gb = Obb::of_points(&gc.points);
    let s0 = obb::scale_ratio(&ob, &gb);
    let o = FitOptions::around(s0, 121);
    let rel = |s: f64| 100.0 * (s / truth.scale - 1.0);
    let show = |f: Option<ProfileFit>| {
        f.map_or("none".to_string(), |f| {
            format!(
                "{:+6.2} % (cost {:.4}, contrast {:.2}, sign {:+})",
                rel(f.scale),
                f.cost,
                f.contrast,
                f.sign
            )
        })
    };
    let r = truth.rotation;
    let c = nalgebra::Point3::from(
        truth.rotation * (truth.scale * ob.center.coords) + truth.translation,
    );
    let gt = ColourProfile::along(&gc.points, &gc.colours, &c, &(r * ax), GUIDANCE_BINS);
    let at_truth = fit(
        &model,
        &gt,
        &FitOptions {
            scale_lo: truth.scale,
            scale_hi: truth.scale,
            steps: 2,
            ..o
        },
    )
    .map_or(f64::NAN, |f| f.cost);
    let gx = gb.axes.column(0).into_owned();
    let go = ColourProfile::along(&gc.points, &gc.colours, &gb.center, &gx, GUIDANCE_BINS);
    eprintln!(
        "COLOUR {id:<44} seed {seed}: elongation {:.2}, colour usable {usable}, OBB scale {:+6.2} %; truth axis {} (cost at the truth {at_truth:.4}); own axis {}",
        ob.extents[0] / ob.extents[1],
        rel(s0),
        show(fit(&model, &gt, &o)),
        show(fit(&model, &go, &o)),
    );
    eprintln!(
        "EDGES  {id:<44} seed {seed}: truth axis {}; own axis {}",
        show(fit_edges(&model, &gt, &o)),
        show(fit_edges(&model, &go, &o)),
    );
    if std::env::var_os("COLOUR_DUMP").is_some() {
        let inv = truth.matrix().try_inverse().unwrap();
        let back: Vec<_> = gc.points.iter().map(|p| inv.transform_point(p)).collect();
        let m40 = ColourProfile::along(&oc.points, &oc.colours, &ob.center, &ax, 40);
        let g40 = ColourProfile::along(&back, &gc.colours, &ob.center, &ax, 40);
        let show = |c: &Option<[f64; 3]>| {
            c.map_or("  -  ".to_string(), |c| {
                format!(
                    "{:.0}{:.0}{:.0}",
                    9.0 * c[0].min(1.0),
                    9.0 * c[1].min(1.0),
                    9.0 * c[2].min(1.0)
                )
            })
        };
        let row = |p: &ColourProfile| -> Vec<String> { p.colour.iter().map(show).collect() };
        eprintln!(
            "  model    rgb (0-9), lo {:+.3} bin {:.4}: {}",
            m40.lo,
            m40.bin,
            row(&m40).join(" ")
        );
        eprintln!(
            "  guidance rgb (0-9), lo {:+.3} bin {:.4}: {}",
            g40.lo,
            g40.bin,
            row(&g40).join(" ")
        );
    }
}

/// `COLOUR_JUDGE=1` (after `compose`, every object with elongation ≥ 2): could the colour
/// profile judge the pipeline's size? Along the *estimate's* axis (no truth used for the fit),
/// the colour cost at the estimate's scale against the colour fit's best, and the geometric fit
/// (the guard's plain surface fit and the offset-out fit) at the estimate against a fixed-scale
/// point-to-plane refit at the colour's scale.
pub fn judge(
    id: &str,
    seed: u64,
    inp: &ObjectInput,
    truth: &Similarity,
    est: &Similarity,
    anchor: Option<&interact3d::mesh::Mesh>,
) {
    use interact3d::compose::icp::Matcher;
    use interact3d::compose::kdtree::KdTree;
    use interact3d::compose::plane_icp::{offset_fit, plane_icp, surface_fit, PlaneIcpOptions};
    use interact3d::compose::scale::rescaled;
    let mut oc = Cloud::sample(&inp.visual, 5000, 1);
    let ob = Obb::of_points(&oc.points);
    if ob.extents[0] / ob.extents[1] < 2.0 {
        return;
    }
    let mut gc = Cloud::sample(&inp.guidance, 2500, 2);
    if !colour::usable(&oc, &gc) {
        return;
    }
    colour::normalise(&mut oc);
    colour::normalise(&mut gc);
    // Without the composed anchor's surface (segmentation bleed), as `compose` strips it.
    if let Some(a) = anchor {
        let f = interact3d::compose::sdf::AnchorField::new(std::slice::from_ref(a), 32);
        let d = interact3d::mesh::Aabb::of_points(&gc.points).map_or(0.0, |b| b.diagonal());
        if let Some(s) = interact3d::compose::bleed::without_placed(&gc, &f, 0.015 * d, 0.5) {
            gc = s;
        }
    }
    let tree = KdTree::new(&oc.points);
    let sp = interact3d::compose::guard::spacing(&inp.visual, 5000);
    let probe = gc.subsample(1000).points;
    let diag = oc.diagonal();
    let cap = 0.03 * est.scale * diag;
    let fits = |t: &Similarity| {
        (
            surface_fit(&oc, &tree, sp, &probe, t, cap),
            offset_fit(&oc, &tree, sp, &probe, t, cap, cap).0,
        )
    };
    let ax = ob.axes.column(0).into_owned();
    let model = ColourProfile::along(&oc.points, &oc.colours, &ob.center, &ax, MODEL_BINS);
    let profile_at = |t: &Similarity| {
        let c = nalgebra::Point3::from(t.rotation * (t.scale * ob.center.coords) + t.translation);
        ColourProfile::along(
            &gc.points,
            &gc.colours,
            &c,
            &(t.rotation * ax),
            GUIDANCE_BINS,
        )
    };
    let g = profile_at(est);
    let o = FitOptions::around(est.scale, 121);
    let Some(best) = fit(&model, &g, &o) else {
        return;
    };
    let at = |s: f64| {
        fit(
            &model,
            &g,
            &FitOptions {
                scale_lo: s,
                scale_hi: s,
                steps: 2,
                ..o
            },
        )
        .map_or(f64::NAN, |f| f.cost)
    };
    let m = Matcher::Geometry(&tree);
    let po = PlaneIcpOptions {
        scale: false,
        ..Default::default()
    };
    // The candidate: the colour's scale, the model's centre where the colour fit puts it along
    // the estimate's axis (same rotation; a reversed fit keeps the centre).
    let mut cand = rescaled(est, best.scale, &ob.center);
    if best.sign > 0 {
        cand.translation += est.rotation * ax * (-best.offset * best.scale);
    }
    let (refit, _) = plane_icp(&oc, &m, &gc.subsample(700), cand, &po);
    let (fe, feo) = fits(est);
    let (fr, fro) = fits(&refit);
    let rel = |s: f64| 100.0 * (s / truth.scale - 1.0);
    // The coloured ICP (6-d key, `compose`'s matcher) with the scale free within ×/÷ 1.4 of the
    // estimate, from the estimate, at several colour weights (compose uses 0.1 of the diagonal).
    let g1500 = gc.subsample(1500);
    let gdiag = g1500.diagonal();
    let icp: Vec<String> = [0.1, 0.3, 1.0]
        .iter()
        .map(|&w| {
            let weight = w * diag;
            let ct = Matcher::colour_tree(&oc, weight);
            let cm = Matcher::Colour { tree: &ct, weight };
            let io = interact3d::compose::icp::IcpOptions {
                iterations: 60,
                keep: 0.8,
                scale_lo: est.scale / 1.4,
                scale_hi: est.scale * 1.4,
                tolerance: 1e-5 * gdiag,
            };
            let (t, _) = interact3d::compose::icp::trimmed_icp(&oc.points, &cm, &g1500, *est, &io);
            let pl = PlaneIcpOptions {
                scale: true,
                scale_lo: est.scale / 1.4,
                scale_hi: est.scale * 1.4,
                ..Default::default()
            };
            let (tp, _) = plane_icp(&oc, &cm, &g1500, *est, &pl);
            format!(
                "w {w}: icp {:+.2} % (fit {:.3e}), plane {:+.2} % (fit {:.3e})",
                rel(t.scale),
                fits(&t).0,
                rel(tp.scale),
                fits(&tp).0
            )
        })
        .collect();
    eprintln!(
        "JUDGEICP {id:<36} seed {seed}: est {:+.2} %; {}",
        rel(est.scale),
        icp.join("; ")
    );
    eprintln!(
        "JUDGE {id:<36} seed {seed}: sign {:+}, est {:+6.2} %, colour {:+6.2} % (cost at est / best {:.3}, contrast {:.2}, best {:.4}); refit colour cost {:.4}; geo fit est {fe:.3e} / {feo:.3e}, refit {fr:.3e} / {fro:.3e} (ratio {:.3} / {:.3})",
        best.sign,
        rel(est.scale),
        rel(best.scale),
        at(est.scale) / best.cost,
        best.contrast,
        best.cost,
        {
            let gr = profile_at(&refit);
            fit(&model, &gr, &FitOptions { scale_lo: refit.scale, scale_hi: refit.scale, steps: 2, ..o }).map_or(f64::NAN, |f| f.cost)
        },
        fr / fe,
        fro / feo,
    );
}
