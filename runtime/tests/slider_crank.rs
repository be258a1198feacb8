//! The solver against the slider-crank's closed form: positions, velocities, accelerations,
//! stepping, CSV output and named diagnostics.

mod common;

use common::slider_crank::{Q, Reference, SliderCrank, reference};
use mechgen_runtime::{Mechanism, Simulation, SolveError, Solver, State, write_csv_header};

fn assert_close(computed: &Q, expected: &Q, what: &str, t: f64) {
    for (index, (c, e)) in computed.iter().zip(expected).enumerate() {
        assert!(
            (c - e).abs() <= 1e-10 * e.abs().max(1.0),
            "{what}[{index}] at t = {t}: {c} vs {e}"
        );
    }
}

fn assert_exact(state: &State<Reference>, mechanism: &SliderCrank) {
    let [q, qd, qdd] = mechanism.exact(state.t);
    assert_close(&state.q, &q, "q", state.t);
    assert_close(state.qd(), &qd, "qd", state.t);
    assert_close(state.qdd(), &qdd, "qdd", state.t);
}

#[test]
fn solve_matches_the_closed_form_from_the_initial_guess() {
    let mut solver = Solver::new(reference(SliderCrank::default()));
    let mut guess = Q::zeros();
    solver.mechanism().initial_guess(&mut guess);
    for t in [0.0, 0.2, 0.5, 0.9] {
        let state = solver.solve(t, &guess).unwrap();
        assert_exact(&state, solver.mechanism().inner());
        assert!(state.iterations <= 8, "{} iterations", state.iterations);
    }
}

#[test]
fn simulation_tracks_a_full_revolution() {
    let period = 2.0 * core::f64::consts::PI / SliderCrank::default().parameters[2];
    let mut totals = [0; 2];
    for (predictor, total) in [true, false].into_iter().zip(&mut totals) {
        let mut simulation =
            Simulation::new(Solver::new(reference(SliderCrank::default())), 0.0).unwrap();
        simulation.set_predictor(predictor);
        let mechanism = simulation.solver().mechanism().inner().clone();
        simulation
            .run(period, 200, |state| {
                assert_exact(state, &mechanism);
                *total += state.iterations;
            })
            .unwrap();
        let body = simulation.state().body(2).unwrap();
        assert!((body.x - mechanism.exact(period)[0][6]).abs() < 1e-10);
    }
    assert!(
        totals[0] < totals[1],
        "iterations with/without predictor: {totals:?}"
    );
}

#[test]
fn parameters_change_the_solution() {
    let mut solver = Solver::new(reference(SliderCrank::default()));
    solver.mechanism_mut().set_parameter("l", 4.0).unwrap();
    let guess = solver.mechanism().inner().exact(0.3)[0];
    let state = solver.solve(0.3, &guess).unwrap();
    assert_eq!(solver.mechanism().parameter(1), Some(4.0));
    assert_exact(&state, solver.mechanism().inner());
}

#[test]
fn csv_has_one_column_per_header_field() {
    let mut solver = Solver::new(reference(SliderCrank::default()));
    let state = solver
        .solve(0.4, &SliderCrank::default().exact(0.4)[0])
        .unwrap();
    let mut csv = String::new();
    write_csv_header(solver.mechanism(), &mut csv).unwrap();
    state.write_csv_row(&mut csv).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert!(lines[0].starts_with("t,crank.x,crank.y,crank.theta,rod.x"));
    assert!(lines[0].contains(",slider.theta,crank.x_dot,"));
    assert!(lines[0].ends_with(",slider.theta_ddot"));
    assert_eq!(lines[0].split(',').count(), 28);
    let slider_x_dot: f64 = lines[1].split(',').nth(1 + 9 + 6).unwrap().parse().unwrap();
    assert_eq!(slider_x_dot, state.qd()[6]);
}

#[test]
fn singular_configuration_is_described_by_name() {
    // With r = l the rod stands vertical at θ₁ = π/2 and the slider's x is undetermined.
    let mut solver = Solver::new(reference(SliderCrank {
        parameters: [1.0, 1.0, 1.0, 0.0],
    }));
    let t = core::f64::consts::FRAC_PI_2;
    let q = Q::from([0.0, 0.0, t, 0.0, 1.0, -t, 0.0, 0.0, 0.0]);
    let error = solver.solve_velocity(&q, t, &mut Q::zeros()).unwrap_err();
    let SolveError::Singular {
        equation,
        coordinate,
        ..
    } = error
    else {
        panic!("expected a singular Jacobian, got {error:?}");
    };
    let described = error.describe(solver.mechanism()).to_string();
    let equation = solver.mechanism().equation_name(equation).unwrap();
    let coordinate = solver.mechanism().coordinate_name(coordinate).unwrap();
    assert!(
        described.contains(&format!(
            "equation `{equation}` leaves coordinate `{coordinate}` undetermined"
        )),
        "{described}"
    );
    assert!(!described.contains('#'), "{described}");
}

#[test]
fn unreachable_pose_fails_with_its_time() {
    // A rod shorter than the crank cannot reach the guide at θ₁ = π/2.
    let mut simulation = Simulation::new(
        Solver::new(reference(SliderCrank {
            parameters: [1.0, 0.5, 1.0, 0.0],
        })),
        0.0,
    )
    .unwrap();
    let t = core::f64::consts::FRAC_PI_2;
    let error = simulation.run(t, 20, |_| {}).unwrap_err();
    assert!(
        error.time().unwrap() > 0.4 && error.time().unwrap() <= t,
        "{error}"
    );
    assert!(simulation.state().t < error.time().unwrap());
}
