//! Steps the falling scissor lift of STAGES stages (10, 100 or 1000) through N fixed
//! generalized-α steps of 1e-3 s, as `benches/dynamics.rs` times it, and prints the
//! integrator's statistics: the program to profile how a step's cost grows with the scene (run
//! it at two step counts under callgrind and take the difference, so that building the
//! integrator cancels out).
//!
//! `cargo run --release -p mechgen-growth --features dynamics --example falling_steps -- 1000 40`

use std::hint::black_box;

use mechgen_growth::falling::{n10, n100, n1000};
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{
    Dynamic, EquationsOfMotion, FreeStorage, Integrator, IntegratorOptions, Solver, StepControl,
    Storage, Structured,
};

/// Releases `lift` and takes `steps` steps; the statistics, or what failed.
fn run<M>(lift: M, steps: u32) -> Result<String, String>
where
    M: Dynamic + EquationsOfMotion + Structured,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    let options = IntegratorOptions {
        control: StepControl::Fixed { step: 1e-3 },
        ..IntegratorOptions::default()
    };
    let mut integrator =
        Integrator::new(Solver::new(lift), 0.0, options).map_err(|e| e.to_string())?;
    for _ in 0..steps {
        if let Err(e) = integrator.step() {
            return Err(integrator.describe(&e).to_string());
        }
        black_box(integrator.free_state(0)[0]);
    }
    let stats = integrator.stats();
    Ok(format!(
        "{steps} steps to t = {:.3} s: bottom link at {:.9} rad; {} Newton iterations, {} \
         factorizations",
        integrator.t(),
        integrator.free_state(0)[0],
        stats.iterations,
        stats.factorizations
    ))
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let number = |k: usize, default: u32| args.get(k).map_or(Ok(default), |a| a.parse::<u32>());
    let (Ok(stages), Ok(steps)) = (number(0, 10), number(1, 40)) else {
        eprintln!("usage: falling_steps [STAGES: 10 | 100 | 1000] [STEPS]");
        std::process::exit(2);
    };
    let outcome = match stages {
        10 => run(n10::FallingScissorLift::default(), steps),
        100 => run(n100::FallingScissorLift::default(), steps),
        1000 => run(n1000::FallingScissorLift::default(), steps),
        _ => Err(format!("no {stages}-stage lift: 10, 100 or 1000")),
    };
    match outcome {
        Ok(line) => println!("{stages} stages, {line}"),
        Err(why) => {
            eprintln!("{stages} stages: {why}");
            std::process::exit(1);
        }
    }
}
