//! The position solve of one block: a Newton step and a clamped step against the pendulum's
//! linearisation, solved by hand.
//!
//! With Φ = (x − a cos θ, y − a sin θ, θ − ω t), the Newton correction δ = Φ_q⁻¹ Φ at q₀ is
//! δθ = θ₀ − ω t, δx = Φ_x − a sin θ₀ δθ, δy = Φ_y + a cos θ₀ δθ. One iteration (the cap) leaves
//! `q` at the last iterate.

mod common;

use common::pendulum::Pendulum;
use mechgen_runtime::nalgebra::Vector3;
use mechgen_runtime::{Dense, SolveError, Solver, SolverOptions};

/// The Newton correction δ at `q` and `t`, by hand.
fn correction(pendulum: &Pendulum, q: Vector3<f64>, t: f64) -> Vector3<f64> {
    let (a, (s, c)) = (pendulum.a, q.z.sin_cos());
    let d_theta = q.z - pendulum.omega * t;
    let phi = (q.x - a * c, q.y - a * s);
    Vector3::new(phi.0 - a * s * d_theta, phi.1 + a * c * d_theta, d_theta)
}

/// The iterate after one update from `q` at `t`, with `max_step`.
fn one_update(q: Vector3<f64>, t: f64, max_step: f64) -> Vector3<f64> {
    let options = SolverOptions {
        max_iterations: 1,
        max_step,
        ..SolverOptions::default()
    };
    let mut solver = Solver::with_options(Dense::new(Pendulum::default()), options);
    let mut q = q;
    match solver.solve_position(&mut q, t) {
        Err(SolveError::NoConvergence { iterations: 1, .. }) => q,
        other => panic!("expected the iteration cap, got {other:?}"),
    }
}

#[test]
fn one_update_is_the_newton_step() {
    let (q0, t) = (Vector3::new(1.5, 1.0, 0.75), 0.4);
    let expected = q0 - correction(&Pendulum::default(), q0, t);
    let q1 = one_update(q0, t, 1.0);
    assert!((q1 - expected).amax() < 1e-15, "{q1} vs {expected}");
    // The angle's equation is linear: one step solves it.
    assert!((q1.z - 1.5 * t).abs() < 1e-15);
}

#[test]
fn a_long_step_is_clamped_to_max_step_along_the_newton_direction() {
    let (q0, t) = (Vector3::new(1.5, 1.0, 0.75), 0.4);
    let delta = correction(&Pendulum::default(), q0, t);
    // The step's length in scene lengths (a = 2, a power of two: x and y count halved) and
    // radians.
    let length = (delta.x / 2.0)
        .abs()
        .max((delta.y / 2.0).abs())
        .max(delta.z.abs());
    let max_step = 0.05;
    assert!(length > max_step);
    let expected = q0 - delta * (max_step / length);
    let q1 = one_update(q0, t, max_step);
    assert!((q1 - expected).amax() < 1e-15, "{q1} vs {expected}");
}
