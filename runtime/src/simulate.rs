//! Stepping a mechanism through time: each Newton solve warm-started from a predictor, checked
//! for a jump to another branch, and retried in sub-steps when it fails or jumps; and every
//! step checked for a singular configuration crossed between two solutions (see
//! [`crate::crossing`]). Assembly, the first state, is in [`crate::assembly`].

use nalgebra::DefaultAllocator;

use crate::error::{Quantity, SolveError};
use crate::mechanism::Storage;
use crate::prediction::Prediction;
use crate::solver::Solver;
use crate::state::State;
use crate::structure::Structured;

/// Default number of times a failed step may be halved; see [`Simulation::set_max_halvings`].
pub const DEFAULT_MAX_HALVINGS: u32 = 10;

/// A solver plus the last solved state, advanced with [`Simulation::step_to`].
///
/// Holds four states and alternates between two of them, so stepping never allocates (nor
/// copies a state on the usual path) and a failed step leaves the last good state untouched.
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
/// use mechgen_runtime::{Simulation, Solver};
///
/// let mut simulation = Simulation::new(Solver::new(SliderCrank::default()), 0.0)?;
/// // A revolution of the crank in 100 steps, visiting every state.
/// let period = core::f64::consts::TAU / 10.0;
/// let mut top = f64::MIN;
/// simulation.run(period, 100, |state| top = top.max(state.slider().x))?;
/// // The slider's furthest position: crank and rod in line.
/// assert!((top - 140.0).abs() < 0.1);
/// # Ok::<(), mechgen_runtime::SolveError>(())
/// ```
pub struct Simulation<M: Structured>
where
    DefaultAllocator: Storage<M::Dim>,
{
    pub(crate) solver: Solver<M>,
    /// The current state, `states[newest]`, and the scratch for the next solve, which after a
    /// step holds the state before the current one.
    pub(crate) states: [State<M>; 2],
    pub(crate) newest: usize,
    /// The state a sub-stepped step started from, restored if it fails.
    saved: State<M>,
    /// The latest solution before a singular crossing, while the crossing is located.
    pub(crate) bracket: State<M>,
    /// The last prediction, to measure how far Newton moved from it.
    pub(crate) prediction: Prediction<M>,
    /// Whether `next` holds a solved earlier state: the predictor's differences with it, and
    /// the coordinates of the guess the prediction leaves as they are.
    pub(crate) has_previous: bool,
    predictor: bool,
    max_halvings: u32,
}

/// A checkpoint: the copy continues from the same state, with the same history.
impl<M: Structured + Clone> Clone for Simulation<M>
where
    M::Workspace: Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    fn clone(&self) -> Self {
        Self {
            solver: self.solver.clone(),
            states: self.states.clone(),
            newest: self.newest,
            saved: self.saved.clone(),
            bracket: self.bracket.clone(),
            prediction: self.prediction.clone(),
            has_previous: self.has_previous,
            predictor: self.predictor,
            max_halvings: self.max_halvings,
        }
    }
}

/// How one predicted solve ended.
enum Outcome {
    Solved,
    /// Converged, but far from the prediction: possibly on another branch.
    Jumped,
    /// Converged with the other sign of det Φ_q: a singular configuration lies between.
    Crossed,
    Failed(SolveError),
}

impl<M: Structured> Simulation<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// A simulation starting from `current`, a solved state (predictor on).
    pub(crate) fn from_state(solver: Solver<M>, mut current: State<M>) -> Self {
        current.substeps = current.substeps.max(1);
        Self {
            saved: current.clone(),
            bracket: current.clone(),
            prediction: Prediction::new(&current),
            states: [current.clone(), current],
            newest: 0,
            solver,
            has_previous: false,
            predictor: true,
            max_halvings: DEFAULT_MAX_HALVINGS,
        }
    }

    /// Turns the third-order predictor on or off (off: each solve starts from the last `q`).
    pub fn set_predictor(&mut self, on: bool) {
        self.predictor = on;
    }

    /// Whether the predictor is on.
    pub fn predictor(&self) -> bool {
        self.predictor
    }

    /// How many times a failed step may be halved (default [`DEFAULT_MAX_HALVINGS`]; 0 turns
    /// sub-stepping off). A step of length h is never cut below h / 2^`halvings`.
    pub fn set_max_halvings(&mut self, halvings: u32) {
        self.max_halvings = halvings.min(60);
    }

    /// The last solved state.
    pub fn state(&self) -> &State<M> {
        &self.states[self.newest]
    }

    /// The solver (and through it the mechanism).
    pub fn solver(&self) -> &Solver<M> {
        &self.solver
    }

    /// The solver, for changing options or parameters between steps.
    pub fn solver_mut(&mut self) -> &mut Solver<M> {
        &mut self.solver
    }

    /// Gives the solver back.
    pub fn into_solver(self) -> Solver<M> {
        self.solver
    }

    /// Solves at `t`, starting Newton from a prediction when the predictor is on: the Taylor
    /// expansion `q + q̇ h + ½ q̈ h² + ⅙ q⃛ h³` (`h = t − t_last`) with the derivatives the scene
    /// computes and one more from the difference with the previous state (the jerk from the
    /// last two accelerations), or, for a positions-only scene, the secant through the last two
    /// solved positions; of the Newton blocks' coordinates only, the ones Newton starts from
    /// (explicit stages assign theirs whatever the guess). The third-order guess is O(h⁴) off,
    /// so Newton typically needs two updates, the second of round-off size (whose factors then
    /// serve the rates).
    ///
    /// When that solve fails in a way a shorter step may cure (no convergence, no assembly, a
    /// branch flip, a singular solution), predicts a turn of more than a radian of a block's
    /// angle, or lands suspiciously far from the prediction (the mirror branch), the
    /// drivers are sub-stepped: the interval is halved, and halved again on failure, down to
    /// 2^-`max_halvings` of it, each sub-step predicted from the last. The state then records the
    /// sub-steps taken ([`State::substeps`]) and all their Newton iterations, evaluations and
    /// fallbacks.
    ///
    /// # Errors
    /// The [`SolveError`] of the solve at `t`, or of the sub-step that could not be shortened
    /// further (with its time); the simulation stays at the previous state.
    pub fn step_to(&mut self, t: f64) -> Result<&State<M>, SolveError> {
        // The names are `'static`: naming a failure borrows nothing from the simulation.
        let names = self.solver.mechanism().names();
        self.step(t).map_err(|e| e.named(names))
    }

    /// [`Simulation::step_to`], with errors from the solver (named) and of its own (not yet).
    fn step(&mut self, t: f64) -> Result<&State<M>, SolveError> {
        if !t.is_finite() {
            return Err(crate::finite::non_finite(t, Quantity::Time));
        }
        match self.advance(t, false) {
            Outcome::Solved => {}
            Outcome::Failed(error) if !retryable(&error) || self.max_halvings == 0 => {
                return Err(error);
            }
            Outcome::Jumped if self.max_halvings == 0 => self.accept(),
            Outcome::Crossed if self.max_halvings == 0 => {
                self.locate_crossing(t)?;
                self.accept();
            }
            // A coarse step may land on the mirror branch, whose determinant has the other
            // sign: sub-step first, and locate a crossing that persists at the finest sub-step.
            Outcome::Failed(_) | Outcome::Jumped | Outcome::Crossed => return self.substep(t),
        }
        let current = &mut self.states[self.newest];
        current.substeps = 1;
        Ok(current)
    }

    /// Reaches `t_end` in sub-steps from `current`; see [`Simulation::step_to`].
    fn substep(&mut self, t_end: f64) -> Result<&State<M>, SolveError> {
        self.saved.copy_from(&self.states[self.newest]);
        let t_start = self.saved.t;
        let shortest = (t_end - t_start).abs() / (1_u64 << self.max_halvings) as f64;
        let mut h = 0.5 * (t_end - t_start);
        let (mut substeps, mut iterations, mut successes) = (0, 0, 0);
        let (mut evaluations, mut fallbacks) = (0, 0);
        loop {
            let reached = self.states[self.newest].t;
            let remaining = t_end - reached;
            if remaining == 0.0 {
                let current = &mut self.states[self.newest];
                current.substeps = substeps;
                current.iterations = iterations;
                current.evaluations = evaluations;
                current.fallbacks = fallbacks;
                return Ok(current);
            }
            // Within a hair of the end, take the end exactly rather than leave a sliver.
            let target = if remaining.abs() <= 1.000_001 * h.abs() {
                t_end
            } else {
                reached + h
            };
            // At the shortest sub-step a jump is accepted: continuation from the last state is
            // as close to the motion as stepping can get (declared branches are still checked).
            let finest = 0.5 * h.abs() < shortest;
            let mut outcome = self.advance(target, finest);
            // At the finest sub-step the prediction is too close to jump: a change of
            // determinant sign, or of a declared branch, is a crossing to locate.
            let crossed = matches!(
                outcome,
                Outcome::Crossed | Outcome::Failed(SolveError::BranchFlip { .. })
            );
            if crossed && finest {
                outcome = self.settle_crossing(target)?;
            }
            match outcome {
                Outcome::Solved => {
                    let current = &self.states[self.newest];
                    (substeps, iterations) = (substeps + 1, iterations + current.iterations);
                    evaluations += current.evaluations;
                    fallbacks += current.fallbacks;
                    successes += 1;
                    // Two good sub-steps in a row: try a longer one (never beyond half the step).
                    if successes >= 2 && 2.0 * h.abs() <= 0.5 * (t_end - t_start).abs() {
                        (h, successes) = (2.0 * h, 0);
                    }
                }
                Outcome::Failed(error) if !retryable(&error) || finest => {
                    self.states[self.newest].copy_from(&self.saved);
                    return Err(error);
                }
                Outcome::Failed(_) | Outcome::Jumped | Outcome::Crossed => {
                    (h, successes) = (0.5 * h, 0);
                }
            }
        }
    }

    /// A crossing at the finest sub-step to `target`, located and accepted; on failure the
    /// state the step started from is restored.
    ///
    /// # Errors
    /// [`Simulation::locate_crossing`]'s.
    fn settle_crossing(&mut self, target: f64) -> Result<Outcome, SolveError> {
        match self.locate_crossing(target) {
            Ok(()) => {
                self.accept();
                Ok(Outcome::Solved)
            }
            Err(error) => {
                self.states[self.newest].copy_from(&self.saved);
                Err(error)
            }
        }
    }

    /// One predicted solve at `t` into `next`; on success `next` becomes `current`, except for
    /// a suspected jump, which is left unaccepted unless `accept_jump`.
    // Always inlined: the usual step is one `advance`, and its large `Outcome` is then not
    // moved through memory, nor its call made (~20 instructions of the seed's ~1,200 a step,
    // which a plain `#[inline]` left out once the prediction moved to its own module).
    #[inline(always)]
    fn advance(&mut self, t: f64, accept_jump: bool) -> Outcome {
        let (current, next) = pair(&mut self.states, self.newest);
        let history = self.has_previous;
        let predicted = self.predictor
            && self
                .prediction
                .predict(&self.solver, current, next, history, t);
        if !predicted {
            next.q.copy_from(&current.q);
        }
        // From here `next` no longer holds the previous state, whatever the outcome.
        self.has_previous = false;
        if let Err(error) = self.solver.solve_predicted(t, next) {
            return Outcome::Failed(error);
        }
        if predicted && !accept_jump && self.prediction.jumped(&self.solver, &next.q) {
            return Outcome::Jumped;
        }
        if next.block_signs != current.block_signs || next.swept {
            return Outcome::Crossed;
        }
        self.accept();
        Outcome::Solved
    }

    /// Makes `next` the current state.
    pub(crate) fn accept(&mut self) {
        self.newest = 1 - self.newest;
        self.has_previous = true;
    }

    /// Calls `visit` with the current state, then steps `steps` times to `t_end` in equal steps,
    /// calling `visit` after each (so `steps + 1` calls when all succeed).
    ///
    /// # Errors
    /// The first failed step's [`SolveError`] (with its time); earlier states were visited.
    pub fn run(
        &mut self,
        t_end: f64,
        steps: usize,
        mut visit: impl FnMut(&State<M>),
    ) -> Result<(), SolveError> {
        visit(&self.states[self.newest]);
        let t_start = self.states[self.newest].t;
        for k in 1..=steps {
            let state = self.step_to(sample_time(t_start, t_end, steps, k))?;
            visit(state);
        }
        Ok(())
    }
}

/// Whether a failed solve is retried in shorter sub-steps: the failures a shorter step may cure
/// ([`SolveError::is_step_related`]), and a singular solution, which Newton may have reached
/// from a prediction off the motion (a Peaucellier cell's two circles made to coincide by a
/// long step); a toggle on the motion stays singular down to the finest sub-step, which then
/// reports it at its time.
fn retryable(error: &SolveError) -> bool {
    error.is_step_related() || matches!(error, SolveError::Singular { .. })
}

/// The state at `newest` and the other one.
pub(crate) fn pair<T>(states: &mut [T; 2], newest: usize) -> (&T, &mut T) {
    let [a, b] = states;
    if newest == 0 { (a, b) } else { (b, a) }
}

/// The k-th of `steps` equal steps from `t0` to `t_end`: `t0 + k·h` with
/// `h = (t_end − t0)/steps` (each time computed from `t0`, not accumulated, so there is no
/// drift), and exactly `t_end` at `k = steps`. This is the documented formula of
/// `mechgen solve --steps`, so a user can reproduce its times to the bit; every caller sampling
/// a motion (the CLI, examples, tests) uses it.
pub fn sample_time(t0: f64, t_end: f64, steps: usize, k: usize) -> f64 {
    if k >= steps {
        t_end
    } else {
        t0 + k as f64 * ((t_end - t0) / steps as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_times_hit_both_ends_and_are_not_accumulated() {
        assert_eq!(sample_time(0.0, 0.02, 10, 0), 0.0);
        assert_eq!(sample_time(0.0, 0.02, 10, 10), 0.02);
        assert_eq!(
            sample_time(0.0, 2.0 * core::f64::consts::PI / 314.0, 360, 360),
            2.0 * core::f64::consts::PI / 314.0
        );
        assert_eq!(sample_time(1.0, -1.0, 4, 2), 0.0);
        assert_eq!(sample_time(0.0, 1.0, 10, 3), 3.0 * 0.1);
        let accumulated = (0..3).fold(0.0, |t, _| t + 1.0 / 10.0);
        assert_ne!(accumulated, 0.3);
    }
}
