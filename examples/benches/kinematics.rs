//! Speed of generated code against the interpreter on the same IR, for the example scenes:
//! evaluating Φ and Φ_q, and one full kinematic step (position, velocity, acceleration at one
//! time, warm-started with the predictor) through the runtime's solver.
//!
//! `cargo bench -p mechgen-examples --bench kinematics`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use mechgen_cli::Interpreted;
use mechgen_examples::scenes::{FourBar, PistonCrank};
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{Matrix, Mechanism, Simulation, Solver, Storage, Vector};

fn interpreted(file: &str) -> Interpreted {
    let path = format!("{}/scenes/{file}", env!("CARGO_MANIFEST_DIR"));
    let source = std::fs::read_to_string(&path).expect("scene file");
    let scene = mechgen::compile_str(&source).unwrap_or_else(|e| panic!("{path}: {e}"));
    Interpreted::new(&scene)
}

/// Benchmarks one mechanism under `label`: Φ, Φ_q, Φ+Φ_q at an assembled state, then a step.
fn bench_scene<M>(c: &mut Criterion, label: &str, mechanism: M, period: f64)
where
    M: Mechanism + Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    let mut simulation =
        Simulation::new(Solver::new(mechanism.clone()), 0.0).expect("scene assembles");
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
    // 360 steps per revolution, as in the examples; time keeps advancing across iterations.
    let h = period / 360.0;
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

fn kinematics(c: &mut Criterion) {
    let seed_period = 2.0 * std::f64::consts::PI / PistonCrank::default().omega;
    bench_scene(c, "seed/generated", PistonCrank::default(), seed_period);
    bench_scene(
        c,
        "seed/interpreted",
        interpreted("piston_crank.mech"),
        seed_period,
    );
    let four_bar_period = 2.0 * std::f64::consts::PI / FourBar::default().omega;
    bench_scene(c, "four_bar/generated", FourBar::default(), four_bar_period);
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
    targets = kinematics
}
criterion_main!(benches);
