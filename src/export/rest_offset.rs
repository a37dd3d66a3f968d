//! The depth a loaded stack rests at, stated to PhysX: `physxCollision:restOffset` per hull.
//!
//! Entry point: [`rest_offsets`] (one offset per hull of every body, metres, 0 outside a
//! loaded stack), called by [`super::usd::write_usd`]; [`hull_depths`] measures the contacts.
//!
//! Our settle's contacts are soft: a body carrying a load ≥ 10× its own mass (the settle's
//! "heavily loaded" list) rests (1 + k) times deeper in its support than an unloaded one, 0.1–
//! 0.9 mm on the loaded stacks of the agreement scenes. PhysX's contacts are rigid: from the
//! exported pose its position iterations push that depth out in the first steps, and the load
//! jumps up to a millimetre (seed 412, docs/agreement.md "Thirteenth stop"). PhysX rests two
//! shapes at the sum of their rest offsets (a negative sum: that far into each other), so the
//! export measures every contact of a loaded stack at the exported pose (exact convex
//! penetration of each pair of hulls, parry; the floor: a hull's lowest vertex) and gives each
//! hull of the stack the offset that makes every touching pair's sum its measured depth:
//! `r_h + r_g = -d_hg`, the floor and the hulls of bodies outside the stack held at 0, solved
//! in the least-squares sense (pairs that form a loop cannot all be met exactly), a hull that
//! touches nothing at 0, and no hull above 0 (no air gap our settle never had; allowed, the
//! least squares gave a few hulls up to +0.21 mm, and PhysX agreed on one held-out verdict
//! and one rest fewer). Per hull, not per body: one body's contacts rest at different depths
//! (a shoe tilted on a pair of scissors: 0.9 mm under the heel, less elsewhere), and one
//! offset for the whole body let its shallower contacts sink and the shoe rock (seed 590,
//! 0.79° → 1.24°). Bodies outside a loaded stack keep 0, PhysX's own default, so an unloaded
//! scene's files are unchanged.

use crate::body::Assembly;
use crate::decompose::scene_aware::geom::polyhedron;
use crate::pose::parry_pose;
use nalgebra::{DMatrix, DVector};
use parry3d_f64::math::Pose;
use parry3d_f64::query;
use parry3d_f64::shape::ConvexPolyhedron;

/// Offsets are written to the micrometre (PhysX's own tolerance is coarser).
const RESOLUTION: f64 = 1e-6;

/// Penetration depths (m, > 0) of the hulls at the bodies' current poses: `(h, g, depth)`
/// with hulls numbered body by body (body 0's first, then body 1's…) and `g = None` for the
/// floor (z = 0), for every overlapping pair of hulls of two bodies and every hull below the
/// floor. Pairs of two fixed bodies are left out.
pub fn hull_depths(a: &Assembly) -> Vec<(usize, Option<usize>, f64)> {
    let first = first_hulls(a);
    let shapes: Vec<(Pose, Vec<Option<ConvexPolyhedron>>)> = a
        .bodies
        .iter()
        .map(|b| {
            (
                parry_pose(&b.pose),
                b.hulls.iter().map(polyhedron).collect(),
            )
        })
        .collect();
    let mut out = Vec::new();
    for (i, b) in a.bodies.iter().enumerate() {
        for (k, h) in b.hulls.iter().enumerate() {
            let lowest = h
                .vertices
                .iter()
                .map(|p| (b.pose * p).z)
                .fold(f64::INFINITY, f64::min);
            if !b.fixed && lowest < 0.0 {
                out.push((first[i] + k, None, -lowest));
            }
        }
        for j in i + 1..a.bodies.len() {
            if b.fixed && a.bodies[j].fixed {
                continue;
            }
            let (pi, si) = &shapes[i];
            let (pj, sj) = &shapes[j];
            for (k, x) in si.iter().enumerate() {
                for (l, y) in sj.iter().enumerate() {
                    let (Some(x), Some(y)) = (x, y) else { continue };
                    if let Ok(Some(c)) = query::contact(pi, x, pj, y, 0.0) {
                        if c.dist < 0.0 {
                            out.push((first[i] + k, Some(first[j] + l), -c.dist));
                        }
                    }
                }
            }
        }
    }
    out
}

/// The number of the first hull of each body, and the total at the end.
fn first_hulls(a: &Assembly) -> Vec<usize> {
    let mut first = vec![0];
    for b in &a.bodies {
        first.push(first.last().unwrap() + b.hulls.len());
    }
    first
}

/// `physxCollision:restOffset` of every hull of every body (m, body by body): 0 outside a
/// loaded stack (a body in `loaded` and every body it touches), and within one the offsets
/// whose pair sums are the stack's contact depths at the exported pose (module doc).
pub fn rest_offsets(a: &Assembly, loaded: &[String]) -> Vec<Vec<f64>> {
    let first = first_hulls(a);
    let per_body = |flat: &[f64]| -> Vec<Vec<f64>> {
        (0..a.bodies.len())
            .map(|i| flat[first[i]..first[i + 1]].to_vec())
            .collect()
    };
    let hulls = *first.last().unwrap();
    let is_loaded: Vec<bool> = a
        .bodies
        .iter()
        .map(|b| !b.fixed && loaded.contains(&b.name))
        .collect();
    if !is_loaded.iter().any(|&l| l) {
        return per_body(&vec![0.0; hulls]);
    }
    let depths = hull_depths(a);
    let body = |h: usize| first.partition_point(|&f| f <= h) - 1;
    // The stack: the loaded bodies and the free bodies touching one.
    let mut in_stack = is_loaded.clone();
    for &(h, g, _) in &depths {
        if let Some(g) = g {
            let (i, j) = (body(h), body(g));
            if is_loaded[i] && !a.bodies[j].fixed {
                in_stack[j] = true;
            }
            if is_loaded[j] && !a.bodies[i].fixed {
                in_stack[i] = true;
            }
        }
    }
    let hull_in_stack: Vec<bool> = (0..hulls).map(|h| in_stack[body(h)]).collect();
    per_body(&solve(&hull_in_stack, &depths))
}

/// The offsets (≤ 0) of the shapes marked `in_stack` (others 0) whose sums over the contacts
/// `depths` (`(i, j, d)`, `j = None` the floor) are `-d`, in the least-squares sense with the
/// smallest offsets where the contacts leave some free; rounded to [`RESOLUTION`]. A shape
/// the least squares would give a positive offset (an air gap our settle never had, where a
/// deeper neighbour pulls its partner's offset down) is held at 0 and the rest solved again.
fn solve(in_stack: &[bool], depths: &[(usize, Option<usize>, f64)]) -> Vec<f64> {
    let mut free = in_stack.to_vec();
    loop {
        let x = least_squares(&free, depths);
        let mut again = false;
        for (i, &r) in x.iter().enumerate() {
            if free[i] && r > 0.0 {
                free[i] = false;
                again = true;
            }
        }
        if !again {
            return x;
        }
    }
}

/// [`solve`] without the sign: the least-squares offsets of the shapes marked `in_stack`.
fn least_squares(in_stack: &[bool], depths: &[(usize, Option<usize>, f64)]) -> Vec<f64> {
    let mut offsets = vec![0.0; in_stack.len()];
    let unknowns: Vec<usize> = (0..in_stack.len()).filter(|&i| in_stack[i]).collect();
    let column = |i: usize| unknowns.iter().position(|&u| u == i);
    // One row per contact touching the stack: r_i + r_j = -d (the floor and bodies outside
    // the stack contribute 0).
    let rows: Vec<(Option<usize>, Option<usize>, f64)> = depths
        .iter()
        .map(|&(i, j, d)| (column(i), j.and_then(column), d))
        .filter(|(ci, cj, _)| ci.is_some() || cj.is_some())
        .collect();
    // A loaded body that touches nothing at this pose (an unsettled export): nothing to state.
    if rows.is_empty() {
        return offsets;
    }
    let mut m = DMatrix::<f64>::zeros(rows.len(), unknowns.len());
    let mut rhs = DVector::<f64>::zeros(rows.len());
    for (r, &(ci, cj, d)) in rows.iter().enumerate() {
        for c in [ci, cj].into_iter().flatten() {
            m[(r, c)] += 1.0;
        }
        rhs[r] = -d;
    }
    // SVD's pseudo-inverse.
    let Ok(x) = m.svd(true, true).solve(&rhs, 1e-12) else {
        return offsets;
    };
    for (k, &i) in unknowns.iter().enumerate() {
        let r = (x[k] / RESOLUTION).round() * RESOLUTION;
        // -0 prints as "-0": keep 0 as PhysX's default text.
        offsets[i] = if r == 0.0 { 0.0 } else { r };
    }
    offsets
}

#[cfg(test)]
mod tests {
    use super::solve;

    fn near(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn a_chain_on_the_floor_meets_every_depth() {
        // Floor – 0 (0.2 mm) – 1 (0.5 mm) – 2 (0.4 mm); body 3 outside the stack.
        let d = [(0, None, 2e-4), (0, Some(1), 5e-4), (1, Some(2), 4e-4)];
        let r = solve(&[true, true, true, false], &d);
        // r0 = -0.2, r1 = -0.5 + 0.2, r2 = -0.4 + 0.3 (mm).
        assert!(
            near(r[0], -2e-4) && near(r[1], -3e-4) && near(r[2], -1e-4),
            "{r:?}"
        );
        assert_eq!(r[3], 0.0);
    }

    #[test]
    fn a_body_outside_the_stack_holds_its_zero() {
        // 0 on the floor (0.2 mm) and on 1 (0.3 mm), 1 not in the stack: rows r0 = -0.2 and
        // r0 = -0.3, least squares r0 = -0.25.
        let d = [(0, None, 2e-4), (0, Some(1), 3e-4)];
        let r = solve(&[true, false], &d);
        assert!(near(r[0], -2.5e-4) && r[1] == 0.0, "{r:?}");
    }

    #[test]
    fn a_loop_is_met_in_the_least_squares_sense() {
        // 0 and 1 both on the floor (0.1 mm each) and on each other (0.4 mm): r0 = r1 = r,
        // rows r = -0.1 (twice) and 2r = -0.4: normal equation 6r = -0.2 - 0.8 → r = -1/6 mm.
        let d = [(0, None, 1e-4), (1, None, 1e-4), (0, Some(1), 4e-4)];
        let r = solve(&[true, true], &d);
        assert!(near(r[0], -1.67e-4) && r[0] == r[1], "{r:?}");
    }

    #[test]
    fn no_shape_gets_an_air_gap() {
        // 0 on the floor (0.4 mm) and on 1 (0.1 mm), 1 also on the floor (0.1 mm): least
        // squares gives r0 = -0.267, r1 = +0.033 mm, an air gap under 1; held at 0, 0 takes
        // r0 = -(0.4 + 0.1) / 2 = -0.25.
        let d = [(0, None, 4e-4), (0, Some(1), 1e-4), (1, None, 1e-4)];
        let r = solve(&[true, true], &d);
        assert!(near(r[0], -2.5e-4) && r[1] == 0.0, "{r:?}");
    }

    #[test]
    fn nothing_touching_states_nothing() {
        assert_eq!(solve(&[true, false], &[]), vec![0.0, 0.0]);
        // A stack body touching nothing takes 0, the smallest offset.
        let r = solve(&[true, true], &[(0, None, 1e-4)]);
        assert!(near(r[0], -1e-4) && r[1] == 0.0, "{r:?}");
    }
}
