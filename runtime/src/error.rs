//! Why a solve failed, with indices that [`SolveError::describe`] turns into scene names.

use core::fmt;

use nalgebra::DefaultAllocator;

use crate::geometry::{GeometryFault, Requirement};
use crate::mechanism::{Mechanism, Storage};
use crate::physics::Subject;

/// The quantity found to be NaN or infinite.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Quantity {
    /// The time passed in.
    Time,
    /// A run-time parameter of the scene (its index).
    Parameter(usize),
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
    /// A branch invariant of the scene (its index).
    Branch(usize),
    /// The generalised applied and inertial forces F of the force solve (a load's expression,
    /// a spring of zero length, an overflowing inertia force).
    Load,
    /// The solved reactions (Lagrange multipliers) of the force solve.
    Reaction,
    /// A marker's value or rate (its index among the marker values).
    Marker(usize),
}

impl Quantity {
    /// Writes the quantity, with `name` for a parameter or branch (its index otherwise).
    fn write(self, f: &mut fmt::Formatter<'_>, name: Option<&str>) -> fmt::Result {
        let text = match self {
            Self::Parameter(index) | Self::Branch(index) | Self::Marker(index) => {
                let what = match self {
                    Self::Parameter(_) => "parameter",
                    Self::Branch(_) => "branch invariant",
                    _ => "marker value",
                };
                return match name {
                    Some(name) => write!(f, "{what} `{name}`"),
                    None => write!(f, "{what} #{index}"),
                };
            }
            Self::Time => "the time",
            Self::Guess => "the positions q (initial guess)",
            Self::Phi => "the constraints Φ",
            Self::Jacobian => "the Jacobian Φ_q",
            Self::Nu => "the velocity right-hand side ν",
            Self::Gamma => "the acceleration right-hand side γ",
            Self::Step => "the Newton step Δq",
            Self::Velocity => "the velocities q̇",
            Self::Acceleration => "the accelerations q̈",
            Self::Load => "the applied and inertial forces F (loads, springs, masses)",
            Self::Reaction => "the reactions (constraint forces and driver efforts)",
        };
        f.write_str(text)
    }
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.write(f, None)
    }
}

/// A failed position, velocity or acceleration solve: what went wrong, and when.
///
/// Indices name equations, coordinates, branches and parameters of the scene; name them with
/// [`SolveError::describe`] (the first equation and coordinate involved) or
/// [`crate::Solver::describe`] (every one). A failed [`crate::Simulation::new`] hands its solver
/// back in a [`crate::AssemblyError`], whose `Display` does this.
///
/// ```
/// # use mechgen_runtime::mechanism;
/// # mechanism! {
/// #     /// Links too short to close: 10 + 20 + 20 cannot span 100.
/// #     pub mechanism Unclosable {
/// #         ground frame at (0, 0, 0);
/// #         body crank near (0, 0, 0);
/// #         body coupler near (10, 0, 0);
/// #         body rocker near (100, 0, 3);
/// #         joint pivot: revolute(frame, crank);
/// #         joint pin: revolute(crank @ (10, 0), coupler);
/// #         joint elbow: revolute(coupler @ (20, 0), rocker @ (20, 0));
/// #         joint rest: revolute(rocker, frame @ (100, 0));
/// #         driver turn: angle(crank) = t;
/// #     }
/// # }
/// use mechgen_runtime::{Simulation, SolveError, Solver};
///
/// let Err(failure) = Simulation::new(Solver::new(Unclosable::default()), 0.0) else {
///     panic!("cannot close");
/// };
/// let SolveError::NoAssembly { residual, .. } = failure.error else {
///     panic!("{failure}");
/// };
/// assert!(residual > 10.0);
/// // Named: "… largest in equation `elbow.x` …" (or another of the loop's equations).
/// assert!(failure.to_string().contains("largest in equation `"));
/// ```
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SolveError {
    /// Newton–Raphson hit the iteration cap while still reducing the residual.
    NoConvergence {
        /// Time of the solve.
        time: f64,
        /// Newton updates applied.
        iterations: usize,
        /// ‖Φ‖∞ at the last iterate.
        residual: f64,
    },
    /// The constraints cannot all be satisfied: the least-squares residual stopped decreasing
    /// well above the tolerance (links too short to close, a driver beyond the reachable range,
    /// inconsistent redundant constraints).
    NoAssembly {
        /// Time of the solve.
        time: f64,
        /// Newton and Levenberg–Marquardt updates applied.
        iterations: usize,
        /// ‖Φ‖∞ at the best point reached.
        residual: f64,
        /// The equation with the largest scaled residual there.
        equation: usize,
    },
    /// Newton's corrections reached the rounding of the coordinates, but the residual stayed
    /// above [`crate::SolverOptions::acceptance_tolerance`]: a coordinate too large to resolve
    /// in double precision (an angle of 1e12 rad, whose rounding alone is 1e-4 rad, or a
    /// position far beyond the scene's size).
    Unresolved {
        /// Time of the solve.
        time: f64,
        /// Newton updates applied.
        iterations: usize,
        /// ‖Φ‖∞ of the block at the returned positions.
        residual: f64,
        /// The equation with the largest scaled residual.
        equation: usize,
    },
    /// Φ_q is singular or too ill-conditioned to trust at the solution: a toggle (dead-point)
    /// position, or redundant constraints.
    ///
    /// `equation` is the first of the `deficiency` dependent equations and `coordinate` the
    /// first coordinate they leave undetermined; [`crate::Solver::dependent_equations`] lists all.
    Singular {
        /// Time of the solve.
        time: f64,
        /// First dependent (redundant) equation.
        equation: usize,
        /// First undetermined coordinate.
        coordinate: usize,
        /// Condition estimate κ₁ of the unit-scaled Φ_q (infinite when a pivot vanished).
        condition: f64,
        /// How many equations depend on the others (n − numerical rank).
        deficiency: usize,
    },
    /// The solution has a branch invariant of the wrong sign: the mechanism would flip to
    /// another assembly branch (through a singular position, or by a too coarse time step).
    BranchFlip {
        /// Time of the solve.
        time: f64,
        /// The branch invariant's index.
        branch: usize,
        /// Its value (signed: positive on the declared branch).
        value: f64,
    },
    /// An input or an evaluated quantity was NaN or infinite.
    NonFinite {
        /// Time of the solve.
        time: f64,
        /// Which quantity.
        quantity: Quantity,
        /// The first equation whose value (Φ, ν, γ), Jacobian row, or closed-form assignment
        /// (of a position, velocity or acceleration) is not finite: it names the joint or
        /// driver whose expressions failed (`sqrt` of a negative number, a division by zero).
        /// `None` for inputs and for values no single equation produced.
        equation: Option<usize>,
    },
    /// A geometric value computed from parameters (a body-fixed point, a distance, a ground
    /// pose, a prismatic axis) breaks its rule with the current parameter values: a distance
    /// that is not positive, a NaN from `sqrt` of a negative number or a division by zero. See
    /// [`crate::Mechanism::check_geometry`].
    Geometry {
        /// Time of the solve.
        time: f64,
        /// The first equation of the joint or driver the value belongs to.
        equation: usize,
        /// The first parameter (by index) the value is computed from.
        parameter: usize,
        /// The value.
        value: f64,
        /// What it must be.
        requirement: Requirement,
    },
    /// A mass property or load constant computed from parameters (a mass, an inertia, a
    /// centre of mass, a spring's stiffness, free length or damping, a load's point) breaks
    /// the rule constants obey at compile time, with the current parameter values: a negative
    /// mass or stiffness. See [`crate::Mechanism::check_physics`].
    Physics {
        /// Time of the solve.
        time: f64,
        /// The body or load the value belongs to.
        subject: Subject,
        /// The first parameter (by index) the value is computed from.
        parameter: usize,
        /// The value.
        value: f64,
        /// What it must be.
        requirement: Requirement,
    },
    /// A vector passed in does not have `dim()` entries (only possible with `Dyn` mechanisms).
    DimensionMismatch {
        /// The mechanism's `dim()`.
        expected: usize,
        /// The length passed in.
        found: usize,
    },
}

impl GeometryFault {
    /// The fault as the error of a solve at `time`.
    pub fn at(self, time: f64) -> SolveError {
        SolveError::Geometry {
            time,
            equation: self.equation,
            parameter: self.parameter,
            value: self.value,
            requirement: self.requirement,
        }
    }
}

/// Names for an error's indices, looked up in the mechanism (and the solver's diagnosis).
#[derive(Default)]
struct Names<'a> {
    equation: Option<&'a str>,
    coordinate: Option<&'a str>,
    branch: Option<&'a str>,
    parameter: Option<&'a str>,
    marker: Option<&'a str>,
    /// The body or load of a [`SolveError::Physics`].
    subject: Option<&'a str>,
}

impl SolveError {
    /// The time at which the solve failed, if the error concerns one.
    pub fn time(&self) -> Option<f64> {
        match *self {
            Self::NoConvergence { time, .. }
            | Self::NoAssembly { time, .. }
            | Self::Unresolved { time, .. }
            | Self::Singular { time, .. }
            | Self::BranchFlip { time, .. }
            | Self::NonFinite { time, .. }
            | Self::Geometry { time, .. }
            | Self::Physics { time, .. } => Some(time),
            Self::DimensionMismatch { .. } => None,
        }
    }

    /// Whether a smaller time step may get past this failure (the simulation sub-steps on these):
    /// the Newton iteration lost its way, as opposed to a property of the configuration or of
    /// the input.
    pub fn is_step_related(&self) -> bool {
        matches!(
            self,
            Self::NoConvergence { .. } | Self::NoAssembly { .. } | Self::BranchFlip { .. }
        )
    }

    /// Displays the error with the mechanism's names instead of indices.
    pub fn describe<'a, M: Mechanism>(&'a self, mechanism: &'a M) -> Described<'a, M>
    where
        DefaultAllocator: Storage<M::Dim>,
    {
        Described {
            error: self,
            mechanism,
            dependent: &[],
            undetermined: &[],
        }
    }

    fn write(&self, f: &mut fmt::Formatter<'_>, names: &Names<'_>) -> fmt::Result {
        let equation = |f: &mut fmt::Formatter<'_>, index: usize| match names.equation {
            Some(name) => write!(f, "`{name}`"),
            None => write!(f, "#{index}"),
        };
        match *self {
            Self::NoConvergence {
                time,
                iterations,
                residual,
            } => write!(
                f,
                "no convergence at t = {time} after {iterations} Newton iterations \
                 (‖Φ‖∞ = {residual:e}); try a smaller time step or a better initial guess"
            ),
            Self::NoAssembly {
                time,
                iterations,
                residual,
                equation: index,
            } => {
                write!(
                    f,
                    "the mechanism cannot assemble at t = {time}: after {iterations} iterations \
                     the residual stopped at ‖Φ‖∞ = {residual:e}, largest in equation "
                )?;
                equation(f, index)?;
                f.write_str("; check the link lengths and the driver values (can the loop close?)")
            }
            Self::Unresolved {
                time,
                iterations,
                residual,
                equation: index,
            } => {
                write!(
                    f,
                    "the positions at t = {time} cannot be resolved in double precision: after \
                     {iterations} iterations the corrections reached the rounding of the \
                     coordinates, but ‖Φ‖∞ = {residual:e} remains, largest in equation "
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
            } => {
                write!(
                    f,
                    "singular Jacobian at t = {time} (condition estimate {condition:.3e} of the \
                     scaled Φ_q): {deficiency} equation{} depend{} on the others; equation ",
                    if deficiency == 1 { "" } else { "s" },
                    if deficiency == 1 { "s" } else { "" },
                )?;
                equation(f, index)?;
                match names.coordinate {
                    Some(name) => write!(f, " leaves coordinate `{name}` undetermined")?,
                    None => write!(f, " leaves coordinate #{coordinate} undetermined")?,
                }
                f.write_str(
                    " (a toggle/dead-point position, or redundant constraints: remove one of \
                     the dependent equations' joints or drivers)",
                )
            }
            Self::BranchFlip {
                time,
                branch,
                value,
            } => {
                write!(
                    f,
                    "the solution at t = {time} is on another assembly branch: "
                )?;
                Quantity::Branch(branch).write(f, names.branch)?;
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
            } => {
                quantity.write(f, names.parameter.or(names.branch).or(names.marker))?;
                write!(f, " became NaN or infinite at t = {time}")?;
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
            } => {
                write!(f, "invalid geometry at t = {time}: a value of equation ")?;
                equation(f, index)?;
                write!(f, " is {value:e}, computed from ")?;
                Quantity::Parameter(parameter).write(f, names.parameter)?;
                write!(
                    f,
                    "; it is {}: set the parameter to a value the mechanism can be built with",
                    requirement.describe()
                )
            }
            Self::Physics {
                time,
                subject,
                parameter,
                value,
                requirement,
            } => {
                write!(f, "invalid physics at t = {time}: a value of ")?;
                match (subject, names.subject) {
                    (Subject::Body(_), Some(name)) => write!(f, "body `{name}`")?,
                    (Subject::Body(index), None) => write!(f, "body #{index}")?,
                    (Subject::Load(_), Some(name)) => write!(f, "load `{name}`")?,
                    (Subject::Load(index), None) => write!(f, "load #{index}")?,
                }
                write!(f, " is {value:e}, computed from ")?;
                Quantity::Parameter(parameter).write(f, names.parameter)?;
                write!(
                    f,
                    "; it is {}: set the parameter to a physical value",
                    requirement.describe()
                )
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
        self.write(f, &Names::default())
    }
}

impl core::error::Error for SolveError {}

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
        let m = self.mechanism;
        let mut names = Names::default();
        match *self.error {
            SolveError::Singular {
                equation,
                coordinate,
                ..
            } => {
                names.equation = m.equation_name(equation);
                names.coordinate = m.coordinate_name(coordinate);
            }
            SolveError::NoAssembly { equation, .. }
            | SolveError::Unresolved { equation, .. }
            | SolveError::NonFinite {
                equation: Some(equation),
                ..
            } => {
                names.equation = m.equation_name(equation);
            }
            SolveError::BranchFlip { branch, .. } => names.branch = m.branch_name(branch),
            SolveError::Geometry {
                equation,
                parameter,
                ..
            } => {
                names.equation = m.equation_name(equation);
                names.parameter = m.parameter_name(parameter);
            }
            SolveError::Physics {
                subject, parameter, ..
            } => {
                names.subject = match subject {
                    // A body's coordinates are named `body.x`, `body.y`, `body.theta`.
                    Subject::Body(body) => m
                        .coordinate_name(3 * body)
                        .map(|x| x.strip_suffix(".x").unwrap_or(x)),
                    Subject::Load(load) => m.load_name(load),
                };
                names.parameter = m.parameter_name(parameter);
            }
            SolveError::NonFinite {
                quantity: Quantity::Parameter(index),
                ..
            } => names.parameter = m.parameter_name(index),
            SolveError::NonFinite {
                quantity: Quantity::Branch(index),
                ..
            } => names.branch = m.branch_name(index),
            SolveError::NonFinite {
                quantity: Quantity::Marker(index),
                ..
            } => names.marker = m.marker_name(index),
            _ => {}
        }
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
                    m.equation_name(index)
                } else {
                    m.coordinate_name(index)
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
    use crate::pendulum::Pendulum;
    use std::string::ToString;

    #[test]
    fn describe_replaces_indices_with_names() {
        let error = SolveError::Singular {
            time: 1.0,
            equation: 2,
            coordinate: 1,
            condition: f64::INFINITY,
            deficiency: 1,
        };
        let plain = error.to_string();
        assert!(plain.contains("1 equation depends"), "{plain}");
        assert!(
            plain.contains("equation #2 leaves coordinate #1"),
            "{plain}"
        );
        let named = error.describe(&Pendulum::default()).to_string();
        assert!(
            named.contains("equation `drive` leaves coordinate `rod.y` undetermined"),
            "{named}"
        );
        assert_eq!(error.time(), Some(1.0));
    }

    #[test]
    fn every_error_says_when_and_what() {
        let pendulum = Pendulum::default();
        let errors = [
            SolveError::NoAssembly {
                time: 0.5,
                iterations: 9,
                residual: 1.5,
                equation: 0,
            },
            SolveError::BranchFlip {
                time: 0.5,
                branch: 0,
                value: -1.0,
            },
            SolveError::NonFinite {
                time: 0.5,
                quantity: Quantity::Parameter(3),
                equation: None,
            },
            SolveError::NonFinite {
                time: 0.5,
                quantity: Quantity::Phi,
                equation: Some(2),
            },
            SolveError::NoConvergence {
                time: 0.5,
                iterations: 25,
                residual: 1e-3,
            },
        ];
        for error in errors {
            let text = error.describe(&pendulum).to_string();
            assert!(text.contains("t = 0.5"), "{text}");
            assert_eq!(error.time(), Some(0.5));
        }
        assert!(
            errors[0]
                .describe(&pendulum)
                .to_string()
                .contains("`pin.x`")
        );
        assert!(errors[2].to_string().contains("parameter #3"));
        let phi = errors[3].describe(&pendulum).to_string();
        assert!(phi.contains("first in equation `drive`"), "{phi}");
        assert!(errors[0].is_step_related() && !errors[2].is_step_related());
    }
}
