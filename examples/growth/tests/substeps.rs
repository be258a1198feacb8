//! A tall linkage's rise is stepped as given, not halved in proportion to its height: its upper
//! bodies travel many scene lengths per step while every joint turns a little, and only a
//! block angle's predicted turn bounds a step (bounding lengths too sub-stepped each step of
//! the 1000-stage lift about 30 times, and made the step's cost grow as N²).

use mechgen_growth::geometry::{alpha, platform_height};
use mechgen_growth::n100::{ScissorLift, ScissorLiftBodies};
use mechgen_runtime::{Simulation, Solver};

#[test]
fn the_100_stage_lift_rises_without_sub_steps() {
    let mut simulation =
        Simulation::new(Solver::new(ScissorLift::default()), 0.0).expect("assembles");
    let start = simulation.state().platform().y;
    for k in 1..=40 {
        let t = 0.02 * f64::from(k);
        let state = simulation
            .step_to(t)
            .unwrap_or_else(|e| panic!("t = {t}: {e}"));
        assert_eq!(state.substeps, 1, "step {k} to t = {t}");
        let expected = platform_height(100, alpha(t));
        let error = (state.platform().y - expected).abs() / expected;
        assert!(error < 1e-12, "t = {t}: relative error {error:e}");
    }
    let risen = simulation.state().platform().y - start;
    assert!(
        risen.abs() > 1.0,
        "the platform moved {risen} (not a still run)"
    );
}
