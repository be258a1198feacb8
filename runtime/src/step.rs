//! The straight kinematic step's terms with the solver
//! ([`crate::Structured::straight_step`]): the settings it checks against ([`StepContext`]),
//! what it reports back ([`StepReport`]), a block's unit scales ([`BlockScales`]). Their
//! checks, which generated code calls, are in `codegen::step`.

use crate::mechanism::LengthScale;
use crate::options::SolverOptions;

/// The solver's settings a straight step checks against, for one solve.
#[derive(Debug, Clone, Copy)]
pub struct StepContext {
    pub(crate) length: LengthScale,
    pub(crate) residual_tolerance: f64,
    pub(crate) step_tolerance: f64,
    /// `max(acceptance_tolerance, residual_tolerance)`, as the sweep accepts.
    pub(crate) acceptance: f64,
    pub(crate) pivot_tolerance: f64,
    /// The static pivots' multiplier limit, `1 / static_pivot_threshold`.
    pub(crate) limit: f64,
    pub(crate) max_condition: f64,
    pub(crate) estimate_condition: bool,
    /// Which closed-form candidate each block tries first: the last straight step's choices
    /// (see [`StepReport::choices`]).
    pub(crate) choices: u64,
}

/// What a straight step found, for the solve's [`crate::Convergence`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    pub(crate) blocks: usize,
    pub(crate) residual: f64,
    pub(crate) condition: f64,
    pub(crate) orientation: i8,
    pub(crate) block_signs: u64,
    /// Bit `stage % 64` set where a block took its second closed-form candidate: only an
    /// order of trial (a shared bit costs an `atan2`, never a different answer).
    pub(crate) choices: u64,
}

/// A block's unit scales: `D_r` per equation, `D_c` and `D_c⁻¹` per coordinate.
#[derive(Debug, Clone, Copy)]
pub struct BlockScales<const N: usize> {
    pub(crate) rows: [f64; N],
    pub(crate) cols: [f64; N],
    pub(crate) inverse_cols: [f64; N],
}

impl StepContext {
    /// The settings of `options` at the solve's length scale, with the blocks trying first
    /// the closed-form candidates of `choices`.
    pub(crate) fn new(options: &SolverOptions, length: LengthScale, choices: u64) -> Self {
        Self {
            length,
            residual_tolerance: options.residual_tolerance,
            step_tolerance: options.step_tolerance,
            acceptance: options.acceptance_tolerance.max(options.residual_tolerance),
            pivot_tolerance: options.pivot_tolerance,
            limit: 1.0 / options.static_pivot_threshold,
            max_condition: options.max_condition,
            estimate_condition: options.estimate_condition,
            choices,
        }
    }
}

impl StepReport {
    /// Nothing solved yet; the condition starts as the sweep's (1, or NaN when not estimated).
    pub(crate) fn new(estimate_condition: bool) -> Self {
        Self {
            blocks: 0,
            residual: 0.0,
            condition: if estimate_condition { 1.0 } else { f64::NAN },
            orientation: 1,
            block_signs: 0,
            choices: 0,
        }
    }
}
