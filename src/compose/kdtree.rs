//! A static k-d tree over points of `D` coordinates (3: positions; 6: positions + weighted
//! colour, for colour-aware correspondences): nearest neighbour and radius queries. Small and
//! exact; built once per cloud (median splits), queried many times by ICP, scoring and features.

use crate::mesh::P3;

const LEAF: usize = 12;

/// A moving query's warm start (ICP asks for the same guidance point's partner at every
/// iteration, each time a little moved): the last answer and a certificate, a ball about the
/// point `at` where that answer was found in which no other point lies within `clear`. A query
/// `q` whose answer's distance `a` and distance `δ` from `at` satisfy `a + δ < clear` has that
/// answer as its strict nearest (every other point is at least `clear − δ > a` away, by the
/// triangle inequality), so the tree is not searched. `Warm::default()`: no hint yet.
#[derive(Clone, Copy, Debug)]
pub struct Warm {
    hint: usize,
    /// The query of the last full search (its first `D` coordinates).
    at: [f64; 6],
    /// A lower bound on the distance (not squared) from `at` to every point but `hint`, shrunk
    /// by a relative margin that covers the rounding of the squared distances; `-1`: none.
    clear: f64,
}

impl Default for Warm {
    fn default() -> Self {
        Warm {
            hint: usize::MAX,
            at: [0.0; 6],
            clear: -1.0,
        }
    }
}

impl Warm {
    /// The answer's index of the last search (`usize::MAX`: none yet).
    pub fn hint(&self) -> usize {
        self.hint
    }
}

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
    /// Tree position of each original index (the inverse of `idx`), for warm starts.
    pos: Vec<u32>,
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

    /// Index and squared distance of the nearest point (`None` for an empty tree); ties go to
    /// the lowest index.
    pub fn nearest(&self, p: &P3) -> Option<(usize, f64)> {
        self.nearest_n(&[p.x, p.y, p.z])
    }

    /// [`Self::nearest`] started from point `hint` (see [`KdTreeN::nearest_from_n`]).
    pub fn nearest_from(&self, p: &P3, hint: usize) -> Option<(usize, f64)> {
        self.nearest_from_n(&[p.x, p.y, p.z], hint)
    }

    /// [`Self::nearest`] when its squared distance is at most `r2`, else `None`.
    pub fn nearest_within(&self, p: &P3, r2: f64) -> Option<(usize, f64)> {
        self.nearest_within_n(&[p.x, p.y, p.z], r2)
    }

    /// Indices of all points within `r` of `p`, ascending.
    pub fn within(&self, p: &P3, r: f64, out: &mut Vec<usize>) {
        self.within_n(&[p.x, p.y, p.z], r, out)
    }

    /// [`Self::nearest`] of a moving query (see [`KdTreeN::nearest_warm_n`]).
    pub fn nearest_warm(&self, p: &P3, warm: &mut Warm) -> Option<(usize, f64)> {
        self.nearest_warm_n(&[p.x, p.y, p.z], warm)
    }
}

impl<const D: usize> KdTreeN<D> {
    pub fn from_coords(pts: Vec<[f64; D]>) -> KdTreeN<D> {
        let mut t = KdTreeN {
            idx: (0..pts.len() as u32).collect(),
            pos: Vec::new(),
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
            t.pos = vec![0; t.idx.len()];
            for (k, &i) in t.idx.iter().enumerate() {
                t.pos[i as usize] = k as u32;
            }
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

    /// Index and squared distance of the nearest point (`None` for an empty tree). Of points
    /// at the same distance, the lowest index: the answer of a brute-force scan.
    pub fn nearest_n(&self, q: &[f64; D]) -> Option<(usize, f64)> {
        self.search(q, f64::INFINITY, usize::MAX)
    }

    /// [`Self::nearest_n`] started from point `hint` (any index; out of range: no hint): the
    /// same answer, found sooner when `hint` is near it, as the previous ICP iteration's
    /// partner of the same guidance point is.
    pub fn nearest_from_n(&self, q: &[f64; D], hint: usize) -> Option<(usize, f64)> {
        self.search(q, f64::INFINITY, hint)
    }

    /// [`Self::nearest_n`] of a query that moves a little between calls (the same guidance point
    /// at each ICP iteration): the same answer, bit for bit. When `warm`'s certificate covers
    /// `q` the answer is its hint and no tree node is read; otherwise a search started from the
    /// hint that also leaves a new certificate in `warm`.
    pub fn nearest_warm_n(&self, q: &[f64; D], warm: &mut Warm) -> Option<(usize, f64)> {
        const { assert!(D <= 6) };
        if let Some(&k) = self.pos.get(warm.hint) {
            if warm.clear > 0.0 {
                let a2 = d2(&self.pts[k as usize], q);
                let mut moved = 0.0;
                for (c, x) in warm.at.iter().zip(q) {
                    moved += (c - x).powi(2);
                }
                if a2.sqrt() + moved.sqrt() < warm.clear {
                    return Some((warm.hint, a2));
                }
            }
        }
        let mut others = f64::INFINITY;
        let found = self.search_with::<true>(q, f64::INFINITY, warm.hint, &mut others);
        warm.hint = found.map_or(usize::MAX, |f| f.0);
        warm.at[..D].copy_from_slice(q);
        // Squared distances are rounded a few ulps (1e-15 relative; every term is a square, so
        // nothing cancels): 1e-9 covers them. Below 1e-200 squares may underflow: no
        // certificate.
        warm.clear = if others > 1e-200 && others.is_finite() {
            others.sqrt() * (1.0 - 1e-9)
        } else {
            -1.0
        };
        found
    }

    /// [`Self::nearest_n`] when its squared distance is at most `r2`, else `None`. A bounded
    /// search prunes from the start: scoring a pose only asks whether a point is within τ.
    pub fn nearest_within_n(&self, q: &[f64; D], r2: f64) -> Option<(usize, f64)> {
        self.search(q, r2, usize::MAX)
    }

    /// The lexicographic minimum of (squared distance, index) over the points at squared
    /// distance `<= r2`. Exact in floating point: a box's `box_d2` never exceeds the `d2` of a
    /// point inside it (rounding is monotone), and a subtree is skipped only when its bound is
    /// strictly above the best distance, so a tie at a lower index in another leaf is found.
    /// A `hint` (an original index) seeds the best with its own (distance, index), a true
    /// candidate, so the minimum is unchanged.
    fn search(&self, q: &[f64; D], r2: f64, hint: usize) -> Option<(usize, f64)> {
        let mut others = f64::INFINITY;
        self.search_with::<false>(q, r2, hint, &mut others)
    }

    /// [`Self::search`]; with `CERT`, `others` also receives a lower bound on the squared
    /// distance of every point but the answer: the least of the other points it read and of
    /// the bounds of the subtrees it skipped (all above the best). The same nodes are visited:
    /// searching further for a stronger certificate (every subtree within 1.5² times the best)
    /// cost more than it saved (22.7 G instructions against 12.6 G on a plate + apple pair).
    #[inline(always)]
    fn search_with<const CERT: bool>(
        &self,
        q: &[f64; D],
        r2: f64,
        hint: usize,
        others: &mut f64,
    ) -> Option<(usize, f64)> {
        if self.pts.is_empty() || box_d2(&self.nodes[0], q) > r2 {
            return None;
        }
        let mut lb = f64::INFINITY;
        let q = *q;
        let mut best = (usize::MAX, r2);
        if let Some(&k) = self.pos.get(hint) {
            let d = d2(&self.pts[k as usize], &q);
            if d <= r2 {
                best = (hint, d);
            }
        }
        // A fixed stack instead of a heap allocation per query (this is the hottest loop of
        // `compose`): one pending sibling per level at most, and median splits of 2^32 points
        // are at most 32 levels deep. The nearer child is followed without a push.
        let mut stack = [(0u32, 0.0f64); 66];
        let mut top = 0;
        let mut n = 0u32;
        loop {
            let node = &self.nodes[n as usize];
            if node.left == 0 {
                let (a, b) = (node.start as usize, node.end as usize);
                for (&i, p) in self.idx[a..b].iter().zip(&self.pts[a..b]) {
                    let d = d2(p, &q);
                    if d < best.1 || (d == best.1 && (i as usize) < best.0) {
                        if CERT && best.0 != usize::MAX {
                            lb = lb.min(best.1);
                        }
                        best = (i as usize, d);
                    } else if CERT && i as usize != best.0 {
                        lb = lb.min(d);
                    }
                }
            } else {
                let l = node.left;
                let dl = box_d2(&self.nodes[l as usize], &q);
                let dr = box_d2(&self.nodes[l as usize + 1], &q);
                let (near, dn, far, df) = if dl <= dr {
                    (l, dl, l + 1, dr)
                } else {
                    (l + 1, dr, l, dl)
                };
                if df <= best.1 {
                    stack[top] = (far, df);
                    top += 1;
                } else if CERT {
                    lb = lb.min(df);
                }
                if dn <= best.1 {
                    n = near;
                    continue;
                } else if CERT {
                    lb = lb.min(dn);
                }
            }
            // The next pending subtree that may still hold a point at or below the best.
            loop {
                if top == 0 {
                    if CERT {
                        *others = lb;
                    }
                    return (best.0 != usize::MAX).then_some(best);
                }
                top -= 1;
                let (m, bd) = stack[top];
                if bd <= best.1 {
                    n = m;
                    break;
                } else if CERT {
                    lb = lb.min(bd);
                }
            }
        }
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

#[cfg(test)]
mod exact_tests {
    //! The tree against a brute-force scan, ties included: the lowest index of the points at
    //! the minimum squared distance (computed by the same `d2`), on random and degenerate sets.
    use super::*;
    use crate::rng::Rng;

    fn brute<const D: usize>(pts: &[[f64; D]], q: &[f64; D], r2: f64) -> Option<(usize, f64)> {
        let mut best: Option<(usize, f64)> = None;
        for (i, p) in pts.iter().enumerate() {
            let d = d2(p, q);
            if d <= r2 && best.is_none_or(|b| d < b.1) {
                best = Some((i, d));
            }
        }
        best
    }

    fn check<const D: usize>(pts: &[[f64; D]], queries: &[[f64; D]], r2s: &[f64]) -> usize {
        let t = KdTreeN::from_coords(pts.to_vec());
        let mut ties = 0;
        for q in queries {
            let want = brute(pts, q, f64::INFINITY);
            assert_eq!(t.nearest_n(q), want, "query {q:?}");
            // Warm starts from any point (near, far, the answer itself, out of range).
            for hint in [0, pts.len() / 2, pts.len().saturating_sub(1), usize::MAX] {
                assert_eq!(t.nearest_from_n(q, hint), want, "{q:?} from {hint}");
            }
            if let Some((i, _)) = want {
                assert_eq!(t.nearest_from_n(q, i), want);
                assert_eq!(t.nearest_from_n(q, i ^ 1), want);
            }
            if let Some((_, d)) = want {
                ties += (pts.iter().filter(|p| d2(p, q) == d).count() > 1) as usize;
            }
            for &r2 in r2s {
                assert_eq!(t.nearest_within_n(q, r2), brute(pts, q, r2), "{q:?} {r2}");
            }
        }
        ties
    }

    fn queries(rng: &mut Rng, pts: &[[f64; 3]], n: usize) -> Vec<[f64; 3]> {
        // The points themselves (exact hits, duplicates' ties), points on a grid of half steps
        // (equidistant from grid neighbours), and random points around the set.
        let mut q: Vec<[f64; 3]> = pts.iter().step_by(7).copied().collect();
        for _ in 0..n {
            q.push([
                (rng.range(-0.5, 4.5) * 2.0).round() / 2.0,
                (rng.range(-0.5, 4.5) * 2.0).round() / 2.0,
                (rng.range(-0.5, 4.5) * 2.0).round() / 2.0,
            ]);
            q.push([
                rng.range(-1.0, 5.0),
                rng.range(-1.0, 5.0),
                rng.range(-1.0, 5.0),
            ]);
        }
        q
    }

    #[test]
    fn nearest_is_the_brute_force_answer_with_ties() {
        let mut rng = Rng::new(11);
        let r2s = [0.0, 0.25, 0.5, 1.0, 2.0];
        // Random.
        let random: Vec<[f64; 3]> = (0..3000)
            .map(|_| {
                [
                    rng.range(0.0, 4.0),
                    rng.range(0.0, 4.0),
                    rng.range(0.0, 4.0),
                ]
            })
            .collect();
        let q = queries(&mut rng, &random, 300);
        check(&random, &q, &r2s);
        // An integer grid (5^3): many equidistant neighbours, splits through equal coordinates.
        let grid: Vec<[f64; 3]> = (0..125)
            .map(|i| [(i % 5) as f64, ((i / 5) % 5) as f64, (i / 25) as f64])
            .collect();
        let q = queries(&mut rng, &grid, 300);
        let grid_ties = check(&grid, &q, &r2s);
        // Every point four times (duplicates spread over leaves by the median splits), in a
        // shuffled order so the lowest index is not always the first copy.
        let mut dup: Vec<[f64; 3]> = (0..4).flat_map(|_| grid.iter().copied()).collect();
        for i in (1..dup.len()).rev() {
            dup.swap(i, (rng.next_f64() * (i + 1) as f64) as usize % (i + 1));
        }
        let q = queries(&mut rng, &dup, 300);
        let dup_ties = check(&dup, &q, &r2s);
        // A single point repeated: every query is a 40-way tie.
        let same = vec![[1.0, 2.0, 3.0]; 40];
        let q = queries(&mut rng, &same, 50);
        assert_eq!(check(&same, &q, &r2s), q.len());
        // Coplanar (z = 2): an integer grid, and random points beside it.
        let plane: Vec<[f64; 3]> = (0..900)
            .map(|i| {
                if i % 2 == 0 {
                    [((i / 2) % 15) as f64, ((i / 2) / 15) as f64, 2.0]
                } else {
                    [rng.range(15.0, 19.0), rng.range(0.0, 4.0), 2.0]
                }
            })
            .collect();
        let q = queries(&mut rng, &plane, 300);
        let plane_ties = check(&plane, &q, &r2s);
        // The sets above do exercise ties.
        eprintln!("ties: grid {grid_ties}, duplicates {dup_ties}, plane {plane_ties}");
        assert!(grid_ties > 100 && dup_ties > 300 && plane_ties > 50);
        // Collinear points, six coordinates (the colour tree's shape) with duplicates.
        let line: Vec<[f64; 6]> = (0..600)
            .map(|i| {
                let x = (i % 200) as f64 * 0.5;
                [x, 0.0, 0.0, 0.1, 0.1, 0.1]
            })
            .collect();
        let q: Vec<[f64; 6]> = (0..400)
            .map(|i| {
                let x = (i as f64 * 0.25).round() / 2.0 + if i % 3 == 0 { 0.25 } else { 0.0 };
                [x, rng.range(-1.0, 1.0), 0.0, 0.1, 0.1, rng.range(0.0, 0.2)]
            })
            .collect();
        assert!(check(&line, &q, &r2s) > 300);
    }

    /// Moving queries through [`KdTreeN::nearest_warm_n`] against a brute-force scan: walks of
    /// small, medium and large steps, so the certificate is used, refused and renewed. Returns
    /// (queries, answered by the certificate alone).
    fn walk<const D: usize>(pts: &[[f64; D]], rng: &mut Rng, start: [f64; D]) -> (usize, usize) {
        let t = KdTreeN::from_coords(pts.to_vec());
        let (mut asked, mut certified) = (0, 0);
        for step in [1e-4, 1e-3, 1e-2, 0.1, 0.5] {
            let mut q = start;
            let mut warm = Warm::default();
            for _ in 0..200 {
                for x in q.iter_mut() {
                    *x += rng.range(-step, step);
                }
                let before = warm.at;
                let got = t.nearest_warm_n(&q, &mut warm);
                assert_eq!(got, brute(pts, &q, f64::INFINITY), "{q:?} step {step}");
                assert_eq!(warm.hint, got.map_or(usize::MAX, |g| g.0));
                asked += 1;
                certified += (warm.at == before && before[..D] != q[..]) as usize;
            }
        }
        (asked, certified)
    }

    #[test]
    fn warm_queries_are_the_brute_force_answer() {
        let mut rng = Rng::new(5);
        let random: Vec<[f64; 3]> = (0..2000)
            .map(|_| {
                [
                    rng.range(0.0, 4.0),
                    rng.range(0.0, 4.0),
                    rng.range(0.0, 4.0),
                ]
            })
            .collect();
        let (mut asked, mut certified) = (0, 0);
        for _ in 0..5 {
            let s = [
                rng.range(0.0, 4.0),
                rng.range(0.0, 4.0),
                rng.range(0.0, 4.0),
            ];
            let (a, c) = walk(&random, &mut rng, s);
            asked += a;
            certified += c;
        }
        // Ties: an integer grid with every point four times, walks from grid points and from
        // half steps (equidistant from neighbours); a single point repeated.
        let grid: Vec<[f64; 3]> = (0..4 * 125)
            .map(|i| {
                let i = i % 125;
                [(i % 5) as f64, ((i / 5) % 5) as f64, (i / 25) as f64]
            })
            .collect();
        for s in [[2.0, 2.0, 2.0], [1.5, 2.0, 2.5], [0.5, 0.5, 0.5]] {
            walk(&grid, &mut rng, s);
        }
        walk(&vec![[1.0, 2.0, 3.0]; 40], &mut rng, [1.0, 2.0, 3.0]);
        // Six coordinates (the colour tree's), collinear with duplicates.
        let line: Vec<[f64; 6]> = (0..600)
            .map(|i| [(i % 200) as f64 * 0.5, 0.0, 0.0, 0.1, 0.1, 0.1])
            .collect();
        // (every point three times: ties everywhere, so the certificate never holds there)
        walk(&line, &mut rng, [10.2, 0.0, 0.0, 0.1, 0.1, 0.1]);
        let cloud6: Vec<[f64; 6]> = (0..2000)
            .map(|_| std::array::from_fn(|k| rng.range(0.0, if k < 3 { 4.0 } else { 0.5 })))
            .collect();
        let (a, c) = walk(&cloud6, &mut rng, [2.0, 2.0, 2.0, 0.2, 0.2, 0.2]);
        asked += a;
        eprintln!("warm walks: {asked} queries, {certified} by the certificate alone, 6-d {c}");
        // The small steps keep their partner: many of those queries need no search.
        assert!(certified > asked / 5 && c > 0);
    }

    #[test]
    fn empty_tree_and_bound_below_the_root_box() {
        let t = KdTreeN::<3>::from_coords(Vec::new());
        assert_eq!(t.nearest_n(&[0.0; 3]), None);
        let t = KdTreeN::from_coords(vec![[1.0, 0.0, 0.0], [3.0, 0.0, 0.0]]);
        assert_eq!(t.nearest_within_n(&[-1.0, 0.0, 0.0], 3.99), None);
        assert_eq!(t.nearest_within_n(&[-1.0, 0.0, 0.0], 4.0), Some((0, 4.0)));
        assert_eq!(t.nearest_n(&[2.0, 0.0, 0.0]), Some((0, 1.0)));
    }
}
