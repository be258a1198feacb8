//! Stepping a mechanism through time, warm-starting each Newton solve from a Taylor predictor.

use nalgebra::DefaultAllocator;

use crate::error::SolveError;
use crate::mechanism::{Mechanism, Outputs, Storage};
use crate::solver::Solver;
use crate::state::State;

/// A solver plus the last solved state, advanced with [`Simulation::step_to`].
///
/// Holds two states and swaps them, so stepping never allocates and a failed step leaves the
/// last good state untouched.
pub struct Simulation<M: Mechanism>
where
    DefaultAllocator: Storage<M::Dim>,
{
    solver: Solver<M>,
    current: State<M>,
    /// Scratch for the next solve; after a step it holds the state before `current`.
    next: State<M>,
    /// Whether `next` holds a solved earlier state (for the positions-only predictor).
    has_previous: bool,
    predictor: bool,
}

impl<M: Mechanism> Simulation<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Assembles the mechanism at `t0` from its declared initial guess (predictor on).
    ///
    /// # Errors
    /// The [`SolveError`] of the first solve (the solver is dropped with it).
    pub fn new(mut solver: Solver<M>, t0: f64) -> Result<Self, SolveError> {
        let mut current = State::new(solver.mechanism());
        solver.mechanism().initial_guess(&mut current.q);
        solver.solve_into(t0, &mut current)?;
        Ok(Self {
            next: current.clone(),
            solver,
            current,
            has_previous: false,
            predictor: true,
        })
    }

    /// Turns the second-order predictor on or off (off: each solve starts from the last `q`).
    pub fn set_predictor(&mut self, on: bool) {
        self.predictor = on;
    }

    /// Whether the predictor is on.
    pub fn predictor(&self) -> bool {
        self.predictor
    }

    /// The last solved state.
    pub fn state(&self) -> &State<M> {
        &self.current
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
    /// expansion `q + q̇ h + ½ q̈ h²` (`h = t − t_last`) with the derivatives the scene computes,
    /// or, for a positions-only scene, the secant through the last two solved positions. The
    /// second-order guess is O(h³) off, so Newton typically needs one or two updates.
    ///
    /// # Errors
    /// The [`SolveError`] of the solve at `t`; the simulation stays at the previous state.
    pub fn step_to(&mut self, t: f64) -> Result<&State<M>, SolveError> {
        let (current, next) = (&self.current, &mut self.next);
        let h = t - current.t;
        let predict = self.predictor && h.is_finite();
        let (q, qd, qdd) = (
            current.q.as_slice(),
            current.velocities.as_slice(),
            current.accelerations.as_slice(),
        );
        // Secant slope (q − q_prev)/h_prev for positions-only scenes, from the previous state
        // still held in `next`.
        let h_prev = current.t - next.t;
        let secant = self.has_previous && h_prev != 0.0 && h_prev.is_finite();
        let outputs = current.outputs();
        for (k, guess) in next.q.as_mut_slice().iter_mut().enumerate() {
            *guess = match outputs {
                _ if !predict => q[k],
                Outputs::Accelerations => q[k] + h * qd[k] + 0.5 * h * h * qdd[k],
                Outputs::Velocities => q[k] + h * qd[k],
                Outputs::Positions if secant => q[k] + (q[k] - *guess) * (h / h_prev),
                Outputs::Positions => q[k],
            };
        }
        self.solver.solve_into(t, next)?;
        core::mem::swap(&mut self.current, &mut self.next);
        self.has_previous = true;
        Ok(&self.current)
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
        visit(&self.current);
        let t_start = self.current.t;
        for k in 1..=steps {
            let state = self.step_to(sample_time(t_start, t_end, steps, k))?;
            visit(state);
        }
        Ok(())
    }
}

/// The k-th of `steps` equal steps from `t0` to `t_end`: `t0 + k·(t_end − t0)/steps`, computed
/// from the ends rather than accumulated (no drift), and exactly `t_end` at `k = steps`. Every
/// caller sampling a motion (the CLI, examples, tests) uses this so their times agree to the bit.
pub fn sample_time(t0: f64, t_end: f64, steps: usize, k: usize) -> f64 {
    if k >= steps {
        t_end
    } else {
        t0 + k as f64 * (t_end - t0) / steps as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pendulum::Pendulum;

    #[test]
    fn sample_times_hit_both_ends_and_are_not_accumulated() {
        assert_eq!(sample_time(0.0, 0.02, 10, 0), 0.0);
        assert_eq!(sample_time(0.0, 0.02, 10, 10), 0.02);
        assert_eq!(
            sample_time(0.0, 2.0 * core::f64::consts::PI / 314.0, 360, 360),
            2.0 * core::f64::consts::PI / 314.0
        );
        assert_eq!(sample_time(1.0, -1.0, 4, 2), 0.0);
        assert_eq!(sample_time(0.0, 1.0, 10, 3), 0.3);
        let accumulated = (0..3).fold(0.0, |t, _| t + 1.0 / 10.0);
        assert_ne!(accumulated, 0.3);
    }

    fn iterations(predictor: bool) -> usize {
        let mut simulation = Simulation::new(Solver::new(Pendulum::default()), 0.0).unwrap();
        simulation.set_predictor(predictor);
        let (mut total, mut calls, mut last_t) = (0, 0, 0.0);
        simulation
            .run(2.0, 40, |state| {
                let exact = Pendulum::default().exact(state.t);
                assert!((state.q.x - exact[0][0]).abs() < 1e-12);
                assert!((state.accelerations.y - exact[2][1]).abs() < 1e-12);
                (total, calls, last_t) = (total + state.iterations, calls + 1, state.t);
            })
            .unwrap();
        assert_eq!((calls, last_t), (41, 2.0));
        total
    }

    #[test]
    fn predictor_saves_newton_iterations() {
        let (with, without) = (iterations(true), iterations(false));
        assert!(with < without, "{with} with predictor, {without} without");
    }

    #[test]
    fn failed_step_keeps_the_last_state_and_reports_its_time() {
        let mut simulation = Simulation::new(Solver::new(Pendulum::default()), 0.0).unwrap();
        simulation.step_to(0.5).unwrap();
        simulation.solver_mut().mechanism_mut().a = f64::NAN;
        let error = simulation.step_to(0.75).unwrap_err();
        assert_eq!(error.time(), Some(0.75));
        assert_eq!(simulation.state().t, 0.5);
        assert!(simulation.step_to(f64::NAN).is_err());
        simulation.solver_mut().mechanism_mut().a = 2.0;
        assert_eq!(simulation.step_to(1.0).unwrap().t, 1.0);
    }
}
