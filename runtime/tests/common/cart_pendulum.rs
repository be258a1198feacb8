//! A hand-written scene that mixes a driver and a free degree of freedom: a cart on a guide
//! along x, driven `x_c = A sin Ω t`, carrying a pendulum pinned at its reference point whose
//! centre of mass (the bob's reference point) is at distance `length`, `x = x_c + L cos θ`,
//! `y = y_c + L sin θ`. The free degree of freedom `swing` holds θ.
//!
//! Its one-coordinate Lagrange equation, the tests' reference:
//! `(J + m L²) θ̈ = m L sin θ ẍ_c − m g L cos θ`; the driver pushes the cart with
//! `f = M_c ẍ_c + m ẍ` (ẍ the bob's), so its power is `f ẋ_c`.

use mechgen_runtime::codegen::math::{cos, sin};
use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{
    Accelerations, Dynamic, EnergyTerms, EquationsOfMotion, Forces, Matrix, Mechanism, Names,
    Outputs, Unit, Vector, Velocities,
};

type Q = Vector<Const<6>>;

#[derive(Debug, Clone)]
pub struct CartPendulum {
    pub length: f64,
    pub bob: (f64, f64),
    pub cart: (f64, f64),
    pub gravity: f64,
    /// Amplitude and angular frequency of the cart's drive.
    pub drive: (f64, f64),
    pub theta0: f64,
    /// `[u, u̇, ü]`, set by the integrator.
    pub free: [f64; 3],
}

impl Default for CartPendulum {
    fn default() -> Self {
        Self {
            length: 0.8,
            bob: (1.5, 0.05),
            cart: (3.0, 0.2),
            gravity: 9.81,
            drive: (0.3, 4.0),
            theta0: -1.2,
            free: [0.0; 3],
        }
    }
}

impl CartPendulum {
    /// The cart's `(x_c, ẋ_c, ẍ_c)` at `t`.
    pub fn cart_motion(&self, t: f64) -> [f64; 3] {
        let (a, w) = self.drive;
        let (s, c) = (sin(w * t), cos(w * t));
        [a * s, a * w * c, -a * w * w * s]
    }

    /// θ̈ of the reference equation at `t`.
    pub fn theta_ddot(&self, t: f64, theta: f64) -> f64 {
        let (m, j) = self.bob;
        let l = self.length;
        let xcdd = self.cart_motion(t)[2];
        (m * l * sin(theta) * xcdd - m * self.gravity * l * cos(theta)) / (j + m * l * l)
    }

    /// The driver's power at `t` on the reference motion.
    pub fn drive_power(&self, t: f64, theta: f64, rate: f64) -> f64 {
        let [_, xcd, xcdd] = self.cart_motion(t);
        let l = self.length;
        let thdd = self.theta_ddot(t, theta);
        let bob_xdd = xcdd - l * (cos(theta) * rate * rate + sin(theta) * thdd);
        (self.cart.0 * xcdd + self.bob.0 * bob_xdd) * xcd
    }
}

const COORDINATES: [&str; 6] = [
    "cart.x",
    "cart.y",
    "cart.theta",
    "bob.x",
    "bob.y",
    "bob.theta",
];
const EQUATIONS: [&str; 6] = ["guide.y", "guide.theta", "shake", "pin.x", "pin.y", "swing"];

pub const NAMES: Names = Names {
    mechanism: "CartPendulum",
    coordinates: &COORDINATES,
    equations: &EQUATIONS,
    ..Names::NONE
};

impl Mechanism for CartPendulum {
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
        if index == 1 || index == 5 {
            Unit::Angle
        } else {
            Unit::Length
        }
    }
    fn length_scale(&self) -> f64 {
        self.length
    }
    fn initial_guess(&self, q: &mut Q) {
        let (l, th) = (self.length, self.theta0);
        *q = Q::from([0.0, 0.0, 0.0, l * cos(th), l * sin(th), th]);
    }
    fn phi(&self, q: &Q, t: f64, out: &mut Q) {
        let (l, th) = (self.length, q[5]);
        let (a, w) = self.drive;
        *out = Q::from([
            q[1],
            q[2],
            q[0] - a * sin(w * t),
            q[3] - q[0] - l * cos(th),
            q[4] - q[1] - l * sin(th),
            th - self.free[0],
        ]);
    }
    fn jacobian(&self, q: &Q, _: f64, out: &mut Matrix<Const<6>>) {
        let (l, th) = (self.length, q[5]);
        out.fill(0.0);
        out[(0, 1)] = 1.0;
        out[(1, 2)] = 1.0;
        out[(2, 0)] = 1.0;
        out[(3, 0)] = -1.0;
        out[(3, 3)] = 1.0;
        out[(3, 5)] = l * sin(th);
        out[(4, 1)] = -1.0;
        out[(4, 4)] = 1.0;
        out[(4, 5)] = -l * cos(th);
        out[(5, 5)] = 1.0;
    }
    fn outputs(&self) -> Outputs {
        Outputs::Forces
    }
    fn nu(&self, _: &Q, t: f64, out: &mut Q) {
        let (a, w) = self.drive;
        *out = Q::from([0.0, 0.0, a * w * cos(w * t), 0.0, 0.0, self.free[1]]);
    }
    fn gamma(&self, q: &Q, qd: &Q, t: f64, out: &mut Q) {
        let (l, th, rate) = (self.length, q[5], qd[5]);
        let (a, w) = self.drive;
        *out = Q::from([
            0.0,
            0.0,
            -a * w * w * sin(w * t),
            -l * cos(th) * rate * rate,
            -l * sin(th) * rate * rate,
            self.free[2],
        ]);
    }
    fn generalized_forces(&self, _: &Q, _: &Q, qdd: &Q, _: f64, out: &mut Q) {
        let ((mc, jc), (m, j), g) = (self.cart, self.bob, self.gravity);
        *out = Q::from([
            -mc * qdd[0],
            -mc * g - mc * qdd[1],
            -jc * qdd[2],
            -m * qdd[3],
            -m * g - m * qdd[4],
            -j * qdd[5],
        ]);
    }
    fn reactions(&self, _: &Q, _: &Q, lambda: &[f64], out: &mut Q) {
        for (o, l) in out.iter_mut().zip(lambda) {
            *o = *l;
        }
    }
    fn reaction_name(&self, index: usize) -> Option<&str> {
        [
            "guide.f",
            "guide.m",
            "shake.effort",
            "pin.fx",
            "pin.fy",
            "swing.effort",
        ]
        .get(index)
        .copied()
    }
}

impl Velocities for CartPendulum {}
impl Accelerations for CartPendulum {}
impl Forces for CartPendulum {}

impl EquationsOfMotion for CartPendulum {
    fn mass_times(&self, _: &Q, v: &Q, out: &mut Q) {
        let ((mc, jc), (m, j)) = (self.cart, self.bob);
        *out = Q::from([
            mc * v[0],
            mc * v[1],
            jc * v[2],
            m * v[3],
            m * v[4],
            j * v[5],
        ]);
    }
    fn energy_terms(&self, q: &Q, _: &Q, _: f64) -> EnergyTerms {
        EnergyTerms {
            gravity: self.gravity * (self.cart.0 * q[1] + self.bob.0 * q[4]),
            ..EnergyTerms::default()
        }
    }
}

impl Dynamic for CartPendulum {
    type Free = Const<1>;

    fn free(&self) -> Const<1> {
        Const
    }
    fn free_name(&self, k: usize) -> Option<&str> {
        (k == 0).then_some("swing")
    }
    fn free_equation(&self, k: usize) -> usize {
        if k == 0 { 5 } else { usize::MAX }
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
