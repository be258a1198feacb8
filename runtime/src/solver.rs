//! The solver: its options, its workspace, unit scaling, and the linear velocity and
//! acceleration solves. The position solve (Newton–Raphson with its safeguards) is in
//! `position.rs`.

use nalgebra::{DefaultAllocator, Dim, U1};

use crate::error::{Described, Quantity, SolveError};
use crate::lu::{DEFAULT_PIVOT_TOLERANCE, Lu, LuError};
use crate::mechanism::{Accelerations, Matrix, Mechanism, Storage, Vector, Velocities};
use crate::state::State;

/// Tolerances and safeguards of the position solve.
///
/// Tolerances apply to the unit-scaled system (see [`crate::Unit`]): lengths are measured in
/// units of the scene's [`Mechanism::length_scale`], angles in radians, and both relative to
/// `max(1, ‖D_c⁻¹ q‖∞)` (so a crank that has turned a million radians is still resolved to
/// round-off). The same options then suit a micro-mechanism in metres and an engine in
/// millimetres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverOptions {
    /// Converged when the scaled residual ‖D_r Φ‖∞ ≤ `residual_tolerance` … (default 1e-10;
    /// times `max(1, ‖D_c⁻¹ q‖∞)`)
    pub residual_tolerance: f64,
    /// … and the scaled Newton step taken from there is ≤ `step_tolerance` (default 1e-10).
    pub step_tolerance: f64,
    /// Updates (Newton, damped or Levenberg–Marquardt) before giving up (default 50).
    pub max_iterations: usize,
    /// Relative pivot tolerance of the scaled Φ_q; see [`Lu::set_pivot_tolerance`] (default
    /// [`DEFAULT_PIVOT_TOLERANCE`]).
    pub pivot_tolerance: f64,
    /// Largest condition estimate of the scaled Φ_q accepted at a solution (default 1e10).
    ///
    /// Velocities and accelerations lose about log₁₀(κ) digits, so 1e10 still leaves six; above
    /// it the solve fails with [`SolveError::Singular`] rather than return digits of noise.
    pub max_condition: f64,
    /// Largest scaled Newton step (default 1): a step is shortened to move no coordinate by
    /// more than this many scene lengths or radians, so a bad guess cannot throw the iterate
    /// across the mechanism.
    pub max_step: f64,
    /// Scale equations and coordinates by their units (default true). Off, tolerances and the
    /// condition estimate apply to raw values: only for measuring what scaling costs.
    pub scale_units: bool,
    /// Estimate the condition of Φ_q at every solution (default true). Off, `max_condition` is
    /// not checked and states report a NaN condition: only for measuring what the estimate costs.
    pub estimate_condition: bool,
}

impl Default for SolverOptions {
    fn default() -> Self {
        Self {
            residual_tolerance: 1e-10,
            step_tolerance: 1e-10,
            max_iterations: 50,
            pivot_tolerance: DEFAULT_PIVOT_TOLERANCE,
            max_condition: 1e10,
            max_step: 1.0,
            scale_units: true,
            estimate_condition: true,
        }
    }
}

/// Outcome of a successful position solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Convergence {
    /// Updates applied (at least 1: the step that confirmed convergence is applied too).
    pub iterations: usize,
    /// ‖Φ‖∞ at the returned positions (unscaled).
    pub residual: f64,
    /// Condition estimate κ₁ of the scaled Φ_q at the returned positions (NaN if switched off).
    pub condition: f64,
}

/// Kinematic solver owning a mechanism and every buffer it needs.
///
/// All storage is created by [`Solver::new`]; solves never allocate, error paths included.
pub struct Solver<M: Mechanism>
where
    DefaultAllocator: Storage<M::Dim>,
{
    pub(crate) mechanism: M,
    pub(crate) options: SolverOptions,
    /// Φ at the current iterate.
    pub(crate) phi: Vector<M::Dim>,
    /// The last step (Φ_q⁻¹ Φ, i.e. −Δq at full length), or a Levenberg–Marquardt step.
    pub(crate) step: Vector<M::Dim>,
    /// The iterate the last step was taken from, for backtracking.
    pub(crate) base: Vector<M::Dim>,
    /// Scratch: Φ at a trial point; J_sᵀ Φ_s in Levenberg–Marquardt.
    pub(crate) trial: Vector<M::Dim>,
    pub(crate) gradient: Vector<M::Dim>,
    /// Unit scales: D_r (per equation, 1/L^p) and D_c (per coordinate, L^p).
    pub(crate) rows: Vector<M::Dim>,
    pub(crate) cols: Vector<M::Dim>,
    /// The scaled Φ_q for Levenberg–Marquardt steps (the LU storage then holds J_sᵀJ_s + μI).
    pub(crate) jacobian: Matrix<M::Dim>,
    /// Factors of the scaled Φ_q at the last positions it was evaluated at, or after a
    /// [`SolveError::Singular`], the rank-revealing diagnosis.
    pub(crate) lu: Lu<M::Dim>,
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
        let zeros = Vector::zeros_generic(dim, U1);
        Self {
            mechanism,
            options,
            phi: zeros.clone(),
            step: zeros.clone(),
            base: zeros.clone(),
            trial: zeros.clone(),
            gradient: zeros.clone(),
            rows: Vector::from_element_generic(dim, U1, 1.0),
            cols: Vector::from_element_generic(dim, U1, 1.0),
            jacobian: Matrix::zeros_generic(dim, dim),
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

    /// The factorisation of the scaled Φ_q from the last solve.
    pub fn lu(&self) -> &Lu<M::Dim> {
        &self.lu
    }

    /// After a [`SolveError::Singular`]: every dependent (redundant) equation, ascending.
    /// Empty otherwise.
    pub fn dependent_equations(&self) -> &[usize] {
        self.lu.dependent_rows()
    }

    /// After a [`SolveError::Singular`]: every coordinate the equations leave undetermined.
    pub fn undetermined_coordinates(&self) -> &[usize] {
        self.lu.undetermined_columns()
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
        state.condition = convergence.condition;
        Ok(())
    }

    /// Evaluates and factors the scaled Φ_q at `q` for a separate derivative solve.
    fn factor_jacobian(&mut self, q: &Vector<M::Dim>, t: f64) -> Result<(), SolveError> {
        self.check_parameters(t)?;
        self.update_scales();
        let Self {
            mechanism,
            lu,
            rows,
            cols,
            ..
        } = self;
        lu.factor_scaled_with(rows, cols, |jacobian| mechanism.jacobian(q, t, jacobian))
            .map_err(|error| lu_error(error, t))
    }

    /// ‖D_c⁻¹ (a − b)‖∞: how far apart two configurations are, in scene lengths and radians
    /// (with the scales of the last solve).
    pub fn scaled_distance(&self, a: &Vector<M::Dim>, b: &Vector<M::Dim>) -> f64 {
        let difference = a.as_slice().iter().zip(b.as_slice()).map(|(x, y)| x - y);
        scaled_max_abs(difference, &self.cols)
    }

    /// Every parameter finite: a NaN set through a public field is reported as itself, not as
    /// the NaN Φ it would cause.
    pub(crate) fn check_parameters(&self, t: f64) -> Result<(), SolveError> {
        let m = &self.mechanism;
        match (0..m.parameter_count()).find(|&i| !m.parameter(i).is_some_and(f64::is_finite)) {
            Some(index) => Err(non_finite(t, Quantity::Parameter(index))),
            None => Ok(()),
        }
    }

    /// Recomputes the unit scales from the current parameters: D_r = 1/L^p per equation,
    /// D_c = L^p per coordinate, with L the scene's length scale rounded to a power of two so
    /// that scaling adds no rounding error.
    pub(crate) fn update_scales(&mut self) {
        let length = if self.options.scale_units {
            power_of_two(self.mechanism.length_scale())
        } else {
            1.0
        };
        let m = &self.mechanism;
        let scale = |power: i32| match power {
            0 => 1.0,
            1 => length,
            _ => length * length,
        };
        for (i, r) in self.rows.as_mut_slice().iter_mut().enumerate() {
            *r = 1.0 / scale(m.equation_unit(i).length_power());
        }
        for (j, c) in self.cols.as_mut_slice().iter_mut().enumerate() {
            *c = scale(m.coordinate_unit(j).length_power());
        }
    }

    /// Length and finiteness of an input, and finiteness of `t`.
    pub(crate) fn check_inputs(
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
    pub(crate) fn check_len(&self, v: &Vector<M::Dim>) -> Result<(), SolveError> {
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

/// The power of two nearest below `length` (1 for zero, subnormal or non-finite lengths, or
/// ones so extreme that their square would overflow the scaled equations).
fn power_of_two(length: f64) -> f64 {
    let length = length.abs();
    if !(1e-100..=1e100).contains(&length) {
        return 1.0;
    }
    // Clearing the mantissa of a normal positive float leaves its power of two.
    f64::from_bits(length.to_bits() & 0xfff0_0000_0000_0000)
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

/// ‖D_c⁻¹ v‖∞ for the entries of `v` (scene lengths and radians); a NaN entry makes it NaN, so
/// that callers see a non-finite step rather than a small one.
pub(crate) fn scaled_max_abs<D: Dim>(v: impl Iterator<Item = f64>, cols: &Vector<D>) -> f64
where
    DefaultAllocator: Storage<D>,
{
    v.zip(cols.as_slice()).fold(0.0, |m, (x, c)| {
        let y = (x / c).abs();
        if y > m || y.is_nan() { y } else { m }
    })
}

/// ‖v‖∞ over the contiguous storage (nalgebra's `amax` iterates element by element, slowly).
pub(crate) fn max_abs<D: Dim>(v: &Vector<D>) -> f64
where
    DefaultAllocator: Storage<D>,
{
    v.as_slice().iter().fold(0.0, |m, x| m.max(x.abs()))
}

pub(crate) fn non_finite(time: f64, quantity: Quantity) -> SolveError {
    SolveError::NonFinite { time, quantity }
}

pub(crate) fn check_finite<D: Dim>(
    v: &Vector<D>,
    t: f64,
    quantity: Quantity,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<D>,
{
    if v.as_slice().iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(non_finite(t, quantity))
    }
}

pub(crate) fn lu_error(error: LuError, time: f64) -> SolveError {
    match error {
        LuError::Singular { row, column, .. } => SolveError::Singular {
            time,
            equation: row,
            coordinate: column,
            condition: f64::INFINITY,
            deficiency: 1,
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
    fn newton_takes_the_same_steps_at_any_length_scale() {
        let solve = |a: f64| {
            let mut solver = Solver::new(Pendulum {
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
        let mut solver = Solver::new(Pendulum::default());
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
