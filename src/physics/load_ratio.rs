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
//! A loaded body's contacts are also recomputed every step instead of recycled
//! ([`SettleOptions::loaded_fresh_contacts`]). Rapier's contact recycling keeps a pair's points
//! and normal, frozen in world space, while the pair moves less than
//! [`SettleOptions::contact_recycle_distance`] (0.5 mm). A light body under a load `k` times its
//! own weight feels a stale point of application `δ` as a tipping torque `k m g δ`, against its
//! own restoring torque `m g r` (`r`: its centre of mass's lever over its base edge): at
//! `k = 10` a 0.5 mm stale lever is worth a 5 mm shift of its own base. Measured (issue #33,
//! "Sixth pass"): a 1.8 kg bottle leaning in a 0.18 kg mug (seed 119) and a teapot on a mug
//! (304) slide slowly, in steps shorter than the recycle distance, and the recycled contacts
//! held the mug upright; with fresh contacts Rapier topples the mug (83° / 84°) as MuJoCo does
//! (82°) from the composed pose.
//!
//! With [`SettleOptions::loaded_stiff_contacts`] a world with a loaded body also runs its contacts
//! stiffer by the substep ratio (off by default; issue #33, "Tenth stop").
//!
//! Entry points: [`heavily_loaded`] (which bodies), [`Sim::load_extra_iterations`] (apply:
//! iterations, fresh contacts, stiff contacts).

use super::world::Sim;
use super::*;
use rapier3d_f64::pipeline::ActiveHooks;

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
        let fresh = self.opts.loaded_fresh_contacts && self.opts.contact_recycling;
        if self.opts.loaded_stiff_contacts && extra_sub > 0 && loaded.iter().any(|&l| l) {
            // Rapier's contact softness is the world's, not a body's: the whole world runs
            // stiffer. `hω` stays the unloaded world's in the loaded islands' substeps.
            let k = self.opts.loaded_solver_iterations as f64 / self.opts.solver_iterations as f64;
            let ip = &mut self.world.integration_parameters;
            ip.contact_softness.natural_frequency = self.opts.contact_frequency * k;
            ip.static_contact_softness.natural_frequency = self.opts.static_contact_frequency * k;
        }
        for (i, _) in loaded.iter().enumerate().filter(|(_, &l)| l) {
            let rb = &mut self.world.bodies[self.handles[i]];
            rb.set_additional_solver_iterations(extra_sub);
            rb.set_additional_pgs_iterations(extra_pgs);
            if fresh {
                // Rapier never recycles a pair whose collider asks for a contact hook; the
                // world's hooks are `()`, whose `modify_solver_contacts` changes nothing, so
                // the flag only turns recycling off for this body's pairs.
                for &c in &self.colliders[i] {
                    self.world.colliders[c].set_active_hooks(ActiveHooks::MODIFY_SOLVER_CONTACTS);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::V3;
    use std::f64::consts::PI;

    /// A box of extents `e` and `mass` standing with its bottom face at height `bottom`.
    fn block(name: &str, e: [f64; 3], mass: f64, x: f64, bottom: f64, fixed: bool) -> SimBody {
        let e = V3::new(e[0], e[1], e[2]);
        let pose = Isometry3::translation(x, 0.0, bottom + e.z / 2.0);
        SimBody {
            fixed,
            ..SimBody::cuboid(name, e, mass, pose, 0.6)
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

    #[test]
    fn a_loaded_bodys_contacts_are_never_recycled() {
        // The 25× stack alone: the dice touches the floor and the brick, the brick nothing
        // else, so every contact pair involves the loaded dice. With the rule, the settle must
        // be exactly Rapier's own without recycling (same loaded iterations), and differ from
        // the recycled run, or the flag did nothing.
        let pair: Vec<SimBody> = stacks()
            .into_iter()
            .filter(|b| ["dice", "brick"].contains(&b.name.as_str()))
            .collect();
        let opts = SettleOptions::default();
        let fresh = settle(&pair, &opts).unwrap();
        assert_eq!(fresh.heavily_loaded, ["dice"]);
        let no_recycling = SettleOptions {
            contact_recycling: false,
            ..SettleOptions::default()
        };
        assert_eq!(fresh, settle(&pair, &no_recycling).unwrap());
        let recycled = SettleOptions {
            loaded_fresh_contacts: false,
            ..SettleOptions::default()
        };
        assert_ne!(fresh, settle(&pair, &recycled).unwrap());
        // Without a loaded body the option changes nothing, bit for bit.
        let plain: Vec<SimBody> = stacks()
            .into_iter()
            .filter(|b| ["anvil", "feather", "pad", "weight"].contains(&b.name.as_str()))
            .collect();
        assert_eq!(
            settle(&plain, &opts).unwrap(),
            settle(&plain, &recycled).unwrap()
        );
    }

    #[test]
    fn stiff_loaded_contacts_sink_the_load_by_the_square_of_the_substep_ratio_less() {
        // The 25x stack alone: a 0.5 kg brick on a 20 g dice on the floor. Rapier's contact is
        // a spring normalised by the effective mass of the constraint, so the brick-dice
        // contact (load m_b g, reduced mass m_b m_d / (m_b + m_d), the four corner points
        // sharing it symmetrically) rests at about a = g (1 + m_b / m_d) = 26 g over
        // 2 omega^2: 0.224 mm at 120 Hz, and 1/4 of it at 240 Hz (the substep ratio 8 / 4 = 2,
        // squared).
        let pair: Vec<SimBody> = stacks()
            .into_iter()
            .filter(|b| ["dice", "brick"].contains(&b.name.as_str()))
            .collect();
        let depth = |stiff: bool| {
            let opts = SettleOptions {
                loaded_stiff_contacts: stiff,
                ..SettleOptions::default()
            };
            let r = settle(&pair, &opts).unwrap();
            assert_eq!(r.heavily_loaded, ["dice"]);
            assert!(r.passed);
            let dice = r.bodies.iter().find(|b| b.name == "dice").unwrap();
            assert_eq!(dice.rest_max_penetration_with.as_deref(), Some("brick"));
            dice.rest_max_penetration
        };
        let spring = |hz: f64| 9.81 * (1.0 + 0.5 / 0.02) / (2.0 * (2.0 * PI * hz).powi(2));
        let (soft, stiff) = (depth(false), depth(true));
        eprintln!(
            "soft {soft:.3e} (spring {:.3e}), stiff {stiff:.3e} (spring {:.3e}), ratio {:.3}",
            spring(120.0),
            spring(240.0),
            stiff / soft
        );
        // The depth goes as 1/omega^2 at a fixed substep: a quarter (measured 0.249).
        assert!((0.22..0.28).contains(&(stiff / soft)), "{stiff} / {soft}");
        // The single-spring estimate gives the order of magnitude only: measured 1.96x of it
        // (the four coupled corner constraints and the floor contact under the dice settle
        // deeper than one spring; not derived here).
        for (d, hz) in [(soft, 120.0), (stiff, 240.0)] {
            assert!(
                (1.0..3.0).contains(&(d / spring(hz))),
                "{d} vs {}",
                spring(hz)
            );
        }
        // Without a loaded body the option changes nothing, bit for bit.
        let plain: Vec<SimBody> = stacks()
            .into_iter()
            .filter(|b| ["anvil", "feather", "pad", "weight"].contains(&b.name.as_str()))
            .collect();
        let stiff_opts = SettleOptions {
            loaded_stiff_contacts: true,
            ..SettleOptions::default()
        };
        assert_eq!(
            settle(&plain, &SettleOptions::default()).unwrap(),
            settle(&plain, &stiff_opts).unwrap()
        );
    }
}
