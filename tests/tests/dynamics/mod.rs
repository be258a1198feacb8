//! Shared by the forward-dynamics tests (`dynamics_*.rs`): integrator options, a scene's
//! `.mech` twin compiled for the interpreter, the motion sampled at given times, and the
//! checks every accepted step must pass (position constraints to the solver's tolerance,
//! velocity constraints to round-off, the free coordinates at the integrator's state).
//!
//! Each test file uses only part of it.
#![allow(dead_code)]

use mechgen_interp::Interpreted;
use mechgen_runtime::nalgebra::{DefaultAllocator, Dim};
use mechgen_runtime::{
    Dynamic, Energy, EquationsOfMotion, FreeStorage, Integrator, IntegratorOptions, Matrix, Solver,
    StepControl, Storage, Structured,
};

/// A fixed step `step` with numerical damping `rho_inf`.
pub fn fixed(step: f64, rho_inf: f64) -> IntegratorOptions {
    IntegratorOptions {
        rho_inf,
        control: StepControl::Fixed { step },
        ..IntegratorOptions::default()
    }
}

/// The error-controlled mode at tolerances `rtol`, `atol`, default damping.
pub fn adaptive(rtol: f64, atol: f64) -> IntegratorOptions {
    IntegratorOptions {
        control: StepControl::Adaptive {
            rtol,
            atol,
            initial: 1e-4,
            min: 1e-12,
            max: f64::INFINITY,
        },
        ..IntegratorOptions::default()
    }
}

/// The interpreter running `.mech` text (a `twin!`'s text), default options.
///
/// # Panics
/// If the text does not compile (a test's fixture).
pub fn interpreted(text: &str) -> Interpreted {
    let scene = mechgen::compile(mechgen::Input::Text(text), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    Interpreted::new(&scene)
}

/// An integrator on `mechanism` from t = 0.
///
/// # Panics
/// If it cannot start (assembly or the initial accelerations fail).
pub fn start<M>(mechanism: M, options: IntegratorOptions) -> Integrator<M>
where
    M: Dynamic + EquationsOfMotion + Structured,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    Integrator::new(Solver::new(mechanism), 0.0, options).unwrap_or_else(|e| panic!("{e}"))
}

/// One output of a run.
#[derive(Debug, Clone)]
pub struct Sample {
    /// Time.
    pub t: f64,
    /// `q`, `q̇`, `q̈`.
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    /// `[u, u̇, ü]` of each free degree of freedom.
    pub free: Vec<[f64; 3]>,
    /// The energy book.
    pub energy: Energy,
}

impl Sample {
    /// The integrator's current state.
    pub fn of<M>(integrator: &Integrator<M>) -> Self
    where
        M: Dynamic + EquationsOfMotion + Structured,
        DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
    {
        let state = integrator.state();
        let frees = integrator.solver().mechanism().free().value();
        Self {
            t: integrator.t(),
            q: state.q.as_slice().to_vec(),
            qd: state.qd().as_slice().to_vec(),
            qdd: state.qdd().as_slice().to_vec(),
            free: (0..frees).map(|k| integrator.free_state(k)).collect(),
            energy: integrator.energy(),
        }
    }
}

/// The motion at each of `times`, stepped onto.
///
/// # Panics
/// On any integrator error (the test's failure, named).
pub fn sample<M>(integrator: &mut Integrator<M>, times: &[f64]) -> Vec<Sample>
where
    M: Dynamic + EquationsOfMotion + Structured,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    times
        .iter()
        .map(|&t| {
            integrator
                .step_to(t)
                .unwrap_or_else(|e| panic!("t = {t}: {e}"));
            Sample::of(integrator)
        })
        .collect()
}

/// `n` evenly spaced times in `(0, t_end]`.
pub fn times(t_end: f64, n: usize) -> Vec<f64> {
    (1..=n).map(|i| t_end * i as f64 / n as f64).collect()
}

/// How far the integrator's state is from the constraints: the largest `|Φ_i(q, t)|` over the
/// scene's own rows (not the free ones) relative to the scene's length, the largest
/// `|Φ_q q̇ − ν|` over them relative to `max|Φ_q| · max|q̇|`, and the largest difference of a
/// free coordinate's value and rate from the integrator's `[u, u̇]` (`free_coordinates[k]`: the
/// coordinate free DOF `k` drives, an `angle(body)` free's `θ`).
pub fn constraint_residuals<M>(integrator: &Integrator<M>, free_coordinates: &[usize]) -> [f64; 3]
where
    M: Dynamic + EquationsOfMotion + Structured,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    let mechanism = integrator.solver().mechanism();
    let state = integrator.state();
    let (q, qd, t) = (&state.q, state.qd(), integrator.t());
    let dim = mechanism.dim();
    let free_rows: Vec<usize> = (0..free_coordinates.len())
        .map(|k| mechanism.free_equation(k))
        .collect();
    let own = |i: &usize| !free_rows.contains(i);

    let mut phi = q.clone();
    mechanism.phi(q, t, &mut phi);
    let position = (0..q.len())
        .filter(own)
        .map(|i| phi[i].abs())
        .fold(0.0, f64::max)
        / mechanism.length_scale();

    let mut jacobian = Matrix::<M::Dim>::zeros_generic(dim, dim);
    mechanism.jacobian(q, t, &mut jacobian);
    let mut nu = q.clone();
    mechanism.nu(q, t, &mut nu);
    let rates = &jacobian * qd;
    let scale = jacobian.amax() * qd.amax().max(1.0);
    let velocity = (0..q.len())
        .filter(own)
        .map(|i| (rates[i] - nu[i]).abs())
        .fold(0.0, f64::max)
        / scale;

    let free = free_coordinates
        .iter()
        .enumerate()
        .map(|(k, &c)| {
            let [u, rate, _] = integrator.free_state(k);
            (q[c] - u).abs().max((qd[c] - rate).abs())
        })
        .fold(0.0, f64::max);
    [position, velocity, free]
}

/// Asserts [`constraint_residuals`] within the solver's acceptance tolerance (positions, in
/// scene lengths), round-off (velocities) and exactly-held frees (to round-off).
pub fn assert_constrained<M>(integrator: &Integrator<M>, free_coordinates: &[usize])
where
    M: Dynamic + EquationsOfMotion + Structured,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    let [position, velocity, free] = constraint_residuals(integrator, free_coordinates);
    let t = integrator.t();
    assert!(position <= 1e-8, "t = {t}: position residual {position:e}");
    assert!(velocity <= 1e-12, "t = {t}: velocity residual {velocity:e}");
    assert!(
        free <= 1e-9,
        "t = {t}: free coordinate off its state by {free:e}"
    );
}

/// Largest `|a_i − b_i|` of two equally long slices.
pub fn worst(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}
