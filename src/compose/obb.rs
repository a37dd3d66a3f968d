//! Oriented bounding boxes from the principal axes of surface samples, and the scale
//! initialisation of the paper (ratio of sorted OBB extents).

use crate::mesh::{P3, V3};
use nalgebra::{Matrix3, SymmetricEigen};

/// An oriented box: centre, axes (columns, right-handed, sorted by extent, longest first) and
/// full extents along them.
#[derive(Clone, Copy, Debug)]
pub struct Obb {
    pub center: P3,
    pub axes: Matrix3<f64>,
    pub extents: V3,
}

impl Obb {
    /// The box of the points along their principal axes.
    pub fn of_points(points: &[P3]) -> Obb {
        let n = points.len().max(1) as f64;
        let mean = points.iter().fold(V3::zeros(), |a, p| a + p.coords) / n;
        let mut cov = Matrix3::zeros();
        for p in points {
            let d = p.coords - mean;
            cov += d * d.transpose();
        }
        cov /= n;
        let eig = SymmetricEigen::new(cov);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
        let mut axes = Matrix3::from_columns(&[
            eig.eigenvectors.column(order[0]).into_owned(),
            eig.eigenvectors.column(order[1]).into_owned(),
            eig.eigenvectors.column(order[2]).into_owned(),
        ]);
        if axes.determinant() < 0.0 {
            let c = -axes.column(2);
            axes.set_column(2, &c);
        }
        // Extents between the 0.5th and 99.5th percentiles of the projections: a few stray
        // points (a fused fragment of the neighbour, noise) do not stretch the box.
        let mut lo = V3::zeros();
        let mut hi = V3::zeros();
        if !points.is_empty() {
            for k in 0..3 {
                let ax = axes.column(k).into_owned();
                let mut proj: Vec<f64> =
                    points.iter().map(|p| ax.dot(&(p.coords - mean))).collect();
                proj.sort_by(f64::total_cmp);
                let cut = proj.len() / 200;
                lo[k] = proj[cut];
                hi[k] = proj[proj.len() - 1 - cut];
            }
        }
        let mid = (lo + hi) / 2.0;
        // Re-sort by extent (principal variance and extent order can differ).
        let ext = hi - lo;
        let mut o = [0usize, 1, 2];
        o.sort_by(|&a, &b| ext[b].total_cmp(&ext[a]));
        let mut sorted = Matrix3::from_columns(&[
            axes.column(o[0]).into_owned(),
            axes.column(o[1]).into_owned(),
            axes.column(o[2]).into_owned(),
        ]);
        if sorted.determinant() < 0.0 {
            let c = -sorted.column(2);
            sorted.set_column(2, &c);
        }
        Obb {
            center: P3::from(mean + axes * mid),
            axes: sorted,
            extents: V3::new(ext[o[0]], ext[o[1]], ext[o[2]]),
        }
    }
}

/// The scale taking `object` onto `guidance`: the median of the ratios of their sorted extents
/// (the median ignores one axis shortened by a hole or lengthened by a fused fragment).
pub fn scale_ratio(object: &Obb, guidance: &Obb) -> f64 {
    let mut r: Vec<f64> = (0..3)
        .filter(|&k| object.extents[k] > 0.0)
        .map(|k| guidance.extents[k] / object.extents[k])
        .collect();
    if r.is_empty() {
        return 1.0;
    }
    r.sort_by(f64::total_cmp);
    r[r.len() / 2]
}

/// The 24 proper rotations that permute and flip the three axes (the symmetries of a box).
pub fn axis_permutations() -> Vec<Matrix3<f64>> {
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut out = Vec::with_capacity(24);
    for p in perms {
        for signs in 0..8u32 {
            let mut m = Matrix3::zeros();
            for (row, &col) in p.iter().enumerate() {
                m[(row, col)] = if signs >> row & 1 == 1 { -1.0 } else { 1.0 };
            }
            if m.determinant() > 0.0 {
                out.push(m);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compose::cloud::Cloud;
    use nalgebra::{Matrix4, UnitQuaternion};

    #[test]
    fn extents_of_a_rotated_box() {
        let mesh = crate::shapes::cuboid(V3::new(0.4, 1.0, 0.2));
        let visual = crate::shapes::plain_visual(&mesh);
        let q = UnitQuaternion::from_euler_angles(0.4, -0.9, 1.7);
        let mut m: Matrix4<f64> = q.to_homogeneous();
        m[(0, 3)] = 3.0;
        m[(1, 3)] = -1.0;
        let cloud = Cloud::sample(&visual, 20_000, 1).transformed(&m);
        let obb = Obb::of_points(&cloud.points);
        let e = obb.extents;
        assert!((e[0] - 1.0).abs() < 0.01, "{e}");
        assert!((e[1] - 0.4).abs() < 0.01, "{e}");
        assert!((e[2] - 0.2).abs() < 0.01, "{e}");
        assert!((obb.center - P3::new(3.0, -1.0, 0.0)).norm() < 0.01);
        // The longest axis is the box's y axis, rotated.
        let y = q * V3::y();
        assert!(obb.axes.column(0).dot(&y).abs() > 0.9999);
        assert!((obb.axes.determinant() - 1.0).abs() < 1e-9);
        assert_eq!(axis_permutations().len(), 24);
    }
}
