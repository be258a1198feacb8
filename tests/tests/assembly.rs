//! Assembly from degenerate guesses: a guess with every link on one line is a stationary point
//! of the residual (its gradient vanishes, the Jacobian is singular), which no Newton or damped
//! step leaves. It is a saddle, left along the Jacobian's null direction, and the mechanism
//! assembles; a mechanism that cannot close stops at a minimum of the residual, which no
//! direction leaves, and reports its value.

use mechgen_examples::closed_form;
use mechgen_examples::scenes::FourBar;
use mechgen_examples::stability::Unclosable;
use mechgen_runtime::{Mechanism, Simulation, SolveError, Solver, SolverOptions, mechanism};

mechanism! {
    /// The examples' crank-rocker four-bar with flat guesses: coupler and rocker along the
    /// frame line, where the loop's Jacobian is singular and the residual's gradient zero.
    pub mechanism FlatFourBar {
        /// Crank speed (rad/s).
        param omega = 10.0;
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body coupler near (20, 0, 0);
        body rocker near (80, 0, 0);
        joint crank_pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (40, 0), coupler);
        joint rocker_pin: revolute(coupler @ (120, 0), rocker @ (80, 0));
        joint rocker_pivot: revolute(rocker, frame @ (100, 0));
        driver crank_angle: angle(crank) = omega * t;
        branch open_assembly: cross(coupler @ (120, 0) -> coupler, rocker @ (80, 0) -> rocker) > 0;
    }
}

mechanism! {
    /// The same flat guesses, with the crossed assembly declared: the side of the flat guess
    /// tried first leads to the open one, so the other side is taken.
    pub mechanism FlatCrossedFourBar {
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body coupler near (20, 0, 0);
        body rocker near (80, 0, 0);
        joint crank_pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (40, 0), coupler);
        joint rocker_pin: revolute(coupler @ (120, 0), rocker @ (80, 0));
        joint rocker_pivot: revolute(rocker, frame @ (100, 0));
        driver crank_angle: angle(crank) = 10 * t;
        branch crossed: cross(coupler @ (120, 0) -> coupler, rocker @ (80, 0) -> rocker) < 0;
    }
}

#[test]
fn flat_guesses_assemble_when_the_loop_can_close() {
    let exact = closed_form::FourBar::default();
    let mut simulation = Simulation::new(Solver::new(FlatFourBar::default()), 0.0)
        .unwrap_or_else(|failure| panic!("{failure}"));
    // The open assembly the branch declares, to the closed form, and followed from there.
    for t in [0.0, 0.1, 0.3] {
        let state = simulation.step_to(t).unwrap();
        let q = exact.q(t);
        for (k, (a, b)) in state.q.iter().zip(q.iter()).enumerate() {
            assert!((a - b).abs() <= 1e-9 * 120.0, "t = {t}, q[{k}]: {a} vs {b}");
        }
    }
}

#[test]
fn a_loop_that_cannot_close_reports_its_minimum_residual() {
    // Flat guesses of links too short: the escape finds no direction that reduces the
    // residual, whose minimum is the 50-long gap.
    let failure = Simulation::new(Solver::new(Unclosable::default()), 0.0)
        .err()
        .expect("cannot close");
    let SolveError::NoAssembly { residual, .. } = failure.error else {
        panic!("{failure}");
    };
    assert!((residual - 50.0).abs() <= 1e-6 * 50.0, "{residual}");
}

#[test]
fn flat_guesses_take_the_branch_the_scene_declares() {
    // The crossed assembly mirrors the open one about the line from the crank pin (40, 0) to
    // the rocker's pivot (100, 0), the x axis at t = 0: the same pin, reflected.
    let simulation = Simulation::new(Solver::new(FlatCrossedFourBar::default()), 0.0)
        .unwrap_or_else(|failure| panic!("{failure}"));
    let q = &simulation.state().q;
    let open = closed_form::FourBar::default().q(0.0);
    // Coupler and rocker angles reflected, positions the same (reference points on the axis).
    for k in [5, 8, 11] {
        assert!(
            (q[k] + open[k]).abs() <= 1e-9,
            "q[{k}]: {} vs -{}",
            q[k],
            open[k]
        );
    }
    for k in [3, 4, 6, 7, 9, 10] {
        assert!(
            (q[k] - open[k]).abs() <= 1e-9 * 120.0,
            "q[{k}]: {} vs {}",
            q[k],
            open[k]
        );
    }
}

#[test]
fn a_guess_newton_does_not_finish_from_names_the_equation_whose_bodies_to_move() {
    // One update is not enough from the four-bar's guesses: "not found from this guess", with
    // the loop equation left furthest from closing, whose joint's bodies are the ones to move.
    // (Newton's path: from its closed form, the four-bar's loop closes in one update.)
    let options = SolverOptions {
        max_iterations: 1,
        closed_forms: false,
        ..SolverOptions::default()
    };
    let failure = Simulation::new(Solver::with_options(FourBar::default(), options), 0.0)
        .err()
        .expect("one update is not enough");
    let SolveError::NoConvergence { equation, .. } = failure.error else {
        panic!("{failure}");
    };
    let name = failure.solver.mechanism().equation_name(equation).unwrap();
    assert!(name.starts_with("rocker_pin."), "{name}");
    let text = failure.to_string();
    assert!(
        text.contains(&format!("largest in equation `{name}`"))
            && text.contains("not found from this guess"),
        "{text}"
    );
}
