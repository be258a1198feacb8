//! Generated code, solved by the runtime, against the closed-form solutions: one revolution of
//! each example scene, and the seed's 17-digit reference table.

use mechgen_examples::accuracy::ErrorTracker;
use mechgen_examples::closed_form;
use mechgen_examples::scenes::{FourBar, PistonCrank};
use mechgen_runtime::{Accelerations, Mechanism, Simulation, Solver, Structured, Vector};

/// The foundation's accuracy target: max error ≤ 1e-10 of each quantity's largest magnitude.
const TOLERANCE: f64 = 1e-10;

fn one_revolution<
    M: Structured<Dim = mechgen_runtime::nalgebra::Const<N>> + Accelerations,
    const N: usize,
>(
    mechanism: M,
    period: f64,
    exact: impl Fn(f64) -> closed_form::Kinematics<N>,
) -> ErrorTracker {
    let mut simulation = Simulation::new(Solver::new(mechanism), 0.0).expect("assembles at t = 0");
    let mut tracker = ErrorTracker::new();
    simulation
        .run(period, 360, |state| {
            tracker.add(
                state.q.as_slice(),
                state.qd().as_slice(),
                state.qdd().as_slice(),
                &exact(state.t),
            );
        })
        .expect("solves every step");
    tracker
}

#[test]
fn seed_piston_crank_matches_its_closed_form_over_one_revolution() {
    let exact = closed_form::PistonCrank::default();
    let errors = one_revolution(PistonCrank::default(), exact.period(), |t| {
        exact.kinematics(t)
    })
    .errors();
    assert!(errors.max() <= TOLERANCE, "{errors:?}");
}

#[test]
fn four_bar_matches_its_closed_form_over_one_revolution() {
    let exact = closed_form::FourBar::default();
    let errors =
        one_revolution(FourBar::default(), exact.period(), |t| exact.kinematics(t)).errors();
    assert!(errors.max() <= TOLERANCE, "{errors:?}");
}

#[test]
fn a_changed_parameter_changes_the_motion_consistently() {
    let mut scene = PistonCrank::default();
    scene
        .set_parameter("omega", 100.0)
        .expect("omega is declared");
    let exact = closed_form::PistonCrank {
        omega: 100.0,
        ..Default::default()
    };
    let errors = one_revolution(scene, exact.period(), |t| exact.kinematics(t)).errors();
    assert!(errors.max() <= TOLERANCE, "{errors:?}");
}

/// The 1000-row table in `tests/data/seed_reference.csv` (50-digit arithmetic, 17 digits).
fn reference_rows() -> Vec<closed_form::Kinematics<15>> {
    let text = include_str!("../data/seed_reference.csv");
    text.lines()
        .skip(1)
        .map(|line| {
            let v: Vec<f64> = line
                .split(',')
                .map(|x| x.parse().expect("number"))
                .collect();
            assert_eq!(v.len(), 46, "t + 3 × 15 columns");
            let part = |k: usize| -> [f64; 15] { std::array::from_fn(|i| v[1 + 15 * k + i]) };
            closed_form::Kinematics {
                t: v[0],
                q: part(0),
                qd: part(1),
                qdd: part(2),
            }
        })
        .collect()
}

#[test]
fn seed_matches_the_reference_table_at_every_row() {
    let rows = reference_rows();
    assert_eq!(rows.len(), 1000);
    let mut simulation =
        Simulation::new(Solver::new(PistonCrank::default()), rows[0].t).expect("assembles");
    let mut tracker = ErrorTracker::new();
    for row in &rows {
        let state = simulation.step_to(row.t).expect("solves");
        tracker.add(
            state.q.as_slice(),
            state.qd().as_slice(),
            state.qdd().as_slice(),
            row,
        );
    }
    let errors = tracker.errors();
    assert!(errors.max() <= TOLERANCE, "{errors:?}");
}

#[test]
fn acceleration_equations_hold_along_the_exact_motion() {
    // Φ_q q̈ = γ with generated Φ_q and γ evaluated at the closed-form q, q̇, q̈: checks γ
    // (including its velocity-squared terms) independently of the solver.
    let scene = PistonCrank::default();
    let exact = closed_form::PistonCrank::default();
    let mut jacobian = mechgen_runtime::Matrix::<<PistonCrank as Mechanism>::Dim>::zeros();
    let mut gamma = Vector::<<PistonCrank as Mechanism>::Dim>::zeros();
    let mut nu = gamma;
    let mut worst: f64 = 0.0;
    let mut scale: f64 = 0.0;
    for k in 0..200 {
        let state = exact.kinematics(exact.period() * f64::from(k) / 200.0);
        let q = Vector::<<PistonCrank as Mechanism>::Dim>::from(state.q);
        let qd = Vector::<<PistonCrank as Mechanism>::Dim>::from(state.qd);
        let qdd = Vector::<<PistonCrank as Mechanism>::Dim>::from(state.qdd);
        scene.jacobian(&q, state.t, &mut jacobian);
        scene.gamma(&q, &qd, state.t, &mut gamma);
        scene.nu(&q, state.t, &mut nu);
        worst = worst.max((jacobian * qdd - gamma).amax());
        worst = worst.max((jacobian * qd - nu).amax());
        scale = scale.max(gamma.amax()).max(nu.amax());
    }
    assert!(worst <= 1e-12 * scale, "residual {worst} at scale {scale}");
}
