//! The force solve of the weighted pendulum: reactions and efforts against the closed form, and
//! a non-finite force as a typed error.

mod common;

use common::pendulum::Pendulum;
use mechgen_runtime::nalgebra;
use mechgen_runtime::{Dense, Quantity, Simulation, SolveError, Solver};

fn weighted() -> Pendulum {
    Pendulum {
        mass: Some((3.0, 0.7, 9.81)),
        ..Pendulum::default()
    }
}

#[test]
fn reactions_and_efforts_match_the_closed_form() {
    let pendulum = weighted();
    let mut simulation = Simulation::new(Solver::new(Dense::new(pendulum.clone())), 0.0)
        .unwrap_or_else(|e| panic!("{e}"));
    simulation
        .run(4.0, 40, |state| {
            let exact = pendulum.exact_reactions(state.t);
            for (solved, exact) in state.constraint_forces().iter().zip(exact) {
                assert!(
                    (solved - exact).abs() <= 1e-12 * 60.0,
                    "{solved} vs {exact}"
                );
            }
        })
        .unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn a_non_finite_force_is_a_typed_error() {
    let mut pendulum = weighted();
    pendulum.mass = Some((f64::INFINITY, 0.7, 9.81));
    let mut solver = Solver::new(Dense::new(pendulum));
    let guess = nalgebra::Vector3::new(2.0, 0.0, 0.0);
    match solver.solve(0.0, &guess) {
        Err(SolveError::NonFinite {
            quantity: Quantity::Load,
            ..
        }) => {}
        other => panic!("expected a non-finite load, got {other:?}"),
    }
}
