//! The straight kinematic step (`Structured::straight_step`, taken by `Solver::solve_into` by
//! default) against the stage sweep it replaces: the same motion over a revolution of every
//! example scene that has one, the seed against its written-out closed form, and, wherever the
//! step declines (guesses far from the solution, a toggle, a loop that cannot close), exactly
//! the sweep's answers and errors; for a scene that computes forces, the reactions of its
//! archived factors as the sweep's.

use mechgen_examples::closed_form;
use mechgen_examples::scenes::{FourBar, Hoeken, PistonCrank, PistonCrankDynamics, QuickReturn};
use mechgen_examples::stability::{SliderCrank, Unclosable};
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{
    Accelerations, Mechanism, Simulation, Solver, SolverOptions, State, Storage, Structured, Vector,
};

/// The options of the stage sweep with its closed-form starts (the straight step off).
fn sweep() -> SolverOptions {
    SolverOptions {
        straight_step: false,
        ..SolverOptions::default()
    }
}

/// Newton's path alone (no closed forms, so no straight step either).
fn newton() -> SolverOptions {
    SolverOptions {
        closed_forms: false,
        ..SolverOptions::default()
    }
}

/// The largest difference of `a` from `b` at each level (positions, velocities,
/// accelerations), relative to that level's largest magnitude in `b`.
fn levels<M: Structured + Accelerations>(a: &State<M>, b: &State<M>) -> [f64; 3]
where
    DefaultAllocator: Storage<M::Dim>,
{
    [
        (a.q.as_slice(), b.q.as_slice()),
        (a.qd().as_slice(), b.qd().as_slice()),
        (a.qdd().as_slice(), b.qdd().as_slice()),
    ]
    .map(|(a, b)| {
        let scale = b.iter().fold(1e-300_f64, |m, v| m.max(v.abs()));
        a.iter()
            .zip(b)
            .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs() / scale))
    })
}

/// Steps `scene` over `turns` periods in `steps` steps with the default options and with
/// `reference` side by side; every default state is a straight step (no Newton iteration,
/// every block from its closed form) within `tolerance` of the reference's.
fn agrees_over<M>(
    scene: M,
    reference: SolverOptions,
    period: f64,
    steps: usize,
    blocks: usize,
    tolerance: f64,
) where
    M: Structured + Accelerations + Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    let start = |options| {
        Simulation::new(Solver::with_options(scene.clone(), options), 0.0)
            .unwrap_or_else(|e| panic!("assembles: {e}"))
    };
    let mut straight = start(SolverOptions::default());
    let mut other = start(reference);
    for i in 1..=steps {
        let t = period * i as f64 / steps as f64;
        let a = straight.step_to(t).unwrap_or_else(|e| panic!("t {t}: {e}"));
        let b = other.step_to(t).unwrap_or_else(|e| panic!("t {t}: {e}"));
        assert_eq!(
            (a.iterations, a.closed_forms, a.evaluations),
            (0, blocks, blocks),
            "t {t}: not a straight step"
        );
        assert_eq!(a.orientation, b.orientation, "t {t}");
        let errors = levels(a, b);
        assert!(errors.iter().all(|&e| e < tolerance), "t {t}: {errors:?}");
    }
}

#[test]
fn every_scene_with_a_straight_step_follows_the_sweep_and_newton_over_a_revolution() {
    for reference in [sweep(), newton()] {
        let seed = PistonCrank::default();
        let period = core::f64::consts::TAU / seed.omega;
        agrees_over(seed, reference, period, 720, 1, 1e-13);
        let four_bar = FourBar::default();
        let period = core::f64::consts::TAU / four_bar.omega;
        agrees_over(four_bar, reference, period, 720, 1, 1e-13);
        let hoeken = Hoeken::default();
        let period = core::f64::consts::TAU / hoeken.omega;
        agrees_over(hoeken, reference, period, 720, 1, 1e-13);
        let quick_return = QuickReturn::default();
        let period = core::f64::consts::TAU / quick_return.omega;
        agrees_over(quick_return, reference, 2.0 * period, 720, 2, 1e-13);
    }
}

#[test]
fn a_scene_that_computes_forces_takes_the_straight_step_with_the_sweeps_reactions() {
    let scene = PistonCrankDynamics::default();
    let period = core::f64::consts::TAU / scene.omega;
    let start = |options| {
        Simulation::new(Solver::with_options(scene, options), 0.0)
            .unwrap_or_else(|e| panic!("assembles: {e}"))
    };
    let (mut straight, mut swept) = (start(SolverOptions::default()), start(sweep()));
    for i in 1..=360 {
        let t = period * f64::from(i) / 360.0;
        let a = straight.step_to(t).unwrap_or_else(|e| panic!("t {t}: {e}"));
        let b = swept.step_to(t).unwrap_or_else(|e| panic!("t {t}: {e}"));
        assert_eq!(
            (a.iterations, a.closed_forms),
            (0, 1),
            "t {t}: not a straight step"
        );
        assert!(
            b.iterations > 0,
            "t {t}: the reference took no Newton iteration"
        );
        let errors = levels(a, b);
        assert!(errors.iter().all(|&e| e < 1e-13), "t {t}: {errors:?}");
        let (r, reference) = (a.constraint_forces(), b.constraint_forces());
        let scale = reference.amax();
        let error = (r - reference).amax() / scale;
        assert!(error < 1e-12, "t {t}: reactions {error:e} off the sweep's");
    }
}

#[test]
fn the_seed_by_straight_steps_matches_its_written_out_closed_form() {
    let hand = closed_form::PistonCrank::default();
    let mut out = ([0.0; 15], [0.0; 15], [0.0; 15]);
    let mut simulation =
        Simulation::new(Solver::new(PistonCrank::default()), 0.0).expect("assembles");
    for i in 1..=720 {
        let t = hand.period() * f64::from(i) / 720.0;
        let state = simulation
            .step_to(t)
            .unwrap_or_else(|e| panic!("t {t}: {e}"));
        assert_eq!(state.iterations, 0, "t {t}: not a straight step");
        hand.written_out(t, &mut out);
        let levels = [
            (state.q.as_slice(), &out.0),
            (state.qd().as_slice(), &out.1),
            (state.qdd().as_slice(), &out.2),
        ];
        for (level, (solved, written)) in levels.into_iter().enumerate() {
            let scale = written.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            for (k, (a, b)) in solved.iter().zip(written).enumerate() {
                let error = (a - b).abs() / scale;
                assert!(error <= 1e-14, "t {t}, level {level}, q[{k}]: {a} vs {b}");
            }
        }
    }
}

/// Solves `scene` at `t` from `guess` with the default options and with the sweep: where the
/// straight step declined (Newton iterated, or the solve failed), the two agree to the bit,
/// errors included; where it was taken, to round-off. Returns whether it was taken.
fn solve_both<M>(scene: &M, t: f64, guess: &Vector<M::Dim>) -> bool
where
    M: Structured + Accelerations + Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    let mut straight = Solver::new(scene.clone());
    let mut other = Solver::with_options(scene.clone(), sweep());
    match (straight.solve(t, guess), other.solve(t, guess)) {
        (Ok(a), Ok(b)) if a.iterations == 0 && a.closed_forms > 0 => {
            let errors = levels(&a, &b);
            assert!(errors.iter().all(|&e| e < 1e-13), "t {t}: {errors:?}");
            true
        }
        (Ok(a), Ok(b)) => {
            let bits = |s: &State<M>| {
                [s.q.as_slice(), s.qd().as_slice(), s.qdd().as_slice()]
                    .map(|v| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>())
            };
            assert_eq!(bits(&a), bits(&b), "t {t}");
            assert_eq!(
                (a.iterations, a.evaluations, a.orientation, a.closed_forms),
                (b.iterations, b.evaluations, b.orientation, b.closed_forms),
                "t {t}"
            );
            false
        }
        (a, b) => {
            let describe = |r: Result<State<M>, _>| r.map(|s| s.q.as_slice().to_vec());
            assert_eq!(
                format!("{:?}", describe(a)),
                format!("{:?}", describe(b)),
                "t {t}"
            );
            false
        }
    }
}

#[test]
fn guesses_the_straight_step_declines_get_exactly_the_sweeps_answer() {
    let seed = PistonCrank::default();
    let mut start = State::new(&seed).q;
    seed.initial_guess(&mut start);
    let solved = Solver::new(seed).solve(0.001, &start).expect("solves");
    let (mut taken, mut declined) = (0, 0);
    // The rod's guess turned by up to a half turn either way, and its y moved: near the
    // solution the straight step takes it; between the two solutions, Newton does.
    for k in -12..=12 {
        for dy in [-40.0, 0.0, 25.0] {
            let mut guess = solved.q;
            guess[8] += core::f64::consts::PI * f64::from(k) / 12.0;
            guess[7] += dy;
            if solve_both(&seed, 0.001, &guess) {
                taken += 1;
            } else {
                declined += 1;
            }
        }
    }
    assert!(
        taken > 0 && declined > 0,
        "taken {taken}, declined {declined}"
    );
}

#[test]
fn at_a_toggle_and_where_a_loop_cannot_close_the_sweeps_errors_stand() {
    // The slider-crank with rod = crank folds at a quarter turn: the straight step declines
    // near it, and the sweep reports the toggle.
    let toggle = SliderCrank {
        r: 1.0,
        l: 1.0,
        omega: 1.0,
    };
    let mut guess = State::new(&toggle).q;
    toggle.initial_guess(&mut guess);
    let mut declined = 0;
    for k in 0..=40 {
        let t = core::f64::consts::FRAC_PI_2 * (0.9 + 0.005 * f64::from(k));
        declined += usize::from(!solve_both(&toggle, t, &guess));
    }
    assert!(declined > 0);
    // No closed form exists: the same error either way.
    let unclosable = Unclosable::default();
    let mut guess = State::new(&unclosable).q;
    unclosable.initial_guess(&mut guess);
    assert!(!solve_both(&unclosable, 0.0, &guess));
    assert!(Solver::new(unclosable).solve(0.0, &guess).is_err());
}
