//! Locating a singular configuration crossed between two solutions of a motion.
//!
//! Newton at a singular root stops about √ε away from it, where the Jacobian's condition is
//! only ~1/√ε, and a step can land on either side of a toggle. Neither the condition limit nor
//! the crawl test can then be relied on. The determinant's sign can be: the LU factors of every
//! solve give it for free ([`crate::State::orientation`]), and it can change between two
//! solutions only if Φ_q is singular somewhere in between. It is tracked per block
//! ([`crate::Convergence::block_signs`]): the product of the blocks' signs would hide two
//! blocks that flip in the same step (two levers on one pin, each its own block). Within one
//! block an even number of flips (two loops of one block through their toggles in the same
//! step) keeps the block's sign and is not seen here; the jump test of stepping (the solution
//! far from the prediction) and declared branch invariants are what catch that case. When a step ends with the other
//! sign, the step's time interval is bisected. Each midpoint is solved from the latest solution
//! on the starting side, which keeps the starting branch, until no double lies between the two
//! ends. The result is either the crossing, located to the last bit of the time and reported as
//! [`SolveError::Singular`] with the rank-revealing diagnosis there, or, when the starting side
//! reaches the step's end after all, a landing on the mirror branch, which is replaced by that
//! solution.
//!
//! A declared branch invariant that turns negative is located the same way: where two branches
//! meet (a slider-crank whose rod equals its crank), the invariant vanishes at the singular
//! configuration, and the crossing is reported as `Singular`; an invariant that changes sign
//! where Φ_q is regular stays a [`SolveError::BranchFlip`], at the located time.

use nalgebra::DefaultAllocator;

use crate::error::SolveError;
use crate::mechanism::Storage;
use crate::simulate::{Simulation, pair};
use crate::structure::Structured;

/// Where a solution lies relative to the crossing being located.
enum Side {
    /// The starting branch, with the starting determinant sign.
    Start,
    /// Past the crossing: the other sign, or a declared branch invariant turned negative.
    Other(Option<SolveError>),
}

/// Bisections of a step at most: far more than the 64 or so that reach adjacent doubles from
/// any step length; the cap only bounds the loop.
const MAX_BISECTIONS: usize = 128;

impl<M: Structured> Simulation<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// The step from the current state to `t_end` ended with the other sign of det Φ_q, or on
    /// the wrong side of a declared branch. Either the crossing is located and returned as
    /// [`SolveError::Singular`] (or the located `BranchFlip`; the simulation stays at the
    /// current state), or the starting branch reaches `t_end` after all, and its solution there
    /// is left in the scratch state for the caller to accept.
    pub(crate) fn locate_crossing(&mut self, t_end: f64) -> Result<(), SolveError> {
        let (current, _) = pair(&mut self.states, self.newest);
        let signs = current.block_signs;
        self.bracket.copy_from(current);
        let (mut low, mut high) = (current.t, t_end);
        let mut flip = None;
        for _ in 0..MAX_BISECTIONS {
            let middle = low + 0.5 * (high - low);
            if middle == low || middle == high {
                break;
            }
            match self.side(middle, signs)? {
                Side::Start => low = middle,
                Side::Other(error) => (high, flip) = (middle, error.or(flip)),
            }
        }
        // Every midpoint stayed on the starting side: the step's end may have been a jump to
        // the mirror branch rather than a crossing. Solve it from the bracket to find out.
        if high == t_end {
            match self.side(t_end, signs)? {
                Side::Start => return Ok(()),
                Side::Other(error) => flip = error.or(flip),
            }
        }
        let diagnosis = self.solver.diagnose_at(high, &self.bracket.q);
        match (diagnosis, flip) {
            // Φ_q is regular where the invariant changes sign: a branch flip, not a toggle.
            (SolveError::Singular { deficiency: 0, .. }, Some(flip)) => Err(flip),
            _ => Err(diagnosis),
        }
    }

    /// Which side of the crossing the solution at `t` (from the bracket) is on; a solution on
    /// the starting side becomes the bracket.
    ///
    /// # Errors
    /// A `Singular` solve (the solver's own diagnosis of the configuration it reached), or,
    /// for any other failure next to the crossing (no convergence, no assembly: the
    /// configuration locks up there), the diagnosis at the bracket.
    fn side(&mut self, t: f64, signs: u64) -> Result<Side, SolveError> {
        match self.solve_from_bracket(t) {
            Ok((reached, false)) if reached == signs => {
                let (_, next) = pair(&mut self.states, self.newest);
                self.bracket.copy_from(next);
                Ok(Side::Start)
            }
            Ok(_) => Ok(Side::Other(None)),
            Err(error @ SolveError::BranchFlip { .. }) => Ok(Side::Other(Some(error))),
            Err(error @ SolveError::Singular { .. }) => Err(error),
            Err(_) => Err(self.solver.diagnose_at(t, &self.bracket.q)),
        }
    }

    /// Solves at `t` from the bracket (Taylor prediction, no history) into the scratch state,
    /// returning the solution's block determinant signs and whether Newton crossed a singular
    /// configuration to get there.
    fn solve_from_bracket(&mut self, t: f64) -> Result<(u64, bool), SolveError> {
        let (_, next) = pair(&mut self.states, self.newest);
        if !self
            .prediction
            .predict(&self.solver, &self.bracket, next, false, t)
        {
            next.q.copy_from(&self.bracket.q);
        }
        self.has_previous = false;
        self.solver.solve_into(t, next)?;
        Ok((next.block_signs, next.swept))
    }
}
