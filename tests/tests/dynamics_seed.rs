//! The free seed (the piston-crank with its mass properties, the crank free, released from rest
//! at 0.3 rad under gravity) against its reduced one-coordinate Lagrange equation, the
//! kinematics in closed form, integrated to about 1e-12 (`mechgen_tests::reference::seed`):
//!
//! - the crank angle and speed and every coordinate, generated, interpreted and the example
//!   scene `examples/scenes/piston_crank_free.mech` with its twin `PistonCrankFree`;
//! - the order of convergence of the fixed-step mode (ρ∞ = 1 and 0.5), and its steps against
//!   generalized-α written from the papers on the reduced equation;
//! - the reactions along the motion against the closed-form Newton–Euler elimination of the
//!   seed (`mechgen_examples::inverse_dynamics`), the free crank's effort zero;
//! - the constraints at every accepted step; generated and interpreted stepping alike;
//! - property tests over random initial states `(u₀, u̇₀)`: the reference, the energy balance
//!   and the constraints.

mod dynamics;

use dynamics::{
    adaptive, assert_constrained, constraint_residuals, fixed, interpreted, sample, start, times,
    worst,
};
use mechgen_examples::closed_form::Kinematics;
use mechgen_examples::inverse_dynamics::seed_reactions;
use mechgen_examples::scenes::PistonCrankFree;
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{
    Dynamic, EquationsOfMotion, FreeStorage, Integrator, IntegratorOptions, Solver, SolverOptions,
    Storage, Structured,
};
use mechgen_tests::example_scene;
use mechgen_tests::reference::generalized_alpha::GeneralizedAlpha;
use mechgen_tests::reference::ode::{self, Tolerance};
use mechgen_tests::reference::seed::FreeSeed as Reference;
use mechgen_tests::twin;
use proptest::prelude::*;

twin! {
    FREE_SEED,
    mechanism FreeSeed {
        /// Release angle and speed of the crank (rad, rad/s).
        param start = 0.3;
        param spin = 0.0;

        ground liner at (156.8, 0, 0);
        body piston near (130, 0, 0) mass 0.5 inertia 300;
        body rod near (29, 72, -2.35) mass 0.4 inertia 1500;
        body crank near (0, 0, 0) mass 1.2 inertia 2000;
        ground bearing at (0, 0, 0);

        joint crank_pin: revolute(rod @ (41.3, 0), crank @ (0, 43));
        joint piston_pin: revolute(piston @ (-28, 0), rod @ (0, 102.6));
        joint main_bearing: revolute(crank, bearing);
        joint slide: prismatic(liner, piston, along (1, 0));

        free crank_angle: angle(crank) from start speed spin;

        branch piston_outboard: dot(bearing -> liner, rod @ (41.3, 0) -> rod @ (0, 102.6)) > 0;

        gravity (0, -9810);
    }
}

/// The crank's angle in `q`.
const CRANK_THETA: usize = 11;

/// The reference `[φ, φ̇, D]` at `at` from `(φ₀, φ̇₀)`.
fn reference(seed: &Reference, phi0: f64, rate0: f64, at: &[f64]) -> Vec<[f64; 3]> {
    ode::sample(
        |_, y| seed.rate(y),
        0.0,
        [phi0, rate0, 0.0],
        at,
        Tolerance::REFERENCE,
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

/// Largest errors of a release of `mechanism` against the reference over `at`: crank angle
/// (rad), crank speed relative to its largest, every coordinate (mm, rad) and every velocity
/// relative to the largest.
fn errors<M>(mechanism: M, options: IntegratorOptions, at: &[f64]) -> [f64; 4]
where
    M: Dynamic + EquationsOfMotion + Structured,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    let seed = Reference::default();
    let exact = reference(&seed, Reference::RELEASE, 0.0, at);
    let top = exact.iter().map(|y| y[1].abs()).fold(0.0, f64::max);
    let mut integrator = start(mechanism, options);
    let mut e = [0.0f64; 4];
    for (s, y) in sample(&mut integrator, at).iter().zip(&exact) {
        let [q, qd, _] = seed.motion(y[0], y[1]);
        let [u, rate, _] = s.free[0];
        e[0] = e[0].max((u - y[0]).abs());
        e[1] = e[1].max((rate - y[1]).abs() / top);
        e[2] = e[2].max(worst(&s.q, &q));
        e[3] = e[3].max(worst(&s.qd, &qd) / (top * 120.0));
    }
    e
}

#[test]
fn the_free_seed_follows_its_reduced_lagrange_equation() {
    // The crank swings 2.6 rad at up to 13.2 rad/s in this time. Bounds of the fixed step:
    // generalized-α (ρ∞ = 0.9) on the reduced equation, emulated at h = 1e-4, is off by
    // 1.3e-7 rad and 7.8e-8 of the top speed. The error-controlled mode controls the error
    // per second of simulated time: after T = 0.5 s at rtol 1e-8, atol 1e-10 (|φ| ≤ 2.9, so a
    // tolerance ≤ 3e-8 rad) the crank is within about T × 3e-8 = 1.5e-8 rad (measured 1.9e-8
    // rad, 21,600 steps); bounds 3 to 5 times the figures measured. (At rtol 1e-10 the error
    // stays at 1.3e-8 rad over 222,000 steps: there the Newton tolerance, 1e-10 rad per step,
    // not the error control, sets it; and that run takes 20 s in a debug build.)
    let at = times(0.5, 50);
    for (label, e, bounds) in [
        (
            "generated, h = 1e-4",
            errors(FreeSeed::default(), fixed(1e-4, 0.9), &at),
            [5e-7, 3e-7, 5e-5, 3e-7],
        ),
        (
            "interpreted, h = 1e-4",
            errors(interpreted(FREE_SEED), fixed(1e-4, 0.9), &at),
            [5e-7, 3e-7, 5e-5, 3e-7],
        ),
        (
            "PistonCrankFree (the example's twin), h = 1e-4",
            errors(PistonCrankFree::default(), fixed(1e-4, 0.9), &at),
            [5e-7, 3e-7, 5e-5, 3e-7],
        ),
        (
            "piston_crank_free.mech, h = 1e-4",
            errors(
                example_scene("piston_crank_free.mech"),
                fixed(1e-4, 0.9),
                &at,
            ),
            [5e-7, 3e-7, 5e-5, 3e-7],
        ),
        (
            "generated, rtol 1e-8",
            errors(FreeSeed::default(), adaptive(1e-8, 1e-10), &at),
            [6e-8, 5e-8, 3e-6, 3e-8],
        ),
        (
            "interpreted, rtol 1e-8",
            errors(interpreted(FREE_SEED), adaptive(1e-8, 1e-10), &at),
            [6e-8, 5e-8, 3e-6, 3e-8],
        ),
    ] {
        eprintln!(
            "{label}: free seed 0.5 s: φ {:.1e} rad, φ̇ {:.1e} (relative), q {:.1e}, \
             q̇ {:.1e} (relative)",
            e[0], e[1], e[2], e[3]
        );
        for (what, (error, bound)) in ["φ", "φ̇", "q", "q̇"].iter().zip(e.iter().zip(bounds)) {
            assert!(*error <= bound, "{label}: {what} off by {error:e}");
        }
    }
}

#[test]
fn halving_the_step_quarters_the_error_of_the_seed() {
    let t_end = 0.2;
    let exact = reference(&Reference::default(), Reference::RELEASE, 0.0, &[t_end])[0];
    for rho_inf in [1.0, 0.5] {
        let e: Vec<f64> = [100, 200, 400, 800]
            .iter()
            .map(|&n| {
                let mut integrator = start(FreeSeed::default(), fixed(t_end / n as f64, rho_inf));
                integrator.step_to(t_end).unwrap_or_else(|e| panic!("{e}"));
                (integrator.free_state(0)[0] - exact[0]).abs()
            })
            .collect();
        let ratios: Vec<f64> = e.windows(2).map(|w| w[0] / w[1]).collect();
        eprintln!("free seed, ρ∞ = {rho_inf}: errors {e:?}, ratios {ratios:?}");
        for r in &ratios {
            assert!((3.4..=4.6).contains(r), "ρ∞ = {rho_inf}: ratios {ratios:?}");
        }
    }
}

#[test]
fn fixed_steps_are_generalized_alpha_on_the_reduced_equation() {
    // Coordinate partitioning: the integrator is generalized-α on the reduced equation, so its
    // fixed steps are those of `reference::generalized_alpha` on the reference's equation, to
    // the Newton tolerance (1e-10 rad; measured: 6e-17 rad and 3e-16 of the rate).
    let seed = Reference::default();
    for rho_inf in [1.0, 0.5, 0.0] {
        let mut reduced = GeneralizedAlpha::new(
            |_, u: &[f64; 1], v: &[f64; 1]| [seed.acceleration(u[0], v[0])],
            0.0,
            [Reference::RELEASE],
            [0.0],
            rho_inf,
        );
        let mut integrator = start(FreeSeed::default(), fixed(1e-3, rho_inf));
        let mut largest = [0.0f64; 2];
        for n in 1..=200 {
            integrator.step().unwrap_or_else(|e| panic!("{e}"));
            reduced.step(1e-3).unwrap_or_else(|e| panic!("{e}"));
            let [u, rate, _] = integrator.free_state(0);
            let [v, vd, _] = reduced.state();
            largest[0] = largest[0].max((u - v[0]).abs());
            largest[1] = largest[1].max((rate - vd[0]).abs() / (1.0 + vd[0].abs()));
            assert!(
                (u - v[0]).abs() <= 1e-10 && (rate - vd[0]).abs() <= 1e-9 * (1.0 + vd[0].abs()),
                "ρ∞ = {rho_inf}, step {n}: ({u}, {rate}) vs ({}, {})",
                v[0],
                vd[0]
            );
        }
        eprintln!(
            "free seed, h = 1 ms, ρ∞ = {rho_inf}: from generalized-α by {:.1e} rad, {:.1e} \
             (relative rate)",
            largest[0], largest[1]
        );
    }
}

#[test]
fn reactions_are_the_newton_euler_ones_and_the_free_crank_needs_no_torque() {
    let seed = Reference::default();
    let mut integrator = start(FreeSeed::default(), adaptive(1e-9, 1e-12));
    // The free crank's equation is where the driver's was: the reference's last row.
    assert_eq!(integrator.solver().mechanism().free_equation(0), 14);
    // The scale of the forces: the weight of the moving parts at the crank's radius.
    let torque_scale = 2.1 * 9810.0 * 43.0;
    let force_scale = 2.1 * 9810.0;
    let mut largest = [0.0f64; 3];
    for &t in &times(0.5, 25) {
        integrator.step_to(t).unwrap_or_else(|e| panic!("{e}"));
        let state = integrator.state();
        let slice = |v: &[f64]| -> [f64; 15] { v.try_into().expect("15 coordinates") };
        let k = Kinematics {
            t,
            q: slice(state.q.as_slice()),
            qd: slice(state.qd().as_slice()),
            qdd: slice(state.qdd().as_slice()),
        };
        let exact = seed_reactions(&seed.geometry, &seed.mass, &k).in_equation_order();
        let solved = integrator
            .constraint_forces()
            .unwrap_or_else(|e| panic!("{e}"))
            .as_slice()
            .to_vec();
        // Row 14 is the free crank's: its effort is the residual of the equation of motion,
        // as small as the Newton tolerance leaves it (measured 2.3e-8 of m g r, here and in
        // Newton–Euler's closed form at the integrator's q̈). Both solve the same (q, q̇, q̈):
        // the other reactions agree to round-off (measured 2.8e-15 of m g).
        assert!(
            solved[14].abs() <= 1e-7 * torque_scale,
            "t = {t}: effort {}",
            solved[14]
        );
        assert!(
            exact[14].abs() <= 1e-7 * torque_scale,
            "t = {t}: torque {}",
            exact[14]
        );
        let error = worst(&solved[..14], &exact[..14]);
        largest = [
            largest[0].max(solved[14].abs() / torque_scale),
            largest[1].max(exact[14].abs() / torque_scale),
            largest[2].max(error / force_scale),
        ];
        assert!(
            error <= 1e-12 * force_scale,
            "t = {t}: reactions off by {error:e}"
        );
    }
    eprintln!(
        "free seed reactions: effort {:.1e}, Newton–Euler torque {:.1e} (of m g r), \
         reactions off by {:.1e} (of m g)",
        largest[0], largest[1], largest[2]
    );
}

#[test]
fn every_accepted_step_satisfies_the_constraints() {
    for options in [adaptive(1e-6, 1e-9), fixed(1e-3, 0.5), fixed(1e-2, 0.0)] {
        let mut integrator = start(FreeSeed::default(), options);
        assert_constrained(&integrator, &[CRANK_THETA]);
        let mut steps = 0;
        while integrator.t() < 0.5 {
            integrator.step().unwrap_or_else(|e| panic!("{e}"));
            assert_constrained(&integrator, &[CRANK_THETA]);
            steps += 1;
        }
        assert_eq!(integrator.stats().steps, steps);
    }
}

#[test]
fn generated_and_interpreted_step_alike() {
    let mut generated = start(FreeSeed::default(), fixed(1e-3, 0.8));
    let mut twin = start(interpreted(FREE_SEED), fixed(1e-3, 0.8));
    for &t in &times(0.5, 50) {
        let a = generated
            .step_to(t)
            .unwrap_or_else(|e| panic!("{e}"))
            .q
            .as_slice()
            .to_vec();
        let b = twin
            .step_to(t)
            .unwrap_or_else(|e| panic!("{e}"))
            .q
            .as_slice()
            .to_vec();
        // libm against std elementary functions: round-off, through a Newton iteration.
        assert!(worst(&a, &b) <= 1e-9, "t = {t}: {:e}", worst(&a, &b));
        let (ea, eb) = (generated.energy(), twin.energy());
        assert!((ea.total() - eb.total()).abs() <= 1e-9 * ea.kinetic.abs().max(1e5));
    }
    assert_eq!(generated.stats().steps, twin.stats().steps);
}

/// The straight step (its closed forms, its force solve, `V` by `straight_velocities` over
/// its archived factors) steps as the stage sweep with `V` over the sweep's archive, and as
/// partial pivoting with `V` refactored: the same steps, iterations and motion to round-off
/// (a wrong `V` changes the Newton iterations, not the answer).
#[test]
fn the_straight_step_steps_as_the_sweep_and_refactored_velocities() {
    let run = |options: SolverOptions| {
        let solver = Solver::with_options(FreeSeed::default(), options);
        let mut integrator =
            Integrator::new(solver, 0.0, fixed(1e-3, 0.8)).unwrap_or_else(|e| panic!("{e}"));
        let mut straight_steps = 0;
        let motion: Vec<[f64; 3]> = times(0.5, 50)
            .iter()
            .map(|&t| {
                integrator.step_to(t).unwrap_or_else(|e| panic!("{e}"));
                // No Newton iteration, the block from its closed form: the straight step (the
                // sweep counts the iteration that verifies a closed form).
                let state = integrator.state();
                straight_steps += usize::from(state.iterations == 0 && state.closed_forms == 1);
                integrator.free_state(0)
            })
            .collect();
        (motion, integrator.stats(), straight_steps)
    };
    let (straight, stats, taken) = run(SolverOptions::default());
    assert_eq!(taken, 50, "every output state by the straight step");
    for reference in [
        SolverOptions {
            straight_step: false,
            ..SolverOptions::default()
        },
        SolverOptions {
            static_pivots: false,
            ..SolverOptions::default()
        },
    ] {
        let (motion, reference_stats, taken) = run(reference);
        assert_eq!(taken, 0, "the references take no straight step");
        assert_eq!(
            (stats.steps, stats.iterations),
            (reference_stats.steps, reference_stats.iterations)
        );
        for (a, b) in straight.iter().zip(&motion) {
            assert!(worst(a, b) <= 1e-10, "{a:?} vs {b:?}");
        }
    }
}

#[test]
fn set_free_restarts_from_the_new_state() {
    let seed = Reference::default();
    let mut integrator = start(FreeSeed::default(), fixed(1e-4, 0.9));
    integrator.step_to(0.1).unwrap_or_else(|e| panic!("{e}"));
    integrator
        .set_free(0, 1.0, -4.0)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(integrator.t(), 0.1);
    let [u, rate, accel] = integrator.free_state(0);
    assert_eq!([u, rate], [1.0, -4.0]);
    // The new accelerations are solved at once: the reference's φ̈ there.
    let expected = seed.acceleration(1.0, -4.0);
    assert!(
        (accel - expected).abs() <= 1e-8 * expected.abs().max(1.0),
        "{accel} vs {expected}"
    );
    assert_constrained(&integrator, &[CRANK_THETA]);
    let exact = reference(&seed, 1.0, -4.0, &[0.1])[0];
    integrator.step_to(0.2).unwrap_or_else(|e| panic!("{e}"));
    assert!((integrator.free_state(0)[0] - exact[0]).abs() <= 1e-6);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// Any release: the reference, the energy book's balance and the constraints.
    #[test]
    fn any_release_follows_the_reference_and_keeps_its_energy(
        phi0 in -1.5..1.5f64,
        rate0 in -40.0..40.0f64,
    ) {
        let seed = Reference::default();
        let mechanism = FreeSeed {
            start: phi0,
            spin: rate0,
            ..FreeSeed::default()
        };
        // Bounds: generalized-α (ρ∞ = 0.9) on the reduced equation, emulated at this step over
        // a grid of these releases, drifts by 3.2e-6 of the scale below and ends within
        // 3.5e-6 rad and 1.1e-6 (relative) of the reference.
        let mut integrator = start(mechanism, fixed(1e-4, 0.9));
        let [u, rate, _] = integrator.free_state(0);
        prop_assert_eq!([u, rate], [phi0, rate0]);
        let total = integrator.energy().total();
        // The energies exchanged: the kinetic energy of the release and the potential's range.
        let scale = seed.energy(&[phi0, rate0, 0.0]) - seed.energy(&[phi0, 0.0, 0.0])
            + 0.4 * 9810.0 * 86.0;
        while integrator.t() < 0.1 {
            integrator.step().unwrap_or_else(|e| panic!("{e}"));
            let [position, velocity, free] = constraint_residuals(&integrator, &[CRANK_THETA]);
            prop_assert!(position <= 1e-8 && velocity <= 1e-12 && free <= 1e-9);
            let drift = (integrator.energy().total() - total).abs() / scale;
            prop_assert!(drift <= 1e-5, "t = {}: energy drift {:e}", integrator.t(), drift);
        }
        // Wherever the last step ended, the reference there.
        let t = integrator.t();
        let exact = reference(&seed, phi0, rate0, &[t])[0];
        let [u, rate, _] = integrator.free_state(0);
        prop_assert!((u - exact[0]).abs() <= 1e-5, "φ {} vs {}", u, exact[0]);
        prop_assert!((rate - exact[1]).abs() <= 5e-6 * (1.0 + exact[1].abs()));
    }
}
