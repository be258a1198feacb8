//! The structured solve (explicit assignments, Newton blocks, static LU) against the dense
//! reference (the same equations as one block, partial pivoting at every iteration), against
//! closed forms (the seed at random scales and speeds, random slider-cranks), and against the interpreter following the same plan; the static pivots'
//! fallback on a scene built to defeat them.

use mechgen_examples::closed_form;
use mechgen_examples::scenes::{FourBar, OffsetSlider, PistonCrank};
use mechgen_examples::stability::{FlexiblePistonCrank, SliderCrank};
use mechgen_runtime::nalgebra::{Const, DefaultAllocator};
use mechgen_runtime::{
    Accelerations, Dense, Mechanism, Simulation, SolveError, Solver, SolverOptions, State, Storage,
    Structured, Vector, mechanism,
};
use mechgen_tests::example_scene as interpreted;
use num_dual::{DualNum, second_derivative};
use proptest::prelude::*;

mechanism! {
    /// A two-link arm whose tip is driven around a circle of radius `r` about the shoulder:
    /// the elbow angle stays fixed (the Jacobian stays regular), while every entry of the
    /// coupled block changes sign as the arm turns, so any pivot order fixed in advance meets
    /// a vanishing pivot somewhere.
    mechanism CircleArm {
        param r = 1.5;
        param w = 1.0;
        ground base at (0, 0, 0);
        body upper near (0, 0, -0.515);
        body fore near (0.870, -0.493, 0.664);
        joint shoulder: revolute(base, upper);
        joint elbow: revolute(upper @ (1, 0), fore);
        driver tip_x: x(fore @ (0.8, 0)) = r * cos(w * t);
        driver tip_y: y(fore @ (0.8, 0)) = r * sin(w * t);
        /// The elbow bends anticlockwise.
        branch elbow_up: cross(upper -> upper @ (1, 0), fore -> fore @ (0.8, 0)) > 0;
    }
}

/// The arm's exact positions at time `t` (links 1 and 0.8).
fn arm_positions<D: DualNum<Primitive = f64> + Copy>(t: D, r: f64, w: f64) -> [D; 9] {
    let (l1, l2) = (1.0, 0.8);
    let elbow = ((r * r - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)).acos();
    let offset = (l2 * elbow.sin()).atan2(l1 + l2 * elbow.cos());
    let upper = t * w - D::from(offset);
    let fore = upper + D::from(elbow);
    let zero = D::from(0.0);
    [
        zero,
        zero,
        zero,
        zero,
        zero,
        upper,
        upper.cos() * D::from(l1),
        upper.sin() * D::from(l1),
        fore,
    ]
}

/// q, q̇, q̈ of every state of a run, in order.
type Run = Vec<[Vec<f64>; 3]>;

/// Solves `m` over `steps` equal steps to `t_end` (predictor on), recording every state and the
/// fallbacks taken.
fn run<M>(m: M, options: SolverOptions, t_end: f64, steps: usize) -> (Run, usize)
where
    M: Structured + Accelerations,
    DefaultAllocator: Storage<M::Dim>,
{
    let solver = Solver::with_options(m, options);
    let mut simulation = Simulation::new(solver, 0.0).expect("assembles");
    let (mut states, mut fallbacks) = (Vec::new(), 0);
    simulation
        .run(t_end, steps, |state: &State<M>| {
            fallbacks += state.fallbacks;
            states.push([
                state.q.as_slice().to_vec(),
                state.qd().as_slice().to_vec(),
                state.qdd().as_slice().to_vec(),
            ]);
        })
        .expect("solves");
    (states, fallbacks)
}

/// The largest difference between two runs, per quantity (q, q̇, q̈), relative to that
/// quantity's largest magnitude over the run: entries that are zero in exact arithmetic hold
/// round-off noise, so per-entry relative errors would be meaningless.
fn difference(a: &Run, b: &Run) -> [f64; 3] {
    assert_eq!(a.len(), b.len());
    let mut worst = [0.0f64; 3];
    for level in 0..3 {
        let scale = a
            .iter()
            .flat_map(|s| s[level].iter())
            .fold(0.0f64, |m, x| m.max(x.abs()))
            .max(f64::MIN_POSITIVE);
        for (x, y) in a.iter().zip(b) {
            for (u, v) in x[level].iter().zip(&y[level]) {
                worst[level] = worst[level].max((u - v).abs() / scale);
            }
        }
    }
    worst
}

/// Agreement to round-off: a few hundred ε of each quantity's scale.
const ROUND_OFF: f64 = 1e-13;

fn assert_round_off(what: &str, worst: [f64; 3]) {
    assert!(
        worst.iter().all(|&w| w <= ROUND_OFF),
        "{what}: q, q̇, q̈ differ by {worst:?}"
    );
}

/// The structured solve and the dense reference over a run.
fn compare_with_dense<M>(what: &str, m: M, t_end: f64, steps: usize)
where
    M: Structured + Accelerations + Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    let options = SolverOptions::default();
    let (structured, _) = run(m.clone(), options, t_end, steps);
    let (dense, _) = run(Dense::new(m), options, t_end, steps);
    assert_round_off(what, difference(&structured, &dense));
}

#[test]
fn every_scene_matches_the_dense_reference() {
    let seed_period = core::f64::consts::TAU / 314.0;
    compare_with_dense("seed", PistonCrank::default(), seed_period, 360);
    compare_with_dense(
        "four-bar",
        FourBar::default(),
        core::f64::consts::TAU / 10.0,
        360,
    );
    let oscillating = FlexiblePistonCrank {
        amplitude: 0.5,
        frequency: 2000.0,
        omega: 0.0,
        ..FlexiblePistonCrank::default()
    };
    compare_with_dense("oscillating seed", oscillating, 0.01, 500);
    compare_with_dense(
        "slider-crank",
        SliderCrank::default(),
        core::f64::consts::TAU,
        360,
    );
    compare_with_dense(
        "circle arm",
        CircleArm::default(),
        core::f64::consts::TAU,
        360,
    );
}

#[test]
fn a_positions_only_scene_matches_the_dense_reference() {
    // Posed by a parameter: each solve starts from the last, as an optimiser's would.
    let mut structured = Solver::new(OffsetSlider::default());
    let mut dense = Solver::new(Dense::new(OffsetSlider::default()));
    let mut q = Vector::<Const<12>>::zeros();
    structured.mechanism().initial_guess(&mut q);
    let mut q_dense = q;
    let exact = closed_form::OffsetSlider::default();
    for k in 0..=100 {
        let angle = 0.5 + 0.06 * k as f64;
        structured
            .mechanism_mut()
            .set_parameter("crank_angle", angle)
            .unwrap();
        dense
            .mechanism_mut()
            .set_parameter("crank_angle", angle)
            .unwrap();
        structured.solve_position(&mut q, 0.0).expect("solves");
        dense.solve_position(&mut q_dense, 0.0).expect("solves");
        for (j, ((s, d), e)) in q.iter().zip(&q_dense).zip(exact.q(angle)).enumerate() {
            assert!(
                (s - d).abs() <= 1e-13 * 100.0,
                "q[{j}] at {angle}: {s} vs {d}"
            );
            assert!(
                (s - e).abs() <= 1e-12 * 100.0,
                "q[{j}] at {angle}: {s} vs {e}"
            );
        }
    }
}

#[test]
fn a_static_pivot_that_vanishes_falls_back_and_stays_exact() {
    let period = core::f64::consts::TAU;
    let options = SolverOptions::default();
    let (structured, fallbacks) = run(CircleArm::default(), options, period, 360);
    assert!(fallbacks > 0, "no static pivot failed over a revolution");
    // Against the closed form, every step, fallback or not.
    for (k, state) in structured.iter().enumerate() {
        let t = mechgen_runtime::sample_time(0.0, period, 360, k);
        let exact: [(f64, f64, f64); 9] = second_derivative(|t| arm_positions(t, 1.5, 1.0), t);
        for (j, (value, derivative, second)) in exact.iter().enumerate() {
            for (level, e) in [value, derivative, second].into_iter().enumerate() {
                let c = state[level][j];
                assert!(
                    (c - e).abs() <= 1e-13 * 2.0,
                    "level {level}, q[{j}] at {t}: {c} vs {e}"
                );
            }
        }
    }
    // Partial pivoting throughout gives the same motion; a stricter threshold falls back more.
    let pivoting = SolverOptions {
        static_pivots: false,
        ..options
    };
    let (partial, none) = run(CircleArm::default(), pivoting, period, 360);
    assert_eq!(
        none, 0,
        "fallbacks are counted only where a static order was tried"
    );
    assert_round_off("arm, partial pivoting", difference(&structured, &partial));
    let strict = SolverOptions {
        static_pivot_threshold: 0.9,
        ..options
    };
    let (_, more) = run(CircleArm::default(), strict, period, 360);
    assert!(more > fallbacks, "{more} ≤ {fallbacks}");
}

#[test]
fn reused_factors_leave_the_rates_exact() {
    // Fine steps: the predictor lands within round-off, the second Newton correction is
    // negligible, and the rates are solved with the factors it was computed from.
    let seed = closed_form::PistonCrank::default();
    for steps in [360, 3600] {
        let (states, _) = run(
            PistonCrank::default(),
            SolverOptions::default(),
            seed.period(),
            steps,
        );
        let mut worst = [0.0f64; 3];
        let scales = [200.0, 2e4, 5e6];
        for (k, state) in states.iter().enumerate() {
            let t = mechgen_runtime::sample_time(0.0, seed.period(), steps, k);
            let exact = seed.kinematics(t);
            for (level, e) in [exact.q, exact.qd, exact.qdd].iter().enumerate() {
                for (c, e) in state[level].iter().zip(e) {
                    worst[level] = worst[level].max((c - e).abs() / scales[level]);
                }
            }
        }
        assert!(
            worst.iter().all(|&w| w <= 1e-14),
            "{steps} steps: {worst:?}"
        );
    }
}

#[test]
fn a_singular_block_names_the_coordinates_downstream() {
    // The slider-crank with l = r at its toggle: the rod's angle block is singular, and the
    // slider's x, computed from the rod angle, is left undetermined with it.
    let scene = SliderCrank {
        l: 1.0,
        ..SliderCrank::default()
    };
    let mut solver = Solver::new(scene);
    let t = core::f64::consts::FRAC_PI_2;
    let q = Vector::<Const<12>>::from([0.0, 0.0, 0.0, 0.0, 0.0, t, 0.0, 1.0, -t, 0.0, 0.0, 0.0]);
    let error = solver
        .solve_velocity(&q, t, &mut Vector::<Const<12>>::zeros())
        .unwrap_err();
    assert!(matches!(error, SolveError::Singular { .. }), "{error:?}");
    let names = |indices: &[usize]| -> Vec<&str> {
        indices
            .iter()
            .map(|&i| SliderCrank::COORDINATES[i])
            .collect()
    };
    let undetermined = names(solver.undetermined_coordinates());
    assert_eq!(undetermined, ["rod.theta", "slider.x"]);
}

/// One solve from `guess` at `t`, as (q, q̇, q̈).
fn solve_once<M>(m: M, t: f64, guess: &[f64]) -> Result<[Vec<f64>; 3], SolveError>
where
    M: Structured + Accelerations,
    DefaultAllocator: Storage<M::Dim>,
{
    let mut solver = Solver::new(m);
    let mut q = Vector::zeros_generic(solver.mechanism().dim(), Const::<1>);
    q.as_mut_slice().copy_from_slice(guess);
    let state = solver.solve(t, &q)?;
    Ok([
        state.q.as_slice().to_vec(),
        state.qd().as_slice().to_vec(),
        state.qdd().as_slice().to_vec(),
    ])
}

proptest! {
    // A fixed seed and no regressions file: every run checks the same cases.
    #![proptest_config(ProptestConfig {
        cases: 64,
        failure_persistence: None,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x5EED),
        ..ProptestConfig::default()
    })]

    /// The seed at random scales, speeds and times, from its closed form perturbed by a
    /// thousandth: the structured solve, the dense reference and the interpreter on the `.mech`
    /// twin's plan reach the same state to round-off.
    #[test]
    fn structured_dense_and_interpreted_agree_on_the_seed(
        log_scale in -3.0..3.0f64,
        log_omega in 0.0..4.0f64,
        phase in 0.0..1.0f64,
        nudge in -1e-3..1e-3f64,
    ) {
        let (scale, omega) = (10f64.powf(log_scale), 10f64.powf(log_omega));
        let exact = closed_form::PistonCrank { scale, omega, ..Default::default() };
        let t = phase * exact.period();
        let guess: Vec<f64> = exact.q(t).iter().map(|x| x * (1.0 + nudge)).collect();
        let scene = FlexiblePistonCrank { scale, omega, ..Default::default() };
        let structured = solve_once(scene, t, &guess).expect("structured");
        let dense = solve_once(Dense::new(scene), t, &guess).expect("dense");
        let worst = difference(&vec![structured.clone()], &vec![dense]);
        prop_assert!(worst.iter().all(|&w| w <= ROUND_OFF), "dense: {:.1e}", worst[2]);

        let mut twin = interpreted("piston_crank.mech");
        Mechanism::set_parameter(&mut twin, "omega", omega).expect("parameter");
        if scale == 1.0 {
            let interpreted = solve_once(twin, t, &guess).expect("interpreted");
            let worst = difference(&vec![structured.clone()], &vec![interpreted]);
            prop_assert!(worst.iter().all(|&w| w <= ROUND_OFF), "interpreter: {worst:?}");
        }
        let exact = exact.kinematics(t);
        for (level, e) in [exact.q, exact.qd, exact.qdd].iter().enumerate() {
            let scale = e.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for (c, e) in structured[level].iter().zip(e) {
                prop_assert!((c - e).abs() <= 1e-13 * scale, "level {level}: {c} vs {e}");
            }
        }
    }

    /// Random slider-cranks at random times: the structured solve against the closed form
    /// (the guess a perturbation of it), and the dense reference against the structured solve.
    #[test]
    fn structured_and_dense_agree_on_random_slider_cranks(
        log_r in -3.0..3.0f64,
        ratio in 1.2..4.0f64,
        log_omega in -1.0..4.0f64,
        angle in 0.0..std::f64::consts::TAU,
    ) {
        let (r, omega) = (10f64.powf(log_r), 10f64.powf(log_omega));
        let exact = closed_form::SliderCrank { crank: r, rod: r * ratio, omega };
        let t = angle / omega;
        let guess: Vec<f64> = exact.kinematics(t).q.iter().map(|x| x * 1.0005).collect();
        let scene = SliderCrank { r, l: r * ratio, omega };
        let structured = solve_once(scene, t, &guess).expect("structured");
        let kinematics = exact.kinematics(t);
        let exact = [kinematics.q, kinematics.qd, kinematics.qdd].map(|level| level.to_vec());
        let worst = difference(&vec![exact], &vec![structured.clone()]);
        prop_assert!(worst.iter().all(|&w| w <= ROUND_OFF), "closed form: {worst:?}");
        let dense = solve_once(Dense::new(scene), t, &guess).expect("dense");
        let worst = difference(&vec![structured], &vec![dense]);
        prop_assert!(worst.iter().all(|&w| w <= ROUND_OFF), "dense: {worst:?}");
    }

    /// The interpreter on the four-bar's `.mech` twin against its generated code, at random
    /// times from the closed form.
    #[test]
    fn the_interpreter_follows_the_generated_plan(phase in 0.0..1.0f64) {
        let exact = closed_form::FourBar::default();
        let t = phase * exact.period();
        let guess = exact.q(t);
        let generated = solve_once(FourBar::default(), t, &guess).expect("generated");
        let interpreted = solve_once(interpreted("four_bar.mech"), t, &guess).expect("interpreted");
        let worst = difference(&vec![generated], &vec![interpreted]);
        prop_assert!(worst.iter().all(|&w| w <= ROUND_OFF), "{worst:?}");
    }
}
