//! Bad input to the forward dynamics gives typed errors that name the scene's terms, never a
//! panic, a hang or a NaN state returned as a success: options out of range, a step rejected
//! below the minimum size, a free degree of freedom that carries no mass (the reduced mass
//! `VᵀMV` singular), a load that turns non-finite, a non-finite restart state. After an
//! error the integrator keeps its last accepted state.

mod dynamics;

use dynamics::{fixed, interpreted, start};
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{
    Dynamic, DynamicsError, EquationsOfMotion, FreeStorage, Integrator, IntegratorOptions,
    Mechanism, Solver, StepControl, Storage, Structured,
};
use mechgen_tests::twin;

twin! {
    WEIGHTED,
    mechanism Weighted {
        /// Mass properties as parameters, so that a run can take them away.
        param m = 2.0;
        param j = 5000.0;
        param m2 = 0.6;
        param j2 = 1800.0;
        ground frame at (0, 0, 0);
        body upper near (0, 0, -90deg) mass m inertia j centre (60, 0);
        body lower near (0, -120, -90deg) mass m2 inertia j2 centre (50, 0);
        joint shoulder: revolute(frame, upper);
        joint elbow: revolute(upper @ (120, 0), lower);
        free upper_angle: angle(upper) from -80deg;
        free lower_angle: angle(lower) from -70deg;
        gravity (0, -9810);
    }
}

mechgen_runtime::mechanism! {
    mechanism FadingPush {
        ground frame at (0, 0, 0);
        body arm near (0, 0, -90deg) mass 1 inertia 2000 centre (100, 0);
        joint pivot: revolute(frame, arm);
        free swing: angle(arm) from -90deg;
        /// Real until t = 1, NaN after.
        load push: torque(arm) = 1e5 * sqrt(1 - t);
        gravity (0, -9810);
    }
}

/// The error of starting `mechanism` with `options` (it must not start).
fn refused<M>(mechanism: M, options: IntegratorOptions) -> DynamicsError
where
    M: Dynamic + EquationsOfMotion + Structured,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    match Integrator::new(Solver::new(mechanism), 0.0, options) {
        Ok(_) => panic!("started"),
        Err(e) => e,
    }
}

#[test]
fn options_out_of_range_are_refused() {
    let adaptive = |rtol: f64, atol: f64, min: f64, max: f64| IntegratorOptions {
        control: StepControl::Adaptive {
            rtol,
            atol,
            initial: 1e-4,
            min,
            max,
        },
        ..IntegratorOptions::default()
    };
    let bad = [
        ("ρ∞ above 1", fixed(1e-3, 1.5)),
        ("ρ∞ below 0", fixed(1e-3, -0.1)),
        ("ρ∞ NaN", fixed(1e-3, f64::NAN)),
        ("zero step", fixed(0.0, 0.5)),
        ("negative step", fixed(-1e-3, 0.5)),
        ("infinite step", fixed(f64::INFINITY, 0.5)),
        ("zero rtol and atol", adaptive(0.0, 0.0, 1e-12, 1.0)),
        ("negative rtol", adaptive(-1e-6, 1e-9, 1e-12, 1.0)),
        ("min above max", adaptive(1e-6, 1e-9, 1.0, 1e-3)),
        (
            "no step budget",
            IntegratorOptions {
                max_steps: 0,
                ..IntegratorOptions::default()
            },
        ),
        (
            "no Newton iterations",
            IntegratorOptions {
                max_iterations: 0,
                ..IntegratorOptions::default()
            },
        ),
    ];
    for (label, options) in bad {
        let error = refused(Weighted::default(), options);
        assert!(
            matches!(error, DynamicsError::BadOptions { .. }),
            "{label}: {error:?}"
        );
        assert!(!error.to_string().is_empty());
    }
}

#[test]
fn a_step_below_the_minimum_is_a_typed_error() {
    // A tolerance no step of at least 1e-2 s can meet.
    let options = IntegratorOptions {
        control: StepControl::Adaptive {
            rtol: 1e-15,
            atol: 1e-18,
            initial: 1e-2,
            min: 1e-2,
            max: 1e-1,
        },
        ..IntegratorOptions::default()
    };
    let mut integrator = start(Weighted::default(), options);
    let before = integrator.state().q;
    match integrator.step() {
        Err(DynamicsError::StepTooSmall { t, step, min }) => {
            assert_eq!(t, 0.0);
            assert_eq!(min, 1e-2);
            assert!(step <= 1e-2, "{step}");
        }
        other => panic!(
            "expected a step below the minimum, got {:?}",
            other.map(|s| s.t)
        ),
    }
    // The last accepted state is kept.
    assert_eq!(integrator.t(), 0.0);
    assert_eq!(integrator.state().q, before);
}

/// Far from t = 0 a step below the clock's spacing would leave the time standing (a hang in
/// `step_to`) or move it by another step than the motion's: a typed error instead.
#[test]
fn a_step_the_clock_cannot_resolve_is_a_typed_error() {
    let t0 = 1e9;
    // The spacing of times near 1e9 is 1.2e-7: a step of 1e-8 rounds to 0.
    let mut integrator = Integrator::new(Solver::new(Weighted::default()), t0, fixed(1e-8, 0.9))
        .unwrap_or_else(|e| panic!("{e}"));
    for result in [
        integrator.step().map(|s| s.t),
        integrator.step_to(t0 + 1e-6).map(|s| s.t),
    ] {
        match result {
            Err(DynamicsError::StepBelowClock { t, step }) => {
                assert_eq!((t, step), (t0, 1e-8));
            }
            other => panic!("expected a step below the clock, got {other:?}"),
        }
    }
    assert_eq!(integrator.t(), t0);
    // A step the clock resolves runs from there (each step the one the clock takes, within
    // a hundredth of 1e-3).
    let mut integrator = Integrator::new(Solver::new(Weighted::default()), t0, fixed(1e-3, 0.9))
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(integrator.step_to(t0 + 0.01).map(|s| s.t), Ok(t0 + 0.01));
}

/// A call that needs more steps than `max_steps` stops with a typed error at the last
/// accepted state, whatever asked for them (a long span, a tight tolerance).
#[test]
fn a_run_past_its_step_budget_is_a_typed_error() {
    let options = IntegratorOptions {
        max_steps: 10,
        ..fixed(1e-3, 0.9)
    };
    let mut integrator = start(Weighted::default(), options);
    match integrator.step_to(1.0).map(|s| s.t) {
        Err(DynamicsError::StepBudget { t, steps }) => {
            assert_eq!(steps, 10);
            assert!((t - 0.01).abs() < 1e-12, "{t}");
        }
        other => panic!("expected the step budget, got {other:?}"),
    }
    assert!((integrator.t() - 0.01).abs() < 1e-12);
    let mut calls = 0;
    let result = integrator.run(1.0, |_, _| calls += 1);
    assert!(matches!(result, Err(DynamicsError::StepBudget { .. })));
    assert_eq!(calls, 10);
    // Each call has its own budget: a nearer time is reached.
    assert!(integrator.step_to(integrator.t() + 0.005).is_ok());
}

#[test]
fn a_free_degree_of_freedom_without_mass_is_named() {
    // The whole chain massless: the first free angle's reduced mass is zero. Only the lower
    // bar massless: the second's is.
    for (zeroed, free, name) in [
        (&["m", "j", "m2", "j2"][..], 0, "upper_angle"),
        (&["m2", "j2"][..], 1, "lower_angle"),
    ] {
        let mut mechanism = Weighted::default();
        for p in zeroed {
            mechanism
                .set_parameter(p, 0.0)
                .unwrap_or_else(|e| panic!("{e}"));
        }
        let error = refused(mechanism, IntegratorOptions::default());
        match error {
            DynamicsError::SingularMass { free: k, .. } => assert_eq!(k, free, "{name}"),
            other => panic!("{name}: expected a singular mass, got {other:?}"),
        }
        assert!(error.to_string().contains(name), "{error}");
    }
    // The interpreter names it the same way.
    let mut twin = interpreted(WEIGHTED);
    for p in ["m2", "j2"] {
        twin.set_parameter(p, 0.0).unwrap_or_else(|e| panic!("{e}"));
    }
    let error = refused(twin, IntegratorOptions::default());
    assert!(
        matches!(error, DynamicsError::SingularMass { free: 1, .. }),
        "{error:?}"
    );
    assert!(error.to_string().contains("lower_angle"), "{error}");
}

#[test]
fn a_load_that_turns_non_finite_stops_the_run_with_a_typed_error() {
    let mut integrator = start(FadingPush::default(), fixed(0.3, 0.5));
    for _ in 0..3 {
        integrator.step().unwrap_or_else(|e| panic!("{e}"));
    }
    let t = integrator.t();
    assert!((t - 0.9).abs() < 1e-12);
    let q = integrator.state().q;
    // The next step's end, t = 1.2, has sqrt(−0.2).
    match integrator.step() {
        Err(DynamicsError::NonFinite { t: at, .. }) | Err(DynamicsError::Solve { t: at, .. }) => {
            // The step's start or its end, whichever the error names.
            assert!((0.9 - 1e-12..=1.2 + 1e-12).contains(&at), "{at}")
        }
        other => panic!("expected a non-finite load, got {:?}", other.map(|s| s.t)),
    }
    assert_eq!(integrator.t(), t);
    assert_eq!(integrator.state().q, q);
    assert!(integrator.state().q.iter().all(|x| x.is_finite()));
    // And `run` reports it as well, without calling back a NaN state.
    let mut integrator = start(FadingPush::default(), fixed(0.3, 0.5));
    let result = integrator.run(2.0, |state, energy| {
        assert!(state.q.iter().all(|x| x.is_finite()) && energy.total().is_finite());
    });
    assert!(result.is_err());
}

#[test]
fn a_non_finite_restart_is_refused_and_keeps_the_state() {
    let mut integrator = start(Weighted::default(), fixed(1e-3, 0.5));
    integrator.step_to(0.01).unwrap_or_else(|e| panic!("{e}"));
    let state = integrator.free_state(1);
    for (value, rate) in [
        (f64::NAN, 0.0),
        (0.0, f64::INFINITY),
        (f64::NEG_INFINITY, 1.0),
    ] {
        assert!(
            integrator.set_free(1, value, rate).is_err(),
            "{value}, {rate}"
        );
        assert_eq!(integrator.free_state(1), state);
    }
    // Past the last free degree of freedom.
    assert!(integrator.set_free(2, 0.0, 0.0).is_err());
}
