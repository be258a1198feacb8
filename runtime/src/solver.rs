//! Newton–Raphson positions and linear velocity/acceleration solves, sharing one workspace.

use nalgebra::{DefaultAllocator, Dim, U1};

use crate::error::{Quantity, SolveError};
use crate::lu::{DEFAULT_PIVOT_TOLERANCE, Lu, LuError};
use crate::mechanism::{Accelerations, Mechanism, Outputs, Storage, Vector, Velocities};
use crate::state::State;

/// Tolerances of the position solve and the factorisation.
///
/// Tolerances are relative to `max(1, ‖q‖∞)`, so they act as absolute tolerances for small
/// mechanisms and relative ones for large coordinates. Angles and lengths share the scale for
/// now; unit-aware scaling is left to the stability work.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverOptions {
    /// Converged when ‖Φ‖∞ ≤ `residual_tolerance · max(1, ‖q‖∞)` … (default 1e-10)
    pub residual_tolerance: f64,
    /// … and the Newton step taken from there has ‖Δq‖∞ ≤ `step_tolerance · max(1, ‖q‖∞)`
    /// (default 1e-10).
    pub step_tolerance: f64,
    /// Newton updates allowed before [`SolveError::NoConvergence`] (default 25).
    pub max_iterations: usize,
    /// Relative pivot tolerance; see [`Lu::set_pivot_tolerance`] (default
    /// [`DEFAULT_PIVOT_TOLERANCE`]).
    pub pivot_tolerance: f64,
}

impl Default for SolverOptions {
    fn default() -> Self {
        Self {
            residual_tolerance: 1e-10,
            step_tolerance: 1e-10,
            max_iterations: 25,
            pivot_tolerance: DEFAULT_PIVOT_TOLERANCE,
        }
    }
}

/// Outcome of a successful position solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Convergence {
    /// Newton updates applied (at least 1: the step that confirmed convergence is applied too).
    pub iterations: usize,
    /// ‖Φ‖∞ at the returned positions.
    pub residual: f64,
    /// [`Lu::rough_condition`] of Φ_q at the returned positions.
    pub condition: f64,
}

/// Kinematic solver owning a mechanism and every buffer it needs.
///
/// All storage is created by [`Solver::new`]; solves never allocate.
pub struct Solver<M: Mechanism>
where
    DefaultAllocator: Storage<M::Dim>,
{
    mechanism: M,
    options: SolverOptions,
    /// Φ, then reused in place for the Newton step.
    phi: Vector<M::Dim>,
    /// Factors of Φ_q at the last positions it was evaluated at.
    lu: Lu<M::Dim>,
}

impl<M: Mechanism> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// A solver with [`SolverOptions::default`].
    pub fn new(mechanism: M) -> Self {
        Self::with_options(mechanism, SolverOptions::default())
    }

    /// A solver with the given options.
    pub fn with_options(mechanism: M, options: SolverOptions) -> Self {
        let dim = mechanism.dim();
        let mut lu = Lu::new(dim);
        lu.set_pivot_tolerance(options.pivot_tolerance);
        Self {
            mechanism,
            options,
            phi: Vector::zeros_generic(dim, U1),
            lu,
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
        self.lu.set_pivot_tolerance(options.pivot_tolerance);
    }

    /// The factorisation of Φ_q from the last solve (for its condition estimate).
    pub fn lu(&self) -> &Lu<M::Dim> {
        &self.lu
    }

    /// Newton–Raphson on Φ(q, t) = 0, starting from and overwriting `q`.
    ///
    /// Each iteration evaluates Φ and Φ_q at `q`, factors Φ_q and applies the step Δq. Once a
    /// step within `step_tolerance` has been applied from a point whose residual was within
    /// `residual_tolerance`, Φ and Φ_q are evaluated and factored once more at the final `q`:
    /// the reported residual is the true one there, the factors the solver keeps are exactly
    /// those of Φ_q(q) (for [`Solver::solve_into`]), and that last step having been applied
    /// leaves `q` quadratically (not merely to within the step tolerance) accurate.
    ///
    /// # Errors
    /// [`SolveError::NonFinite`] for a non-finite `t`, guess, Φ, Φ_q or step;
    /// [`SolveError::Singular`] when Φ_q has no usable pivot at an iterate;
    /// [`SolveError::NoConvergence`] after `max_iterations` updates. `q` holds the last iterate.
    pub fn solve_position(
        &mut self,
        q: &mut Vector<M::Dim>,
        t: f64,
    ) -> Result<Convergence, SolveError> {
        self.check_inputs(t, q, Quantity::Guess)?;
        let Self {
            mechanism,
            options,
            phi,
            lu,
        } = self;
        let (mut iterations, mut converged) = (0, false);
        loop {
            let factored =
                lu.factor_with(|jacobian| mechanism.phi_and_jacobian(q, t, phi, jacobian));
            check_finite(phi, t, Quantity::Phi)?;
            factored.map_err(|error| lu_error(error, t))?;
            let residual = max_abs(phi);
            if converged {
                return Ok(Convergence {
                    iterations,
                    residual,
                    condition: lu.rough_condition().unwrap_or(f64::INFINITY),
                });
            }
            if iterations >= options.max_iterations {
                return Err(SolveError::NoConvergence {
                    time: t,
                    iterations,
                    residual,
                });
            }

            lu.solve_in_place(phi).map_err(|error| lu_error(error, t))?;
            // `phi` now holds Φ_q⁻¹ Φ = −Δq.
            let step = max_abs(phi);
            if !step.is_finite() {
                return Err(non_finite(t, Quantity::Step));
            }
            let scale = max_abs(q).max(1.0);
            converged = residual <= options.residual_tolerance * scale
                && step <= options.step_tolerance * scale;
            *q -= &*phi;
            iterations += 1;
            // A positions-only scene needs no factors at the returned q (nothing solves with
            // them): stop without the confirming evaluation; `residual` is then the one before
            // the last (tiny) step, an upper bound.
            if converged && mechanism.outputs() == Outputs::Positions {
                return Ok(Convergence {
                    iterations,
                    residual,
                    condition: lu.rough_condition().unwrap_or(f64::INFINITY),
                });
            }
        }
    }

    /// Positions (from `q_guess`) at `t`, and the derivatives the scene provides.
    ///
    /// Allocates the returned state for `Dyn` mechanisms; use [`Solver::solve_into`] to reuse one.
    ///
    /// # Errors
    /// As [`Solver::solve_into`].
    pub fn solve(&mut self, t: f64, q_guess: &Vector<M::Dim>) -> Result<State<M>, SolveError> {
        self.check_len(q_guess)?;
        let mut state = State::new(&self.mechanism);
        state.q.copy_from(q_guess);
        self.solve_into(t, &mut state)?;
        Ok(state)
    }

    /// Solves positions starting from `state.q`, then the derivatives the scene provides
    /// ([`Mechanism::derivatives`]), into `state`.
    ///
    /// Φ_q is factored once for both ν and γ solves: [`Solver::solve_position`] ends by
    /// evaluating and factoring Φ_q at the positions it returns, and those factors are reused.
    /// On error `state` is partly updated.
    ///
    /// # Errors
    /// Any [`SolveError`] of the position, velocity or acceleration solve.
    pub fn solve_into(&mut self, t: f64, state: &mut State<M>) -> Result<(), SolveError> {
        self.check_len(&state.velocities)?;
        self.check_len(&state.accelerations)?;
        let convergence = self.solve_position(&mut state.q, t)?;
        self.mechanism.derivatives(
            &state.q,
            t,
            &self.lu,
            &mut state.velocities,
            &mut state.accelerations,
        )?;
        state.t = t;
        state.iterations = convergence.iterations;
        Ok(())
    }

    fn factor_jacobian(&mut self, q: &Vector<M::Dim>, t: f64) -> Result<(), SolveError> {
        let mechanism = &self.mechanism;
        self.lu
            .factor_with(|jacobian| mechanism.jacobian(q, t, jacobian))
            .map_err(|error| lu_error(error, t))
    }

    /// Length and finiteness of an input, and finiteness of `t`.
    fn check_inputs(
        &self,
        t: f64,
        v: &Vector<M::Dim>,
        quantity: Quantity,
    ) -> Result<(), SolveError> {
        if !t.is_finite() {
            return Err(non_finite(t, Quantity::Time));
        }
        self.check_len(v)?;
        check_finite(v, t, quantity)
    }

    /// Only a `Dyn` vector can disagree with the workspace; nalgebra would panic on it.
    fn check_len(&self, v: &Vector<M::Dim>) -> Result<(), SolveError> {
        let expected = self.phi.nrows();
        if v.nrows() == expected && self.mechanism.dim().value() == expected {
            Ok(())
        } else {
            Err(SolveError::DimensionMismatch {
                expected,
                found: v.nrows(),
            })
        }
    }
}

impl<M: Velocities> Solver<M>
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
        self.check_inputs(t, q, Quantity::Guess)?;
        self.check_len(qd)?;
        self.factor_jacobian(q, t)?;
        solve_velocities(&self.mechanism, q, t, &self.lu, qd)
    }
}

impl<M: Accelerations> Solver<M>
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
        self.check_inputs(t, q, Quantity::Guess)?;
        self.check_inputs(t, qd, Quantity::Velocity)?;
        self.check_len(qdd)?;
        self.factor_jacobian(q, t)?;
        solve_accelerations(&self.mechanism, q, qd, t, &self.lu, qdd)
    }
}

/// Solves Φ_q q̇ = ν into `qd` with `factors`, the LU of Φ_q(q): the velocity half of
/// [`Mechanism::derivatives`] for scenes that compute velocities.
///
/// # Errors
/// [`SolveError::NonFinite`] for a non-finite ν or q̇; the factorisation's errors.
pub fn solve_velocities<M: Velocities>(
    mechanism: &M,
    q: &Vector<M::Dim>,
    t: f64,
    factors: &Lu<M::Dim>,
    qd: &mut Vector<M::Dim>,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    mechanism.nu(q, t, qd);
    check_finite(qd, t, Quantity::Nu)?;
    factors.solve_in_place(qd).map_err(|e| lu_error(e, t))?;
    check_finite(qd, t, Quantity::Velocity)
}

/// Solves Φ_q q̈ = γ(q, q̇, t) into `qdd` with `factors`, the LU of Φ_q(q): the acceleration
/// half of [`Mechanism::derivatives`].
///
/// # Errors
/// [`SolveError::NonFinite`] for a non-finite γ or q̈; the factorisation's errors.
pub fn solve_accelerations<M: Accelerations>(
    mechanism: &M,
    q: &Vector<M::Dim>,
    qd: &Vector<M::Dim>,
    t: f64,
    factors: &Lu<M::Dim>,
    qdd: &mut Vector<M::Dim>,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    mechanism.gamma(q, qd, t, qdd);
    check_finite(qdd, t, Quantity::Gamma)?;
    factors.solve_in_place(qdd).map_err(|e| lu_error(e, t))?;
    check_finite(qdd, t, Quantity::Acceleration)
}

/// ‖v‖∞ over the contiguous storage (nalgebra's `amax` iterates element by element, slowly).
fn max_abs<D: Dim>(v: &Vector<D>) -> f64
where
    DefaultAllocator: Storage<D>,
{
    v.as_slice().iter().fold(0.0, |m, x| m.max(x.abs()))
}

fn non_finite(time: f64, quantity: Quantity) -> SolveError {
    SolveError::NonFinite { time, quantity }
}

fn check_finite<D: Dim>(v: &Vector<D>, t: f64, quantity: Quantity) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<D>,
{
    if v.as_slice().iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(non_finite(t, quantity))
    }
}

fn lu_error(error: LuError, time: f64) -> SolveError {
    match error {
        LuError::Singular { row, column, pivot } => SolveError::Singular {
            time,
            equation: row,
            coordinate: column,
            pivot,
        },
        LuError::NonFinite => non_finite(time, Quantity::Jacobian),
        // The solver checks sizes and factors before every solve; map rather than panic.
        LuError::NotFactored => non_finite(time, Quantity::Jacobian),
        LuError::DimensionMismatch { expected, found } => {
            SolveError::DimensionMismatch { expected, found }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pendulum::Pendulum;

    fn assert_exact(state: &State<Pendulum>, mechanism: &Pendulum) {
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
        let mut solver = Solver::new(Pendulum::default());
        let mut guess = Vector::zeros_generic(nalgebra::Const, U1);
        solver.mechanism().initial_guess(&mut guess);
        let state = solver.solve(0.7, &guess).unwrap();
        assert_exact(&state, solver.mechanism());
        assert!((1..=6).contains(&state.iterations), "{}", state.iterations);

        // From the solution itself one (null) update confirms convergence.
        let mut q = state.q;
        let convergence = solver.solve_position(&mut q, 0.7).unwrap();
        assert_eq!(convergence.iterations, 1);
        assert!(convergence.residual <= 1e-15);
    }

    #[test]
    fn separate_velocity_and_acceleration_solves_agree() {
        let mut solver = Solver::new(Pendulum::default());
        let q = Vector::from(solver.mechanism().exact(2.0)[0]);
        let mut qd = Vector::<nalgebra::Const<3>>::zeros();
        let mut qdd = qd;
        solver.solve_velocity(&q, 2.0, &mut qd).unwrap();
        solver.solve_acceleration(&q, &qd, 2.0, &mut qdd).unwrap();
        let mut state = State::new(solver.mechanism());
        (state.t, state.q, state.velocities, state.accelerations) = (2.0, q, qd, qdd);
        assert_exact(&state, solver.mechanism());
    }

    #[test]
    fn iteration_cap_reports_no_convergence() {
        let options = SolverOptions {
            max_iterations: 1,
            ..SolverOptions::default()
        };
        let mut solver = Solver::with_options(Pendulum::default(), options);
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
        let mut solver = Solver::new(pendulum);
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
        let mut solver = Solver::new(Pendulum::default());
        let good = Vector::from([2.0, 0.0, 0.0]);
        let quantity = |result: Result<State<Pendulum>, SolveError>| match result {
            Err(SolveError::NonFinite { quantity, .. }) => quantity,
            other => panic!("expected NonFinite, got {other:?}"),
        };
        assert_eq!(quantity(solver.solve(f64::NAN, &good)), Quantity::Time);
        let bad = Vector::from([2.0, f64::INFINITY, 0.0]);
        assert_eq!(quantity(solver.solve(0.0, &bad)), Quantity::Guess);
        solver.mechanism_mut().a = f64::NAN;
        assert_eq!(quantity(solver.solve(0.0, &good)), Quantity::Phi);
        solver.mechanism_mut().a = 2.0;
        solver.mechanism_mut().omega = f64::INFINITY;
        assert_eq!(quantity(solver.solve(0.0, &good)), Quantity::Phi);
    }

    #[cfg(feature = "alloc")]
    #[test]
    fn dyn_mechanisms_solve_and_reject_wrong_lengths() {
        use crate::pendulum::DynPendulum;
        use nalgebra::DVector;

        let mut solver = Solver::new(DynPendulum(Pendulum::default()));
        let state = solver
            .solve(0.7, &DVector::from_row_slice(&[2.0, 0.1, 0.1]))
            .unwrap();
        let exact = Pendulum::default().exact(0.7);
        assert!((state.accelerations[1] - exact[2][1]).abs() < 1e-12);

        let mismatch = SolveError::DimensionMismatch {
            expected: 3,
            found: 2,
        };
        assert_eq!(solver.solve(0.7, &DVector::zeros(2)).err(), Some(mismatch));
        let mut short = state.clone();
        short.accelerations = DVector::zeros(2);
        assert_eq!(solver.solve_into(0.7, &mut short), Err(mismatch));
        let mut long = DVector::zeros(4);
        assert!(solver.solve_position(&mut long, 0.7).is_err());
    }
}
