//! Generated code through the runtime allocates nothing: positions, velocities and
//! accelerations of the seed over many steps, the force solve (reactions and driver efforts),
//! sub-stepping, assembly at a later start time (the motion followed from t = 0), every error
//! path with its description, and CSV output; and the dense reference (`Dense`, any mechanism
//! as one block) on the same paths.
//!
//! A counting global allocator wraps the system one. This file holds a single test so that no
//! other test thread allocates while it counts.

use core::fmt::Write;
use mechgen_examples::scenes::{
    FourBar, PistonCrank, PistonCrankBodies, PistonCrankDynamics, PistonCrankDynamicsForces,
};
use mechgen_examples::stability::{
    self, FlexiblePistonCrank, Parallelogram, SliderCrank, Unclosable,
};
use mechgen_runtime::{Dense, Mechanism, Simulation, SolveError, Solver, write_csv_header};
use mechgen_tests::counting::{self, Counting, Sink};

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn generated_scenes_solve_without_allocating() {
    counting::start();
    // The counter is live: a real allocation is seen.
    let before = counting::allocations();
    drop(core::hint::black_box(Box::new(0_u8)));
    assert!(counting::allocations() > before);

    let before = counting::allocations();
    let mut sink = Sink(0);
    let mut simulation = Simulation::new(Solver::new(PistonCrank::default()), 0.0).expect("seed");
    let mut piston_travel = 0.0f64;
    simulation
        .run(0.2, 5_000, |state| {
            piston_travel = piston_travel.max(state.piston().x);
            state.write_csv_row(&mut sink).expect("sink never fails");
        })
        .expect("seed solves");
    // An error path: a non-finite time is refused without allocating.
    assert!(simulation.step_to(f64::NAN).is_err());
    simulation.set_predictor(false);
    simulation
        .run(0.3, 500, |_| {})
        .expect("seed solves without predictor");

    let mut four_bar = Simulation::new(Solver::new(FourBar::default()), 0.0).expect("four-bar");
    four_bar.run(1.0, 1_000, |_| {}).expect("four-bar solves");
    // A start at t0 > 0: assembled at t = 0 and followed to t0.
    let later = Simulation::new(Solver::new(FourBar::default()), 0.3).expect("four-bar at 0.3");
    assert!(later.state().substeps > 1);

    // The force solve: reactions and efforts at every step, by name and as CSV columns.
    let mut dynamics =
        Simulation::new(Solver::new(PistonCrankDynamics::default()), 0.0).expect("dynamics");
    let mut peak_torque = 0.0f64;
    dynamics
        .run(0.05, 1_000, |state| {
            let pin = state.reactions().crank_pin;
            peak_torque = peak_torque.max(state.efforts().crank_angle.abs());
            assert!(pin.fx.is_finite() && pin.fy.is_finite());
            state.write_csv_row(&mut sink).expect("sink never fails");
        })
        .expect("dynamics solves");
    assert!(peak_torque > 0.0);

    // Every safeguard and failure of the stability work: sub-stepping a coarse step, the
    // Levenberg–Marquardt fallback ending in NoAssembly, the rank-revealing diagnosis of a
    // toggle and of redundant constraints, a branch flip from a bad guess, a NaN parameter.
    let oscillating = FlexiblePistonCrank {
        omega: 0.0,
        amplitude: 0.5,
        frequency: 2000.0,
        ..FlexiblePistonCrank::default()
    };
    let mut coarse = Simulation::new(Solver::new(oscillating), 0.0).expect("oscillating seed");
    let mut substeps = 0;
    coarse
        .run(core::f64::consts::TAU / 2000.0, 6, |state| {
            substeps += state.substeps;
        })
        .expect("sub-steps through");
    assert!(substeps > 7, "{substeps}");
    let unclosable = Simulation::new(Solver::new(Unclosable::default()), 0.0);
    assert!(matches!(
        unclosable.map_err(|failure| failure.error).err(),
        Some(SolveError::NoAssembly { .. })
    ));
    let mut toggle = Simulation::new(
        Solver::new(SliderCrank {
            l: 1.0,
            ..SliderCrank::default()
        }),
        0.0,
    )
    .expect("slider-crank");
    let error = toggle.run(core::f64::consts::TAU, 97, |_| {}).unwrap_err();
    write!(sink, "{}", toggle.solver().describe(&error)).expect("sink never fails");
    let mut solver = Solver::new(Parallelogram::default());
    let mut q = Default::default();
    solver.mechanism().initial_guess(&mut q);
    let error = solver.solve_position(&mut q, 0.0).unwrap_err();
    write!(sink, "{}", solver.describe(&error)).expect("sink never fails");
    assert!(matches!(error, SolveError::Singular { .. }));
    assert!(stability::seed_from_origin(0.0).is_err());
    let mut nan = Solver::new(FlexiblePistonCrank::default());
    nan.mechanism_mut().omega = f64::NAN;
    assert!(nan.solve_position(&mut Default::default(), 0.0).is_err());

    // The dense reference: one solve with the CSV header and row, a run with and without the
    // predictor, a NaN time and a pose the rod is too short to reach, described.
    let mut solver = Solver::new(Dense::new(SliderCrank::default()));
    let mut guess = Default::default();
    solver.mechanism().initial_guess(&mut guess);
    let state = solver.solve(0.25, &guess).expect("assembles");
    write_csv_header(solver.mechanism(), &mut sink).unwrap();
    state.write_csv_row(&mut sink).unwrap();
    let mut simulation = Simulation::new(solver, 0.0).expect("assembles");
    let mut steps = 0;
    simulation
        .run(3.0, 500, |state| {
            steps += 1;
            state.write_csv_row(&mut sink).unwrap();
        })
        .expect("the dense reference solves");
    simulation.set_predictor(false);
    simulation.step_to(3.1).expect("solves");
    let nan = simulation.step_to(f64::NAN).unwrap_err();
    write!(sink, "{nan}").unwrap();
    simulation.solver_mut().mechanism_mut().inner_mut().l = 0.5;
    let unreachable = simulation.step_to(3.9).unwrap_err();
    write!(
        sink,
        "{}",
        unreachable.describe(simulation.solver().mechanism())
    )
    .unwrap();
    assert_eq!(steps, 501);
    let allocations = counting::allocations() - before;

    assert_eq!(allocations, 0, "heap allocations in solve paths");
    assert!(sink.0 > 0 && piston_travel > 180.0);
}
