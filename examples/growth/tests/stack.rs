//! The 1000-stage lift (6,012 coordinates, 1,001 Newton blocks) solved through its structure on a
//! thread with the default stack: its state vectors live on the stack, but no n × n matrix does
//! (the solver's workspace is sized by the largest block, 6 × 6, and the dense alternative would
//! need 289 MB).
//!
//! This drives [`Solver`] directly, as an embedded loop would. A [`mechgen_runtime::Simulation`]
//! keeps three states and a prediction besides (about 570 kB here); an unoptimised build copies
//! such values on the stack when moving them, so at this size it wants about 3 MiB there (the
//! main thread's 8 MiB, or an optimised build, are enough).

use mechgen_growth::geometry::{alpha, platform_height};
use mechgen_growth::n1000::{ScissorLift, ScissorLiftBodies};
use mechgen_runtime::{Mechanism, Solver, State};

#[test]
fn the_1000_stage_lift_rises_on_a_default_thread_stack() {
    // `spawn` without a stack size: Rust's default (2 MiB unless RUST_MIN_STACK says otherwise).
    let rise = std::thread::spawn(|| {
        let mut solver = Solver::new(ScissorLift::default());
        let mut state = State::new(solver.mechanism());
        solver.mechanism().initial_guess(&mut state.q);
        let mut worst = 0.0f64;
        for step in 0..=10 {
            let t = 0.05 * f64::from(step);
            // Each solve starts from the last solution, as a control loop's would.
            solver
                .solve_into(t, &mut state)
                .unwrap_or_else(|e| panic!("t = {t}: {e}"));
            let expected = platform_height(1000, alpha(t));
            worst = worst.max((state.platform().y - expected).abs() / expected);
        }
        worst
    });
    let worst = rise.join().expect("the solve fits the default stack");
    assert!(
        worst <= 1e-12,
        "platform height off by {worst:e} (relative)"
    );
}
