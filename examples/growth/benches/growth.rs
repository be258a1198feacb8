//! How a step's cost grows with the scene: the scissor lift at 10, 100 and 1000 stages (72, 612
//! and 6,012 coordinates), each iteration assembling the lift at t = 0 and taking 40 steps of
//! 0.02 s (α from 0.3 to 0.7 rad). Per step is the iteration's time / 40: it carries 1/40 of an
//! assembly at every size alike, so the fitted exponent is the step's.
//!
//! After criterion's figures, the run prints each size's fastest batch per step and the
//! least-squares exponent p of time ∝ Nᵖ through them. The dense reference runs at 10 stages
//! only: at 100 its 612 × 612 matrices no longer fit a thread's stack.
//!
//! `cargo bench -p mechgen-growth`

mod fit;

use std::cell::RefCell;
use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::Criterion;
use mechgen_growth::{n10, n100, n1000};
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{Dense, Simulation, Solver, Storage, Structured};

const STEPS: u32 = 40;
const H: f64 = 0.02;

/// Assembles `lift` and takes [`STEPS`] steps.
fn rise<M: Structured + Clone>(lift: &M)
where
    DefaultAllocator: Storage<M::Dim>,
{
    let mut simulation = Simulation::new(Solver::new(lift.clone()), 0.0).expect("assembles");
    for k in 1..=STEPS {
        let state = simulation.step_to(f64::from(k) * H).expect("steps");
        black_box(state.q[0]);
    }
}

/// Times `lift` under `name`, keeping the fastest batch's time per step in `fastest`.
fn time<M: Structured + Clone>(c: &mut Criterion, name: &str, lift: M, fastest: &RefCell<f64>)
where
    DefaultAllocator: Storage<M::Dim>,
{
    let mut group = c.benchmark_group("scissor/step");
    group.sample_size(10);
    group.bench_function(name, |b| {
        b.iter_custom(|iterations| {
            let start = Instant::now();
            for _ in 0..iterations {
                rise(&lift);
            }
            let elapsed = start.elapsed();
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
    let dense = RefCell::new(f64::INFINITY);
    time(&mut c, "10", n10::ScissorLift::default(), &sizes[0].1);
    time(
        &mut c,
        "10_dense",
        Dense::new(n10::ScissorLift::default()),
        &dense,
    );
    time(&mut c, "100", n100::ScissorLift::default(), &sizes[1].1);
    time(&mut c, "1000", n1000::ScissorLift::default(), &sizes[2].1);
    c.final_summary();

    // Fastest batch per step, and the least-squares slope of log(time) over log(N).
    let points: Vec<(f64, f64)> = sizes
        .iter()
        .filter(|(_, t)| t.borrow().is_finite())
        .map(|(n, t)| ((6 * n + 12) as f64, *t.borrow()))
        .collect();
    println!("\nscissor lift, fastest batch per step:");
    for (coordinates, seconds) in &points {
        println!("  N = {coordinates:>5}: {:>10.2} µs", seconds * 1e6);
    }
    if dense.borrow().is_finite() {
        println!(
            "  N =    72, dense reference: {:.2} µs ({:.1}× the structured step)",
            *dense.borrow() * 1e6,
            *dense.borrow() / points.first().map_or(f64::NAN, |p| p.1)
        );
    }
    if points.len() >= 2 {
        println!("  fitted exponent: time ∝ N^{:.3}", fit::exponent(&points));
    }
}
