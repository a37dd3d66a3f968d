//! `--profile-probe`: the scale the axial profile alone gives each object (no `compose`), against
//! the truth: the object's long axis (its OBB's) mapped into the guidance frame by the true
//! rotation (`truth axis`) or taken from the guidance part's own OBB (`own axis`), the model's
//! profile matched onto the guidance's (`profile.rs` beside it). Tells whether the
//! profile carries the size before anything is wired into the pipeline.

use crate::profile::{fit, FitOptions, Profile, ProfileFit};
use interact3d::compose::cloud::Cloud;
use interact3d::compose::obb::Obb;
use interact3d::compose::ObjectInput;
use interact3d::mesh::V3;
use interact3d::pose::Similarity;

fn frame(axes: &nalgebra::Matrix3<f64>) -> (V3, [V3; 2]) {
    (
        axes.column(0).into_owned(),
        [axes.column(1).into_owned(), axes.column(2).into_owned()],
    )
}

pub fn print(id: &str, seed: u64, inp: &ObjectInput, truth: &Similarity) {
    let oc = Cloud::sample(&inp.visual, 8000, 11);
    let ob = Obb::of_points(&oc.points);
    let (ax, ac) = frame(&ob.axes);
    let model = Profile::along(&oc.points, &ob.center, &ax, ac, 120).filled();
    let gc = Cloud::sample(&inp.guidance, 8000, 12);
    let gb = Obb::of_points(&gc.points);
    let s0 = interact3d::compose::obb::scale_ratio(&ob, &gb);
    let diag = oc.diagonal();
    let o = FitOptions::around(s0, diag, 121);
    let rel = |s: f64| 100.0 * (s / truth.scale - 1.0);
    let show = |f: Option<ProfileFit>| {
        f.map_or("none".to_string(), |f| {
            format!(
                "{:+6.2} % (cost {:.2e} = {:.2} % diag, contrast {:.2}, widen {:+.2} % diag, sign {:+})",
                rel(f.scale),
                f.cost,
                100.0 * f.cost / (truth.scale * diag),
                f.contrast,
                100.0 * f.widen / (truth.scale * diag),
                f.sign
            )
        })
    };
    // The truth's axis through the truth's centre.
    let r = truth.rotation;
    let c = truth.rotation * (truth.scale * ob.center.coords) + truth.translation;
    let gt = Profile::along(
        &gc.points,
        &nalgebra::Point3::from(c),
        &(r * ax),
        [r * ac[0], r * ac[1]],
        60,
    );
    let model_r = Profile::radial(&oc.points, &ob.center, &ax, 120, 0.5).filled();
    let gr = Profile::radial(&gc.points, &nalgebra::Point3::from(c), &(r * ax), 60, 0.5);
    let model_q = Profile::radial(&oc.points, &ob.center, &ax, 120, 0.25).filled();
    let gq = Profile::radial(&gc.points, &nalgebra::Point3::from(c), &(r * ax), 60, 0.25);
    let at_truth = |m: &Profile, g: &Profile, o: &FitOptions| {
        let t = FitOptions {
            scale_lo: truth.scale,
            scale_hi: truth.scale,
            steps: 2,
            ..*o
        };
        fit(m, g, &t).map_or(f64::NAN, |f| 100.0 * f.cost / (truth.scale * diag))
    };
    let o_r = FitOptions {
        widen_max: o.widen_max / 2.0,
        ..o
    };
    let (gx, gcs) = frame(&gb.axes);
    let go = Profile::along(&gc.points, &gb.center, &gx, gcs, 60);
    eprintln!(
        "PROFILE {id:<44} seed {seed}: elongation {:.2}, OBB scale {:+6.2} %; truth axis {}; own axis {}; radial, truth line {} (cost at the truth {:.2} % diag); q25 radial {} (at the truth {:.2} %)",
        ob.extents[0] / ob.extents[1],
        rel(s0),
        show(fit(&model, &gt, &o)),
        show(fit(&model, &go, &o)),
        show(fit(&model_r, &gr, &o_r)),
        at_truth(&model_r, &gr, &o_r),
        show(fit(&model_q, &gq, &o_r)),
        at_truth(&model_q, &gq, &o_r),
    );
}

/// The model's profile and the guidance's (truth axis, mapped back to object units by the
/// truth), side by side in % of the object's diagonal (`PROFILE_DUMP=1`).
pub fn dump(inp: &ObjectInput, truth: &Similarity) {
    let oc = Cloud::sample(&inp.visual, 8000, 11);
    let ob = Obb::of_points(&oc.points);
    let (ax, ac) = frame(&ob.axes);
    let model = Profile::along(&oc.points, &ob.center, &ax, ac, 40).filled();
    let model_r = Profile::radial(&oc.points, &ob.center, &ax, 40, 0.5).filled();
    let gc = Cloud::sample(&inp.guidance, 8000, 12);
    // The guidance in object units (the truth's inverse), binned on the model's bins.
    let inv = truth.matrix().try_inverse().unwrap();
    let back: Vec<_> = gc.points.iter().map(|p| inv.transform_point(p)).collect();
    let g = Profile::along(&back, &ob.center, &ax, ac, 40);
    let gr = Profile::radial(&back, &ob.center, &ax, 40, 0.5);
    let d = oc.diagonal();
    // Bin k of both profiles, in % of the diagonal: "model/guidance".
    let row = |m: &Profile, g: &Profile| -> Vec<String> {
        (0..40)
            .map(|k| {
                format!(
                    "{:.1}/{:.1}",
                    100.0 * m.width[k] / d,
                    100.0 * g.width[k] / d
                )
            })
            .collect()
    };
    let (row, rrow) = (row(&model, &g), row(&model_r, &gr));
    eprintln!(
        "  model/guidance radius (% diag), lo {:+.1} vs {:+.1}: {}",
        100.0 * gr.lo / d,
        100.0 * model_r.lo / d,
        rrow.join(" ")
    );
    eprintln!("  model/guidance width (% diag) along the axis, {:.1} % diag a bin (guidance lo {:+.1} % vs model {:+.1} %): {}", 100.0 * model.bin / d, 100.0 * g.lo / d, 100.0 * model.lo / d, row.join(" "));
}
