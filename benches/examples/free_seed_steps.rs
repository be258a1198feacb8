//! Steps the free seed (`PistonCrankFree`, generated) through N fixed generalized-α steps of
//! 1e-4 s, as `benches/dynamics.rs` times it, and prints the integrator's statistics: the
//! program to profile a step with (run it at two step counts under callgrind and take the
//! difference, so that building the integrator cancels out; `benches/peer/README.md`).
//!
//! `cargo run --release -p mechgen-benches --example free_seed_steps -- 5000`

use std::hint::black_box;

use mechgen_examples::report::Plan;
use mechgen_examples::scenes::PistonCrankFree;
use mechgen_runtime::{Integrator, IntegratorOptions, Solver, StepControl};

fn main() {
    let steps: u32 = match std::env::args().nth(1).map(|a| a.parse()) {
        None => 5000,
        Some(Ok(n)) => n,
        Some(Err(e)) => {
            eprintln!("usage: free_seed_steps [STEPS] ({e})");
            std::process::exit(2);
        }
    };
    let solver = Solver::with_options(PistonCrankFree::default(), Plan::full().reference.options());
    let options = IntegratorOptions {
        control: StepControl::Fixed { step: 1e-4 },
        ..IntegratorOptions::default()
    };
    let mut integrator = match Integrator::new(solver, 0.0, options) {
        Ok(integrator) => integrator,
        Err(e) => {
            eprintln!("the free seed does not start: {e}");
            std::process::exit(1);
        }
    };
    let before = integrator.stats();
    for _ in 0..steps {
        if let Err(e) = integrator.step() {
            eprintln!("step failed: {}", integrator.describe(&e));
            std::process::exit(1);
        }
        black_box(integrator.free_state(0)[0]);
    }
    let stats = integrator.stats();
    println!(
        "{steps} steps to t = {:.4} s: crank angle {:.9} rad; {} Newton iterations \
         ({} before the first step), {} factorizations",
        integrator.t(),
        integrator.free_state(0)[0],
        stats.iterations,
        before.iterations,
        stats.factorizations,
    );
}
