//! Forward dynamics up to a toggle of the partition, through the scene's own solve plan: a
//! pendulum whose free coordinate is its arm's x (`x = d cos θ`) falls past the horizontal,
//! where x stops determining θ and the reflected motion `θ → −θ` gives the same smooth x(t).
//! Generated and interpreted, at fixed steps of 0.2 and 0.1 ms the integrator stops with
//! [`DynamicsError::Toggle`] within a step of the horizontal (its time from the exact
//! large-amplitude motion of `mechgen_tests::reference::pendulum`), the state before it kept on
//! the release side. (At 0.5 ms and coarser the step across the horizontal asks for an x
//! beyond the arm's reach, 150 mm, and fails to assemble, or its iteration stalls: a
//! `Solve` or `NoConvergence` error, not this one.)

mod dynamics;

use dynamics::{fixed, interpreted, start};
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{
    Dynamic, DynamicsError, EquationsOfMotion, FreeStorage, Storage, Structured,
};
use mechgen_tests::reference::pendulum::Pendulum as Reference;
use mechgen_tests::twin;
use std::f64::consts::FRAC_PI_2;

twin! {
    SWING,
    mechanism Swing {
        ground frame at (0, 0, 0);
        /// A bar along its x axis, its centre of mass (its reference point) 150 mm from the
        /// pivot, released from rest 60° above the horizontal (x = 75 mm).
        body arm near (75, 130, 60deg) mass 2 inertia 5000;
        joint pivot: revolute(frame, arm @ (-150, 0));
        free reach: x(arm) from 75;
        gravity (0, -9810);
    }
}

/// The arm's angle `θ` in `q` (frame, arm).
const ARM_THETA: usize = 5;

/// The time the arm reaches the horizontal (`φ = θ + π/2` falls from 150° to 90°), by
/// bisection on the exact motion from rest.
fn horizontal_time() -> f64 {
    let reference = Reference {
        mass: 2.0,
        inertia: 5000.0,
        arm: 150.0,
        gravity: 9810.0,
    };
    let amplitude = 60f64.to_radians() + FRAC_PI_2;
    let (mut before, mut after) = (0.0, 0.5 * reference.period(amplitude));
    while after - before > 1e-12 {
        let mid = 0.5 * (before + after);
        if reference.exact_from_rest(amplitude, mid) > FRAC_PI_2 {
            before = mid;
        } else {
            after = mid;
        }
    }
    before
}

/// Steps `mechanism` at fixed steps `h` towards 1 s and checks that it stops at the toggle.
fn stops_at_the_toggle<M>(label: &str, mechanism: M, h: f64, toggle: f64)
where
    M: Dynamic + EquationsOfMotion + Structured,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    let mut integrator = start(mechanism, fixed(h, 0.9));
    let Err(error) = integrator.step_to(1.0).map(|_| ()) else {
        panic!("{label}, h = {h}: passed the toggle at {toggle}");
    };
    let described = integrator.describe(&error).to_string();
    let DynamicsError::Toggle { t, step } = error else {
        panic!("{label}, h = {h}: {described}");
    };
    // A step reaching or passing the horizontal (the method's phase error at these steps is
    // far below 1e-4 s), the state before it kept, short of it and on the release side.
    let kept = integrator.t();
    assert!(kept < toggle && kept + step == t, "{label}: {kept} {t}");
    assert!(t > toggle - 1e-4, "{label}, h = {h}: {t} vs {toggle}");
    let theta = integrator.state().q[ARM_THETA];
    assert!(theta > 0.0 && theta < 0.01, "{label}, h = {h}: θ = {theta}");
}

#[test]
fn a_falling_arm_whose_x_is_free_stops_at_the_horizontal() {
    let toggle = horizontal_time();
    for h in [2e-4, 1e-4] {
        stops_at_the_toggle("generated", Swing::default(), h, toggle);
        stops_at_the_toggle("interpreted", interpreted(SWING), h, toggle);
    }
}
