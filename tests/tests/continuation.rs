//! The state at a time is the one continuous motion from t = 0 reaches: whatever start time a
//! simulation is assembled at, whatever times were asked before, and however many blocks change
//! their determinant's sign in one step. Every scene here has Newton blocks with a mirror
//! solution (a lever on either side of its pin, a ram on either side of its lever, the two
//! intersections of a Peaucellier cell's circles), so a solve that loses the motion lands on a
//! wrong but valid configuration: only comparing with the motion followed in fine steps shows it.

use mechgen_examples::scenes::{FourBar, PistonCrank};
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{Simulation, SolveError, Solver, Storage, Structured, Unit, mechanism};
use proptest::prelude::*;
use proptest::test_runner::{RngSeed, TestCaseError};

mechanism! {
    /// A crank whose pin runs in the slot of a lever (the core of a Whitworth quick-return):
    /// the lever's angle has two solutions at every crank angle, half a turn apart.
    pub mechanism MirrorAtStart {
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body lever near (0, 0, 0);
        joint crank_pivot: revolute(frame @ (0, 30), crank);
        joint lever_pivot: revolute(frame, lever);
        joint pin: slot(lever, crank @ (50, 0), along (1, 0));
        driver spin: angle(crank) = t;
    }
}

mechanism! {
    /// Two levers on the same crank pin, each its own Newton block: both flip together when a
    /// step lands both on their mirror solutions, which keeps the product of the blocks'
    /// determinant signs.
    pub mechanism TwinLevers {
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body lever near (0, 0, 0);
        body twin near (0, 0, 0);
        joint crank_pivot: revolute(frame @ (0, 30), crank);
        joint lever_pivot: revolute(frame, lever);
        joint pin: slot(lever, crank @ (50, 0), along (1, 0));
        joint twin_pivot: revolute(twin, frame);
        joint pin2: slot(twin, crank @ (50, 0), along (1, 0));
        driver spin: angle(crank) = 6 * t + 0.2 * sin(3 * t);
    }
}

/// Lever angles of [`MirrorAtStart`] in closed form, unwrapped along the motion from t = 0: the
/// lever points from its pivot at the origin to the crank pin.
fn lever_angle(crank: f64) -> f64 {
    let (x, y) = (50.0 * crank.cos(), 30.0 + 50.0 * crank.sin());
    let wrapped = y.atan2(x);
    // The pin turns round the lever's pivot once per crank turn (the crank is longer than the
    // pivots' distance), so the lever's unwrapped angle gains a turn per crank turn.
    let turns = ((crank - wrapped) / core::f64::consts::TAU).round();
    wrapped + turns * core::f64::consts::TAU
}

/// Steps from t = 0 to `t` in `steps` equal steps.
fn stepped<M: Structured>(scene: M, t: f64, steps: usize) -> Result<Simulation<M>, SolveError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    let mut simulation = Simulation::new(Solver::new(scene), 0.0)?;
    simulation.run(t, steps, |_| {})?;
    Ok(simulation)
}

#[test]
fn two_blocks_flipping_in_one_step_are_caught() {
    // 16 steps to t = 3: the crank turns 18 rad, more than half a turn per step.
    let fine = stepped(TwinLevers::default(), 3.0, 3000).unwrap();
    let reference = fine.state().q[TwinLevers::LEVER_THETA];
    assert!((reference - 18.7196).abs() < 1e-4, "{reference}");
    match stepped(TwinLevers::default(), 3.0, 16) {
        Ok(coarse) => {
            let q = &coarse.state().q;
            for index in [TwinLevers::LEVER_THETA, TwinLevers::TWIN_THETA] {
                assert!(
                    (q[index] - reference).abs() < 1e-9,
                    "coordinate {index}: {} vs {reference}",
                    q[index]
                );
            }
        }
        Err(error) => assert!(error.time().is_some(), "{error:?}"),
    }
}

#[test]
fn the_lever_follows_its_closed_form_along_the_motion() {
    let mut simulation = Simulation::new(Solver::new(MirrorAtStart::default()), 0.0).unwrap();
    simulation
        .run(20.0, 400, |state| {
            let expected = lever_angle(state.t);
            let theta = state.q[MirrorAtStart::LEVER_THETA];
            assert!(
                (theta - expected).abs() < 1e-10,
                "t = {}: {theta} vs {expected}",
                state.t
            );
        })
        .unwrap();
}

mechanism! {
    /// A Whitworth quick-return: the crank is longer than the distance between the pivots, so
    /// the slotted lever turns fully, and a rod from the lever's far end drives a ram along a
    /// guide. The lever block and the ram block (rod angle and ram position) each have a mirror.
    pub mechanism Whitworth {
        ground frame at (0, 0, 0);
        body crank near (0, 30, 0);
        body lever near (0, 0, 0.54);
        body rod near (-34.3, -20.6, 0.006);
        body ram near (65.7, -20, 0);
        joint crank_pivot: revolute(frame @ (0, 30), crank);
        joint lever_pivot: revolute(frame, lever);
        joint pin: slot(lever, crank @ (50, 0), along (1, 0));
        joint tip: revolute(lever @ (-40, 0), rod);
        joint ram_pin: revolute(rod @ (100, 0), ram);
        joint guide: prismatic(frame @ (0, -20), ram, along (1, 0));
        driver spin: angle(crank) = 2 * t;
    }
}

mechanism! {
    /// A Peaucellier–Lipkin cell of distance joints: arms of 2.5 from the origin, a rhombus of
    /// side 1 whose vertex C the crank carries on a circle through the origin, and P, the
    /// vertex opposite C, which moves on a straight line. A and B are the two intersections of
    /// the circles about O and C (one arm on each: both on one is singular), P the second
    /// intersection of the circles about A and B.
    pub mechanism Peaucellier {
        ground frame at (0, 0, 0);
        body crank near (1.5, 0, 0);
        body arm_a near (0, 0, 0.41);
        body arm_b near (0, 0, -0.41);
        body side near (2.375, 0.78, -2.25);
        joint crank_pivot: revolute(frame @ (1.5, 0), crank);
        joint pivot_a: revolute(frame, arm_a);
        joint pivot_b: revolute(frame, arm_b);
        joint a_to_c: distance(arm_a @ (2.5, 0), crank @ (1.5, 0), 1);
        joint b_to_c: distance(arm_b @ (2.5, 0), crank @ (1.5, 0), 1);
        joint hinge: revolute(arm_a @ (2.5, 0), side);
        joint p_to_b: distance(side @ (1, 0), arm_b @ (2.5, 0), 1);
        driver swing: angle(crank) = 1.2 * sin(t);
    }
}

/// How the corpus's scenes are sampled: start times in `0..horizon`, the motion followed in
/// `rate` steps per second for the reference, positions compared to `size` × 1e-8.
struct Sampling {
    horizon: f64,
    rate: f64,
    size: f64,
}

/// The state at `t0` three ways: the motion from t = 0 followed in fine steps (the reference),
/// a simulation started at `t0`, and one started at `t1` (before or after `t0`) and stepped to
/// `t0`. All three must be the same state, angles with the same winding.
fn same_state_however_reached<M: Structured + Clone>(
    scene: M,
    sampling: &Sampling,
    t0: f64,
    t1: f64,
) -> Result<(), TestCaseError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    let steps = ((t0 * sampling.rate).ceil() as usize).max(1);
    let reference = stepped(scene.clone(), t0, steps)
        .map_err(|e| TestCaseError::fail(format!("t0 = {t0}, reference: {e:?}")))?;
    let direct = Simulation::new(Solver::new(scene.clone()), t0)
        .map_err(|e| TestCaseError::fail(format!("start at t0 = {t0}: {e}")))?;
    let mut earlier = Simulation::new(Solver::new(scene.clone()), t1)
        .map_err(|e| TestCaseError::fail(format!("start at t1 = {t1}: {e}")))?;
    earlier
        .step_to(t0)
        .map_err(|e| TestCaseError::fail(format!("t1 = {t1} to t0 = {t0}: {e:?}")))?;
    let expected = &reference.state().q;
    for (how, state) in [
        ("started at t0", direct.state()),
        ("via t1", earlier.state()),
    ] {
        prop_assert_eq!(state.t, t0);
        for (k, (a, b)) in state.q.iter().zip(expected.iter()).enumerate() {
            let scale = match scene.coordinate_unit(k) {
                Unit::Angle => 1.0,
                _ => sampling.size,
            };
            prop_assert!(
                (a - b).abs() <= 1e-8 * scale,
                "{} t0 = {}, t1 = {}: q[{}] = {} vs {} stepped from 0",
                how,
                t0,
                t1,
                k,
                a,
                b
            );
        }
    }
    Ok(())
}

/// Deterministic (fixed seed), and no regression file written into the tree.
fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 40,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(20),
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn a_state_does_not_depend_on_the_start_time_or_the_times_asked_before(
        scene in 0_usize..5,
        u0 in 0.02_f64..1.0,
        u1 in 0.0_f64..1.0,
    ) {
        let (four_bar, mirror, whitworth, peaucellier, seed) = (
            Sampling { horizon: 3.0, rate: 200.0, size: 120.0 },
            Sampling { horizon: 20.0, rate: 20.0, size: 50.0 },
            Sampling { horizon: 10.0, rate: 40.0, size: 100.0 },
            Sampling { horizon: 10.0, rate: 40.0, size: 2.5 },
            Sampling { horizon: 0.2, rate: 6000.0, size: 160.0 },
        );
        match scene {
            0 => same_state_however_reached(
                FourBar::default(), &four_bar, u0 * four_bar.horizon, u1 * four_bar.horizon,
            )?,
            1 => same_state_however_reached(
                MirrorAtStart::default(), &mirror, u0 * mirror.horizon, u1 * mirror.horizon,
            )?,
            2 => same_state_however_reached(
                Whitworth::default(), &whitworth, u0 * whitworth.horizon, u1 * whitworth.horizon,
            )?,
            3 => same_state_however_reached(
                Peaucellier::default(),
                &peaucellier,
                u0 * peaucellier.horizon,
                u1 * peaucellier.horizon,
            )?,
            _ => same_state_however_reached(
                PistonCrank::default(), &seed, u0 * seed.horizon, u1 * seed.horizon,
            )?,
        }
    }
}

/// The scene as `mechgen solve` reads it: the interpreter, the CLI's solver path.
const MIRROR_AT_START: &str = "
mechanism MirrorAtStart {
    ground frame at (0, 0, 0);
    body crank near (0, 0, 0);
    body lever near (0, 0, 0);
    joint crank_pivot: revolute(frame @ (0, 30), crank);
    joint lever_pivot: revolute(frame, lever);
    joint pin: slot(lever, crank @ (50, 0), along (1, 0));
    driver spin: angle(crank) = t;
}";

#[test]
fn a_start_at_three_seconds_is_not_the_mirror() {
    // `--at 3` gave the mirror angle −0.6426; the motion from t = 0 reaches 2.4990.
    let expected = lever_angle(3.0);
    assert!((expected - 2.4990).abs() < 1e-4, "{expected}");
    let scene = mechgen::compile(
        mechgen::Input::Text(MIRROR_AT_START),
        &mechgen::Options::default(),
    )
    .unwrap();
    let interpreted = mechgen_interp::Interpreted::new(&scene);
    let simulation = Simulation::new(Solver::new(interpreted), 3.0).unwrap();
    let theta = simulation.state().q[MirrorAtStart::LEVER_THETA];
    assert!((theta - expected).abs() < 1e-10, "{theta}");
    let generated = Simulation::new(Solver::new(MirrorAtStart::default()), 3.0).unwrap();
    assert!((generated.state().q[MirrorAtStart::LEVER_THETA] - expected).abs() < 1e-10);
}

#[test]
fn every_start_time_of_the_quick_return_gives_the_ram_the_motion_reaches() {
    // The count: 9 of 20 start times in 0..3 s gave the wrong ram position.
    let mut reference = Simulation::new(Solver::new(Whitworth::default()), 0.0).unwrap();
    for k in 1..=20 {
        let t0 = 3.0 * k as f64 / 20.0;
        // The motion from t = 0 in steps of 0.5 ms (1 mrad of crank).
        reference.run(t0, 300, |_| {}).unwrap();
        let expected = reference.state().q;
        let started = Simulation::new(Solver::new(Whitworth::default()), t0).unwrap();
        let q = &started.state().q;
        assert!(
            (q[Whitworth::RAM_X] - expected[Whitworth::RAM_X]).abs() < 1e-8 * 100.0,
            "t0 = {t0}: ram at {} vs {}",
            q[Whitworth::RAM_X],
            expected[Whitworth::RAM_X]
        );
        assert!((q[Whitworth::LEVER_THETA] - expected[Whitworth::LEVER_THETA]).abs() < 1e-8);
    }
}

#[test]
fn a_start_time_beyond_the_step_budget_is_refused() {
    // The seed at 314 rad/s from t = 0 to t0 = 1e4 s: 3.1e6 rad of crank, more than the
    // budget's steps of about 0.2 scene lengths or radians can follow.
    let failure = Simulation::new(Solver::new(PistonCrank::default()), 1e4)
        .err()
        .expect("out of reach");
    let SolveError::Unreachable {
        time,
        reached,
        steps,
        ..
    } = failure.error
    else {
        panic!("{failure}");
    };
    assert_eq!(
        (time, steps),
        (1e4, mechgen_runtime::MAX_CONTINUATION_STEPS)
    );
    assert!(reached > 0.0 && reached < time, "{reached}");
    let text = failure.to_string();
    assert!(
        text.contains("out of reach") && text.contains("t = 0"),
        "{text}"
    );
}
