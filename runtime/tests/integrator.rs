//! The forward-dynamics integrator against independent references: the pendulum's
//! one-coordinate Lagrange equation integrated by RK4 with tiny steps in the test, its
//! small-amplitude harmonic solution and its large-amplitude period from the complete elliptic
//! integral (by the arithmetic–geometric mean), and the modal solution of two sliders on
//! springs (the stiff case); plus the constraint residuals, the force solve of the produced
//! motion, the energy balance, and the typed errors.

mod common;

use common::cart_pendulum::CartPendulum;
use common::double_pendulum::DoublePendulum;
use common::free_pendulum::FreePendulum;
use common::free_slider_crank::FreeSliderCrank;
use common::scene::Scene;
use common::sliders::Sliders;
use core::f64::consts::{FRAC_PI_2, PI};
use mechgen_runtime::{
    DynamicsError, Integrator, IntegratorOptions, Mechanism, Solver, SolverOptions, StepControl,
};

type Pendulum = Integrator<Scene<FreePendulum>>;

fn fixed(rho_inf: f64, step: f64) -> IntegratorOptions {
    IntegratorOptions {
        rho_inf,
        control: StepControl::Fixed { step },
        ..IntegratorOptions::default()
    }
}

fn adaptive(rho_inf: f64, rtol: f64, atol: f64) -> IntegratorOptions {
    IntegratorOptions {
        rho_inf,
        control: StepControl::Adaptive {
            rtol,
            atol,
            initial: 1e-3,
            min: 1e-12,
            max: f64::INFINITY,
        },
        ..IntegratorOptions::default()
    }
}

fn pendulum(p: FreePendulum, options: IntegratorOptions) -> Pendulum {
    match Integrator::new(Solver::new(Scene::new(p)), 0.0, options) {
        Ok(integrator) => integrator,
        Err(error) => panic!("{error}"),
    }
}

/// `(θ, θ̇)` at `t` from the pendulum's Lagrange equation, by classical RK4 with steps of at
/// most 1e-4 s (error ~1e-15 over a few seconds).
fn reference(p: &FreePendulum, theta0: f64, rate0: f64, t: f64) -> (f64, f64) {
    let n = (t / 1e-4).ceil().max(1.0) as usize;
    let h = t / n as f64;
    let f = |y: [f64; 2]| [y[1], p.theta_ddot(y[0], y[1])];
    let mut y = [theta0, rate0];
    for _ in 0..n {
        let k1 = f(y);
        let k2 = f([y[0] + 0.5 * h * k1[0], y[1] + 0.5 * h * k1[1]]);
        let k3 = f([y[0] + 0.5 * h * k2[0], y[1] + 0.5 * h * k2[1]]);
        let k4 = f([y[0] + h * k3[0], y[1] + h * k3[1]]);
        for i in 0..2 {
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    (y[0], y[1])
}

/// The position and velocity constraint residuals of the pendulum's state, each row in its
/// unit (lengths relative to the rod), the free row against the integrator's free state.
fn residuals(integrator: &Pendulum) -> (f64, f64) {
    let p = integrator.solver().mechanism().inner();
    let state = integrator.state();
    let (q, qd) = (&state.q, state.qd());
    let [u, ud, _] = integrator.free_state(0);
    let l = p.length;
    let (s, c) = (q.z.sin(), q.z.cos());
    let position = [(q.x - l * c) / l, (q.y - l * s) / l, q.z - u];
    let velocity = [
        (qd.x + l * s * qd.z) / l,
        (qd.y - l * c * qd.z) / l,
        qd.z - ud,
    ];
    let max = |v: [f64; 3]| v.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
    (max(position), max(velocity))
}

/// The largest error in θ and θ̇ over the samples t = 0.1, 0.2, …, `t_end` of a fixed-step run
/// released from rest at `theta0`.
fn fixed_step_error(rho: f64, h: f64, theta0: f64, t_end: f64) -> (f64, f64) {
    let p = FreePendulum::released(theta0, 0.0);
    let samples = (t_end / 0.1).round() as usize;
    let exact: Vec<(f64, f64)> = (1..=samples)
        .map(|k| reference(&p, theta0, 0.0, 0.1 * k as f64))
        .collect();
    let mut integrator = pendulum(p, fixed(rho, h));
    let (mut position, mut velocity) = (0.0_f64, 0.0_f64);
    for (k, (theta, rate)) in exact.into_iter().enumerate() {
        let t = 0.1 * (k + 1) as f64;
        integrator.step_to(t).unwrap();
        assert_eq!(integrator.t(), t);
        let [u, ud, _] = integrator.free_state(0);
        position = position.max((u - theta).abs());
        velocity = velocity.max((ud - rate).abs());
    }
    (position, velocity)
}

#[test]
fn halving_the_step_divides_the_error_by_four_for_every_rho() {
    let theta0 = -FRAC_PI_2 + 1.0;
    for rho in [1.0, 0.8, 0.5, 0.0] {
        let errors: Vec<(f64, f64)> = [0.02, 0.01, 0.005]
            .iter()
            .map(|&h| fixed_step_error(rho, h, theta0, 2.0))
            .collect();
        eprintln!("ρ∞ = {rho}: largest errors (θ, θ̇) at h = 0.02, 0.01, 0.005: {errors:?}");
        for pair in errors.windows(2) {
            let (position, velocity) = (pair[0].0 / pair[1].0, pair[0].1 / pair[1].1);
            eprintln!("ρ∞ = {rho}: ratios {position:.3} {velocity:.3}");
            assert!(
                (3.5..4.6).contains(&position),
                "ρ∞ = {rho}: θ ratio {position}"
            );
            assert!(
                (3.5..4.6).contains(&velocity),
                "ρ∞ = {rho}: θ̇ ratio {velocity}"
            );
        }
    }
}

#[test]
fn a_small_swing_follows_the_harmonic_solution() {
    let amplitude = 1e-3;
    let p = FreePendulum::released(-FRAC_PI_2 + amplitude, 0.0);
    let w = p.omega();
    let mut integrator = pendulum(p, adaptive(0.9, 1e-9, 1e-12));
    for k in 1..=40 {
        let t = 0.05 * k as f64;
        integrator.step_to(t).unwrap();
        let phi = integrator.free_state(0)[0] + FRAC_PI_2;
        let harmonic = amplitude * (w * t).cos();
        // The nonlinearity shifts the frequency by a relative φ0²/16 ≈ 6e-8.
        assert!(
            (phi - harmonic).abs() < 1e-3 * amplitude,
            "t = {t}: {phi} vs {harmonic}"
        );
    }
}

/// K(k) = π / (2 AGM(1, √(1 − k²))).
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0_f64, (1.0 - k * k).sqrt());
    while (a - b).abs() > 1e-16 * a {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    PI / (2.0 * a)
}

#[test]
fn a_large_swing_returns_after_the_elliptic_period() {
    let amplitude = 2.5;
    let p = FreePendulum::released(-FRAC_PI_2 + amplitude, 0.0);
    let period = 4.0 * elliptic_k((0.5 * amplitude).sin()) / p.omega();
    let mut integrator = pendulum(p, adaptive(0.9, 1e-7, 1e-10));
    integrator.step_to(period).unwrap();
    let [u, ud, _] = integrator.free_state(0);
    eprintln!(
        "period {period}: φ − φ0 = {:e}, φ̇ = {ud:e}, {:?}",
        u + FRAC_PI_2 - amplitude,
        integrator.stats()
    );
    assert!((u + FRAC_PI_2 - amplitude).abs() < 1e-5);
    assert!(ud.abs() < 1e-4);
    // Half a period later it is at the other extreme.
    integrator.step_to(1.5 * period).unwrap();
    let [u, ud, _] = integrator.free_state(0);
    assert!((u + FRAC_PI_2 + amplitude).abs() < 1e-5);
    assert!(ud.abs() < 1e-4);
}

#[test]
fn constraints_hold_at_every_accepted_step() {
    for options in [fixed(0.7, 0.01), adaptive(0.9, 1e-6, 1e-9)] {
        let mut integrator = pendulum(FreePendulum::released(0.4, 2.0), options);
        let (mut position, mut velocity) = (0.0_f64, 0.0_f64);
        for _ in 0..300 {
            integrator.step().unwrap();
            let (p, v) = residuals(&integrator);
            position = position.max(p);
            velocity = velocity.max(v);
        }
        eprintln!("largest residuals: |Φ| {position:e}, |Φ_q q̇ − ν| {velocity:e}");
        // The solver's acceptance tolerance (scaled) is 1e-8; Newton lands far below it.
        assert!(position < 1e-8, "{position}");
        assert!(velocity < 1e-13, "{velocity}");
    }
}

/// The reactions after a step are the force solve of the state's motion, and they match the
/// reference: the pin carries `m (a − g)` with the centre's acceleration from the reference
/// equation's θ, θ̇, θ̈; the free degree of freedom's effort vanishes.
#[test]
fn reactions_are_the_force_solve_of_the_motion() {
    let p = FreePendulum::released(-0.3, 1.0);
    let mut integrator = pendulum(p.clone(), fixed(0.9, 1e-3));
    integrator.step_to(0.4).unwrap();
    let (theta, rate) = reference(&p, -0.3, 1.0, 0.4);
    let theta_ddot = p.theta_ddot(theta, rate);
    let (l, m, g) = (p.length, p.mass, p.gravity);
    let (s, c) = (theta.sin(), theta.cos());
    let ax = -l * s * theta_ddot - l * c * rate * rate;
    let ay = l * c * theta_ddot - l * s * rate * rate;
    // The pin's force on the bob, from Newton's law on the centre.
    let pin = [m * ax, m * (ay + g)];
    let state = integrator.state().clone();
    let [u, ud, udd] = integrator.free_state(0);
    let reactions = *integrator.constraint_forces().unwrap();
    // Φ_qᵀ λ = F with F = Q − M q̈: the pin's multipliers are minus its force on the bob.
    assert!(
        (reactions[0] + pin[0]).abs() < 1e-5 * m * g,
        "{reactions:?} vs {pin:?}"
    );
    assert!(
        (reactions[1] + pin[1]).abs() < 1e-5 * m * g,
        "{reactions:?} vs {pin:?}"
    );
    assert!(
        reactions[2].abs() < 1e-8 * m * g * l,
        "effort {}",
        reactions[2]
    );
    // A fresh solver at the same free state and time gives the same force solve.
    let mut same = p.clone();
    same.free = [u, ud, udd];
    let mut solver = Solver::new(Scene::new(same));
    let fresh = solver.solve(state.t, &state.q).unwrap();
    let difference = (fresh.constraint_forces() - reactions).amax();
    assert!(difference < 1e-9 * m * g, "{difference}");
}

/// Two sliders: the slow mode resolved by the step, the fast one (from a spring k2) with a
/// period 1000× shorter than it.
fn stiff_sliders(h: f64, excite: f64) -> (Sliders, [f64; 2], f64) {
    let masses = [1.0, 1.0];
    let k1 = 2.0 * (2.0 * PI).powi(2);
    let fast = 2.0 * PI * 1000.0 / h;
    let k2 = 0.5 * fast * fast;
    // Modes: det(K − ω² M) = 0 with K = [[k1 + k2, −k2], [−k2, k2]], M = I.
    let trace = k1 + 2.0 * k2;
    let det = k1 * k2;
    let slow2 = 0.5 * (trace - (trace * trace - 4.0 * det).sqrt());
    // Slow mode shape (k1 + k2 − ω²) φa = k2 φb.
    let shape = [1.0, (k1 + k2 - slow2) / k2];
    let (gap, amplitude) = (0.5, 0.1);
    let sliders = Sliders {
        masses,
        k1,
        k2,
        c2: 0.0,
        gap,
        initial: [
            (amplitude * shape[0], 0.0),
            (gap + amplitude * shape[1] + excite, 0.0),
        ],
        free: [[0.0; 3]; 2],
    };
    (sliders, shape.map(|s| amplitude * s), slow2.sqrt())
}

#[test]
fn a_stiff_spring_neither_blows_up_nor_needs_a_small_step() {
    // Not a whole slow period: at its extremes the phase error shows only at second order.
    let t_end = 0.8;
    for rho in [1.0, 0.8, 0.0] {
        let mut errors = vec![];
        for h in [0.02, 0.01, 0.005] {
            let (sliders, modal, w) = stiff_sliders(0.01, 0.0);
            let gap = sliders.gap;
            let mut integrator =
                Integrator::new(Solver::new(Scene::new(sliders)), 0.0, fixed(rho, h)).unwrap();
            integrator
                .run(t_end, |state, _| {
                    assert!(state.q[0].abs() < 0.2 && (state.q[3] - gap).abs() < 0.2);
                })
                .unwrap();
            let exact = modal[0] * (w * t_end).cos();
            errors.push((integrator.free_state(0)[0] - exact).abs());
            eprintln!("ρ∞ = {rho}, h = {h}: {:?}", integrator.stats());
            // Linear: the prediction is the answer, which the second evaluation confirms.
            let stats = integrator.stats();
            assert!(10 * stats.iterations <= 21 * stats.steps, "{stats:?}");
        }
        eprintln!("stiff ρ∞ = {rho}: errors {errors:?}");
        // Second order (÷ 4 per halving) on the slow mode, amplitude 0.1, the fast one
        // 1000 × beyond the middle step.
        let amplitude = 0.1;
        assert!(errors[0] < 0.05 * amplitude, "{errors:?}");
        for pair in errors.windows(2) {
            assert!((3.5..4.5).contains(&(pair[0] / pair[1])), "{errors:?}");
        }
    }
}

/// The fast mode excited: with ρ∞ = 1 its amplitude is kept (never grows), with ρ∞ < 1 it is
/// damped out within a few steps, the slow motion untouched.
#[test]
fn numerical_damping_removes_an_excited_stiff_mode() {
    let excite = 1e-4;
    for (rho, bound) in [(1.0, 1.0 + 1e-9), (0.5, 1e-6), (0.0, 1e-6)] {
        let (sliders, _, _) = stiff_sliders(0.01, excite);
        let gap = sliders.gap;
        let mut integrator =
            Integrator::new(Solver::new(Scene::new(sliders)), 0.0, fixed(rho, 0.01)).unwrap();
        // Stretch of the stiff spring beyond the slow mode's (k1-driven) share.
        let fast = |i: &Integrator<Scene<Sliders>>| {
            let q = &i.state().q;
            let k = i.solver().mechanism().inner();
            let quasi_static = -k.k1 * q[0] / k.k2;
            (q[3] - q[0] - gap) + quasi_static
        };
        let mut largest = 0.0_f64;
        for step in 0..40 {
            integrator.step().unwrap();
            if step >= 30 {
                largest = largest.max(fast(&integrator).abs());
            }
        }
        eprintln!(
            "ρ∞ = {rho}: fast-mode amplitude after 30 steps {largest:e} {:?}",
            integrator.stats()
        );
        assert!(largest <= bound * excite, "ρ∞ = {rho}: {largest}");
    }
}

#[test]
fn bad_options_are_refused_by_name() {
    let p = FreePendulum::released(-1.0, 0.0);
    let cases = [
        (fixed(f64::NAN, 0.01), "rho_inf"),
        (fixed(1.5, 0.01), "rho_inf"),
        (fixed(0.9, 0.0), "step"),
        (fixed(0.9, f64::INFINITY), "step"),
        (adaptive(0.9, f64::NAN, 1e-9), "rtol"),
        (adaptive(0.9, 0.0, 0.0), "atol"),
        (
            IntegratorOptions {
                newton_tolerance: -1.0,
                ..IntegratorOptions::default()
            },
            "newton_tolerance",
        ),
    ];
    for (options, name) in cases {
        match Integrator::new(Solver::new(Scene::new(p.clone())), 0.0, options) {
            Err(DynamicsError::BadOptions { option, .. }) => assert_eq!(option, name),
            Err(other) => panic!("{name}: {other}"),
            Ok(_) => panic!("{name} accepted"),
        }
    }
    let mut integrator = pendulum(p, fixed(0.9, 0.01));
    integrator.step_to(0.1).unwrap();
    for t in [f64::NAN, 0.05] {
        let error = integrator.step_to(t).map(|_| ()).unwrap_err();
        assert!(matches!(
            error,
            DynamicsError::BadOptions { option: "t", .. }
        ));
    }
    let error = integrator.set_free(0, f64::INFINITY, 0.0).unwrap_err();
    assert!(matches!(
        error,
        DynamicsError::BadOptions {
            option: "value",
            ..
        }
    ));
    let error = integrator.set_free(1, 0.0, 0.0).unwrap_err();
    assert!(matches!(
        error,
        DynamicsError::BadOptions { option: "free", .. }
    ));
    assert_eq!(integrator.t(), 0.1);
}

#[test]
fn a_massless_free_degree_of_freedom_is_named() {
    let mut p = FreePendulum::released(-1.0, 0.0);
    p.mass = 0.0;
    p.inertia = 0.0;
    let Err(error) = Integrator::new(Solver::new(Scene::new(p)), 0.0, fixed(0.9, 0.01)) else {
        panic!("a massless pendulum started");
    };
    assert!(matches!(
        error,
        DynamicsError::SingularMass {
            free: 0,
            equation: 2,
            ..
        }
    ));
    let message = error.to_string();
    assert!(
        message.contains("`swing`") && message.contains("no mass"),
        "{message}"
    );
}

#[test]
fn the_step_falls_below_its_minimum_with_a_typed_error() {
    let options = IntegratorOptions {
        control: StepControl::Adaptive {
            rtol: 1e-14,
            atol: 1e-16,
            initial: 0.1,
            min: 0.05,
            max: 1.0,
        },
        ..IntegratorOptions::default()
    };
    let mut integrator = pendulum(FreePendulum::released(-1.0, 0.0), options);
    let error = integrator.step().map(|_| ()).unwrap_err();
    assert!(
        matches!(error, DynamicsError::StepTooSmall { min: 0.05, .. }),
        "{error}"
    );
    assert_eq!(integrator.t(), 0.0);
    assert!(integrator.free_state(0).iter().all(|x| x.is_finite()));
}

#[test]
fn newton_failure_is_a_typed_error() {
    let options = IntegratorOptions {
        max_iterations: 1,
        newton_tolerance: 1e-300,
        ..fixed(0.9, 0.05)
    };
    let mut integrator = pendulum(FreePendulum::released(-1.0, 3.0), options);
    let error = integrator.step().map(|_| ()).unwrap_err();
    assert!(
        matches!(error, DynamicsError::NoConvergence { iterations: 1, .. }),
        "{error}"
    );
    assert_eq!(integrator.t(), 0.0);
}

/// The free coordinate x cannot pass the rod's reach: where the rod is horizontal the
/// partition is singular (a toggle for the free motion: `V = ∂q/∂x` is infinite there). Past
/// it the kinematic solve would follow the reflected motion θ → −θ with the same smooth x(t)
/// (a silent wrong answer); instead the step that meets it fails with `Toggle` at that time,
/// the state before it kept: at fixed steps the first step whose end is past the toggle, in
/// the error-controlled mode within half a millisecond of it.
#[test]
fn a_toggle_met_by_the_free_motion_is_a_typed_error() {
    let mut p = FreePendulum::released(-2.0, 0.0);
    p.free_x = true;
    // x = L cos(−2) moving right fast enough to swing past horizontal (x = L, θ = 0).
    let speed = 8.0;
    p.initial = (Some(p.length * (-2.0_f64).cos()), speed);
    let rate = speed / (-p.length * (-2.0_f64).sin());
    // The time θ reaches 0, by bisection on the reference.
    let (mut before, mut after) = (0.0, 1.0);
    assert!(reference(&p, -2.0, rate, after).0 > 0.0);
    while after - before > 1e-9 {
        let mid = 0.5 * (before + after);
        if reference(&p, -2.0, rate, mid).0 < 0.0 {
            before = mid;
        } else {
            after = mid;
        }
    }
    let toggle = before;
    for options in [
        fixed(0.9, 0.01),
        fixed(0.9, 0.001),
        adaptive(0.9, 1e-6, 1e-9),
    ] {
        let mut integrator = pendulum(p.clone(), options);
        let Err(error) = integrator.step_to(2.0).map(|_| ()) else {
            panic!("passed the toggle");
        };
        let described = integrator.describe(&error).to_string();
        eprintln!("toggle at {toggle}: {described} {:?}", integrator.stats());
        let DynamicsError::Toggle { t, step } = error else {
            panic!("{described}");
        };
        // The state before the step is kept, short of the toggle.
        assert!(integrator.t() < toggle && integrator.t() + step == t);
        assert!(integrator.state().q.iter().all(|x| x.is_finite()));
        if let StepControl::Fixed { step: h } = options.control {
            // The first step past it (the method's phase error at these steps is far below
            // 1e-4 s).
            assert!(
                integrator.t() <= toggle + 1e-4 && t > toggle - 1e-4,
                "{t} vs {toggle}"
            );
            // The step the clock takes: h to rounding.
            assert!((step - h).abs() <= 1e-12 * h, "{step} vs {h}");
        } else {
            // Stopped by the growth of ‖V‖ (a thousandfold where |sin θ| is a thousandth of
            // its start's: measured 0.19 ms before the toggle).
            assert!((t - toggle).abs() < 5e-4, "{t} vs {toggle}");
        }
    }
}

/// A free value not declared is the driven quantity at the scene's guess, assembled.
#[test]
fn an_undeclared_initial_value_comes_from_the_guess() {
    let mut p = FreePendulum::released(-1.2, 0.0);
    p.initial = (None, 0.5);
    let integrator = pendulum(p, fixed(0.9, 0.01));
    let [u, ud, udd] = integrator.free_state(0);
    assert!((u + 1.2).abs() < 1e-12 && ud == 0.5);
    let p = integrator.solver().mechanism().inner();
    assert!((udd - p.theta_ddot(-1.2, 0.5)).abs() < 1e-12);
    assert!(integrator.solver().mechanism().coordinate_name(2) == Some("bob.theta"));
}

/// Error control: the global error against the reference stays within a few × the
/// tolerance (which is per second of simulated time: 5 s here) and follows it in proportion,
/// the steps growing as tol^(−1/2) (local error O(h³) against a tolerance ∝ h).
#[test]
fn the_error_controlled_mode_follows_its_tolerance() {
    let theta0 = -FRAC_PI_2 + 1.0;
    let p = FreePendulum::released(theta0, 0.0);
    let times: Vec<f64> = (1..=10).map(|k| 0.5 * k as f64).collect();
    let exact: Vec<(f64, f64)> = times
        .iter()
        .map(|&t| reference(&p, theta0, 0.0, t))
        .collect();
    let mut results = vec![];
    for rtol in [1e-4, 1e-6, 1e-8] {
        let mut integrator = pendulum(p.clone(), adaptive(0.9, rtol, 1e-3 * rtol));
        let mut error = 0.0_f64;
        for (&t, &(theta, _)) in times.iter().zip(&exact) {
            integrator.step_to(t).unwrap();
            assert_eq!(integrator.t(), t);
            error = error.max((integrator.free_state(0)[0] - theta).abs());
        }
        // The tolerance on θ: rtol |θ| with |θ| ≤ π/2 + 1.
        let tolerance = rtol * (FRAC_PI_2 + 1.0);
        let stats = integrator.stats();
        eprintln!(
            "rtol {rtol:e}: largest error {error:.3e} = {:.1} × tolerance, {stats:?}",
            error / tolerance
        );
        // Per second over 5 s: a few × 5 × the tolerance.
        assert!(error < 15.0 * tolerance, "rtol {rtol}: {error}");
        results.push((error, stats.steps as f64));
    }
    for pair in results.windows(2) {
        let (errors, steps) = (pair[0].0 / pair[1].0, pair[1].1 / pair[0].1);
        eprintln!("100× tighter: error ÷ {errors:.1}, steps × {steps:.2}");
        assert!((40.0..250.0).contains(&errors), "{errors}");
        assert!((6.0..15.0).contains(&steps), "{steps}");
    }
}

/// The energy book against the reference: the kinetic energy is ½ I θ̇² of the pin, the
/// gravity potential m g y, and with ρ∞ = 1 (no numerical damping) the total of an undamped
/// swing stays within a bound that does not grow over 1,000 periods.
#[test]
fn an_undamped_swing_keeps_its_energy_over_a_thousand_periods() {
    let amplitude = 0.5;
    let p = FreePendulum::released(-FRAC_PI_2 + amplitude, 0.0);
    let period = 4.0 * elliptic_k((0.5 * amplitude).sin()) / p.omega();
    let (inertia, m, g, l) = (p.pin_inertia(), p.mass, p.gravity, p.length);
    let mut integrator = pendulum(p, fixed(1.0, period / 40.0));
    let start = integrator.energy();
    let e0 = start.total();
    // The swing's energy scale: the potential it turns into kinetic energy.
    let scale = m * g * l * (1.0 - amplitude.cos());
    assert!((start.gravity - m * g * (-l * amplitude.cos())).abs() < 1e-12 * scale);
    let (mut early, mut late, mut book) = (0.0_f64, 0.0_f64, 0.0_f64);
    let periods = 1000.0;
    integrator
        .run(periods * period, |state, energy| {
            let drift = (energy.total() - e0).abs() / scale;
            if state.t < 10.0 * period {
                early = early.max(drift);
            }
            if state.t > (periods - 10.0) * period {
                late = late.max(drift);
            }
            let kinetic = 0.5 * inertia * state.qd().z * state.qd().z;
            book = book.max((energy.kinetic - kinetic).abs() / scale);
        })
        .unwrap();
    eprintln!(
        "1000 periods at h = T/40: |ΔE|/E_swing ≤ {early:.3e} (first 10), {late:.3e} (last 10); \
         {:?}",
        integrator.stats()
    );
    assert!(book < 1e-12, "{book}");
    assert!(early < 2e-3 && late < 2e-3, "{early} {late}");
    // Bounded, not drifting: the last periods are no worse than the first ones.
    assert!(late < 1.5 * early, "{early} {late}");
}

/// A damped swing loses what the damper dissipates: the book's dissipation against the
/// reference's `∫ c θ̇² dt` (integrated with the Lagrange equation by RK4), and the balance
/// `kinetic + gravity + dissipated` constant.
#[test]
fn a_damped_swing_loses_what_the_damper_dissipates() {
    let theta0 = -FRAC_PI_2 + 1.2;
    let mut p = FreePendulum::released(theta0, 0.0);
    p.damping = 0.8;
    // Reference: (θ, θ̇, D) with D' = c θ̇², RK4 with steps of 1e-4.
    let t_end = 5.0;
    let n = 50_000;
    let h = t_end / n as f64;
    let f = |y: [f64; 3]| [y[1], p.theta_ddot(y[0], y[1]), p.damping * y[1] * y[1]];
    let mut y = [theta0, 0.0, 0.0];
    for _ in 0..n {
        let k1 = f(y);
        let k2 = f(core::array::from_fn(|i| y[i] + 0.5 * h * k1[i]));
        let k3 = f(core::array::from_fn(|i| y[i] + 0.5 * h * k2[i]));
        let k4 = f(core::array::from_fn(|i| y[i] + h * k3[i]));
        y = core::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    }
    for (rho, step) in [(1.0, 2e-3), (0.8, 1e-3)] {
        let mut integrator = pendulum(p.clone(), fixed(rho, step));
        let e0 = integrator.energy().total();
        let mut balance = 0.0_f64;
        integrator
            .run(t_end, |_, energy| {
                balance = balance.max((energy.total() - e0).abs())
            })
            .unwrap();
        let energy = integrator.energy();
        let relative = (energy.dissipated - y[2]).abs() / y[2];
        eprintln!(
            "ρ∞ = {rho}, h = {step}: dissipated {:.6} vs {:.6} (relative {relative:.1e}), \
             balance within {:.1e} of {:.3}",
            energy.dissipated, y[2], balance, y[2]
        );
        assert!(relative < 2e-4, "{relative}");
        assert!(balance < 2e-4 * y[2], "{balance}");
        assert_eq!(
            (energy.loads_work, energy.drivers_work.abs() < 1e-9),
            (0.0, true)
        );
    }
}

/// A driver and a free degree of freedom in one scene: the pendulum on a shaken cart follows
/// its Lagrange equation, and the book's drivers' work is the reference's `∫ f ẋ_c dt`, the
/// balance with it constant.
#[test]
fn a_driver_and_a_free_swing_mix_and_the_drivers_work_is_booked() {
    let scene = CartPendulum::default();
    let t_end = 3.0;
    // Reference: (θ, θ̇, W) with W' = the driver's power, RK4 with steps of 1e-4.
    let n = 30_000;
    let h = t_end / n as f64;
    let f = |t: f64, y: [f64; 3]| {
        [
            y[1],
            scene.theta_ddot(t, y[0]),
            scene.drive_power(t, y[0], y[1]),
        ]
    };
    let mut y = [scene.theta0, 0.0, 0.0];
    for i in 0..n {
        let t = i as f64 * h;
        let k1 = f(t, y);
        let k2 = f(
            t + 0.5 * h,
            core::array::from_fn(|i| y[i] + 0.5 * h * k1[i]),
        );
        let k3 = f(
            t + 0.5 * h,
            core::array::from_fn(|i| y[i] + 0.5 * h * k2[i]),
        );
        let k4 = f(t + h, core::array::from_fn(|i| y[i] + h * k3[i]));
        y = core::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    }
    let mut integrator = Integrator::new(
        Solver::new(Scene::new(scene.clone())),
        0.0,
        adaptive(0.9, 1e-7, 1e-10),
    )
    .unwrap();
    let e0 = integrator.energy().total();
    let mut balance = 0.0_f64;
    integrator
        .run(t_end, |_, energy| {
            balance = balance.max((energy.total() - e0).abs())
        })
        .unwrap();
    let [u, ud, _] = integrator.free_state(0);
    let energy = integrator.energy();
    eprintln!(
        "cart: θ error {:.2e}, θ̇ error {:.2e}, drivers' work {:.6} vs {:.6}, balance {balance:.1e}, {:?}",
        u - y[0],
        ud - y[1],
        energy.drivers_work,
        y[2],
        integrator.stats()
    );
    assert!((u - y[0]).abs() < 1e-5 && (ud - y[1]).abs() < 1e-4);
    let scale = y[2].abs().max(1.0);
    assert!((energy.drivers_work - y[2]).abs() < 1e-4 * scale);
    assert!(balance < 1e-4 * scale, "{balance}");
    // The cart follows its driver exactly.
    let cart = scene.cart_motion(t_end);
    let state = integrator.state();
    assert!((state.q[0] - cart[0]).abs() < 1e-12 && (state.qd()[0] - cart[1]).abs() < 1e-12);
}

/// `[θ1, θ2, θ̇1, θ̇2]` of the double pendulum at `t` from rest, by RK4 with steps of 1e-4.
fn double_reference(p: &DoublePendulum, t: f64) -> [f64; 4] {
    let n = (t / 1e-4).ceil() as usize;
    let h = t / n as f64;
    let f = |y: [f64; 4]| {
        let [a, b] = p.accelerations([y[0], y[1]], [y[2], y[3]]);
        [y[2], y[3], a, b]
    };
    let mut y = [p.theta0[0], p.theta0[1], 0.0, 0.0];
    for _ in 0..n {
        let k1 = f(y);
        let k2 = f(core::array::from_fn(|i| y[i] + 0.5 * h * k1[i]));
        let k3 = f(core::array::from_fn(|i| y[i] + 0.5 * h * k2[i]));
        let k4 = f(core::array::from_fn(|i| y[i] + h * k3[i]));
        y = core::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    }
    y
}

/// Two coupled free degrees of freedom: the double pendulum against its reduced-coordinate
/// equations, second order in fixed steps and within the tolerance in the error-controlled
/// mode, its energy kept.
#[test]
fn a_double_pendulum_follows_its_reduced_equations() {
    let p = DoublePendulum::default();
    let t_end = 2.0;
    let exact = double_reference(&p, t_end);
    let error = |integrator: &Integrator<Scene<DoublePendulum>>| {
        let [a, b] = [0, 1].map(|k| integrator.free_state(k)[0]);
        (a - exact[0]).abs().max((b - exact[1]).abs())
    };
    let mut errors = vec![];
    for h in [0.01, 0.005] {
        let mut integrator =
            Integrator::new(Solver::new(Scene::new(p.clone())), 0.0, fixed(0.8, h)).unwrap();
        integrator.step_to(t_end).unwrap();
        errors.push(error(&integrator));
    }
    let mut integrator = Integrator::new(
        Solver::new(Scene::new(p.clone())),
        0.0,
        adaptive(0.9, 1e-7, 1e-10),
    )
    .unwrap();
    let e0 = integrator.energy().total();
    integrator.step_to(t_end).unwrap();
    let adaptive_error = error(&integrator);
    let drift = (integrator.energy().total() - e0).abs();
    eprintln!(
        "double pendulum: fixed errors {errors:?}, ratio {:.2}; error-controlled {adaptive_error:.2e}, \
         energy drift {drift:.1e}, {:?}",
        errors[0] / errors[1],
        integrator.stats()
    );
    assert!((3.5..4.6).contains(&(errors[0] / errors[1])));
    assert!(adaptive_error < 15.0 * 1e-7 * t_end, "{adaptive_error}");
    assert!(drift < 1e-5, "{drift}");
}

/// `set_free` restarts the motion from a new free state: the motion afterwards is the
/// reference's from that state, and the energy book jumps by exactly the energy it adds.
#[test]
fn set_free_restarts_the_motion_from_the_new_state() {
    let p = FreePendulum::released(-1.0, 0.0);
    let mut integrator = pendulum(p.clone(), adaptive(0.9, 1e-8, 1e-11));
    integrator.step_to(0.3).unwrap();
    let before = integrator.energy();
    integrator.set_free(0, -2.0, 1.5).unwrap();
    assert_eq!(integrator.free_state(0)[..2], [-2.0, 1.5]);
    assert!((integrator.free_state(0)[2] - p.theta_ddot(-2.0, 1.5)).abs() < 1e-12);
    let after = integrator.energy();
    let (m, g, l) = (p.mass, p.gravity, p.length);
    let expected = 0.5 * p.pin_inertia() * 1.5 * 1.5 + m * g * l * (-2.0_f64).sin();
    assert!((after.kinetic + after.gravity - expected).abs() < 1e-12 * expected.abs());
    assert_eq!(after.dissipated, before.dissipated);
    integrator.step_to(1.3).unwrap();
    let (theta, rate) = reference(&p, -2.0, 1.5, 1.0);
    let [u, ud, _] = integrator.free_state(0);
    assert!(
        (u - theta).abs() < 1e-6 && (ud - rate).abs() < 1e-5,
        "{u} {theta}"
    );
}

/// A force that turns NaN mid-run is a typed error at that step, never a NaN state returned as
/// a success; a NaN from the start stops the start.
#[test]
fn a_non_finite_force_is_a_typed_error() {
    for options in [fixed(0.9, 0.01), adaptive(0.9, 1e-6, 1e-9)] {
        let mut p = FreePendulum::released(-1.0, 0.0);
        p.nan_after = 0.25;
        let mut integrator = pendulum(p, options);
        let error = integrator.step_to(1.0).map(|_| ()).unwrap_err();
        eprintln!("{error}");
        assert!(
            matches!(
                error,
                DynamicsError::Solve { .. } | DynamicsError::NonFinite { .. }
            ),
            "{error}"
        );
        assert!(integrator.t() < 0.25 && integrator.t() > 0.2);
        let state = integrator.state();
        assert!(
            state
                .q
                .iter()
                .chain(state.qd().iter())
                .all(|x| x.is_finite())
        );
        assert!(integrator.free_state(0).iter().all(|x| x.is_finite()));
    }
    let mut p = FreePendulum::released(-1.0, 0.0);
    p.gravity = f64::NAN;
    let result = Integrator::new(Solver::new(Scene::new(p)), 0.0, fixed(0.9, 0.01));
    assert!(matches!(
        result.map(|_| ()),
        Err(DynamicsError::Solve { .. } | DynamicsError::NonFinite { .. })
    ));
}

/// A small deterministic generator (the tests need no dependency for a few random numbers).
struct Lcg(u64);

impl Lcg {
    /// Uniform in [lo, hi).
    fn next(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// Random initial states and ρ∞: the fixed-step error against the reference (θ, and θ̇ / ω)
/// falls by 3–5 × from h = 0.01 to 0.005 and stays below 1e-3, and the constraints hold.
#[test]
fn random_initial_states_stay_second_order_accurate() {
    let mut random = Lcg(22);
    for _ in 0..12 {
        let theta0 = random.next(-2.8, -0.3);
        let rate0 = random.next(-3.0, 3.0);
        let rho = random.next(0.0, 1.0);
        let p = FreePendulum::released(theta0, rate0);
        let t_end = 1.0;
        let (theta, rate) = reference(&p, theta0, rate0, t_end);
        let errors: Vec<f64> = [0.01, 0.005]
            .iter()
            .map(|&h| {
                let mut integrator = pendulum(p.clone(), fixed(rho, h));
                integrator.step_to(t_end).unwrap();
                let (position, velocity) = residuals(&integrator);
                assert!(position < 1e-8 && velocity < 1e-13);
                let [u, ud, _] = integrator.free_state(0);
                (u - theta).abs().max((ud - rate).abs() / p.omega())
            })
            .collect();
        let ratio = errors[0] / errors[1];
        assert!(
            errors[1] < 1e-3 && (3.0..5.0).contains(&ratio),
            "θ0 {theta0}, θ̇0 {rate0}, ρ∞ {rho}: {errors:?}"
        );
    }
}

/// The interpreter's shape of scene: the same pendulum behind `Dyn` coordinates and free
/// degrees of freedom (storage allocated once by `new`) takes bit-identical steps.
#[cfg(feature = "alloc")]
#[test]
fn a_dyn_scene_steps_exactly_as_the_fixed_size_one() {
    use common::free_pendulum::DynFreePendulum;
    let p = FreePendulum::released(-0.7, 1.1);
    for options in [fixed(0.8, 0.01), adaptive(0.9, 1e-6, 1e-9)] {
        let mut fixed_size = pendulum(p.clone(), options);
        let mut dynamic = Integrator::new(
            Solver::new(Scene::new(DynFreePendulum(p.clone()))),
            0.0,
            options,
        )
        .unwrap();
        for _ in 0..50 {
            fixed_size.step().unwrap();
            dynamic.step().unwrap();
            assert_eq!(fixed_size.t(), dynamic.t());
            assert_eq!(fixed_size.free_state(0), dynamic.free_state(0));
            assert_eq!(
                fixed_size.state().q.as_slice(),
                dynamic.state().q.as_slice()
            );
        }
        assert_eq!(fixed_size.energy(), dynamic.energy());
        assert_eq!(fixed_size.stats(), dynamic.stats());
    }
}

/// `(θ, θ̇)` of the free slider-crank at `t` from rest, by RK4 with steps of 1e-4.
fn crank_reference(p: &FreeSliderCrank, t: f64) -> (f64, f64) {
    let n = (t / 1e-4).ceil() as usize;
    let h = t / n as f64;
    let f = |y: [f64; 2]| [y[1], p.theta_ddot(y[0], y[1])];
    let mut y = [p.theta0, 0.0];
    for _ in 0..n {
        let k1 = f(y);
        let k2 = f(core::array::from_fn(|i| y[i] + 0.5 * h * k1[i]));
        let k3 = f(core::array::from_fn(|i| y[i] + 0.5 * h * k2[i]));
        let k4 = f(core::array::from_fn(|i| y[i] + h * k3[i]));
        y = core::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    }
    (y[0], y[1])
}

/// The seed's shape: a slider-crank with its crank free under gravity and a spring on the
/// slider, against its reduced one-coordinate equation from the closed-form kinematics; second
/// order in fixed steps (its energy error too), within the tolerance in the error-controlled
/// mode, the crank angle's effort zero.
#[test]
fn a_free_slider_crank_follows_its_reduced_equation() {
    let p = FreeSliderCrank::default();
    let t_end = 1.5;
    let (theta, rate) = crank_reference(&p, t_end);
    let run = |options: IntegratorOptions| {
        let mut integrator =
            Integrator::new(Solver::new(Scene::new(p.clone())), 0.0, options).unwrap();
        let e0 = integrator.energy().total();
        integrator.step_to(t_end).unwrap();
        let [u, ud, _] = integrator.free_state(0);
        let effort = integrator.constraint_forces().unwrap()[2];
        let drift = (integrator.energy().total() - e0).abs();
        (
            (u - theta).abs(),
            (ud - rate).abs(),
            effort,
            drift,
            integrator.stats(),
        )
    };
    let coarse = run(fixed(0.9, 0.01));
    let fine = run(fixed(0.9, 0.005));
    let controlled = run(adaptive(0.9, 1e-7, 1e-10));
    eprintln!("slider-crank: θ(1.5) = {theta:.6}; fixed 0.01 {coarse:?}");
    eprintln!("  fixed 0.005 {fine:?}");
    eprintln!("  rtol 1e-7 {controlled:?}");
    assert!(
        (3.5..4.5).contains(&(coarse.0 / fine.0)),
        "{coarse:?} {fine:?}"
    );
    assert!(controlled.0 < 15.0 * 1e-7 * t_end && controlled.1 < 1e-4);
    // The energy error is the method's, second order too.
    assert!((3.5..4.5).contains(&(coarse.3 / fine.3)) && controlled.3 < 1e-5);
    for (_, _, effort, _, _) in [coarse, fine, controlled] {
        assert!(effort.abs() < 1e-8, "{effort}");
    }
}

/// `V`'s velocity solves over the factors the evaluation archived for its force solve give the
/// motion that solving them afresh gives: with static pivots off nothing is archived (every
/// block is factored with partial pivoting), so the integrator refactors for `V`, and two runs
/// agree to round-off over 150 steps: the cart pendulum's, whose driver makes every `V` a
/// velocity solve, and the free slider-crank's fast motion (one free degree of freedom and no
/// driver: `V` is `q̇ / u̇` but at its start from rest, where it is solved for).
#[test]
fn v_over_the_archived_factors_is_v_refactored() {
    let options = |static_pivots: bool| SolverOptions {
        static_pivots,
        ..SolverOptions::default()
    };
    let cart = |static_pivots: bool| {
        let scene = Scene::new(CartPendulum::default());
        let solver = Solver::with_options(scene, options(static_pivots));
        let mut integrator = Integrator::new(solver, 0.0, fixed(0.9, 0.01)).unwrap();
        integrator.step_to(1.5).unwrap();
        (integrator.free_state(0), integrator.stats().steps)
    };
    let slider_crank = |static_pivots: bool| {
        let scene = Scene::new(FreeSliderCrank::default());
        let solver = Solver::with_options(scene, options(static_pivots));
        let mut integrator = Integrator::new(solver, 0.0, fixed(0.9, 0.01)).unwrap();
        integrator.step_to(1.5).unwrap();
        (integrator.free_state(0), integrator.stats().steps)
    };
    let runs: [&dyn Fn(bool) -> ([f64; 3], usize); 2] = [&cart, &slider_crank];
    for run in runs {
        let (archived, steps) = run(true);
        let (refactored, same_steps) = run(false);
        assert_eq!(steps, same_steps);
        for (a, r) in archived.iter().zip(refactored) {
            assert!(
                (a - r).abs() <= 1e-9 * (1.0 + r.abs()),
                "{archived:?} {refactored:?}"
            );
        }
    }
}

/// A stiff spring in a linkage: the free slider-crank's slider on a spring whose period
/// through the linkage is some 400× shorter than the step (k = 6e11, h = 1e-2), preloaded by
/// 1 µm, over 1 s. With ρ∞ = 1 the fast oscillation it excites keeps its amplitude (the slider within
/// about twice the preload); with ρ∞ < 1 it is damped out and the crank settles on the static
/// equilibrium of the reduced equation (`θ̈(θ, 0) = 0`, solved here by the secant method).
#[test]
fn a_stiff_spring_in_a_linkage_settles_on_its_equilibrium() {
    let mut p = FreeSliderCrank::default();
    let x_start = {
        let integrator =
            Integrator::new(Solver::new(Scene::new(p.clone())), 0.0, fixed(1.0, 0.01)).unwrap();
        integrator.state().q[6]
    };
    let preload = 1e-6;
    p.spring = (6e11, x_start + preload);
    // The static equilibrium: θ̈(θ, 0) = 0 near θ0.
    let (mut a, mut b) = (p.theta0, p.theta0 - 1e-5);
    for _ in 0..50 {
        let (fa, fb) = (p.theta_ddot(a, 0.0), p.theta_ddot(b, 0.0));
        if fb == fa {
            break;
        }
        (a, b) = (b, b - fb * (b - a) / (fb - fa));
    }
    let equilibrium = b;
    for rho in [1.0, 0.8, 0.0] {
        let mut integrator =
            Integrator::new(Solver::new(Scene::new(p.clone())), 0.0, fixed(rho, 0.01)).unwrap();
        let mut range = (f64::MAX, f64::MIN);
        integrator
            .run(1.0, |state, _| {
                let x = state.q[6] - x_start;
                range = (range.0.min(x), range.1.max(x));
            })
            .unwrap();
        let theta = integrator.free_state(0)[0];
        eprintln!(
            "stiff linkage ρ∞ = {rho}: θ − θ_eq = {:.1e}, slider moved {:.2e}..{:.2e}, {:?}",
            theta - equilibrium,
            range.0,
            range.1,
            integrator.stats()
        );
        // Twice the preload (an undamped swing about the preloaded equilibrium), and the
        // little gravity adds.
        assert!(range.0 > -1e-9 && range.1 < 2.01 * preload, "{range:?}");
        if rho < 1.0 {
            assert!(
                (theta - equilibrium).abs() < 1e-9,
                "{theta} vs {equilibrium}"
            );
        }
    }
}

/// A free state the kinematics cannot reach (x beyond the rod's length) is refused with the
/// kinematic error, and the integrator goes on from the state it had.
#[test]
fn an_unreachable_free_state_leaves_the_integrator_as_it_was() {
    let mut p = FreePendulum::released(-2.0, 0.0);
    p.free_x = true;
    p.initial = (Some(p.length * (-2.0_f64).cos()), 0.0);
    let mut integrator = pendulum(p.clone(), fixed(0.9, 0.01));
    integrator.step_to(0.1).unwrap();
    let (q, free) = (integrator.state().q, integrator.free_state(0));
    let error = integrator.set_free(0, 2.0 * p.length, 0.0).unwrap_err();
    assert!(matches!(error, DynamicsError::Solve { .. }), "{error}");
    assert_eq!((integrator.state().q, integrator.free_state(0)), (q, free));
    integrator.step_to(0.2).unwrap();
    assert!(integrator.state().q.iter().all(|x| x.is_finite()));
}

/// A clone is a checkpoint: stepped on, it gives bit for bit what the original gives.
#[test]
fn a_clone_continues_exactly_as_the_original() {
    let mut original = pendulum(FreePendulum::released(-0.9, 0.4), adaptive(0.9, 1e-6, 1e-9));
    original.step_to(0.5).unwrap();
    let mut copy = original.clone();
    original.step_to(1.5).unwrap();
    copy.step_to(1.5).unwrap();
    assert_eq!(original.free_state(0), copy.free_state(0));
    assert_eq!(original.state().q, copy.state().q);
    assert_eq!(original.energy(), copy.energy());
    assert_eq!(original.stats(), copy.stats());
}
