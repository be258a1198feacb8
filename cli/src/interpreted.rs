//! A compiled scene evaluated by the interpreter, behind the runtime's `Mechanism` trait.
//!
//! This is what a run-time (non-generated) library would do: the same IR as the generated code,
//! walked at run time. It lets the CLI, the tests and the report drive the one solver
//! implementation of `mechgen-runtime` with scenes read from `.mech` files.

use std::cell::RefCell;

use mechgen::Scene;
use mechgen::interpret::{Inputs, Tape};
use mechgen::kinematics::LengthScale;
use mechgen_runtime::nalgebra::Dyn;
use mechgen_runtime::{
    Accelerations, Lu, Matrix, Mechanism, Outputs, ParameterError, SolveError, Unit, Vector,
    Velocities, solve_accelerations, solve_velocities,
};

/// A scene whose kinematics are interpreted rather than generated.
#[derive(Debug, Clone)]
pub struct Interpreted {
    name: String,
    coordinates: Vec<String>,
    equations: Vec<String>,
    param_names: Vec<String>,
    params: Vec<f64>,
    guess: Tape,
    phi: Tape,
    jacobian: Tape,
    phi_and_jacobian: Tape,
    /// ν and γ, present when the scene asked for them.
    nu: Option<Tape>,
    gamma: Option<Tape>,
    outputs: Outputs,
    /// Structural non-zeros of Φ_q, in the order the Jacobian tape produces them.
    pattern: Vec<(usize, usize)>,
    coordinate_units: Vec<Unit>,
    equation_units: Vec<Unit>,
    /// The folded constant lengths, and a tape of the parameter-dependent ones.
    length_scale: LengthScale,
    lengths: Tape,
    branch_names: Vec<String>,
    /// One tape per branch invariant (its signed value).
    branches: Vec<Tape>,
    /// Tape slots and output values, reused by every call (evaluation is `&self`).
    scratch: RefCell<Scratch>,
}

#[derive(Debug, Clone, Default)]
struct Scratch {
    slots: Vec<f64>,
    values: Vec<f64>,
}

impl Interpreted {
    /// Builds the interpreter for a compiled scene (parameters start at their defaults).
    pub fn new(scene: &Scene) -> Self {
        let (model, kin) = (&scene.model, &scene.kinematics);
        let arena = &model.arena;
        let jacobian_values: Vec<_> = kin.jacobian.iter().map(|e| e.value).collect();
        let both: Vec<_> = kin
            .phi
            .iter()
            .copied()
            .chain(jacobian_values.iter().copied())
            .collect();
        let tapes = [
            Tape::new(arena, &kin.guess),
            Tape::new(arena, &kin.phi),
            Tape::new(arena, &jacobian_values),
            Tape::new(arena, &both),
        ];
        let nu = kin.nu.as_deref().map(|nu| Tape::new(arena, nu));
        let gamma = kin.gamma.as_deref().map(|gamma| Tape::new(arena, gamma));
        let lengths = Tape::new(arena, &kin.length_scale.dependent);
        let branches: Vec<Tape> = kin
            .branches
            .iter()
            .map(|&b| Tape::new(arena, &[b]))
            .collect();
        let slots = tapes
            .iter()
            .chain(&nu)
            .chain(&gamma)
            .chain([&lengths])
            .chain(&branches)
            .map(Tape::len)
            .max()
            .unwrap_or(0);
        let values = both
            .len()
            .max(model.dim())
            .max(kin.length_scale.dependent.len())
            .max(1);
        let [guess, phi, jacobian, phi_and_jacobian] = tapes;
        let outputs = match model.outputs {
            mechgen::model::Outputs::Positions => Outputs::Positions,
            mechgen::model::Outputs::Velocities => Outputs::Velocities,
            mechgen::model::Outputs::Accelerations => Outputs::Accelerations,
        };
        Interpreted {
            name: model.name.to_string(),
            coordinates: model.coordinate_names(),
            equations: model.equation_names(),
            param_names: model.params.iter().map(|p| p.name.to_string()).collect(),
            params: model.params.iter().map(|p| p.default).collect(),
            guess,
            phi,
            jacobian,
            phi_and_jacobian,
            nu,
            gamma,
            outputs,
            pattern: kin.jacobian.iter().map(|e| (e.row, e.col)).collect(),
            coordinate_units: model.coordinate_units().into_iter().map(unit).collect(),
            equation_units: model.equation_units().into_iter().map(unit).collect(),
            length_scale: kin.length_scale.clone(),
            lengths,
            branch_names: model.branches.iter().map(|b| b.name.clone()).collect(),
            branches,
            scratch: RefCell::new(Scratch {
                slots: vec![0.0; slots],
                values: vec![0.0; values],
            }),
        }
    }

    /// The mechanism's name as declared.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of coordinates (= equations).
    pub fn len(&self) -> usize {
        self.coordinates.len()
    }

    /// True for a scene without coordinates (never produced by a checked model).
    pub fn is_empty(&self) -> bool {
        self.coordinates.is_empty()
    }

    /// Structural non-zeros of Φ_q as (equation, coordinate).
    pub fn jacobian_pattern(&self) -> &[(usize, usize)] {
        &self.pattern
    }

    fn run(&self, tape: &Tape, inputs: Inputs<'_>, write: impl FnOnce(&[f64])) {
        let mut scratch = self.scratch.borrow_mut();
        let Scratch { slots, values } = &mut *scratch;
        tape.eval(inputs, slots, values);
        write(values);
    }

    fn inputs<'a>(&'a self, q: &'a [f64], qd: &'a [f64], t: f64) -> Inputs<'a> {
        Inputs {
            q,
            qd,
            t,
            params: &self.params,
        }
    }

    fn write_jacobian(&self, values: &[f64], out: &mut Matrix<Dyn>) {
        // Slice fill: nalgebra's `fill` goes element by element.
        out.as_mut_slice().fill(0.0);
        for (&(row, col), &value) in self.pattern.iter().zip(values) {
            out[(row, col)] = value;
        }
    }
}

fn unit(unit: mechgen::model::Unit) -> Unit {
    match unit {
        mechgen::model::Unit::Angle => Unit::Angle,
        mechgen::model::Unit::Length => Unit::Length,
        mechgen::model::Unit::Area => Unit::Area,
    }
}

fn copy_into(values: &[f64], out: &mut Vector<Dyn>) {
    for (o, v) in out.iter_mut().zip(values) {
        *o = *v;
    }
}

impl Mechanism for Interpreted {
    type Dim = Dyn;

    fn dim(&self) -> Dyn {
        Dyn(self.coordinates.len())
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

    fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), ParameterError> {
        if !value.is_finite() {
            return Err(ParameterError::NonFinite);
        }
        let index = self
            .param_names
            .iter()
            .position(|p| p == name)
            .ok_or(ParameterError::Unknown)?;
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
        self.run(&self.lengths, self.inputs(&[], &[], 0.0), |v| {
            scale = self.length_scale.evaluate(&v[..count.min(v.len())]);
        });
        scale
    }

    fn branch_count(&self) -> usize {
        self.branches.len()
    }

    fn branch_name(&self, index: usize) -> Option<&str> {
        self.branch_names.get(index).map(String::as_str)
    }

    fn branch_value(&self, index: usize, q: &Vector<Dyn>) -> f64 {
        let Some(tape) = self.branches.get(index) else {
            return f64::NAN;
        };
        let mut value = f64::NAN;
        self.run(tape, self.inputs(q.as_slice(), &[], 0.0), |v| {
            value = v.first().copied().unwrap_or(f64::NAN);
        });
        value
    }

    fn initial_guess(&self, q: &mut Vector<Dyn>) {
        self.run(&self.guess, self.inputs(&[], &[], 0.0), |v| copy_into(v, q));
    }

    fn phi(&self, q: &Vector<Dyn>, t: f64, out: &mut Vector<Dyn>) {
        self.run(&self.phi, self.inputs(q.as_slice(), &[], t), |v| {
            copy_into(v, out);
        });
    }

    fn jacobian(&self, q: &Vector<Dyn>, t: f64, out: &mut Matrix<Dyn>) {
        self.run(&self.jacobian, self.inputs(q.as_slice(), &[], t), |v| {
            self.write_jacobian(v, out);
        });
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
            &self.phi_and_jacobian,
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

    fn derivatives(
        &self,
        q: &Vector<Dyn>,
        t: f64,
        factors: &Lu<Dyn>,
        qd: &mut Vector<Dyn>,
        qdd: &mut Vector<Dyn>,
    ) -> Result<(), SolveError> {
        if self.outputs >= Outputs::Velocities {
            solve_velocities(self, q, t, factors, qd)?;
        }
        if self.outputs >= Outputs::Accelerations {
            solve_accelerations(self, q, qd, t, factors, qdd)?;
        }
        Ok(())
    }
}

/// One interpreter type serves every scene, so it implements the derivative traits for all;
/// a scene that did not ask for an output writes NaN there, and [`Mechanism::derivatives`]
/// never asks for it.
impl Velocities for Interpreted {
    fn nu(&self, q: &Vector<Dyn>, t: f64, out: &mut Vector<Dyn>) {
        match &self.nu {
            Some(tape) => self.run(tape, self.inputs(q.as_slice(), &[], t), |v| {
                copy_into(v, out)
            }),
            None => out.as_mut_slice().fill(f64::NAN),
        }
    }
}

impl Accelerations for Interpreted {
    fn gamma(&self, q: &Vector<Dyn>, qd: &Vector<Dyn>, t: f64, out: &mut Vector<Dyn>) {
        match &self.gamma {
            Some(tape) => self.run(tape, self.inputs(q.as_slice(), qd.as_slice(), t), |v| {
                copy_into(v, out);
            }),
            None => out.as_mut_slice().fill(f64::NAN),
        }
    }
}
