//! A small f64 bounding-volume hierarchy over triangles (median split, leaves of up to
//! [`LEAF`] triangles) with the three traversals the metrics need: all intersecting leaf pairs
//! of two trees, the minimum distance between two trees (branch and bound), and the nearest
//! triangle to a point. Everything is sequential and visits nodes in a fixed order, so results
//! are bit-for-bit reproducible.

use super::geom::{self, V};

const LEAF: usize = 4;

#[derive(Clone, Copy, Debug)]
pub struct Bb {
    pub min: V,
    pub max: V,
}

impl Bb {
    pub const EMPTY: Bb = Bb {
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
    };
    pub fn grow(&mut self, p: V) {
        for k in 0..3 {
            self.min[k] = self.min[k].min(p[k]);
            self.max[k] = self.max[k].max(p[k]);
        }
    }
    pub fn merge(&self, o: &Bb) -> Bb {
        let mut b = *self;
        b.grow(o.min);
        b.grow(o.max);
        b
    }
    /// Closed overlap test.
    pub fn overlaps(&self, o: &Bb) -> bool {
        (0..3).all(|k| self.min[k] <= o.max[k] && o.min[k] <= self.max[k])
    }
    pub fn contains(&self, p: V) -> bool {
        (0..3).all(|k| self.min[k] <= p[k] && p[k] <= self.max[k])
    }
    /// Squared distance between two boxes (0 when they overlap).
    pub fn dist2(&self, o: &Bb) -> f64 {
        let mut d = 0.0;
        for k in 0..3 {
            let g = (o.min[k] - self.max[k])
                .max(self.min[k] - o.max[k])
                .max(0.0);
            d += g * g;
        }
        d
    }
    /// Squared distance from a point to the box (0 inside).
    pub fn point_dist2(&self, p: V) -> f64 {
        let mut d = 0.0;
        for k in 0..3 {
            let g = (self.min[k] - p[k]).max(p[k] - self.max[k]).max(0.0);
            d += g * g;
        }
        d
    }
}

#[derive(Clone, Copy, Debug)]
struct Node {
    bb: Bb,
    /// Leaf: first index into `order`; inner: index of the left child (right = left + 1).
    start: u32,
    /// Leaf: number of triangles (> 0); inner: 0.
    count: u32,
}

/// A BVH over a triangle soup (the corners of every triangle, already resolved).
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
    pub tris: Vec<[V; 3]>,
}

fn tri_bb(t: &[V; 3]) -> Bb {
    let mut b = Bb::EMPTY;
    for p in t {
        b.grow(*p);
    }
    b
}

impl Bvh {
    pub fn new(tris: Vec<[V; 3]>) -> Bvh {
        let boxes: Vec<Bb> = tris.iter().map(tri_bb).collect();
        let cent: Vec<V> = boxes
            .iter()
            .map(|b| geom::scale(geom::add(b.min, b.max), 0.5))
            .collect();
        let mut order: Vec<u32> = (0..tris.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * tris.len() / LEAF + 1);
        nodes.push(Node {
            bb: Bb::EMPTY,
            start: 0,
            count: 0,
        });
        if !tris.is_empty() {
            build(&mut nodes, 0, &mut order, 0, &boxes, &cent);
        }
        Bvh { nodes, order, tris }
    }

    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    fn leaf(&self, n: &Node) -> &[u32] {
        &self.order[n.start as usize..(n.start + n.count) as usize]
    }

    /// Calls `f(i, j)` for every pair of triangles (i in self, j in other) whose boxes overlap,
    /// in a fixed order. `f` returns false to stop early.
    pub fn overlapping_pairs(&self, other: &Bvh, mut f: impl FnMut(usize, usize) -> bool) {
        if self.is_empty() || other.is_empty() {
            return;
        }
        let mut stack = vec![(0u32, 0u32)];
        while let Some((a, b)) = stack.pop() {
            let (na, nb) = (&self.nodes[a as usize], &other.nodes[b as usize]);
            if !na.bb.overlaps(&nb.bb) {
                continue;
            }
            match (na.count > 0, nb.count > 0) {
                (true, true) => {
                    for &i in self.leaf(na) {
                        let bi = tri_bb(&self.tris[i as usize]);
                        if !bi.overlaps(&nb.bb) {
                            continue;
                        }
                        for &j in other.leaf(nb) {
                            if bi.overlaps(&tri_bb(&other.tris[j as usize]))
                                && !f(i as usize, j as usize)
                            {
                                return;
                            }
                        }
                    }
                }
                (false, true) => {
                    stack.push((na.start + 1, b));
                    stack.push((na.start, b));
                }
                (true, false) => {
                    stack.push((a, nb.start + 1));
                    stack.push((a, nb.start));
                }
                (false, false) => {
                    // Split the bigger box.
                    let ea = geom::norm2(geom::sub(na.bb.max, na.bb.min));
                    let eb = geom::norm2(geom::sub(nb.bb.max, nb.bb.min));
                    if ea >= eb {
                        stack.push((na.start + 1, b));
                        stack.push((na.start, b));
                    } else {
                        stack.push((a, nb.start + 1));
                        stack.push((a, nb.start));
                    }
                }
            }
        }
    }

    /// Exact minimum squared distance between the two triangle sets (branch and bound on box
    /// distances; closest child pairs first).
    pub fn min_dist2(&self, other: &Bvh) -> f64 {
        let mut best = f64::INFINITY;
        if self.is_empty() || other.is_empty() {
            return best;
        }
        let mut stack = vec![(0u32, 0u32, self.nodes[0].bb.dist2(&other.nodes[0].bb))];
        while let Some((a, b, d)) = stack.pop() {
            if d >= best {
                continue;
            }
            let (na, nb) = (&self.nodes[a as usize], &other.nodes[b as usize]);
            if na.count > 0 && nb.count > 0 {
                for &i in self.leaf(na) {
                    for &j in other.leaf(nb) {
                        let d2 =
                            geom::tri_tri_dist2(&self.tris[i as usize], &other.tris[j as usize]);
                        if d2 < best {
                            best = d2;
                            if best == 0.0 {
                                return 0.0;
                            }
                        }
                    }
                }
                continue;
            }
            let split_a = nb.count > 0
                || (na.count == 0 && {
                    let ea = geom::norm2(geom::sub(na.bb.max, na.bb.min));
                    let eb = geom::norm2(geom::sub(nb.bb.max, nb.bb.min));
                    ea >= eb
                });
            let kids: [(u32, u32); 2] = if split_a {
                [(na.start, b), (na.start + 1, b)]
            } else {
                [(a, nb.start), (a, nb.start + 1)]
            };
            let mut c: [(u32, u32, f64); 2] = kids.map(|(x, y)| {
                (
                    x,
                    y,
                    self.nodes[x as usize].bb.dist2(&other.nodes[y as usize].bb),
                )
            });
            // Push the farther first so the nearer is explored first.
            if c[0].2 < c[1].2 {
                c.swap(0, 1);
            }
            for e in c {
                if e.2 < best {
                    stack.push(e);
                }
            }
        }
        best
    }

    /// Squared distance from `p` to the nearest triangle, and that triangle. `hint`, a
    /// triangle likely to be near (e.g. the answer for a neighbouring point), only seeds the
    /// bound: the result is the exact minimum either way.
    pub fn nearest(&self, p: V, hint: Option<usize>) -> (f64, usize) {
        let mut best = f64::INFINITY;
        let mut arg = usize::MAX;
        if self.is_empty() {
            return (best, arg);
        }
        if let Some(h) = hint.filter(|&h| h < self.tris.len()) {
            best = geom::point_tri_dist2(p, &self.tris[h]);
            arg = h;
        }
        let mut stack = vec![(0u32, self.nodes[0].bb.point_dist2(p))];
        while let Some((a, d)) = stack.pop() {
            if d >= best {
                continue;
            }
            let na = &self.nodes[a as usize];
            if na.count > 0 {
                for &i in self.leaf(na) {
                    let d2 = geom::point_tri_dist2(p, &self.tris[i as usize]);
                    if d2 < best {
                        best = d2;
                        arg = i as usize;
                    }
                }
                continue;
            }
            let l = (na.start, self.nodes[na.start as usize].bb.point_dist2(p));
            let r = (
                na.start + 1,
                self.nodes[na.start as usize + 1].bb.point_dist2(p),
            );
            let (near, far) = if l.1 <= r.1 { (l, r) } else { (r, l) };
            if far.1 < best {
                stack.push(far);
            }
            if near.1 < best {
                stack.push(near);
            }
        }
        (best, arg)
    }
}

fn build(
    nodes: &mut Vec<Node>,
    ni: usize,
    order: &mut [u32],
    start: u32,
    boxes: &[Bb],
    cent: &[V],
) {
    let mut bb = Bb::EMPTY;
    let mut cb = Bb::EMPTY;
    for &i in order.iter() {
        bb = bb.merge(&boxes[i as usize]);
        cb.grow(cent[i as usize]);
    }
    nodes[ni].bb = bb;
    if order.len() <= LEAF {
        nodes[ni].start = start;
        nodes[ni].count = order.len() as u32;
        return;
    }
    let ext = geom::sub(cb.max, cb.min);
    let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] {
        0
    } else if ext[1] >= ext[2] {
        1
    } else {
        2
    };
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&x, &y| {
        cent[x as usize][axis]
            .total_cmp(&cent[y as usize][axis])
            .then(x.cmp(&y))
    });
    let left = nodes.len();
    let empty = Node {
        bb: Bb::EMPTY,
        start: 0,
        count: 0,
    };
    nodes.push(empty);
    nodes.push(empty);
    nodes[ni].start = left as u32;
    nodes[ni].count = 0;
    let (lo, hi) = order.split_at_mut(mid);
    build(nodes, left, lo, start, boxes, cent);
    build(nodes, left + 1, hi, start + mid as u32, boxes, cent);
}
