//! The integrator on a hand-written scene with a free degree of freedom (until `mechanism!`
//! emits `free`): a slider on a spring, its position free, every coordinate assigned in closed
//! form. It proves the integrator's generic code (the reduced equations, the iteration matrix
//! over `Const` dimensions, the energy book) links without std or alloc.

use mechgen_runtime::codegen::{Buffers, Stage};
use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{
    Accelerations, Dynamic, EnergyTerms, EquationsOfMotion, Forces, Integrator, IntegratorOptions,
    Matrix, Mechanism, Outputs, ParameterError, Solver, Structured, Unit, Vector, Velocities,
};

type Q = Vector<Const<3>>;

/// A slider of mass 2 on a spring of stiffness 50 (free length 0) along x, with a damper.
#[derive(Default)]
struct Slider {
    free: [f64; 3],
}

const MASS: f64 = 2.0;
const STIFFNESS: f64 = 50.0;
const DAMPING: f64 = 0.3;

impl Mechanism for Slider {
    type Dim = Const<3>;
    type Markers = [f64; 0];

    fn dim(&self) -> Const<3> {
        Const
    }
    fn marker_storage(&self) -> [f64; 0] {
        []
    }
    fn coordinate_name(&self, index: usize) -> Option<&str> {
        ["slider.x", "slider.y", "slider.theta"].get(index).copied()
    }
    fn equation_name(&self, index: usize) -> Option<&str> {
        ["guide.y", "guide.theta", "push"].get(index).copied()
    }
    fn parameter_count(&self) -> usize {
        0
    }
    fn parameter_name(&self, _: usize) -> Option<&str> {
        None
    }
    fn parameter(&self, _: usize) -> Option<f64> {
        None
    }
    fn set_parameter<'a>(&'a mut self, name: &'a str, _: f64) -> Result<(), ParameterError<'a>> {
        Err(ParameterError::Unknown {
            name,
            declared: &[] as &[&str; 0],
        })
    }
    fn coordinate_unit(&self, index: usize) -> Unit {
        if index == 2 {
            Unit::Angle
        } else {
            Unit::Length
        }
    }
    fn equation_unit(&self, index: usize) -> Unit {
        if index == 1 {
            Unit::Angle
        } else {
            Unit::Length
        }
    }
    fn length_scale(&self) -> f64 {
        1.0
    }
    fn initial_guess(&self, q: &mut Q) {
        *q = Q::from([0.5, 0.0, 0.0]);
    }
    fn phi(&self, q: &Q, _: f64, out: &mut Q) {
        *out = Q::from([q[1], q[2], q[0] - self.free[0]]);
    }
    fn jacobian(&self, _: &Q, _: f64, out: &mut Matrix<Const<3>>) {
        *out = Matrix::<Const<3>>::from_row_slice(&[0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0]);
    }
    fn outputs(&self) -> Outputs {
        Outputs::Forces
    }
    fn nu(&self, _: &Q, _: f64, out: &mut Q) {
        *out = Q::from([0.0, 0.0, self.free[1]]);
    }
    fn gamma(&self, _: &Q, _: &Q, _: f64, out: &mut Q) {
        *out = Q::from([0.0, 0.0, self.free[2]]);
    }
    fn generalized_forces(&self, q: &Q, qd: &Q, qdd: &Q, _: f64, out: &mut Q) {
        let spring = -STIFFNESS * q[0] - DAMPING * qd[0];
        *out = Q::from([spring - MASS * qdd[0], -MASS * qdd[1], -qdd[2]]);
    }
    fn reactions(&self, _: &Q, _: &Q, lambda: &[f64], out: &mut Q) {
        for (o, l) in out.iter_mut().zip(lambda) {
            *o = *l;
        }
    }
}

impl Velocities for Slider {}
impl Accelerations for Slider {}
impl Forces for Slider {}

/// One explicit stage: y and θ held at 0, x at the free state.
impl Structured for Slider {
    type Workspace = Buffers<1, 1, 1, 3, 0, 3>;

    fn workspace(&self) -> Self::Workspace {
        Buffers::new()
    }
    fn stage_count(&self) -> usize {
        1
    }
    fn stage(&self, index: usize) -> Option<Stage<'_>> {
        (index == 0).then_some(Stage::Explicit {
            equations: &[0, 1, 2],
            coordinates: &[1, 2, 0],
            reads: &[],
        })
    }
    fn assign_positions(&self, _: usize, q: &mut Q, _: &[f64], _: f64) {
        *q = Q::from([self.free[0], 0.0, 0.0]);
    }
    fn assign_velocities(&self, _: usize, _: &Q, _: &[f64], qd: &mut Q, _: f64) {
        *qd = Q::from([self.free[1], 0.0, 0.0]);
    }
    fn assign_accelerations(&self, _: usize, _: &Q, _: &[f64], _: &Q, qdd: &mut Q, _: f64) {
        *qdd = Q::from([self.free[2], 0.0, 0.0]);
    }
    fn block_jacobian(&self, _: usize, _: &Q, _: &[f64], _: f64, _: &mut [f64], _: &mut [f64]) {}
    fn assign_multipliers(
        &self,
        _: usize,
        q: &Q,
        _: &[f64],
        qd: &Q,
        qdd: &Q,
        lambda: &mut [f64],
        t: f64,
    ) {
        // Each equation's coefficient on its coordinate is 1: λ_e = F_c.
        let mut forces = Q::zeros();
        self.generalized_forces(q, qd, qdd, t, &mut forces);
        for (l, c) in lambda.iter_mut().zip([1, 2, 0]) {
            *l = forces[c];
        }
    }
}

impl EquationsOfMotion for Slider {
    fn mass_times(&self, _: &Q, v: &Q, out: &mut Q) {
        *out = Q::from([MASS * v[0], MASS * v[1], v[2]]);
    }
    fn stiffness_times(&self, _: &Q, _: &Q, _: f64, v: &Q, out: &mut Q) -> bool {
        *out = Q::from([STIFFNESS * v[0], 0.0, 0.0]);
        true
    }
    fn damping_times(&self, _: &Q, _: &Q, _: f64, v: &Q, out: &mut Q) -> bool {
        *out = Q::from([DAMPING * v[0], 0.0, 0.0]);
        true
    }
    fn energy_terms(&self, q: &Q, qd: &Q, _: f64) -> EnergyTerms {
        EnergyTerms {
            springs: 0.5 * STIFFNESS * q[0] * q[0],
            dampers: DAMPING * qd[0] * qd[0],
            ..EnergyTerms::default()
        }
    }
}

impl Dynamic for Slider {
    type Free = Const<1>;

    fn free(&self) -> Const<1> {
        Const
    }
    fn free_name(&self, k: usize) -> Option<&str> {
        (k == 0).then_some("push")
    }
    fn free_equation(&self, k: usize) -> usize {
        if k == 0 { 2 } else { usize::MAX }
    }
    fn free_initial(&self, _: usize) -> (Option<f64>, f64) {
        (Some(0.5), 0.0)
    }
    fn free_state(&self, k: usize) -> [f64; 3] {
        if k == 0 { self.free } else { [f64::NAN; 3] }
    }
    fn set_free(&mut self, k: usize, state: [f64; 3]) {
        if k == 0 {
            self.free = state;
        }
    }
}

/// Integrates the damped slider to `t_end` (error-controlled) and returns its energy balance
/// `total()` (NaN on failure).
pub extern "C" fn mechgen_nostd_integrate(t_end: f64) -> f64 {
    let solver = Solver::new(Slider::default());
    let Ok(mut integrator) = Integrator::new(solver, 0.0, IntegratorOptions::default()) else {
        return f64::NAN;
    };
    let mut total = f64::NAN;
    match integrator.run(t_end, |_, energy| total = energy.total()) {
        Ok(()) => total,
        Err(_) => f64::NAN,
    }
}
