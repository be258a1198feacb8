//! The textbook functions of an interpreted scene (Φ, Φ_q, ν, γ, the forces, the markers,
//! the parameter checks) as tapes, behind the runtime's `Mechanism` trait.

use mechgen::Scene;
use mechgen::expr::tape::Tape;
use mechgen::model::{geometry, physics};
use mechgen_runtime::codegen::{check_physics, first_load_fault};
use mechgen_runtime::nalgebra::Dyn;
use mechgen_runtime::{
    Accelerations, Forces, GeometryFault, Matrix, Mechanism, Names, Outputs, ParameterError,
    PhysicsFault, Quantity, Requirement, Subject, Unit, Vector, Velocities,
};

use super::Interpreted;
use mechgen::expr::tape::Inputs;

/// The scene's functions of the whole state, one tape each.
#[derive(Debug, Clone)]
pub(super) struct Textbook {
    guess: Tape,
    phi: Tape,
    jacobian: Tape,
    phi_and_jacobian: Tape,
    /// ν and γ, present when the scene asked for them.
    nu: Option<Tape>,
    gamma: Option<Tape>,
    /// The force solve's textbook functions (F, and the reactions from λ), present when the
    /// scene computes forces.
    forces: Option<(Tape, Tape)>,
    /// Two values per load naming the one that makes F non-finite (`Scene::load_witnesses`),
    /// and how many values that is.
    load_witnesses: (Tape, usize),
    /// The markers' values.
    markers: Tape,
    /// The parameter-dependent lengths of the length scale.
    lengths: Tape,
    /// The geometry, and the mass properties and load constants, written in parameters.
    geometry_values: Tape,
    physics_values: Tape,
    /// One tape per branch invariant (its signed value).
    branches: Vec<Tape>,
}

impl Textbook {
    pub(super) fn new(scene: &Scene) -> Self {
        let (arena, kin) = (&scene.model.arena, &scene.kinematics);
        let tape = |roots: &[mechgen::expr::Id]| Tape::new(arena, roots);
        let jacobian_values: Vec<_> = kin.jacobian.iter().map(|e| e.value).collect();
        let both: Vec<_> = kin.phi.iter().chain(&jacobian_values).copied().collect();
        let geometry: Vec<_> = kin.geometry.iter().map(|c| c.value).collect();
        let physics: Vec<_> = kin.physics.iter().map(|c| c.value).collect();
        Textbook {
            guess: tape(&kin.guess),
            phi: tape(&kin.phi),
            jacobian: tape(&jacobian_values),
            phi_and_jacobian: tape(&both),
            nu: kin.nu.as_deref().map(tape),
            gamma: kin.gamma.as_deref().map(tape),
            forces: (scene.forces.as_ref()).map(|f| (tape(&f.generalized), tape(&f.reactions))),
            load_witnesses: (tape(&scene.load_witnesses), scene.load_witnesses.len()),
            markers: tape(&kin.markers),
            lengths: tape(&kin.length_scale.dependent),
            geometry_values: tape(&geometry),
            physics_values: tape(&physics),
            branches: kin.branches.iter().map(|&b| tape(&[b])).collect(),
        }
    }

    pub(super) fn tapes(&self) -> impl Iterator<Item = &Tape> {
        [
            &self.guess,
            &self.phi,
            &self.jacobian,
            &self.phi_and_jacobian,
        ]
        .into_iter()
        .chain(&self.nu)
        .chain(&self.gamma)
        .chain(self.forces.iter().flat_map(|(f, r)| [f, r]))
        .chain([&self.load_witnesses.0, &self.markers, &self.lengths])
        .chain([&self.geometry_values, &self.physics_values])
        .chain(&self.branches)
    }
}

/// The runtime's unit for a coordinate's or an equation's.
pub(super) fn unit(unit: mechgen::model::Unit) -> Unit {
    match unit {
        mechgen::model::Unit::Angle => Unit::Angle,
        mechgen::model::Unit::Length => Unit::Length,
        mechgen::model::Unit::Area => Unit::Area,
    }
}

pub(super) fn copy_into(values: &[f64], out: &mut Vector<Dyn>) {
    for (o, v) in out.iter_mut().zip(values) {
        *o = *v;
    }
}

impl Mechanism for Interpreted {
    type Dim = Dyn;
    type Markers = Vec<f64>;

    fn marker_storage(&self) -> Vec<f64> {
        vec![0.0; self.marker_names.len()]
    }

    fn marker_values(
        &self,
        q: &Vector<Dyn>,
        qd: &Vector<Dyn>,
        qdd: &Vector<Dyn>,
        t: f64,
        out: &mut Vec<f64>,
    ) {
        let inputs = self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), &[], t);
        self.run(&self.textbook.markers, inputs, |v| {
            out.iter_mut().zip(v).for_each(|(o, v)| *o = *v);
        });
    }

    fn marker_name(&self, index: usize) -> Option<&str> {
        self.marker_names.get(index).map(String::as_str)
    }

    fn dim(&self) -> Dyn {
        Dyn(self.coordinates.len())
    }

    fn names(&self) -> &'static Names {
        self.names
    }

    fn coordinate_name(&self, index: usize) -> Option<&str> {
        self.coordinates.get(index).map(String::as_str)
    }

    fn equation_name(&self, index: usize) -> Option<&str> {
        self.equations.get(index).map(String::as_str)
    }

    fn parameter_count(&self) -> usize {
        self.params.len()
    }

    fn parameter_name(&self, index: usize) -> Option<&str> {
        self.param_names.get(index).map(String::as_str)
    }

    fn parameter(&self, index: usize) -> Option<f64> {
        self.params.get(index).copied()
    }

    fn set_parameter<'a>(
        &'a mut self,
        name: &'a str,
        value: f64,
    ) -> Result<(), ParameterError<'a>> {
        let Some(index) = self.param_names.iter().position(|p| p == name) else {
            return Err(ParameterError::Unknown {
                name,
                declared: &self.param_names,
            });
        };
        if !value.is_finite() {
            return Err(ParameterError::NonFinite { name, value });
        }
        self.params[index] = value;
        Ok(())
    }

    fn coordinate_unit(&self, index: usize) -> Unit {
        self.coordinate_units
            .get(index)
            .copied()
            .unwrap_or(Unit::Angle)
    }

    fn equation_unit(&self, index: usize) -> Unit {
        self.equation_units
            .get(index)
            .copied()
            .unwrap_or(Unit::Angle)
    }

    fn length_scale(&self) -> f64 {
        let count = self.length_scale.dependent.len();
        let mut scale = self.length_scale.constant;
        self.run(&self.textbook.lengths, self.inputs(&[], &[], 0.0), |v| {
            scale = self.length_scale.evaluate(&v[..count.min(v.len())]);
        });
        scale
    }

    fn check_geometry(&self) -> Result<(), GeometryFault> {
        let tape = &self.textbook.geometry_values;
        self.check_values(&self.geometry, tape, |value, c| {
            mechgen_runtime::codegen::check_geometry(
                value,
                requirement(c.requirement),
                c.subject,
                c.parameter,
            )
        })
    }

    fn check_physics(&self) -> Result<(), PhysicsFault> {
        let tape = &self.textbook.physics_values;
        self.check_values(&self.physics, tape, |value, c| {
            let subject = match c.subject {
                physics::Subject::Body(b) => Subject::Body(b),
                physics::Subject::Load(l) => Subject::Load(l),
            };
            check_physics(value, requirement(c.requirement), subject, c.parameter)
        })
    }

    fn branch_count(&self) -> usize {
        self.textbook.branches.len()
    }

    fn branch_name(&self, index: usize) -> Option<&str> {
        self.branch_names.get(index).map(String::as_str)
    }

    fn branch_value(&self, index: usize, q: &Vector<Dyn>) -> f64 {
        let Some(tape) = self.textbook.branches.get(index) else {
            return f64::NAN;
        };
        let mut value = f64::NAN;
        self.run(tape, self.inputs(q.as_slice(), &[], 0.0), |v| {
            value = v.first().copied().unwrap_or(f64::NAN);
        });
        value
    }

    fn initial_guess(&self, q: &mut Vector<Dyn>) {
        self.run(&self.textbook.guess, self.inputs(&[], &[], 0.0), |v| {
            copy_into(v, q)
        });
    }

    fn phi(&self, q: &Vector<Dyn>, t: f64, out: &mut Vector<Dyn>) {
        self.run(&self.textbook.phi, self.inputs(q.as_slice(), &[], t), |v| {
            copy_into(v, out);
        });
    }

    fn jacobian(&self, q: &Vector<Dyn>, t: f64, out: &mut Matrix<Dyn>) {
        self.run(
            &self.textbook.jacobian,
            self.inputs(q.as_slice(), &[], t),
            |v| {
                self.write_jacobian(v, out);
            },
        );
    }

    fn phi_and_jacobian(
        &self,
        q: &Vector<Dyn>,
        t: f64,
        phi: &mut Vector<Dyn>,
        jacobian: &mut Matrix<Dyn>,
    ) {
        let n = self.coordinates.len();
        self.run(
            &self.textbook.phi_and_jacobian,
            self.inputs(q.as_slice(), &[], t),
            |v| {
                let (phi_values, jacobian_values) = v.split_at(n.min(v.len()));
                copy_into(phi_values, phi);
                self.write_jacobian(jacobian_values, jacobian);
            },
        );
    }

    fn outputs(&self) -> Outputs {
        self.outputs
    }

    fn nu(&self, q: &Vector<Dyn>, t: f64, out: &mut Vector<Dyn>) {
        match &self.textbook.nu {
            Some(tape) => self.run(tape, self.inputs(q.as_slice(), &[], t), |v| {
                copy_into(v, out);
            }),
            None => out.as_mut_slice().fill(f64::NAN),
        }
    }

    fn gamma(&self, q: &Vector<Dyn>, qd: &Vector<Dyn>, t: f64, out: &mut Vector<Dyn>) {
        match &self.textbook.gamma {
            Some(tape) => self.run(tape, self.inputs(q.as_slice(), qd.as_slice(), t), |v| {
                copy_into(v, out);
            }),
            None => out.as_mut_slice().fill(f64::NAN),
        }
    }

    fn generalized_forces(
        &self,
        q: &Vector<Dyn>,
        qd: &Vector<Dyn>,
        qdd: &Vector<Dyn>,
        t: f64,
        out: &mut Vector<Dyn>,
    ) {
        match &self.textbook.forces {
            Some((tape, _)) => {
                let inputs = self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), &[], t);
                self.run(tape, inputs, |v| copy_into(v, out));
            }
            None => out.as_mut_slice().fill(f64::NAN),
        }
    }

    fn load_fault(&self, q: &Vector<Dyn>, qd: &Vector<Dyn>, t: f64) -> Option<Quantity> {
        let (tape, count) = &self.textbook.load_witnesses;
        let mut fault = None;
        let inputs = self.inputs(q.as_slice(), qd.as_slice(), t);
        self.run(tape, inputs, |v| {
            fault = first_load_fault(v.get(..*count).unwrap_or(v));
        });
        fault
    }

    fn reactions(&self, q: &Vector<Dyn>, qd: &Vector<Dyn>, lambda: &[f64], out: &mut Vector<Dyn>) {
        match &self.textbook.forces {
            Some((_, tape)) => {
                let inputs = Inputs {
                    lambda,
                    ..self.inputs(q.as_slice(), qd.as_slice(), 0.0)
                };
                self.run(tape, inputs, |v| copy_into(v, out));
            }
            None => out.as_mut_slice().fill(f64::NAN),
        }
    }

    fn reaction_name(&self, index: usize) -> Option<&str> {
        self.textbook.forces.as_ref()?;
        self.reaction_names.get(index).map(String::as_str)
    }
}

impl Interpreted {
    /// Evaluates the values of `checks` (`tape`) with the current parameters and checks each
    /// in order with `check`, stopping at the first fault.
    fn check_values<S, F>(
        &self,
        checks: &[geometry::Check<S>],
        tape: &Tape,
        check: impl Fn(f64, &geometry::Check<S>) -> Result<(), F>,
    ) -> Result<(), F> {
        let mut result = Ok(());
        if checks.is_empty() {
            return result;
        }
        self.run(tape, self.inputs(&[], &[], 0.0), |v| {
            result = checks
                .iter()
                .zip(v)
                .try_for_each(|(c, &value)| check(value, c));
        });
        result
    }
}

/// One interpreter type serves every scene, so it is marked as computing every level; a scene
/// that did not ask for an output writes NaN there, and the solver never asks for it.
impl Velocities for Interpreted {}
impl Accelerations for Interpreted {}
impl Forces for Interpreted {}

/// The runtime's name for a geometric rule.
fn requirement(requirement: geometry::Requirement) -> Requirement {
    match requirement {
        geometry::Requirement::Length => Requirement::Length,
        geometry::Requirement::Distance => Requirement::Distance,
        geometry::Requirement::Angle => Requirement::Angle,
        geometry::Requirement::Axis => Requirement::Axis,
        geometry::Requirement::Ratio => Requirement::Ratio,
        geometry::Requirement::Mass => Requirement::Mass,
        geometry::Requirement::Inertia => Requirement::Inertia,
        geometry::Requirement::Stiffness => Requirement::Stiffness,
        geometry::Requirement::FreeLength => Requirement::FreeLength,
        geometry::Requirement::Damping => Requirement::Damping,
    }
}
