//! Derived parameters (`param c = sqrt(a^2 + b^2 - 2 * a * b * cos(gamma));`): a scene using
//! them moves exactly as the scene with their expressions written out, before and after its
//! run-time parameters change, in generated and interpreted code; the generated accessors
//! follow the parameters; the generated code is a reviewed snapshot.

use mechgen_interp::Interpreted;
use mechgen_runtime::{Mechanism, Simulation, Solver, sample_time};
use mechgen_tests::twin;

twin! {
    DERIVED,
    /// A slider-crank whose rod is the third side of a triangle (law of cosines).
    pub mechanism Derived {
        /// Crank length.
        param a = 20;
        /// The triangle's other side.
        param b = 30;
        /// The angle between `a` and `b`.
        param gamma = 100deg;
        /// The third side, by the law of cosines.
        param c = sqrt(a^2 + b^2 - 2 * a * b * cos(gamma));
        param half = c / 2;

        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body rod near (39, 0, 0);
        body slider near (59, 0, 0);

        joint pivot: revolute(frame, crank);
        joint pin: revolute(crank @ (a, 0), rod @ (-half, 0));
        joint wrist: revolute(rod @ (half, 0), slider);
        joint guide: prismatic(frame, slider, along (1, 0));
        driver spin: angle(crank) = t;
    }
}

twin! {
    WRITTEN_OUT,
    /// The same scene with the derived parameters written out.
    pub mechanism WrittenOut {
        /// Crank length.
        param a = 20;
        /// The triangle's other side.
        param b = 30;
        /// The angle between `a` and `b`.
        param gamma = 100deg;

        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body rod near (39, 0, 0);
        body slider near (59, 0, 0);

        joint pivot: revolute(frame, crank);
        joint pin: revolute(crank @ (a, 0), rod @ (-sqrt(a^2 + b^2 - 2 * a * b * cos(gamma)) / 2, 0));
        joint wrist: revolute(rod @ (sqrt(a^2 + b^2 - 2 * a * b * cos(gamma)) / 2, 0), slider);
        joint guide: prismatic(frame, slider, along (1, 0));
        driver spin: angle(crank) = t;
    }
}

/// q, q̇, q̈ at 25 times over two turns.
fn motion<M>(mechanism: M) -> Vec<Vec<f64>>
where
    M: mechgen_runtime::Structured + mechgen_runtime::Accelerations,
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    let mut simulation =
        Simulation::new(Solver::new(mechanism), 0.0).unwrap_or_else(|e| panic!("{e}"));
    let mut rows = Vec::new();
    simulation
        .run(4.0 * core::f64::consts::PI, 24, |state| {
            let mut row: Vec<f64> = state.q.iter().copied().collect();
            row.extend(state.qd().iter());
            row.extend(state.qdd().iter());
            rows.push(row);
        })
        .unwrap_or_else(|e| panic!("{e}"));
    rows
}

fn assert_close(a: &[Vec<f64>], b: &[Vec<f64>]) {
    for (k, (a, b)) in a.iter().zip(b).enumerate() {
        for (j, (x, y)) in a.iter().zip(b).enumerate() {
            assert!(
                (x - y).abs() <= 1e-12 * (1.0 + y.abs()),
                "step {k}, value {j}: {x} vs {y}"
            );
        }
    }
}

#[test]
fn derived_parameters_move_as_the_written_out_scene_and_follow_their_parameters() {
    let law_of_cosines =
        |s: &Derived| (s.a * s.a + s.b * s.b - 2.0 * s.a * s.b * s.gamma.cos()).sqrt();
    let mut derived = Derived::default();
    assert_eq!(derived.c(), law_of_cosines(&derived));
    assert_eq!(derived.half(), derived.c() / 2.0);
    assert_close(&motion(derived), &motion(WrittenOut::default()));

    // Set at run time: the derived lengths follow.
    derived.a = 22.0;
    derived.gamma = 90f64.to_radians();
    let written = WrittenOut {
        a: 22.0,
        gamma: 90f64.to_radians(),
        ..WrittenOut::default()
    };
    assert!((derived.c() - law_of_cosines(&derived)).abs() < 1e-13);
    let moved = motion(derived);
    assert_close(&moved, &motion(written));
    // The slider's travel is the crank plus the rod: a + c at t = 0.
    let slider_x = moved[0][9];
    assert!((slider_x - (22.0 + derived.c())).abs() < 1e-9, "{slider_x}");
    // Not a field: the struct has the three run-time parameters only.
    assert_eq!(derived.parameter_count(), 3);
}

#[test]
fn the_interpreter_substitutes_them_too() {
    let scene = mechgen::compile(mechgen::Input::Text(DERIVED), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let mut interpreted = Interpreted::new(&scene);
    interpreted
        .set_parameter("a", 22.0)
        .expect("a run-time parameter");
    assert!(
        interpreted.set_parameter("c", 1.0).is_err(),
        "derived: not settable"
    );
    let generated = Derived {
        a: 22.0,
        ..Derived::default()
    };
    let t = sample_time(0.0, 1.0, 3, 2);
    let mut by_interpreter = Simulation::new(Solver::new(interpreted), 0.0).unwrap();
    let mut by_generated = Simulation::new(Solver::new(generated), 0.0).unwrap();
    let interpreted_q: Vec<f64> = by_interpreter
        .step_to(t)
        .unwrap()
        .q
        .iter()
        .copied()
        .collect();
    let generated_q: Vec<f64> = by_generated.step_to(t).unwrap().q.iter().copied().collect();
    assert_close(&[interpreted_q], &[generated_q]);
    // The written-out twin's text compiles too (it is the reference above).
    assert!(
        mechgen::compile(
            mechgen::Input::Text(WRITTEN_OUT),
            &mechgen::Options::default()
        )
        .is_ok()
    );
}

#[test]
fn generated_code_snapshot() {
    let code = mechgen::expand(mechgen::Input::Text(DERIVED), &mechgen::Options::default())
        .map(mechgen::pretty)
        .unwrap_or_else(|e| panic!("{e}"));
    insta::assert_snapshot!("derived_parameters", code);
}
