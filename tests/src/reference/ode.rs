//! An adaptive Dormand–Prince 5(4) integrator for `ẏ = f(t, y)` (Dormand & Prince 1980; the
//! pair and the step control of Hairer, Nørsett & Wanner, *Solving ODEs I*, II.4–5), landing
//! exactly on requested times: the reference solutions the forward-dynamics tests compare
//! mechgen with are integrated by it to about 1e-12, independently of the runtime.
//!
//! The solution is advanced with compensated (Kahan) summation of the increments, so that the
//! round-off of tens of thousands of tiny steps stays below the tolerance.

use std::fmt;

/// `c`, the stage times.
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];

/// `a`, the stage coefficients, row `i` for stage `i` (lower triangular).
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];

/// The fifth-order weights (the last stage's row: the pair is "first same as last").
const B: [f64; 7] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
    0.0,
];

/// Fifth- minus fourth-order weights: the local error estimate.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Relative and absolute tolerances of one step's local error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
}

impl Tolerance {
    /// What the references use: global errors of about 1e-12 on the smooth problems of the
    /// tests over a few periods (measured in this module's tests).
    pub const REFERENCE: Tolerance = Tolerance {
        rtol: 1e-14,
        atol: 1e-16,
    };
}

/// Why an integration stopped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OdeError {
    /// The right-hand side or the state became non-finite at `t`.
    NonFinite {
        /// Time of the last accepted state.
        t: f64,
    },
    /// The step needed fell below round-off of `t` (a singularity of the equations).
    StepTooSmall {
        /// Time of the last accepted state.
        t: f64,
        /// The step the control asked for.
        step: f64,
    },
    /// More than [`Ode::MAX_STEPS`] steps for one call.
    TooManySteps {
        /// Time of the last accepted state.
        t: f64,
    },
}

impl fmt::Display for OdeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OdeError::NonFinite { t } => write!(f, "non-finite state or rate after t = {t}"),
            OdeError::StepTooSmall { t, step } => {
                write!(f, "step {step:e} below round-off at t = {t}")
            }
            OdeError::TooManySteps { t } => write!(f, "too many steps, stopped at t = {t}"),
        }
    }
}

impl std::error::Error for OdeError {}

/// An initial value problem `ẏ = f(t, y)`, `y(t₀) = y₀`, being integrated.
pub struct Ode<const N: usize, F: Fn(f64, &[f64; N]) -> [f64; N]> {
    f: F,
    t: f64,
    y: [f64; N],
    /// Compensation of the Kahan sums of `y`.
    carry: [f64; N],
    /// `f(t, y)` (the pair is FSAL: the last stage of a step is the next one's first).
    rate: [f64; N],
    /// The step the control proposes next (not shortened by a landing).
    step: f64,
    tolerance: Tolerance,
    accepted: usize,
    rejected: usize,
}

impl<const N: usize, F: Fn(f64, &[f64; N]) -> [f64; N]> Ode<N, F> {
    /// Steps one call of [`Ode::advance_to`] may take.
    pub const MAX_STEPS: usize = 10_000_000;

    /// The problem `ẏ = f(t, y)` from `(t0, y0)`, integrated to `tolerance`.
    pub fn new(f: F, t0: f64, y0: [f64; N], tolerance: Tolerance) -> Self {
        let rate = f(t0, &y0);
        // A first step whose Euler increment is about the tolerance (fifth root: the order).
        let scale = y0
            .iter()
            .zip(&rate)
            .map(|(y, r)| r.abs() / (tolerance.atol + tolerance.rtol * y.abs()))
            .fold(0.0, f64::max);
        let step = if scale > 0.0 {
            (1.0 / scale).powf(0.2).min(1.0) * 0.1
        } else {
            1e-3
        };
        Self {
            f,
            t: t0,
            y: y0,
            carry: [0.0; N],
            rate,
            step,
            tolerance,
            accepted: 0,
            rejected: 0,
        }
    }

    /// Time of the current state.
    pub fn t(&self) -> f64 {
        self.t
    }

    /// The current state.
    pub fn y(&self) -> &[f64; N] {
        &self.y
    }

    /// Accepted and rejected steps so far.
    pub fn steps(&self) -> (usize, usize) {
        (self.accepted, self.rejected)
    }

    /// Integrates to `t_end` (not before the current time), landing on it exactly, and returns
    /// the state there.
    ///
    /// # Errors
    /// [`OdeError`] if the state becomes non-finite, the step underflows or the call takes
    /// more than [`Ode::MAX_STEPS`] steps; the state stays at the last accepted step.
    pub fn advance_to(&mut self, t_end: f64) -> Result<[f64; N], OdeError> {
        for _ in 0..Self::MAX_STEPS {
            let remaining = t_end - self.t;
            if remaining <= 0.0 {
                return Ok(self.y);
            }
            // Land on t_end: take the rest when it is within a step (or a bit more).
            let h = if remaining <= 1.1 * self.step {
                remaining
            } else {
                self.step
            };
            if self.t + h == self.t {
                return Err(OdeError::StepTooSmall { t: self.t, step: h });
            }
            self.attempt(h, h == remaining, t_end)?;
        }
        Err(OdeError::TooManySteps { t: self.t })
    }

    /// One attempted step of size `h`: accepted (state advanced) or rejected (step reduced).
    fn attempt(&mut self, h: f64, landing: bool, t_end: f64) -> Result<(), OdeError> {
        let (increment, error, last_rate) = self.stages(h);
        if !error.is_finite() || increment.iter().any(|d| !d.is_finite()) {
            // Most often a step too large for the equations: retry smaller, then give up.
            if h < 1e-14 * self.t.abs().max(1.0) {
                return Err(OdeError::NonFinite { t: self.t });
            }
            self.step = h * 0.1;
            self.rejected += 1;
            return Ok(());
        }
        let factor = if error == 0.0 {
            5.0
        } else {
            (0.9 * error.powf(-0.2)).clamp(0.2, 5.0)
        };
        if error <= 1.0 {
            for ((y, c), d) in self.y.iter_mut().zip(&mut self.carry).zip(&increment) {
                let corrected = d - *c;
                let sum = *y + corrected;
                *c = (sum - *y) - corrected;
                *y = sum;
            }
            self.t = if landing { t_end } else { self.t + h };
            self.rate = last_rate;
            self.accepted += 1;
            // A landing step shorter than proposed does not shrink the next one.
            self.step = if landing && h < self.step {
                self.step.max(h * factor)
            } else {
                h * factor
            };
        } else {
            self.rejected += 1;
            self.step = h * factor.min(1.0);
        }
        Ok(())
    }

    /// The seven stages of one step of size `h`: the increment `y₁ − y₀`, the scaled error
    /// norm (≤ 1 accepts) and `f(t + h, y₁)`.
    fn stages(&self, h: f64) -> ([f64; N], f64, [f64; N]) {
        let mut k = [[0.0; N]; 7];
        k[0] = self.rate;
        for s in 1..7 {
            let mut y = self.y;
            for (i, yi) in y.iter_mut().enumerate() {
                *yi += h * (0..s).map(|j| A[s][j] * k[j][i]).sum::<f64>();
            }
            k[s] = (self.f)(self.t + C[s] * h, &y);
        }
        let combine = |weights: &[f64; 7], i: usize| {
            h * weights.iter().zip(&k).map(|(w, ks)| w * ks[i]).sum::<f64>()
        };
        let increment: [f64; N] = std::array::from_fn(|i| combine(&B, i));
        let mut sum = 0.0;
        for (i, (y, d)) in self.y.iter().zip(&increment).enumerate() {
            let scale = self.tolerance.atol + self.tolerance.rtol * y.abs().max((y + d).abs());
            sum += (combine(&E, i) / scale).powi(2);
        }
        let error = (sum / N as f64).sqrt();
        (increment, error, k[6])
    }
}

/// The solution of `ẏ = f(t, y)`, `y(t0) = y0` at each of `times` (increasing, from `t0`),
/// integrated to `tolerance`.
///
/// # Errors
/// As [`Ode::advance_to`].
pub fn sample<const N: usize>(
    f: impl Fn(f64, &[f64; N]) -> [f64; N],
    t0: f64,
    y0: [f64; N],
    times: &[f64],
    tolerance: Tolerance,
) -> Result<Vec<[f64; N]>, OdeError> {
    let mut ode = Ode::new(f, t0, y0, tolerance);
    times.iter().map(|&t| ode.advance_to(t)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Largest difference of two sequences of states.
    fn worst<const N: usize>(a: &[[f64; N]], b: &[[f64; N]]) -> f64 {
        a.iter()
            .zip(b)
            .flat_map(|(x, y)| x.iter().zip(y).map(|(p, q)| (p - q).abs()))
            .fold(0.0, f64::max)
    }

    #[test]
    fn harmonic_oscillator_to_1e12_over_ten_periods() {
        let w = 3.0;
        let times: Vec<f64> = (1..=100).map(|i| i as f64 * 0.2).collect();
        let solved = sample(
            |_, y: &[f64; 2]| [y[1], -w * w * y[0]],
            0.0,
            [1.0, 0.5],
            &times,
            Tolerance::REFERENCE,
        )
        .unwrap();
        let exact: Vec<[f64; 2]> = times
            .iter()
            .map(|&t| {
                let (s, c) = (w * t).sin_cos();
                [c + 0.5 / w * s, -w * s + 0.5 * c]
            })
            .collect();
        let error = worst(&solved, &exact);
        eprintln!("harmonic oscillator, 9.5 periods: {error:.1e}");
        assert!(error < 1e-12, "{error:e}");
    }

    #[test]
    fn the_error_falls_as_the_fifth_power_of_the_tolerance_allows() {
        // ẏ = y cos t, y = exp(sin t): non-autonomous, non-linear in t.
        let f = |t: f64, y: &[f64; 1]| [y[0] * t.cos()];
        let exact = 3.0f64.sin().exp();
        let errors: Vec<f64> = [1e-6, 1e-9, 1e-12]
            .iter()
            .map(|&rtol| {
                let tol = Tolerance { rtol, atol: rtol };
                let y = sample(f, 0.0, [1.0], &[3.0], tol).unwrap()[0][0];
                (y - exact).abs()
            })
            .collect();
        eprintln!("exp(sin t) at t = 3 for rtol 1e-6, 1e-9, 1e-12: {errors:?}");
        assert!(errors[0] < 1e-5 && errors[1] < 1e-8 && errors[2] < 2e-12);
        assert!(errors[2] < errors[1] && errors[1] < errors[0]);
    }

    #[test]
    fn lands_exactly_on_requested_times_and_counts_steps() {
        let mut ode = Ode::new(|_, y: &[f64; 1]| [-y[0]], 0.0, [1.0], Tolerance::REFERENCE);
        for t in [0.1, 0.1 + 1e-9, 0.7, 2.0] {
            ode.advance_to(t).unwrap();
            assert_eq!(ode.t(), t);
            assert!((ode.y()[0] - (-t).exp()).abs() < 1e-14);
        }
        // A time before the current one is already reached.
        assert_eq!(ode.advance_to(1.0).unwrap(), *ode.y());
        let (accepted, _) = ode.steps();
        assert!(accepted > 10, "{accepted}");
    }

    #[test]
    fn a_blow_up_is_an_error_not_a_nan() {
        // ẏ = y², y(0) = 1: y = 1/(1 − t) blows up at t = 1.
        let result = sample(
            |_, y: &[f64; 1]| [y[0] * y[0]],
            0.0,
            [1.0],
            &[2.0],
            Tolerance::REFERENCE,
        );
        match result {
            Err(OdeError::StepTooSmall { t, .. } | OdeError::NonFinite { t }) => {
                assert!(t < 1.0 && t > 0.99, "{t}")
            }
            other => panic!("{other:?}"),
        }
    }
}
