//! Masses, inertias, spring constants and gear ratios written in parameters obey, at run time,
//! the rules constants obey at compile time: `--set m=-1` is refused with a typed error naming
//! the parameter, the body or load and the rule, instead of solving for a body of −1 kg. In
//! generated code, the interpreter and the dense reference (the CLI's refusal is tested in
//! `cli/tests/physics_checks.rs`); a scene whose physics is constant generates no check.

use mechgen_interp::Interpreted;
use mechgen_runtime::{
    Dense, Mechanism, Requirement, SolveError, Solver, Structured, Subject, Vector,
    nalgebra::DefaultAllocator,
};
use mechgen_tests::twin;

twin! {
    LOADED,
    /// A slider-crank with a gear on the crank and a spring on the slider, its physics in
    /// parameters.
    mechanism Loaded {
        param m = 2;
        param j = 0.01;
        param k = 500;
        param c = 4;
        param free = 0.2;
        param ratio = 2;
        param arm = 0.03;
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0.2) mass m inertia j centre (arm, 0);
        body slider near (0.33, 0, 0) mass 0.7 inertia 0.001;
        body wheel near (0, 0, 0) mass 1 inertia 0.1;
        joint pivot: revolute(frame, crank);
        joint axle: revolute(frame, wheel);
        joint mesh: gear(crank, wheel, ratio ratio);
        joint guide: prismatic(frame, slider, along (1, 0));
        joint rod: distance(crank @ (0.1, 0), slider, 0.25);
        driver spin: angle(crank) = 0.2 + 20 * t;
        gravity (0, -9.81);
        load coil: spring(frame @ (0.6, 0.1), slider, stiffness k, length free, damping c);
        outputs positions, velocities, accelerations, forces;
    }
}

/// (parameter, value, the rule broken, the subject, its name in the message).
const BAD: [(&str, f64, Requirement, Subject, &str); 7] = [
    (
        "m",
        -1.0,
        Requirement::Mass,
        Subject::Body(1),
        "body `crank`",
    ),
    (
        "j",
        -10.0,
        Requirement::Inertia,
        Subject::Body(1),
        "body `crank`",
    ),
    (
        "arm",
        1e101,
        Requirement::Length,
        Subject::Body(1),
        "body `crank`",
    ),
    (
        "k",
        -20.0,
        Requirement::Stiffness,
        Subject::Load(0),
        "load `coil`",
    ),
    (
        "c",
        -1.0,
        Requirement::Damping,
        Subject::Load(0),
        "load `coil`",
    ),
    (
        "free",
        -0.1,
        Requirement::FreeLength,
        Subject::Load(0),
        "load `coil`",
    ),
    ("ratio", 0.0, Requirement::Ratio, Subject::Body(0), "`mesh`"),
];

/// Solves `m` at t = 0.1 with `parameter` set to `value`.
fn solve_with<M: Structured>(
    mut m: M,
    parameter: &str,
    value: f64,
) -> Result<(), (SolveError, String)>
where
    DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    m.set_parameter(parameter, value).unwrap();
    let mut guess = Vector::<M::Dim>::zeros_generic(m.dim(), mechgen_runtime::nalgebra::U1);
    m.initial_guess(&mut guess);
    let mut solver = Solver::new(m);
    solver.solve(0.1, &guess).map(|_| ()).map_err(|error| {
        let text = solver.describe(&error).to_string();
        (error, text)
    })
}

/// Each bad value is refused by `solve` with the error naming it; the defaults and the
/// boundary values the compile-time rules accept (zero mass, zero damping) solve.
fn refuses_bad_physics(solve: impl Fn(&str, f64) -> Result<(), (SolveError, String)>) {
    let names = ["m", "j", "k", "c", "free", "ratio", "arm"];
    for (parameter, value, requirement, subject, named) in BAD {
        let (error, text) = solve(parameter, value).unwrap_err();
        let index = names.iter().position(|&n| n == parameter).unwrap();
        match error {
            SolveError::Physics {
                subject: s,
                parameter: p,
                value: v,
                requirement: r,
                ..
            } => assert_eq!((s, p, v, r), (subject, index, value, requirement), "{text}"),
            // The ratio is the gear joint's: a geometry error naming its equation.
            SolveError::Geometry {
                parameter: p,
                value: v,
                requirement: r,
                ..
            } => {
                assert_eq!(requirement, Requirement::Ratio, "{text}");
                assert_eq!((p, v, r), (index, value, requirement), "{text}");
            }
            _ => panic!("{parameter} = {value}: {error:?}"),
        }
        assert!(text.contains(named), "{text}");
        assert!(text.contains(&format!("parameter `{parameter}`")), "{text}");
        assert!(!error.is_step_related());
    }
    for (parameter, value) in [
        ("m", 2.0),
        ("m", 0.0),
        ("c", 0.0),
        ("free", 0.0),
        ("ratio", -3.0),
    ] {
        solve(parameter, value).unwrap_or_else(|e| panic!("{parameter} = {value}: {}", e.1));
    }
}

#[test]
fn generated_code_checks_physics_set_at_run_time() {
    refuses_bad_physics(|p, v| solve_with(Loaded::default(), p, v));
    refuses_bad_physics(|p, v| solve_with(Dense::new(Loaded::default()), p, v));
}

#[test]
fn the_interpreter_checks_physics_set_at_run_time() {
    let scene =
        mechgen::compile(mechgen::Input::Text(LOADED), &mechgen::Options::default()).unwrap();
    refuses_bad_physics(|p, v| solve_with(Interpreted::new(&scene), p, v));
}

#[test]
fn constant_physics_generates_no_check() {
    let constant = LOADED
        .replace("mass m inertia j centre(arm, 0)", "mass 2 inertia 0.01")
        .replace(
            "stiffness k, length free, damping c",
            "stiffness 500, length 0.2, damping 4",
        )
        .replace("ratio ratio", "ratio 2");
    for (source, generated) in [(LOADED, true), (constant.as_str(), false)] {
        let tokens: proc_macro2::TokenStream = source.parse().unwrap();
        let code = mechgen::expand(mechgen::Input::Tokens(tokens), &mechgen::Options::default())
            .unwrap()
            .to_string();
        assert_eq!(
            code.contains("check_physics"),
            generated,
            "{generated}:\n{source}"
        );
    }
}

/// A solver checks its parameters once, not on every solve, but again after any change
/// through `mechanism_mut`: a bad value set between two solves of one solver is refused by
/// the next, and the good value set back solves again.
#[test]
fn a_solver_checks_parameters_set_between_its_solves() {
    let m = Loaded::default();
    let mut guess = Vector::<<Loaded as Mechanism>::Dim>::zeros();
    m.initial_guess(&mut guess);
    let mut solver = Solver::new(m);
    solver.solve(0.1, &guess).expect("the defaults solve");
    for (parameter, value, requirement, ..) in BAD {
        let m = solver.mechanism();
        let index = (0..m.parameter_count()).find(|&i| m.parameter_name(i) == Some(parameter));
        let good = index.and_then(|i| m.parameter(i)).expect("declared");
        solver
            .mechanism_mut()
            .set_parameter(parameter, value)
            .unwrap();
        match solver.solve(0.1, &guess) {
            Err(
                SolveError::Physics { requirement: r, .. }
                | SolveError::Geometry { requirement: r, .. },
            ) => {
                assert_eq!(r, requirement, "{parameter} = {value}");
            }
            other => panic!("{parameter} = {value}: {other:?}"),
        }
        solver
            .mechanism_mut()
            .set_parameter(parameter, good)
            .unwrap();
        solver
            .solve(0.1, &guess)
            .expect("the good value solves again");
    }
}
