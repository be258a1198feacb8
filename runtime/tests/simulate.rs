//! Stepping the pendulum: the predictor saves Newton iterations, and a failed step keeps the
//! last state.

mod common;

use common::pendulum::Pendulum;
use mechgen_runtime::{Dense, Simulation, Solver};

fn iterations(predictor: bool) -> usize {
    let mut simulation =
        Simulation::new(Solver::new(Dense::new(Pendulum::default())), 0.0).unwrap();
    simulation.set_predictor(predictor);
    let (mut total, mut calls, mut last_t) = (0, 0, 0.0);
    simulation
        .run(2.0, 40, |state| {
            let exact = Pendulum::default().exact(state.t);
            assert!((state.q.x - exact[0][0]).abs() < 1e-12);
            assert!((state.qdd().y - exact[2][1]).abs() < 1e-12);
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
    let mut simulation =
        Simulation::new(Solver::new(Dense::new(Pendulum::default())), 0.0).unwrap();
    simulation.step_to(0.5).unwrap();
    simulation.solver_mut().mechanism_mut().inner_mut().a = f64::NAN;
    let error = simulation.step_to(0.75).unwrap_err();
    assert_eq!(error.time(), Some(0.75));
    assert_eq!(simulation.state().t, 0.5);
    assert!(simulation.step_to(f64::NAN).is_err());
    simulation.solver_mut().mechanism_mut().inner_mut().a = 2.0;
    assert_eq!(simulation.step_to(1.0).unwrap().t, 1.0);
}
