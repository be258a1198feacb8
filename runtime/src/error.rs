//! Why a solve failed, with indices that [`SolveError::describe`] turns into scene names.

use core::fmt;

use nalgebra::DefaultAllocator;

use crate::mechanism::{Mechanism, Storage};

/// The quantity found to be NaN or infinite.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// The time passed in.
    Time,
    /// The initial guess, or the positions passed to a velocity or acceleration solve.
    Guess,
    /// The constraint vector Φ.
    Phi,
    /// The Jacobian Φ_q.
    Jacobian,
    /// The velocity right-hand side ν.
    Nu,
    /// The acceleration right-hand side γ.
    Gamma,
    /// The Newton step Δq (the iteration is diverging).
    Step,
    /// The velocities q̇ (solved, or passed to an acceleration solve).
    Velocity,
    /// The solved accelerations q̈.
    Acceleration,
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Time => "the time",
            Self::Guess => "the positions q (initial guess)",
            Self::Phi => "the constraints Φ",
            Self::Jacobian => "the Jacobian Φ_q",
            Self::Nu => "the velocity right-hand side ν",
            Self::Gamma => "the acceleration right-hand side γ",
            Self::Step => "the Newton step Δq",
            Self::Velocity => "the velocities q̇",
            Self::Acceleration => "the accelerations q̈",
        })
    }
}

/// A failed position, velocity or acceleration solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SolveError {
    /// Newton–Raphson hit the iteration cap; the mechanism may not be able to assemble at `time`.
    NoConvergence {
        /// Time of the solve.
        time: f64,
        /// Newton updates applied.
        iterations: usize,
        /// ‖Φ‖∞ at the last iterate.
        residual: f64,
    },
    /// Φ_q has no usable pivot: the mechanism is locked, over- or under-constrained here.
    ///
    /// `equation` and `coordinate` are indices; name them with
    /// [`Mechanism::equation_name`] / [`Mechanism::coordinate_name`] or [`SolveError::describe`].
    Singular {
        /// Time of the solve.
        time: f64,
        /// The likeliest redundant or conflicting equation.
        equation: usize,
        /// The coordinate the equations failed to determine.
        coordinate: usize,
        /// Magnitude of the best available pivot.
        pivot: f64,
    },
    /// An input or an evaluated quantity was NaN or infinite.
    NonFinite {
        /// Time of the solve.
        time: f64,
        /// Which quantity.
        quantity: Quantity,
    },
    /// A vector passed in does not have `dim()` entries (only possible with `Dyn` mechanisms).
    DimensionMismatch {
        /// The mechanism's `dim()`.
        expected: usize,
        /// The length passed in.
        found: usize,
    },
}

impl SolveError {
    /// The time at which the solve failed, if the error concerns one.
    pub fn time(&self) -> Option<f64> {
        match *self {
            Self::NoConvergence { time, .. }
            | Self::Singular { time, .. }
            | Self::NonFinite { time, .. } => Some(time),
            Self::DimensionMismatch { .. } => None,
        }
    }

    /// Displays the error with the mechanism's equation and coordinate names instead of indices.
    pub fn describe<'a, M: Mechanism>(&'a self, mechanism: &'a M) -> Described<'a, M>
    where
        DefaultAllocator: Storage<M::Dim>,
    {
        Described {
            error: self,
            mechanism,
        }
    }

    fn write(&self, f: &mut fmt::Formatter<'_>, names: Option<(&str, &str)>) -> fmt::Result {
        match *self {
            Self::NoConvergence {
                time,
                iterations,
                residual,
            } => write!(
                f,
                "no convergence at t = {time} after {iterations} Newton iterations \
                 (‖Φ‖∞ = {residual:e}); the mechanism may not assemble here"
            ),
            Self::Singular {
                time,
                equation,
                coordinate,
                pivot,
            } => {
                write!(f, "singular Jacobian at t = {time}: ")?;
                match names {
                    Some((equation, coordinate)) => {
                        write!(f, "equation {equation} / coordinate {coordinate}")?;
                    }
                    None => write!(
                        f,
                        "equation #{equation} / coordinate #{coordinate} (see \
                         Mechanism::equation_name / coordinate_name)"
                    )?,
                }
                write!(
                    f,
                    " is redundant, conflicting or locked (|pivot| = {pivot:e})"
                )
            }
            Self::NonFinite { time, quantity } => {
                write!(f, "{quantity} became NaN or infinite at t = {time}")
            }
            Self::DimensionMismatch { expected, found } => {
                write!(
                    f,
                    "vector of length {found} passed to a mechanism of dim {expected}"
                )
            }
        }
    }
}

impl fmt::Display for SolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.write(f, None)
    }
}

impl core::error::Error for SolveError {}

/// A [`SolveError`] displayed with names from its mechanism; see [`SolveError::describe`].
pub struct Described<'a, M> {
    error: &'a SolveError,
    mechanism: &'a M,
}

impl<M: Mechanism> fmt::Display for Described<'_, M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names = match *self.error {
            SolveError::Singular {
                equation,
                coordinate,
                ..
            } => self
                .mechanism
                .equation_name(equation)
                .zip(self.mechanism.coordinate_name(coordinate)),
            _ => None,
        };
        self.error.write(f, names)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pendulum::Pendulum;
    use std::string::ToString;

    #[test]
    fn describe_replaces_indices_with_names() {
        let error = SolveError::Singular {
            time: 1.0,
            equation: 2,
            coordinate: 1,
            pivot: 0.0,
        };
        let plain = error.to_string();
        assert!(plain.contains("equation #2 / coordinate #1"), "{plain}");
        let named = error.describe(&Pendulum::default()).to_string();
        assert!(
            named.contains("equation drive / coordinate rod.y"),
            "{named}"
        );
        assert_eq!(error.time(), Some(1.0));
    }
}
