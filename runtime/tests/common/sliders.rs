//! Two hand-written sliders on one guide along x, each a free degree of freedom (its x):
//! `a` tied to the frame at x = 0 by a spring `k1` (free length 0), `b` tied to `a` by a
//! spring `k2` of free length `gap` with a damper `c2`. Linear: the tests' reference is its
//! modal solution. With `k2` huge it is the stiff case: a fast mode far above 1/h.

use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{
    Accelerations, Dynamic, EnergyTerms, EquationsOfMotion, Forces, Matrix, Mechanism, Names,
    Outputs, Unit, Vector, Velocities,
};

type Q = Vector<Const<6>>;

#[derive(Debug, Clone)]
pub struct Sliders {
    pub masses: [f64; 2],
    pub k1: f64,
    pub k2: f64,
    pub c2: f64,
    pub gap: f64,
    /// Declared initial `(x, ẋ)` of each slider.
    pub initial: [(f64, f64); 2],
    /// `[u, u̇, ü]` of each, set by the integrator.
    pub free: [[f64; 3]; 2],
}

/// q: a.x, a.y, a.θ, b.x, b.y, b.θ.
const COORDINATES: [&str; 6] = ["a.x", "a.y", "a.theta", "b.x", "b.y", "b.theta"];
/// Φ: the guide holds y and θ of each, then the free degrees of freedom.
const EQUATIONS: [&str; 6] = [
    "guide_a.y",
    "guide_a.theta",
    "guide_b.y",
    "guide_b.theta",
    "push_a",
    "push_b",
];
const INERTIA: f64 = 0.01;

pub const NAMES: Names = Names {
    mechanism: "Sliders",
    coordinates: &COORDINATES,
    equations: &EQUATIONS,
    ..Names::NONE
};

impl Sliders {
    /// The extension of the spring between the sliders.
    fn stretch(&self, q: &Q) -> f64 {
        q[3] - q[0] - self.gap
    }
}

impl Mechanism for Sliders {
    type Dim = Const<6>;
    type Markers = [f64; 0];

    fn names(&self) -> &'static Names {
        &NAMES
    }
    fn dim(&self) -> Const<6> {
        Const
    }
    no_parameters_or_markers!();
    fn coordinate_name(&self, index: usize) -> Option<&str> {
        COORDINATES.get(index).copied()
    }
    fn equation_name(&self, index: usize) -> Option<&str> {
        EQUATIONS.get(index).copied()
    }
    fn coordinate_unit(&self, index: usize) -> Unit {
        if index % 3 == 2 {
            Unit::Angle
        } else {
            Unit::Length
        }
    }
    fn equation_unit(&self, index: usize) -> Unit {
        if index == 1 || index == 3 {
            Unit::Angle
        } else {
            Unit::Length
        }
    }
    fn length_scale(&self) -> f64 {
        self.gap
    }
    fn initial_guess(&self, q: &mut Q) {
        *q = Q::from([0.1, 0.0, 0.0, self.gap, 0.0, 0.0]);
    }
    fn phi(&self, q: &Q, _: f64, out: &mut Q) {
        *out = Q::from([
            q[1],
            q[2],
            q[4],
            q[5],
            q[0] - self.free[0][0],
            q[3] - self.free[1][0],
        ]);
    }
    fn jacobian(&self, _: &Q, _: f64, out: &mut Matrix<Const<6>>) {
        out.fill(0.0);
        for (row, column) in [1, 2, 4, 5, 0, 3].into_iter().enumerate() {
            out[(row, column)] = 1.0;
        }
    }
    fn outputs(&self) -> Outputs {
        Outputs::Forces
    }
    fn nu(&self, _: &Q, _: f64, out: &mut Q) {
        *out = Q::from([0.0, 0.0, 0.0, 0.0, self.free[0][1], self.free[1][1]]);
    }
    fn gamma(&self, _: &Q, _: &Q, _: f64, out: &mut Q) {
        *out = Q::from([0.0, 0.0, 0.0, 0.0, self.free[0][2], self.free[1][2]]);
    }
    fn generalized_forces(&self, q: &Q, qd: &Q, qdd: &Q, _: f64, out: &mut Q) {
        let [ma, mb] = self.masses;
        let pull = self.k2 * self.stretch(q) + self.c2 * (qd[3] - qd[0]);
        *out = Q::from([
            -self.k1 * q[0] + pull - ma * qdd[0],
            -ma * qdd[1],
            -INERTIA * qdd[2],
            -pull - mb * qdd[3],
            -mb * qdd[4],
            -INERTIA * qdd[5],
        ]);
    }
    fn reactions(&self, _: &Q, _: &Q, lambda: &[f64], out: &mut Q) {
        for (o, l) in out.iter_mut().zip(lambda) {
            *o = *l;
        }
    }
    fn reaction_name(&self, index: usize) -> Option<&str> {
        [
            "guide_a.f",
            "guide_a.m",
            "guide_b.f",
            "guide_b.m",
            "push_a.effort",
            "push_b.effort",
        ]
        .get(index)
        .copied()
    }
}

impl Velocities for Sliders {}
impl Accelerations for Sliders {}
impl Forces for Sliders {}

impl EquationsOfMotion for Sliders {
    fn mass_times(&self, _: &Q, v: &Q, out: &mut Q) {
        let [ma, mb] = self.masses;
        *out = Q::from([
            ma * v[0],
            ma * v[1],
            INERTIA * v[2],
            mb * v[3],
            mb * v[4],
            INERTIA * v[5],
        ]);
    }
    fn stiffness_times(&self, _: &Q, _: &Q, _: f64, v: &Q, out: &mut Q) -> bool {
        let (k1, k2) = (self.k1, self.k2);
        let stretch = v[3] - v[0];
        *out = Q::from([k1 * v[0] - k2 * stretch, 0.0, 0.0, k2 * stretch, 0.0, 0.0]);
        true
    }
    fn damping_times(&self, _: &Q, _: &Q, _: f64, v: &Q, out: &mut Q) -> bool {
        let rate = self.c2 * (v[3] - v[0]);
        *out = Q::from([-rate, 0.0, 0.0, rate, 0.0, 0.0]);
        self.c2 != 0.0
    }
    fn energy_terms(&self, q: &Q, qd: &Q, _: f64) -> EnergyTerms {
        let stretch = self.stretch(q);
        let rate = qd[3] - qd[0];
        EnergyTerms {
            gravity: 0.0,
            springs: 0.5 * self.k1 * q[0] * q[0] + 0.5 * self.k2 * stretch * stretch,
            loads: 0.0,
            dampers: self.c2 * rate * rate,
        }
    }
}

impl Dynamic for Sliders {
    type Free = Const<2>;

    fn free(&self) -> Const<2> {
        Const
    }
    fn free_name(&self, k: usize) -> Option<&str> {
        ["push_a", "push_b"].get(k).copied()
    }
    fn free_equation(&self, k: usize) -> usize {
        if k < 2 { 4 + k } else { usize::MAX }
    }
    fn free_initial(&self, k: usize) -> (Option<f64>, f64) {
        let (x, v) = self.initial.get(k).copied().unwrap_or((f64::NAN, f64::NAN));
        (Some(x), v)
    }
    fn free_state(&self, k: usize) -> [f64; 3] {
        self.free.get(k).copied().unwrap_or([f64::NAN; 3])
    }
    fn set_free(&mut self, k: usize, state: [f64; 3]) {
        if let Some(free) = self.free.get_mut(k) {
            *free = state;
        }
    }
}
