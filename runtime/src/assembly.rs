//! Assembly: the first state of a [`Simulation`], at any start time.
//!
//! A scene's `near` guesses describe the mechanism at t = 0 ([`GUESS_TIME`]). Newton from them
//! at a later start time t0 has to bridge all the motion the drivers prescribe in between: a
//! driven angle of 40 rad inside a loop's Newton block is many turns from the guess, and the
//! iteration may wander off or settle on the mirror branch. So when the direct solve at t0 fails
//! in a way a shorter step may cure ([`SolveError::is_step_related`]), the mechanism is
//! assembled at t = 0, where the guess fits, and followed in time to t0 (a homotopy in t along
//! the drivers), with every safeguard of stepping: the predictor, the jump and crossing checks,
//! sub-stepping. The steps adapt so that the solution moves about [`STEP_MOTION`] (scene
//! lengths, radians) per step, and their number is bounded ([`MAX_CONTINUATION_STEPS`]). The state reached at
//! t0 is the one continuous motion from the assembled start arrives at, with the declared
//! branch kept; if the continuation fails too, the direct solve's error is returned.

use core::fmt;

use nalgebra::DefaultAllocator;

use crate::error::SolveError;
use crate::mechanism::Storage;
use crate::simulate::Simulation;
use crate::solver::Solver;
use crate::state::State;
use crate::structure::Structured;

/// The time the scene's `near` guesses describe.
pub const GUESS_TIME: f64 = 0.0;
/// Scaled motion (scene lengths, radians) a continuation step aims for: small enough that the
/// predictor lands within Newton's quadratic basin, large enough to cover a turn in ~30 steps.
const STEP_MOTION: f64 = 0.2;
/// The first continuation step, as a fraction of the interval (grown by the motion rule).
const FIRST_STEP: f64 = 1.0 / 1024.0;
/// Most continuation steps before giving up: bounds the work of a start time the motion cannot
/// be followed to (each step is itself bounded by the sub-stepping limit).
pub const MAX_CONTINUATION_STEPS: usize = 20_000;

impl<M: Structured> Simulation<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Assembles the mechanism at `t0` from its declared initial guess (predictor on): by
    /// Newton's method directly, or, when that fails in a way stepping may cure and `t0` is not
    /// the guesses' own time ([`GUESS_TIME`]), by assembling at t = 0 and following the motion
    /// to `t0` with every stepping safeguard, in steps that move the solution about 0.2 scene
    /// lengths or radians, at most [`MAX_CONTINUATION_STEPS`] of them; the state reached is the
    /// one continuous motion arrives at. The state then counts the continuation's steps in
    /// [`State::substeps`], and its work in [`State::iterations`] and [`State::evaluations`].
    ///
    /// # Errors
    /// An [`AssemblyError`]: the [`SolveError`] of the solve at `t0`, with the solver handed
    /// back, so that the error is displayed with the scene's names (and converts into the
    /// plain [`SolveError`] with `?`).
    // Without an allocator the solver can only be handed back by value; the `Ok` variant, a
    // `Simulation` holding one, is larger still.
    #[allow(clippy::result_large_err)]
    pub fn new(mut solver: Solver<M>, t0: f64) -> Result<Self, AssemblyError<M>> {
        let mut current = State::new(solver.mechanism());
        solver.mechanism().initial_guess(&mut current.q);
        match solver.solve_into(t0, &mut current) {
            Ok(()) => Ok(Self::from_state(solver, current)),
            Err(error) if error.is_step_related() && t0 != GUESS_TIME && t0.is_finite() => {
                Self::continue_to(solver, t0).map_err(|solver| AssemblyError { error, solver })
            }
            Err(error) => Err(AssemblyError { error, solver }),
        }
    }

    /// Assembles at [`GUESS_TIME`] and steps to `t0`; the solver back if either fails.
    #[allow(clippy::result_large_err)]
    fn continue_to(mut solver: Solver<M>, t0: f64) -> Result<Self, Solver<M>> {
        let mut current = State::new(solver.mechanism());
        solver.mechanism().initial_guess(&mut current.q);
        if solver.solve_into(GUESS_TIME, &mut current).is_err() {
            return Err(solver);
        }
        let mut simulation = Self::from_state(solver, current);
        let mut h = (t0 - GUESS_TIME) * FIRST_STEP;
        let (mut steps, mut iterations, mut evaluations) = (0, 0, 0);
        loop {
            let reached = simulation.state().t;
            if reached == t0 {
                break;
            }
            if steps == MAX_CONTINUATION_STEPS {
                return Err(simulation.solver);
            }
            // Within a hair of the end, take the end exactly rather than leave a sliver.
            let target = if (t0 - reached).abs() <= 1.000_001 * h.abs() {
                t0
            } else {
                reached + h
            };
            let state = match simulation.step_to(target) {
                Ok(state) => state,
                Err(_) => return Err(simulation.solver),
            };
            (iterations, evaluations) = (
                iterations + state.iterations,
                evaluations + state.evaluations,
            );
            let cut = state.substeps > 1;
            steps += 1;
            h *= if cut {
                // The step had to be cut: the next one starts shorter.
                0.5
            } else {
                let (state, previous) = (
                    &simulation.states[simulation.newest],
                    &simulation.states[1 - simulation.newest],
                );
                let motion = simulation.solver.scaled_distance(&previous.q, &state.q);
                if motion > 0.0 {
                    (STEP_MOTION / motion).clamp(0.5, 2.0)
                } else {
                    2.0
                }
            };
        }
        let state = &mut simulation.states[simulation.newest];
        (state.substeps, state.iterations, state.evaluations) = (steps, iterations, evaluations);
        Ok(simulation)
    }
}

/// A failed [`Simulation::new`]: the error, and the solver it came from, so that the error can
/// be displayed with the scene's names ([`Solver::describe`]; `Display` and `Debug` do it) and
/// the solver reused (with other options or parameters).
pub struct AssemblyError<M: Structured>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// What went wrong, and when.
    pub error: SolveError,
    /// The solver, with the diagnosis of a [`SolveError::Singular`].
    pub solver: Solver<M>,
}

impl<M: Structured> fmt::Display for AssemblyError<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.solver.describe(&self.error))
    }
}

/// The named description, so that `unwrap` and `expect` show it.
impl<M: Structured> fmt::Debug for AssemblyError<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{self}")
    }
}

impl<M: Structured> core::error::Error for AssemblyError<M> where DefaultAllocator: Storage<M::Dim> {}

impl<M: Structured> From<AssemblyError<M>> for SolveError
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn from(failure: AssemblyError<M>) -> Self {
        failure.error
    }
}
