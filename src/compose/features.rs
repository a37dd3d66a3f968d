//! FPFH (Rusu et al. 2009) on voxel-downsampled clouds: 33-bin histograms of the Darboux-frame
//! angles between each keypoint's normal and its neighbours', smoothed over the neighbourhood.

use super::cloud::Cloud;
use super::kdtree::KdTree;
use crate::mesh::{P3, V3};
use rayon::prelude::*;
use std::collections::BTreeMap;

pub const BINS: usize = 11;
pub const DIM: usize = 3 * BINS;

/// Keypoints (voxel centroids with averaged normals and colours) and their descriptors.
#[derive(Clone, Debug, Default)]
pub struct Features {
    pub points: Vec<P3>,
    pub normals: Vec<V3>,
    pub colours: Vec<[f64; 3]>,
    pub descriptors: Vec<[f32; DIM]>,
}

/// Average the cloud's points per voxel of size `voxel` (cells in sorted order: deterministic).
pub fn downsample(c: &Cloud, voxel: f64) -> Cloud {
    let mut cells: BTreeMap<[i64; 3], (V3, V3, [f64; 3], usize)> = BTreeMap::new();
    for i in 0..c.len() {
        let p = c.points[i];
        let key = [
            (p.x / voxel).floor() as i64,
            (p.y / voxel).floor() as i64,
            (p.z / voxel).floor() as i64,
        ];
        let e = cells
            .entry(key)
            .or_insert((V3::zeros(), V3::zeros(), [0.0; 3], 0));
        e.0 += p.coords;
        e.1 += c.normals[i];
        for k in 0..3 {
            e.2[k] += c.colours[i][k];
        }
        e.3 += 1;
    }
    let mut out = Cloud::default();
    for (_, (p, n, col, k)) in cells {
        let kf = k as f64;
        out.points.push(P3::from(p / kf));
        out.normals.push(if n.norm() > 1e-12 {
            n.normalize()
        } else {
            V3::z()
        });
        out.colours.push(col.map(|x| x / kf));
    }
    out
}

fn spfh(pts: &[P3], nrm: &[V3], i: usize, nb: &[usize]) -> [f32; DIM] {
    let mut h = [0f32; DIM];
    let (p, n) = (pts[i], nrm[i]);
    let mut count = 0;
    for &j in nb {
        if j == i {
            continue;
        }
        let d = pts[j] - p;
        let dist = d.norm();
        if dist < 1e-12 {
            continue;
        }
        let dn = d / dist;
        let u = n;
        let v = u.cross(&dn);
        if v.norm() < 1e-9 {
            continue;
        }
        let v = v.normalize();
        let w = u.cross(&v);
        let nj = nrm[j];
        let alpha = v.dot(&nj); // [-1, 1]
        let phi = u.dot(&dn); // [-1, 1]
        let theta = w.dot(&nj).atan2(u.dot(&nj)); // [-pi, pi]
        let bin = |x: f64, lo: f64, hi: f64| {
            (((x - lo) / (hi - lo) * BINS as f64) as usize).min(BINS - 1)
        };
        h[bin(alpha, -1.0, 1.0)] += 1.0;
        h[BINS + bin(phi, -1.0, 1.0)] += 1.0;
        h[2 * BINS + bin(theta, -std::f64::consts::PI, std::f64::consts::PI)] += 1.0;
        count += 1;
    }
    if count > 0 {
        let s = 100.0 / count as f32;
        h.iter_mut().for_each(|x| *x *= s);
    }
    h
}

/// Downsample `c` at `voxel` and describe each keypoint by FPFH over `radius`.
pub fn fpfh(c: &Cloud, voxel: f64, radius: f64) -> Features {
    let k = downsample(c, voxel);
    let tree = KdTree::new(&k.points);
    let nbs: Vec<Vec<usize>> = (0..k.len())
        .into_par_iter()
        .map(|i| {
            let mut out = Vec::new();
            tree.within(&k.points[i], radius, &mut out);
            out
        })
        .collect();
    let sp: Vec<[f32; DIM]> = (0..k.len())
        .into_par_iter()
        .map(|i| spfh(&k.points, &k.normals, i, &nbs[i]))
        .collect();
    let descriptors: Vec<[f32; DIM]> = (0..k.len())
        .into_par_iter()
        .map(|i| {
            let mut h = sp[i];
            let mut acc = [0f32; DIM];
            let mut wsum = 0f32;
            for &j in &nbs[i] {
                if j == i {
                    continue;
                }
                let d = (k.points[j] - k.points[i]).norm() as f32;
                if d <= 0.0 {
                    continue;
                }
                let w = 1.0 / d;
                for b in 0..DIM {
                    acc[b] += w * sp[j][b];
                }
                wsum += w;
            }
            if wsum > 0.0 {
                for b in 0..DIM {
                    h[b] += acc[b] / wsum;
                }
            }
            // Normalise each of the three histograms to sum 100.
            for s in 0..3 {
                let sum: f32 = h[s * BINS..(s + 1) * BINS].iter().sum();
                if sum > 0.0 {
                    for b in s * BINS..(s + 1) * BINS {
                        h[b] *= 100.0 / sum;
                    }
                }
            }
            h
        })
        .collect();
    Features {
        points: k.points,
        normals: k.normals,
        colours: k.colours,
        descriptors,
    }
}

fn fdist(a: &[f32; DIM], b: &[f32; DIM]) -> f32 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// One chunk of rows of the matching: each row's nearest column, and each column's (least
/// distance, row) over the chunk's rows.
type Chunk = (Vec<usize>, Vec<(f32, usize)>);

/// Putative correspondences (index in `a`, index in `b`): each point's nearest descriptor in
/// the other set, both directions, mutual matches first, deterministic order.
pub fn match_features(a: &Features, b: &Features) -> Vec<(usize, usize)> {
    if a.descriptors.is_empty() || b.descriptors.is_empty() {
        return Vec::new();
    }
    // Both directions from one pass over the distance matrix (fdist is symmetric bit for bit:
    // (x − y)² = (y − x)²): each row's and each column's first index of least distance, as a
    // scan of the row or the column in index order finds it. Rows are split into chunks; a
    // later chunk takes a column only with a strictly smaller distance, so the merge keeps the
    // lowest index of a tie.
    let chunk = 64;
    let parts: Vec<Chunk> = a
        .descriptors
        .par_chunks(chunk)
        .enumerate()
        .map(|(c, rows)| {
            let mut cols = vec![(f32::INFINITY, 0usize); b.descriptors.len()];
            let ab = rows
                .iter()
                .enumerate()
                .map(|(r, x)| {
                    let i = c * chunk + r;
                    let mut best = (0, f32::INFINITY);
                    for (j, (y, col)) in b.descriptors.iter().zip(cols.iter_mut()).enumerate() {
                        let d = fdist(x, y);
                        if d < best.1 {
                            best = (j, d);
                        }
                        if d < col.0 {
                            *col = (d, i);
                        }
                    }
                    best.0
                })
                .collect();
            (ab, cols)
        })
        .collect();
    let mut ab: Vec<usize> = Vec::with_capacity(a.descriptors.len());
    let mut cols = vec![(f32::INFINITY, 0usize); b.descriptors.len()];
    for (rows, part) in parts {
        ab.extend(rows);
        for (col, p) in cols.iter_mut().zip(part) {
            if p.0 < col.0 {
                *col = p;
            }
        }
    }
    let ba: Vec<usize> = cols.into_iter().map(|c| c.1).collect();
    let mut mutual = Vec::new();
    let mut rest = Vec::new();
    for (i, &j) in ab.iter().enumerate() {
        if ba[j] == i {
            mutual.push((i, j));
        } else {
            rest.push((i, j));
        }
    }
    for (j, &i) in ba.iter().enumerate() {
        if ab[i] != j {
            rest.push((i, j));
        }
    }
    mutual.extend(rest);
    mutual
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one-pass matcher gives the pairs of two separate nearest-descriptor scans (each
    /// direction's first index of least distance), on descriptors with many exact ties and more
    /// rows than one chunk.
    #[test]
    fn one_pass_matching_equals_two_scans() {
        let mut rng = crate::rng::Rng::new(4);
        let mut set = |n: usize| Features {
            descriptors: (0..n)
                .map(|_| std::array::from_fn(|_| rng.below(3) as f32 * 0.5))
                .collect(),
            ..Default::default()
        };
        for (na, nb) in [(1, 1), (5, 200), (150, 90), (300, 301)] {
            let (a, b) = (set(na), set(nb));
            let scan = |x: &[f32; DIM], s: &[[f32; DIM]]| {
                let d: Vec<f32> = s.iter().map(|y| fdist(x, y)).collect();
                let m = d.iter().cloned().fold(f32::INFINITY, f32::min);
                d.iter().position(|&v| v == m).unwrap()
            };
            let ab: Vec<usize> = a
                .descriptors
                .iter()
                .map(|x| scan(x, &b.descriptors))
                .collect();
            let ba: Vec<usize> = b
                .descriptors
                .iter()
                .map(|x| scan(x, &a.descriptors))
                .collect();
            let mut want: Vec<(usize, usize)> = Vec::new();
            let mut rest = Vec::new();
            for (i, &j) in ab.iter().enumerate() {
                if ba[j] == i {
                    want.push((i, j));
                } else {
                    rest.push((i, j));
                }
            }
            for (j, &i) in ba.iter().enumerate() {
                if ab[i] != j {
                    rest.push((i, j));
                }
            }
            want.extend(rest);
            assert_eq!(match_features(&a, &b), want, "{na} × {nb}");
        }
    }
}
