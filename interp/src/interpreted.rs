//! A compiled scene evaluated by the interpreter, behind the runtime's `Mechanism` and
//! `Structured` traits.
//!
//! This is what a run-time (non-generated) library would do: the same IR and the same solve
//! plan as the generated code, walked at run time (tapes for the expressions, the static LU's
//! operation list for the factorisations). It lets the CLI, the tests and the report drive the
//! one solver implementation of `mechgen-runtime` with scenes read from `.mech` files, and it
//! agrees with generated code to the bit.

use std::cell::{Cell, RefCell};

use mechgen::Scene;
use mechgen::interpret::{Inputs, Tape};
use mechgen::kernels::{self, Buffer, Method};
use mechgen::kinematics::LengthScale;
use mechgen::{geometry, physics};
use mechgen_runtime::first_load_fault;
use mechgen_runtime::nalgebra::Dyn;
use mechgen_runtime::{
    Accelerations, Block, Forces, GeometryFault, Matrix, Mechanism, Names, Outputs, ParameterError,
    Pattern, PhysicsFault, Quantity, Requirement, Stage, Structured, Subject, Unit, VecBuffers,
    Vector, Velocities, check_physics,
};

/// A scene whose kinematics are interpreted rather than generated.
#[derive(Debug, Clone)]
pub struct Interpreted {
    name: String,
    coordinates: Vec<String>,
    equations: Vec<String>,
    param_names: Vec<String>,
    params: Vec<f64>,
    /// Derived parameters (computed from the others, substituted into every tape).
    derived_names: Vec<String>,
    guess: Tape,
    phi: Tape,
    jacobian: Tape,
    phi_and_jacobian: Tape,
    /// ν and γ, present when the scene asked for them.
    nu: Option<Tape>,
    gamma: Option<Tape>,
    /// The force solve's textbook functions (F, and the reactions from λ), and the reactions'
    /// names, present when the scene computes forces.
    forces: Option<(Tape, Tape)>,
    /// Two values per load naming the one that makes F non-finite (`Scene::load_witnesses`),
    /// and how many values that is.
    load_witnesses: (Tape, usize),
    reaction_names: Vec<String>,
    /// The markers' values (the textbook tape) and their names.
    markers: Tape,
    marker_names: Vec<String>,
    outputs: Outputs,
    /// Structural non-zeros of Φ_q, in the order the Jacobian tape produces them.
    pattern: Vec<(usize, usize)>,
    coordinate_units: Vec<Unit>,
    equation_units: Vec<Unit>,
    /// The folded constant lengths, and a tape of the parameter-dependent ones.
    length_scale: LengthScale,
    lengths: Tape,
    /// The geometry written in parameters: each value's rule, and one tape for the values.
    geometry: Vec<geometry::Check>,
    geometry_values: Tape,
    /// The mass properties and load constants written in parameters, likewise.
    physics: Vec<physics::Check>,
    physics_values: Tape,
    branch_names: Vec<String>,
    /// Every name, `'static` for the errors the solver returns (interned, see `names`).
    names: &'static Names,
    /// One tape per branch invariant (its signed value).
    branches: Vec<Tape>,
    /// The plan's kernels as tapes, behind the `Structured` methods.
    plan: PlanTapes,
    /// Tape slots and output values, reused by every call (evaluation is `&self`).
    scratch: RefCell<Scratch>,
    /// Block Jacobian evaluations so far: the unit of a solve's work, which fuzzing bounds.
    evaluations: Cell<u64>,
}

/// A kernel of the plan as a tape, with where its values go.
#[derive(Debug, Clone)]
struct Compiled {
    tape: Tape,
    outputs: Vec<(Buffer, usize)>,
}

impl Compiled {
    fn new(arena: &mechgen::expr::Arena, kernel: &kernels::Kernel) -> Self {
        Compiled {
            tape: Tape::with_inputs(arena, &kernel.roots, &kernel.cached),
            outputs: kernel.outputs.clone(),
        }
    }
}

/// The scene's kernel list (`mechgen::kernels`) compiled: the `Structured` methods look up
/// the kernel of a stage and method in a table, where generated code has a `match`.
#[derive(Debug, Clone)]
struct PlanTapes {
    /// The kernel list: the stage table, the static LUs, the workspace's sizes.
    list: kernels::Kernels,
    /// `dispatch[stage][method as usize]`: the stage's kernel of that method in `kernels`.
    dispatch: Vec<[Option<usize>; Method::ALL.len()]>,
    kernels: Vec<Compiled>,
    /// The markers and the branch invariants at the solved state, reading the trig cache.
    markers: Option<Compiled>,
    branches: Vec<Compiled>,
}

impl PlanTapes {
    fn new(arena: &mechgen::expr::Arena, list: &kernels::Kernels) -> Self {
        let mut dispatch = vec![[None; Method::ALL.len()]; list.shapes.len()];
        for (k, kernel) in list.stages.iter().enumerate() {
            dispatch[kernel.stage][kernel.method as usize] = Some(k);
        }
        let compile = |kernel: &kernels::Kernel| Compiled::new(arena, kernel);
        PlanTapes {
            dispatch,
            kernels: list.stages.iter().map(|k| compile(&k.kernel)).collect(),
            markers: list.markers.as_ref().map(compile),
            branches: list.branches.iter().map(compile).collect(),
            list: list.clone(),
        }
    }

    /// Stage `stage`'s kernel of `method`, if it has one.
    fn kernel(&self, stage: usize, method: Method) -> Option<&Compiled> {
        let k = (*self.dispatch.get(stage)?)[method as usize]?;
        self.kernels.get(k)
    }

    fn tapes(&self) -> impl Iterator<Item = &Tape> {
        self.kernels
            .iter()
            .chain(&self.markers)
            .chain(&self.branches)
            .map(|k| &k.tape)
    }
}

#[derive(Debug, Clone, Default)]
struct Scratch {
    slots: Vec<f64>,
    values: Vec<f64>,
}

impl Interpreted {
    /// Block Jacobian evaluations (each with its residual) made since the scene was built: the
    /// work of every solve, whatever its outcome, counted without a clock.
    pub fn evaluations(&self) -> u64 {
        self.evaluations.get()
    }

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
        let geometry_ids: Vec<_> = kin.geometry.iter().map(|c| c.value).collect();
        let geometry_values = Tape::new(arena, &geometry_ids);
        let physics_ids: Vec<_> = kin.physics.iter().map(|c| c.value).collect();
        let physics_values = Tape::new(arena, &physics_ids);
        let branches: Vec<Tape> = kin
            .branches
            .iter()
            .map(|&b| Tape::new(arena, &[b]))
            .collect();
        let plan = PlanTapes::new(arena, &scene.kernels);
        let forces = scene.forces.as_ref().map(|f| {
            (
                Tape::new(arena, &f.generalized),
                Tape::new(arena, &f.reactions),
            )
        });
        let markers = Tape::new(arena, &kin.markers);
        let load_witnesses = Tape::new(arena, &scene.load_witnesses);
        let slots = tapes
            .iter()
            .chain(&nu)
            .chain(&gamma)
            .chain(forces.iter().flat_map(|(f, r)| [f, r]))
            .chain([&markers, &load_witnesses])
            .chain([&lengths, &geometry_values, &physics_values])
            .chain(&branches)
            .chain(plan.tapes())
            .map(Tape::len)
            .max()
            .unwrap_or(0);
        let values = both
            .len()
            .max(model.dim())
            .max(kin.length_scale.dependent.len())
            .max(kin.geometry.len())
            .max(kin.physics.len())
            .max(
                plan.kernels
                    .iter()
                    .map(|k| k.outputs.len())
                    .max()
                    .unwrap_or(0),
            )
            .max(kin.markers.len())
            .max(scene.load_witnesses.len())
            .max(1);
        let [guess, phi, jacobian, phi_and_jacobian] = tapes;
        let outputs = match model.outputs {
            mechgen::model::Outputs::Positions => Outputs::Positions,
            mechgen::model::Outputs::Velocities => Outputs::Velocities,
            mechgen::model::Outputs::Accelerations => Outputs::Accelerations,
            mechgen::model::Outputs::Forces => Outputs::Forces,
        };
        Interpreted {
            name: model.name.to_string(),
            coordinates: model.coordinate_names(),
            equations: model.equation_names(),
            param_names: model.params.iter().map(|p| p.name.to_string()).collect(),
            params: model.params.iter().map(|p| p.default).collect(),
            derived_names: model.derived.iter().map(|d| d.name.to_string()).collect(),
            guess,
            phi,
            jacobian,
            phi_and_jacobian,
            nu,
            gamma,
            forces,
            load_witnesses: (load_witnesses, scene.load_witnesses.len()),
            reaction_names: model.reaction_names(),
            markers,
            marker_names: model.marker_names(),
            outputs,
            pattern: kin.jacobian.iter().map(|e| (e.row, e.col)).collect(),
            coordinate_units: model.coordinate_units().into_iter().map(unit).collect(),
            equation_units: model.equation_units().into_iter().map(unit).collect(),
            length_scale: kin.length_scale.clone(),
            lengths,
            geometry: kin.geometry.clone(),
            geometry_values,
            physics: kin.physics.clone(),
            physics_values,
            branch_names: model.branches.iter().map(|b| b.name.clone()).collect(),
            names: crate::names::intern([
                vec![model.name.to_string()],
                model.coordinate_names(),
                model.equation_names(),
                model.params.iter().map(|p| p.name.to_string()).collect(),
                model.branches.iter().map(|b| b.name.clone()).collect(),
                model.marker_names(),
                model.loads.iter().map(|l| l.name.clone()).collect(),
            ]),
            branches,
            plan,
            evaluations: Cell::new(0),
            scratch: RefCell::new(Scratch {
                slots: vec![0.0; slots],
                values: vec![0.0; values],
            }),
        }
    }

    /// The derived parameters' names: computed from the others, not settable.
    pub fn derived_parameter_names(&self) -> &[String] {
        &self.derived_names
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
        self.inputs_with(q, qd, &[], &[], t)
    }

    fn inputs_with<'a>(
        &'a self,
        q: &'a [f64],
        qd: &'a [f64],
        qdd: &'a [f64],
        trig: &'a [f64],
        t: f64,
    ) -> Inputs<'a> {
        Inputs {
            q,
            qd,
            qdd,
            trig,
            lambda: &[],
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
        self.run(&self.markers, inputs, |v| {
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
        self.run(&self.lengths, self.inputs(&[], &[], 0.0), |v| {
            scale = self.length_scale.evaluate(&v[..count.min(v.len())]);
        });
        scale
    }

    fn check_geometry(&self) -> Result<(), GeometryFault> {
        let mut result = Ok(());
        if self.geometry.is_empty() {
            return result;
        }
        self.run(&self.geometry_values, self.inputs(&[], &[], 0.0), |v| {
            result = self.geometry.iter().zip(v).try_for_each(|(c, &value)| {
                mechgen_runtime::check_geometry(
                    value,
                    requirement(c.requirement),
                    c.equation,
                    c.parameter,
                )
            });
        });
        result
    }

    fn check_physics(&self) -> Result<(), PhysicsFault> {
        let mut result = Ok(());
        if self.physics.is_empty() {
            return result;
        }
        self.run(&self.physics_values, self.inputs(&[], &[], 0.0), |v| {
            result = self.physics.iter().zip(v).try_for_each(|(c, &value)| {
                let subject = match c.subject {
                    physics::Subject::Body(b) => Subject::Body(b),
                    physics::Subject::Load(l) => Subject::Load(l),
                };
                check_physics(value, requirement(c.requirement), subject, c.parameter)
            });
        });
        result
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

    fn nu(&self, q: &Vector<Dyn>, t: f64, out: &mut Vector<Dyn>) {
        match &self.nu {
            Some(tape) => self.run(tape, self.inputs(q.as_slice(), &[], t), |v| {
                copy_into(v, out);
            }),
            None => out.as_mut_slice().fill(f64::NAN),
        }
    }

    fn gamma(&self, q: &Vector<Dyn>, qd: &Vector<Dyn>, t: f64, out: &mut Vector<Dyn>) {
        match &self.gamma {
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
        match &self.forces {
            Some((tape, _)) => {
                let inputs = self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), &[], t);
                self.run(tape, inputs, |v| copy_into(v, out));
            }
            None => out.as_mut_slice().fill(f64::NAN),
        }
    }

    fn load_fault(&self, q: &Vector<Dyn>, qd: &Vector<Dyn>, t: f64) -> Option<Quantity> {
        let (tape, count) = &self.load_witnesses;
        let mut fault = None;
        let inputs = self.inputs(q.as_slice(), qd.as_slice(), t);
        self.run(tape, inputs, |v| {
            fault = first_load_fault(v.get(..*count).unwrap_or(v));
        });
        fault
    }

    fn reactions(&self, q: &Vector<Dyn>, qd: &Vector<Dyn>, lambda: &[f64], out: &mut Vector<Dyn>) {
        match &self.forces {
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
        self.forces.as_ref()?;
        self.reaction_names.get(index).map(String::as_str)
    }
}

/// One interpreter type serves every scene, so it is marked as computing every level; a scene
/// that did not ask for an output writes NaN there, and the solver never asks for it.
impl Velocities for Interpreted {}
impl Accelerations for Interpreted {}
impl Forces for Interpreted {}

impl Structured for Interpreted {
    type Workspace = VecBuffers;

    fn workspace(&self) -> VecBuffers {
        let sizes = &self.plan.list.sizes;
        VecBuffers::new(
            sizes.largest_block,
            sizes.largest_slots,
            sizes.stages,
            sizes.coordinates,
            sizes.trig,
            sizes.forces.unwrap_or(0),
        )
    }

    fn stage_count(&self) -> usize {
        self.plan.list.shapes.len()
    }

    fn stage(&self, index: usize) -> Option<Stage<'_>> {
        let shape = self.plan.list.shapes.get(index)?;
        let (equations, coordinates, reads) = (&shape.equations, &shape.coordinates, &shape.reads);
        Some(match &shape.block {
            None => Stage::Explicit {
                equations,
                coordinates,
                reads,
            },
            Some(block) => Stage::Block(Block {
                equations,
                coordinates,
                pattern: Pattern::Sparse(&block.pattern),
                slots: block.slots,
                pivots: &block.pivots,
                reads,
            }),
        })
    }

    fn assign_positions(&self, stage: usize, q: &mut Vector<Dyn>, trig: &[f64], t: f64) {
        let inputs = self.inputs_with(q.as_slice(), &[], &[], trig, t);
        if let Some(kernel) = self.evaluate(stage, Method::Positions, inputs) {
            self.scatter(kernel, Buffer::Q, q.as_mut_slice());
        }
    }

    fn assign_velocities(
        &self,
        stage: usize,
        q: &Vector<Dyn>,
        trig: &[f64],
        qd: &mut Vector<Dyn>,
        t: f64,
    ) {
        let inputs = self.inputs_with(q.as_slice(), qd.as_slice(), &[], trig, t);
        if let Some(kernel) = self.evaluate(stage, Method::Velocities, inputs) {
            self.scatter(kernel, Buffer::Qd, qd.as_mut_slice());
        }
    }

    fn assign_accelerations(
        &self,
        stage: usize,
        q: &Vector<Dyn>,
        trig: &[f64],
        qd: &Vector<Dyn>,
        qdd: &mut Vector<Dyn>,
        t: f64,
    ) {
        let inputs = self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), trig, t);
        if let Some(kernel) = self.evaluate(stage, Method::Accelerations, inputs) {
            self.scatter(kernel, Buffer::Qdd, qdd.as_mut_slice());
        }
    }

    fn block_jacobian(
        &self,
        stage: usize,
        q: &Vector<Dyn>,
        trig: &[f64],
        t: f64,
        phi: &mut [f64],
        values: &mut [f64],
    ) {
        self.evaluations.set(self.evaluations.get() + 1);
        let inputs = self.inputs_with(q.as_slice(), &[], &[], trig, t);
        if let Some(kernel) = self.evaluate(stage, Method::Jacobian, inputs) {
            self.scatter(kernel, Buffer::Phi, phi);
            self.scatter(kernel, Buffer::Values, values);
        }
    }

    fn fill_trig(&self, stage: usize, q: &Vector<Dyn>, trig: &mut [f64]) {
        let inputs = self.inputs(q.as_slice(), &[], 0.0);
        if let Some(kernel) = self.evaluate(stage, Method::FillTrig, inputs) {
            self.scatter(kernel, Buffer::Trig, trig);
        }
    }

    fn branch(&self, index: usize, q: &Vector<Dyn>, trig: &[f64]) -> f64 {
        let Some(kernel) = self.plan.branches.get(index) else {
            return f64::NAN;
        };
        let mut value = f64::NAN;
        let inputs = self.inputs_with(q.as_slice(), &[], &[], trig, 0.0);
        self.run(&kernel.tape, inputs, |v| {
            value = v.first().copied().unwrap_or(f64::NAN)
        });
        value
    }

    fn markers(
        &self,
        q: &Vector<Dyn>,
        trig: &[f64],
        qd: &Vector<Dyn>,
        qdd: &Vector<Dyn>,
        t: f64,
        out: &mut Vec<f64>,
    ) {
        let Some(kernel) = &self.plan.markers else {
            return;
        };
        let inputs = self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), trig, t);
        self.run(&kernel.tape, inputs, |v| {
            out.iter_mut().zip(v).for_each(|(o, v)| *o = *v);
        });
    }

    fn factor(&self, stage: usize, values: &mut [f64], tiny: f64, limit: f64) -> Result<(), usize> {
        match self.plan.list.factorization(stage) {
            Some(f) if values.len() >= f.slots => f.factor(values, tiny, limit),
            _ => Err(0),
        }
    }

    fn solve(&self, stage: usize, values: &[f64], x: &mut [f64]) {
        if let Some(f) = self.plan.list.factorization(stage) {
            f.solve(values, x);
        }
    }

    fn solve_transpose(&self, stage: usize, values: &[f64], x: &mut [f64]) {
        if let Some(f) = self.plan.list.factorization(stage) {
            f.solve_transpose(values, x);
        }
    }

    fn velocity_rhs(
        &self,
        stage: usize,
        q: &Vector<Dyn>,
        trig: &[f64],
        qd: &Vector<Dyn>,
        t: f64,
        out: &mut [f64],
    ) {
        let inputs = self.inputs_with(q.as_slice(), qd.as_slice(), &[], trig, t);
        match self.evaluate(stage, Method::VelocityRhs, inputs) {
            Some(kernel) => self.scatter(kernel, Buffer::Out, out),
            None => out.fill(f64::NAN),
        }
    }

    fn acceleration_rhs(
        &self,
        stage: usize,
        q: &Vector<Dyn>,
        trig: &[f64],
        qd: &Vector<Dyn>,
        qdd: &Vector<Dyn>,
        t: f64,
        out: &mut [f64],
    ) {
        let inputs = self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), trig, t);
        match self.evaluate(stage, Method::AccelerationRhs, inputs) {
            Some(kernel) => self.scatter(kernel, Buffer::Out, out),
            None => out.fill(f64::NAN),
        }
    }

    fn assign_multipliers(
        &self,
        stage: usize,
        q: &Vector<Dyn>,
        trig: &[f64],
        qd: &Vector<Dyn>,
        qdd: &Vector<Dyn>,
        lambda: &mut [f64],
        t: f64,
    ) {
        let inputs = Inputs {
            lambda,
            ..self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), trig, t)
        };
        match self.evaluate(stage, Method::Multipliers, inputs) {
            Some(kernel) => self.scatter(kernel, Buffer::Lambda, lambda),
            // As the trait's default: the stage's multipliers are unknown.
            None => {
                let equations = self.plan.list.shapes.get(stage).map(|s| &s.equations);
                for &e in equations.into_iter().flatten() {
                    if let Some(l) = lambda.get_mut(e) {
                        *l = f64::NAN;
                    }
                }
            }
        }
    }

    fn force_rhs(
        &self,
        stage: usize,
        q: &Vector<Dyn>,
        trig: &[f64],
        qd: &Vector<Dyn>,
        qdd: &Vector<Dyn>,
        lambda: &[f64],
        t: f64,
        out: &mut [f64],
    ) {
        let inputs = Inputs {
            lambda,
            ..self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), trig, t)
        };
        match self.evaluate(stage, Method::ForceRhs, inputs) {
            Some(kernel) => self.scatter(kernel, Buffer::Out, out),
            None => out.fill(f64::NAN),
        }
    }
}

impl Interpreted {
    /// Evaluates stage `stage`'s kernel of `method` into the scratch values, or returns `None`
    /// when the stage has no such kernel. Every value is computed before
    /// [`Interpreted::scatter`] writes any back, as generated code loads its inputs first.
    fn evaluate(&self, stage: usize, method: Method, inputs: Inputs<'_>) -> Option<&Compiled> {
        let kernel = self.plan.kernel(stage, method)?;
        let mut scratch = self.scratch.borrow_mut();
        let Scratch { slots, values } = &mut *scratch;
        kernel.tape.eval(inputs, slots, values);
        Some(kernel)
    }

    /// Writes the values of [`Interpreted::evaluate`] that `kernel` sends to `buffer` into
    /// `out`, at their indices.
    fn scatter(&self, kernel: &Compiled, buffer: Buffer, out: &mut [f64]) {
        let scratch = self.scratch.borrow();
        for (&(b, i), &v) in kernel.outputs.iter().zip(&scratch.values) {
            if let (true, Some(o)) = (b == buffer, out.get_mut(i)) {
                *o = v;
            }
        }
    }
}

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
