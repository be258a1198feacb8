//! How a forward-dynamics step's cost grows with the scene: the falling scissor lift (masses on
//! every body, the bottom link's angle free, released from rest at α0 = 0.3 rad under gravity;
//! `falling.rs`) at 10, 100 and 1000 stages (72, 612 and 6,012 coordinates). Each iteration
//! releases the lift from a new `Integrator` (assembly and initial accelerations, not timed)
//! and times 40 fixed generalized-α steps of 1e-3 s (ρ∞ = 0.9, the default).
//!
//! After criterion's figures, the run prints each size's fastest batch per step and the
//! least-squares exponent p of time ∝ Nᵖ through them, as `growth.rs` does for the kinematic
//! step (the target: p ≤ 1.2).
//!
//! The scenes need the `free` grammar, hence the `dynamics` feature (`required-features`).
//!
//! `cargo bench -p mechgen-growth --features dynamics --bench dynamics`

mod fit;

use std::cell::RefCell;
use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::Criterion;
use mechgen_growth::falling::{n10, n100, n1000};
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{
    Dynamic, EquationsOfMotion, FreeStorage, Integrator, IntegratorOptions, Solver, StepControl,
    Storage, Structured,
};

const STEPS: u32 = 40;
const H: f64 = 1e-3;

/// The lift released at t = 0, stepping at [`H`].
fn release<M>(lift: &M) -> Integrator<M>
where
    M: Dynamic + EquationsOfMotion + Structured + Clone,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    let options = IntegratorOptions {
        control: StepControl::Fixed { step: H },
        ..IntegratorOptions::default()
    };
    Integrator::new(Solver::new(lift.clone()), 0.0, options).expect("the lift assembles")
}

/// Times `lift` under `name`, keeping the fastest batch's time per step in `fastest`.
fn time<M>(c: &mut Criterion, name: &str, lift: M, fastest: &RefCell<f64>)
where
    M: Dynamic + EquationsOfMotion + Structured + Clone,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    let mut group = c.benchmark_group("falling_scissor/step");
    group.sample_size(10);
    group.bench_function(name, |b| {
        b.iter_custom(|iterations| {
            let mut elapsed = Duration::ZERO;
            for _ in 0..iterations {
                let mut integrator = release(&lift);
                let start = Instant::now();
                for _ in 0..STEPS {
                    let state = integrator.step().expect("the lift falls");
                    black_box(state.q[0]);
                }
                elapsed += start.elapsed();
            }
            let per_step = elapsed.as_secs_f64() / (iterations as f64 * f64::from(STEPS));
            let mut best = fastest.borrow_mut();
            *best = best.min(per_step);
            elapsed
        });
    });
    group.finish();
}

fn main() {
    let mut c = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3))
        .configure_from_args();
    let sizes: [(usize, RefCell<f64>); 3] =
        [10, 100, 1000].map(|n| (n, RefCell::new(f64::INFINITY)));
    time(
        &mut c,
        "10",
        n10::FallingScissorLift::default(),
        &sizes[0].1,
    );
    time(
        &mut c,
        "100",
        n100::FallingScissorLift::default(),
        &sizes[1].1,
    );
    time(
        &mut c,
        "1000",
        n1000::FallingScissorLift::default(),
        &sizes[2].1,
    );
    c.final_summary();

    // Fastest batch per step, and the least-squares slope of log(time) over log(N).
    let points: Vec<(f64, f64)> = sizes
        .iter()
        .filter(|(_, t)| t.borrow().is_finite())
        .map(|(n, t)| ((6 * n + 12) as f64, *t.borrow()))
        .collect();
    println!("\nfalling scissor lift, fastest batch per fixed step of {H} s:");
    for (coordinates, seconds) in &points {
        println!("  N = {coordinates:>5}: {:>10.2} µs", seconds * 1e6);
    }
    if points.len() >= 2 {
        println!("  fitted exponent: time ∝ N^{:.3}", fit::exponent(&points));
    }
}
