//! A hand-written pendulum with a free degree of freedom: one body whose centre of mass (its
//! reference point) hangs at distance `length` from a pin at the origin, `x = L cos θ`,
//! `y = L sin θ`, mass `m`, inertia `J` about the centre, gravity `(0, −g)`, and an optional
//! rotational damper `c` (torque `−c θ̇`). The free degree of freedom `swing` holds θ (or, with
//! `free_x`, the coordinate x, whose partition is singular where the rod is horizontal: a
//! toggle for the free motion).
//!
//! Its one-coordinate Lagrange equation, the tests' reference: `(J + m L²) θ̈ = −m g L cos θ − c θ̇`.

use mechgen_runtime::codegen::math::{cos, sin};
use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{
    Accelerations, Dynamic, EnergyTerms, EquationsOfMotion, Forces, Matrix, Mechanism, Names,
    Outputs, Unit, Vector, Velocities,
};

type Q = Vector<Const<3>>;

#[derive(Debug, Clone)]
pub struct FreePendulum {
    pub length: f64,
    pub mass: f64,
    pub inertia: f64,
    pub gravity: f64,
    pub damping: f64,
    /// The free degree of freedom holds x instead of θ.
    pub free_x: bool,
    /// The declared initial value (`None`: the value at the guess) and rate.
    pub initial: (Option<f64>, f64),
    /// The guess's angle.
    pub guess: f64,
    /// `[u, u̇, ü]`, set by the integrator.
    pub free: [f64; 3],
    /// From this time on the forces are NaN (a load whose expression fails).
    pub nan_after: f64,
}

impl FreePendulum {
    /// Released at angle `theta0` (θ from the x axis, −π/2 hanging) with rate `rate`.
    pub fn released(theta0: f64, rate: f64) -> Self {
        Self {
            length: 1.5,
            mass: 2.0,
            inertia: 0.1,
            gravity: 9.81,
            damping: 0.0,
            free_x: false,
            initial: (Some(theta0), rate),
            guess: theta0,
            free: [0.0; 3],
            nan_after: f64::INFINITY,
        }
    }

    /// The moment of inertia about the pin.
    pub fn pin_inertia(&self) -> f64 {
        self.inertia + self.mass * self.length * self.length
    }

    /// θ̈ of the reference equation.
    pub fn theta_ddot(&self, theta: f64, theta_dot: f64) -> f64 {
        (-self.mass * self.gravity * self.length * cos(theta) - self.damping * theta_dot)
            / self.pin_inertia()
    }

    /// Small-amplitude angular frequency about the hanging position.
    pub fn omega(&self) -> f64 {
        (self.mass * self.gravity * self.length / self.pin_inertia()).sqrt()
    }
}

const COORDINATES: [&str; 3] = ["bob.x", "bob.y", "bob.theta"];
const EQUATIONS: [&str; 3] = ["pin.x", "pin.y", "swing"];

pub const NAMES: Names = Names {
    mechanism: "FreePendulum",
    coordinates: &COORDINATES,
    equations: &EQUATIONS,
    ..Names::NONE
};

impl Mechanism for FreePendulum {
    type Dim = Const<3>;
    type Markers = [f64; 0];

    fn names(&self) -> &'static Names {
        &NAMES
    }
    fn dim(&self) -> Const<3> {
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
        if index < 2 { Unit::Length } else { Unit::Angle }
    }
    fn equation_unit(&self, index: usize) -> Unit {
        if index < 2 || self.free_x {
            Unit::Length
        } else {
            Unit::Angle
        }
    }
    fn length_scale(&self) -> f64 {
        self.length
    }
    fn initial_guess(&self, q: &mut Q) {
        let (l, th) = (self.length, self.guess);
        *q = Q::from([l * cos(th) * 1.01, l * sin(th) * 0.99, th]);
    }
    fn phi(&self, q: &Q, _: f64, out: &mut Q) {
        let (l, th) = (self.length, q.z);
        let held = if self.free_x { q.x } else { th };
        *out = Q::from([q.x - l * cos(th), q.y - l * sin(th), held - self.free[0]]);
    }
    fn jacobian(&self, q: &Q, _: f64, out: &mut Matrix<Const<3>>) {
        let (l, th) = (self.length, q.z);
        let held = if self.free_x {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 0.0, 1.0]
        };
        *out = Matrix::<Const<3>>::from_row_slice(&[
            1.0,
            0.0,
            l * sin(th),
            0.0,
            1.0,
            -l * cos(th),
            held[0],
            held[1],
            held[2],
        ]);
    }
    fn outputs(&self) -> Outputs {
        Outputs::Forces
    }
    fn nu(&self, _: &Q, _: f64, out: &mut Q) {
        *out = Q::from([0.0, 0.0, self.free[1]]);
    }
    fn gamma(&self, q: &Q, qd: &Q, _: f64, out: &mut Q) {
        let (l, th, w) = (self.length, q.z, qd.z);
        *out = Q::from([-l * cos(th) * w * w, -l * sin(th) * w * w, self.free[2]]);
    }
    fn generalized_forces(&self, _: &Q, qd: &Q, qdd: &Q, t: f64, out: &mut Q) {
        let (m, j) = (self.mass, self.inertia);
        let g = if t < self.nan_after {
            self.gravity
        } else {
            f64::NAN
        };
        *out = Q::from([
            -m * qdd.x,
            -m * g - m * qdd.y,
            -self.damping * qd.z - j * qdd.z,
        ]);
    }
    /// The multipliers as they are: the pin's rows carry the force the pin exerts on the bob
    /// (`Φ_qᵀ λ = F`), the free row its effort.
    fn reactions(&self, _: &Q, _: &Q, lambda: &[f64], out: &mut Q) {
        for (o, l) in out.iter_mut().zip(lambda) {
            *o = *l;
        }
    }
    fn reaction_name(&self, index: usize) -> Option<&str> {
        ["pin.fx", "pin.fy", "swing.effort"].get(index).copied()
    }
}

impl Velocities for FreePendulum {}
impl Accelerations for FreePendulum {}
impl Forces for FreePendulum {}

impl EquationsOfMotion for FreePendulum {
    fn mass_times(&self, _: &Q, v: &Q, out: &mut Q) {
        *out = Q::from([self.mass * v.x, self.mass * v.y, self.inertia * v.z]);
    }
    fn damping_times(&self, _: &Q, _: &Q, _: f64, v: &Q, out: &mut Q) -> bool {
        *out = Q::from([0.0, 0.0, self.damping * v.z]);
        self.damping != 0.0
    }
    fn energy_terms(&self, q: &Q, qd: &Q, _: f64) -> EnergyTerms {
        EnergyTerms {
            gravity: self.mass * self.gravity * q.y,
            springs: 0.0,
            loads: 0.0,
            dampers: self.damping * qd.z * qd.z,
        }
    }
}

impl Dynamic for FreePendulum {
    type Free = Const<1>;

    fn free(&self) -> Const<1> {
        Const
    }
    fn free_name(&self, k: usize) -> Option<&str> {
        (k == 0).then_some("swing")
    }
    fn free_equation(&self, k: usize) -> usize {
        if k == 0 { 2 } else { usize::MAX }
    }
    fn free_initial(&self, _: usize) -> (Option<f64>, f64) {
        self.initial
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

/// The same pendulum behind `Dyn` dimensions (coordinates and free degrees of freedom), as
/// the interpreter presents a scene.
#[cfg(feature = "alloc")]
pub struct DynFreePendulum(pub FreePendulum);

#[cfg(feature = "alloc")]
mod dynamic {
    use super::{
        Accelerations, DynFreePendulum, Dynamic, EnergyTerms, EquationsOfMotion, Forces, Mechanism,
        Names, Outputs, Q, Unit, Vector, Velocities,
    };
    use mechgen_runtime::Matrix;
    use mechgen_runtime::nalgebra::{Dyn, Matrix3};

    fn fixed(v: &Vector<Dyn>) -> Q {
        Q::from_iterator(v.iter().copied())
    }

    /// Runs `f` on the fixed-size pendulum and copies its vector result into `out`.
    fn into(out: &mut Vector<Dyn>, f: impl FnOnce(&mut Q)) {
        let mut result = Q::zeros();
        f(&mut result);
        out.copy_from_slice(result.as_slice());
    }

    impl Mechanism for DynFreePendulum {
        type Dim = Dyn;
        type Markers = [f64; 0];

        fn names(&self) -> &'static Names {
            self.0.names()
        }
        fn dim(&self) -> Dyn {
            Dyn(3)
        }
        no_parameters_or_markers!();
        fn coordinate_name(&self, index: usize) -> Option<&str> {
            self.0.coordinate_name(index)
        }
        fn equation_name(&self, index: usize) -> Option<&str> {
            self.0.equation_name(index)
        }
        fn coordinate_unit(&self, index: usize) -> Unit {
            self.0.coordinate_unit(index)
        }
        fn equation_unit(&self, index: usize) -> Unit {
            self.0.equation_unit(index)
        }
        fn length_scale(&self) -> f64 {
            self.0.length_scale()
        }
        fn initial_guess(&self, q: &mut Vector<Dyn>) {
            into(q, |out| self.0.initial_guess(out));
        }
        fn phi(&self, q: &Vector<Dyn>, t: f64, out: &mut Vector<Dyn>) {
            into(out, |out| self.0.phi(&fixed(q), t, out));
        }
        fn jacobian(&self, q: &Vector<Dyn>, t: f64, out: &mut Matrix<Dyn>) {
            let mut jacobian = Matrix3::zeros();
            self.0.jacobian(&fixed(q), t, &mut jacobian);
            out.copy_from(&jacobian);
        }
        fn outputs(&self) -> Outputs {
            Outputs::Forces
        }
        fn nu(&self, q: &Vector<Dyn>, t: f64, out: &mut Vector<Dyn>) {
            into(out, |out| self.0.nu(&fixed(q), t, out));
        }
        fn gamma(&self, q: &Vector<Dyn>, qd: &Vector<Dyn>, t: f64, out: &mut Vector<Dyn>) {
            into(out, |out| self.0.gamma(&fixed(q), &fixed(qd), t, out));
        }
        fn generalized_forces(
            &self,
            q: &Vector<Dyn>,
            qd: &Vector<Dyn>,
            qdd: &Vector<Dyn>,
            t: f64,
            out: &mut Vector<Dyn>,
        ) {
            into(out, |out| {
                self.0
                    .generalized_forces(&fixed(q), &fixed(qd), &fixed(qdd), t, out)
            });
        }
        fn reactions(
            &self,
            q: &Vector<Dyn>,
            qd: &Vector<Dyn>,
            lambda: &[f64],
            out: &mut Vector<Dyn>,
        ) {
            into(out, |out| {
                self.0.reactions(&fixed(q), &fixed(qd), lambda, out)
            });
        }
    }

    impl Velocities for DynFreePendulum {}
    impl Accelerations for DynFreePendulum {}
    impl Forces for DynFreePendulum {}

    impl EquationsOfMotion for DynFreePendulum {
        fn mass_times(&self, q: &Vector<Dyn>, v: &Vector<Dyn>, out: &mut Vector<Dyn>) {
            into(out, |out| self.0.mass_times(&fixed(q), &fixed(v), out));
        }
        fn damping_times(
            &self,
            q: &Vector<Dyn>,
            qd: &Vector<Dyn>,
            t: f64,
            v: &Vector<Dyn>,
            out: &mut Vector<Dyn>,
        ) -> bool {
            let mut has = false;
            into(out, |out| {
                has = self
                    .0
                    .damping_times(&fixed(q), &fixed(qd), t, &fixed(v), out);
            });
            has
        }
        fn energy_terms(&self, q: &Vector<Dyn>, qd: &Vector<Dyn>, t: f64) -> EnergyTerms {
            self.0.energy_terms(&fixed(q), &fixed(qd), t)
        }
    }

    impl Dynamic for DynFreePendulum {
        type Free = Dyn;

        fn free(&self) -> Dyn {
            Dyn(1)
        }
        fn free_name(&self, k: usize) -> Option<&str> {
            self.0.free_name(k)
        }
        fn free_equation(&self, k: usize) -> usize {
            self.0.free_equation(k)
        }
        fn free_initial(&self, k: usize) -> (Option<f64>, f64) {
            self.0.free_initial(k)
        }
        fn free_state(&self, k: usize) -> [f64; 3] {
            self.0.free_state(k)
        }
        fn set_free(&mut self, k: usize, state: [f64; 3]) {
            self.0.set_free(k, state);
        }
    }
}
