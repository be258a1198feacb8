//! The integrator's options: fixed or error-controlled steps, ρ∞, the Newton iteration's limits,
//! and their checks.

use super::error::DynamicsError;

/// How the integrator chooses its steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepControl {
    /// Every step of size `step` (the last one before a requested time shorter, to land on it).
    Fixed {
        /// Step size (s).
        step: f64,
    },
    /// Steps sized so that the estimated local error each step adds to every free
    /// coordinate stays below `(atol + rtol·|u|)` per second of simulated time (in the
    /// coordinate's units: radians, scene lengths): the error after T seconds is then about
    /// T × the tolerance.
    Adaptive {
        /// Relative tolerance.
        rtol: f64,
        /// Absolute tolerance.
        atol: f64,
        /// The first step.
        initial: f64,
        /// The smallest step tried before [`DynamicsError::StepTooSmall`].
        min: f64,
        /// The largest step (may be infinite).
        max: f64,
    },
}

impl Default for StepControl {
    /// Error-controlled: `rtol` 1e-6, `atol` 1e-9, first step 1e-4, steps from 1e-12 up to
    /// 0.1 (where the error estimate vanishes, at rest or under a constant force, the steps
    /// would otherwise grow without bound and stride over time-dependent loads).
    fn default() -> Self {
        Self::Adaptive {
            rtol: 1e-6,
            atol: 1e-9,
            initial: 1e-4,
            min: 1e-12,
            max: 0.1,
        }
    }
}

/// The integrator's options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntegratorOptions {
    /// Spectral radius at infinity ρ∞ in [0, 1]: 1 keeps every frequency (no numerical
    /// damping, the trapezoidal rule), lower values damp frequencies far above 1/h, 0
    /// annihilates them in one step. Default 0.9.
    pub rho_inf: f64,
    /// Fixed or error-controlled steps (default error-controlled).
    pub control: StepControl,
    /// Newton iterations per step (default 8) before the matrix is refreshed or the step
    /// fails.
    pub max_iterations: u32,
    /// Steps one call to [`crate::Integrator::step_to`] or [`crate::Integrator::run`] may take
    /// before it stops with [`DynamicsError::StepBudget`] (default 10⁷), so that a run whose
    /// tolerance or span asks for more never looks like a hang.
    pub max_steps: u64,
    /// The Newton iteration stops when the correction it would apply changes no free
    /// acceleration by more than this times the largest free acceleration (each in units of
    /// the scene's length scale, or radians; accelerations too small to move the state over
    /// the step count as zero) (default 1e-10).
    pub newton_tolerance: f64,
}

impl Default for IntegratorOptions {
    fn default() -> Self {
        Self {
            rho_inf: 0.9,
            control: StepControl::default(),
            max_iterations: 8,
            max_steps: 10_000_000,
            newton_tolerance: 1e-10,
        }
    }
}

impl IntegratorOptions {
    /// Checks every value.
    ///
    /// # Errors
    /// [`DynamicsError::BadOptions`] naming the first value out of range.
    pub fn check(&self) -> Result<(), DynamicsError> {
        let bad = |option, value| Err(DynamicsError::BadOptions { option, value });
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !(0.0..=1.0).contains(&self.rho_inf) {
            return bad("rho_inf", self.rho_inf);
        }
        if self.max_iterations == 0 {
            return bad("max_iterations", 0.0);
        }
        if self.max_steps == 0 {
            return bad("max_steps", 0.0);
        }
        if !positive(self.newton_tolerance) {
            return bad("newton_tolerance", self.newton_tolerance);
        }
        match self.control {
            StepControl::Fixed { step } if !positive(step) => bad("step", step),
            StepControl::Fixed { .. } => Ok(()),
            StepControl::Adaptive {
                rtol,
                atol,
                initial,
                min,
                max,
            } => {
                let checks = [
                    ("rtol", rtol, rtol.is_finite() && rtol >= 0.0),
                    ("atol", atol, atol.is_finite() && atol >= 0.0),
                    ("atol", atol, atol > 0.0 || rtol > 0.0),
                    ("initial", initial, positive(initial)),
                    ("min", min, positive(min) && min <= initial),
                    ("max", max, max >= initial),
                ];
                match checks.iter().find(|(_, _, ok)| !ok) {
                    Some(&(option, value, _)) => bad(option, value),
                    None => Ok(()),
                }
            }
        }
    }
}
