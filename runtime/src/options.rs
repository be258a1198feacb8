//! The solver's options and the levels of a sweep: what the solver, the block Newton
//! iteration, the force solve and the NaN tracing all read, kept apart from the solver itself so
//! that they depend on it in one direction only.

use crate::lu::DEFAULT_PIVOT_TOLERANCE;
use crate::mechanism::Outputs;

/// Tolerances and safeguards of the solve.
///
/// Tolerances apply to the unit-scaled system (see [`crate::Unit`]): lengths are measured in
/// units of the scene's [`crate::Mechanism::length_scale`], angles in radians, and both
/// relative to `max(1, ‖D_c⁻¹ q_b‖∞)` over the coordinates of the block being solved (so a
/// coupler that has turned a million radians is still resolved to round-off). The same options
/// then suit a micro-mechanism in metres and an engine in millimetres.
///
/// ```
/// # use mechgen_runtime::mechanism;
/// # mechanism! {
/// #     /// A slider-crank (mm, rad, s).
/// #     pub mechanism SliderCrank {
/// #         param omega = 10.0;
/// #         ground frame at (0, 0, 0);
/// #         body crank near (0, 0, 0.5);
/// #         body rod near (35, 19, -0.19);
/// #         body slider near (133, 0, 0);
/// #         joint pivot: revolute(frame, crank);
/// #         joint crank_pin: revolute(crank @ (40, 0), rod);
/// #         joint wrist: revolute(rod @ (100, 0), slider);
/// #         joint guide: prismatic(frame, slider, along (1, 0));
/// #         driver turn: angle(crank) = 0.5 + omega * t;
/// #     }
/// # }
/// use mechgen_runtime::{Simulation, Solver, SolverOptions};
///
/// // Tighter than the default, and without the condition estimate (a little faster).
/// let options = SolverOptions {
///     residual_tolerance: 1e-13,
///     estimate_condition: false,
///     ..SolverOptions::default()
/// };
/// let simulation = Simulation::new(Solver::with_options(SliderCrank::default(), options), 0.0)?;
/// assert!(simulation.state().condition.is_nan());
/// # Ok::<(), mechgen_runtime::SolveError>(())
/// ```
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverOptions {
    /// A first Newton correction ends the iteration only from a point whose scaled residual
    /// ‖D_r Φ_b‖∞ is within `residual_tolerance` (default 1e-10; times the magnitude above).
    pub residual_tolerance: f64,
    /// Converged once a scaled Newton correction is within `step_tolerance` (default 1e-10) and
    /// convergence is evident (see the `position` module: quadratic contraction, or a first
    /// correction from a point within `residual_tolerance`).
    pub step_tolerance: f64,
    /// A solution is accepted only when its scaled residual ‖D_r Φ_b‖∞ is within this, in
    /// scene lengths and radians, whatever the size of the coordinates (default 1e-8). The step
    /// and residual tolerances above are relative to the coordinates' magnitude, so that a
    /// crank that has turned for hours still converges; this absolute test is what keeps a
    /// coordinate too large to resolve (an angle of 1e12 rad, whose rounding alone is 1e-4)
    /// from being accepted: such a solve fails with [`crate::SolveError::Unresolved`]. A looser
    /// `residual_tolerance` (a work-precision sweep) loosens it to that.
    pub acceptance_tolerance: f64,
    /// Updates (Newton, damped or Levenberg–Marquardt) per block before giving up (default 50).
    pub max_iterations: usize,
    /// Relative pivot tolerance τ of the scaled block Jacobians: a pivot counts as zero when
    /// `|u_kk| ≤ τ · n · max|s_ij|` (default [`DEFAULT_PIVOT_TOLERANCE`]).
    pub pivot_tolerance: f64,
    /// Factor blocks with the pivot order the scene fixed at generation time (default true).
    /// Off, every block is factored with partial pivoting: only for comparisons.
    pub static_pivots: bool,
    /// Threshold u of the static pivots (default 0.1): a static pivot is kept while it is at
    /// least u times every other entry of its column in the remaining submatrix (multipliers at
    /// most 1/u, as in threshold partial pivoting). When one is not, the block is refactored
    /// with partial pivoting, and the fallback is counted ([`crate::State::fallbacks`]).
    pub static_pivot_threshold: f64,
    /// Largest condition estimate of a scaled block Jacobian accepted at a solution (default
    /// 1e8).
    ///
    /// Above it the solve fails with [`crate::SolveError::Singular`]. Two reasons set the default.
    /// Velocities and accelerations lose about log₁₀(κ) digits, so 1e8 still leaves eight.
    /// And at a double root (a toggle position), Newton places the solution only about √ε
    /// away, where κ is of order 1/√ε ≈ 7e7 times the scene's own constants (about 1e9 for a
    /// slider-crank whose rod equals its crank). A limit above that would accept such a point,
    /// with velocities halfway between the two branches that meet there.
    pub max_condition: f64,
    /// Largest scaled Newton step (default 1): a step is shortened to move no coordinate by
    /// more than this many scene lengths or radians, so a bad guess cannot throw the iterate
    /// across the mechanism.
    pub max_step: f64,
    /// Scale equations and coordinates by their units (default true). Off, tolerances and the
    /// condition estimate apply to raw values: only for measuring what scaling costs.
    pub scale_units: bool,
    /// Estimate the condition of every block at its solution (default true). Off,
    /// `max_condition` is not checked and states report a NaN condition: only for measuring
    /// what the estimate costs.
    pub estimate_condition: bool,
    /// Start each block that has a closed form (`Structured::closed_form`) from its solution
    /// nearest the guess (default true); Newton then verifies it. Off, Newton starts from the
    /// guess itself: only for comparing the two paths.
    pub closed_forms: bool,
    /// Solve a scene that has a straight step (`Structured::straight_step`: every block with
    /// a closed form, the accelerations or the forces asked for) by it when `closed_forms`
    /// and `static_pivots` are on too (default true): the stages in one generated function,
    /// each block taking its closed-form solution under the checks Newton's first iteration
    /// would make, then, with forces, the force solve; where one fails, the stage sweep runs.
    /// Off, the sweep always runs: only for comparing the two paths.
    pub straight_step: bool,
}

impl Default for SolverOptions {
    fn default() -> Self {
        Self {
            residual_tolerance: 1e-10,
            step_tolerance: 1e-10,
            acceptance_tolerance: 1e-8,
            max_iterations: 50,
            pivot_tolerance: DEFAULT_PIVOT_TOLERANCE,
            static_pivots: true,
            static_pivot_threshold: 0.1,
            max_condition: 1e8,
            max_step: 1.0,
            scale_units: true,
            estimate_condition: true,
            closed_forms: true,
            straight_step: true,
        }
    }
}

/// What a stage sweep computes besides positions: ordered, each level including the ones
/// before it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Rates {
    None,
    Velocities,
    Both,
    /// Both rates, then the force solve in reverse.
    Forces,
}

impl Rates {
    pub(crate) fn of(outputs: Outputs) -> Self {
        match outputs {
            Outputs::Positions => Rates::None,
            Outputs::Velocities => Rates::Velocities,
            Outputs::Accelerations => Rates::Both,
            Outputs::Forces => Rates::Forces,
        }
    }
}
