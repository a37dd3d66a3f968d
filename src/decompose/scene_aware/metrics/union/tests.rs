//! [`UnionFaces`] against what it replaces, on a real object: the GSO TROCHILUS_BOOST shoe
//! (`shared/`, skipped without it) under its own 32 collision hulls. Its distances are
//! `Surface::distance` on the rebuilt union boundary ([`super::super::union_boundary`]), to the
//! bit, and a boundary moved by a split and a merge (three hulls out, three in, as `unfill`'s
//! moves) is the one built anew, triangle for triangle to the bit.

use super::*;
use crate::decompose::scene_aware::geom::{clip, Surface};
use crate::decompose::scene_aware::metrics::{seen_samples, union_boundary};
use crate::mesh::V3;
use std::path::{Path, PathBuf};

/// `shared/datasets/objects/gso/TROCHILUS_BOOST` beside the repository or its parent.
fn shoe_dir() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    [root.join("../shared"), root.join("../../shared")]
        .into_iter()
        .map(|p| p.join("datasets/objects/gso/TROCHILUS_BOOST"))
        .find(|p| p.join("model.obj").is_file())
}

fn load(p: &Path) -> Mesh {
    crate::io::load_visual(p, &crate::io::Limits::default())
        .unwrap()
        .geometry()
}

fn bits(m: &Mesh) -> (Vec<[u64; 3]>, Vec<[u32; 3]>) {
    let v = m
        .vertices
        .iter()
        .map(|p| [p.x, p.y, p.z].map(f64::to_bits))
        .collect();
    (v, m.triangles.clone())
}

/// Every sample's distance to `u` is that to the surface of its mesh, to the bit.
fn same_distances(u: &UnionFaces, pts: &[P3]) {
    let b = Surface::new(&u.mesh()).expect("a boundary");
    for p in pts {
        assert_eq!(u.distance(p).to_bits(), b.distance(p).to_bits(), "{p:?}");
    }
}

#[test]
fn union_faces_recut_in_part_are_the_boundary_built_anew() {
    let Some(dir) = shoe_dir() else {
        eprintln!("shared datasets not present: skipped");
        return;
    };
    let s = Surface::new(&load(&dir.join("model.obj"))).expect("the shoe");
    let hulls: Vec<Hull> = (0..32)
        .map(|k| {
            let m = load(&dir.join(format!("model_collision_{k}.obj")));
            Hull::from_points(&m.vertices).expect("a hull")
        })
        .collect();
    let pts = seen_samples(&s, 3000);
    let full = UnionFaces::new(&hulls, s.diag);
    assert_eq!(
        bits(&full.mesh()),
        bits(&union_boundary(&hulls, s.diag).unwrap().mesh),
        "the mesh union_boundary's surface is made of"
    );
    same_distances(&full, &pts);
    // Moves as unfill's: hull w split in two by a plane through its box centre, hulls i and j
    // merged into the hull of both; the rest kept in order, the three new ones last.
    let (mut reused, mut recut) = (0, 0);
    for (r, (w, i, j)) in [(3, 9, 10), (0, 17, 30), (12, 5, 21), (25, 26, 27)]
        .into_iter()
        .enumerate()
    {
        let h = &hulls[w];
        let axis = [V3::x(), V3::y(), V3::z()][r % 3];
        let c = axis.dot(&h.aabb.center().coords);
        let lo = clip(h, &axis, c).expect("a half");
        let hi = clip(h, &(-axis), -c).expect("a half");
        let both: Vec<P3> = hulls[i]
            .vertices
            .iter()
            .chain(&hulls[j].vertices)
            .copied()
            .collect();
        let m = Hull::from_points(&both).expect("a merge");
        let gone = [w, i, j];
        let mut next: Vec<Hull> = Vec::new();
        let mut from = Vec::new();
        for (k, g) in hulls.iter().enumerate() {
            if !gone.contains(&k) {
                next.push(g.clone());
                from.push(Some(k));
            }
        }
        let changed: Vec<Aabb> = [&hulls[w], &hulls[i], &hulls[j], &lo, &hi, &m]
            .map(|g| g.aabb)
            .to_vec();
        next.extend([lo, hi, m]);
        from.extend([None; 3]);
        let moved = full.moved(&next, &from);
        let anew = UnionFaces::new(&next, s.diag);
        assert_eq!(bits(&moved.mesh()), bits(&anew.mesh()), "move {r}");
        same_distances(&moved, &pts);
        // Both paths of `moved` ran: hulls kept whole and hulls recut face by face.
        for g in &next[..next.len() - 3] {
            if changed.iter().any(|c| c.intersects(&g.aabb, 1e-6 * s.diag)) {
                recut += 1;
            } else {
                reused += 1;
            }
        }
        // A move of a move: back to the original hulls from `moved`.
        let back_from: Vec<Option<usize>> = (0..hulls.len())
            .map(|k| (!gone.contains(&k)).then(|| k - gone.iter().filter(|&&g| g < k).count()))
            .collect();
        let back = moved.moved(&hulls, &back_from);
        assert_eq!(bits(&back.mesh()), bits(&full.mesh()), "move {r} undone");
    }
    assert!(
        reused > 0 && recut > 0,
        "{reused} kept whole, {recut} recut"
    );
}
