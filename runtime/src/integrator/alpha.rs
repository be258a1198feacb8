//! Generalized-α (Chung & Hulbert 1993) in the form Arnold & Brüls (2007) use for constrained
//! systems: the equations of motion hold exactly at every step's end, and the numerical damping
//! lives in an auxiliary acceleration-like sequence `a`,
//!
//! ```text
//! (1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) ü_{n+1} + α_f ü_n
//! u_{n+1} = u_n + h u̇_n + h² ((½ − β) a_n + β a_{n+1})
//! u̇_{n+1} = u̇_n + h ((1 − γ) a_n + γ a_{n+1})
//! ```
//!
//! with the coefficients from the spectral radius at infinity ρ∞ (1: no damping, the
//! trapezoidal rule; 0: asymptotic annihilation of the highest frequencies in one step). The
//! unknown of a step is `ü_{n+1}`; everything else follows from it.

use nalgebra::{DefaultAllocator, Dim, OVector, U1};

use crate::mechanism::Storage;

/// The method's coefficients for one ρ∞.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Alpha {
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub gamma: f64,
    pub beta: f64,
}

impl Alpha {
    /// The second-order, optimally dissipative choice for `rho` in [0, 1]: α_m = (2ρ∞ − 1) /
    /// (ρ∞ + 1), α_f = ρ∞ / (ρ∞ + 1), γ = ½ + α_f − α_m, β = ¼ (γ + ½)².
    pub fn new(rho: f64) -> Self {
        let alpha_m = (2.0 * rho - 1.0) / (rho + 1.0);
        let alpha_f = rho / (rho + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        let beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
        Self {
            alpha_m,
            alpha_f,
            gamma,
            beta,
        }
    }

    /// `∂a_{n+1} / ∂ü_{n+1} = (1 − α_f) / (1 − α_m)` (α_m ≤ ½, so never a division by 0).
    pub fn gain(&self) -> f64 {
        (1.0 - self.alpha_f) / (1.0 - self.alpha_m)
    }

    /// `∂u_{n+1}/∂ü_{n+1}` and `∂u̇_{n+1}/∂ü_{n+1}` at step `h`: the factors of the stiffness
    /// and damping in the iteration matrix.
    pub fn derivatives(&self, h: f64) -> (f64, f64) {
        let gain = self.gain();
        (h * h * self.beta * gain, h * self.gamma * gain)
    }

    /// The constant `C` of the local error of `u`, `C h³ u⃛`, so that
    /// `C h² (ü_{n+1} − ü_n)` estimates it.
    ///
    /// `a_n` tracks `ü(t_n + (α_m − α_f) h)` to second order (Arnold & Brüls 2007), so Taylor
    /// expansion of the position update gives `C = β − γ/2 + 1/12`. For Newmark (α_m = α_f = 0,
    /// γ = ½) this is Zienkiewicz & Xie's (1991) `β − 1/6`; it is 1/12 at ρ∞ = 1 (the
    /// trapezoidal rule), 0.084 at ρ∞ = 0.9 and 1/3 at ρ∞ = 0.
    pub fn error_constant(&self) -> f64 {
        self.beta - 0.5 * self.gamma + 1.0 / 12.0
    }
}

/// The free degrees of freedom's state: values, rates, accelerations (those that satisfy the
/// equations of motion) and the method's acceleration-like sequence.
#[derive(Debug, Clone)]
pub(crate) struct FreeMotion<F: Dim>
where
    DefaultAllocator: Storage<F>,
{
    pub u: OVector<f64, F>,
    pub ud: OVector<f64, F>,
    pub udd: OVector<f64, F>,
    pub a: OVector<f64, F>,
}

impl<F: Dim> FreeMotion<F>
where
    DefaultAllocator: Storage<F>,
{
    /// Zeros for `f` free degrees of freedom.
    pub fn new(f: F) -> Self {
        let zeros = || OVector::zeros_generic(f, U1);
        Self {
            u: zeros(),
            ud: zeros(),
            udd: zeros(),
            a: zeros(),
        }
    }

    /// Copies `other` without allocating.
    pub fn copy_from(&mut self, other: &Self) {
        self.u.copy_from(&other.u);
        self.ud.copy_from(&other.ud);
        self.udd.copy_from(&other.udd);
        self.a.copy_from(&other.a);
    }

    /// `[u, u̇, ü]` of degree of freedom `k`.
    pub fn of(&self, k: usize) -> [f64; 3] {
        [self.u[k], self.ud[k], self.udd[k]]
    }

    /// The state at the end of a step of size `h` from `from` whose accelerations are
    /// `self.udd` (the Newton iterate): fills `a`, `u` and `u̇`.
    pub fn advance(&mut self, from: &Self, alpha: &Alpha, h: f64) {
        let Alpha {
            alpha_m,
            alpha_f,
            gamma,
            beta,
        } = *alpha;
        for k in 0..self.u.len() {
            let a0 = from.a[k];
            let a = (alpha_f * from.udd[k] + (1.0 - alpha_f) * self.udd[k] - alpha_m * a0)
                / (1.0 - alpha_m);
            self.a[k] = a;
            self.u[k] = from.u[k] + h * from.ud[k] + h * h * ((0.5 - beta) * a0 + beta * a);
            self.ud[k] = from.ud[k] + h * ((1.0 - gamma) * a0 + gamma * a);
        }
    }

    /// Whether every value is finite; otherwise the first degree of freedom that is not.
    pub fn first_non_finite(&self) -> Option<usize> {
        (0..self.u.len()).find(|&k| {
            !(self.u[k].is_finite()
                && self.ud[k].is_finite()
                && self.udd[k].is_finite()
                && self.a[k].is_finite())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficients_match_the_published_limits() {
        // ρ∞ = 1: the trapezoidal rule (Newmark γ = ½, β = ¼), α_m = α_f = ½.
        let a = Alpha::new(1.0);
        assert_eq!(
            (a.alpha_m, a.alpha_f, a.gamma, a.beta),
            (0.5, 0.5, 0.5, 0.25)
        );
        assert!((a.error_constant() - 1.0 / 12.0).abs() < 1e-15);
        // ρ∞ = 0: α_m = −1, α_f = 0, γ = 3/2, β = 1.
        let a = Alpha::new(0.0);
        assert_eq!(
            (a.alpha_m, a.alpha_f, a.gamma, a.beta),
            (-1.0, 0.0, 1.5, 1.0)
        );
        assert!((a.error_constant() - 1.0 / 3.0).abs() < 1e-15);
    }

    /// The amplification matrix of the undamped test equation ü = −ω² u at ωh → ∞ has spectral
    /// radius ρ∞, all three eigenvalues at −ρ∞: the method's defining property, checked from
    /// the update formulas.
    #[test]
    fn every_eigenvalue_at_infinity_is_minus_rho() {
        for rho in [0.0, 0.3, 0.6, 0.9, 1.0] {
            let alpha = Alpha::new(rho);
            let (w, h) = (1.0, 1e6);
            // Columns: the step's image of the unit starting states in the scaled variables
            // (u, h u̇, h² a).
            let mut m = [[0.0; 3]; 3];
            for (j, column) in m.iter_mut().enumerate() {
                let mut from = FreeMotion::new(nalgebra::Const::<1>);
                match j {
                    0 => from.u[0] = 1.0,
                    1 => from.ud[0] = 1.0 / h,
                    _ => from.a[0] = 1.0 / (h * h),
                }
                // ü_n on the equation of motion: −ω² u_n.
                from.udd[0] = -w * w * from.u[0];
                // Linear in ü_{n+1}: solve ü = −ω² u(ü) from two evaluations.
                let mut to = FreeMotion::new(nalgebra::Const::<1>);
                let residual = |to: &mut FreeMotion<nalgebra::Const<1>>, x: f64| {
                    to.udd[0] = x;
                    to.advance(&from, &alpha, h);
                    x + w * w * to.u[0]
                };
                let r0 = residual(&mut to, 0.0);
                let r1 = residual(&mut to, 1.0);
                let x = -r0 / (r1 - r0);
                residual(&mut to, x);
                *column = [to.u[0], to.ud[0] * h, to.a[0] * h * h];
            }
            // At infinity the three eigenvalues coincide at −ρ∞ (Chung & Hulbert's optimal
            // choice): the characteristic polynomial is (λ + ρ∞)³, so the trace, the sum of
            // the principal 2 × 2 minors and the determinant are −3ρ∞, 3ρ∞², −ρ∞³.
            let trace = m[0][0] + m[1][1] + m[2][2];
            let minor = |i: usize, j: usize| m[i][i] * m[j][j] - m[i][j] * m[j][i];
            let minors = minor(0, 1) + minor(0, 2) + minor(1, 2);
            let det = m[0][0] * minor(1, 2) - m[1][0] * (m[0][1] * m[2][2] - m[0][2] * m[2][1])
                + m[2][0] * (m[0][1] * m[1][2] - m[0][2] * m[1][1]);
            let expected = [-3.0 * rho, 3.0 * rho * rho, -rho * rho * rho];
            for (found, expected) in [trace, minors, det].into_iter().zip(expected) {
                assert!(
                    (found - expected).abs() < 1e-4,
                    "ρ∞ = {rho}: {found} vs {expected}"
                );
            }
        }
    }

    /// The local error of `u` over one step from exact data of the oscillator `u = cos t`
    /// (with `a_n` the exact acceleration at `t_n + (α_m − α_f) h`, where the method's `a`
    /// lives) is `C h³ u⃛`, with the constant of [`Alpha::error_constant`].
    #[test]
    fn the_error_constant_is_the_local_error_of_u() {
        for rho in [0.0, 0.5, 0.9, 1.0] {
            let alpha = Alpha::new(rho);
            let shift = alpha.alpha_m - alpha.alpha_f;
            let t0 = 0.7;
            let mut ratios = [0.0; 2];
            for (ratio, h) in ratios.iter_mut().zip([1e-2, 5e-3]) {
                let mut from = FreeMotion::new(nalgebra::Const::<1>);
                from.u[0] = libm::cos(t0);
                from.ud[0] = -libm::sin(t0);
                from.udd[0] = -libm::cos(t0);
                from.a[0] = -libm::cos(t0 + shift * h);
                // ü_{n+1} exact: the local error is the update's alone.
                let mut to = FreeMotion::new(nalgebra::Const::<1>);
                to.udd[0] = -libm::cos(t0 + h);
                to.advance(&from, &alpha, h);
                let error = to.u[0] - libm::cos(t0 + h);
                // u⃛ = sin t.
                *ratio = error / (alpha.error_constant() * h * h * h * libm::sin(t0));
            }
            for ratio in ratios {
                assert!((ratio - 1.0).abs() < 0.05, "ρ∞ = {rho}: {ratios:?}");
            }
        }
    }
}
