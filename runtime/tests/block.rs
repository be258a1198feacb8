//! One block's algebra: the unit-scaled Jacobian's condition and the solve that undoes the
//! scaling, against the pendulum's block inverted by hand.
//!
//! The pendulum's Φ_q is J = [[1, 0, a s], [0, 1, −a c], [0, 0, 1]] (s, c of θ). Scaled by the
//! length scale L (a power of two: pin equations divided by L, x and y multiplied by it),
//! S = [[1, 0, r s], [0, 1, −r c], [0, 0, 1]] with r = a / L, whose inverse negates the corner
//! entries: ‖S‖₁ = ‖S⁻¹‖₁ = 1 + r (|s| + |c|).

mod common;

use common::pendulum::Pendulum;
use mechgen_runtime::nalgebra::Vector3;
use mechgen_runtime::{Dense, Solver, SolverOptions, State};

/// The pendulum with a = 3 (L = 2, so r = 3/2) solved at `t`.
fn solved(t: f64, options: SolverOptions) -> (Pendulum, State<Dense<Pendulum>>) {
    let pendulum = Pendulum {
        a: 3.0,
        ..Pendulum::default()
    };
    let mut solver = Solver::with_options(Dense::new(pendulum.clone()), options);
    let guess = Vector3::new(2.5, 1.5, 1.5 * t + 0.1);
    let state = solver.solve(t, &guess).unwrap_or_else(|e| panic!("{e}"));
    (pendulum, state)
}

fn condition(r: f64, theta: f64) -> f64 {
    let (s, c) = theta.sin_cos();
    let norm = 1.0 + r * (s.abs() + c.abs());
    norm * norm
}

#[test]
fn the_condition_is_that_of_the_unit_scaled_block() {
    let (_, state) = solved(0.7, SolverOptions::default());
    let expected = condition(1.5, state.q.z);
    assert!(
        (state.condition - expected).abs() <= 1e-12 * expected,
        "{} vs {expected}",
        state.condition
    );
}

#[test]
fn without_unit_scaling_the_condition_is_the_raw_jacobians() {
    let options = SolverOptions {
        scale_units: false,
        ..SolverOptions::default()
    };
    let (_, state) = solved(0.7, options);
    let expected = condition(3.0, state.q.z);
    assert!(
        (state.condition - expected).abs() <= 1e-12 * expected,
        "{} vs {expected}",
        state.condition
    );
}

#[test]
fn the_block_solve_undoes_the_scaling() {
    let (pendulum, state) = solved(0.7, SolverOptions::default());
    // q̇ = J⁻¹ ν with ν = (0, 0, ω): θ̇ = ω, then ẋ = −a s θ̇, ẏ = a c θ̇.
    let (a, w, (s, c)) = (pendulum.a, pendulum.omega, state.q.z.sin_cos());
    let expected = [-a * s * w, a * c * w, w];
    for (computed, expected) in state.qd().iter().zip(expected) {
        assert!((computed - expected).abs() <= 1e-14 * expected.abs().max(1.0));
    }
    // The block's determinant (of S: 1) is positive.
    assert_eq!(state.orientation, 1);
}
