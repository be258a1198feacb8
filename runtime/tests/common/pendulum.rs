//! A hand-written driven pendulum, the smallest mechanism the tests solve.
//!
//! One body, pinned at the origin at distance `a` from its reference point, its angle driven as
//! `θ = ω t`: `x = a cos θ`, `y = a sin θ`. `duplicate_pin` replaces the driver with a copy of the
//! first pin equation to make Φ_q singular on purpose. With `mass` set it computes forces: a
//! mass `m` with inertia `J` at its reference point, under gravity `(0, −g)`.

use mechgen_runtime::codegen::math::{cos, sin};
use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{
    Accelerations, Forces, Matrix, Mechanism, Names, Outputs, ParameterError, Unit, Vector,
    Velocities,
};

#[derive(Debug, Clone)]
pub struct Pendulum {
    pub a: f64,
    pub omega: f64,
    pub duplicate_pin: bool,
    /// `(m, J, g)`: mass, inertia and gravity, for the force solve.
    pub mass: Option<(f64, f64, f64)>,
}

impl Default for Pendulum {
    fn default() -> Self {
        Self {
            a: 2.0,
            omega: 1.5,
            duplicate_pin: false,
            mass: None,
        }
    }
}

impl Pendulum {
    /// Closed-form `(q, q̇, q̈)` at `t`.
    pub fn exact(&self, t: f64) -> [[f64; 3]; 3] {
        let (a, w) = (self.a, self.omega);
        let (s, c) = (sin(w * t), cos(w * t));
        [
            [a * c, a * s, w * t],
            [-a * w * s, a * w * c, w],
            [-a * w * w * c, -a * w * w * s, 0.0],
        ]
    }
}

const COORDINATES: [&str; 3] = ["rod.x", "rod.y", "rod.theta"];
const EQUATIONS: [&str; 3] = ["pin.x", "pin.y", "drive"];

/// The pendulum's names, as a generated scene's `NAMES`.
pub const NAMES: Names = Names {
    mechanism: "Pendulum",
    coordinates: &COORDINATES,
    equations: &EQUATIONS,
    ..Names::NONE
};

impl Mechanism for Pendulum {
    type Dim = Const<3>;
    type Markers = [f64; 0];

    fn names(&self) -> &'static Names {
        &NAMES
    }
    fn dim(&self) -> Const<3> {
        Const
    }
    fn marker_storage(&self) -> [f64; 0] {
        []
    }
    fn coordinate_name(&self, index: usize) -> Option<&str> {
        COORDINATES.get(index).copied()
    }
    fn equation_name(&self, index: usize) -> Option<&str> {
        EQUATIONS.get(index).copied()
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
        if index < 2 { Unit::Length } else { Unit::Angle }
    }
    fn equation_unit(&self, index: usize) -> Unit {
        if index < 2 || self.duplicate_pin {
            Unit::Length
        } else {
            Unit::Angle
        }
    }
    fn length_scale(&self) -> f64 {
        self.a.abs()
    }
    fn initial_guess(&self, q: &mut Vector<Const<3>>) {
        *q = Vector::from([self.a, 0.1, 0.1]);
    }
    fn phi(&self, q: &Vector<Const<3>>, t: f64, out: &mut Vector<Const<3>>) {
        let (x, y, th) = (q.x, q.y, q.z);
        let pin_x = x - self.a * cos(th);
        let third = if self.duplicate_pin {
            pin_x
        } else {
            th - self.omega * t
        };
        *out = Vector::from([pin_x, y - self.a * sin(th), third]);
    }
    fn jacobian(&self, q: &Vector<Const<3>>, _: f64, out: &mut Matrix<Const<3>>) {
        let th = q.z;
        let (s, c) = (self.a * sin(th), self.a * cos(th));
        let third = if self.duplicate_pin {
            [1.0, 0.0, s]
        } else {
            [0.0, 0.0, 1.0]
        };
        *out = Matrix::<Const<3>>::from_row_slice(&[
            1.0, 0.0, s, //
            0.0, 1.0, -c, //
            third[0], third[1], third[2],
        ]);
    }

    fn outputs(&self) -> Outputs {
        if self.mass.is_some() {
            Outputs::Forces
        } else {
            Outputs::Accelerations
        }
    }

    fn nu(&self, _: &Vector<Const<3>>, _: f64, out: &mut Vector<Const<3>>) {
        *out = Vector::from([0.0, 0.0, self.omega]);
    }

    fn gamma(
        &self,
        q: &Vector<Const<3>>,
        qd: &Vector<Const<3>>,
        _: f64,
        out: &mut Vector<Const<3>>,
    ) {
        let (th, thd) = (q.z, qd.z);
        let w2 = thd * thd;
        *out = Vector::from([-self.a * cos(th) * w2, -self.a * sin(th) * w2, 0.0]);
    }

    fn generalized_forces(
        &self,
        _: &Vector<Const<3>>,
        _: &Vector<Const<3>>,
        qdd: &Vector<Const<3>>,
        _: f64,
        out: &mut Vector<Const<3>>,
    ) {
        let (m, j, g) = self.mass.unwrap_or((f64::NAN, f64::NAN, f64::NAN));
        *out = Vector::from([-m * qdd.x, m * (-g - qdd.y), -j * qdd.z]);
    }

    /// The pin's force on the rod (`pin` is `revolute(rod @ (−a, 0), ground)`) and the drive's
    /// torque.
    fn reactions(
        &self,
        _: &Vector<Const<3>>,
        _: &Vector<Const<3>>,
        lambda: &[f64],
        out: &mut Vector<Const<3>>,
    ) {
        for (o, l) in out.iter_mut().zip(lambda) {
            *o = -l;
        }
    }

    fn reaction_name(&self, index: usize) -> Option<&str> {
        ["pin.fx", "pin.fy", "drive.effort"].get(index).copied()
    }
}

impl Velocities for Pendulum {}
impl Accelerations for Pendulum {}
impl Forces for Pendulum {}

impl Pendulum {
    /// Closed-form reactions at `t` (with `mass` set): the pin carries `m (a_c − g)`, the
    /// driver turns the rod against the pin force's moment (θ̈ = 0).
    pub fn exact_reactions(&self, t: f64) -> [f64; 3] {
        let (m, _, g) = self.mass.unwrap_or((f64::NAN, f64::NAN, f64::NAN));
        let [q, _, qdd] = self.exact(t);
        let pin = [m * qdd[0], m * (qdd[1] + g)];
        // The pin is at A(θ) (−a, 0) from the reference point: τ = −(r × F).
        let r = [-self.a * cos(q[2]), -self.a * sin(q[2])];
        [pin[0], pin[1], -(r[0] * pin[1] - r[1] * pin[0])]
    }
}

/// The same pendulum behind a `Dyn` dimension, as the interpreter would present it.
#[cfg(feature = "alloc")]
pub struct DynPendulum(pub Pendulum);

#[cfg(feature = "alloc")]
mod dynamic {
    use super::{
        Accelerations, DynPendulum, Mechanism, Outputs, ParameterError, Unit, Vector, Velocities,
    };
    use mechgen_runtime::Matrix;
    use mechgen_runtime::nalgebra::{Const, Dyn, Matrix3, Vector3};

    fn fixed(v: &Vector<Dyn>) -> Vector3<f64> {
        Vector3::from_iterator(v.iter().copied())
    }

    impl Mechanism for DynPendulum {
        type Dim = Dyn;
        type Markers = [f64; 0];

        fn dim(&self) -> Dyn {
            Dyn(3)
        }
        fn marker_storage(&self) -> [f64; 0] {
            []
        }
        fn coordinate_name(&self, index: usize) -> Option<&str> {
            self.0.coordinate_name(index)
        }
        fn equation_name(&self, index: usize) -> Option<&str> {
            self.0.equation_name(index)
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
        fn set_parameter<'a>(
            &'a mut self,
            name: &'a str,
            _: f64,
        ) -> Result<(), ParameterError<'a>> {
            Err(ParameterError::Unknown {
                name,
                declared: &[] as &[&str; 0],
            })
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
            let mut fixed_q = Vector3::zeros();
            self.0.initial_guess(&mut fixed_q);
            q.copy_from_slice(fixed_q.as_slice());
        }
        fn phi(&self, q: &Vector<Dyn>, t: f64, out: &mut Vector<Dyn>) {
            let mut phi = Vector::<Const<3>>::zeros();
            self.0.phi(&fixed(q), t, &mut phi);
            out.copy_from_slice(phi.as_slice());
        }
        fn jacobian(&self, q: &Vector<Dyn>, t: f64, out: &mut Matrix<Dyn>) {
            let mut jacobian = Matrix3::zeros();
            self.0.jacobian(&fixed(q), t, &mut jacobian);
            out.copy_from(&jacobian);
        }

        fn outputs(&self) -> Outputs {
            Outputs::Accelerations
        }

        fn nu(&self, q: &Vector<Dyn>, t: f64, out: &mut Vector<Dyn>) {
            let mut nu = Vector3::zeros();
            self.0.nu(&fixed(q), t, &mut nu);
            out.copy_from_slice(nu.as_slice());
        }

        fn gamma(&self, q: &Vector<Dyn>, qd: &Vector<Dyn>, t: f64, out: &mut Vector<Dyn>) {
            let mut gamma = Vector3::zeros();
            self.0.gamma(&fixed(q), &fixed(qd), t, &mut gamma);
            out.copy_from_slice(gamma.as_slice());
        }
    }

    impl Velocities for DynPendulum {}
    impl Accelerations for DynPendulum {}
}
