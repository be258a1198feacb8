//! A solved state read back: a body's three coordinates and their rates, and the CSV header and
//! row, which line up and round-trip.

mod common;

use common::pendulum::Pendulum;
use mechgen_runtime::{Dense, Solver, State, Vector, write_csv_header};

/// A solved state of the pendulum at t = 0.5 (its rates are the solver's to write: distinct
/// values, one per slot), its positions then set to 1, 2, 3.
fn sample() -> State<Dense<Pendulum>> {
    let mut solver = Solver::new(Dense::new(Pendulum::default()));
    let mut state = solver.solve(0.5, &Vector::from([2.0, 0.1, 0.1])).unwrap();
    state.q = Vector::from([1.0, 2.0, 3.0]);
    state
}

#[test]
fn body_reads_three_coordinates() {
    let state = sample();
    let body = state.body(0).unwrap();
    assert_eq!((body.x, body.y, body.theta), (1.0, 2.0, 3.0));
    let (qd, qdd) = (state.qd(), state.qdd());
    assert_eq!(
        (body.x_dot, body.y_dot, body.theta_dot),
        (qd[0], qd[1], qd[2])
    );
    assert_eq!(
        (body.x_ddot, body.y_ddot, body.theta_ddot),
        (qdd[0], qdd[1], qdd[2])
    );
    assert_eq!(state.body(1), None);
    assert_eq!(state.body(usize::MAX), None);
}

#[test]
fn csv_header_and_row_line_up_and_round_trip() {
    let mut header = String::new();
    write_csv_header(&Pendulum::default(), &mut header).unwrap();
    assert_eq!(
        header,
        "t,rod.x,rod.y,rod.theta,rod.x_dot,rod.y_dot,rod.theta_dot,\
         rod.x_ddot,rod.y_ddot,rod.theta_ddot\n"
    );

    // Positions of every magnitude and a negative zero round-trip too.
    let mut state = sample();
    state.q = Vector::from([1e20, -0.0, 1e-20]);
    let mut row = String::new();
    state.write_csv_row(&mut row).unwrap();
    let values: Vec<f64> = row
        .trim_end_matches('\n')
        .split(',')
        .map(|field| field.parse().unwrap())
        .collect();
    let expected = [state.t]
        .into_iter()
        .chain(state.q.iter().copied())
        .chain(state.qd().iter().copied())
        .chain(state.qdd().iter().copied());
    assert!(values.iter().copied().eq(expected));
    assert_eq!(header.split(',').count(), values.len());
}
