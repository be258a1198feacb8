//! A solve error of the pendulum named with its tables: described by the mechanism, and named by
//! the solver that returns it.

mod common;

use common::pendulum::{self, Pendulum};
use mechgen_runtime::nalgebra;
use mechgen_runtime::{Dense, Names, Simulation, SolveError, Solver};

#[test]
fn describe_replaces_indices_with_names() {
    let error = SolveError::Singular {
        time: 1.0,
        equation: 2,
        coordinate: 1,
        condition: f64::INFINITY,
        deficiency: 1,
        names: &Names::NONE,
    };
    let plain = error.to_string();
    assert!(plain.contains("1 equation depends"), "{plain}");
    assert!(
        plain.contains("equation #2 leaves coordinate #1"),
        "{plain}"
    );
    let named = error.describe(&Pendulum::default()).to_string();
    assert!(
        named.contains("equation `drive` leaves coordinate `rod.y` undetermined"),
        "{named}"
    );
    assert_eq!(error.time(), Some(1.0));
    assert!(!error.is_step_related());
}

#[test]
fn the_solver_names_the_errors_it_returns() {
    let mut solver = Solver::new(Dense::new(Pendulum::default()));
    let short = nalgebra::Vector3::new(f64::NAN, 0.0, 0.0);
    let error = solver.solve(0.0, &short).err().map(|e| format!("{e:?}"));
    assert_eq!(
        error.as_deref(),
        Some("NonFinite: the positions q (initial guess) became NaN or infinite at t = 0")
    );
    let mut simulation = match Simulation::new(Solver::new(Dense::new(Pendulum::default())), 0.0) {
        Ok(simulation) => simulation,
        Err(e) => panic!("{e}"),
    };
    let Err(error) = simulation.step_to(f64::NAN) else {
        panic!("a NaN time must fail");
    };
    assert_eq!(error.names(), &pendulum::NAMES);
    let singular = Pendulum {
        duplicate_pin: true,
        ..Pendulum::default()
    };
    let guess = nalgebra::Vector3::new(2.0, 0.0, 0.0);
    let Err(error) = Solver::new(Dense::new(singular)).solve(0.0, &guess) else {
        panic!("a duplicated pin is singular");
    };
    let text = format!("{error:?}");
    assert!(text.starts_with("Singular: "), "{text}");
    assert!(
        text.contains("equation `drive`") || text.contains("equation `pin.x`"),
        "{text}"
    );
    assert!(!text.contains('#'), "{text}");
}
