//! Closed-form similarity (Umeyama 1991) with a bounded scale, and scale-aware trimmed ICP.

use super::cloud::Cloud;
use super::kdtree::{KdTree, KdTreeN, Warm};
use crate::mesh::{P3, V3};
use crate::pose::Similarity;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion};

/// The similarity `y ≈ s·R·x + t` minimising the squared error over the pairs, with `s`
/// clamped to `[lo, hi]` (for a fixed R the error is a convex quadratic in s, so clamping the
/// unconstrained optimum gives the constrained one). `None` with fewer than 3 pairs.
pub fn umeyama(x: &[P3], y: &[P3], lo: f64, hi: f64) -> Option<Similarity> {
    let n = x.len();
    if n < 3 || y.len() != n {
        return None;
    }
    let nf = n as f64;
    let mx = x.iter().fold(V3::zeros(), |a, p| a + p.coords) / nf;
    let my = y.iter().fold(V3::zeros(), |a, p| a + p.coords) / nf;
    let mut cov = Matrix3::zeros();
    let mut var_x = 0.0;
    for (p, q) in x.iter().zip(y) {
        let dx = p.coords - mx;
        let dy = q.coords - my;
        cov += dy * dx.transpose();
        var_x += dx.norm_squared();
    }
    cov /= nf;
    var_x /= nf;
    if !(var_x > 0.0) {
        return None;
    }
    let svd = cov.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let mut s_diag = Matrix3::identity();
    if u.determinant() * vt.determinant() < 0.0 {
        s_diag[(2, 2)] = -1.0;
    }
    let r = u * s_diag * vt;
    let trace = (Matrix3::from_diagonal(&svd.singular_values) * s_diag).trace();
    let s = (trace / var_x).clamp(lo, hi);
    let t = my - s * r * mx;
    let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    Some(Similarity {
        scale: s,
        rotation,
        translation: t,
    })
}

/// Options of the trimmed ICP.
#[derive(Clone, Copy, Debug)]
pub struct IcpOptions {
    pub iterations: usize,
    /// Fraction of the correspondences kept (the closest ones).
    pub keep: f64,
    /// Scale bounds.
    pub scale_lo: f64,
    pub scale_hi: f64,
    /// Stop when the transform moves the guidance points by less than this (guidance units).
    pub tolerance: f64,
}

/// How ICP pairs a guidance point (mapped into the object frame) with an object sample.
pub enum Matcher<'a> {
    /// The nearest object sample.
    Geometry(&'a KdTree),
    /// The nearest in position + `weight` × colour (both clouds' colours gain-normalised):
    /// on a symmetric shape the geometry is ambiguous and the print decides.
    Colour { tree: &'a KdTreeN<6>, weight: f64 },
}

/// A point and its colour as one key of the colour tree, the colour weighted by `weight`.
fn coloured(q: &P3, colour: &[f64; 3], weight: f64) -> [f64; 6] {
    [
        q.x,
        q.y,
        q.z,
        weight * colour[0],
        weight * colour[1],
        weight * colour[2],
    ]
}

impl<'a> Matcher<'a> {
    /// The 6-d tree of `object` for [`Matcher::Colour`].
    pub fn colour_tree(object: &Cloud, weight: f64) -> KdTreeN<6> {
        KdTreeN::from_coords(
            object
                .points
                .iter()
                .zip(&object.colours)
                .map(|(p, c)| coloured(p, c, weight))
                .collect(),
        )
    }

    /// The object sample paired with `q` (object frame) of colour `colour`.
    pub fn nearest(&self, q: &P3, colour: &[f64; 3]) -> Option<(usize, f64)> {
        self.nearest_from(q, colour, usize::MAX)
    }

    /// [`Self::nearest`] started from object sample `hint` (the same answer; see
    /// [`KdTreeN::nearest_from_n`]).
    pub fn nearest_from(&self, q: &P3, colour: &[f64; 3], hint: usize) -> Option<(usize, f64)> {
        match self {
            Matcher::Geometry(t) => t.nearest_from(q, hint),
            Matcher::Colour { tree, weight } => {
                tree.nearest_from_n(&coloured(q, colour, *weight), hint)
            }
        }
    }

    /// [`Self::nearest`] of a guidance point asked again at every ICP iteration, each time a
    /// little moved: the same answer, often without a search (see [`KdTreeN::nearest_warm_n`]).
    pub fn nearest_warm(&self, q: &P3, colour: &[f64; 3], warm: &mut Warm) -> Option<(usize, f64)> {
        match self {
            Matcher::Geometry(t) => t.nearest_warm(q, warm),
            Matcher::Colour { tree, weight } => {
                tree.nearest_warm_n(&coloured(q, colour, *weight), warm)
            }
        }
    }
}

/// Order the `k` smallest of `items` by `key` (a distance, then a distinct index) first,
/// ascending: the prefix a full sort gives (the key is a total order, the indices being
/// distinct), at the cost of a selection and a sort of the prefix only. The order of the rest
/// is unspecified. ICP's pairs use (distance, guidance index); `global::recentred` its
/// residuals in the order found.
pub(super) fn smallest_sorted<T>(items: &mut [T], k: usize, key: impl Fn(&T) -> (f64, usize)) {
    let by = |a: &T, b: &T| {
        let (a, b) = (key(a), key(b));
        a.0.total_cmp(&b.0).then(a.1.cmp(&b.1))
    };
    let k = k.min(items.len());
    if k < items.len() {
        items.select_nth_unstable_by(k, by);
    }
    items[..k].sort_unstable_by(by);
}

/// The element at `i` of `v` sorted ascending (`f64::total_cmp`): a median or quantile without
/// sorting all of `v` (`v` is reordered).
pub(super) fn nth_smallest(v: &mut [f64], i: usize) -> f64 {
    *v.select_nth_unstable_by(i, f64::total_cmp).1
}

/// Transform the object into the guidance points: for each guidance point the nearest object
/// sample (the guidance part has holes, the object does not, so correspondences go from the
/// guidance to the object), the worst `1 − keep` dropped, Umeyama on the rest, repeated.
/// Returns the pose and the RMS of the kept pairs (guidance units).
pub fn trimmed_icp(
    object: &[P3],
    matcher: &Matcher,
    guidance: &Cloud,
    init: Similarity,
    o: &IcpOptions,
) -> (Similarity, f64) {
    let mut t = init;
    let mut rms = f64::INFINITY;
    let n = guidance.len();
    let mut pairs: Vec<(f64, usize, usize)> = Vec::with_capacity(n);
    let mut xs = Vec::with_capacity(n);
    let mut ys = Vec::with_capacity(n);
    // Each guidance point's partner in the previous iteration and the ball about it where that
    // partner is certainly still the nearest: the next search starts there, or is not needed.
    let mut prev = vec![Warm::default(); n];
    for _ in 0..o.iterations {
        let inv = t
            .matrix()
            .try_inverse()
            .unwrap_or_else(nalgebra::Matrix4::identity);
        pairs.clear();
        for gi in 0..n {
            let q = inv.transform_point(&guidance.points[gi]);
            if let Some((oi, _)) = matcher.nearest_warm(&q, &guidance.colours[gi], &mut prev[gi]) {
                // Trim by the geometric distance only: with colour-aware matching the pairs
                // whose colours disagree are the ones that turn a symmetric shape the right way;
                // they are not outliers.
                pairs.push(((q - object[oi]).norm_squared(), gi, oi));
            }
        }
        if pairs.len() < 3 {
            break;
        }
        let k = ((pairs.len() as f64 * o.keep) as usize).clamp(3, pairs.len());
        smallest_sorted(&mut pairs, k, |p| (p.0, p.1));
        xs.clear();
        ys.clear();
        for &(_, gi, oi) in &pairs[..k] {
            xs.push(object[oi]);
            ys.push(guidance.points[gi]);
        }
        let m = t.matrix();
        rms = (xs
            .iter()
            .zip(&ys)
            .map(|(x, y)| (m.transform_point(x) - y).norm_squared())
            .sum::<f64>()
            / k as f64)
            .sqrt();
        let Some(next) = umeyama(&xs, &ys, o.scale_lo, o.scale_hi) else {
            break;
        };
        let nm = next.matrix();
        let moved = xs
            .iter()
            .step_by((xs.len() / 32).max(1))
            .map(|p| (nm.transform_point(p) - m.transform_point(p)).norm())
            .fold(0.0, f64::max);
        t = next;
        if moved < o.tolerance {
            break;
        }
    }
    (t, rms)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// The selection gives the prefix of a full stable sort, element for element, on data with
    /// many tied distances (the guidance index decides), and the quantile of a full sort.
    #[test]
    fn smallest_sorted_is_the_prefix_of_a_full_sort() {
        let mut rng = Rng::new(3);
        for n in [1usize, 2, 7, 100, 1500] {
            let pairs: Vec<(f64, usize, usize)> = (0..n)
                .map(|i| {
                    (
                        (rng.below(20) as f64) * 0.25,
                        (i * 7919) % n.max(1),
                        rng.below(50),
                    )
                })
                .collect();
            // Distinct guidance indices, as ICP's pairs have (one pair per guidance point).
            let mut seen = std::collections::HashSet::new();
            assert!(pairs.iter().all(|p| seen.insert(p.1)));
            let mut full = pairs.clone();
            full.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for k in [0, 1, n / 2, (n as f64 * 0.8) as usize, n] {
                let mut part = pairs.clone();
                smallest_sorted(&mut part, k, |p| (p.0, p.1));
                assert_eq!(part[..k], full[..k], "n {n} k {k}");
            }
            let mut v: Vec<f64> = pairs.iter().map(|p| p.0 - 2.0).collect();
            let mut sorted = v.clone();
            sorted.sort_by(f64::total_cmp);
            assert_eq!(nth_smallest(&mut v, n / 2), sorted[n / 2]);
        }
    }

    #[test]
    fn umeyama_recovers_a_known_similarity_exactly() {
        let mut rng = Rng::new(7);
        let truth = Similarity {
            scale: 0.137,
            rotation: rng.rotation(),
            translation: V3::new(0.3, -1.2, 2.5),
        };
        let x: Vec<P3> = (0..50)
            .map(|_| P3::new(rng.normal(), rng.normal(), rng.normal()))
            .collect();
        let y: Vec<P3> = x
            .iter()
            .map(|p| truth.matrix().transform_point(p))
            .collect();
        let s = umeyama(&x, &y, 1e-6, 1e6).unwrap();
        assert!((s.scale - truth.scale).abs() < 1e-12);
        assert!(s.rotation.angle_to(&truth.rotation) < 1e-9);
        assert!((s.translation - truth.translation).norm() < 1e-12);
        // A bound on the scale is honoured, and the rotation is still right.
        let b = umeyama(&x, &y, 0.2, 0.3).unwrap();
        assert_eq!(b.scale, 0.2);
        assert!(b.rotation.angle_to(&truth.rotation) < 1e-9);
    }

    #[test]
    fn icp_converges_from_a_nearby_start_with_outliers() {
        let mut rng = Rng::new(11);
        let mesh = crate::shapes::cuboid(V3::new(1.0, 0.6, 0.3));
        let vis = crate::shapes::plain_visual(&mesh);
        let obj = crate::compose::cloud::Cloud::sample(&vis, 4000, 1);
        let truth = Similarity {
            scale: 2.0,
            rotation: UnitQuaternion::from_euler_angles(0.3, 0.2, -0.4),
            translation: V3::new(1.0, 2.0, 3.0),
        };
        let mut g = Cloud::default();
        for p in Cloud::sample(&vis, 1000, 2)
            .points
            .iter()
            .filter(|p| p.x < 0.3)
        {
            // a hole: part of the surface missing
            g.points.push(truth.matrix().transform_point(p));
        }
        for _ in 0..60 {
            g.points.push(P3::new(
                rng.range(0.0, 3.0),
                rng.range(1.0, 4.0),
                rng.range(2.0, 5.0),
            ));
        }
        g.colours = vec![[0.5; 3]; g.points.len()];
        g.normals = vec![V3::z(); g.points.len()];
        let init = Similarity {
            scale: 1.9,
            rotation: UnitQuaternion::from_euler_angles(0.4, 0.1, -0.3),
            translation: V3::new(1.05, 2.0, 2.95),
        };
        let tree = KdTree::new(&obj.points);
        let o = IcpOptions {
            iterations: 100,
            keep: 0.85,
            scale_lo: 1.5,
            scale_hi: 2.5,
            tolerance: 1e-7,
        };
        let (t, _) = trimmed_icp(&obj.points, &Matcher::Geometry(&tree), &g, init, &o);
        assert!(t.rotation.angle_to(&truth.rotation).to_degrees() < 1.0);
        assert!((t.scale - 2.0).abs() < 0.03, "{}", t.scale);
        assert!((t.translation - truth.translation).norm() < 0.03);
    }
}
