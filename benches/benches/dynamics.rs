//! Speed of forward dynamics on the free seed (`piston_crank_free.mech`: the seed with its
//! mass properties, the crank released from rest at 0.3 rad under gravity), in one run beside
//! the driven seed's kinematic step and beside the peer, Exudyn.
//!
//! Groups:
//! - `free_seed/fixed/{generated,interpreted}`: one accepted generalized-α step of 1e-4 s
//!   (ρ∞ = 0.9, the default), the release restarted from a new `Integrator` (assembled at
//!   t = 0, not timed) every 5,000 steps, every batch whole releases (the same 0.5 s motion).
//! - `seed/generated`: the driven seed's `Simulation` step, as `kinematics.rs` times it (360
//!   steps per revolution, the report's reference solver options), for the ratio.
//! - `free_seed/adaptive`: the whole 0.5 s release in the error-controlled mode at rtol 1e-6
//!   (atol 1e-9, the defaults), from a new `Integrator` (not timed).
//!
//! After criterion's figures the run prints the median and the fastest batch per step of each
//! (every batch steps through whole runs: see `time_steps`), the ratio of the medians of the
//! free step and the driven one, the adaptive run's steps (accepted, rejected), Newton
//! iterations and factorizations, the largest error of the crank angle at t = 0.1, …, 0.5 s
//! against the reduced Lagrange reference ([`mechgen_examples::free_seed`], RK4 at 1e-5 s) for
//! both modes, and, when `python3` with `exudyn` is installed, the peer's step on the same
//! scene measured in this run (`benches/peer/exudyn_free_seed.py --summary`) with the ratio
//! of the medians and both errors (without them, a note says why). The fastest batches beside
//! the medians, because the machines are shared and noise only ever adds time.
//!
//! `cargo bench -p mechgen-benches --bench dynamics`

use std::cell::RefCell;
use std::hint::black_box;
use std::process::Command;
use std::time::{Duration, Instant};

use criterion::{BenchmarkGroup, Criterion, measurement::WallTime};
use mechgen_examples::free_seed::FreeSeed;
use mechgen_examples::report::Plan;
use mechgen_examples::scenes::{PistonCrank, PistonCrankFree};
use mechgen_interp::Interpreted;
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{
    Dynamic, EquationsOfMotion, FreeStorage, Integrator, IntegratorOptions, Simulation, Solver,
    StepControl, Storage, Structured,
};

/// The fixed step of the comparison (s): the peer's.
const STEP: f64 = 1e-4;
/// The release (s): 5,000 fixed steps.
const RELEASE: f64 = 0.5;
/// Where the crank angle is compared with the reference (s).
const TIMES: [f64; 5] = [0.1, 0.2, 0.3, 0.4, 0.5];
/// Crank angle at release (rad): the scene's `from`.
const START: f64 = 0.3;
/// Output times per revolution of the driven seed, as in `kinematics.rs`.
const DRIVEN_STEPS: u64 = 360;

/// Every batch's time per step of each timed method (seconds).
#[derive(Default)]
struct Timings(RefCell<Vec<(String, Vec<f64>)>>);

impl Timings {
    fn record(&self, name: &str, seconds: f64) {
        let mut all = self.0.borrow_mut();
        match all.iter_mut().find(|(n, _)| n == name) {
            Some((_, batches)) => batches.push(seconds),
            None => all.push((name.to_owned(), vec![seconds])),
        }
    }

    /// `(median, fastest)` over the batches of `name`.
    fn get(&self, name: &str) -> Option<(f64, f64)> {
        let all = self.0.borrow();
        let (_, batches) = all.iter().find(|(n, _)| n == name)?;
        let mut sorted = batches.clone();
        sorted.sort_by(f64::total_cmp);
        let middle = sorted.len() / 2;
        let median = if sorted.len() % 2 == 1 {
            sorted[middle]
        } else {
            0.5 * (sorted[middle - 1] + sorted[middle])
        };
        Some((median, sorted[0]))
    }
}

/// Times `step` as criterion's `step` in `group`: `step(run, k)` takes step k (1-based) of a
/// run that `start()` begins afresh (not timed) every `chunk` steps.
///
/// Every batch steps through whole runs (criterion's iteration count rounded up to a multiple
/// of `chunk`, the time scaled back to the count): the cost of a step changes along a motion
/// (the free seed's early steps, near rest, converge in fewer iterations), and a batch of the
/// first steps alone would be faster than the motion's average.
fn time_steps<S>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    timings: &Timings,
    name: &str,
    chunk: u64,
    start: impl Fn() -> S,
    mut step: impl FnMut(&mut S, u64),
) {
    group.bench_function("step", |b| {
        b.iter_custom(|iterations| {
            let runs = iterations.div_ceil(chunk).max(1);
            let mut total = Duration::ZERO;
            for _ in 0..runs {
                let mut run = start();
                let started = Instant::now();
                for k in 1..=chunk {
                    step(&mut run, k);
                }
                total += started.elapsed();
            }
            let per_step = total.as_secs_f64() / (runs * chunk) as f64;
            timings.record(name, per_step);
            Duration::from_secs_f64(per_step * iterations as f64)
        });
    });
}

/// The free seed released at t = 0 under `control`, its solver with the report's reference
/// options (as the driven seed's).
fn release<M>(mechanism: M, control: StepControl) -> Integrator<M>
where
    M: Dynamic + EquationsOfMotion + Structured,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    let solver = Solver::with_options(mechanism, Plan::full().reference.options());
    let options = IntegratorOptions {
        control,
        ..IntegratorOptions::default()
    };
    Integrator::new(solver, 0.0, options).expect("the free seed assembles at release")
}

fn fixed() -> StepControl {
    StepControl::Fixed { step: STEP }
}

/// The error-controlled mode at the tolerance (the defaults, written out).
fn adaptive() -> StepControl {
    StepControl::Adaptive {
        rtol: 1e-6,
        atol: 1e-9,
        initial: 1e-4,
        min: 1e-12,
        max: f64::INFINITY,
    }
}

/// One fixed step of the free seed, `mechanism` generated or interpreted.
fn free_fixed<M>(c: &mut Criterion, timings: &Timings, label: &str, mechanism: M)
where
    M: Dynamic + EquationsOfMotion + Structured + Clone,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    let mut group = c.benchmark_group(label);
    let chunk = (RELEASE / STEP).round() as u64;
    time_steps(
        &mut group,
        timings,
        label,
        chunk,
        || release(mechanism.clone(), fixed()),
        |integrator, _| {
            integrator.step().expect("the free seed steps");
            black_box(integrator.free_state(0)[0]);
        },
    );
    group.finish();
}

/// The driven seed's kinematic step, as `kinematics.rs` times it.
fn driven(c: &mut Criterion, timings: &Timings) {
    let seed = PistonCrank::default();
    let h = 2.0 * std::f64::consts::PI / seed.omega / DRIVEN_STEPS as f64;
    let options = Plan::full().reference.options();
    let checkpoint =
        Simulation::new(Solver::with_options(seed, options), 0.0).expect("scene assembles");
    let mut group = c.benchmark_group("seed/generated");
    time_steps(
        &mut group,
        timings,
        "seed/generated",
        DRIVEN_STEPS,
        || checkpoint.clone(),
        |simulation, k| {
            let state = simulation.step_to(k as f64 * h).expect("steps");
            black_box(state.q[0]);
        },
    );
    group.finish();
}

/// The whole release in the error-controlled mode.
fn free_adaptive(c: &mut Criterion, timings: &Timings) {
    let mut group = c.benchmark_group("free_seed/adaptive");
    group.bench_function("release", |b| {
        b.iter_custom(|iterations| {
            let mut total = Duration::ZERO;
            for _ in 0..iterations {
                let mut integrator = release(PistonCrankFree::default(), adaptive());
                let started = Instant::now();
                integrator.step_to(RELEASE).expect("the free seed releases");
                total += started.elapsed();
                black_box(integrator.free_state(0)[0]);
            }
            timings.record(
                "free_seed/adaptive",
                total.as_secs_f64() / iterations as f64,
            );
            total
        });
    });
    group.finish();
}

/// The largest |φ − φ_ref| at [`TIMES`] of a release under `control`, and the run's statistics.
fn accuracy(control: StepControl, reference: &[[f64; 2]]) -> (f64, String) {
    let mut integrator = release(PistonCrankFree::default(), control);
    let mut worst = 0.0f64;
    for (&t, expected) in TIMES.iter().zip(reference) {
        integrator.step_to(t).expect("the free seed releases");
        worst = worst.max((integrator.free_state(0)[0] - expected[0]).abs());
    }
    let stats = integrator.stats();
    let counts = format!(
        "{} steps ({} rejected), {} Newton iterations, {} factorizations",
        stats.steps, stats.rejected, stats.iterations, stats.factorizations
    );
    (worst, counts)
}

/// The peer's figures measured now, from the script's `--summary` line, or why there are none.
struct Peer {
    /// Seconds per step: median and fastest of the script's runs.
    median: f64,
    fastest: f64,
    /// Largest |φ − φ_ref| at [`TIMES`] (rad).
    error: f64,
}

fn exudyn() -> Result<Peer, String> {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/peer/exudyn_free_seed.py");
    let output = Command::new("python3")
        .args([script, "--summary", "--step", &STEP.to_string()])
        .output()
        .map_err(|e| format!("python3: {e}"))?;
    let text = String::from_utf8_lossy(&output.stdout);
    if !output.status.success() {
        let error = String::from_utf8_lossy(&output.stderr);
        return Err(format!("{}{}", text.trim(), error.trim()));
    }
    let field = |key: &str| {
        text.split_whitespace()
            .find_map(|pair| pair.strip_prefix(key)?.strip_prefix('='))
            .and_then(|value| value.parse::<f64>().ok())
            .ok_or_else(|| format!("no `{key}` in {text:?}"))
    };
    Ok(Peer {
        median: field("us_per_step_median")? * 1e-6,
        fastest: field("us_per_step_fastest")? * 1e-6,
        error: field("max_abs_dphi")?,
    })
}

/// `median ns (fastest ns)` of a time per step.
fn nanoseconds((median, fastest): (f64, f64)) -> String {
    format!("{:>8.1} ns (fastest {:>8.1})", median * 1e9, fastest * 1e9)
}

fn summary(timings: &Timings) {
    let reference = FreeSeed::default().release([START, 0.0], &TIMES, 1e-5);
    let (fixed_error, fixed_counts) = accuracy(fixed(), &reference);
    let (adaptive_error, adaptive_counts) = accuracy(adaptive(), &reference);
    println!(
        "\nfree seed: median batch per step (fastest), max |Δφ| at t = 0.1 … 0.5 s against the \
         reduced Lagrange reference"
    );
    let driven = timings.get("seed/generated");
    let generated = timings.get("free_seed/fixed/generated");
    for (label, what) in [
        ("free_seed/fixed/generated", "generated"),
        ("free_seed/fixed/interpreted", "interpreted"),
    ] {
        if let Some(step) = timings.get(label) {
            let ratio = driven.map_or(String::from("—"), |d| format!("{:.2}", step.0 / d.0));
            println!(
                "  fixed step {STEP:e} s, {what:<11} {}  = {ratio}× the driven step",
                nanoseconds(step)
            );
        }
    }
    if let Some(d) = driven {
        println!("  driven seed, kinematic step     {}", nanoseconds(d));
    }
    println!("  fixed step: max |Δφ| = {fixed_error:.3e} rad; {fixed_counts}");
    if let Some((median, fastest)) = timings.get("free_seed/adaptive") {
        println!(
            "  adaptive (rtol 1e-6, atol 1e-9): the {RELEASE} s release in {:.1} µs (fastest \
             {:.1}), max |Δφ| = {adaptive_error:.3e} rad; {adaptive_counts}",
            median * 1e6,
            fastest * 1e6
        );
    }
    match exudyn() {
        Ok(peer) => {
            println!(
                "  Exudyn, same scene and step, this run: {:.2} µs per step (fastest {:.2}), \
                 max |Δφ| = {:.3e} rad",
                peer.median * 1e6,
                peer.fastest * 1e6,
                peer.error
            );
            if let Some((ours, _)) = generated {
                let accuracy = if fixed_error <= peer.error {
                    "ours as accurate or more"
                } else {
                    "ours LESS accurate"
                };
                println!(
                    "  Exudyn / generated fixed step: {:.1}× (medians; {accuracy}: {fixed_error:.3e} \
                     against {:.3e} rad)",
                    peer.median / ours,
                    peer.error
                );
            }
        }
        Err(why) => println!("  Exudyn not measured: {why}"),
    }
}

fn main() {
    let mut c = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .configure_from_args();
    let timings = Timings::default();
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/scenes/piston_crank_free.mech"
    );
    let source = std::fs::read_to_string(path).expect("the free seed's scene file");
    let scene = mechgen::compile(mechgen::Input::Text(&source), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{path}: {e}"));
    free_fixed(
        &mut c,
        &timings,
        "free_seed/fixed/generated",
        PistonCrankFree::default(),
    );
    free_fixed(
        &mut c,
        &timings,
        "free_seed/fixed/interpreted",
        Interpreted::new(&scene),
    );
    driven(&mut c, &timings);
    free_adaptive(&mut c, &timings);
    c.final_summary();
    summary(&timings);
}
