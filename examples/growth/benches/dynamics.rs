//! How a forward-dynamics step's cost grows with the scene: the falling scissor lift (masses on
//! every body, the bottom link's angle free, released from rest at α0 = 0.3 rad under gravity;
//! `falling.rs`) at 10, 100 and 1000 stages (72, 612 and 6,012 coordinates). Each iteration
//! releases the lift from a new `Integrator` (assembly and initial accelerations, not timed)
//! and times 40 fixed generalized-α steps of 1e-3 s (ρ∞ = 0.9, the default).
//!
//! After criterion's figures (per release of 40 steps), the run prints each size's median and
//! fastest batch per step, the Newton iterations per step, and the least-squares exponent p of
//! time ∝ Nᵖ through the medians and through the fastest, as `growth.rs` does for the
//! kinematic step (the target: p ≤ 1.2).
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

/// Every batch's time per step of one size (seconds), and its release's Newton iterations
/// per step.
#[derive(Default)]
struct Size {
    batches: RefCell<Vec<f64>>,
    iterations: RefCell<f64>,
}

impl Size {
    /// `(median, fastest)` over the batches, if any.
    fn times(&self) -> Option<(f64, f64)> {
        let mut sorted = self.batches.borrow().clone();
        sorted.sort_by(f64::total_cmp);
        let middle = sorted.len() / 2;
        let median = match sorted.len() {
            0 => return None,
            n if n % 2 == 1 => sorted[middle],
            _ => 0.5 * (sorted[middle - 1] + sorted[middle]),
        };
        Some((median, sorted[0]))
    }
}

/// Times `lift` under `name`, keeping every batch's time per step in `size`.
fn time<M>(c: &mut Criterion, name: &str, lift: M, size: &Size)
where
    M: Dynamic + EquationsOfMotion + Structured + Clone,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    let mut group = c.benchmark_group("falling_scissor/release_of_40_steps");
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
            size.batches.borrow_mut().push(per_step);
            elapsed
        });
    });
    group.finish();
    let mut integrator = release(&lift);
    for _ in 0..STEPS {
        integrator.step().expect("the lift falls");
    }
    *size.iterations.borrow_mut() = integrator.stats().iterations as f64 / f64::from(STEPS);
}

fn main() {
    let mut c = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3))
        .configure_from_args();
    let sizes: [(usize, Size); 3] = [10, 100, 1000].map(|n| (n, Size::default()));
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

    // Median and fastest batch per step, and the least-squares slope of log(time) over log(N)
    // through each.
    let points: Vec<(f64, (f64, f64), f64)> = sizes
        .iter()
        .filter_map(|(n, size)| {
            let coordinates = (6 * n + 12) as f64;
            Some((coordinates, size.times()?, *size.iterations.borrow()))
        })
        .collect();
    println!("\nfalling scissor lift, per fixed step of {H} s (median batch, fastest):");
    for (coordinates, (median, fastest), iterations) in &points {
        println!(
            "  N = {coordinates:>5}: {:>10.2} µs ({:>10.2}), {iterations:.2} Newton iterations \
             per step",
            median * 1e6,
            fastest * 1e6
        );
    }
    if points.len() >= 2 {
        let fit = |pick: fn(&(f64, f64)) -> f64| {
            let xy: Vec<(f64, f64)> = points.iter().map(|(n, t, _)| (*n, pick(t))).collect();
            fit::exponent(&xy)
        };
        println!(
            "  fitted exponent: time ∝ N^{:.3} (medians), N^{:.3} (fastest)",
            fit(|t| t.0),
            fit(|t| t.1)
        );
    }
}
