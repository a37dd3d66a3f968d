//! Extra solver iterations where a light body carries a much heavier one.
//!
//! Projected Gauss-Seidel converges slowly across a contact whose two bodies have very different
//! masses: with Rapier's 4 substeps × 1 sweep the normal impulses under a 16 g dice loaded by a
//! shoe have not converged when friction is clamped to them, and the dice is squeezed out where
//! MuJoCo and PhysX hold it (issue #33, "Fourth pass"). More substeps and sweeps everywhere fix
//! that but change every other scene's dynamics too. So only the bodies that *carry* a body at
//! least [`SettleOptions::load_ratio`] times their own mass are marked, from the contacts at the
//! world's start; Rapier then runs [`SettleOptions::loaded_solver_iterations`] substeps ×
//! [`SettleOptions::loaded_pgs_iterations`] sweeps for the whole contact island they belong to
//! (`additional_solver_iterations` / `additional_pgs_iterations` are per island). A scene with no
//! such pair runs exactly as before, bit for bit.
//!
//! Entry points: [`heavily_loaded`] (which bodies), [`Sim::load_extra_iterations`] (apply).

use super::world::Sim;
use super::*;

/// `loaded[j]`: dynamic body `j` supports (`supports[i]` contains `j`) a dynamic body `i` with
/// `mass_i >= ratio * mass_j`. `supports` is the contact graph's supports (index
/// `bodies.len()` is the floor, never marked). A ratio that is not finite and > 1 marks nothing.
pub(super) fn heavily_loaded(bodies: &[SimBody], supports: &[Vec<usize>], ratio: f64) -> Vec<bool> {
    let n = bodies.len();
    let mut loaded = vec![false; n];
    if !(ratio.is_finite() && ratio > 1.0) {
        return loaded;
    }
    for (i, below) in supports.iter().enumerate() {
        if bodies[i].fixed {
            continue;
        }
        for &j in below {
            if j < n && !bodies[j].fixed && bodies[i].mass >= ratio * bodies[j].mass {
                loaded[j] = true;
            }
        }
    }
    loaded
}

impl Sim<'_> {
    /// Give each marked body (and so its contact island) the loaded substeps and sweeps.
    pub(super) fn load_extra_iterations(&mut self, loaded: &[bool]) {
        let extra_sub = self
            .opts
            .loaded_solver_iterations
            .saturating_sub(self.opts.solver_iterations);
        let extra_pgs = self
            .opts
            .loaded_pgs_iterations
            .saturating_sub(self.opts.pgs_iterations);
        for (i, _) in loaded.iter().enumerate().filter(|(_, &l)| l) {
            let rb = &mut self.world.bodies[self.handles[i]];
            rb.set_additional_solver_iterations(extra_sub);
            rb.set_additional_pgs_iterations(extra_pgs);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::V3;
    use crate::shapes::cuboid;

    /// A box of extents `e` and `mass` standing with its bottom face at height `bottom`.
    fn block(name: &str, e: [f64; 3], mass: f64, x: f64, bottom: f64, fixed: bool) -> SimBody {
        let e = V3::new(e[0], e[1], e[2]);
        SimBody {
            name: name.into(),
            pose: Isometry3::translation(x, 0.0, bottom + e.z / 2.0),
            hulls: vec![cuboid(e)],
            mass,
            com: P3::origin(),
            inertia: Matrix3::from_diagonal(&Vector3::new(
                mass / 12.0 * (e.y * e.y + e.z * e.z),
                mass / 12.0 * (e.x * e.x + e.z * e.z),
                mass / 12.0 * (e.x * e.x + e.y * e.y),
            )),
            friction: 0.6,
            fixed,
        }
    }

    /// Five two-block stacks on the floor, 0.5 m apart, each upper block 0.1 mm above the
    /// lower one's top face (within the 2 mm support distance; an exact touch leaves the
    /// contact normal to rounding). By hand (ratio 10, "upper mass ≥ 10 × lower mass", lower
    /// dynamic): light on heavy (0.05 on 1 kg) no; 0.5 kg on a 20 g dice (25×) yes, the dice;
    /// 0.9 kg on 0.1 kg (9×) no; exactly 10× (0.625 on 0.0625 kg, both exact in binary) yes;
    /// 1 kg on a fixed table no.
    fn stacks() -> Vec<SimBody> {
        let gap = 1e-4;
        vec![
            block("anvil", [0.1, 0.1, 0.1], 1.0, 0.0, 0.0, false),
            block("feather", [0.04, 0.04, 0.04], 0.05, 0.0, 0.1 + gap, false),
            block("dice", [0.03, 0.03, 0.03], 0.02, 0.5, 0.0, false),
            block("brick", [0.1, 0.1, 0.05], 0.5, 0.5, 0.03 + gap, false),
            block("pad", [0.06, 0.06, 0.06], 0.1, 1.0, 0.0, false),
            block("weight", [0.1, 0.1, 0.05], 0.9, 1.0, 0.06 + gap, false),
            block("pad10", [0.06, 0.06, 0.06], 0.0625, 1.5, 0.0, false),
            block("weight10", [0.1, 0.1, 0.05], 0.625, 1.5, 0.06 + gap, false),
            block("table", [0.1, 0.1, 0.1], 0.01, 2.0, 0.0, true),
            block("block", [0.1, 0.1, 0.05], 1.0, 2.0, 0.1 + gap, false),
        ]
    }

    #[test]
    fn marks_the_light_body_under_a_ten_times_heavier_one() {
        let bodies = stacks();
        let opts = SettleOptions::default();
        let sim = Sim::new(&bodies, &opts).unwrap();
        let g = sim.contact_graph(opts.support_distance);
        // Every upper block rests on its lower one (and nothing else): the graph the rule reads.
        for (upper, lower) in [(1, 0), (3, 2), (5, 4), (7, 6), (9, 8)] {
            assert_eq!(g.supports[upper], [lower], "{}", bodies[upper].name);
        }
        let names = |loaded: Vec<bool>| -> Vec<&str> {
            (0..bodies.len())
                .filter(|&i| loaded[i])
                .map(|i| bodies[i].name.as_str())
                .collect()
        };
        assert_eq!(
            names(heavily_loaded(&bodies, &g.supports, 10.0)),
            ["dice", "pad10"]
        );
        // A lower ratio takes in the 9× pair (but never the fixed table, nor the floor).
        assert_eq!(
            names(heavily_loaded(&bodies, &g.supports, 8.0)),
            ["dice", "pad", "pad10"]
        );
        assert!(names(heavily_loaded(&bodies, &g.supports, 0.0)).is_empty());
        assert!(names(heavily_loaded(&bodies, &g.supports, f64::INFINITY)).is_empty());
    }

    #[test]
    fn scenes_without_a_heavy_load_run_exactly_as_with_the_rule_off() {
        let opts = SettleOptions::default();
        let off = SettleOptions {
            load_ratio: 0.0,
            ..SettleOptions::default()
        };
        // Only the stacks without a ≥ 10× load: bit-identical with the rule on or off.
        let plain: Vec<SimBody> = stacks()
            .into_iter()
            .filter(|b| !["dice", "brick", "pad10", "weight10"].contains(&b.name.as_str()))
            .collect();
        let on = settle(&plain, &opts).unwrap();
        assert!(on.heavily_loaded.is_empty());
        assert_eq!(on, settle(&plain, &off).unwrap());
        // The whole scene reports the two loaded bodies, and with the rule off none.
        let all = stacks();
        assert_eq!(
            settle(&all, &opts).unwrap().heavily_loaded,
            ["dice", "pad10"]
        );
        assert!(settle(&all, &off).unwrap().heavily_loaded.is_empty());
    }
}
