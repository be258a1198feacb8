//! Assembly from degenerate guesses: a guess with every link on one line is a stationary point
//! of the residual (its gradient vanishes, the Jacobian is singular), which no Newton or damped
//! step leaves. It is a saddle, left along the Jacobian's null direction, and the mechanism
//! assembles; a mechanism that cannot close stops at a minimum of the residual, which no
//! direction leaves, and reports its value.

use mechgen_examples::closed_form;
use mechgen_examples::stability::Unclosable;
use mechgen_runtime::{Simulation, SolveError, Solver, mechanism};

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
