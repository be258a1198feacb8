//! A hand-written double pendulum with both absolute angles free (`upper`, `lower`): link 1
//! pinned at the origin, its centre of mass at `c1` from the pin, link 2 pinned at its far end
//! (`l1` from the origin pin), its centre at `c2` from that pin. Two free degrees of freedom
//! whose `V = ∂q/∂u` columns both move link 2, so the reduced mass is full.
//!
//! Its reduced-coordinate Lagrange equations (absolute angles θ1, θ2, Δ = θ1 − θ2,
//! k = m2 l1 c2): `M [θ̈1, θ̈2] = [−k sin Δ θ̇2² − (m1 c1 + m2 l1) g cos θ1,
//! k sin Δ θ̇1² − m2 g c2 cos θ2]`, `M = [[J1 + m1 c1² + m2 l1², k cos Δ], [k cos Δ, J2 + m2 c2²]]`.

use mechgen_runtime::codegen::math::{cos, sin};
use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{
    Accelerations, Dynamic, EnergyTerms, EquationsOfMotion, Forces, Matrix, Mechanism, Names,
    Outputs, Unit, Vector, Velocities,
};

type Q = Vector<Const<6>>;

#[derive(Debug, Clone)]
pub struct DoublePendulum {
    pub l1: f64,
    pub c1: f64,
    pub c2: f64,
    /// `(m, J)` of each link.
    pub links: [(f64, f64); 2],
    pub gravity: f64,
    pub theta0: [f64; 2],
    pub free: [[f64; 3]; 2],
}

impl Default for DoublePendulum {
    fn default() -> Self {
        Self {
            l1: 1.0,
            c1: 0.5,
            c2: 0.4,
            links: [(2.0, 0.17), (1.0, 0.06)],
            gravity: 9.81,
            theta0: [-1.0, -0.6],
            free: [[0.0; 3]; 2],
        }
    }
}

impl DoublePendulum {
    /// `[θ̈1, θ̈2]` of the reference equations.
    pub fn accelerations(&self, theta: [f64; 2], rate: [f64; 2]) -> [f64; 2] {
        let [(m1, j1), (m2, j2)] = self.links;
        let (l1, c1, c2, g) = (self.l1, self.c1, self.c2, self.gravity);
        let d = theta[0] - theta[1];
        let k = m2 * l1 * c2;
        let m = [
            [j1 + m1 * c1 * c1 + m2 * l1 * l1, k * cos(d)],
            [k * cos(d), j2 + m2 * c2 * c2],
        ];
        let r = [
            -k * sin(d) * rate[1] * rate[1] - (m1 * c1 + m2 * l1) * g * cos(theta[0]),
            k * sin(d) * rate[0] * rate[0] - m2 * g * c2 * cos(theta[1]),
        ];
        let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        [
            (r[0] * m[1][1] - m[0][1] * r[1]) / det,
            (m[0][0] * r[1] - m[1][0] * r[0]) / det,
        ]
    }
}

const COORDINATES: [&str; 6] = [
    "upper_link.x",
    "upper_link.y",
    "upper_link.theta",
    "lower_link.x",
    "lower_link.y",
    "lower_link.theta",
];
const EQUATIONS: [&str; 6] = ["top.x", "top.y", "elbow.x", "elbow.y", "upper", "lower"];

pub const NAMES: Names = Names {
    mechanism: "DoublePendulum",
    coordinates: &COORDINATES,
    equations: &EQUATIONS,
    ..Names::NONE
};

impl Mechanism for DoublePendulum {
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
        if index >= 4 {
            Unit::Angle
        } else {
            Unit::Length
        }
    }
    fn length_scale(&self) -> f64 {
        self.l1
    }
    fn initial_guess(&self, q: &mut Q) {
        let [a, b] = self.theta0;
        let (l1, c1, c2) = (self.l1, self.c1, self.c2);
        *q = Q::from([
            c1 * cos(a),
            c1 * sin(a),
            a,
            l1 * cos(a) + c2 * cos(b),
            l1 * sin(a) + c2 * sin(b),
            b,
        ]);
    }
    fn phi(&self, q: &Q, _: f64, out: &mut Q) {
        let (l1, c1, c2) = (self.l1, self.c1, self.c2);
        let (a, b) = (q[2], q[5]);
        let rest = l1 - c1;
        *out = Q::from([
            q[0] - c1 * cos(a),
            q[1] - c1 * sin(a),
            q[3] - q[0] - rest * cos(a) - c2 * cos(b),
            q[4] - q[1] - rest * sin(a) - c2 * sin(b),
            a - self.free[0][0],
            b - self.free[1][0],
        ]);
    }
    fn jacobian(&self, q: &Q, _: f64, out: &mut Matrix<Const<6>>) {
        let (l1, c1, c2) = (self.l1, self.c1, self.c2);
        let (a, b) = (q[2], q[5]);
        let rest = l1 - c1;
        out.fill(0.0);
        out[(0, 0)] = 1.0;
        out[(0, 2)] = c1 * sin(a);
        out[(1, 1)] = 1.0;
        out[(1, 2)] = -c1 * cos(a);
        out[(2, 0)] = -1.0;
        out[(2, 2)] = rest * sin(a);
        out[(2, 3)] = 1.0;
        out[(2, 5)] = c2 * sin(b);
        out[(3, 1)] = -1.0;
        out[(3, 2)] = -rest * cos(a);
        out[(3, 4)] = 1.0;
        out[(3, 5)] = -c2 * cos(b);
        out[(4, 2)] = 1.0;
        out[(5, 5)] = 1.0;
    }
    fn outputs(&self) -> Outputs {
        Outputs::Forces
    }
    fn nu(&self, _: &Q, _: f64, out: &mut Q) {
        *out = Q::from([0.0, 0.0, 0.0, 0.0, self.free[0][1], self.free[1][1]]);
    }
    fn gamma(&self, q: &Q, qd: &Q, _: f64, out: &mut Q) {
        let (l1, c1, c2) = (self.l1, self.c1, self.c2);
        let (a, b, wa, wb) = (q[2], q[5], qd[2], qd[5]);
        let rest = l1 - c1;
        let (wa2, wb2) = (wa * wa, wb * wb);
        *out = Q::from([
            -c1 * cos(a) * wa2,
            -c1 * sin(a) * wa2,
            -rest * cos(a) * wa2 - c2 * cos(b) * wb2,
            -rest * sin(a) * wa2 - c2 * sin(b) * wb2,
            self.free[0][2],
            self.free[1][2],
        ]);
    }
    fn generalized_forces(&self, _: &Q, _: &Q, qdd: &Q, _: f64, out: &mut Q) {
        let ([(m1, j1), (m2, j2)], g) = (self.links, self.gravity);
        *out = Q::from([
            -m1 * qdd[0],
            -m1 * g - m1 * qdd[1],
            -j1 * qdd[2],
            -m2 * qdd[3],
            -m2 * g - m2 * qdd[4],
            -j2 * qdd[5],
        ]);
    }
    fn reactions(&self, _: &Q, _: &Q, lambda: &[f64], out: &mut Q) {
        for (o, l) in out.iter_mut().zip(lambda) {
            *o = *l;
        }
    }
    fn reaction_name(&self, index: usize) -> Option<&str> {
        [
            "top.fx",
            "top.fy",
            "elbow.fx",
            "elbow.fy",
            "upper.effort",
            "lower.effort",
        ]
        .get(index)
        .copied()
    }
}

impl Velocities for DoublePendulum {}
impl Accelerations for DoublePendulum {}
impl Forces for DoublePendulum {}

impl EquationsOfMotion for DoublePendulum {
    fn mass_times(&self, _: &Q, v: &Q, out: &mut Q) {
        let [(m1, j1), (m2, j2)] = self.links;
        *out = Q::from([
            m1 * v[0],
            m1 * v[1],
            j1 * v[2],
            m2 * v[3],
            m2 * v[4],
            j2 * v[5],
        ]);
    }
    fn energy_terms(&self, q: &Q, _: &Q, _: f64) -> EnergyTerms {
        let [(m1, _), (m2, _)] = self.links;
        EnergyTerms {
            gravity: self.gravity * (m1 * q[1] + m2 * q[4]),
            ..EnergyTerms::default()
        }
    }
}

impl Dynamic for DoublePendulum {
    type Free = Const<2>;

    fn free(&self) -> Const<2> {
        Const
    }
    fn free_name(&self, k: usize) -> Option<&str> {
        ["upper", "lower"].get(k).copied()
    }
    fn free_equation(&self, k: usize) -> usize {
        if k < 2 { 4 + k } else { usize::MAX }
    }
    fn free_initial(&self, k: usize) -> (Option<f64>, f64) {
        (self.theta0.get(k).copied(), 0.0)
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
