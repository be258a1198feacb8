//! The slider-crank fixture (`slider_crank.rs`) with its crank free instead of driven, and
//! masses: the crank's inertia about its pivot, the rod's mass and inertia at the crank pin
//! (its reference point), the slider's mass, gravity `(0, −g)` and a spring pulling the slider
//! towards `x0`. A free degree of freedom whose `V = ∂q/∂θ` changes with θ (the slider's
//! motion), as in the seed.
//!
//! Its reduced one-coordinate equation, the tests' reference, from the closed-form
//! kinematics: with `J = ∂q/∂θ`, `H = ∂²q/∂θ²` (the fixture's exact `q̇`, `q̈` at unit speed),
//! `q̈ = J θ̈ + H θ̇²` and `Jᵀ (Q − M q̈) = 0`, so `θ̈ = Jᵀ (Q − M H θ̇²) / (Jᵀ M J)`.

use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{
    Accelerations, Dynamic, EnergyTerms, EquationsOfMotion, Forces, Matrix, Mechanism, Outputs,
    Unit, Velocities,
};

use super::slider_crank::{COORDINATES, EQUATIONS, Q, SliderCrank};

#[derive(Debug, Clone)]
pub struct FreeSliderCrank {
    /// r, l (the drive's ω and θ₀ are unused: the crank is free).
    pub r: f64,
    pub l: f64,
    /// `(m, J)` of crank, rod, slider.
    pub bodies: [(f64, f64); 3],
    pub gravity: f64,
    /// Spring stiffness and the slider position where it is relaxed.
    pub spring: (f64, f64),
    pub theta0: f64,
    pub free: [f64; 3],
}

impl Default for FreeSliderCrank {
    fn default() -> Self {
        Self {
            r: 1.0,
            l: 3.0,
            bodies: [(1.0, 0.4), (0.8, 0.3), (1.5, 0.05)],
            gravity: 9.81,
            spring: (20.0, 3.2),
            theta0: 0.3,
            free: [0.0; 3],
        }
    }
}

impl FreeSliderCrank {
    /// The kinematic fixture with the crank at θ turning at unit speed (its exact `q`, `q̇`,
    /// `q̈` are then `q`, `J`, `H`).
    fn kinematics(&self, theta: f64) -> SliderCrank {
        SliderCrank {
            parameters: [self.r, self.l, 1.0, theta],
        }
    }

    /// The masses per coordinate.
    fn masses(&self) -> [f64; 9] {
        let [(m1, j1), (m2, j2), (m3, j3)] = self.bodies;
        [m1, m1, j1, m2, m2, j2, m3, m3, j3]
    }

    /// The applied forces `Q(q, q̇)` (gravity, the spring).
    fn applied(&self, q: &Q) -> [f64; 9] {
        let [(m1, _), (m2, _), (m3, _)] = self.bodies;
        let g = self.gravity;
        let (k, x0) = self.spring;
        [
            0.0,
            -m1 * g,
            0.0,
            0.0,
            -m2 * g,
            0.0,
            -k * (q[6] - x0),
            -m3 * g,
            0.0,
        ]
    }

    /// θ̈ of the reference equation.
    pub fn theta_ddot(&self, theta: f64, rate: f64) -> f64 {
        let [q, j, h] = self.kinematics(theta).exact(0.0);
        let (masses, applied) = (self.masses(), self.applied(&q));
        let (mut numerator, mut denominator) = (0.0, 0.0);
        for i in 0..9 {
            numerator += j[i] * (applied[i] - masses[i] * h[i] * rate * rate);
            denominator += j[i] * masses[i] * j[i];
        }
        numerator / denominator
    }
}

impl Mechanism for FreeSliderCrank {
    type Dim = Const<9>;
    type Markers = [f64; 0];

    no_parameters_or_markers!();
    fn dim(&self) -> Const<9> {
        Const
    }
    fn coordinate_name(&self, index: usize) -> Option<&str> {
        COORDINATES.get(index).copied()
    }
    fn equation_name(&self, index: usize) -> Option<&str> {
        if index == 2 {
            Some("crank_angle")
        } else {
            EQUATIONS.get(index).copied()
        }
    }
    fn coordinate_unit(&self, index: usize) -> Unit {
        self.kinematics(0.0).coordinate_unit(index)
    }
    fn equation_unit(&self, index: usize) -> Unit {
        self.kinematics(0.0).equation_unit(index)
    }
    fn length_scale(&self) -> f64 {
        self.r.max(self.l)
    }
    fn initial_guess(&self, q: &mut Q) {
        *q = self.kinematics(self.theta0).exact(0.0)[0];
    }
    /// The drive's row `θ₁ − θ₀ − ω t` with θ₀ = u and ω = 0.
    fn phi(&self, q: &Q, _: f64, out: &mut Q) {
        self.kinematics(self.free[0]).phi(q, 0.0, out);
    }
    fn jacobian(&self, q: &Q, t: f64, out: &mut Matrix<Const<9>>) {
        self.kinematics(0.0).jacobian(q, t, out);
    }
    fn outputs(&self) -> Outputs {
        Outputs::Forces
    }
    fn nu(&self, _: &Q, _: f64, out: &mut Q) {
        *out = Q::zeros();
        out[2] = self.free[1];
    }
    fn gamma(&self, q: &Q, qd: &Q, t: f64, out: &mut Q) {
        self.kinematics(0.0).gamma(q, qd, t, out);
        out[2] = self.free[2];
    }
    fn generalized_forces(&self, q: &Q, _: &Q, qdd: &Q, _: f64, out: &mut Q) {
        let (masses, applied) = (self.masses(), self.applied(q));
        for i in 0..9 {
            out[i] = applied[i] - masses[i] * qdd[i];
        }
    }
    fn reactions(&self, _: &Q, _: &Q, lambda: &[f64], out: &mut Q) {
        for (o, l) in out.iter_mut().zip(lambda) {
            *o = *l;
        }
    }
}

impl Velocities for FreeSliderCrank {}
impl Accelerations for FreeSliderCrank {}
impl Forces for FreeSliderCrank {}

impl EquationsOfMotion for FreeSliderCrank {
    fn mass_times(&self, _: &Q, v: &Q, out: &mut Q) {
        let masses = self.masses();
        for i in 0..9 {
            out[i] = masses[i] * v[i];
        }
    }
    fn stiffness_times(&self, _: &Q, _: &Q, _: f64, v: &Q, out: &mut Q) -> bool {
        *out = Q::zeros();
        out[6] = self.spring.0 * v[6];
        true
    }
    fn energy_terms(&self, q: &Q, _: &Q, _: f64) -> EnergyTerms {
        let [(m1, _), (m2, _), (m3, _)] = self.bodies;
        let (k, x0) = self.spring;
        EnergyTerms {
            gravity: self.gravity * (m1 * q[1] + m2 * q[4] + m3 * q[7]),
            springs: 0.5 * k * (q[6] - x0) * (q[6] - x0),
            ..EnergyTerms::default()
        }
    }
}

impl Dynamic for FreeSliderCrank {
    type Free = Const<1>;

    fn free(&self) -> Const<1> {
        Const
    }
    fn free_name(&self, k: usize) -> Option<&str> {
        (k == 0).then_some("crank_angle")
    }
    fn free_equation(&self, k: usize) -> usize {
        if k == 0 { 2 } else { usize::MAX }
    }
    fn free_initial(&self, _: usize) -> (Option<f64>, f64) {
        (Some(self.theta0), 0.0)
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
