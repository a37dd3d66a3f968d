//! The size of an elongated object from its 1-D profile along its long axis: the cross-section
//! width as a function of the axial coordinate (a handle–shaft step, a bowl–handle neck, the
//! ends), matched between the model (object units) and the guidance (guidance units) with an
//! unknown scale, axial offset, axis direction and width offset (a reconstruction's blur fattens
//! or erodes every cross-section by about the same depth). The guidance must be explained by the
//! model: a guidance cross-section beyond the model's ends costs its whole width, while a model
//! stretch with no guidance (a hole, the hidden contact side) costs nothing. So the scale is
//! pinned by the axial positions of the profile's structure, which holes and noise leave in
//! place, not by the guidance's surface fit.
//!
//! Entry points: [`Profile::along`] (the widths of points binned along an axis), [`fit`] (the
//! scale, offset and direction that best map a model profile onto a guidance profile).

use interact3d::mesh::{P3, V3};

/// Cross-section widths of a point set along an axis.
#[derive(Clone, Debug)]
pub struct Profile {
    /// Axial coordinate of the first bin's start.
    pub lo: f64,
    /// Bin length.
    pub bin: f64,
    /// Width in each bin (`NaN` where the bin has too few points).
    pub width: Vec<f64>,
}

/// Fewest points a bin needs for a width.
const MIN_POINTS: usize = 4;
/// Directions across the axis over which a bin's width is the largest spread.
const DIRECTIONS: usize = 8;
/// The spread of a bin along a direction: between these quantiles of its projections.
const SPREAD_QUANTILE: f64 = 0.05;

fn quantile(sorted: &[f64], q: f64) -> f64 {
    let i = (q * (sorted.len() - 1) as f64).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

/// `points` binned along `axis` (unit) through `origin`: `bins` bins over the 0.5–99.5 % range
/// of the axial coordinates, each point's offset from `origin` mapped by `f` into its bin.
/// Returns (the first bin's start, the bin length, the bins); with no points, one unit-long bin
/// start at 0 and empty bins.
fn binned<T>(
    points: &[P3],
    origin: &P3,
    axis: &V3,
    bins: usize,
    f: impl Fn(&V3) -> T,
) -> (f64, f64, Vec<Vec<T>>) {
    let bins = bins.max(1);
    let mut members: Vec<Vec<T>> = (0..bins).map(|_| Vec::new()).collect();
    let u: Vec<f64> = points.iter().map(|p| axis.dot(&(p - origin))).collect();
    if u.is_empty() {
        return (0.0, 1.0, members);
    }
    let mut s = u.clone();
    s.sort_by(f64::total_cmp);
    let cut = s.len() / 200;
    let (lo, hi) = (s[cut], s[s.len() - 1 - cut]);
    let bin = ((hi - lo) / bins as f64).max(f64::MIN_POSITIVE);
    for (p, &ui) in points.iter().zip(&u) {
        let k = ((ui - lo) / bin).floor();
        if k < 0.0 || k >= bins as f64 {
            continue;
        }
        members[k as usize].push(f(&(p - origin)));
    }
    (lo, bin, members)
}

impl Profile {
    /// The widths of `points` along `axis` (unit) through `origin`, in `bins` bins over the
    /// 0.5–99.5 % range of the axial coordinates. `across` are two unit vectors spanning the
    /// plane across the axis; a bin's width is the largest 5–95 % spread of its points along
    /// [`DIRECTIONS`] directions in that plane (a cylinder seen from one side still shows its
    /// full diameter across the line of sight).
    pub fn along(points: &[P3], origin: &P3, axis: &V3, across: [V3; 2], bins: usize) -> Profile {
        let (lo, bin, members) = binned(points, origin, axis, bins, |d| {
            [across[0].dot(d), across[1].dot(d)]
        });
        let width = members
            .iter()
            .map(|m| {
                if m.len() < MIN_POINTS {
                    return f64::NAN;
                }
                (0..DIRECTIONS)
                    .map(|j| {
                        let a = std::f64::consts::PI * j as f64 / DIRECTIONS as f64;
                        let (c, sn) = (a.cos(), a.sin());
                        let mut x: Vec<f64> = m.iter().map(|q| c * q[0] + sn * q[1]).collect();
                        x.sort_by(f64::total_cmp);
                        quantile(&x, 1.0 - SPREAD_QUANTILE) - quantile(&x, SPREAD_QUANTILE)
                    })
                    .fold(0.0, f64::max)
            })
            .collect();
        Profile { lo, bin, width }
    }

    /// The `q` quantile (0.5: the median) of the distances of `points` to the line through
    /// `origin` along `axis` (unit), in `bins` bins over the 0.5–99.5 % range of the axial
    /// coordinates: a radius profile, robust to a minority of stray points in a bin (bleed onto
    /// the support lies off the axis).
    pub fn radial(points: &[P3], origin: &P3, axis: &V3, bins: usize, q: f64) -> Profile {
        let (lo, bin, mut members) = binned(points, origin, axis, bins, |d| {
            (d - axis * axis.dot(d)).norm()
        });
        let width = members
            .iter_mut()
            .map(|m| {
                if m.len() < MIN_POINTS {
                    return f64::NAN;
                }
                m.sort_by(f64::total_cmp);
                quantile(m, q)
            })
            .collect();
        Profile { lo, bin, width }
    }

    /// Axial coordinate of bin `k`'s centre.
    fn centre(&self, k: usize) -> f64 {
        self.lo + (k as f64 + 0.5) * self.bin
    }

    /// The axial range covered by the bins.
    fn hi(&self) -> f64 {
        self.lo + self.bin * self.width.len() as f64
    }

    /// Bins without a width take their nearest neighbours' (linear between them): a complete
    /// model's sparse bins (a thin shaft sampled by area) are not holes.
    pub fn filled(mut self) -> Profile {
        let known: Vec<usize> = (0..self.width.len())
            .filter(|&k| self.width[k].is_finite())
            .collect();
        if known.is_empty() {
            return self;
        }
        for k in 0..self.width.len() {
            if self.width[k].is_finite() {
                continue;
            }
            let after = known.partition_point(|&j| j < k);
            self.width[k] = match (after.checked_sub(1).map(|i| known[i]), known.get(after)) {
                (Some(a), Some(&b)) => {
                    let t = (k - a) as f64 / (b - a) as f64;
                    self.width[a] * (1.0 - t) + self.width[b] * t
                }
                (Some(a), None) => self.width[a],
                (None, Some(&b)) => self.width[b],
                (None, None) => unreachable!("known is not empty"),
            };
        }
        self
    }

    /// The width at axial coordinate `u` (linear between bin centres), 0 beyond the ends.
    fn at(&self, u: f64) -> f64 {
        if u < self.lo || u > self.hi() {
            return 0.0;
        }
        let x = (u - self.lo) / self.bin - 0.5;
        let n = self.width.len();
        if x <= 0.0 {
            return self.width[0];
        }
        let k = x.floor() as usize;
        if k + 1 >= n {
            return self.width[n - 1];
        }
        let t = x - k as f64;
        self.width[k] * (1.0 - t) + self.width[k + 1] * t
    }
}

/// The map of a model profile onto a guidance profile that [`fit`] found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfileFit {
    /// Scale (guidance units per object unit).
    pub scale: f64,
    /// Guidance axial coordinate of the model's axial origin: v = offset + sign × scale × u.
    pub offset: f64,
    /// −1 when the model runs against the guidance's axis.
    pub sign: f64,
    /// Width offset taken out (guidance units).
    pub widen: f64,
    /// Trimmed mean width residual (guidance units).
    pub cost: f64,
    /// The best cost of any scale at least `contrast_gap` away from `scale` (relative), over
    /// `cost`: how sharply the profile pins the scale (1 = not at all).
    pub contrast: f64,
}

/// Options of [`fit`].
#[derive(Clone, Copy, Debug)]
pub struct FitOptions {
    /// Scales tried: `steps` log-spaced values over [lo, hi] (guidance units per object unit).
    pub scale_lo: f64,
    pub scale_hi: f64,
    pub steps: usize,
    /// Largest width offset taken out, guidance units.
    pub widen_max: f64,
    /// Fraction of the guidance's bins kept (the best-fitting) in the cost.
    pub keep: f64,
    /// Relative distance from the best scale beyond which a scale counts against the contrast.
    pub contrast_gap: f64,
}

impl FitOptions {
    /// `steps` scales within ×/÷ 1.5 of `scale`, width offsets up to 3 % of the scaled
    /// diagonal `diag`, the best-fitting 80 % of the bins kept, rivals counted from 5 % away:
    /// the probe's search around the bounding-box scale.
    pub fn around(scale: f64, diag: f64, steps: usize) -> FitOptions {
        FitOptions {
            scale_lo: scale / 1.5,
            scale_hi: scale * 1.5,
            steps,
            widen_max: 0.03 * diag * scale,
            keep: 0.8,
            contrast_gap: 0.05,
        }
    }
}

/// The cost of mapping `model` onto `guidance` by v = b + sign·k·u, with the width offset
/// fitted (median, clamped to ±`widen_max`); returns (cost, widen).
fn cost(
    model: &Profile,
    guidance: &Profile,
    k: f64,
    b: f64,
    sign: f64,
    o: &FitOptions,
) -> (f64, f64) {
    let mut pred: Vec<(f64, f64)> = Vec::with_capacity(guidance.width.len());
    for (j, &g) in guidance.width.iter().enumerate() {
        if !g.is_finite() {
            continue;
        }
        let u = sign * (guidance.centre(j) - b) / k;
        pred.push((g, k * model.at(u)));
    }
    if pred.is_empty() {
        return (f64::INFINITY, 0.0);
    }
    let mut inside: Vec<f64> = pred
        .iter()
        .filter(|p| p.1 > 0.0)
        .map(|p| p.0 - p.1)
        .collect();
    let widen = if inside.is_empty() {
        0.0
    } else {
        inside.sort_by(f64::total_cmp);
        inside[inside.len() / 2].clamp(-o.widen_max, o.widen_max)
    };
    let mut r: Vec<f64> = pred
        .iter()
        .map(|&(g, m)| if m > 0.0 { (g - m - widen).abs() } else { g })
        .collect();
    r.sort_by(f64::total_cmp);
    let n = ((o.keep * r.len() as f64).ceil() as usize).clamp(1, r.len());
    (r[..n].iter().sum::<f64>() / n as f64, widen)
}

/// The scale, axial offset, direction and width offset mapping `model` (object units, complete,
/// see [`Profile::filled`]) onto `guidance` (guidance units, bins without points ignored) with
/// the least trimmed width residual. For each scale the axial offset is searched in half-bin
/// steps of the guidance over every placement where the two overlap. `None` when the guidance
/// has no bin with a width.
pub fn fit(model: &Profile, guidance: &Profile, o: &FitOptions) -> Option<ProfileFit> {
    if guidance.width.iter().all(|w| !w.is_finite()) || model.width.is_empty() {
        return None;
    }
    let steps = o.steps.max(2);
    let ratio = (o.scale_hi / o.scale_lo).ln();
    // The best (cost, b, widen) of each scale and sign.
    let mut per_scale: Vec<(f64, ProfileFit)> = Vec::with_capacity(steps);
    for i in 0..steps {
        let k = o.scale_lo * (ratio * i as f64 / (steps - 1) as f64).exp();
        let mut best: Option<ProfileFit> = None;
        for sign in [1.0, -1.0] {
            // v of the model's ends: b + sign·k·lo and b + sign·k·hi must overlap [g.lo, g.hi].
            let (a, z) = (sign * k * model.lo, sign * k * model.hi());
            let (mn, mx) = (a.min(z), a.max(z));
            let (b0, b1) = (guidance.lo - mx, guidance.hi() - mn);
            let step = guidance.bin / 2.0;
            let n = ((b1 - b0) / step).ceil() as usize;
            for t in 0..=n {
                let b = b0 + step * t as f64;
                let (c, widen) = cost(model, guidance, k, b, sign, o);
                if best.is_none_or(|f| c < f.cost) {
                    best = Some(ProfileFit {
                        scale: k,
                        offset: b,
                        sign,
                        widen,
                        cost: c,
                        contrast: 1.0,
                    });
                }
            }
        }
        if let Some(f) = best {
            per_scale.push((k, f));
        }
    }
    let (_, mut best) = *per_scale
        .iter()
        .min_by(|a, b| a.1.cost.total_cmp(&b.1.cost))?;
    let rival = per_scale
        .iter()
        .filter(|(k, _)| (k / best.scale).ln().abs() > o.contrast_gap.ln_1p())
        .map(|(_, f)| f.cost)
        .fold(f64::INFINITY, f64::min);
    best.contrast = if best.cost > 0.0 {
        rival / best.cost
    } else {
        f64::INFINITY
    };
    Some(best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use interact3d::rng::Rng;

    /// A stepped bar along x: a handle of radius 0.08 over [0, 0.4), a shaft of radius 0.02 over
    /// [0.4, 1.0]: points on the side surfaces (by area), with `holes` (axial intervals with no
    /// points) and Gaussian noise σ, then scaled by `k` and shifted along x by `shift`.
    fn stepped(
        n: usize,
        k: f64,
        shift: f64,
        holes: &[(f64, f64)],
        sigma: f64,
        seed: u64,
    ) -> Vec<P3> {
        let mut rng = Rng::new(seed);
        let (rh, rs) = (0.08, 0.02);
        let (ah, as_) = (rh * 0.4, rs * 0.6);
        let mut pts = Vec::new();
        while pts.len() < n {
            let on_handle = rng.next_f64() < ah / (ah + as_);
            let (x, r) = if on_handle {
                (0.4 * rng.next_f64(), rh)
            } else {
                (0.4 + 0.6 * rng.next_f64(), rs)
            };
            if holes.iter().any(|&(a, b)| x >= a && x < b) {
                continue;
            }
            // Only the upper half is visible (the contact side hidden).
            let th = std::f64::consts::PI * rng.next_f64();
            let (y, z) = (r * th.cos(), r * th.sin());
            let nz = |rng: &mut Rng| sigma * rng.normal();
            pts.push(P3::new(
                k * x + shift + nz(&mut rng),
                k * y + nz(&mut rng),
                k * z + nz(&mut rng),
            ));
        }
        pts
    }

    fn bar_profile(points: &[P3], bins: usize) -> Profile {
        Profile::along(points, &P3::origin(), &V3::x(), [V3::y(), V3::z()], bins)
    }

    #[test]
    fn a_stepped_bar_with_holes_and_noise_gives_its_scale() {
        let model = bar_profile(&stepped(8000, 1.0, 0.0, &[], 0.0, 1), 120).filled();
        let diag = (1.0f64 + 0.16 * 0.16 * 2.0).sqrt();
        for (k, seed) in [(1.3, 2u64), (0.8, 3), (1.05, 4)] {
            // A hole of 12 % of the diagonal at the far end of the shaft (its end cut off), one
            // across the step's neighbourhood, noise 0.3 % of the diagonal.
            let holes = [(0.88, 1.0), (0.15, 0.27)];
            let g = stepped(6000, k, 0.37, &holes, 0.003 * diag * k, seed);
            let gp = bar_profile(&g, 60);
            let o = FitOptions::around(k, diag, 81);
            let f = fit(&model, &gp, &o).unwrap();
            let err = f.scale / k - 1.0;
            assert!(err.abs() < 0.03, "k {k}: profile scale error {err}");
            assert_eq!(f.sign, 1.0);
            assert!(f.contrast > 1.2, "k {k}: contrast {}", f.contrast);
        }
    }

    #[test]
    fn a_plain_cylinder_does_not_pin_its_scale_once_its_ends_are_hidden() {
        // No structure along the axis and both ends cut off: any scale within the width offset
        // fits, and the contrast says so.
        let cyl = |n, k: f64, lo: f64, hi: f64, seed| {
            let mut rng = Rng::new(seed);
            (0..n)
                .map(|_| {
                    let x = lo + (hi - lo) * rng.next_f64();
                    let th = std::f64::consts::PI * rng.next_f64();
                    P3::new(k * x, k * 0.05 * th.cos(), k * 0.05 * th.sin())
                })
                .collect::<Vec<_>>()
        };
        let model = bar_profile(&cyl(6000, 1.0, 0.0, 1.0, 1), 120).filled();
        let g = bar_profile(&cyl(4000, 1.2, 0.2, 0.8, 2), 60);
        let o = FitOptions {
            scale_lo: 0.8,
            scale_hi: 1.8,
            steps: 61,
            widen_max: 0.05,
            keep: 0.8,
            contrast_gap: 0.05,
        };
        let f = fit(&model, &g, &o).unwrap();
        assert!(f.contrast < 1.2, "contrast {}", f.contrast);
    }
}
