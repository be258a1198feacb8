//! Steps the driven seed (`PistonCrank`, generated) through N `Simulation` steps of a crank
//! revolution in 360, from a default `Solver` (the public path a user takes, every safeguard
//! on), as `benches/kinematics.rs` times it: the program to profile a kinematic step with (run
//! it at two step counts under callgrind and take the difference, so that assembly cancels out).
//!
//! `cargo run --release -p mechgen-benches --example seed_steps -- 36000 [newton]` (`newton`:
//! with the closed-form groups off, Newton's path alone).

use std::hint::black_box;

use mechgen_examples::scenes::PistonCrank;
use mechgen_runtime::{Simulation, Solver, SolverOptions};

fn main() {
    let steps: u32 = match std::env::args().nth(1).map(|a| a.parse()) {
        None => 36_000,
        Some(Ok(n)) => n,
        Some(Err(e)) => {
            eprintln!("usage: seed_steps [STEPS] ({e})");
            std::process::exit(2);
        }
    };
    let options = SolverOptions {
        closed_forms: std::env::args().nth(2).as_deref() != Some("newton"),
        ..SolverOptions::default()
    };
    let seed = PistonCrank::default();
    let h = std::f64::consts::TAU / seed.omega / 360.0;
    let mut simulation = match Simulation::new(Solver::with_options(seed, options), 0.0) {
        Ok(simulation) => simulation,
        Err(e) => {
            eprintln!("the seed does not assemble: {e}");
            std::process::exit(1);
        }
    };
    let mut top = f64::MIN;
    for k in 1..=steps {
        match simulation.step_to(f64::from(k) * h) {
            Ok(state) => top = top.max(black_box(state.q[3])),
            Err(e) => {
                eprintln!("step {k} failed: {e}");
                std::process::exit(1);
            }
        }
    }
    println!(
        "{steps} steps to t = {:.4} s: piston's furthest x {top:.9}",
        f64::from(steps) * h
    );
}
