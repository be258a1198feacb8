//! The free seed's reference motion: the piston-crank with its mass properties and its crank
//! free (`piston_crank_free.mech`), reduced to its one coordinate, the crank angle φ, and
//! integrated in this module, independently of mechgen's solver and integrator.
//!
//! With the closed-form kinematics `q(φ)` ([`PistonCrank::positions_at_angle`], its first two
//! derivatives `q' = dq/dφ`, `q'' = d²q/dφ²` exact from second-order dual numbers) and the
//! bodies' reference points at their centres of mass, the kinetic energy is `½ m(φ) φ̇²` with
//! `m = q'ᵀ M q'`, and Lagrange's equation is
//! `m(φ) φ̈ + (q'ᵀ M q'') φ̇² = q'ᵀ f_g` (the middle term is `½ m'(φ) φ̇²`; `f_g` the weights).
//! Classical Runge–Kutta at a fixed step integrates it ([`FreeSeed::release`]); at 1e-5 s its
//! error over the seed's 0.5 s release is far below 1e-12 rad (the tests halve the step).

use crate::closed_form::{PistonCrank, differentiate};
use crate::inverse_dynamics::MassProperties;

/// The seed with its mass properties, moving freely under gravity: the reference of the free
/// seed's forward dynamics (tests, benchmarks, the peer comparison).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FreeSeed {
    /// Geometry (its `omega` is not used: the crank is free).
    pub form: PistonCrank,
    /// Masses, inertias and gravity.
    pub mass: MassProperties,
}

/// The crank's state: angle (rad) and rate (rad/s).
pub type Crank = [f64; 2];

impl FreeSeed {
    /// `(m(φ), q'ᵀ M q''(φ), q'ᵀ f_g(φ))`: reduced mass, half its derivative, reduced weight.
    fn reduced(&self, phi: f64) -> (f64, f64, f64) {
        let k = differentiate(|phi| self.form.positions_at_angle(phi), phi);
        let (mut m, mut c, mut q) = (0.0, 0.0, 0.0);
        // Moving bodies: piston, rod, crank at coordinates 3, 6, 9 (x, y, θ each).
        for (start, (mass, inertia)) in [
            (3, self.mass.piston),
            (6, self.mass.rod),
            (9, self.mass.crank),
        ] {
            let (d1, d2) = (&k.qd[start..start + 3], &k.qdd[start..start + 3]);
            m += mass * (d1[0] * d1[0] + d1[1] * d1[1]) + inertia * d1[2] * d1[2];
            c += mass * (d1[0] * d2[0] + d1[1] * d2[1]) + inertia * d1[2] * d2[2];
            q += mass * (self.mass.gravity[0] * d1[0] + self.mass.gravity[1] * d1[1]);
        }
        (m, c, q)
    }

    /// The crank's angular acceleration φ̈ at `crank` (Lagrange's equation solved for it).
    pub fn acceleration(&self, [phi, rate]: Crank) -> f64 {
        let (m, c, q) = self.reduced(phi);
        (q - c * rate * rate) / m
    }

    /// Kinetic plus gravitational potential energy at `crank` (kg·mm²/s²): constant along the
    /// motion.
    pub fn energy(&self, [phi, rate]: Crank) -> f64 {
        let (m, _, _) = self.reduced(phi);
        let q = self.form.positions_at_angle(phi);
        let g = self.mass.gravity;
        let potential: f64 = [
            (3, self.mass.piston.0),
            (6, self.mass.rod.0),
            (9, self.mass.crank.0),
        ]
        .iter()
        .map(|&(start, mass)| -mass * (g[0] * q[start] + g[1] * q[start + 1]))
        .sum();
        0.5 * m * rate * rate + potential
    }

    /// The crank's state at each of `times` (ascending, from 0) after starting at `start`,
    /// by classical Runge–Kutta with steps of at most `step` that land on every time.
    pub fn release(&self, start: Crank, times: &[f64], step: f64) -> Vec<Crank> {
        let mut state = start;
        let mut t = 0.0;
        let mut out = Vec::with_capacity(times.len());
        for &target in times {
            let span = target - t;
            // A whole number of equal steps onto `target` (at least one for a positive span).
            let count = (span / step).ceil().max(0.0);
            if count > 0.0 {
                let h = span / count;
                for _ in 0..count as u64 {
                    state = self.rk4(state, h);
                }
            }
            t = target;
            out.push(state);
        }
        out
    }

    fn rk4(&self, [phi, rate]: Crank, h: f64) -> Crank {
        let f = |[p, r]: Crank| [r, self.acceleration([p, r])];
        let k1 = f([phi, rate]);
        let k2 = f([phi + 0.5 * h * k1[0], rate + 0.5 * h * k1[1]]);
        let k3 = f([phi + 0.5 * h * k2[0], rate + 0.5 * h * k2[1]]);
        let k4 = f([phi + h * k3[0], rate + h * k3[1]]);
        [
            phi + h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
            rate + h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::FreeSeed;

    const TIMES: [f64; 5] = [0.1, 0.2, 0.3, 0.4, 0.5];

    #[test]
    fn the_reference_converges_at_fourth_order_below_1e_12() {
        let seed = FreeSeed::default();
        let coarse = seed.release([0.3, 0.0], &TIMES, 2e-5);
        let fine = seed.release([0.3, 0.0], &TIMES, 1e-5);
        let finer = seed.release([0.3, 0.0], &TIMES, 5e-6);
        let worst = |a: &[[f64; 2]], b: &[[f64; 2]]| {
            a.iter()
                .zip(b)
                .map(|(x, y)| (x[0] - y[0]).abs())
                .fold(0.0, f64::max)
        };
        let (first, second) = (worst(&coarse, &fine), worst(&fine, &finer));
        assert!(second < 1e-12, "halving 1e-5 s moves φ by {second:e} rad");
        // Fourth order: 16× smaller per halving, until round-off takes over.
        assert!(
            first > 8.0 * second || first < 1e-13,
            "{first:e} then {second:e}"
        );
    }

    #[test]
    fn the_reference_keeps_its_energy() {
        let seed = FreeSeed::default();
        let start = seed.energy([0.3, 0.0]);
        for state in seed.release([0.3, 0.0], &TIMES, 1e-5) {
            let drift = (seed.energy(state) - start).abs() / start.abs();
            assert!(
                drift < 1e-12,
                "relative energy drift {drift:e} at {state:?}"
            );
        }
    }

    #[test]
    fn released_from_rest_the_weight_of_the_rod_turns_the_crank() {
        // At rest only the rod's weight acts (the crank's centre is on its axis, the piston
        // does not rise): φ̈ = m_rod g y_rod'(φ) / m(φ), computed here by central differences
        // of the closed-form positions (the module's derivatives come from dual numbers).
        let seed = FreeSeed::default();
        let (phi, e) = (0.3, 1e-6);
        let q = |phi: f64| seed.form.positions_at_angle(phi);
        let d = |i: usize| (q(phi + e)[i] - q(phi - e)[i]) / (2.0 * e);
        let (piston, rod, crank) = (seed.mass.piston, seed.mass.rod, seed.mass.crank);
        let m = piston.0 * d(3).powi(2)
            + rod.0 * (d(6).powi(2) + d(7).powi(2))
            + rod.1 * d(8).powi(2)
            + crank.1;
        let expected = rod.0 * seed.mass.gravity[1] * d(7) / m;
        let got = seed.acceleration([phi, 0.0]);
        assert!(expected > 0.0, "the crank turns forward: {expected}");
        assert!(
            (got - expected).abs() < 1e-7 * expected,
            "{got} against {expected}"
        );
    }
}
