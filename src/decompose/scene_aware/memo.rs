//! The parts' memo: a candidate part is a pure function of its triangles and cuts, so it is
//! built once per object ([`Memo`]) and shared by the rounds of both strategies that ask for it.
//!
//! Entry points: [`Memo`], [`Built`].

use super::*;

/// A part's triangles and cuts (normal and offset as bits), what [`build_part`] builds from.
pub(super) type PartKey = (Vec<u32>, Vec<[u64; 4]>);

/// Parts already built with one `Params`, by [`PartKey`]: the rebalancing and the polishing
/// try the same merges and splits again from round to round (on the GSO mug 5,245 of 17,549
/// builds repeated an earlier one). `build_part` is a pure function of its key, so a part
/// taken from here is the one it would build; the parallel callers may both build a missing
/// one, and insert the same. Likewise the 2-means halves of a patch that [`split_ways`] tries
/// first, by the patch's triangles: the rebalancing tries a border move between the same two
/// patches again after moves elsewhere (on the GSO TROCHILUS shoe a fifth of the triangles
/// split were split before). Emptied once the patches are final.
#[derive(Clone, Debug, Default)]
pub(super) struct Memo {
    pub(super) parts: Shared<PartKey, Built>,
    pub(super) halves: Shared<Vec<u32>, Vec<Vec<u32>>>,
}

/// A map the parallel builds of one `Params` share.
pub(super) type Shared<K, V> = std::sync::Arc<Mutex<std::collections::HashMap<K, V, KeyHash>>>;

/// The memo's hasher: a multiply-rotate hash of 8 bytes at a time (as rustc's `FxHasher`).
/// A key holds a patch's triangle list, hundreds of indices: SipHash, made to resist chosen
/// keys, took 1.4 % of the GSO mug's instructions hashing them. The memo is only looked up,
/// never iterated, so its order does not reach the results.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct KeyHash;

impl std::hash::BuildHasher for KeyHash {
    type Hasher = KeyHasher;
    fn build_hasher(&self) -> KeyHasher {
        KeyHasher(0)
    }
}

pub(super) struct KeyHasher(pub(super) u64);

impl std::hash::Hasher for KeyHasher {
    fn write(&mut self, bytes: &[u8]) {
        let mut words = bytes.chunks_exact(8);
        for w in &mut words {
            self.add(u64::from_le_bytes(w.try_into().expect("8 bytes")));
        }
        let rest = words.remainder();
        if !rest.is_empty() {
            let mut last = [0u8; 8];
            last[..rest.len()].copy_from_slice(rest);
            self.add(u64::from_le_bytes(last));
        }
    }

    fn write_usize(&mut self, n: usize) {
        self.add(n as u64);
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

impl KeyHasher {
    pub(super) fn add(&mut self, w: u64) {
        self.0 = (self.0.rotate_left(5) ^ w).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

/// What [`build_new_part`] found for a key. Unboxed though the variants differ in size: one
/// per key in the memo, and a box would cost an allocation per build.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub(super) enum Built {
    /// The part (`None`: no hull).
    Done(Option<Part>),
    /// Its hull deviates this much or more: it was not measured further.
    Above(f64),
}

impl Memo {
    pub(super) fn key(tris: &[u32], cuts: &[(V3, f64)]) -> PartKey {
        let cuts = cuts
            .iter()
            .map(|(n, c)| [n.x.to_bits(), n.y.to_bits(), n.z.to_bits(), c.to_bits()])
            .collect();
        (tris.to_vec(), cuts)
    }

    pub(super) fn get(&self, k: &PartKey) -> Option<Built> {
        self.parts.lock().ok()?.get(k).cloned()
    }

    /// Keep `v` unless what is kept already says more: a built part, or a higher bound.
    pub(super) fn put(&self, k: PartKey, v: Built) {
        if let Ok(mut m) = self.parts.lock() {
            let more = match (m.get(&k), &v) {
                (Some(Built::Done(_)), _) => false,
                (Some(Built::Above(old)), Built::Above(new)) => new > old,
                _ => true,
            };
            if more {
                m.insert(k, v);
            }
        }
    }

    /// The 2-means halves of the patch `tris`, by `kmeans` (a pure function of them) when not
    /// kept yet.
    pub(super) fn halves(
        &self,
        tris: &[u32],
        kmeans: impl FnOnce() -> Vec<Vec<u32>>,
    ) -> Vec<Vec<u32>> {
        if let Some(h) = self.halves.lock().ok().and_then(|m| m.get(tris).cloned()) {
            return h;
        }
        let h = kmeans();
        if let Ok(mut m) = self.halves.lock() {
            m.insert(tris.to_vec(), h.clone());
        }
        h
    }

    pub(super) fn clear(&self) {
        if let Ok(mut m) = self.parts.lock() {
            m.clear();
        }
        if let Ok(mut m) = self.halves.lock() {
            m.clear();
        }
    }
}
