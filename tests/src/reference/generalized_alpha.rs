//! The generalized-α method (Chung & Hulbert 1993, in the form of Arnold & Brüls 2007) on a
//! reduced equation of motion `ü = f(t, u, u̇)` of `N` coordinates, written from the papers
//! and independent of the runtime: with coordinate partitioning the runtime's integrator is
//! this method applied to the same reduced equations (its kinematic solve supplies `f`), so a
//! fixed-step run of a scene equals a run of this on the reduced equations of
//! [`super::seed`], [`super::pendulum`] or [`super::double_pendulum`] up to the solvers'
//! tolerances. The tests use it for that comparison and to calibrate their error bounds.
//!
//! With `ρ∞ ∈ [0, 1]`: `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`, `α_f = ρ∞/(ρ∞ + 1)`,
//! `γ = ½ + α_f − α_m`, `β = ¼ (γ + ½)²`, and one step from `(u, u̇, a, ü)`:
//!
//! ```text
//! (1 − α_m) a₊ = (1 − α_f) ü₊ + α_f ü − α_m a
//! u₊ = u + h u̇ + h² ((½ − β) a + β a₊)
//! u̇₊ = u̇ + h ((1 − γ) a + γ a₊)
//! ü₊ = f(t + h, u₊, u̇₊)                       solved for ü₊ by Newton
//! ```
//!
//! starting from `a = ü = f(t₀, u₀, u̇₀)`.

use std::fmt;

/// Newton iterations per step before giving up.
const MAX_NEWTON: usize = 50;

/// A step whose Newton iteration did not converge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonFailure {
    /// Time of the step's start.
    pub t: f64,
}

impl fmt::Display for NewtonFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Newton did not converge in the step from t = {}", self.t)
    }
}

impl std::error::Error for NewtonFailure {}

/// The method's coefficients for a numerical damping `ρ∞`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Coefficients {
    alpha_m: f64,
    alpha_f: f64,
    gamma: f64,
    beta: f64,
}

impl Coefficients {
    fn new(rho_inf: f64) -> Self {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        Self {
            alpha_m,
            alpha_f,
            gamma,
            beta: 0.25 * (gamma + 0.5) * (gamma + 0.5),
        }
    }
}

/// A reduced equation `ü = f(t, u, u̇)` being integrated by generalized-α.
pub struct GeneralizedAlpha<const N: usize, F: Fn(f64, &[f64; N], &[f64; N]) -> [f64; N]> {
    f: F,
    c: Coefficients,
    t: f64,
    u: [f64; N],
    rate: [f64; N],
    /// The acceleration-like variable `a`.
    a: [f64; N],
    /// The acceleration `ü`.
    accel: [f64; N],
}

impl<const N: usize, F: Fn(f64, &[f64; N], &[f64; N]) -> [f64; N]> GeneralizedAlpha<N, F> {
    /// The problem from `(t0, u0, u̇0)` with numerical damping `rho_inf` (1: none, 0: the most).
    pub fn new(f: F, t0: f64, u0: [f64; N], rate0: [f64; N], rho_inf: f64) -> Self {
        let accel = f(t0, &u0, &rate0);
        Self {
            f,
            c: Coefficients::new(rho_inf),
            t: t0,
            u: u0,
            rate: rate0,
            a: accel,
            accel,
        }
    }

    /// Time of the current state.
    pub fn t(&self) -> f64 {
        self.t
    }

    /// `u`, `u̇`, `ü` now.
    pub fn state(&self) -> [[f64; N]; 3] {
        [self.u, self.rate, self.accel]
    }

    /// `(a₊, u₊, u̇₊)` of a step of size `h` ending at acceleration `x`.
    fn update(&self, x: &[f64; N], h: f64) -> [[f64; N]; 3] {
        let c = &self.c;
        let a: [f64; N] = std::array::from_fn(|i| {
            ((1.0 - c.alpha_f) * x[i] + c.alpha_f * self.accel[i] - c.alpha_m * self.a[i])
                / (1.0 - c.alpha_m)
        });
        let u = std::array::from_fn(|i| {
            self.u[i] + h * self.rate[i] + h * h * ((0.5 - c.beta) * self.a[i] + c.beta * a[i])
        });
        let rate = std::array::from_fn(|i| {
            self.rate[i] + h * ((1.0 - c.gamma) * self.a[i] + c.gamma * a[i])
        });
        [a, u, rate]
    }

    /// `x − f(t + h, u₊(x), u̇₊(x))`, zero at the step's acceleration.
    fn residual(&self, x: &[f64; N], h: f64) -> [f64; N] {
        let [_, u, rate] = self.update(x, h);
        let f = (self.f)(self.t + h, &u, &rate);
        std::array::from_fn(|i| x[i] - f[i])
    }

    /// One step of size `h`.
    ///
    /// # Errors
    /// [`NewtonFailure`] if Newton (with a central-difference Jacobian) does not converge to
    /// round-off of the accelerations (or, with a stiff force, stall at a correction that moves
    /// the positions by round-off), or the state turns non-finite; the state is then unchanged.
    pub fn step(&mut self, h: f64) -> Result<(), NewtonFailure> {
        let mut x = self.accel;
        let mut previous = f64::INFINITY;
        for _ in 0..MAX_NEWTON {
            let r = self.residual(&x, h);
            let dx = solve(self.jacobian(&x, h), r.map(|v| -v));
            // Round-off of the residual scales with the accelerations it combines.
            let size = x
                .iter()
                .chain(&self.accel)
                .chain(&self.a)
                .fold(1.0f64, |m, v| m.max(v.abs()));
            let correction = dx.iter().fold(0.0f64, |m, d| m.max(d.abs()));
            for (xi, d) in x.iter_mut().zip(&dx) {
                *xi += d;
            }
            if !x.iter().all(|v| v.is_finite()) {
                break;
            }
            // With a stiff force the residual's round-off is that of the force (`k ℓ`), far
            // above the accelerations': the corrections then stop shrinking at a floor. Once
            // they do, and they move the positions (by `β h² dx`) by no more than round-off
            // of the coordinates, the iteration is done.
            let positions = self.u.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            let stalled = correction > 0.5 * previous
                && self.c.beta * h * h * correction <= 1e-14 * positions;
            previous = correction;
            if stalled || dx.iter().all(|d| d.abs() <= 1e-13 * size) {
                let [a, u, rate] = self.update(&x, h);
                (self.a, self.u, self.rate, self.accel) = (a, u, rate, x);
                self.t += h;
                return Ok(());
            }
        }
        Err(NewtonFailure { t: self.t })
    }

    /// `∂r/∂x` by central differences.
    fn jacobian(&self, x: &[f64; N], h: f64) -> [[f64; N]; N] {
        let mut j = [[0.0; N]; N];
        for k in 0..N {
            let d = 1e-6 * (1.0 + x[k].abs());
            let (mut up, mut down) = (*x, *x);
            up[k] += d;
            down[k] -= d;
            let (ru, rd) = (self.residual(&up, h), self.residual(&down, h));
            for (i, row) in j.iter_mut().enumerate() {
                row[k] = (ru[i] - rd[i]) / (2.0 * d);
            }
        }
        j
    }
}

/// `A x = b` by Gaussian elimination with partial pivoting (a singular `A` gives non-finite
/// values, which [`GeneralizedAlpha::step`] reports).
fn solve<const N: usize>(mut a: [[f64; N]; N], mut b: [f64; N]) -> [f64; N] {
    for c in 0..N {
        let pivot = (c..N)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap_or(c);
        a.swap(c, pivot);
        b.swap(c, pivot);
        let (head, tail) = a.split_at_mut(c + 1);
        let row = &head[c];
        for (r, lower) in tail.iter_mut().enumerate() {
            let factor = lower[c] / row[c];
            for (x, y) in lower[c..].iter_mut().zip(&row[c..]) {
                *x -= factor * y;
            }
            b[c + 1 + r] -= factor * b[c];
        }
    }
    let mut x = [0.0; N];
    for c in (0..N).rev() {
        let known: f64 = (c + 1..N).map(|k| a[c][k] * x[k]).sum();
        x[c] = (b[c] - known) / a[c][c];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `ü = −ω² u` from `(1, 0)`, `steps` steps of `h` with damping `rho`: the final `u`.
    fn oscillator(w: f64, rho: f64, h: f64, steps: usize) -> [[f64; 1]; 3] {
        let mut m =
            GeneralizedAlpha::new(|_, u: &[f64; 1], _| [-w * w * u[0]], 0.0, [1.0], [0.0], rho);
        for _ in 0..steps {
            m.step(h).unwrap();
        }
        m.state()
    }

    #[test]
    fn second_order_for_every_damping() {
        for rho in [1.0, 0.9, 0.5, 0.0] {
            let errors: Vec<f64> = [400, 800, 1600]
                .iter()
                .map(|&n| (oscillator(2.0, rho, 3.0 / n as f64, n)[0][0] - 6f64.cos()).abs())
                .collect();
            let ratios = [errors[0] / errors[1], errors[1] / errors[2]];
            eprintln!("generalized-α, ρ∞ = {rho}: ratios {ratios:?}");
            for r in ratios {
                assert!((3.8..4.2).contains(&r), "ρ∞ = {rho}: {ratios:?}");
            }
        }
    }

    #[test]
    fn no_damping_at_one_and_the_asymptotic_radius_below() {
        // A mode 1,000 times faster than the step (ωh = 1000): with ρ∞ = 1 it keeps its
        // amplitude (it neither blows up nor decays), with ρ∞ = 0.5 it shrinks by about 0.6 a
        // step (ρ∞ is the limit ωh → ∞), with ρ∞ = 0 it drops to O(1/ωh) at once.
        let amplitude = |rho: f64, steps: usize| {
            let [u, rate, _] = oscillator(1e3, rho, 1.0, steps);
            u[0].abs().max(rate[0].abs() / 1e3)
        };
        assert!(
            (0.5..=1.5).contains(&amplitude(1.0, 200)),
            "{}",
            amplitude(1.0, 200)
        );
        assert!(
            amplitude(0.5, 40) <= 0.7f64.powi(40),
            "{}",
            amplitude(0.5, 40)
        );
        assert!(amplitude(0.0, 3) <= 2e-3, "{}", amplitude(0.0, 3));
        // A resolved mode (ωh = 0.1) over 1,000 periods: undamped with ρ∞ = 1.
        let [u, rate, _] = oscillator(1.0, 1.0, 0.1, 62_832);
        let energy = u[0] * u[0] + rate[0] * rate[0];
        assert!((energy - 1.0).abs() <= 1e-3, "{energy}");
    }

    #[test]
    fn a_coupled_pair_is_solved_as_one() {
        // Two masses, springs 1-2-wall: ü = −K u, modes ω² = (3 ± √5)/2; the fixed-step
        // solution converges to the exact one at second order.
        let f = |_: f64, u: &[f64; 2], _: &[f64; 2]| [-2.0 * u[0] + u[1], u[0] - u[1]];
        let exact = |t: f64| {
            // u(0) = (1, 0): project on the modes v = (1, (2 − ω²)).
            let modes = [(3.0 - 5f64.sqrt()) / 2.0, (3.0 + 5f64.sqrt()) / 2.0];
            let mut u = [0.0; 2];
            let vectors = modes.map(|w2: f64| [1.0, 2.0 - w2]);
            let (p, q) = (vectors[0], vectors[1]);
            let det = p[0] * q[1] - q[0] * p[1];
            let coefficients = [q[1] / det, -p[1] / det];
            for ((w2, v), c) in modes.iter().zip(vectors).zip(coefficients) {
                let cos = (w2.sqrt() * t).cos();
                u[0] += c * v[0] * cos;
                u[1] += c * v[1] * cos;
            }
            u
        };
        let run = |n: usize| {
            let mut m = GeneralizedAlpha::new(f, 0.0, [1.0, 0.0], [0.0, 0.0], 0.8);
            for _ in 0..n {
                m.step(5.0 / n as f64).unwrap();
            }
            let [u, _, _] = m.state();
            let e = exact(5.0);
            (u[0] - e[0]).abs().max((u[1] - e[1]).abs())
        };
        let (coarse, fine) = (run(200), run(400));
        assert!(
            (3.8..4.2).contains(&(coarse / fine)),
            "{coarse:e}, {fine:e}"
        );
        assert!(fine < 1e-3, "{fine:e}");
    }

    #[test]
    fn a_singular_iteration_is_an_error_not_a_nan() {
        // A right-hand side that is NaN: no Newton iterate is finite.
        let mut m = GeneralizedAlpha::new(|_, _: &[f64; 1], _| [f64::NAN], 0.0, [0.0], [0.0], 1.0);
        assert_eq!(m.step(0.1), Err(NewtonFailure { t: 0.0 }));
        assert_eq!(m.t(), 0.0);
    }
}
