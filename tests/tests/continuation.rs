//! The state at a time is the one continuous motion from t = 0 reaches: whatever start time a
//! simulation is assembled at, whatever times were asked before, and however many blocks change
//! their determinant's sign in one step. Every scene here has Newton blocks with a mirror
//! solution (a lever on either side of its pin, a ram on either side of its lever, the two
//! intersections of a Peaucellier cell's circles), so a solve that loses the motion lands on a
//! wrong but valid configuration: only comparing with the motion followed in fine steps shows it.

use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{Simulation, SolveError, Solver, Storage, Structured, mechanism};

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
