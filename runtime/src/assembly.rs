//! Assembly: the first state of a [`Simulation`], at any start time.
//!
//! A scene's `near` guesses describe the mechanism at t = 0 ([`GUESS_TIME`]), and the state a
//! simulation starts from at t0 must be the one continuous motion from there reaches. Newton
//! from the guesses directly at t0 cannot promise that: it accepts whatever it converges to,
//! and a Newton block has a mirror solution (a lever on the other side of its pin, a ram on the
//! other side of its crank) as good as the right one, or a singular one (two circles of a
//! Peaucellier cell made to coincide). So a scene with Newton blocks is assembled at t = 0,
//! where the guesses fit, and followed in time to t0 (a homotopy in t along the drivers) with
//! every safeguard of stepping: the predictor, the jump and crossing checks, sub-stepping. The
//! steps adapt so that the blocks' coordinates move about [`STEP_MOTION`] (scene lengths,
//! radians) per step, and their number is bounded ([`MAX_CONTINUATION_STEPS`]): a start time
//! further than that is refused ([`SolveError::Unreachable`]), as is one the motion cannot reach
//! (the error of the step where it stops: a toggle, a lock). A scene whose coordinates are all
//! assigned in closed form has one solution at every time and is solved at t0 directly.

use core::fmt;

use nalgebra::DefaultAllocator;

use crate::error::SolveError;
use crate::mechanism::Storage;
use crate::simulate::Simulation;
use crate::solver::Solver;
use crate::state::State;
use crate::structure::{Stage, Structured};

/// The time the scene's `near` guesses describe.
pub const GUESS_TIME: f64 = 0.0;
/// Scaled motion of the blocks' coordinates (scene lengths, radians) a continuation step aims
/// for: small enough that the predictor lands within Newton's quadratic basin, large enough to
/// cover a turn in ~30 steps.
const STEP_MOTION: f64 = 0.2;
/// The first continuation step, as a fraction of the interval (grown by the motion rule).
const FIRST_STEP: f64 = 1.0 / 1024.0;
/// Most continuation steps before a start time counts as out of reach: bounds the work of
/// [`Simulation::new`] (each step is itself bounded by the sub-stepping limit).
pub const MAX_CONTINUATION_STEPS: usize = 100_000;

impl<M: Structured> Simulation<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Assembles the mechanism at `t0` on the state continuous motion from its declared
    /// initial guess at t = 0 ([`GUESS_TIME`]) reaches (predictor on). At `t0` = 0, or for a
    /// scene without Newton blocks (every coordinate in closed form: one solution), Newton
    /// solves at `t0` directly; otherwise the mechanism is assembled at t = 0 and the motion
    /// followed to `t0` with every stepping safeguard, in steps that move the blocks'
    /// coordinates about 0.2 scene lengths or radians, at most [`MAX_CONTINUATION_STEPS`] of
    /// them. The state then counts the continuation's steps in [`State::substeps`], and its
    /// work in [`State::iterations`] and [`State::evaluations`]. A guess with links in line
    /// (a stationary point of the residual) is left on the side that gives the declared
    /// branches, if either does.
    ///
    /// # Errors
    /// An [`AssemblyError`]: the [`SolveError`] of the assembly at t = 0 (the guesses describe
    /// t = 0, so a scene that cannot be assembled there has no motion to follow, even where
    /// its drivers are defined later), of the step where the motion stops (a toggle, a lock:
    /// `t0` is out of its reach), or [`SolveError::Unreachable`] when `t0` is further than the
    /// step budget; with the solver handed back, so that the error is displayed with the
    /// scene's names (and converts into the plain [`SolveError`] with `?`).
    // Without an allocator the solver can only be handed back by value; the `Ok` variant, a
    // `Simulation` holding one, is larger still.
    #[allow(clippy::result_large_err)]
    pub fn new(mut solver: Solver<M>, t0: f64) -> Result<Self, AssemblyError<M>> {
        let mut current = State::new(solver.mechanism());
        let direct = t0 == GUESS_TIME || !t0.is_finite() || !has_blocks(solver.mechanism());
        let start = if direct { t0 } else { GUESS_TIME };
        match assemble(&mut solver, start, &mut current) {
            Ok(()) if direct => Ok(Self::from_state(solver, current)),
            Ok(()) => Self::from_state(solver, current).follow_to(t0),
            Err(error) => Err(AssemblyError { error, solver }),
        }
    }

    /// Steps from the assembled state to `t0`, adapting the step to the blocks' motion.
    #[allow(clippy::result_large_err)]
    fn follow_to(mut self, t0: f64) -> Result<Self, AssemblyError<M>> {
        let mut h = (t0 - GUESS_TIME) * FIRST_STEP;
        let (mut steps, mut iterations, mut evaluations) = (0, 0, 0);
        loop {
            let reached = self.state().t;
            if reached == t0 {
                break;
            }
            if steps == MAX_CONTINUATION_STEPS {
                let error = SolveError::Unreachable {
                    time: t0,
                    reached,
                    steps,
                    names: self.solver.mechanism().names(),
                };
                return Err(AssemblyError {
                    error,
                    solver: self.solver,
                });
            }
            // Within a hair of the end, take the end exactly rather than leave a sliver.
            let target = if (t0 - reached).abs() <= 1.000_001 * h.abs() {
                t0
            } else {
                reached + h
            };
            let state = match self.step_to(target) {
                Ok(state) => state,
                Err(error) => {
                    return Err(AssemblyError {
                        error,
                        solver: self.solver,
                    });
                }
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
                let (state, previous) = (&self.states[self.newest], &self.states[1 - self.newest]);
                // Only the blocks' coordinates can lose their branch; a driven angle assigned
                // in closed form may move as far as it likes.
                let motion = self.solver.block_motion(&previous.q, &state.q);
                if motion > 0.0 {
                    (STEP_MOTION / motion).clamp(0.5, 2.0)
                } else {
                    2.0
                }
            };
        }
        let state = &mut self.states[self.newest];
        (state.substeps, state.iterations, state.evaluations) = (steps, iterations, evaluations);
        Ok(self)
    }
}

/// Solves from the declared guess at `t` into `state`. A guess with links in line is a
/// stationary point that Newton leaves along the Jacobian's null direction, on one side first;
/// when that side leads off a declared branch, the other side is tried (the branch the
/// declarations choose). Otherwise the first solve's error stands.
fn assemble<M: Structured>(
    solver: &mut Solver<M>,
    t: f64,
    state: &mut State<M>,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    solver.mechanism().initial_guess(&mut state.q);
    let error = match solver.solve_into(t, state) {
        Err(error @ SolveError::BranchFlip { .. }) => error,
        solved => return solved,
    };
    solver.escape_side = -1.0;
    solver.mechanism().initial_guess(&mut state.q);
    let other = solver.solve_into(t, state);
    solver.escape_side = 1.0;
    other.map_err(|_| error)
}

/// Whether any stage of the scene is a Newton block (which may have several solutions).
fn has_blocks<M: Structured>(m: &M) -> bool
where
    DefaultAllocator: Storage<M::Dim>,
{
    (0..m.stage_count()).any(|s| matches!(m.stage(s), Some(Stage::Block(_))))
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
