//! Stiff and extreme cases: every one ends in the right answer (against its closed form) or in
//! the typed error that says what went wrong and when. Never a panic, never a NaN.

use mechgen_examples::stability::{
    self, FlexiblePistonCrank, Parallelogram, SliderCrank, Unclosable,
};
use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{Mechanism, Simulation, SolveError, Solver, Unit, Vector};
use proptest::prelude::*;

/// The accuracy target of the foundation, kept at every scale and speed.
const TOLERANCE: f64 = 1e-10;

#[test]
fn seed_converges_alike_at_every_length_scale() {
    let reference = stability::scaled_seed(1.0, 314.0, 360);
    assert!(reference.failure.is_none(), "{reference:?}");
    for scale in [1e-6, 1e4] {
        let scaled = stability::scaled_seed(scale, 314.0, 360);
        assert!(scaled.failure.is_none(), "scale {scale}: {scaled:?}");
        assert!(
            scaled.errors.max() <= TOLERANCE,
            "scale {scale}: {:?}",
            scaled.errors
        );
        // Unit scaling makes the iteration the same one: same iteration counts, same sub-steps,
        // and a condition estimate that moves only as much as rounding the scale to a power of
        // two changes the scaled entries.
        assert_eq!(scaled.iterations, reference.iterations, "scale {scale}");
        assert_eq!(scaled.substeps, reference.substeps, "scale {scale}");
        let ratio = scaled.max_condition / reference.max_condition;
        assert!((0.25..=4.0).contains(&ratio), "scale {scale}: {ratio}");
    }
}

#[test]
fn seed_driven_at_1e5_rad_per_s_matches_its_closed_form() {
    let fast = stability::scaled_seed(1.0, 1e5, 360);
    assert!(fast.failure.is_none(), "{fast:?}");
    assert!(fast.errors.max() <= TOLERANCE, "{:?}", fast.errors);
    assert!(fast.iterations_per_step() <= 3.0, "{fast:?}");
}

#[test]
fn fast_oscillating_driver_is_followed_over_several_periods() {
    // θ = 0.5 sin(2000 t): 5 periods, 100 steps per period.
    let oscillating = stability::oscillating_seed(0.5, 2000.0, 5, 100);
    assert!(oscillating.failure.is_none(), "{oscillating:?}");
    assert!(
        oscillating.errors.max() <= TOLERANCE,
        "{:?}",
        oscillating.errors
    );
}

#[test]
fn coarse_steps_on_a_fast_oscillation_sub_step_instead_of_jumping() {
    // Six steps per period: the Taylor predictor overshoots badly at the turning points; the
    // simulation must notice and sub-step rather than return another configuration.
    let coarse = stability::oscillating_seed(0.5, 2000.0, 3, 6);
    assert!(coarse.failure.is_none(), "{coarse:?}");
    assert!(coarse.errors.max() <= TOLERANCE, "{:?}", coarse.errors);
}

#[test]
fn rod_a_micrometre_longer_than_the_crank_passes_the_near_toggle_on_its_branch() {
    // l = r (1 + 1e-6): at θ = π/2 the rod is within 1.4e-3 rad of perpendicular to the slide.
    let near = stability::slider_crank(1.0, 1.0 + 1e-6, 360);
    assert!(near.failure.is_none(), "{near:?}");
    assert!(near.errors.q <= TOLERANCE, "{:?}", near.errors);
    // Velocities and accelerations inherit the conditioning: the acceleration peak itself is
    // ~1/√(2e-6) times the crank's, and its closed form loses digits the same way.
    assert!(near.errors.max() <= 1e-7, "{:?}", near.errors);
    let regular = stability::slider_crank(1.0, 2.0, 360);
    assert!(
        near.max_condition > 100.0 * regular.max_condition,
        "near toggle {:.3e}, regular {:.3e}",
        near.max_condition,
        regular.max_condition
    );
}

#[test]
fn rod_equal_to_crank_is_singular_at_the_toggle() {
    let scene = SliderCrank {
        l: 1.0,
        ..SliderCrank::default()
    };
    let period = core::f64::consts::TAU;
    let mut simulation = Simulation::new(Solver::new(scene), 0.0).unwrap();
    let mut last = 0.0;
    let error = simulation
        .run(period, 360, |state| {
            assert!(state.q.iter().all(|x| x.is_finite()));
            last = state.t;
        })
        .unwrap_err();
    let toggle = period / 4.0;
    let SolveError::Singular {
        time,
        condition,
        deficiency,
        ..
    } = error
    else {
        panic!("expected Singular, got {error:?}");
    };
    assert!(
        (time - toggle).abs() <= 1e-12,
        "at t = {time}, toggle at {toggle}"
    );
    assert!(condition > 1e10, "{condition:e}");
    assert_eq!(deficiency, 1);
    assert!(last < toggle && simulation.state().t == last);
    let message = simulation.solver().describe(&error).to_string();
    assert!(message.contains("slider.x"), "{message}");
}

#[test]
fn rod_equal_to_crank_never_steps_through_the_toggle_unnoticed() {
    // Steps that straddle the toggle instead of landing on it: the solution past it is on
    // the other branch (or the toggle is hit by a sub-step); either way a typed error, in time.
    let scene = SliderCrank {
        l: 1.0,
        ..SliderCrank::default()
    };
    let period = core::f64::consts::TAU;
    let mut simulation = Simulation::new(Solver::new(scene), 0.0).unwrap();
    let error = simulation.run(period, 97, |_| {}).unwrap_err();
    let time = error.time().unwrap();
    assert!(
        (time - period / 4.0).abs() <= period / 97.0,
        "{error:?} at t = {time}"
    );
    assert!(
        matches!(
            error,
            SolveError::Singular { .. } | SolveError::BranchFlip { .. }
        ),
        "{error:?}"
    );
}

#[test]
fn parallelogram_with_an_extra_link_reports_the_redundant_equation() {
    let solver = Solver::new(Parallelogram::default());
    let error = match Simulation::new(solver, 0.0) {
        Ok(_) => panic!("redundant constraints must be refused"),
        Err(error) => error,
    };
    let SolveError::Singular { deficiency, .. } = error.error else {
        panic!("expected Singular, got {error:?}");
    };
    assert_eq!(deficiency, 1);
    // The failure hands the solver back: its Display names the dependent equations.
    let named = error.to_string();
    assert!(named.contains("dependent equations"), "{named}");
    // The diagnosis lists every dependent equation; here one of the six pin equations.
    let mut solver = Solver::new(Parallelogram::default());
    let mut q = Vector::<Const<15>>::zeros();
    solver.mechanism().initial_guess(&mut q);
    let error = solver.solve_position(&mut q, 0.0).unwrap_err();
    let dependent: Vec<&str> = solver
        .dependent_equations()
        .iter()
        .map(|&i| solver.mechanism().equation_name(i).unwrap())
        .collect();
    assert_eq!(dependent.len(), 1, "{dependent:?}");
    assert!(dependent[0].contains("_pin.") || dependent[0].contains("_pivot."));
    let message = solver.describe(&error).to_string();
    assert!(message.contains("dependent equations"), "{message}");
}

#[test]
fn four_bar_that_cannot_close_reports_no_assembly() {
    let error = match Simulation::new(Solver::new(Unclosable::default()), 0.0) {
        Ok(_) => panic!("a 100-long frame cannot be closed by 10 + 20 + 20"),
        Err(error) => error,
    };
    let SolveError::NoAssembly { residual, time, .. } = error.error else {
        panic!("expected NoAssembly, got {error:?}");
    };
    assert_eq!(time, 0.0);
    // The best the links can do, stretched in line towards the rocker's pivot, leaves the
    // 50-long gap the README reports (90 from the crank pin to the pivot, 40 of links).
    assert!((residual - 50.0).abs() <= 1e-6 * 50.0, "{residual}");
    // Display (and Debug, for `unwrap`) name the equation, with no scene at hand.
    let message = error.to_string();
    assert!(message.contains("cannot assemble"), "{message}");
    assert!(message.contains("largest in equation `"), "{message}");
    assert_eq!(format!("{error:?}"), message);
}

#[test]
fn seed_from_every_body_at_the_origin_is_refused_on_the_mirror_branch() {
    // As the README states: Newton (damped, then Levenberg–Marquardt) converges, to the mirror
    // assembly (the piston on the crank's side of the bearing), and the declared branch
    // refuses it. The solution is a real one: Φ = 0 to the tolerance.
    let exact = mechgen_examples::closed_form::PistonCrank::default();
    for t in [0.0, 0.002, 0.01] {
        let error = stability::seed_from_origin(t).expect_err("the mirror branch is refused");
        let SolveError::BranchFlip {
            time,
            branch,
            value,
            ..
        } = error
        else {
            panic!("t = {t}: expected BranchFlip, got {error:?}");
        };
        assert_eq!((time, branch), (t, 0), "{error:?}");
        assert!(value < -1e3, "t = {t}: {value}");
        // The same solve, keeping its iterate: an assembly with the crank where the driver
        // puts it, mirrored about the crank pin's vertical.
        let scene = mechgen_examples::scenes::PistonCrank::default();
        let mut q = Vector::<Const<15>>::zeros();
        scene.initial_guess(&mut q);
        for k in 3..12 {
            q[k] = 0.0;
        }
        let mut solver = Solver::new(scene);
        let again = solver.solve_position(&mut q, t).unwrap_err();
        assert_eq!(again, error);
        let mut phi = Vector::<Const<15>>::zeros();
        solver.mechanism().phi(&q, t, &mut phi);
        assert!(phi.amax() <= 1e-9 * 200.0, "t = {t}: {:e}", phi.amax());
        let declared = exact.q(t);
        // Crank and rod pin as declared; the piston on the other side of the crank pin.
        assert!((q[11] - declared[11]).abs() <= TOLERANCE, "t = {t}");
        // Crank pin at crank @ (0, 43); the piston's pin 28 behind its reference point: the
        // mirror puts the piston's pin as far behind the crank pin as the declared one is ahead.
        let pin_x = q[9] - 43.0 * q[11].sin();
        let mirrored = 2.0 * (pin_x + 28.0) - declared[3];
        assert!(
            (q[3] - mirrored).abs() <= 1e-9 * 200.0,
            "t = {t}: piston at {} vs mirror {mirrored}",
            q[3]
        );
    }
}

#[test]
fn non_finite_parameters_and_times_are_typed_errors() {
    use mechgen_runtime::Quantity;
    let mut solver = Solver::new(FlexiblePistonCrank::default());
    let mut q = Vector::<Const<15>>::zeros();
    solver.mechanism().initial_guess(&mut q);
    solver.mechanism_mut().omega = f64::NAN;
    let error = solver.solve_position(&mut q.clone(), 0.0).unwrap_err();
    assert_eq!(
        error,
        SolveError::NonFinite {
            time: 0.0,
            quantity: Quantity::Parameter(1),
            equation: None,
            names: &FlexiblePistonCrank::NAMES,
        }
    );
    // Named by the error itself, as `main` would print it.
    assert!(
        format!("{error:?}").contains("parameter `omega`"),
        "{error:?}"
    );
    solver.mechanism_mut().omega = 314.0;
    let error = solver.solve_position(&mut q, f64::INFINITY).unwrap_err();
    assert!(matches!(
        error,
        SolveError::NonFinite {
            quantity: Quantity::Time,
            ..
        }
    ));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Random slider-cranks, many of which cannot turn or assemble: each solve either satisfies
    /// Φ = 0 to the tolerance with finite derivatives, or returns a typed error with its time.
    #[test]
    fn perturbed_slider_cranks_solve_or_fail_cleanly(
        log_r in -6.0..4.0_f64,
        ratio in 0.2..4.0_f64,
        log_omega in -2.0..5.0_f64,
        t in 0.0..7.0_f64,
        steps in 1usize..40,
    ) {
        let (r, omega) = (10f64.powf(log_r), 10f64.powf(log_omega));
        let scene = SliderCrank { r, l: r * ratio, omega };
        let assembled = Simulation::new(Solver::new(scene), 0.0).map_err(SolveError::from);
        let result = assembled.and_then(|mut simulation| {
            simulation.run(t / omega, steps, |state| {
                let finite = state.q.iter().chain(state.qd().iter()).chain(state.qdd().iter())
                    .all(|x| x.is_finite());
                assert!(finite, "{state:?}");
                let mut phi = Vector::<Const<12>>::zeros();
                scene.phi(&state.q, state.t, &mut phi);
                // Lengths to the tolerance of the scene's size, angles in radians.
                let size = r.max(r * ratio);
                for (i, residual) in phi.iter().enumerate() {
                    let scale = match scene.equation_unit(i) {
                        Unit::Angle => 1.0,
                        Unit::Length => size,
                        Unit::Area => size * size,
                    };
                    assert!(residual.abs() <= 1e-9 * scale, "Φ[{i}] = {residual:e}");
                }
            })
        });
        if let Err(error) = result {
            prop_assert!(error.time().is_some_and(f64::is_finite), "{error:?}");
            let mismatch = matches!(error, SolveError::DimensionMismatch { .. });
            prop_assert!(!mismatch, "{:?}", error);
        }
    }
}
