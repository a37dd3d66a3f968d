//! Sets of mesh vertex indices as bitmaps over their range: a patch's vertices (each several
//! times among its triangles) gathered without a list of them, read back ascending, and each
//! one's position in that ascending list found by counting bits (no binary search).
//!
//! Entry points: [`VertexSet`], [`distinct_sorted`].

/// Indices in `lo..=hi`, one bit each, with the count of members before each word once
/// [`VertexSet::ranked`] has run.
pub(super) struct VertexSet {
    lo: u32,
    bits: Vec<u64>,
    before: Vec<u32>,
}

impl VertexSet {
    /// The empty set over `lo..=hi` (`lo ≤ hi`).
    pub(super) fn new(lo: u32, hi: u32) -> VertexSet {
        VertexSet {
            lo,
            bits: vec![0u64; ((hi - lo) as usize >> 6) + 1],
            before: Vec::new(),
        }
    }

    /// Adds `x` (within the range).
    #[inline]
    pub(super) fn insert(&mut self, x: u32) {
        let i = (x - self.lo) as usize;
        self.bits[i >> 6] |= 1 << (i & 63);
    }

    /// Adds every member of `other` (over the same range).
    pub(super) fn union_with(&mut self, other: &VertexSet) {
        debug_assert!(self.lo == other.lo && self.bits.len() == other.bits.len());
        for (a, b) in self.bits.iter_mut().zip(&other.bits) {
            *a |= b;
        }
    }

    /// The members, ascending.
    pub(super) fn to_vec(&self) -> Vec<u32> {
        // Sized once: pushing into an empty vector reallocated it about log2(n) times.
        let mut out = Vec::with_capacity(self.bits.iter().map(|b| b.count_ones() as usize).sum());
        for (w, &b) in self.bits.iter().enumerate() {
            let mut b = b;
            while b != 0 {
                out.push(self.lo + 64 * w as u32 + b.trailing_zeros());
                b &= b - 1;
            }
        }
        out
    }

    /// Counts the members before each word, for [`VertexSet::rank`].
    pub(super) fn ranked(mut self) -> VertexSet {
        let mut n = 0u32;
        self.before = self
            .bits
            .iter()
            .map(|b| {
                let at = n;
                n += b.count_ones();
                at
            })
            .collect();
        self
    }

    /// The position of member `x` in [`VertexSet::to_vec`] (what `binary_search` finds there):
    /// the members below it. Needs [`VertexSet::ranked`].
    #[inline]
    pub(super) fn rank(&self, x: u32) -> usize {
        let i = (x - self.lo) as usize;
        let below = self.bits[i >> 6] & ((1u64 << (i & 63)) - 1);
        (self.before[i >> 6] + below.count_ones()) as usize
    }
}

/// The values of `v`, each once, ascending, by a bitmap over their range: the vertex indices
/// of a patch's triangles (each several times). Sorting them instead was most of the 10 % of
/// the sneaker's decomposition spent in sorts.
pub fn distinct_sorted(v: &[u32]) -> Vec<u32> {
    let (Some(&lo), Some(&hi)) = (v.iter().min(), v.iter().max()) else {
        return Vec::new();
    };
    let mut set = VertexSet::new(lo, hi);
    for &x in v {
        set.insert(x);
    }
    set.to_vec()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every member's rank is its position in the ascending list (what a binary search in
    /// the list finds), and the union is the sorted, deduplicated concatenation: random sets
    /// over small and wide ranges, members on word boundaries (63, 64, 127, 128).
    #[test]
    fn rank_is_the_position_in_the_sorted_list() {
        let mut rng = crate::rng::Rng::new(9);
        for (n, lo, range) in [(1, 0, 1), (40, 7, 10), (500, 1000, 70_000), (300, 0, 130)] {
            let draw = |rng: &mut crate::rng::Rng| -> Vec<u32> {
                let mut v: Vec<u32> = (0..n).map(|_| lo + rng.below(range) as u32).collect();
                v.extend([lo, lo + range as u32 - 1]);
                v.extend([63u32, 64, 127, 128].map(|x| lo + x % range as u32));
                v
            };
            let (a, b) = (draw(&mut rng), draw(&mut rng));
            let hi = lo + range as u32 - 1;
            let (mut sa, mut sb) = (VertexSet::new(lo, hi), VertexSet::new(lo, hi));
            a.iter().for_each(|&x| sa.insert(x));
            b.iter().for_each(|&x| sb.insert(x));
            sa.union_with(&sb);
            let mut want: Vec<u32> = a.iter().chain(&b).copied().collect();
            want.sort_unstable();
            want.dedup();
            let set = sa.ranked();
            assert_eq!(set.to_vec(), want);
            for &x in a.iter().chain(&b) {
                assert_eq!(Ok(set.rank(x)), want.binary_search(&x), "{x}");
            }
        }
    }
}
