//! A static k-d tree over points of `D` coordinates (3: positions; 6: positions + weighted
//! colour, for colour-aware correspondences): nearest neighbour and radius queries. Small and
//! exact; built once per cloud (median splits), queried many times by ICP, scoring and features.

use crate::mesh::P3;

const LEAF: usize = 12;

#[derive(Clone, Debug)]
struct Node<const D: usize> {
    lo: [f64; D],
    hi: [f64; D],
    /// Leaf: range into `idx`; inner: children in `left`, `left + 1`.
    start: u32,
    end: u32,
    left: u32,
}

/// A k-d tree over a fixed set of points.
#[derive(Clone, Debug)]
pub struct KdTreeN<const D: usize> {
    /// The points, in tree order after the build.
    pts: Vec<[f64; D]>,
    idx: Vec<u32>,
    nodes: Vec<Node<D>>,
}

/// The 3-d tree of positions.
pub type KdTree = KdTreeN<3>;

fn d2<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    let mut s = 0.0;
    for k in 0..D {
        s += (a[k] - b[k]).powi(2);
    }
    s
}

fn box_d2<const D: usize>(n: &Node<D>, p: &[f64; D]) -> f64 {
    let mut s = 0.0;
    for k in 0..D {
        let d = (n.lo[k] - p[k]).max(0.0).max(p[k] - n.hi[k]);
        s += d * d;
    }
    s
}

impl KdTree {
    pub fn new(points: &[P3]) -> KdTree {
        KdTreeN::from_coords(points.iter().map(|p| [p.x, p.y, p.z]).collect())
    }

    /// Index and squared distance of the nearest point (`None` for an empty tree).
    pub fn nearest(&self, p: &P3) -> Option<(usize, f64)> {
        self.nearest_n(&[p.x, p.y, p.z])
    }

    /// Indices of all points within `r` of `p`, ascending.
    pub fn within(&self, p: &P3, r: f64, out: &mut Vec<usize>) {
        self.within_n(&[p.x, p.y, p.z], r, out)
    }
}

impl<const D: usize> KdTreeN<D> {
    pub fn from_coords(pts: Vec<[f64; D]>) -> KdTreeN<D> {
        let mut t = KdTreeN {
            idx: (0..pts.len() as u32).collect(),
            pts,
            nodes: Vec::new(),
        };
        if !t.pts.is_empty() {
            t.nodes.push(Node {
                lo: [0.0; D],
                hi: [0.0; D],
                start: 0,
                end: 0,
                left: 0,
            });
            t.build(0, 0, t.idx.len());
            // The points in tree order, so a leaf's points are contiguous in memory (`idx`
            // keeps their original indices).
            t.pts = t.idx.iter().map(|&i| t.pts[i as usize]).collect();
        }
        t
    }

    pub fn len(&self) -> usize {
        self.pts.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pts.is_empty()
    }

    fn build(&mut self, node: usize, start: usize, end: usize) {
        let mut lo = [f64::INFINITY; D];
        let mut hi = [f64::NEG_INFINITY; D];
        for &i in &self.idx[start..end] {
            let p = self.pts[i as usize];
            for k in 0..D {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        self.nodes[node].lo = lo;
        self.nodes[node].hi = hi;
        self.nodes[node].start = start as u32;
        self.nodes[node].end = end as u32;
        if end - start <= LEAF {
            self.nodes[node].left = 0;
            return;
        }
        let axis = (0..D)
            .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
            .unwrap();
        let mid = (start + end) / 2;
        let pts = &self.pts;
        self.idx[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
            pts[a as usize][axis]
                .total_cmp(&pts[b as usize][axis])
                .then(a.cmp(&b))
        });
        let left = self.nodes.len();
        let blank = self.nodes[node].clone();
        self.nodes.push(blank.clone());
        self.nodes.push(blank);
        self.nodes[node].left = left as u32;
        self.build(left, start, mid);
        self.build(left + 1, mid, end);
    }

    /// Index and squared distance of the nearest point (`None` for an empty tree).
    pub fn nearest_n(&self, q: &[f64; D]) -> Option<(usize, f64)> {
        if self.pts.is_empty() {
            return None;
        }
        let q = *q;
        let mut best = (usize::MAX, f64::INFINITY);
        // A fixed stack instead of a heap allocation per query (this is the hottest loop of
        // `compose`): a path holds at most one pending sibling per level, and median splits
        // of 2^32 points are at most 32 levels deep.
        let mut stack = [(0u32, 0.0f64); 66];
        stack[0] = (0, box_d2(&self.nodes[0], &q));
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (n, bd) = stack[top];
            if bd >= best.1 {
                continue;
            }
            let node = &self.nodes[n as usize];
            if node.left == 0 {
                let (a, b) = (node.start as usize, node.end as usize);
                for (&i, p) in self.idx[a..b].iter().zip(&self.pts[a..b]) {
                    let d = d2(p, &q);
                    if d < best.1 || (d == best.1 && (i as usize) < best.0) {
                        best = (i as usize, d);
                    }
                }
                continue;
            }
            let l = node.left;
            let dl = box_d2(&self.nodes[l as usize], &q);
            let dr = box_d2(&self.nodes[l as usize + 1], &q);
            // Push the farther first so the nearer is visited first.
            if dl <= dr {
                stack[top] = (l + 1, dr);
                stack[top + 1] = (l, dl);
            } else {
                stack[top] = (l, dl);
                stack[top + 1] = (l + 1, dr);
            }
            top += 2;
        }
        Some(best)
    }

    /// Indices of all points within `r` of `q`, ascending.
    pub fn within_n(&self, q: &[f64; D], r: f64, out: &mut Vec<usize>) {
        out.clear();
        if self.pts.is_empty() {
            return;
        }
        let q = *q;
        let r2 = r * r;
        let mut stack = vec![0u32];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if box_d2(node, &q) > r2 {
                continue;
            }
            if node.left == 0 {
                let (a, b) = (node.start as usize, node.end as usize);
                for (&i, p) in self.idx[a..b].iter().zip(&self.pts[a..b]) {
                    if d2(p, &q) <= r2 {
                        out.push(i as usize);
                    }
                }
                continue;
            }
            stack.push(node.left);
            stack.push(node.left + 1);
        }
        out.sort_unstable();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn nearest_and_radius_match_brute_force() {
        let mut rng = Rng::new(3);
        let pts: Vec<P3> = (0..2000)
            .map(|_| P3::new(rng.next_f64(), rng.next_f64() * 2.0, rng.next_f64() * 0.5))
            .collect();
        let t = KdTree::new(&pts);
        let mut out = Vec::new();
        for _ in 0..200 {
            let q = P3::new(
                rng.range(-0.2, 1.2),
                rng.range(-0.2, 2.2),
                rng.range(-0.2, 0.7),
            );
            let (i, d) = t.nearest(&q).unwrap();
            let bf = pts
                .iter()
                .map(|p| (p - q).norm_squared())
                .fold(f64::INFINITY, f64::min);
            assert_eq!(d, bf);
            assert_eq!((pts[i] - q).norm_squared(), bf);
            t.within(&q, 0.15, &mut out);
            let bf: Vec<usize> = (0..pts.len())
                .filter(|&k| (pts[k] - q).norm_squared() <= 0.15 * 0.15)
                .collect();
            assert_eq!(out, bf);
        }
    }
}
