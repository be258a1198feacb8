//! The forward dynamics of a generated scene allocate nothing: starting the integrator
//! (assembly, the initial accelerations), fixed and error-controlled steps, stepping onto
//! requested times, a run with a callback, the energy book, the reactions along the motion, a
//! restart from a new free state, and the error paths with their messages (written to a
//! fixed sink). The scene is the free seed with a spring-damper, so the stiffness and damping
//! products take part.
//!
//! A counting global allocator wraps the system one (as `no_alloc.rs`); this file holds a
//! single test so that no other test thread allocates while it counts.

use core::fmt::Write;
use mechgen_runtime::{Integrator, IntegratorOptions, Solver, StepControl};
use mechgen_tests::counting::{self, Counting, Sink};

#[global_allocator]
static GLOBAL: Counting = Counting;

mechgen_runtime::mechanism! {
    mechanism SprungFreeSeed {
        ground liner at (156.8, 0, 0);
        body piston near (130, 0, 0) mass 0.5 inertia 300;
        body rod near (29, 72, -2.35) mass 0.4 inertia 1500;
        body crank near (0, 0, 0) mass 1.2 inertia 2000;
        ground bearing at (0, 0, 0);

        joint crank_pin: revolute(rod @ (41.3, 0), crank @ (0, 43));
        joint piston_pin: revolute(piston @ (-28, 0), rod @ (0, 102.6));
        joint main_bearing: revolute(crank, bearing);
        joint slide: prismatic(liner, piston, along (1, 0));

        free crank_angle: angle(crank) from 0.3;

        load coil: spring(liner @ (100, 0), piston, stiffness 1e4, length 138.8, damping 1);

        branch piston_outboard: dot(bearing -> liner, rod @ (41.3, 0) -> rod @ (0, 102.6)) > 0;

        gravity (0, -9810);
    }
}

#[test]
fn the_forward_dynamics_allocate_nothing() {
    counting::start();
    // The counter is live: a real allocation is seen.
    let before = counting::allocations();
    drop(core::hint::black_box(Box::new(0_u8)));
    assert!(counting::allocations() > before);

    let before = counting::allocations();
    let mut sink = Sink(0);
    let fixed = IntegratorOptions {
        rho_inf: 0.5,
        control: StepControl::Fixed { step: 1e-3 },
        ..IntegratorOptions::default()
    };
    let mut integrator =
        Integrator::new(Solver::new(SprungFreeSeed::default()), 0.0, fixed).expect("starts");
    for _ in 0..200 {
        integrator.step().expect("steps");
    }
    integrator.step_to(0.2505).expect("lands");
    let energy = integrator.energy();
    assert!(energy.total().is_finite() && energy.dissipated > 0.0);
    let effort = integrator.constraint_forces().expect("force solve")[14];
    assert!(effort.is_finite());
    integrator.set_free(0, 1.0, -3.0).expect("restarts");
    let mut calls = 0;
    integrator
        .run(0.4, |state, energy| {
            calls += 1;
            assert!(state.q[11].is_finite() && energy.total().is_finite());
        })
        .expect("runs");
    assert!(calls > 0);
    let stats = integrator.stats();
    assert!(stats.steps > 300);

    // The error-controlled mode, the default.
    let mut adaptive = Integrator::new(
        Solver::new(SprungFreeSeed::default()),
        0.0,
        IntegratorOptions::default(),
    )
    .expect("starts");
    adaptive.step_to(0.3).expect("error-controlled");

    // Error paths and their messages: a step below the minimum, refused options.
    let starved = IntegratorOptions {
        control: StepControl::Adaptive {
            rtol: 1e-15,
            atol: 1e-18,
            initial: 1e-2,
            min: 1e-2,
            max: 1e-1,
        },
        ..IntegratorOptions::default()
    };
    let mut starved =
        Integrator::new(Solver::new(SprungFreeSeed::default()), 0.0, starved).expect("starts");
    let error = starved.step().expect_err("no step meets that tolerance");
    write!(sink, "{error}").expect("sink never fails");
    let refused = Integrator::new(
        Solver::new(SprungFreeSeed::default()),
        0.0,
        IntegratorOptions {
            rho_inf: 2.0,
            ..IntegratorOptions::default()
        },
    );
    match refused {
        Ok(_) => panic!("ρ∞ = 2 accepted"),
        Err(error) => write!(sink, "{error}").expect("sink never fails"),
    }
    assert!(integrator.set_free(0, f64::NAN, 0.0).is_err());

    let allocations = counting::allocations() - before;
    counting::stop();
    assert!(sink.0 > 0);
    assert_eq!(
        allocations, 0,
        "the forward dynamics allocated {allocations} times"
    );
}
