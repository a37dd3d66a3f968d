//! The anchor's choice: the silhouette area of a guidance part seen along −Z.
//!
//! Entry point: [`silhouette_area`] (re-exported as `compose::silhouette_area`).

use crate::mesh::VisualMesh;

/// Silhouette area of a mesh seen along −Z (front view of the Y-up guidance frame), on a
/// `cells`² raster over `window` (x, y bounds).
pub fn silhouette_area(mesh: &VisualMesh, window: ([f64; 2], [f64; 2]), cells: usize) -> f64 {
    let (lo, hi) = window;
    let w = [(hi[0] - lo[0]).max(1e-12), (hi[1] - lo[1]).max(1e-12)];
    let mut covered = vec![false; cells * cells];
    for part in &mesh.parts {
        for t in &part.triangles {
            let q = t.map(|i| {
                let p = part.positions[i as usize];
                [
                    (p.x - lo[0]) / w[0] * cells as f64,
                    (p.y - lo[1]) / w[1] * cells as f64,
                ]
            });
            let area2 = (q[1][0] - q[0][0]) * (q[2][1] - q[0][1])
                - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]);
            if area2 == 0.0 {
                continue;
            }
            let x0 = q
                .iter()
                .map(|p| p[0])
                .fold(f64::INFINITY, f64::min)
                .floor()
                .max(0.0) as usize;
            let x1 = (q
                .iter()
                .map(|p| p[0])
                .fold(f64::NEG_INFINITY, f64::max)
                .ceil() as usize)
                .min(cells);
            let y0 = q
                .iter()
                .map(|p| p[1])
                .fold(f64::INFINITY, f64::min)
                .floor()
                .max(0.0) as usize;
            let y1 = (q
                .iter()
                .map(|p| p[1])
                .fold(f64::NEG_INFINITY, f64::max)
                .ceil() as usize)
                .min(cells);
            for y in y0..y1 {
                for x in x0..x1 {
                    let c = [x as f64 + 0.5, y as f64 + 0.5];
                    let e = |a: [f64; 2], b: [f64; 2]| {
                        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
                    };
                    let (e0, e1, e2) = (e(q[0], q[1]), e(q[1], q[2]), e(q[2], q[0]));
                    if (e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0)
                        || (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0)
                    {
                        covered[y * cells + x] = true;
                    }
                }
            }
        }
    }
    covered.iter().filter(|&&c| c).count() as f64 * w[0] * w[1] / (cells * cells) as f64
}
