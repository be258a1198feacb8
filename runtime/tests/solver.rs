//! The solver's position, velocity and acceleration solves of the pendulum against its closed
//! form: Newton's convergence and factor reuse, unit scaling, the safeguards, and the errors.

mod common;

use common::pendulum::Pendulum;
use mechgen_runtime::nalgebra::{self, Const, U1};
use mechgen_runtime::{
    Dense, Mechanism, Quantity, SolveError, Solver, SolverOptions, State, Vector,
};

type Reference = Dense<Pendulum>;

fn dense(pendulum: Pendulum) -> Solver<Reference> {
    Solver::new(Dense::new(pendulum))
}

/// `(q, q̇, q̈)` at `t` match the closed form.
fn assert_exact(t: f64, motion: [&Vector<Const<3>>; 3], mechanism: &Pendulum) {
    let exact = mechanism.exact(t);
    for (computed, expected) in motion.into_iter().zip(exact) {
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
    let motion = [&state.q, state.qd(), state.qdd()];
    assert_exact(state.t, motion, solver.mechanism().inner());
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
    // With the rates (a full solve): the factors at the result are needed.
    let evaluations = |solver: &mut Solver<Reference>, nudge: f64| {
        let mut q = exact;
        q[2] += nudge;
        let state = solver.solve(0.7, &q).unwrap();
        (state.iterations, state.evaluations)
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
    assert_exact(2.0, [&q, &qd, &qdd], solver.mechanism().inner());
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
    use common::pendulum::DynPendulum;
    use mechgen_runtime::Names;
    use nalgebra::DVector;

    let mut solver = Solver::new(Dense::new(DynPendulum(Pendulum::default())));
    let state = solver
        .solve(0.7, &DVector::from_row_slice(&[2.0, 0.1, 0.1]))
        .unwrap();
    let exact = Pendulum::default().exact(0.7);
    assert!((state.qdd()[1] - exact[2][1]).abs() < 1e-12);

    let mismatch = SolveError::DimensionMismatch {
        expected: 3,
        found: 2,
        names: &Names::NONE,
    };
    assert_eq!(solver.solve(0.7, &DVector::zeros(2)).err(), Some(mismatch));
    // A state of another size (a user can resize only its positions).
    let mut short = state.clone();
    short.q = DVector::zeros(2);
    assert_eq!(solver.solve_into(0.7, &mut short), Err(mismatch));
    let mut long = DVector::zeros(4);
    assert!(solver.solve_position(&mut long, 0.7).is_err());
}
