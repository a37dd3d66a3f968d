//! For a missed object (`-v`): is it a search failure or a guidance that does not show the
//! object's size? Prints the OBB's initial scale, the guard's fit (mean truncated distance of
//! guidance points to the posed surface, plain and with the pose's own normal offset taken out)
//! at the true pose and at the estimate, and the offset-aware fit along a sweep of scales from
//! the estimate (each scale refitted by a fixed-scale point-to-plane ICP): when the truth fits
//! better than the estimate and the sweep reaches it, a wider scale search would fix the miss;
//! when the estimate fits better, the guidance prefers the wrong size and no search on it can.
//!
//! [`contact`] prints, for every item, its gap to the anchor (min Φ of the anchor over the
//! item's samples) at the estimate and at the truth, beside what the contact-scale stage did:
//! the cue is real when the truth touches and a wrong-size estimate floats or penetrates.

use interact3d::compose::cloud::Cloud;
use interact3d::compose::icp::Matcher;
use interact3d::compose::kdtree::KdTree;
use interact3d::compose::plane_icp::{offset_fit, plane_icp, surface_fit, PlaneIcpOptions};
use interact3d::compose::scale::rescaled;
use interact3d::compose::ObjectInput;
use interact3d::pose::Similarity;

pub fn print(inp: &ObjectInput, truth: &Similarity, est: &Similarity, initial_scale: f64) {
    let oc = Cloud::sample(&inp.visual, 4000, 1);
    let tree = KdTree::new(&oc.points);
    let sp = interact3d::compose::guard::spacing(&inp.visual, 4000);
    let gc = Cloud::sample(&inp.guidance, 1500, 2);
    let probe = &gc.points[..gc.len().min(1000)];
    let fit = |t: &Similarity| {
        let cap = 0.03 * t.scale * oc.diagonal();
        (
            surface_fit(&oc, &tree, sp, probe, t, cap),
            offset_fit(&oc, &tree, sp, probe, t, cap, cap).0,
        )
    };
    let (ft, fto) = fit(truth);
    let (fe, feo) = fit(est);
    let rel = |s: f64| 100.0 * (s / truth.scale - 1.0);
    eprintln!(
        "      initial (OBB) scale {:+6.2} %; fit (plain / offset out): truth {ft:.3e} / {fto:.3e}, estimate {fe:.3e} / {feo:.3e}",
        rel(initial_scale)
    );
    let m = Matcher::Geometry(&tree);
    let c = interact3d::compose::obb::Obb::of_points(&oc.points).center;
    let sweep: Vec<String> = [-0.2, -0.1, -0.05, 0.05, 0.1, 0.2]
        .iter()
        .map(|f| {
            let s = est.scale * (1.0 + f);
            let o = PlaneIcpOptions {
                scale: false,
                ..Default::default()
            };
            let (t, _) = plane_icp(&oc, &m, &gc, rescaled(est, s, &c), &o);
            format!("{:+.0} %: {:.3e}", rel(s), fit(&t).1)
        })
        .collect();
    eprintln!(
        "      offset-out fit along a scale sweep from the estimate: {}",
        sweep.join(", ")
    );
}

/// The item's gap to the anchor at the estimate (against the composed anchor) and at the truth
/// (against the true anchor), in % of the item's diagonal, and the contact stage's report.
pub fn contact(
    id: &str,
    inp: &ObjectInput,
    est: (&interact3d::mesh::Mesh, &Similarity),
    truth: (&interact3d::mesh::Mesh, &Similarity),
    report: Option<&interact3d::compose::contact_scale::ContactReport>,
) {
    use interact3d::compose::contact_scale::{GapProbe, DENSE};
    use interact3d::compose::sdf::AnchorField;
    let oc = Cloud::sample(&inp.visual, 1000, 3);
    let diag = oc.diagonal();
    // The stage's own gap measure: 1,000 samples refined on a dense sample (the truth's exact
    // gap is 0.1 % of the diagonal; 1,000 samples alone read 0.2–1.5 %).
    let probe = GapProbe::new(
        oc.points.clone(),
        &Cloud::sample(&inp.visual, DENSE, 4).points,
    );
    let at = |(m, t): (&interact3d::mesh::Mesh, &Similarity)| {
        let f = AnchorField::new(std::slice::from_ref(m), 32);
        let g = probe.gap(t, &f);
        (100.0 * g.value / (t.scale * diag), g.normal.y)
    };
    let (ge, ne) = at(est);
    let (gt, nt) = at(truth);
    eprintln!(
        "  CONTACT {id:<44} gap % diag: estimate {ge:+6.2} (n.y {ne:+.2}), truth {gt:+6.2} (n.y {nt:+.2}), scale {:+6.2} %; stage {}",
        100.0 * (est.1.scale / truth.1.scale - 1.0),
        report.map_or("-".to_string(), |r| serde_json::to_string(r).unwrap_or_default())
    );
}
