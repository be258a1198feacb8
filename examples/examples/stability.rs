//! The stiff and extreme cases of the stability work, measured: Newton iterations per step,
//! sub-steps, the error against each case's closed form, the largest condition estimate of the
//! scaled Jacobian, and the time per step; then the cases that must fail, with their errors.
//!
//! `cargo run --release --example stability`

use mechgen_examples::stability::{self, Measured, Parallelogram, Unclosable};
use mechgen_runtime::{Mechanism, Simulation, Solver};

fn row(case: &str, m: &Measured) {
    let outcome = match &m.failure {
        None => String::from("ok"),
        Some(error) => format!("{error}").chars().take(60).collect(),
    };
    println!(
        "{case:<44} {:>6} {:>8.2} {:>5} {:>8} {:>9.1e} {:>9.1e} {:>9.1e} {:>9.2e} {:>8.2}  {outcome}",
        m.steps,
        m.iterations_per_step(),
        m.max_iterations,
        m.substeps,
        m.errors.q,
        m.errors.qd,
        m.errors.qdd,
        m.max_condition,
        m.micros_per_step,
    );
}

fn main() {
    println!(
        "{:<44} {:>6} {:>8} {:>5} {:>8} {:>9} {:>9} {:>9} {:>9} {:>8}",
        "case",
        "steps",
        "it/step",
        "max",
        "substeps",
        "err q",
        "err q̇",
        "err q̈",
        "max κ",
        "µs/step"
    );
    row("seed, scale 1", &stability::scaled_seed(1.0, 314.0, 360));
    row(
        "seed, scale 1e-6",
        &stability::scaled_seed(1e-6, 314.0, 360),
    );
    row("seed, scale 1e4", &stability::scaled_seed(1e4, 314.0, 360));
    row(
        "seed, ω = 1e5 rad/s",
        &stability::scaled_seed(1.0, 1e5, 360),
    );
    row(
        "seed, θ = 0.5 sin(2000 t), 100 steps/period",
        &stability::oscillating_seed(0.5, 2000.0, 5, 100),
    );
    row(
        "seed, θ = 0.5 sin(2000 t), 6 steps/period",
        &stability::oscillating_seed(0.5, 2000.0, 3, 6),
    );
    row(
        "slider-crank, l = 2 r",
        &stability::slider_crank(1.0, 2.0, 360),
    );
    row(
        "slider-crank, l = r (1 + 1e-6)",
        &stability::slider_crank(1.0, 1.0 + 1e-6, 360),
    );
    row(
        "slider-crank, l = r (toggle at θ = 90°)",
        &stability::slider_crank(1.0, 1.0, 360),
    );
    row(
        "slider-crank, l = r, 97 steps (straddling)",
        &stability::slider_crank(1.0, 1.0, 97),
    );

    println!();
    let describe = |case: &str, result: Result<(), String>| match result {
        Ok(()) => println!("{case}: solved"),
        Err(message) => println!("{case}:\n  {}", message.replace('\n', "\n  ")),
    };
    let mut solver = Solver::new(Parallelogram::default());
    let mut q = Default::default();
    solver.mechanism().initial_guess(&mut q);
    describe(
        "parallelogram with a third parallel crank",
        solver
            .solve_position(&mut q, 0.0)
            .map(drop)
            .map_err(|e| solver.describe(&e).to_string()),
    );
    describe(
        "four-bar 10 + 20 + 20 against a 100 frame",
        Simulation::new(Solver::new(Unclosable::default()), 0.0)
            .map(drop)
            .map_err(|e| e.to_string()),
    );
    for t in [0.0, 0.002, 0.01] {
        describe(
            &format!("seed from every moving body at the origin, t = {t}"),
            stability::seed_from_origin(t)
                .map(|state| {
                    println!(
                        "  t = {t}: {} iterations, piston.x = {:.6}",
                        state.iterations, state.q[3]
                    );
                })
                .map_err(|e| {
                    e.describe(&mechgen_examples::scenes::PistonCrank::default())
                        .to_string()
                }),
        );
    }
}
