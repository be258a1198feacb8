//! [`DynamicsError`]: why the integrator could not start or take a step, when, with which step
//! size, naming the scene's terms (its free degrees of freedom by their equations' names).

use core::fmt;

use nalgebra::DefaultAllocator;

use crate::dynamic::{Dynamic, FreeStorage};
use crate::error::SolveError;
use crate::mechanism::Storage;
use crate::names::Names;

/// A failed start or step of the [`crate::Integrator`]: the state it held is kept (a failed step
/// changes nothing), so the caller may change options or the free state and go on.
///
/// Free degrees of freedom are numbered in declaration order; `Display` names each by its
/// equation (the row its `free` declaration adds, which the scene's [`Names`] name), and
/// [`DynamicsError::describe`] by the name the scene gives it ([`Dynamic::free_name`]).
#[derive(Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum DynamicsError {
    /// The kinematic solve failed at a step's iterate: no assembly, a toggle of the coordinate
    /// a free degree of freedom names (the partition is singular there: declare another
    /// coordinate free), a branch flip, a non-finite value.
    Solve {
        /// Time of the step's end.
        t: f64,
        /// Step size (0 at the start).
        step: f64,
        /// The solver's error (named).
        error: SolveError,
    },
    /// The step reached or crossed a singular configuration of the partition (the sign of
    /// det Φ_q changed, `∂q/∂u` grew a thousandfold, or the coordinates' velocities kinked as
    /// on the reflected motion): the coordinates the free degrees of freedom name cannot carry
    /// the mechanism through it (a slider's position at a crank's dead centre: the crank angle
    /// can). Declare another coordinate free.
    Toggle {
        /// Time of the step's end.
        t: f64,
        /// Step size.
        step: f64,
    },
    /// The error-controlled step fell below the minimum size without an accepted step.
    StepTooSmall {
        /// Time the step starts from.
        t: f64,
        /// The step size that was refused.
        step: f64,
        /// The minimum ([`crate::StepControl::Adaptive`]'s `min`).
        min: f64,
    },
    /// The Newton iteration on the free accelerations did not converge within
    /// [`crate::IntegratorOptions::max_iterations`] (after a refresh of its matrix).
    NoConvergence {
        /// Time of the step's end.
        t: f64,
        /// Step size.
        step: f64,
        /// Iterations done.
        iterations: u32,
        /// The last correction, scaled as the tolerance is (see
        /// [`crate::IntegratorOptions::newton_tolerance`]).
        residual: f64,
    },
    /// The reduced mass `VᵀMV` (the mass matrix restricted to the motions the free degrees of
    /// freedom allow) is not positive definite: free degree of freedom `free` moves nothing
    /// that has mass or inertia (or only what the ones before it move).
    SingularMass {
        /// Time.
        t: f64,
        /// The free degree of freedom (declaration order).
        free: usize,
        /// Its equation (Φ order).
        equation: usize,
        /// The scene's names.
        #[cfg_attr(feature = "serde", serde(skip))]
        names: &'static Names,
    },
    /// A free degree of freedom's state or its equation's residual became NaN or infinite.
    NonFinite {
        /// Time of the step's end.
        t: f64,
        /// Step size.
        step: f64,
        /// The free degree of freedom, when one is to blame.
        free: Option<usize>,
    },
    /// The step is below what the clock resolves at `t`: `t + step` rounds to a time more than
    /// a hundredth of the step away from it (far from t = 0 the floating-point spacing of
    /// times grows; at worst the clock would stand still).
    StepBelowClock {
        /// Time the step starts from.
        t: f64,
        /// The step size that was refused.
        step: f64,
    },
    /// One call ([`crate::Integrator::step_to`], [`crate::Integrator::run`]) took
    /// [`crate::IntegratorOptions::max_steps`] steps without reaching its time.
    StepBudget {
        /// Time reached.
        t: f64,
        /// The steps taken in the call.
        steps: u64,
    },
    /// An option, a free state or a target time that is not usable (non-finite, out of range,
    /// a time behind the integrator's): `option` names it.
    BadOptions {
        /// Which option (`rho_inf`, `step`, `rtol`, …, `value`, `rate`, `free`, `t`).
        option: &'static str,
        /// The value refused.
        value: f64,
    },
}

impl DynamicsError {
    /// The time of the failure (`None` for bad options).
    pub fn time(&self) -> Option<f64> {
        match *self {
            Self::Solve { t, .. }
            | Self::StepTooSmall { t, .. }
            | Self::Toggle { t, .. }
            | Self::NoConvergence { t, .. }
            | Self::SingularMass { t, .. }
            | Self::NonFinite { t, .. }
            | Self::StepBelowClock { t, .. }
            | Self::StepBudget { t, .. } => Some(t),
            Self::BadOptions { .. } => None,
        }
    }

    /// Displays the error with `mechanism`'s names: its free degrees of freedom by name, and a
    /// kinematic failure as [`SolveError::describe`] does.
    pub fn describe<'a, M: Dynamic>(&'a self, mechanism: &'a M) -> DescribedDynamics<'a, M>
    where
        DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
    {
        DescribedDynamics {
            error: self,
            mechanism,
        }
    }

    /// Writes the message, naming free degree of freedom `k` with `free`. One arm per
    /// variant, the messages side by side (long, but one phase).
    fn write(
        &self,
        f: &mut fmt::Formatter<'_>,
        free: &dyn Fn(&mut fmt::Formatter<'_>, usize) -> fmt::Result,
    ) -> fmt::Result {
        match *self {
            Self::Solve { t, step, ref error } => {
                write!(f, "the step to t = {t} (h = {step:e}) failed: {error}")
            }
            Self::Toggle { t, step } => write!(
                f,
                "the step to t = {t} (h = {step:e}) reaches a singular configuration of the \
                 free coordinates (a toggle of the partition, where they stall while the \
                 mechanism moves on): they cannot carry the mechanism through it; declare \
                 another coordinate free"
            ),
            Self::StepTooSmall { t, step, min } => write!(
                f,
                "at t = {t} the error-controlled step fell to {step:e}, below the minimum \
                 {min:e}: loosen rtol/atol, lower the minimum, or look for a stiff or \
                 discontinuous force"
            ),
            Self::NoConvergence {
                t,
                step,
                iterations,
                residual,
            } => write!(
                f,
                "the Newton iteration of the step to t = {t} (h = {step:e}) did not converge in \
                 {iterations} iterations (last scaled correction {residual:e}): take a smaller \
                 step (or, if the corrections were still shrinking, raise max_iterations)"
            ),
            Self::SingularMass { t, free: k, .. } => {
                write!(f, "at t = {t} free degree of freedom ")?;
                free(f, k)?;
                f.write_str(
                    " moves no mass or inertia (the reduced mass is not positive definite): \
                     give the bodies it moves mass, or declare another coordinate free",
                )
            }
            Self::NonFinite { t, step, free: k } => {
                write!(
                    f,
                    "the step to t = {t} (h = {step:e}) gave a NaN or infinite "
                )?;
                match k {
                    Some(k) => {
                        f.write_str("value of free degree of freedom ")?;
                        free(f, k)
                    }
                    None => f.write_str("value"),
                }
            }
            Self::StepBelowClock { t, step } => write!(
                f,
                "at t = {t} a step of {step:e} is below what the time's floating-point spacing \
                 resolves (t + h would round by more than a hundredth of h): take larger steps, \
                 or start the run nearer t = 0"
            ),
            Self::StepBudget { t, steps } => write!(
                f,
                "{steps} steps reached t = {t} only, short of the time asked for: raise \
                 max_steps, loosen rtol/atol, or ask for a nearer time"
            ),
            Self::BadOptions { option, value } => {
                write!(f, "integrator option `{option}` cannot be {value}")?;
                f.write_str(match option {
                    "rho_inf" => " (it must be in [0, 1])",
                    "t" => " (a finite time not before the integrator's)",
                    "free" => " (no such free degree of freedom)",
                    _ => " (it must be finite and positive)",
                })
            }
        }
    }

    /// The equation of free degree of freedom `k`, when the error carries it.
    fn free_equation(&self) -> Option<(usize, &'static Names)> {
        match *self {
            Self::SingularMass {
                equation, names, ..
            } => Some((equation, names)),
            _ => None,
        }
    }
}

impl fmt::Display for DynamicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let named = self.free_equation();
        self.write(f, &|f, k| match named.and_then(|(e, n)| n.equation(e)) {
            Some(name) => write!(f, "`{name}`"),
            None => write!(f, "#{k}"),
        })
    }
}

impl fmt::Debug for DynamicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "DynamicsError({self})")
    }
}

impl core::error::Error for DynamicsError {}

/// A [`DynamicsError`] displayed with a mechanism's names ([`DynamicsError::describe`]).
pub struct DescribedDynamics<'a, M> {
    error: &'a DynamicsError,
    mechanism: &'a M,
}

impl<M: Dynamic> fmt::Display for DescribedDynamics<'_, M>
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let m = self.mechanism;
        if let DynamicsError::Solve { t, step, error } = self.error {
            return write!(
                f,
                "the step to t = {t} (h = {step:e}) failed: {}",
                error.describe(m)
            );
        }
        self.error.write(f, &|f, k| match m.free_name(k) {
            Some(name) => write!(f, "`{name}`"),
            None => write!(f, "#{k}"),
        })
    }
}
