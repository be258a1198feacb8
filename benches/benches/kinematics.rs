//! Speed of the example scenes, in one run, against their hand-written closed forms
//! (`mechgen_examples::closed_form`): the table of step ratios.
//!
//! A *step* is what a user's loop pays per output time: for the seed and the four-bar, a
//! `Simulation` step (q, q̇, q̈ at the next of 360 times per crank revolution, predictor on, the
//! report's reference tolerance); for the offset slider, a positions-only solve at the next of
//! 360 crank angles, warm-started from the last; for a closed form, its evaluation at that time
//! or angle. Every revolution restarts from a checkpoint assembled at t = 0 (the copy is not
//! timed), so all methods solve the same 360 states however long criterion runs: an endless run
//! would reach huge times, where the predictor's time differences lose digits and the workload
//! changes.
//!
//! Methods per scene: `closed_form`; `generated` (the emitted structured solve); `dense` (the
//! same generated equations through the dense one-block reference); the accuracy report's
//! Jacobian baselines around the same scene (finite differences, forward-mode AD, all dense);
//! `naive` (the seed emitted without folding, simplification or sharing); `interpreted`
//! (`mechgen-interp` on the scene's `.mech` twin). Besides `step`, each solver method times Φ,
//! Φ_q and Φ+Φ_q at an assembled state, which the report prints beside its own figures.
//! For the seed and the four-bar, `generated_solver` and `generated_predicted` time the same
//! steps through `Solver::solve_into` alone, from the last positions and from the positions
//! `Simulation` predicts: the difference between `generated` and `generated_predicted` is
//! `Simulation`'s bookkeeping (predictor, jump and crossing checks, state rotation).
//!
//! The group `seed/safeguards` times a seed step with the stability safeguards (unit scaling,
//! condition estimate) on and off. The groups `seed_forces/*` time the seed with its mass
//! properties, whose step adds the force solve (reactions and driving torque), against the
//! closed form plus its Newton–Euler elimination (`mechgen_examples::inverse_dynamics`) and
//! against the kinematic seed step of the same run.
//!
//! The closed-form groups (issue 23): `{scene}/default` times the steps a user takes (a
//! `Simulation` over `Solver::new`, default options, every safeguard on) and `{scene}/newton`
//! the same with `SolverOptions::closed_forms` off, for the seed, the four-bar, Hoeken's
//! linkage, the quick-return (`quick_return/written_out`: its closed form written out by hand)
//! and the posed offset slider; the last table compares them with the written-out closed forms.
//!
//! After criterion's figures, the run prints each scene's fastest batch per step for
//! `closed_form`, `generated` and `dense`, and their ratios: fastest batches, because the
//! machines are shared and noise only ever adds time.
//!
//! `cargo bench -p mechgen-benches --bench kinematics`

use std::cell::RefCell;
use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkGroup, Criterion, measurement::WallTime};
use mechgen_examples::inverse_dynamics::{MassProperties, seed_reactions};
use mechgen_examples::report::{AutoDiff, CentralDifference, ForwardDifference, Plan};
use mechgen_examples::scenes::{
    FourBar, Hoeken, OffsetSlider, PistonCrank, PistonCrankDynamics, QuickReturn,
};
use mechgen_examples::{closed_form, written_out};
use mechgen_interp::Interpreted;
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{
    Accelerations, Dense, Matrix, Mechanism, Simulation, Solver, SolverOptions, State, Storage,
    Structured, Vector,
};

/// The seed generated naively (no folding, no simplification, no shared sub-expressions) by
/// the package's `build.rs`: the baseline the lean code is timed against.
// Deliberately unsimplified code (`0.0 - 0.0`, `x * 1.0`, …): lints about it are the point.
#[allow(missing_docs, dead_code, clippy::all)]
mod naive {
    include!(concat!(env!("OUT_DIR"), "/piston_crank_naive.rs"));
}

/// Output times (or angles) per crank revolution: the report's reference setting.
const STEPS: u64 = 360;

/// The fastest batch per step of each (scene, method) timed with [`time_steps`].
#[derive(Default)]
struct Fastest(RefCell<Vec<(String, f64)>>);

impl Fastest {
    fn record(&self, name: &str, seconds: f64) {
        let mut all = self.0.borrow_mut();
        match all.iter_mut().find(|(n, _)| n == name) {
            Some((_, best)) => *best = best.min(seconds),
            None => all.push((name.to_owned(), seconds)),
        }
    }

    fn get(&self, name: &str) -> Option<f64> {
        self.0.borrow().iter().find(|(n, _)| n == name).map(|p| p.1)
    }
}

/// Times `step` as criterion's `step` in `group`: `step(run, k)` takes step k (1-based) of a
/// revolution started from a copy of `start`, a new copy every [`STEPS`] steps.
fn time_steps<S: Clone>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    fastest: &Fastest,
    name: &str,
    start: &S,
    mut step: impl FnMut(&mut S, u64),
) {
    group.bench_function("step", |b| {
        b.iter_custom(|iterations| {
            let mut total = Duration::ZERO;
            let mut done = 0;
            while done < iterations {
                let chunk = (iterations - done).min(STEPS);
                let mut run = start.clone();
                let started = Instant::now();
                for k in 1..=chunk {
                    step(&mut run, k);
                }
                total += started.elapsed();
                done += chunk;
            }
            fastest.record(name, total.as_secs_f64() / iterations as f64);
            total
        });
    });
}

/// The IR of a scene's `.mech` twin.
fn scene(file: &str) -> mechgen::Scene {
    let path = format!("{}/../examples/scenes/{file}", env!("CARGO_MANIFEST_DIR"));
    let source = std::fs::read_to_string(&path).expect("scene file");
    mechgen::compile(mechgen::Input::Text(&source), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn interpreted(file: &str) -> Interpreted {
    Interpreted::new(&scene(file))
}

/// Φ, Φ_q and Φ+Φ_q of `mechanism` at `q`.
fn equations<M: Mechanism>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    mechanism: &M,
    q: &Vector<M::Dim>,
    t: f64,
) where
    DefaultAllocator: Storage<M::Dim>,
{
    let dim = mechanism.dim();
    let mut phi = Vector::<M::Dim>::zeros_generic(dim, mechgen_runtime::nalgebra::Const::<1>);
    let mut jacobian = Matrix::<M::Dim>::zeros_generic(dim, dim);
    group.bench_function("phi", |b| {
        b.iter(|| mechanism.phi(black_box(q), black_box(t), &mut phi));
    });
    group.bench_function("jacobian", |b| {
        b.iter(|| mechanism.jacobian(black_box(q), black_box(t), &mut jacobian));
    });
    group.bench_function("phi_and_jacobian", |b| {
        b.iter(|| {
            mechanism.phi_and_jacobian(black_box(q), black_box(t), &mut phi, &mut jacobian);
        });
    });
}

/// A driven scene through `Simulation` under `label`: Φ, Φ_q and Φ+Φ_q at the assembled state,
/// then steps of a revolution of `period`.
fn driven<M>(c: &mut Criterion, fastest: &Fastest, label: &str, mechanism: M, period: f64)
where
    M: Structured + Clone,
    M::Workspace: Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    let options = Plan::full().reference.options();
    driven_with(c, fastest, label, mechanism, period, options);
}

/// [`driven`] with the solver's `options`.
fn driven_with<M>(
    c: &mut Criterion,
    fastest: &Fastest,
    label: &str,
    mechanism: M,
    period: f64,
    options: SolverOptions,
) where
    M: Structured + Clone,
    M::Workspace: Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    let checkpoint = Simulation::new(Solver::with_options(mechanism.clone(), options), 0.0)
        .expect("scene assembles");
    let mut group = c.benchmark_group(label);
    equations(&mut group, &mechanism, &checkpoint.state().q, 0.1 * period);
    simulation_steps(&mut group, fastest, label, &checkpoint, period);
    group.finish();
}

/// The same steps through `Solver::solve_into` alone, from the previous state: what a step
/// costs without `Simulation`'s predictor, crossing checks and sub-stepping (so Newton starts
/// from the last positions rather than from the predicted ones).
fn solver_steps<M>(c: &mut Criterion, fastest: &Fastest, label: &str, mechanism: M, period: f64)
where
    M: Structured + Clone,
    M::Workspace: Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    let options = Plan::full().reference.options();
    let checkpoint =
        Simulation::new(Solver::with_options(mechanism, options), 0.0).expect("scene assembles");
    let h = period / STEPS as f64;
    let mut group = c.benchmark_group(label);
    let start = (checkpoint.solver().clone(), checkpoint.state().clone());
    time_steps(&mut group, fastest, label, &start, |(solver, state), k| {
        solver.solve_into(k as f64 * h, state).expect("solves");
        black_box(state.q[0]);
    });
    group.finish();
}

/// The same steps through `Solver::solve_into`, each started from the positions `Simulation`
/// predicts for it (computed before timing, and checked to give its solutions to the bit):
/// the same Newton work, without the predictor, the jump and crossing checks and the state
/// rotation, so the difference from `Simulation`'s step is that bookkeeping.
fn predicted_steps<M>(c: &mut Criterion, fastest: &Fastest, label: &str, mechanism: M, period: f64)
where
    M: Structured + Accelerations + Clone,
    M::Workspace: Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    let options = Plan::full().reference.options();
    let checkpoint =
        Simulation::new(Solver::with_options(mechanism, options), 0.0).expect("scene assembles");
    let h = period / STEPS as f64;
    let guesses = predictions(&checkpoint, h);
    let mut group = c.benchmark_group(label);
    let start = (checkpoint.solver().clone(), checkpoint.state().clone());
    time_steps(&mut group, fastest, label, &start, |(solver, state), k| {
        state.q.copy_from(&guesses[k as usize - 1]);
        solver.solve_into(k as f64 * h, state).expect("solves");
        black_box(state.q[0]);
    });
    group.finish();
}

/// The positions `Simulation` starts Newton from at each of [`STEPS`] steps of `h` from
/// `checkpoint`: its third-order Taylor prediction (`q + q̇ h + ½ q̈ h² + ⅙ q⃛ h³`, the jerk
/// from the last two accelerations, none at the first step; of every coordinate, where
/// `Simulation` predicts the blocks' only, which are all Newton reads), asserted to lead
/// `solve_into` to `Simulation`'s own solutions exactly.
fn predictions<M>(checkpoint: &Simulation<M>, h: f64) -> Vec<Vector<M::Dim>>
where
    M: Structured + Accelerations + Clone,
    M::Workspace: Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    let mut simulation = checkpoint.clone();
    let mut solver = checkpoint.solver().clone();
    let mut previous: Option<State<M>> = None;
    let mut guesses = Vec::new();
    for k in 1..=STEPS {
        let t = k as f64 * h;
        let current = simulation.state().clone();
        let step = t - current.t;
        let mut guess = current.q.clone();
        for j in 0..guess.len() {
            let jerk = previous.as_ref().map_or(0.0, |p| {
                step * step * step / (6.0 * (current.t - p.t)) * (current.qdd()[j] - p.qdd()[j])
            });
            guess[j] =
                current.q[j] + step * current.qd()[j] + 0.5 * step * step * current.qdd()[j] + jerk;
        }
        let mut check = current.clone();
        check.q.copy_from(&guess);
        solver.solve_into(t, &mut check).expect("solves");
        let solved = simulation.step_to(t).expect("steps");
        assert_eq!(
            check.q, solved.q,
            "the prediction at step {k} is Simulation's"
        );
        guesses.push(guess);
        previous = Some(current);
    }
    guesses
}

/// Steps of a revolution of `period` from `checkpoint`.
fn simulation_steps<M>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    fastest: &Fastest,
    label: &str,
    checkpoint: &Simulation<M>,
    period: f64,
) where
    M: Structured + Clone,
    M::Workspace: Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    let h = period / STEPS as f64;
    time_steps(group, fastest, label, checkpoint, |simulation, k| {
        let state = simulation.step_to(k as f64 * h).expect("steps");
        black_box(state.q[0]);
    });
}

/// A closed form's evaluation at the next of [`STEPS`] times (or angles) of a revolution.
fn closed<F: Clone, R>(
    c: &mut Criterion,
    fastest: &Fastest,
    label: &str,
    form: F,
    h: f64,
    evaluate: impl Fn(&F, f64) -> R,
) {
    let mut group = c.benchmark_group(label);
    time_steps(&mut group, fastest, label, &form, |form, k| {
        black_box(evaluate(form, black_box(k as f64 * h)));
    });
    group.finish();
}

/// A scene's steps as a user takes them (`Solver::new`: default options, every safeguard on)
/// under `{scene}/default`, the stage sweep with its closed-form starts (the straight step off)
/// under `{scene}/sweep`, and Newton's path alone (closed-form groups off) under
/// `{scene}/newton`: what the straight step and the closed forms save, measured in one run.
fn closed_forms<M>(c: &mut Criterion, fastest: &Fastest, scene: &str, mechanism: M, period: f64)
where
    M: Structured + Clone,
    M::Workspace: Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    let variants = [
        ("default", true, true),
        ("sweep", true, false),
        ("newton", false, true),
    ];
    for (method, closed_forms, straight_step) in variants {
        let options = SolverOptions {
            closed_forms,
            straight_step,
            ..SolverOptions::default()
        };
        let label = format!("{scene}/{method}");
        driven_with(c, fastest, &label, mechanism.clone(), period, options);
    }
}

/// The offset slider posed at the next of [`STEPS`] crank angles, warm-started from the last
/// solve (its positions-only, time-free use).
fn posed<M>(
    c: &mut Criterion,
    fastest: &Fastest,
    (label, options): (&str, SolverOptions),
    mechanism: M,
    pose: fn(&mut M, f64),
) where
    M: Structured + Clone,
    M::Workspace: Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    let mut solver = Solver::with_options(mechanism.clone(), options);
    let mut state = State::new(solver.mechanism());
    solver.mechanism().initial_guess(&mut state.q);
    pose(solver.mechanism_mut(), 0.0);
    solver.solve_into(0.0, &mut state).expect("assembles");
    let mut group = c.benchmark_group(label);
    equations(&mut group, &mechanism, &state.q, 0.0);
    let h = 2.0 * std::f64::consts::PI / STEPS as f64;
    time_steps(
        &mut group,
        fastest,
        label,
        &(solver, state),
        |(solver, state), k| {
            pose(solver.mechanism_mut(), k as f64 * h);
            solver.solve_into(0.0, state).expect("solves");
            black_box(state.q[0]);
        },
    );
    group.finish();
}

/// What the stability safeguards cost per seed step: unit scaling and the condition estimate,
/// each switched off alone and together (the line search and the Levenberg–Marquardt fallback
/// cost nothing until a step fails).
fn safeguards(c: &mut Criterion, fastest: &Fastest) {
    let seed = PistonCrank::default();
    let period = 2.0 * std::f64::consts::PI / seed.omega;
    for (label, scale_units, estimate_condition) in [
        ("scaling+condition", true, true),
        ("scaling", true, false),
        ("condition", false, true),
        ("neither", false, false),
    ] {
        let options = SolverOptions {
            scale_units,
            estimate_condition,
            ..Plan::full().reference.options()
        };
        let checkpoint =
            Simulation::new(Solver::with_options(seed, options), 0.0).expect("scene assembles");
        let mut variant = c.benchmark_group(format!("seed/safeguards/{label}"));
        simulation_steps(
            &mut variant,
            fastest,
            &format!("seed/safeguards/{label}"),
            &checkpoint,
            period,
        );
        variant.finish();
    }
}

fn seed(c: &mut Criterion, fastest: &Fastest) {
    let seed = PistonCrank::default();
    let period = 2.0 * std::f64::consts::PI / seed.omega;
    let form = closed_form::PistonCrank::default();
    closed(
        c,
        fastest,
        "seed/closed_form",
        form,
        period / STEPS as f64,
        |f, t| f.kinematics(t),
    );
    closed(
        c,
        fastest,
        "seed/written_out",
        form,
        period / STEPS as f64,
        |f, t| {
            let mut step = ([0.0; 15], [0.0; 15], [0.0; 15]);
            f.written_out(t, &mut step);
            step
        },
    );
    driven(c, fastest, "seed/generated", seed, period);
    closed_forms(c, fastest, "seed", seed, period);
    solver_steps(c, fastest, "seed/generated_solver", seed, period);
    predicted_steps(c, fastest, "seed/generated_predicted", seed, period);
    driven(c, fastest, "seed/dense", Dense::new(seed), period);
    driven(
        c,
        fastest,
        "seed/forward_difference",
        Dense::new(ForwardDifference::new(seed)),
        period,
    );
    driven(
        c,
        fastest,
        "seed/central_difference",
        Dense::new(CentralDifference::new(seed)),
        period,
    );
    let ad = AutoDiff::new(seed, &scene("piston_crank.mech")).expect("twin scenes match");
    driven(c, fastest, "seed/autodiff", Dense::new(ad), period);
    // The same seed emitted naively: what the lean emission saves, measured in the same run.
    driven(
        c,
        fastest,
        "seed/naive",
        naive::PistonCrank::default(),
        period,
    );
    driven(
        c,
        fastest,
        "seed/interpreted",
        interpreted("piston_crank.mech"),
        period,
    );
}

/// The seed with masses: a step with the force solve, generated, through the dense reference
/// and interpreted, against the closed form with its inverse dynamics.
fn seed_forces(c: &mut Criterion, fastest: &Fastest) {
    let seed = PistonCrankDynamics::default();
    let period = 2.0 * std::f64::consts::PI / seed.omega;
    let (form, mass) = (
        closed_form::PistonCrank::default(),
        MassProperties::default(),
    );
    closed(
        c,
        fastest,
        "seed_forces/closed_form",
        (form, mass),
        period / STEPS as f64,
        |(form, mass), t| seed_reactions(form, mass, &form.kinematics(t)),
    );
    driven(c, fastest, "seed_forces/generated", seed, period);
    driven(c, fastest, "seed_forces/dense", Dense::new(seed), period);
    driven(
        c,
        fastest,
        "seed_forces/interpreted",
        interpreted("piston_crank_dynamics.mech"),
        period,
    );
}

fn four_bar(c: &mut Criterion, fastest: &Fastest) {
    let four_bar = FourBar::default();
    let period = 2.0 * std::f64::consts::PI / four_bar.omega;
    let form = closed_form::FourBar::default();
    closed(
        c,
        fastest,
        "four_bar/closed_form",
        form,
        period / STEPS as f64,
        |f, t| f.kinematics(t),
    );
    closed(
        c,
        fastest,
        "four_bar/written_out",
        form,
        period / STEPS as f64,
        |f, t| {
            let mut step = ([0.0; 12], [0.0; 12], [0.0; 12]);
            f.written_out(t, &mut step);
            step
        },
    );
    driven(c, fastest, "four_bar/generated", four_bar, period);
    closed_forms(c, fastest, "four_bar", four_bar, period);
    solver_steps(c, fastest, "four_bar/generated_solver", four_bar, period);
    predicted_steps(c, fastest, "four_bar/generated_predicted", four_bar, period);
    driven(c, fastest, "four_bar/dense", Dense::new(four_bar), period);
    let forward = Dense::new(ForwardDifference::new(four_bar));
    driven(c, fastest, "four_bar/forward_difference", forward, period);
    let central = Dense::new(CentralDifference::new(four_bar));
    driven(c, fastest, "four_bar/central_difference", central, period);
    let ad = AutoDiff::new(four_bar, &scene("four_bar.mech")).expect("twin scenes match");
    driven(c, fastest, "four_bar/autodiff", Dense::new(ad), period);
    driven(
        c,
        fastest,
        "four_bar/interpreted",
        interpreted("four_bar.mech"),
        period,
    );
}

fn offset_slider(c: &mut Criterion, fastest: &Fastest) {
    let form = closed_form::OffsetSlider::default();
    let h = 2.0 * std::f64::consts::PI / STEPS as f64;
    closed(
        c,
        fastest,
        "offset_slider/closed_form",
        form,
        h,
        |f, theta| f.q(theta),
    );
    let pose = |m: &mut OffsetSlider, theta: f64| m.crank_angle = theta;
    let reference = Plan::full().reference.options();
    let slider = OffsetSlider::default();
    posed(
        c,
        fastest,
        ("offset_slider/generated", reference),
        slider,
        pose,
    );
    for (method, closed_forms) in [("default", true), ("newton", false)] {
        let options = SolverOptions {
            closed_forms,
            ..SolverOptions::default()
        };
        let label = format!("offset_slider/{method}");
        posed(c, fastest, (&label, options), slider, pose);
    }
    let pose_dense = |m: &mut Dense<OffsetSlider>, theta: f64| m.inner_mut().crank_angle = theta;
    let dense = Dense::new(slider);
    posed(
        c,
        fastest,
        ("offset_slider/dense", reference),
        dense,
        pose_dense,
    );
}

/// Hoeken's linkage (a four-bar with a long coupler): its closed-form group on and off.
fn hoeken(c: &mut Criterion, fastest: &Fastest) {
    let hoeken = Hoeken::default();
    let period = 2.0 * std::f64::consts::PI / hoeken.omega;
    closed_forms(c, fastest, "hoeken", hoeken, period);
}

/// The crank and slotted lever quick-return (a slot, then a link and ram: two closed-form
/// groups) against its written-out closed form.
fn quick_return(c: &mut Criterion, fastest: &Fastest) {
    let form = written_out::QuickReturn::default();
    let period = form.period();
    closed(
        c,
        fastest,
        "quick_return/written_out",
        form,
        period / STEPS as f64,
        |f, t| {
            let mut step = ([0.0; 15], [0.0; 15], [0.0; 15]);
            f.written_out(t, &mut step);
            step
        },
    );
    closed_forms(c, fastest, "quick_return", QuickReturn::default(), period);
}

/// The closed-form groups' table: each scene's step as a user takes it (default options),
/// against the written-out closed form where there is one and against Newton's path alone.
fn closed_form_summary(fastest: &Fastest) {
    println!("\nclosed-form groups, default options (fastest batch per step, ns):");
    println!(
        "  {:<15} {:>11} {:>9} {:>8} {:>9} {:>8} {:>9}",
        "scene", "written out", "default", "×", "Newton", "×", "saved"
    );
    for scene in [
        "seed",
        "four_bar",
        "hoeken",
        "quick_return",
        "offset_slider",
    ] {
        let time = |method: &str| fastest.get(&format!("{scene}/{method}"));
        let (Some(default), Some(newton)) = (time("default"), time("newton")) else {
            continue;
        };
        let hand = time("written_out");
        let cell = |t: f64| match hand {
            Some(hand) => format!("{:>9.1} {:>8.2}", t * 1e9, t / hand),
            None => format!("{:>9.1} {:>8}", t * 1e9, "—"),
        };
        let hand = hand.map_or("—".to_owned(), |h| format!("{:.1}", h * 1e9));
        println!(
            "  {scene:<15} {hand:>11} {} {} {:>8.0} %",
            cell(default),
            cell(newton),
            100.0 * (1.0 - default / newton)
        );
    }
}

/// The ratio table: fastest batch per step against the scene's closed form, and the
/// generated step against the closed form written out by hand where there is one.
fn summary(fastest: &Fastest) {
    println!("\nfastest batch per step (ns), and × the closed form:");
    println!(
        "  {:<28} {:>11} {:>11} {:>8} {:>11} {:>8}",
        "scene", "closed form", "generated", "×", "dense", "×"
    );
    for (scene, what) in [
        ("seed", "seed (q, q̇, q̈)"),
        ("seed_forces", "seed with forces (… and λ)"),
        ("four_bar", "four-bar (q, q̇, q̈)"),
        ("offset_slider", "offset slider (q)"),
    ] {
        let time = |method: &str| fastest.get(&format!("{scene}/{method}"));
        let Some(base) = time("closed_form") else {
            continue;
        };
        let cell = |t: Option<f64>| match t {
            Some(t) => format!("{:>11.1} {:>8.2}", t * 1e9, t / base),
            None => format!("{:>11} {:>8}", "—", "—"),
        };
        println!(
            "  {what:<28} {:>11.1} {} {}",
            base * 1e9,
            cell(time("generated")),
            cell(time("dense"))
        );
    }
    for scene in ["seed", "four_bar"] {
        let time = |method: &str| fastest.get(&format!("{scene}/{method}"));
        if let (Some(step), Some(solver)) = (time("generated"), time("generated_solver")) {
            println!(
                "  {scene}: Simulation step {:.1} ns; Solver::solve_into from the last positions \
                 {:.1} ns ({:+.1} ns: what the predictor saves, less the bookkeeping)",
                step * 1e9,
                solver * 1e9,
                (step - solver) * 1e9
            );
        }
        if let (Some(step), Some(solver)) = (time("generated"), time("generated_predicted")) {
            println!(
                "  {scene}: Solver::solve_into from Simulation's predictions {:.1} ns \
                 ({:+.1} ns: Simulation's bookkeeping, the predictor and the jump and crossing checks)",
                solver * 1e9,
                (step - solver) * 1e9
            );
        }
        if let (Some(hand), Some(generated)) = (time("written_out"), time("generated")) {
            println!(
                "  {scene}: written out by hand {:.1} ns per step; generated {:.2}× that",
                hand * 1e9,
                generated / hand
            );
        }
    }
    if let (Some(forces), Some(kinematics)) = (
        fastest.get("seed_forces/generated"),
        fastest.get("seed/generated"),
    ) {
        println!(
            "  seed force solve: {:.1} ns per step ({:.2}× the kinematic step)",
            (forces - kinematics) * 1e9,
            forces / kinematics
        );
    }
    let safeguards = fastest.get("seed/safeguards/scaling+condition");
    if let (Some(on), Some(off)) = (safeguards, fastest.get("seed/safeguards/neither")) {
        println!(
            "  seed safeguards (scaling + condition estimate): {:.1} ns per step ({:+.1} %)",
            (on - off) * 1e9,
            100.0 * (on / off - 1.0)
        );
    }
}

fn main() {
    let mut c = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .configure_from_args();
    let fastest = Fastest::default();
    seed(&mut c, &fastest);
    seed_forces(&mut c, &fastest);
    four_bar(&mut c, &fastest);
    offset_slider(&mut c, &fastest);
    hoeken(&mut c, &fastest);
    quick_return(&mut c, &fastest);
    safeguards(&mut c, &fastest);
    c.final_summary();
    summary(&fastest);
    closed_form_summary(&fastest);
}
