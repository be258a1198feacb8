//! The free seed: the piston-crank with the `PistonCrankDynamics` mass properties, its crank
//! angle `φ` the one coordinate, moving under gravity (and, for the stiff test, a spring
//! between the piston and the liner), by its reduced Lagrange equation
//!
//! ```text
//! m(φ) φ̈ + ½ m′(φ) φ̇² = Q(φ, φ̇),   m(φ) = Σ_bodies m |c′(φ)|² + J θ′(φ)²,
//! Q = −dV/dφ − c ℓ′² φ̇,             V = −Σ m g · c + ½ k (ℓ − L)²
//! ```
//!
//! where `′` is d/dφ, `c` a body's centre of mass (its reference point in this scene), `θ` its
//! angle and `ℓ` the spring's length. The kinematics `q(φ)`, `q′`, `q″` are the seed's closed
//! form written out by hand (`mechgen_examples::written_out`, the crank turning at unit rate so
//! that time is the angle): nothing here comes from mechgen.

use mechgen_examples::closed_form::PistonCrank;
use mechgen_examples::inverse_dynamics::MassProperties;

/// Coordinate index of each moving body's `x` (then `y`, `θ`) in the seed's `q`.
const BODIES: [usize; 3] = [3, 6, 9];

/// A linear spring-damper from a point fixed on the liner's axis to the piston's reference
/// point (both on the world x axis): tension `k (ℓ − L) + c ℓ̇`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spring {
    /// World x of the fixed end, mm.
    pub anchor: f64,
    /// Stiffness `k`, kg/s².
    pub stiffness: f64,
    /// Free length `L`, mm.
    pub length: f64,
    /// Damping `c`, kg/s.
    pub damping: f64,
}

/// The seed's positions and their first and second derivatives along the crank angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Configuration {
    /// `q(φ)`.
    pub q: [f64; 15],
    /// `∂q/∂φ`.
    pub dq: [f64; 15],
    /// `∂²q/∂φ²`.
    pub ddq: [f64; 15],
}

/// The free seed: geometry, mass properties, gravity and an optional spring.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FreeSeed {
    /// The geometry (its `omega` is not used: the crank is free).
    pub geometry: PistonCrank,
    /// Masses, inertias and gravity.
    pub mass: MassProperties,
    /// The spring-damper, if any.
    pub spring: Option<Spring>,
}

impl Default for FreeSeed {
    /// The seed of `examples/scenes/piston_crank_dynamics.mech` without its driver.
    fn default() -> Self {
        Self {
            geometry: PistonCrank::default(),
            mass: MassProperties::default(),
            spring: None,
        }
    }
}

impl FreeSeed {
    /// The release angle of the tests, rad.
    pub const RELEASE: f64 = 0.3;

    /// The seed with a spring of stiffness `stiffness` (and damping `damping`) from the liner's
    /// point at world x `anchor` to the piston, at rest (free length) at crank angle `phi0`.
    pub fn with_spring(anchor: f64, stiffness: f64, damping: f64, phi0: f64) -> Self {
        let mut seed = Self::default();
        let length = (seed.configuration(phi0).q[3] - anchor).abs();
        seed.spring = Some(Spring {
            anchor,
            stiffness,
            length,
            damping,
        });
        seed
    }

    /// `q`, `∂q/∂φ`, `∂²q/∂φ²` at crank angle `phi`.
    pub fn configuration(&self, phi: f64) -> Configuration {
        let unit_rate = PistonCrank {
            omega: 1.0,
            ..self.geometry
        };
        let mut out = ([0.0; 15], [0.0; 15], [0.0; 15]);
        unit_rate.written_out(phi, &mut out);
        Configuration {
            q: out.0,
            dq: out.1,
            ddq: out.2,
        }
    }

    /// `(m, J)` of the moving bodies in [`BODIES`] order.
    fn bodies(&self) -> [(f64, f64); 3] {
        [self.mass.piston, self.mass.rod, self.mass.crank]
    }

    /// The generalised mass `m(φ)` and its derivative `m′(φ)`, kg·mm².
    pub fn generalised_mass(&self, c: &Configuration) -> (f64, f64) {
        let (mut m, mut dm) = (0.0, 0.0);
        for (&i, (mass, inertia)) in BODIES.iter().zip(self.bodies()) {
            let (d, dd) = (&c.dq[i..i + 3], &c.ddq[i..i + 3]);
            m += mass * (d[0] * d[0] + d[1] * d[1]) + inertia * d[2] * d[2];
            dm += 2.0 * (mass * (d[0] * dd[0] + d[1] * dd[1]) + inertia * d[2] * dd[2]);
        }
        (m, dm)
    }

    /// The spring's length `ℓ` and `ℓ′ = dℓ/dφ` (zeros without a spring).
    fn spring_length(&self, c: &Configuration) -> (f64, f64) {
        self.spring.map_or((0.0, 0.0), |s| {
            let offset = c.q[3] - s.anchor;
            (offset.abs(), offset.signum() * c.dq[3])
        })
    }

    /// The potential energy `V(φ)` of gravity and the spring, kg·mm²/s².
    pub fn potential(&self, c: &Configuration) -> f64 {
        let g = self.mass.gravity;
        let gravity: f64 = BODIES
            .iter()
            .zip(self.bodies())
            .map(|(&i, (mass, _))| -mass * (g[0] * c.q[i] + g[1] * c.q[i + 1]))
            .sum();
        let (length, _) = self.spring_length(c);
        let spring = self
            .spring
            .map_or(0.0, |s| 0.5 * s.stiffness * (length - s.length).powi(2));
        gravity + spring
    }

    /// The generalised force `Q(φ, φ̇)` along the crank angle: `−dV/dφ` and the damper's.
    pub fn generalised_force(&self, c: &Configuration, rate: f64) -> f64 {
        let g = self.mass.gravity;
        let gravity: f64 = BODIES
            .iter()
            .zip(self.bodies())
            .map(|(&i, (mass, _))| mass * (g[0] * c.dq[i] + g[1] * c.dq[i + 1]))
            .sum();
        let (length, dlength) = self.spring_length(c);
        let spring = self.spring.map_or(0.0, |s| {
            -(s.stiffness * (length - s.length) + s.damping * dlength * rate) * dlength
        });
        gravity + spring
    }

    /// The crank's angular acceleration `φ̈` at `(φ, φ̇)`.
    pub fn acceleration(&self, phi: f64, rate: f64) -> f64 {
        self.solve_acceleration(&self.configuration(phi), rate)
    }

    /// `φ̈` from the reduced equation at configuration `c` and rate `rate`.
    fn solve_acceleration(&self, c: &Configuration, rate: f64) -> f64 {
        let (m, dm) = self.generalised_mass(c);
        (self.generalised_force(c, rate) - 0.5 * dm * rate * rate) / m
    }

    /// `[φ̇, φ̈, Ḋ]` at `[φ, φ̇, D]`, `D` the energy the damper has dissipated (`Ḋ = c ℓ̇²`).
    pub fn rate(&self, y: &[f64; 3]) -> [f64; 3] {
        let [phi, rate, _] = *y;
        let c = self.configuration(phi);
        let accel = self.solve_acceleration(&c, rate);
        let (_, dlength) = self.spring_length(&c);
        let damping = self.spring.map_or(0.0, |s| s.damping);
        [rate, accel, damping * (dlength * rate).powi(2)]
    }

    /// Kinetic plus potential energy plus what the damper dissipated: constant along a motion.
    pub fn energy(&self, y: &[f64; 3]) -> f64 {
        let [phi, rate, dissipated] = *y;
        let c = self.configuration(phi);
        0.5 * self.generalised_mass(&c).0 * rate * rate + self.potential(&c) + dissipated
    }

    /// The seed's `q`, `q̇`, `q̈` at the reduced state `(φ, φ̇)`: `q̇ = q′ φ̇`,
    /// `q̈ = q′ φ̈ + q″ φ̇²`.
    pub fn motion(&self, phi: f64, rate: f64) -> [[f64; 15]; 3] {
        let c = self.configuration(phi);
        let accel = self.solve_acceleration(&c, rate);
        [
            c.q,
            c.dq.map(|d| d * rate),
            std::array::from_fn(|i| c.dq[i] * accel + c.ddq[i] * rate * rate),
        ]
    }

    /// The small-oscillation angular frequency `√(V″/m)` about the crank angle `phi` (rad/s;
    /// NaN where `V″ < 0`), `V″` by central differences of `V′ = −Q(φ, 0)`.
    pub fn local_frequency(&self, phi: f64) -> f64 {
        let h = 1e-6;
        let slope = |p: f64| -self.generalised_force(&self.configuration(p), 0.0);
        let curvature = (slope(phi + h) - slope(phi - h)) / (2.0 * h);
        (curvature / self.generalised_mass(&self.configuration(phi)).0).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::ode::{Ode, Tolerance};
    use mechgen_examples::closed_form::Kinematics;
    use mechgen_examples::inverse_dynamics::seed_reactions;
    use num_dual::{Dual2_64, second_derivative};

    /// `[φ, φ̇, D]` at `times` from rest at the release angle.
    fn release(seed: &FreeSeed, times: &[f64]) -> Vec<[f64; 3]> {
        let mut ode = Ode::new(
            |_, y: &[f64; 3]| seed.rate(y),
            0.0,
            [FreeSeed::RELEASE, 0.0, 0.0],
            Tolerance::REFERENCE,
        );
        times.iter().map(|&t| ode.advance_to(t).unwrap()).collect()
    }

    #[test]
    fn the_written_out_derivatives_are_the_dual_number_ones() {
        let seed = FreeSeed::default();
        for phi in [0.0, 0.3, 2.0, 4.5] {
            let c = seed.configuration(phi);
            let parts: [(f64, f64, f64); 15] =
                second_derivative(|p: Dual2_64| seed.geometry.positions_at_angle(p), phi);
            for (i, (q, dq, ddq)) in parts.into_iter().enumerate() {
                assert!((c.q[i] - q).abs() < 1e-12 * q.abs().max(1.0));
                assert!((c.dq[i] - dq).abs() < 1e-12 * dq.abs().max(1.0));
                assert!((c.ddq[i] - ddq).abs() < 1e-12 * ddq.abs().max(1.0));
            }
        }
    }

    #[test]
    fn the_crank_needs_no_torque_along_the_reduced_motion() {
        // Newton–Euler body by body (the force solve's closed-form reference) along the motion
        // the Lagrange equation gives: the driving torque of a free crank is zero.
        let seed = FreeSeed::default();
        for (phi, rate) in [(0.3, 0.0), (1.0, -20.0), (2.5, 35.0), (-0.4, 5.0)] {
            let [q, qd, qdd] = seed.motion(phi, rate);
            let k = Kinematics { t: 0.0, q, qd, qdd };
            let torque = seed_reactions(&seed.geometry, &seed.mass, &k).crank_angle;
            // Against the gravity torque's scale, m g r.
            let scale = 2.1 * 9810.0 * 43.0;
            assert!(torque.abs() < 1e-12 * scale, "{phi}: {torque:e}");
        }
    }

    #[test]
    fn the_examples_reduced_equation_is_this_one() {
        // `mechgen_examples::free_seed` (RK4, for the example binary and the benchmarks)
        // derives the same equation independently (dual numbers, not the written-out
        // derivatives): the two must not drift apart.
        let (ours, theirs) = (
            FreeSeed::default(),
            mechgen_examples::free_seed::FreeSeed::default(),
        );
        for (phi, rate) in [(0.3, 0.0), (1.0, -20.0), (2.5, 35.0), (-0.4, 5.0)] {
            let (a, b) = (
                ours.acceleration(phi, rate),
                theirs.acceleration([phi, rate]),
            );
            assert!(
                (a - b).abs() <= 1e-12 * a.abs().max(1.0),
                "{phi}, {rate}: {a} vs {b}"
            );
        }
    }

    #[test]
    fn the_free_seed_conserves_its_energy_to_1e12() {
        let seed = FreeSeed::default();
        let times: Vec<f64> = (1..=100).map(|i| i as f64 * 0.005).collect();
        let states = release(&seed, &times);
        let energy = seed.energy(&[FreeSeed::RELEASE, 0.0, 0.0]);
        // The energy exchanged: the gravity potential's range over a turn.
        let range = seed.mass.rod.0 * 9810.0 * 2.0 * 43.0;
        let drift = states
            .iter()
            .map(|y| (seed.energy(y) - energy).abs() / range)
            .fold(0.0, f64::max);
        let swing = states.iter().map(|y| y[0]).fold(f64::MIN, f64::max)
            - states.iter().map(|y| y[0]).fold(f64::MAX, f64::min);
        eprintln!("free seed, 0.5 s: energy drift {drift:.1e} (relative), swing {swing:.2} rad");
        assert!(drift < 1e-12, "{drift:e}");
        // It moves: gravity on the rod turns the crank.
        assert!(swing > 0.1, "{swing}");
    }

    #[test]
    fn the_stiff_seed_conserves_energy_and_dissipates_what_its_damper_does() {
        for damping in [0.0, 200.0] {
            let seed = FreeSeed::with_spring(256.8, 1e7, damping, FreeSeed::RELEASE);
            let period = 2.0 * std::f64::consts::PI / seed.local_frequency(FreeSeed::RELEASE);
            let times: Vec<f64> = (1..=50).map(|i| i as f64 * 0.01).collect();
            let states = release(&seed, &times);
            let energy = seed.energy(&[FreeSeed::RELEASE, 0.0, 0.0]);
            let range = seed.mass.rod.0 * 9810.0 * 2.0 * 43.0;
            let drift = states
                .iter()
                .map(|y| (seed.energy(y) - energy).abs() / range)
                .fold(0.0, f64::max);
            let dissipated = states.last().unwrap()[2];
            eprintln!(
                "stiff seed (c = {damping}): spring period at release {period:.2e} s, \
                 energy drift over 0.5 s {drift:.1e}, dissipated {dissipated:.3e}"
            );
            assert!(drift < 1e-11, "{drift:e}");
            assert_eq!(dissipated > 0.0, damping > 0.0);
            // At rest length at release: the spring starts slack of force.
            let c = seed.configuration(FreeSeed::RELEASE);
            assert!(seed.spring_length(&c).0 - seed.spring.unwrap().length == 0.0);
        }
    }
}
