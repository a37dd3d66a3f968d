//! Segmentation bleed: a guidance part cut from a fused reconstruction carries a strip of its
//! neighbour's surface across the contact (a ring of plate around a box's foot, the mug's floor
//! under a die). Registration fits that strip as if it were the object, so the object grows to
//! cover it (a box's bottom face "explains" the coplanar ring). Once the neighbour is placed, its
//! surface is known: guidance points on it belong to it, not to the object being registered.
//!
//! Entry point: [`without_placed`].

use super::cloud::Cloud;
use super::sdf::AnchorField;

/// `guidance` without its points within `band` of the placed objects' surface (|Φ| < band).
/// `None` when that would leave less than `min_kept` of the points (then the part is mostly
/// contact, and nothing is removed).
pub fn without_placed(
    guidance: &Cloud,
    field: &AnchorField,
    band: f64,
    min_kept: f64,
) -> Option<Cloud> {
    let keep: Vec<bool> = guidance
        .points
        .iter()
        .map(|p| field.eval(p).0.abs() >= band)
        .collect();
    let n = keep.iter().filter(|&&k| k).count();
    if n == guidance.len() || (n as f64) < min_kept * guidance.len() as f64 {
        return None;
    }
    Some(Cloud {
        points: pick(&guidance.points, &keep),
        normals: pick(&guidance.normals, &keep),
        colours: pick(&guidance.colours, &keep),
    })
}

fn pick<T: Copy>(v: &[T], keep: &[bool]) -> Vec<T> {
    v.iter()
        .zip(keep)
        .filter(|(_, &k)| k)
        .map(|(x, _)| *x)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{P3, V3};

    /// A unit cube placed at the origin; a part made of a box 0.2 on a side resting on its top
    /// face (y = 0.5) plus a 0.4-wide ring of the cube's top around it (the bleed). Exactly
    /// the ring and the box's points within the band of the top face go.
    #[test]
    fn strips_the_placed_surface_only() {
        let field = AnchorField::new(&[crate::shapes::cuboid(V3::new(1.0, 1.0, 1.0))], 32);
        let mut g = Cloud::default();
        let mut expect_kept = 0;
        for i in 0..20 {
            for j in 0..20 {
                // The ring on the cube's top, 1e-3 above it (noise).
                let (x, z) = (-0.2 + 0.02 * i as f64, -0.2 + 0.02 * j as f64);
                g.points.push(P3::new(x, 0.501, z));
                // The box's side face x = 0.1, from y = 0.5 up to 0.7.
                let y = 0.5 + 0.01 * i as f64;
                g.points.push(P3::new(0.1, y, -0.1 + 0.01 * j as f64));
                // Band 0.015: side points at y − 0.5 ≥ 0.02 stay.
                if i >= 2 {
                    expect_kept += 1;
                }
            }
        }
        let n = g.points.len();
        g.normals = vec![V3::y(); n];
        g.colours = vec![[0.5; 3]; n];
        let s = without_placed(&g, &field, 0.015, 0.2).expect("some points stripped");
        assert_eq!(s.len(), expect_kept);
        assert!(s.points.iter().all(|p| p.y >= 0.52 - 1e-12 && p.x == 0.1));
        assert_eq!(s.normals.len(), s.len());
        assert_eq!(s.colours.len(), s.len());
        // Keeping at least 60 % is not possible here (less than half stays): nothing removed.
        assert!(without_placed(&g, &field, 0.015, 0.6).is_none());
    }
}
