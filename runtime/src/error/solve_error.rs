//! [`SolveError`]: why a position, velocity or acceleration solve failed, when, and with which
//! scene's names.

use super::message::Described;
use super::quantity::Quantity;

use nalgebra::DefaultAllocator;

use crate::geometry::{GeometryFault, Requirement};
use crate::mechanism::{Mechanism, Storage};
use crate::names::Names;
use crate::physics::Subject;

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
    pub(super) fn kind(&self) -> &'static str {
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
}

impl core::error::Error for SolveError {}
