//! The simple pendulum, a rigid body swinging about a fixed pivot under gravity: the harmonic
//! solution of small swings, the exact large-amplitude motion from rest by Jacobi's elliptic
//! sine and its period `4 K(k) / ω₀` by the complete elliptic integral `K`, both from the
//! arithmetic–geometric mean (Abramowitz & Stegun 17.6, 16.4), and its equation of motion for
//! [`super::ode`].
//!
//! The swing angle `φ` is measured from the hanging position (centre of mass straight below
//! the pivot), positive anticlockwise: for a body whose x axis points from the pivot to its
//! centre of mass, under gravity `(0, −g)`, `φ = θ + π/2`.

use std::f64::consts::PI;

/// A rigid body on a pivot: `J_pivot φ̈ = −m g d sin φ`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pendulum {
    /// Mass, kg.
    pub mass: f64,
    /// Moment of inertia about the centre of mass, kg·mm².
    pub inertia: f64,
    /// Distance from the pivot to the centre of mass, mm.
    pub arm: f64,
    /// Magnitude of gravity, mm/s² (pointing to −y).
    pub gravity: f64,
}

impl Pendulum {
    /// Moment of inertia about the pivot (parallel axes), kg·mm².
    pub fn pivot_inertia(&self) -> f64 {
        self.inertia + self.mass * self.arm * self.arm
    }

    /// Small-swing angular frequency `ω₀ = √(m g d / J_pivot)`, rad/s.
    pub fn omega(&self) -> f64 {
        (self.mass * self.gravity * self.arm / self.pivot_inertia()).sqrt()
    }

    /// `[φ̇, φ̈]` at `[φ, φ̇]`: the equation of motion as a first-order system.
    pub fn rate(&self, y: &[f64; 2]) -> [f64; 2] {
        let w = self.omega();
        [y[1], -w * w * y[0].sin()]
    }

    /// Kinetic plus potential energy (zero hanging at rest), kg·mm²/s².
    pub fn energy(&self, y: &[f64; 2]) -> f64 {
        0.5 * self.pivot_inertia() * y[1] * y[1]
            + self.mass * self.gravity * self.arm * (1.0 - y[0].cos())
    }

    /// `[φ, φ̇]` at `t` of the linearised motion `φ̈ = −ω₀² φ` from `[φ₀, φ̇₀]` at 0.
    pub fn harmonic(&self, start: [f64; 2], t: f64) -> [f64; 2] {
        let w = self.omega();
        let (s, c) = (w * t).sin_cos();
        [
            start[0] * c + start[1] / w * s,
            -start[0] * w * s + start[1] * c,
        ]
    }

    /// The period of the swing of amplitude `amplitude` (released from rest there, below π),
    /// `4 K(sin(φ₀/2)) / ω₀`, s.
    pub fn period(&self, amplitude: f64) -> f64 {
        4.0 * elliptic_k((amplitude / 2.0).sin()) / self.omega()
    }

    /// The exact `φ(t)` released from rest at `amplitude` (below π) at `t = 0`:
    /// `sin(φ/2) = k sn(K − ω₀ t, k)`, `k = sin(φ₀/2)`.
    pub fn exact_from_rest(&self, amplitude: f64, t: f64) -> f64 {
        let k = (amplitude / 2.0).sin();
        2.0 * (k * jacobi_sn(elliptic_k(k) - self.omega() * t, k)).asin()
    }
}

/// The arithmetic–geometric mean of `a` and `b` (positive), to round-off.
pub fn agm(mut a: f64, mut b: f64) -> f64 {
    // Quadratic convergence: a handful of rounds from any sane pair; the bound stops a NaN.
    for _ in 0..64 {
        if (a - b).abs() <= 4.0 * f64::EPSILON * a {
            break;
        }
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    0.5 * (a + b)
}

/// The complete elliptic integral of the first kind `K(k) = π / (2 AGM(1, √(1 − k²)))`,
/// `0 ≤ k < 1` (modulus `k`, not the parameter `m = k²`).
pub fn elliptic_k(k: f64) -> f64 {
    PI / (2.0 * agm(1.0, (1.0 - k * k).sqrt()))
}

/// Jacobi's elliptic sine `sn(u, k)`, `0 ≤ k < 1`, by the descending Landen (AGM) scheme
/// (Abramowitz & Stegun 16.4.3).
pub fn jacobi_sn(u: f64, k: f64) -> f64 {
    let (mut a, mut b, mut c) = (1.0, (1.0 - k * k).sqrt(), k);
    let mut ratios = [0.0f64; 32];
    let mut n = 0;
    while c.abs() > f64::EPSILON * a && n < ratios.len() {
        (a, b, c) = (0.5 * (a + b), (a * b).sqrt(), 0.5 * (a - b));
        ratios[n] = c / a;
        n += 1;
    }
    let mut phi = 2f64.powi(n as i32) * a * u;
    for ratio in ratios[..n].iter().rev() {
        phi = 0.5 * (phi + (ratio * phi.sin()).asin());
    }
    phi.sin()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::ode::{Ode, Tolerance};

    const PENDULUM: Pendulum = Pendulum {
        mass: 2.0,
        inertia: 5000.0,
        arm: 150.0,
        gravity: 9810.0,
    };

    #[test]
    fn elliptic_functions_match_tabulated_values() {
        // K(0) = π/2; K(sin 45°) = 1.854074677301372 (A&S table 17.1); sn(u, 0) = sin u;
        // sn(K, k) = 1; sn(u, k) for k → 1 is tanh u.
        assert!((elliptic_k(0.0) - PI / 2.0).abs() < 1e-15);
        assert!((elliptic_k(0.5f64.sqrt()) - 1.854_074_677_301_372).abs() < 1e-14);
        assert!((jacobi_sn(0.7, 0.0) - 0.7f64.sin()).abs() < 1e-15);
        for k in [0.1, 0.5, 0.9, 0.99] {
            assert!((jacobi_sn(elliptic_k(k), k) - 1.0).abs() < 1e-14, "{k}");
        }
        let k = (1.0 - 1e-16f64).sqrt();
        assert!((jacobi_sn(0.8, k) - 0.8f64.tanh()).abs() < 1e-7);
    }

    #[test]
    fn small_swings_are_harmonic_and_the_period_tends_to_two_pi_over_omega() {
        let w = PENDULUM.omega();
        let t0 = 2.0 * PI / w;
        let amplitude = 1e-3;
        // The period grows as 1 + φ₀²/16 (the series of K).
        let relative = PENDULUM.period(amplitude) / t0 - 1.0;
        assert!(
            (relative - amplitude * amplitude / 16.0).abs() < 1e-12,
            "{relative:e}"
        );
        // The exact motion departs from the harmonic one by O(φ₀³).
        for t in [0.1, 0.37, 1.0] {
            let exact = PENDULUM.exact_from_rest(amplitude, t);
            let linear = PENDULUM.harmonic([amplitude, 0.0], t)[0];
            assert!((exact - linear).abs() < amplitude.powi(3) * (w * t), "{t}");
        }
    }

    #[test]
    fn the_integrated_swing_matches_the_elliptic_solution_to_1e12() {
        for amplitude in [0.1, 1.0, 2.5, 3.0] {
            let period = PENDULUM.period(amplitude);
            let mut ode = Ode::new(
                |_, y: &[f64; 2]| PENDULUM.rate(y),
                0.0,
                [amplitude, 0.0],
                Tolerance::REFERENCE,
            );
            let mut worst = 0.0f64;
            for i in 1..=60 {
                let t = period * i as f64 / 20.0;
                let phi = ode.advance_to(t).unwrap()[0];
                worst = worst.max((phi - PENDULUM.exact_from_rest(amplitude, t)).abs());
            }
            // After three periods, back at the start, at rest.
            let [phi, rate] = *ode.y();
            eprintln!(
                "pendulum amplitude {amplitude}: worst |φ − φ_exact| {worst:.1e}, \
                 after 3 periods {:.1e}, {:.1e} rad/s",
                phi - amplitude,
                rate
            );
            assert!(worst < 1e-11 * amplitude.max(1.0), "{amplitude}: {worst:e}");
            assert!((phi - amplitude).abs() < 1e-11 && rate.abs() < 1e-11 * PENDULUM.omega());
            let energy = PENDULUM.energy(&[amplitude, 0.0]);
            assert!((PENDULUM.energy(ode.y()) - energy).abs() < 1e-12 * energy);
        }
    }
}
