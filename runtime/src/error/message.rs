//! The messages: each variant's text, named from a [`Lookup`], as `Display` and `Debug` print
//! it and as [`Described`] prints it with a mechanism's names.

use core::fmt;

use super::lookup::{FromMechanism, Lookup, write_name};
use super::quantity::Quantity;
use super::solve_error::SolveError;

use nalgebra::DefaultAllocator;

use crate::mechanism::{Mechanism, Storage};
use crate::physics::Subject;

impl SolveError {
    pub(super) fn write(&self, f: &mut fmt::Formatter<'_>, names: &dyn Lookup) -> fmt::Result {
        // Kept whole: one arm per variant, so that each message reads in one place.
        let equation =
            |f: &mut fmt::Formatter<'_>, index: usize| write_name(f, names.equation(index), index);
        match *self {
            Self::NoConvergence {
                time,
                iterations,
                residual,
                equation: index,
                ..
            } => {
                write!(
                    f,
                    "no convergence at t = {time} after {iterations} Newton iterations \
                     (‖Φ‖∞ = {residual:.3e}, largest in equation "
                )?;
                equation(f, index)?;
                f.write_str(
                    "); not found from this guess: try a smaller time step, or move the \
                     initial guesses of that equation's bodies closer to an assembled pose",
                )
            }
            Self::NoAssembly {
                time,
                iterations,
                residual,
                equation: index,
                ..
            } => {
                write!(
                    f,
                    "the mechanism cannot assemble at t = {time}: after {iterations} iterations \
                     the residual stopped at ‖Φ‖∞ = {residual:.3e}, largest in equation "
                )?;
                equation(f, index)?;
                f.write_str("; check the link lengths and the driver values (can the loop close?)")
            }
            Self::Unresolved {
                time,
                iterations,
                residual,
                equation: index,
                ..
            } => {
                write!(
                    f,
                    "the positions at t = {time} cannot be resolved in double precision: "
                )?;
                // An explicit stage assigns in closed form, without iterations.
                if iterations == 0 {
                    f.write_str("assigned in closed form")?;
                } else {
                    write!(
                        f,
                        "after {iterations} iterations the corrections reached the rounding of \
                         the coordinates"
                    )?;
                }
                write!(
                    f,
                    ", but ‖Φ‖∞ = {residual:.3e} remains, largest in equation "
                )?;
                equation(f, index)?;
                f.write_str(
                    "; a coordinate is too large for its rounding to satisfy the constraints \
                     (an angle of many turns in a guess or a driver, or a position far outside \
                     the scene): reduce angles modulo 2π and keep the coordinates near the \
                     scene's size",
                )
            }
            Self::Singular {
                time,
                equation: index,
                coordinate,
                condition,
                deficiency,
                ..
            } => {
                write!(
                    f,
                    "singular Jacobian at t = {time} (condition estimate {condition:.3e} of the \
                     scaled Φ_q): {deficiency} equation{} depend{} on the others; equation ",
                    if deficiency == 1 { "" } else { "s" },
                    if deficiency == 1 { "s" } else { "" },
                )?;
                equation(f, index)?;
                f.write_str(" leaves coordinate ")?;
                write_name(f, names.coordinate(coordinate), coordinate)?;
                f.write_str(
                    " undetermined (a toggle/dead-point position, or redundant constraints: \
                     remove one of the dependent equations' joints or drivers)",
                )
            }
            Self::BranchFlip {
                time,
                branch,
                value,
                ..
            } => {
                write!(
                    f,
                    "the solution at t = {time} is on another assembly branch: "
                )?;
                Quantity::Branch(branch).write(f, names)?;
                write!(
                    f,
                    " is {value:e} (should be positive); stepping, the motion passes through a \
                     singular position or the step is too coarse; assembling, move the initial \
                     guess towards the declared branch"
                )
            }
            Self::NonFinite {
                time,
                quantity,
                equation: index,
                ..
            } => {
                quantity.write(f, names)?;
                write!(f, " became NaN or infinite at t = {time}")?;
                match quantity {
                    Quantity::SpringEnds(_) => f.write_str(
                        ": its ends coincide, where a spring with a free length or damping has \
                         no direction (give it free length 0 and no damping, or keep its ends \
                         apart)",
                    )?,
                    Quantity::LoadValue(_) => f.write_str(
                        " (check its expression and the parameters it reads for an overflow, a \
                         division by zero or a square root of a negative number at this time)",
                    )?,
                    _ => {}
                }
                if let Some(index) = index {
                    f.write_str(", first in equation ")?;
                    equation(f, index)?;
                    f.write_str(
                        " (check its joint's or driver's expressions for a square root of a \
                         negative number, a logarithm of zero or a division by zero at this time)",
                    )?;
                }
                Ok(())
            }
            Self::Geometry {
                time,
                equation: index,
                parameter,
                value,
                requirement,
                ..
            } => {
                write!(f, "invalid geometry at t = {time}: a value of equation ")?;
                equation(f, index)?;
                write!(f, " is {value:e}, computed from ")?;
                Quantity::Parameter(parameter).write(f, names)?;
                write!(
                    f,
                    "; it is {}: set the parameter to a value the mechanism can be built with",
                    requirement.describe()
                )
            }
            Self::Unreachable {
                time,
                reached,
                steps,
                ..
            } => write!(
                f,
                "the start time t = {time} is out of reach: the `near` guesses describe the \
                 mechanism at t = 0, and {steps} steps of its motion from there reached only \
                 t = {reached}; start nearer t = 0"
            ),
            Self::Physics {
                time,
                subject,
                parameter,
                value,
                requirement,
                ..
            } => {
                write!(f, "invalid physics at t = {time}: a value of ")?;
                match subject {
                    // A body's coordinates are named `body.x`, `body.y`, `body.theta`.
                    Subject::Body(index) => {
                        let name = names.coordinate(3 * index);
                        f.write_str("body ")?;
                        write_name(f, name.map(|x| x.strip_suffix(".x").unwrap_or(x)), index)?;
                    }
                    Subject::Load(index) => {
                        f.write_str("load ")?;
                        write_name(f, names.load(index), index)?;
                    }
                }
                write!(f, " is {value:e}, computed from ")?;
                Quantity::Parameter(parameter).write(f, names)?;
                write!(
                    f,
                    "; it is {}: set the parameter to a physical value",
                    requirement.describe()
                )
            }
            Self::DimensionMismatch {
                expected,
                found,
                names,
            } => {
                write!(f, "vector of length {found} passed to ")?;
                if !names.mechanism.is_empty() {
                    write!(f, "`{}`, ", names.mechanism)?;
                }
                write!(f, "a mechanism of {expected} coordinates (`dim()`)")
            }
        }
    }
}

/// The message with the scene's names (those the error carries).
impl fmt::Display for SolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.write(f, self.names())
    }
}

/// The variant, then the named message: what `unwrap`, `expect` and an error returned from
/// `main` print (`NoAssembly: the mechanism cannot assemble at t = 0: … equation
/// `rocker_pin.x` …`).
impl fmt::Debug for SolveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: ", self.kind())?;
        self.write(f, self.names())
    }
}

/// A [`SolveError`] displayed with names from its mechanism; see [`SolveError::describe`].
pub struct Described<'a, M> {
    pub(crate) error: &'a SolveError,
    pub(crate) mechanism: &'a M,
    /// Every dependent equation of a `Singular` error, when the solver's diagnosis is at hand.
    pub(crate) dependent: &'a [usize],
    /// Every undetermined coordinate of a `Singular` error, likewise.
    pub(crate) undetermined: &'a [usize],
}

impl<M: Mechanism> fmt::Display for Described<'_, M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names = FromMechanism(self.mechanism, self.error.names());
        self.error.write(f, &names)?;
        let lists = [
            ("dependent equations", self.dependent, true),
            ("undetermined coordinates", self.undetermined, false),
        ];
        for (what, indices, equations) in lists {
            if indices.is_empty() {
                continue;
            }
            write!(f, "\n  {what}:")?;
            for &index in indices {
                let name = if equations {
                    names.equation(index)
                } else {
                    names.coordinate(index)
                };
                match name {
                    Some(name) => write!(f, " {name}")?,
                    None => write!(f, " #{index}")?,
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Requirement;
    use crate::names::Names;
    use std::format;
    use std::string::ToString;
    use std::vec::Vec;

    static TABLE: Names = Names {
        mechanism: "Linkage",
        coordinates: &["crank.x", "crank.y", "crank.theta"],
        equations: &["pivot.x", "pivot.y", "spin"],
        parameters: &["omega", "length"],
        branches: &["open"],
        markers: &["tip.x"],
        loads: &["gas"],
    };

    /// One error of every variant (and every quantity that has an index), each with the
    /// names it must show.
    fn every_error() -> Vec<(SolveError, &'static [&'static str])> {
        // Kept whole: a table, one error per variant and per indexed quantity.
        let names = &Names::NONE;
        let non_finite = |quantity, equation| SolveError::NonFinite {
            time: 0.5,
            quantity,
            equation,
            names,
        };
        std::vec![
            (
                SolveError::NoConvergence {
                    time: 0.5,
                    iterations: 25,
                    residual: 1e-3,
                    equation: 0,
                    names,
                },
                &["`pivot.x`"][..],
            ),
            (
                SolveError::Unreachable {
                    time: 3.0,
                    reached: 0.5,
                    steps: 100_000,
                    names,
                },
                &[],
            ),
            (
                SolveError::Physics {
                    time: 0.5,
                    subject: crate::physics::Subject::Body(0),
                    parameter: 1,
                    value: -1.0,
                    requirement: Requirement::Mass,
                    names,
                },
                &["body `crank`", "parameter `length`"],
            ),
            (
                SolveError::Physics {
                    time: 0.5,
                    subject: crate::physics::Subject::Load(0),
                    parameter: 0,
                    value: -1.0,
                    requirement: Requirement::Stiffness,
                    names,
                },
                &["load `gas`", "parameter `omega`"],
            ),
            (
                SolveError::NoAssembly {
                    time: 0.5,
                    iterations: 9,
                    residual: 1.5,
                    equation: 1,
                    names,
                },
                &["`pivot.y`"],
            ),
            (
                SolveError::Unresolved {
                    time: 0.5,
                    iterations: 9,
                    residual: 1e-4,
                    equation: 2,
                    names,
                },
                &["`spin`"],
            ),
            (
                SolveError::Singular {
                    time: 0.5,
                    equation: 2,
                    coordinate: 1,
                    condition: f64::INFINITY,
                    deficiency: 1,
                    names,
                },
                &["equation `spin` leaves coordinate `crank.y`"],
            ),
            (
                SolveError::BranchFlip {
                    time: 0.5,
                    branch: 0,
                    value: -1.0,
                    names,
                },
                &["branch invariant `open`"],
            ),
            (
                non_finite(Quantity::Parameter(1), None),
                &["parameter `length`"]
            ),
            (
                non_finite(Quantity::Branch(0), None),
                &["branch invariant `open`"]
            ),
            (
                non_finite(Quantity::Marker(0), None),
                &["marker value `tip.x`"]
            ),
            (
                non_finite(Quantity::LoadValue(0), None),
                &["the force or moment of load `gas`"]
            ),
            (
                non_finite(Quantity::SpringEnds(0), None),
                &["the force of spring `gas`", "its ends coincide"]
            ),
            (
                non_finite(Quantity::Phi, Some(0)),
                &["first in equation `pivot.x`"]
            ),
            (
                SolveError::Geometry {
                    time: 0.5,
                    equation: 0,
                    parameter: 1,
                    value: -5.0,
                    requirement: Requirement::Distance,
                    names,
                },
                &["equation `pivot.x`", "parameter `length`"],
            ),
            (
                SolveError::DimensionMismatch {
                    expected: 3,
                    found: 2,
                    names,
                },
                &["`Linkage`"],
            ),
        ]
    }

    #[test]
    fn display_and_debug_name_everything_once_named() {
        for (error, expected) in every_error() {
            let named = error.named(&TABLE);
            assert_eq!(named.names(), &TABLE);
            let debug = format!("{named:?}");
            for text in [named.to_string(), debug.clone()] {
                for name in expected {
                    assert!(text.contains(name), "`{name}` missing from: {text}");
                }
                // No bare index: every index the error holds is named.
                assert!(!text.contains('#'), "{text}");
            }
            // Debug leads with the variant, so that `unwrap` and `main` say which one it is.
            assert!(debug.starts_with(named.kind()), "{debug}");
            if let Some(time) = named.time() {
                assert!(debug.contains(&format!("t = {time}")), "{debug}");
            }
            // Unnamed, the same error shows indices.
            assert!(
                error.to_string().contains('#')
                    || expected.is_empty()
                    || expected[0].contains("Linkage")
            );
        }
    }
}
