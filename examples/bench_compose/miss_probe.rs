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

/// `SUPPORT_PROBE=1`: is the resting contact a constraint the truth satisfies and a wrong size
/// violates? For every item, at scales around the truth (and at the estimate's), the pose is
/// refitted from the estimate rescaled about its visible part's centroid (a fixed-scale
/// point-to-plane ICP with a normal offset, as the scale sweep does), and printed: the gap to
/// the composed anchor (% of the item's diagonal at that scale), the guard's offset-out fit
/// (cap fixed at the estimate's), and the fit once the item is moved along the support's
/// normal to touch it (the pose a support-bounded sweep would judge).
pub fn support(
    id: &str,
    inp: &ObjectInput,
    anchor: &interact3d::mesh::Mesh,
    truth: &Similarity,
    est: &Similarity,
) {
    use interact3d::compose::contact_scale::{GapProbe, DENSE};
    use interact3d::compose::plane_icp::plane_icp_offset;
    use interact3d::compose::sdf::AnchorField;
    let oc = Cloud::sample(&inp.visual, 5000, 1);
    let tree = KdTree::new(&oc.points);
    let sp = interact3d::compose::guard::spacing(&inp.visual, 5000);
    let gc = Cloud::sample(&inp.guidance, 2500, 2);
    let probe: Vec<_> = gc.subsample(1000).points;
    let g700 = gc.subsample(700);
    let diag = oc.diagonal();
    let field = AnchorField::new(std::slice::from_ref(anchor), 32);
    let gaps = GapProbe::new(
        oc.subsample(1000).points,
        &Cloud::sample(&inp.visual, DENSE, 4).points,
    );
    let cap = 0.03 * est.scale * diag;
    let fit = |t: &Similarity| offset_fit(&oc, &tree, sp, &probe, t, cap, 0.03 * t.scale * diag).0;
    // The visible part's centroid at the estimate (object samples within 2 % of the diagonal).
    let inv = est.matrix().try_inverse().unwrap();
    let near2 = (0.02 * diag).powi(2);
    let mut seen = vec![false; oc.len()];
    for g in &gc.points {
        if let Some((i, d2)) = tree.nearest(&inv.transform_point(g)) {
            seen[i] |= d2 <= near2;
        }
    }
    let vis: Vec<_> = (0..oc.len()).filter(|&i| seen[i]).collect();
    let pivot = interact3d::mesh::P3::from(
        vis.iter().fold(interact3d::mesh::V3::zeros(), |a, &i| {
            a + oc.points[i].coords
        }) / vis.len().max(1) as f64,
    );
    let m = Matcher::Geometry(&tree);
    let row = |label: String, t: &Similarity| -> String {
        let g = gaps.gap(t, &field);
        let mut touched = *t;
        touched.translation -= g.normal.normalize() * g.value;
        format!(
            "{label}: gap {:+6.2} % fit {:.3e} touched {:.3e}",
            100.0 * g.value / (t.scale * diag),
            fit(t),
            fit(&touched)
        )
    };
    let mut rows = vec![row("est".into(), est), row("truth-pose".into(), truth)];
    let ks = [0.75, 0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.2, 1.3];
    for k in ks {
        let s = truth.scale * k;
        let o = PlaneIcpOptions {
            iterations: 12,
            scale: false,
            scale_lo: s,
            scale_hi: s,
            offset: true,
            offset_max: 0.03 * s * diag,
            ..Default::default()
        };
        let (t, _, _) = plane_icp_offset(&oc, &m, &g700, rescaled(est, s, &pivot), &o);
        rows.push(row(format!("k {k:.2}"), &t));
    }
    eprintln!(
        "  SUPPORT {id:<44} est scale {:+6.2} %\n    {}",
        100.0 * (est.scale / truth.scale - 1.0),
        rows.join("\n    ")
    );
}
