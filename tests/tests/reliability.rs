//! The reliability holes a new user met, each closed: scenes that hung or exited 0 with a wrong
//! answer now end in a solution whose constraints hold or in a typed error that says why.

use mechgen_cli::Interpreted;
use mechgen_examples::scenes::PistonCrank;
use mechgen_runtime::{Mechanism, Simulation, SolveError, Solver, Vector, nalgebra::Const};

const SEED: &str = include_str!("../../examples/scenes/piston_crank.mech");

fn interpreted(source: &str) -> Result<Interpreted, String> {
    mechgen::compile_str(source)
        .map(|scene| Interpreted::new(&scene))
        .map_err(|errors| errors.messages().join("\n"))
}

#[test]
fn geometry_beyond_double_precision_is_a_compile_error_not_a_hang() {
    for huge in ["1e150", "1e140", "1e100", "1e20"] {
        let source = SEED.replace("rod @ (41.3, 0)", &format!("rod @ ({huge}, 0)"));
        let error = interpreted(&source).expect_err(huge);
        assert!(
            error.contains("cannot resolve both") || error.contains("out of the range"),
            "{error}"
        );
    }
}

#[test]
fn angles_of_many_turns_in_poses_and_guesses_are_reduced() {
    let source = SEED.replace("bearing at (0, 0, 0)", "bearing at (0, 0, -1e20)");
    let mechanism = interpreted(&source).unwrap();
    let simulation = Simulation::new(Solver::new(mechanism), 0.0).unwrap();
    let bearing_theta = simulation.state().q[14];
    assert!(
        bearing_theta.abs() <= core::f64::consts::PI,
        "{bearing_theta}"
    );
    assert_eq!(bearing_theta, (-1e20_f64).sin().atan2((-1e20_f64).cos()));

    // A guess of 1e12 rad is the angle it means.
    let source = SEED.replace("near (29, 72, -2.35)", "near (29, 72, 1e12)");
    let mechanism = interpreted(&source).unwrap();
    let mut guess = Vector::<mechgen_runtime::nalgebra::Dyn>::zeros(15);
    mechanism.initial_guess(&mut guess);
    assert!(guess[8].abs() <= core::f64::consts::PI);
}

#[test]
fn a_huge_angle_passed_at_run_time_is_unresolved_not_accepted() {
    // The generated seed, given a rod angle of 1e12 rad directly: its rounding alone (1e-4 rad)
    // exceeds any acceptable residual.
    let mut solver = Solver::new(PistonCrank::default());
    let mut guess = Vector::<Const<15>>::zeros();
    solver.mechanism().initial_guess(&mut guess);
    guess[8] = 1e12;
    match solver.solve(0.0, &guess) {
        Ok(state) => {
            // Accepted only if the constraints hold.
            let mut phi = Vector::<Const<15>>::zeros();
            solver.mechanism().phi(&state.q, 0.0, &mut phi);
            assert!(phi.amax() <= 1e-8 * 128.0, "{phi:?}");
        }
        Err(error) => {
            assert!(
                matches!(
                    error,
                    SolveError::Unresolved { .. } | SolveError::BranchFlip { .. }
                ),
                "{error:?}"
            );
            let text = solver.describe(&error).to_string();
            assert!(text.contains("t = 0"), "{text}");
        }
    }
    let error = SolveError::Unresolved {
        time: 2.0,
        iterations: 1,
        residual: 95.0,
        equation: 8,
    };
    let text = error.describe(solver.mechanism()).to_string();
    assert!(
        text.contains("cannot be resolved") && text.contains("`piston_pin.x`"),
        "{text}"
    );
    assert!(!error.is_step_related());
}

#[test]
fn the_seed_assembles_at_any_start_time() {
    // The driven angle is far from the guess (0.15 s at 314 rad/s is 47 rad; 10 s is 3140).
    for t0 in [0.15, 0.5, 10.0] {
        let simulation = Simulation::new(Solver::new(PistonCrank::default()), t0)
            .unwrap_or_else(|e| panic!("t0 = {t0}: {e:?}"));
        let exact = mechgen_examples::closed_form::PistonCrank::default().q(t0);
        let q = &simulation.state().q;
        // The crank angle itself is ωt0; every other coordinate is within a turn.
        let error = (q - Vector::<Const<15>>::from_column_slice(&exact)).amax();
        assert!(
            error <= 1e-12 * (1.0 + 314.0 * t0) * 160.0,
            "t0 = {t0}: {error:e}"
        );
    }
}
