//! Static equilibrium of a contact network under gravity, without a solver's dynamics: can the
//! contacts of a set of rigid bodies, at fixed poses, carry every body's weight with forces
//! inside their Coulomb friction cones?
//!
//! Entry points: [`balance`] (the relative unbalanced wrench of each group of bodies coupled by
//! contacts; 0 when the network holds) and [`nnls`] (Lawson–Hanson non-negative least squares,
//! the solver behind it). Used by the settle test's creep rule (see [`super::creep`]).
//!
//! Each contact's friction cone is replaced by an inscribed pyramid of [`CONE_SIDES`] edges, so
//! a network that balances on the pyramid balances on the cone (the check errs towards "does
//! not hold"): with 16 edges every direction keeps at least cos(π/16) = 98.1 % of `mu`. With
//! non-negative edge forces `λ`, equilibrium is `A λ = w` (per body: force and torque about its
//! centre of mass), a linear feasibility problem; [`nnls`] finds the `λ ≥ 0` closest to it, and
//! the residual is exactly zero (to round-off) when the network holds. A hand-written NNLS is
//! preferred to a conic solver crate: the problems have 6 rows per body and a few hundred
//! columns, and the polyhedral cone is the conservative side of the exact one.

use nalgebra::{DMatrix, DVector, Vector3};

/// Edges of the inscribed friction pyramid.
pub const CONE_SIDES: usize = 16;

/// One contact point: a force along `normal` (unit, pushing body `a` away from `b`) within the
/// cone of half-angle atan(`mu`) acts on `a` at `point`, and its opposite on `b` (`None`: the
/// floor or a fixed body, which carry anything).
#[derive(Clone, Debug, PartialEq)]
pub struct Contact {
    pub a: usize,
    pub b: Option<usize>,
    pub point: Vector3<f64>,
    pub normal: Vector3<f64>,
    pub mu: f64,
}

/// A dynamic body as the balance sees it: mass (kg), world centre of mass, and a length (m)
/// that turns its torques into forces (its reach from the centre of mass), so that force and
/// torque rows weigh alike.
#[derive(Clone, Debug, PartialEq)]
pub struct Load {
    pub mass: f64,
    pub com: Vector3<f64>,
    pub length: f64,
}

/// For each body, the relative unbalanced wrench of its group (the bodies coupled to it by
/// contacts between dynamic bodies): |A λ − w| / (g · the group's mass) at the best `λ ≥ 0`,
/// force and torque/length rows together. 0 when the contacts can hold the group at rest;
/// of order 1 when nothing holds it (a body in free fall gives exactly 1).
pub fn balance(loads: &[Load], contacts: &[Contact], gravity: f64) -> Vec<f64> {
    let n = loads.len();
    // Groups: union-find over contacts between two dynamic bodies.
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    for c in contacts {
        if let Some(b) = c.b {
            let (ra, rb) = (root(&mut parent, c.a), root(&mut parent, b));
            if ra != rb {
                parent[ra.max(rb)] = ra.min(rb);
            }
        }
    }
    let groups: Vec<usize> = (0..n).map(|i| root(&mut parent, i)).collect();
    let mut out = vec![0.0; n];
    for g in 0..n {
        if groups[g] != g {
            continue;
        }
        let members: Vec<usize> = (0..n).filter(|&i| groups[i] == g).collect();
        let row = |i: usize| members.iter().position(|&m| m == i);
        let cs: Vec<&Contact> = contacts.iter().filter(|c| groups[c.a] == g).collect();
        let rows = 6 * members.len();
        let mut a = DMatrix::zeros(rows, cs.len() * CONE_SIDES);
        let mut w = DVector::zeros(rows);
        let mut weight = 0.0;
        for (k, &i) in members.iter().enumerate() {
            // The contacts must supply the opposite of gravity: +m g along z, no torque.
            w[6 * k + 2] = loads[i].mass * gravity;
            weight += loads[i].mass * gravity;
        }
        for (ci, c) in cs.iter().enumerate() {
            for (s, e) in pyramid(&c.normal, c.mu).iter().enumerate() {
                let col = ci * CONE_SIDES + s;
                for (body, sign) in [(Some(c.a), 1.0), (c.b, -1.0)] {
                    let Some(k) = body.and_then(row) else {
                        continue;
                    };
                    let l = &loads[members[k]];
                    let f = e * sign;
                    let t = (c.point - l.com).cross(&f) / l.length.max(1e-9);
                    for r in 0..3 {
                        a[(6 * k + r, col)] = f[r];
                        a[(6 * k + 3 + r, col)] = t[r];
                    }
                }
            }
        }
        let lambda = nnls(&a, &w);
        let rel = if weight > 0.0 {
            (&a * lambda - &w).norm() / weight
        } else {
            0.0
        };
        for &i in &members {
            out[i] = rel;
        }
    }
    out
}

/// The unit edges of the friction pyramid inscribed in the cone about `normal` (unit) of
/// half-angle atan(`mu`).
fn pyramid(normal: &Vector3<f64>, mu: f64) -> Vec<Vector3<f64>> {
    let helper = if normal.x.abs() < 0.6 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let t1 = normal.cross(&helper).normalize();
    let t2 = normal.cross(&t1);
    (0..CONE_SIDES)
        .map(|s| {
            let th = std::f64::consts::TAU * s as f64 / CONE_SIDES as f64;
            (normal + (t1 * th.cos() + t2 * th.sin()) * mu).normalize()
        })
        .collect()
}

/// Lawson–Hanson non-negative least squares: the `x ≥ 0` minimising |A x − b|. Deterministic
/// (ties go to the lowest column); stops after a bounded number of passes, so an unconverged
/// answer is still feasible (`x ≥ 0`) and its residual an upper bound of the optimum: the
/// balance can only err towards "does not hold".
pub fn nnls(a: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let n = a.ncols();
    let mut x = DVector::zeros(n);
    let mut passive = vec![false; n];
    let scale = a.amax().max(1e-300) * b.amax().max(1e-300);
    let tol = 1e-12 * scale * (a.nrows().max(n) as f64);
    let solve = |passive: &[bool]| -> (Vec<usize>, DVector<f64>) {
        let idx: Vec<usize> = (0..n).filter(|&j| passive[j]).collect();
        let ap = a.select_columns(idx.iter());
        let z = ap
            .svd(true, true)
            .solve(b, 1e-13)
            .unwrap_or_else(|_| DVector::zeros(idx.len()));
        (idx, z)
    };
    for _ in 0..3 * n.max(1) {
        let grad = a.transpose() * (b - a * &x);
        let pick = (0..n).filter(|&j| !passive[j] && grad[j] > tol).fold(
            None,
            |best: Option<usize>, j| match best {
                Some(k) if grad[k] >= grad[j] => Some(k),
                _ => Some(j),
            },
        );
        let Some(j) = pick else {
            break;
        };
        passive[j] = true;
        for _ in 0..n {
            let (idx, z) = solve(&passive);
            if z.iter().all(|&v| v > 0.0) {
                x.fill(0.0);
                for (k, &j) in idx.iter().enumerate() {
                    x[j] = z[k];
                }
                break;
            }
            // Step from x towards z until the first passive variable reaches zero.
            let mut alpha = 1.0f64;
            for (k, &j) in idx.iter().enumerate() {
                if z[k] <= 0.0 {
                    let d = x[j] - z[k];
                    if d > 0.0 {
                        alpha = alpha.min(x[j] / d);
                    }
                }
            }
            for (k, &j) in idx.iter().enumerate() {
                x[j] += alpha * (z[k] - x[j]);
                if x[j] <= tol.max(1e-15 * x.amax()) {
                    x[j] = 0.0;
                    passive[j] = false;
                }
            }
            if !idx.iter().any(|&j| passive[j]) {
                break;
            }
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: f64 = 9.81;

    /// A 0.2 × 0.1 (x × y) box of mass 1, 0.1 high, on a plane tilted by `angle` about y: its
    /// four base corners as contacts with the plane's normal.
    fn box_on_incline(angle: f64, mu: f64) -> (Vec<Load>, Vec<Contact>) {
        let (s, c) = angle.sin_cos();
        // Plane frame: x' down the slope (rotated about y), z' the normal.
        let xp = Vector3::new(c, 0.0, -s);
        let zp = Vector3::new(s, 0.0, c);
        let yp = Vector3::y();
        let com = zp * 0.05;
        let contacts = [(-0.1, -0.05), (0.1, -0.05), (0.1, 0.05), (-0.1, 0.05)]
            .iter()
            .map(|&(u, v)| Contact {
                a: 0,
                b: None,
                point: xp * u + yp * v,
                normal: zp,
                mu,
            })
            .collect();
        let loads = vec![Load {
            mass: 1.0,
            com,
            length: 0.12,
        }];
        (loads, contacts)
    }

    #[test]
    fn a_box_on_an_incline_holds_iff_tan_angle_is_within_mu() {
        let mu: f64 = 0.5;
        // The inscribed pyramid keeps at least cos(π/16) of mu in every direction.
        let keep = (std::f64::consts::PI / CONE_SIDES as f64).cos();
        for (ratio, holds) in [
            (0.0, true),
            (0.5, true),
            (0.9, true),
            (keep * 0.999, true),
            (1.01, false),
            (1.2, false),
            (2.0, false),
        ] {
            let angle = (ratio * mu).atan();
            let (l, c) = box_on_incline(angle, mu);
            let r = balance(&l, &c, G)[0];
            assert_eq!(r < 1e-6, holds, "tan = {ratio} mu: residual {r}");
            if !holds {
                // Unbalanced part of the weight: its distance to the cone, at least
                // (sin a − mu cos a) / sqrt(1 + mu²) for the exact cone and at most
                // sin a − mu_eff cos a for the cone of mu_eff = cos(π/16)·mu inside the pyramid.
                let (s, c) = angle.sin_cos();
                let exact = (s - mu * c) / (1.0 + mu * mu).sqrt();
                assert!(r <= s - keep * mu * c + 1e-9 && r >= exact - 1e-9, "{r}");
            }
        }
    }

    #[test]
    fn a_box_in_free_fall_is_wholly_unbalanced() {
        let (l, _) = box_on_incline(0.0, 0.5);
        assert!((balance(&l, &[], G)[0] - 1.0).abs() < 1e-12);
    }

    /// A uniform ladder (mass 1, length 1) from the floor to a wall at `theta` from the floor,
    /// friction `mu1` at the floor and `mu2` at the wall: the classic condition for rest is
    /// tan θ ≥ (1 − mu1·mu2) / (2 mu1). Two contact points at each end (0.1 apart in y) so that
    /// the ladder cannot spin about its own length.
    fn ladder(theta: f64, mu1: f64, mu2: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        let foot = Vector3::new(0.0, 0.0, 0.0);
        let top = Vector3::new(c, 0.0, s);
        let com = (foot + top) / 2.0;
        let mut contacts = Vec::new();
        for dy in [-0.05, 0.05] {
            let off = Vector3::new(0.0, dy, 0.0);
            contacts.push(Contact {
                a: 0,
                b: None,
                point: foot + off,
                normal: Vector3::z(),
                mu: mu1,
            });
            contacts.push(Contact {
                a: 0,
                b: None,
                point: top + off,
                normal: -Vector3::x(),
                mu: mu2,
            });
        }
        let loads = [Load {
            mass: 1.0,
            com,
            length: 0.5,
        }];
        balance(&loads, &contacts, G)[0]
    }

    #[test]
    fn a_ladder_rests_per_the_classic_condition() {
        for (mu1, mu2) in [(0.5f64, 0.0f64), (0.4, 0.3), (0.8, 0.5)] {
            let critical = ((1.0 - mu1 * mu2) / (2.0 * mu1)).atan();
            // Well inside, with the pyramid's loss of at most 2 % of mu.
            assert!(ladder(critical + 0.05, mu1, mu2) < 1e-6, "{mu1} {mu2}");
            assert!(ladder(1.4, mu1, mu2) < 1e-6);
            assert!(ladder(critical - 0.02, mu1, mu2) > 1e-4, "{mu1} {mu2}");
            assert!(ladder(critical * 0.5, mu1, mu2) > 1e-3);
        }
    }

    #[test]
    fn a_stack_is_balanced_as_one_group() {
        // A 1 kg block (0.1 cube) on the floor carrying a 3 kg block centred on it: balanced.
        // Shift the top block's centre past the lower one's edge: the top cannot be held.
        let corners = [(-0.05, -0.05), (0.05, -0.05), (0.05, 0.05), (-0.05, 0.05)];
        let run = |shift: f64| {
            let mut cs = Vec::new();
            for &(x, y) in &corners {
                cs.push(Contact {
                    a: 0,
                    b: None,
                    point: Vector3::new(x, y, 0.0),
                    normal: Vector3::z(),
                    mu: 0.5,
                });
                // The top block touches the lower one's top face where they overlap.
                let xs = (x + shift).clamp(-0.05, 0.05);
                cs.push(Contact {
                    a: 1,
                    b: Some(0),
                    point: Vector3::new(xs, y, 0.1),
                    normal: Vector3::z(),
                    mu: 0.5,
                });
            }
            let loads = [
                Load {
                    mass: 1.0,
                    com: Vector3::new(0.0, 0.0, 0.05),
                    length: 0.09,
                },
                Load {
                    mass: 3.0,
                    com: Vector3::new(shift, 0.0, 0.15),
                    length: 0.09,
                },
            ];
            balance(&loads, &cs, G)
        };
        let ok = run(0.03);
        assert!(ok[0] < 1e-6 && ok[1] < 1e-6, "{ok:?}");
        let off = run(0.07);
        assert!(off[0] > 1e-3 && off[0] == off[1], "{off:?}");
    }

    #[test]
    fn nnls_matches_a_hand_solved_case() {
        // min |x1 e1 + x2 (1,1) - (2, -1)| with x >= 0: the unconstrained optimum has x2 < 0,
        // so x2 = 0, x1 = 2, residual 1.
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 0.0, 1.0]);
        let b = DVector::from_vec(vec![2.0, -1.0]);
        let x = nnls(&a, &b);
        assert!((x[0] - 2.0).abs() < 1e-12 && x[1] == 0.0, "{x}");
    }
}
