//! Speed of generated code against the interpreter on the same IR, for the example scenes:
//! evaluating Φ and Φ_q, and one full kinematic step (position, velocity, acceleration at one
//! time, warm-started with the predictor) through the runtime's solver.
//!
//! The finite-difference and automatic-differentiation Jacobians of the accuracy report
//! (`mechgen_examples::report`) are timed in the same groups, and steps use the report's
//! reference setting (its tolerance and steps per revolution), so the report's per-call and
//! per-step figures can be checked against these (the report prints criterion's beside its own).
//!
//! The group `seed/safeguards` times one seed revolution (assembly and 360 steps) with the
//! stability safeguards (unit scaling, condition estimate) on and off.
//!
//! `cargo bench -p mechgen-examples --bench kinematics`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use mechgen_cli::Interpreted;
use mechgen_examples::report::{AutoDiff, CentralDifference, ForwardDifference, Plan};
use mechgen_examples::scenes::{FourBar, PistonCrank};
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{
    Dense, Matrix, Simulation, Solver, SolverOptions, Storage, Structured, Vector,
};

/// The seed generated naively (no folding, no simplification, no shared sub-expressions) by
/// the package's `build.rs`: the baseline the lean code is timed against. Bench-only, so the
/// examples do not pay for compiling it.
// Deliberately unsimplified code (`0.0 - 0.0`, `x * 1.0`, …): lints about it are the point.
#[allow(missing_docs, dead_code, clippy::all)]
mod naive {
    include!(concat!(env!("OUT_DIR"), "/piston_crank_naive.rs"));
}

/// The IR of a scene's `.mech` twin.
fn scene(file: &str) -> mechgen::Scene {
    let path = format!("{}/scenes/{file}", env!("CARGO_MANIFEST_DIR"));
    let source = std::fs::read_to_string(&path).expect("scene file");
    mechgen::compile_str(&source).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn interpreted(file: &str) -> Interpreted {
    Interpreted::new(&scene(file))
}

/// Benchmarks one mechanism under `label`: Φ, Φ_q, Φ+Φ_q at an assembled state, then a step.
fn bench_scene<M>(c: &mut Criterion, label: &str, mechanism: M, period: f64)
where
    M: Structured + Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    let reference = Plan::full().reference;
    let mut simulation = Simulation::new(
        Solver::with_options(mechanism.clone(), reference.options()),
        0.0,
    )
    .expect("scene assembles");
    let q = simulation.state().q.clone();
    let dim = mechanism.dim();
    let mut phi = Vector::<M::Dim>::zeros_generic(dim, mechgen_runtime::nalgebra::Const::<1>);
    let mut jacobian = Matrix::<M::Dim>::zeros_generic(dim, dim);
    let t = 0.1 * period;

    let mut group = c.benchmark_group(label);
    group.bench_function("phi", |b| {
        b.iter(|| mechanism.phi(black_box(&q), black_box(t), &mut phi));
    });
    group.bench_function("jacobian", |b| {
        b.iter(|| mechanism.jacobian(black_box(&q), black_box(t), &mut jacobian));
    });
    group.bench_function("phi_and_jacobian", |b| {
        b.iter(|| {
            mechanism.phi_and_jacobian(black_box(&q), black_box(t), &mut phi, &mut jacobian);
        });
    });
    // The report's reference steps per revolution (360, as in the examples); time keeps
    // advancing across iterations.
    let h = period / reference.steps as f64;
    let mut time = 0.0;
    group.bench_function("step", |b| {
        b.iter(|| {
            time += h;
            let state = simulation.step_to(black_box(time)).expect("steps");
            black_box(state.q[0]);
        });
    });
    group.finish();
}

/// What the stability safeguards cost per seed step, measured in one group: unit scaling and the
/// condition estimate, each switched off alone and together (the line search and the
/// Levenberg–Marquardt fallback cost nothing until a step fails).
fn safeguards(c: &mut Criterion) {
    let seed = PistonCrank::default();
    let period = 2.0 * std::f64::consts::PI / seed.omega;
    let reference = Plan::full().reference;
    let mut group = c.benchmark_group("seed/safeguards");
    for (label, scale_units, estimate_condition) in [
        ("scaling+condition", true, true),
        ("scaling", true, false),
        ("condition", false, true),
        ("neither", false, false),
    ] {
        let options = SolverOptions {
            scale_units,
            estimate_condition,
            ..reference.options()
        };
        // One revolution from assembly per iteration: every variant solves the same 361
        // states (an endless run would drift to huge crank angles, a different workload).
        group.bench_function(label, |b| {
            b.iter(|| {
                let solver = Solver::with_options(seed, options);
                let mut simulation = Simulation::new(solver, 0.0).expect("scene assembles");
                simulation
                    .run(period, reference.steps, |state| {
                        black_box(state.q[0]);
                    })
                    .expect("steps");
            });
        });
    }
    group.finish();
}

fn kinematics(c: &mut Criterion) {
    let seed_period = 2.0 * std::f64::consts::PI / PistonCrank::default().omega;
    bench_scene(c, "seed/generated", PistonCrank::default(), seed_period);
    // The report's Jacobian baselines, around the same generated scene.
    let seed = PistonCrank::default();
    bench_scene(
        c,
        "seed/forward_difference",
        Dense::new(ForwardDifference::new(seed)),
        seed_period,
    );
    bench_scene(
        c,
        "seed/central_difference",
        Dense::new(CentralDifference::new(seed)),
        seed_period,
    );
    let seed_ad = AutoDiff::new(seed, &scene("piston_crank.mech")).expect("twin scenes match");
    bench_scene(c, "seed/autodiff", Dense::new(seed_ad), seed_period);
    // The same seed emitted naively (no folding, no simplification, no sharing): what the lean
    // emission saves, measured in the same run.
    bench_scene(c, "seed/naive", naive::PistonCrank::default(), seed_period);
    bench_scene(
        c,
        "seed/dense",
        Dense::new(PistonCrank::default()),
        seed_period,
    );
    bench_scene(
        c,
        "seed/interpreted",
        interpreted("piston_crank.mech"),
        seed_period,
    );
    let four_bar_period = 2.0 * std::f64::consts::PI / FourBar::default().omega;
    bench_scene(c, "four_bar/generated", FourBar::default(), four_bar_period);
    let four_bar = FourBar::default();
    bench_scene(
        c,
        "four_bar/forward_difference",
        Dense::new(ForwardDifference::new(four_bar)),
        four_bar_period,
    );
    bench_scene(
        c,
        "four_bar/central_difference",
        Dense::new(CentralDifference::new(four_bar)),
        four_bar_period,
    );
    let four_bar_ad = AutoDiff::new(four_bar, &scene("four_bar.mech")).expect("twin scenes match");
    bench_scene(
        c,
        "four_bar/autodiff",
        Dense::new(four_bar_ad),
        four_bar_period,
    );
    bench_scene(
        c,
        "four_bar/interpreted",
        interpreted("four_bar.mech"),
        four_bar_period,
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(std::time::Duration::from_millis(500))
        .measurement_time(std::time::Duration::from_secs(2));
    targets = safeguards, kinematics
}
criterion_main!(benches);
