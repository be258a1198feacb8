//! Why a solve failed, naming the scene's equations, coordinates, branches and parameters
//! from the [`Names`] the solver attaches to every error it returns.

use core::fmt;

use nalgebra::DefaultAllocator;

use crate::geometry::{GeometryFault, Requirement};
use crate::mechanism::{Mechanism, Storage};
use crate::names::Names;
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
    /// The generalised applied and inertial forces F of the force solve as a whole, when no
    /// single load explains them ([`Quantity::LoadValue`] and [`Quantity::SpringEnds`] name
    /// one): the masses' inertia or gravity overflowing.
    Load,
    /// The solved reactions (Lagrange multipliers) of the force solve.
    Reaction,
    /// A marker's value or rate (its index among the marker values).
    Marker(usize),
    /// One load's force or moment (its index among the scene's loads): its expression or the
    /// parameters it reads (a moment of 1e310, a division by zero).
    LoadValue(usize),
    /// A spring's force where its ends coincide (its index among the scene's loads): with a
    /// non-zero free length or damping its direction, and so its force, is undefined there.
    SpringEnds(usize),
}

/// The first load, among [`crate::Mechanism::load_fault`]'s witnesses (two values per load:
/// the sum of its contributions to F, and for a spring the squared distance between its ends,
/// else 1), whose contribution is not finite: [`Quantity::SpringEnds`] when the ends meet,
/// [`Quantity::LoadValue`] otherwise. Generated scenes and the interpreter call it.
pub fn first_load_fault(witnesses: &[f64]) -> Option<Quantity> {
    witnesses
        .chunks_exact(2)
        .position(|w| !w[0].is_finite())
        .map(|load| {
            if witnesses.get(2 * load + 1).is_some_and(|&d| d == 0.0) {
                Quantity::SpringEnds(load)
            } else {
                Quantity::LoadValue(load)
            }
        })
}

impl Quantity {
    /// Writes the quantity, naming a parameter, branch or marker from `names` (its index
    /// otherwise).
    fn write(self, f: &mut fmt::Formatter<'_>, names: &dyn Lookup) -> fmt::Result {
        let (label, name, index) = match self {
            Self::Parameter(i) => ("parameter ", names.parameter(i), i),
            Self::Branch(i) => ("branch invariant ", names.branch(i), i),
            Self::Marker(i) => ("marker value ", names.marker(i), i),
            Self::LoadValue(i) => ("the force or moment of load ", names.load(i), i),
            Self::SpringEnds(i) => ("the force of spring ", names.load(i), i),
            _ => return f.write_str(self.text()),
        };
        f.write_str(label)?;
        write_name(f, name, index)
    }

    /// What an unindexed quantity is called.
    fn text(self) -> &'static str {
        match self {
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
            Self::Parameter(_)
            | Self::Branch(_)
            | Self::Marker(_)
            | Self::LoadValue(_)
            | Self::SpringEnds(_) => "",
        }
    }
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.write(f, &Names::NONE)
    }
}

/// A failed position, velocity or acceleration solve: what went wrong, and when.
///
/// Indices refer to equations, coordinates, branches and parameters of the scene; the solver
/// attaches the scene's [`Names`] to every error it returns, so `Display` and `Debug` (what an
/// error returned from `main` prints) name them, wherever the error goes.
/// [`crate::Solver::describe`] adds every dependent equation and undetermined coordinate of
/// the `Singular` it just returned. The error is `Copy` (the names are one `&'static`
/// pointer) and allocation-free.
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
#[derive(Clone, Copy, PartialEq)]
pub enum SolveError {
    /// Newton–Raphson hit the iteration cap while still reducing the residual.
    NoConvergence {
        /// Time of the solve.
        time: f64,
        /// Newton updates applied.
        iterations: usize,
        /// ‖Φ‖∞ at the last iterate.
        residual: f64,
        /// The equation with the largest scaled residual there: its joint's bodies are the
        /// ones whose guesses to move.
        equation: usize,
        /// The scene's names, which `Display` and `Debug` use ([`Names::NONE`] until the
        /// solver attaches its mechanism's, [`crate::Mechanism::names`]).
        #[cfg_attr(feature = "serde", serde(skip))]
        names: &'static Names,
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
        /// The scene's names, which `Display` and `Debug` use ([`Names::NONE`] until the
        /// solver attaches its mechanism's, [`crate::Mechanism::names`]).
        #[cfg_attr(feature = "serde", serde(skip))]
        names: &'static Names,
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
        /// The scene's names, which `Display` and `Debug` use ([`Names::NONE`] until the
        /// solver attaches its mechanism's, [`crate::Mechanism::names`]).
        #[cfg_attr(feature = "serde", serde(skip))]
        names: &'static Names,
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
        /// The scene's names, which `Display` and `Debug` use ([`Names::NONE`] until the
        /// solver attaches its mechanism's, [`crate::Mechanism::names`]).
        #[cfg_attr(feature = "serde", serde(skip))]
        names: &'static Names,
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
        /// The scene's names, which `Display` and `Debug` use ([`Names::NONE`] until the
        /// solver attaches its mechanism's, [`crate::Mechanism::names`]).
        #[cfg_attr(feature = "serde", serde(skip))]
        names: &'static Names,
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
        /// The scene's names, which `Display` and `Debug` use ([`Names::NONE`] until the
        /// solver attaches its mechanism's, [`crate::Mechanism::names`]).
        #[cfg_attr(feature = "serde", serde(skip))]
        names: &'static Names,
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
        /// The scene's names, which `Display` and `Debug` use ([`Names::NONE`] until the
        /// solver attaches its mechanism's, [`crate::Mechanism::names`]).
        #[cfg_attr(feature = "serde", serde(skip))]
        names: &'static Names,
    },
    /// [`crate::Simulation::new`] followed the motion from t = 0 (where the `near` guesses
    /// describe the mechanism) towards the start time for
    /// [`crate::MAX_CONTINUATION_STEPS`] steps without reaching it: the state there
    /// cannot be shown to be the one continuous motion reaches.
    Unreachable {
        /// The start time asked for.
        time: f64,
        /// The time the motion was followed to.
        reached: f64,
        /// Steps taken.
        steps: usize,
        /// The scene's names, which `Display` and `Debug` use ([`Names::NONE`] until the
        /// solver attaches its mechanism's, [`crate::Mechanism::names`]).
        #[cfg_attr(feature = "serde", serde(skip))]
        names: &'static Names,
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
        /// The scene's names, which `Display` and `Debug` use ([`Names::NONE`] until the
        /// solver attaches its mechanism's, [`crate::Mechanism::names`]).
        #[cfg_attr(feature = "serde", serde(skip))]
        names: &'static Names,
    },
    /// A vector passed in does not have `dim()` entries (only possible with `Dyn` mechanisms).
    DimensionMismatch {
        /// The mechanism's `dim()`.
        expected: usize,
        /// The length passed in.
        found: usize,
        /// The scene's names, which `Display` and `Debug` use ([`Names::NONE`] until the
        /// solver attaches its mechanism's, [`crate::Mechanism::names`]).
        #[cfg_attr(feature = "serde", serde(skip))]
        names: &'static Names,
    },
}

impl GeometryFault {
    /// The fault as the error of a solve at `time` (unnamed until the solver names it).
    pub fn at(self, time: f64) -> SolveError {
        SolveError::Geometry {
            time,
            equation: self.equation,
            parameter: self.parameter,
            value: self.value,
            requirement: self.requirement,
            names: &Names::NONE,
        }
    }
}

/// Where an error's indices find their names: its own [`Names`], or a mechanism.
trait Lookup {
    fn equation(&self, index: usize) -> Option<&str>;
    fn coordinate(&self, index: usize) -> Option<&str>;
    fn parameter(&self, index: usize) -> Option<&str>;
    fn branch(&self, index: usize) -> Option<&str>;
    fn marker(&self, index: usize) -> Option<&str>;
    fn load(&self, index: usize) -> Option<&str>;
}

impl Lookup for Names {
    fn equation(&self, index: usize) -> Option<&str> {
        Names::equation(self, index)
    }
    fn coordinate(&self, index: usize) -> Option<&str> {
        Names::coordinate(self, index)
    }
    fn parameter(&self, index: usize) -> Option<&str> {
        Names::parameter(self, index)
    }
    fn branch(&self, index: usize) -> Option<&str> {
        Names::branch(self, index)
    }
    fn marker(&self, index: usize) -> Option<&str> {
        Names::marker(self, index)
    }
    fn load(&self, index: usize) -> Option<&str> {
        Names::load(self, index)
    }
}

/// A mechanism's own names first, then those the error carries.
struct FromMechanism<'a, M>(&'a M, &'static Names);

impl<M: Mechanism> Lookup for FromMechanism<'_, M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn equation(&self, index: usize) -> Option<&str> {
        self.0.equation_name(index).or(self.1.equation(index))
    }
    fn coordinate(&self, index: usize) -> Option<&str> {
        self.0.coordinate_name(index).or(self.1.coordinate(index))
    }
    fn parameter(&self, index: usize) -> Option<&str> {
        self.0.parameter_name(index).or(self.1.parameter(index))
    }
    fn branch(&self, index: usize) -> Option<&str> {
        self.0.branch_name(index).or(self.1.branch(index))
    }
    fn marker(&self, index: usize) -> Option<&str> {
        self.0.marker_name(index).or(self.1.marker(index))
    }
    fn load(&self, index: usize) -> Option<&str> {
        self.0.names().load(index).or(self.1.load(index))
    }
}

/// Writes `` `name` `` when known, `#index` otherwise.
fn write_name(f: &mut fmt::Formatter<'_>, name: Option<&str>, index: usize) -> fmt::Result {
    match name {
        Some(name) => write!(f, "`{name}`"),
        None => write!(f, "#{index}"),
    }
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
            | Self::Unreachable { time, .. }
            | Self::Physics { time, .. } => Some(time),
            Self::DimensionMismatch { .. } => None,
        }
    }

    /// The name tables the error's `Display` and `Debug` use ([`Names::NONE`] when the error
    /// did not come from a solver, or from a mechanism without names).
    pub fn names(&self) -> &'static Names {
        match *self {
            Self::NoConvergence { names, .. }
            | Self::NoAssembly { names, .. }
            | Self::Unresolved { names, .. }
            | Self::Singular { names, .. }
            | Self::BranchFlip { names, .. }
            | Self::NonFinite { names, .. }
            | Self::Geometry { names, .. }
            | Self::Unreachable { names, .. }
            | Self::Physics { names, .. }
            | Self::DimensionMismatch { names, .. } => names,
        }
    }

    /// The error with `table` as its names (the solver does this for every error it returns).
    #[must_use]
    pub fn named(mut self, table: &'static Names) -> Self {
        match &mut self {
            Self::NoConvergence { names, .. }
            | Self::NoAssembly { names, .. }
            | Self::Unresolved { names, .. }
            | Self::Singular { names, .. }
            | Self::BranchFlip { names, .. }
            | Self::NonFinite { names, .. }
            | Self::Geometry { names, .. }
            | Self::Unreachable { names, .. }
            | Self::Physics { names, .. }
            | Self::DimensionMismatch { names, .. } => *names = table,
        }
        self
    }

    /// The variant's name, which `Debug` leads with.
    fn kind(&self) -> &'static str {
        match self {
            Self::NoConvergence { .. } => "NoConvergence",
            Self::NoAssembly { .. } => "NoAssembly",
            Self::Unresolved { .. } => "Unresolved",
            Self::Singular { .. } => "Singular",
            Self::BranchFlip { .. } => "BranchFlip",
            Self::NonFinite { .. } => "NonFinite",
            Self::Geometry { .. } => "Geometry",
            Self::Unreachable { .. } => "Unreachable",
            Self::Physics { .. } => "Physics",
            Self::DimensionMismatch { .. } => "DimensionMismatch",
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

    /// Displays the error with the mechanism's names (those the error carries where the
    /// mechanism has none).
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

    fn write(&self, f: &mut fmt::Formatter<'_>, names: &dyn Lookup) -> fmt::Result {
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

    #[test]
    fn the_first_non_finite_load_is_named_with_its_cause() {
        let nan = f64::NAN;
        assert_eq!(first_load_fault(&[1.0, 1.0, 2.0, 0.0]), None);
        assert_eq!(
            first_load_fault(&[1.0, 1.0, nan, 0.0, nan, 1.0]),
            Some(Quantity::SpringEnds(1))
        );
        assert_eq!(
            first_load_fault(&[f64::INFINITY, 1.0, nan, 0.0]),
            Some(Quantity::LoadValue(0))
        );
    }
}
