//! What a successful position solve reports: iterations, residual, condition, fallbacks
//! and the blocks' orientations, over all blocks.

use crate::position::Solved;

/// Outcome of a successful position solve, over all blocks.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Convergence {
    /// Updates applied by the block that needed the most (0 when every coordinate is explicit).
    pub iterations: usize,
    /// Largest ‖Φ_b‖∞ (unscaled) of the blocks at their last evaluation: at the returned
    /// positions, or, where the last correction was of round-off size, just before it.
    /// Explicit assignments satisfy their equations to the rounding of the coordinates they
    /// combine; where that rounding could reach `acceptance_tolerance` (coordinates beyond
    /// ~4e4 scene lengths or radians), their residuals at the returned positions are
    /// evaluated and included here.
    pub residual: f64,
    /// Largest condition estimate κ₁ of the scaled block Jacobians at the solution (1 without
    /// blocks; NaN if switched off).
    pub condition: f64,
    /// Block factorisations whose static pivots failed their test and were redone with partial
    /// pivoting.
    pub fallbacks: usize,
    /// Evaluations and factorisations of block Jacobians, summed over the blocks: one per
    /// Newton iteration, plus one at the returned positions unless the last correction was of
    /// round-off size (its factors then serve the rates).
    pub evaluations: usize,
    /// The sign of det Φ_q (unit-scaled, in the scene's solve order), +1 or −1: the product of
    /// the blocks' determinant signs (fixed and explicit coordinates have constant
    /// coefficients). It changes between two solutions only if Φ_q is singular somewhere
    /// between them; [`crate::Simulation`] watches it to catch toggle crossings.
    pub orientation: i8,
    /// Which blocks have a negative determinant: the XOR of a 64-bit code per such block
    /// (a splitmix64 code of the stage index, distinct and non-zero for every stage). Two states
    /// whose blocks' signs differ have a singular configuration between them even when an even
    /// number of blocks flipped and `orientation` did not change; the codes of two different
    /// blocks never cancel (three or more could, with a chance of order 2⁻⁶⁴).
    pub block_signs: u64,
    /// Whether a block's Newton iterates met both determinant signs: the iteration crossed
    /// a singular configuration between its start and the solution.
    pub swept: bool,
    /// Blocks whose Newton iteration started from their closed-form solution.
    pub closed_forms: usize,
}

impl Convergence {
    pub(super) fn start(estimate_condition: bool) -> Self {
        Convergence {
            iterations: 0,
            residual: 0.0,
            condition: if estimate_condition { 1.0 } else { f64::NAN },
            fallbacks: 0,
            evaluations: 0,
            orientation: 1,
            block_signs: 0,
            swept: false,
            closed_forms: 0,
        }
    }

    pub(super) fn add(&mut self, stage: usize, block: &Solved, newton: (usize, usize, bool)) {
        let (fallbacks, evaluations, closed_form) = newton;
        self.closed_forms += usize::from(closed_form);
        self.iterations = self.iterations.max(block.iterations);
        self.residual = self.residual.max(block.residual);
        // NaN (estimate off) stays NaN.
        self.condition = if block.condition > self.condition {
            block.condition
        } else {
            self.condition
        };
        self.fallbacks += fallbacks;
        self.evaluations += evaluations;
        if block.orientation < 0.0 {
            self.orientation = -self.orientation;
            self.block_signs ^= crate::block_signs::block_code(stage);
        }
        self.swept |= block.swept;
    }
}
