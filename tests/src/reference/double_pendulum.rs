//! The double pendulum of two rigid bars in reduced coordinates (the bars' absolute angles),
//! its Lagrange equations written out by hand: the reference the forward dynamics of a
//! two-body, two-free-DOF scene is compared with.
//!
//! Bar 1 turns about the origin; bar 2 about the end of bar 1, `length` from the origin along
//! bar 1's x axis. Each bar's centre of mass is on its x axis, `centre` from its pivot, so with
//! `e(θ) = (cos θ, sin θ)`:
//! `c₁ = a₁ e(θ₁)`, `c₂ = l₁ e(θ₁) + a₂ e(θ₂)`. Then
//! `T = ½ A θ̇₁² + ½ D θ̇₂² + B cos(θ₁ − θ₂) θ̇₁ θ̇₂`, with `A = J₁ + m₁ a₁² + m₂ l₁²`,
//! `D = J₂ + m₂ a₂²`, `B = m₂ l₁ a₂`, and `V = −g · (m₁ c₁ + m₂ c₂)`, so that
//!
//! ```text
//! A θ̈₁ + B cos δ θ̈₂ + B sin δ θ̇₂² = (m₁ a₁ + m₂ l₁) g · e⊥(θ₁)
//! B cos δ θ̈₁ + D θ̈₂ − B sin δ θ̇₁² = m₂ a₂ g · e⊥(θ₂)        δ = θ₁ − θ₂, e⊥ = (−sin, cos)
//! ```

/// One bar: its mass properties and where its centre of mass and its far pivot are.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bar {
    /// Mass, kg.
    pub mass: f64,
    /// Moment of inertia about the centre of mass, kg·mm².
    pub inertia: f64,
    /// Distance from the bar's pivot to its centre of mass along its x axis, mm.
    pub centre: f64,
    /// Distance from the bar's pivot to the next bar's pivot along its x axis, mm (unused for
    /// the last bar).
    pub length: f64,
}

/// Two bars in a chain from a fixed pivot at the origin, under `gravity`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DoublePendulum {
    /// The bar on the fixed pivot.
    pub first: Bar,
    /// The bar on the first bar's end.
    pub second: Bar,
    /// Gravity in world axes, mm/s².
    pub gravity: [f64; 2],
}

impl DoublePendulum {
    /// The constants `A`, `B`, `D` of the kinetic energy.
    fn inertias(&self) -> (f64, f64, f64) {
        let (b1, b2) = (&self.first, &self.second);
        (
            b1.inertia + b1.mass * b1.centre * b1.centre + b2.mass * b1.length * b1.length,
            b2.mass * b1.length * b2.centre,
            b2.inertia + b2.mass * b2.centre * b2.centre,
        )
    }

    /// `g · e⊥(θ)`, the rate of `g · e(θ)`.
    fn lever(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        -self.gravity[0] * s + self.gravity[1] * c
    }

    /// `[θ̇₁, θ̇₂, θ̈₁, θ̈₂]` at `[θ₁, θ₂, θ̇₁, θ̇₂]`: the Lagrange equations solved for the
    /// accelerations (the 2×2 mass matrix is positive definite: `AD − B² cos² δ > 0`).
    pub fn rate(&self, y: &[f64; 4]) -> [f64; 4] {
        let [t1, t2, w1, w2] = *y;
        let (a, b, d) = self.inertias();
        let (b1, b2) = (&self.first, &self.second);
        let (sin, cos) = (t1 - t2).sin_cos();
        let q1 = (b1.mass * b1.centre + b2.mass * b1.length) * self.lever(t1) - b * sin * w2 * w2;
        let q2 = b2.mass * b2.centre * self.lever(t2) + b * sin * w1 * w1;
        let (m12, det) = (b * cos, a * d - b * b * cos * cos);
        [w1, w2, (d * q1 - m12 * q2) / det, (a * q2 - m12 * q1) / det]
    }

    /// Kinetic plus gravity potential energy, kg·mm²/s².
    pub fn energy(&self, y: &[f64; 4]) -> f64 {
        let [t1, t2, w1, w2] = *y;
        let (a, b, d) = self.inertias();
        let kinetic = 0.5 * a * w1 * w1 + 0.5 * d * w2 * w2 + b * (t1 - t2).cos() * w1 * w2;
        let [c1, c2] = self.centres(t1, t2);
        let g = self.gravity;
        let height = |c: [f64; 2]| -(g[0] * c[0] + g[1] * c[1]);
        kinetic + self.first.mass * height(c1) + self.second.mass * height(c2)
    }

    /// The two centres of mass in world axes at `(θ₁, θ₂)`, mm.
    pub fn centres(&self, t1: f64, t2: f64) -> [[f64; 2]; 2] {
        let (e1, e2) = (t1.sin_cos(), t2.sin_cos());
        let (a1, l1, a2) = (self.first.centre, self.first.length, self.second.centre);
        [
            [a1 * e1.1, a1 * e1.0],
            [l1 * e1.1 + a2 * e2.1, l1 * e1.0 + a2 * e2.0],
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::ode::{Ode, Tolerance};
    use crate::reference::pendulum::Pendulum;

    const CHAIN: DoublePendulum = DoublePendulum {
        first: Bar {
            mass: 1.0,
            inertia: 3000.0,
            centre: 60.0,
            length: 120.0,
        },
        second: Bar {
            mass: 0.6,
            inertia: 1800.0,
            centre: 50.0,
            length: 100.0,
        },
        gravity: [0.0, -9810.0],
    };

    #[test]
    fn a_chaotic_swing_conserves_its_energy_to_1e12() {
        // Both bars horizontal, released from rest: a large, irregular motion.
        let start = [0.0, 0.3, 0.0, 0.0];
        let mut ode = Ode::new(
            |_, y: &[f64; 4]| CHAIN.rate(y),
            0.0,
            start,
            Tolerance::REFERENCE,
        );
        let energy = CHAIN.energy(&start);
        // The scale of the energies exchanged: the potential drop to hanging.
        let scale = 9810.0 * (1.0 * 60.0 + 0.6 * 170.0);
        let mut worst = 0.0f64;
        for i in 1..=50 {
            let y = ode.advance_to(0.02 * i as f64).unwrap();
            worst = worst.max((CHAIN.energy(&y) - energy).abs() / scale);
        }
        eprintln!("double pendulum, 1 s: energy drift {worst:.1e} (relative)");
        assert!(worst < 1e-12, "{worst:e}");
    }

    #[test]
    fn a_massless_second_bar_leaves_a_simple_pendulum() {
        // m₂ = 0 decouples the bars (B = 0); a small J₂ keeps the mass matrix regular.
        let mut chain = CHAIN;
        chain.second.mass = 0.0;
        chain.second.inertia = 1.0;
        let single = Pendulum {
            mass: 1.0,
            inertia: 3000.0,
            arm: 60.0,
            gravity: 9810.0,
        };
        for theta in [-1.2, -0.3, 0.4] {
            let phi = theta + std::f64::consts::FRAC_PI_2;
            let rate = chain.rate(&[theta, 0.7, 1.1, -0.4]);
            let reference = single.rate(&[phi, 1.1]);
            assert!((rate[2] - reference[1]).abs() < 1e-12 * reference[1].abs().max(1.0));
        }
    }

    #[test]
    fn the_equations_are_the_lagrangian_s_by_finite_differences() {
        // d/dt ∂T/∂θ̇ − ∂T/∂θ + ∂V/∂θ = 0 along the solution, the derivatives by central
        // differences of the energy expressions alone (independent of `rate`'s algebra).
        let y = [0.4, -0.9, 1.3, -2.1];
        let r = CHAIN.rate(&y);
        let (a, b, d) = CHAIN.inertias();
        let momenta = |y: &[f64; 4]| {
            let c = (y[0] - y[1]).cos();
            [a * y[2] + b * c * y[3], d * y[3] + b * c * y[2]]
        };
        let h = 1e-5;
        let shift = |s: f64| std::array::from_fn::<f64, 4, _>(|i| y[i] + s * r[i]);
        let (p_next, p_prev) = (momenta(&shift(h)), momenta(&shift(-h)));
        // ∂L/∂θ_k with the rates held: L = T − V = (kinetic − potential), by energy pieces.
        let lagrangian = |y: &[f64; 4]| {
            let kinetic = {
                let (w1, w2) = (y[2], y[3]);
                0.5 * a * w1 * w1 + 0.5 * d * w2 * w2 + b * (y[0] - y[1]).cos() * w1 * w2
            };
            2.0 * kinetic - CHAIN.energy(y)
        };
        for k in 0..2 {
            let dp = (p_next[k] - p_prev[k]) / (2.0 * h);
            let mut up = y;
            let mut down = y;
            up[k] += h;
            down[k] -= h;
            let dl = (lagrangian(&up) - lagrangian(&down)) / (2.0 * h);
            assert!(
                (dp - dl).abs() < 1e-5 * dp.abs().max(1e3),
                "{k}: {dp} vs {dl}"
            );
        }
    }
}
