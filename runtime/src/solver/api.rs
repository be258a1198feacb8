//! The [`Solver`] type and its public methods: one instant's positions, rates and forces,
//! and the lists behind a [`SolveError::Singular`].

use nalgebra::DefaultAllocator;

use super::convergence::Convergence;
use super::sweep::Extras;

use crate::error::{Described, Quantity, SolveError};
use crate::mechanism::{Accelerations, LengthScale, Storage, Vector, Velocities};
use crate::options::{Rates, SolverOptions};
use crate::state::State;
use crate::structure::Structured;
use crate::workspace::Workspace;

/// Kinematic solver owning a mechanism and every buffer it needs.
///
/// All storage is created by [`Solver::new`]: the scene's [`Structured::Workspace`], sized by
/// its largest block. Solves never allocate, error paths included.
///
/// One instant, from the scene's guess:
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
/// use mechgen_runtime::{Mechanism, Solver, Vector, nalgebra::Const};
///
/// let mut solver = Solver::new(SliderCrank::default());
/// let mut guess = Vector::<Const<12>>::zeros();
/// solver.mechanism().initial_guess(&mut guess);
/// let state = solver.solve(0.05, &guess)?;
/// // q is in declaration order: frame, crank, rod, slider (x, y, θ each).
/// assert!((state.q[SliderCrank::CRANK_THETA] - 1.0).abs() < 1e-12);
/// let slider_speed = state.qd()[SliderCrank::SLIDER_X];
/// assert!(slider_speed < 0.0);
/// # Ok::<(), mechgen_runtime::SolveError>(())
/// ```
pub struct Solver<M: Structured>
where
    DefaultAllocator: Storage<M::Dim>,
{
    pub(crate) mechanism: M,
    pub(crate) options: SolverOptions,
    pub(super) workspace: M::Workspace,
    /// The length scale of the last solve, rounded to a power of two.
    pub(super) length: LengthScale,
    /// How many dependent equations and undetermined coordinates the last diagnosis found
    /// (heads of the workspace's diagnosis buffers).
    pub(super) diagnosed: (usize, usize),
    /// Which side of a stationary guess Newton leaves it by first (+1 or −1; see the
    /// `position` module's escape): [`crate::Simulation::new`] tries the other side when the
    /// first leads off a declared branch.
    pub(crate) escape_side: f64,
}

/// A copy with its own workspace (to run the same scene on another thread, or to restart
/// from a checkpoint).
impl<M: Structured + Clone> Clone for Solver<M>
where
    M::Workspace: Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    fn clone(&self) -> Self {
        Self {
            mechanism: self.mechanism.clone(),
            options: self.options,
            workspace: self.workspace.clone(),
            length: self.length,
            diagnosed: self.diagnosed,
            escape_side: self.escape_side,
        }
    }
}

impl<M: Structured> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// A solver with [`SolverOptions::default`].
    pub fn new(mechanism: M) -> Self {
        Self::with_options(mechanism, SolverOptions::default())
    }

    /// A solver with the given options.
    pub fn with_options(mechanism: M, options: SolverOptions) -> Self {
        Self {
            workspace: mechanism.workspace(),
            mechanism,
            options,
            length: LengthScale::new(1.0),
            diagnosed: (0, 0),
            escape_side: 1.0,
        }
    }

    /// The mechanism.
    pub fn mechanism(&self) -> &M {
        &self.mechanism
    }

    /// The mechanism, for setting parameters between solves. Its `dim()` must not change.
    pub fn mechanism_mut(&mut self) -> &mut M {
        &mut self.mechanism
    }

    /// Gives the mechanism back.
    pub fn into_mechanism(self) -> M {
        self.mechanism
    }

    /// The current options.
    pub fn options(&self) -> &SolverOptions {
        &self.options
    }

    /// Replaces the options.
    pub fn set_options(&mut self, options: SolverOptions) {
        self.options = options;
    }

    /// After a [`SolveError::Singular`]: every dependent (redundant) equation of the block that
    /// failed, ascending. Empty otherwise.
    pub fn dependent_equations(&self) -> &[usize] {
        let (rows, _) = self.workspace.diagnosis();
        rows.get(..self.diagnosed.0).unwrap_or(&[])
    }

    /// After a [`SolveError::Singular`]: every coordinate left undetermined, ascending: those of
    /// the failed block the dependent equations leave free, and those of every later stage
    /// computed from them.
    pub fn undetermined_coordinates(&self) -> &[usize] {
        let (_, columns) = self.workspace.diagnosis();
        columns.get(..self.diagnosed.1).unwrap_or(&[])
    }

    /// Displays `error` with the scene's names and, for the [`SolveError::Singular`] this
    /// solver just returned, every dependent equation and undetermined coordinate.
    pub fn describe<'a>(&'a self, error: &'a SolveError) -> Described<'a, M> {
        let (dependent, undetermined) = match error {
            SolveError::Singular { .. } => {
                (self.dependent_equations(), self.undetermined_coordinates())
            }
            _ => (&[][..], &[][..]),
        };
        Described {
            error,
            mechanism: &self.mechanism,
            dependent,
            undetermined,
        }
    }

    /// Positions (from `q_guess`) at `t`, and the derivatives the scene provides.
    ///
    /// Allocates the returned state for `Dyn` mechanisms; use [`Solver::solve_into`] to reuse one.
    ///
    /// # Errors
    /// As [`Solver::solve_into`].
    pub fn solve(&mut self, t: f64, q_guess: &Vector<M::Dim>) -> Result<State<M>, SolveError> {
        self.check_len(q_guess).map_err(|e| self.named(e))?;
        let mut state = State::new(&self.mechanism);
        state.q.copy_from(q_guess);
        self.solve_into(t, &mut state)?;
        Ok(state)
    }

    /// `error` with the scene's names: every error a public method returns goes through here.
    fn named(&self, error: SolveError) -> SolveError {
        error.named(self.mechanism.names())
    }

    /// Solves positions starting from `state.q`, and the derivatives the scene provides, into
    /// `state`, stage by stage: each block's velocities and accelerations are solved with the
    /// factors its Newton iteration ends with. A scene that computes forces then solves
    /// `Φ_qᵀ λ = F` with the same factors, stage by stage in reverse, into the state's
    /// reactions ([`crate::Forces`]). On error `state` is partly updated.
    ///
    /// # Errors
    /// Any [`SolveError`] of the position, velocity, acceleration or force solve.
    pub fn solve_into(&mut self, t: f64, state: &mut State<M>) -> Result<(), SolveError> {
        self.solve_state(t, state).map_err(|e| self.named(e))
    }

    /// [`Solver::solve_into`], with unnamed errors.
    fn solve_state(&mut self, t: f64, state: &mut State<M>) -> Result<(), SolveError> {
        self.check_len(&state.velocities)?;
        self.check_len(&state.accelerations)?;
        self.check_len(&state.reactions)?;
        let rates = Rates::of(self.mechanism.outputs());
        let convergence = self.solve_stages(
            t,
            &mut state.q,
            &mut state.velocities,
            &mut state.accelerations,
            rates,
            Some(Extras {
                reactions: &mut state.reactions,
                markers: &mut state.markers,
            }),
        )?;
        state.t = t;
        state.iterations = convergence.iterations;
        state.condition = convergence.condition;
        state.evaluations = convergence.evaluations;
        state.fallbacks = convergence.fallbacks;
        state.orientation = convergence.orientation;
        state.block_signs = convergence.block_signs;
        state.swept = convergence.swept;
        Ok(())
    }

    /// Newton–Raphson on Φ(q, t) = 0, starting from and overwriting `q`: explicit stages are
    /// assigned, each block is solved by Newton's method on its own equations (see the
    /// `position` module for the stopping rule and the safeguards). At each block's solution the
    /// condition of its scaled Jacobian must be below `max_condition`, and at the end every
    /// branch invariant of the scene positive.
    ///
    /// # Errors
    /// [`SolveError::NonFinite`] for a non-finite `t`, parameter, guess, Φ, Φ_q or step;
    /// [`SolveError::Singular`] at a solution where a block is singular or too
    /// ill-conditioned (the solver then lists every dependent equation:
    /// [`Solver::dependent_equations`]); [`SolveError::NoAssembly`] when a block's residual
    /// stops decreasing above the tolerance; [`SolveError::BranchFlip`] for a solution on
    /// another branch; [`SolveError::NoConvergence`] after `max_iterations` updates of a block.
    /// `q` holds the last iterate.
    pub fn solve_position(
        &mut self,
        q: &mut Vector<M::Dim>,
        t: f64,
    ) -> Result<Convergence, SolveError> {
        let (mut qd, mut qdd) = (q.clone(), q.clone());
        self.solve_stages(t, q, &mut qd, &mut qdd, Rates::None, None)
            .map_err(|e| self.named(e))
    }
}

impl<M: Structured + Velocities> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Solves Φ_q q̇ = ν at positions `q` (assumed to satisfy Φ = 0) into `qd`.
    ///
    /// # Errors
    /// [`SolveError::NonFinite`] or [`SolveError::Singular`] as for positions.
    pub fn solve_velocity(
        &mut self,
        q: &Vector<M::Dim>,
        t: f64,
        qd: &mut Vector<M::Dim>,
    ) -> Result<(), SolveError> {
        let mut qdd = q.clone();
        self.check_inputs(t, q, Quantity::Guess)
            .and_then(|()| self.check_len(qd))
            .and_then(|()| self.rate_stages(t, q, qd, &mut qdd, Rates::Velocities))
            .map_err(|e| self.named(e))
    }
}

impl<M: Structured + Accelerations> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Solves Φ_q q̈ = γ(q, q̇, t) into `qdd`.
    ///
    /// # Errors
    /// [`SolveError::NonFinite`] or [`SolveError::Singular`] as for positions.
    pub fn solve_acceleration(
        &mut self,
        q: &Vector<M::Dim>,
        qd: &Vector<M::Dim>,
        t: f64,
        qdd: &mut Vector<M::Dim>,
    ) -> Result<(), SolveError> {
        let mut velocities = qd.clone();
        self.check_inputs(t, q, Quantity::Guess)
            .and_then(|()| self.check_inputs(t, qd, Quantity::Velocity))
            .and_then(|()| self.check_len(qdd))
            .and_then(|()| self.rate_stages(t, q, &mut velocities, qdd, Rates::Both))
            .map_err(|e| self.named(e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dense::Dense;
    use crate::mechanism::Mechanism;
    #[cfg(feature = "alloc")]
    use crate::names::Names;
    use crate::pendulum::Pendulum;
    use nalgebra::U1;

    type Reference = Dense<Pendulum>;

    fn dense(pendulum: Pendulum) -> Solver<Reference> {
        Solver::new(Dense::new(pendulum))
    }

    fn assert_exact(state: &State<Reference>, mechanism: &Pendulum) {
        let exact = mechanism.exact(state.t);
        for (computed, expected) in [&state.q, &state.velocities, &state.accelerations]
            .into_iter()
            .zip(exact)
        {
            for (c, e) in computed.iter().zip(expected) {
                assert!((c - e).abs() <= 1e-12 * e.abs().max(1.0), "{c} vs {e}");
            }
        }
    }

    #[test]
    fn newton_converges_quadratically_to_the_closed_form() {
        let mut solver = dense(Pendulum::default());
        let mut guess = Vector::zeros_generic(nalgebra::Const, U1);
        solver.mechanism().initial_guess(&mut guess);
        let state = solver.solve(0.7, &guess).unwrap();
        assert_exact(&state, solver.mechanism().inner());
        assert!((1..=6).contains(&state.iterations), "{}", state.iterations);

        // From the solution itself one (null) update confirms convergence.
        let mut q = state.q;
        let convergence = solver.solve_position(&mut q, 0.7).unwrap();
        assert_eq!(convergence.iterations, 1);
        assert!(convergence.residual <= 1e-15);
    }

    #[test]
    fn factors_are_reused_only_after_a_round_off_correction() {
        let mut solver = dense(Pendulum::default());
        let exact = Vector::from(solver.mechanism().inner().exact(0.7)[0]);
        // With the rates: the factors at the result are needed.
        let evaluations = |solver: &mut Solver<Reference>, nudge: f64| {
            let mut q = exact;
            q[2] += nudge;
            let (mut qd, mut qdd) = (q, q);
            let convergence = solver
                .solve_stages(0.7, &mut q, &mut qd, &mut qdd, Rates::Both, None)
                .unwrap();
            (convergence.iterations, convergence.evaluations)
        };
        // From the solution: one update of round-off size, its factors kept.
        assert_eq!(evaluations(&mut solver, 0.0), (1, 1));
        // 1e-9 off: the second correction is ~1e-18, negligible: two evaluations.
        assert_eq!(evaluations(&mut solver, 1e-9), (2, 2));
        // 1e-6 off: the second correction (~1e-13) ends the iteration but is not negligible:
        // the block is evaluated and factored once more at the result.
        assert_eq!(evaluations(&mut solver, 1e-6), (2, 3));
        // Positions alone need no factors at the result.
        let mut q = exact;
        q[2] += 1e-6;
        let convergence = solver.solve_position(&mut q, 0.7).unwrap();
        assert_eq!((convergence.iterations, convergence.evaluations), (2, 2));
    }

    #[test]
    fn newton_takes_the_same_steps_at_any_length_scale() {
        let solve = |a: f64| {
            let mut solver = dense(Pendulum {
                a,
                ..Pendulum::default()
            });
            let mut q = Vector::from([0.9 * a, 0.3 * a, 0.4]);
            let convergence = solver.solve_position(&mut q, 0.7).unwrap();
            (convergence.iterations, q[2], convergence.condition)
        };
        let reference = solve(2.0);
        // Scaled by a power of two, the scaled problem is the same to the bit.
        for a in [2.0 * 2f64.powi(-20), 2.0 * 2f64.powi(14)] {
            assert_eq!(solve(a), reference, "a = {a}");
        }
        // Otherwise the scale is rounded to a power of two, which leaves the scaled entries
        // within a factor of two of these: the same iterations and solution.
        for a in [2e-6, 2e4] {
            let (iterations, theta, _) = solve(a);
            assert_eq!(iterations, reference.0, "a = {a}");
            assert!((theta - reference.1).abs() < 1e-14, "a = {a}");
        }
    }

    #[test]
    fn a_guess_half_a_turn_away_still_converges() {
        let mut solver = dense(Pendulum::default());
        // The rod guessed pointing the other way, its angle 3 rad off: steps are clamped and
        // damped rather than thrown across the plane.
        let mut q = Vector::from([-2.0, 0.0, 0.7 + 3.0]);
        let convergence = solver.solve_position(&mut q, 0.7 / 1.5).unwrap();
        let exact = Pendulum::default().exact(0.7 / 1.5);
        assert!(
            (q[0] - exact[0][0]).abs() < 1e-12,
            "{q:?} after {convergence:?}"
        );
    }

    #[test]
    fn separate_velocity_and_acceleration_solves_agree() {
        let mut solver = dense(Pendulum::default());
        let q = Vector::from(solver.mechanism().inner().exact(2.0)[0]);
        let mut qd = Vector::<nalgebra::Const<3>>::zeros();
        let mut qdd = qd;
        solver.solve_velocity(&q, 2.0, &mut qd).unwrap();
        solver.solve_acceleration(&q, &qd, 2.0, &mut qdd).unwrap();
        let mut state = State::new(solver.mechanism());
        (state.t, state.q, state.velocities, state.accelerations) = (2.0, q, qd, qdd);
        assert_exact(&state, solver.mechanism().inner());
    }

    #[test]
    fn iteration_cap_reports_no_convergence() {
        let options = SolverOptions {
            max_iterations: 1,
            ..SolverOptions::default()
        };
        let mut solver = Solver::with_options(Dense::new(Pendulum::default()), options);
        let mut q = Vector::from([0.0, 0.0, 3.0]);
        let error = solver.solve_position(&mut q, 0.0).unwrap_err();
        assert!(matches!(
            error,
            SolveError::NoConvergence {
                time: 0.0,
                iterations: 1,
                ..
            }
        ));
    }

    #[test]
    fn singular_jacobian_names_the_duplicate_equation() {
        let pendulum = Pendulum {
            duplicate_pin: true,
            ..Pendulum::default()
        };
        let mut solver = dense(pendulum);
        let error = solver
            .solve(1.0, &Vector::from([2.0, 0.0, 0.0]))
            .unwrap_err();
        let SolveError::Singular {
            equation,
            coordinate,
            ..
        } = error
        else {
            panic!("expected a singular Jacobian, got {error:?}");
        };
        assert_eq!((equation, coordinate), (2, 2));
    }

    #[test]
    fn non_finite_inputs_and_evaluations_are_reported() {
        let mut solver = dense(Pendulum::default());
        let good = Vector::from([2.0, 0.0, 0.0]);
        let quantity = |result: Result<State<Reference>, SolveError>| match result {
            Err(SolveError::NonFinite { quantity, .. }) => quantity,
            other => panic!("expected NonFinite, got {other:?}"),
        };
        assert_eq!(quantity(solver.solve(f64::NAN, &good)), Quantity::Time);
        let bad = Vector::from([2.0, f64::INFINITY, 0.0]);
        assert_eq!(quantity(solver.solve(0.0, &bad)), Quantity::Guess);
        solver.mechanism_mut().inner_mut().a = f64::NAN;
        assert_eq!(quantity(solver.solve(0.0, &good)), Quantity::Phi);
        solver.mechanism_mut().inner_mut().a = 2.0;
        solver.mechanism_mut().inner_mut().omega = f64::INFINITY;
        assert_eq!(quantity(solver.solve(0.0, &good)), Quantity::Phi);
    }

    #[cfg(feature = "alloc")]
    #[test]
    fn dyn_mechanisms_solve_and_reject_wrong_lengths() {
        use crate::pendulum::DynPendulum;
        use nalgebra::DVector;

        let mut solver = Solver::new(Dense::new(DynPendulum(Pendulum::default())));
        let state = solver
            .solve(0.7, &DVector::from_row_slice(&[2.0, 0.1, 0.1]))
            .unwrap();
        let exact = Pendulum::default().exact(0.7);
        assert!((state.accelerations[1] - exact[2][1]).abs() < 1e-12);

        let mismatch = SolveError::DimensionMismatch {
            expected: 3,
            found: 2,
            names: &Names::NONE,
        };
        assert_eq!(solver.solve(0.7, &DVector::zeros(2)).err(), Some(mismatch));
        let mut short = state.clone();
        short.accelerations = DVector::zeros(2);
        assert_eq!(solver.solve_into(0.7, &mut short), Err(mismatch));
        let mut long = DVector::zeros(4);
        assert!(solver.solve_position(&mut long, 0.7).is_err());
    }
}
