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
use mechgen::factor::Factorization;
use mechgen::interpret::{Inputs, Tape};
use mechgen::kinematics::LengthScale;
use mechgen::reactions::ForceStage;
use mechgen::structure::{self, Phase, Plan};
use mechgen::{geometry, physics};
use mechgen_runtime::codegen::{
    Block, Pattern, Stage, VecBuffers, check_physics, first_load_fault,
};
use mechgen_runtime::nalgebra::Dyn;
use mechgen_runtime::{
    Accelerations, Forces, GeometryFault, Matrix, Mechanism, Names, Outputs, ParameterError,
    PhysicsFault, Quantity, Requirement, Structured, Subject, Unit, Vector, Velocities,
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
    /// The markers' values: the textbook tape, the same reading the trig cache, and names.
    markers: (Tape, Tape),
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
    /// One tape per branch invariant (its signed value), and the same reading the trig cache.
    branches: Vec<Tape>,
    cached_branches: Vec<Tape>,
    /// The solve plan, stage by stage, and the earlier stages each reads.
    stages: Vec<PlanStage>,
    reads: Vec<Vec<usize>>,
    /// Workspace sizes: largest block, most value slots, trig cache, force solve.
    largest: (usize, usize, usize, usize),
    /// Tape slots and output values, reused by every call (evaluation is `&self`).
    scratch: RefCell<Scratch>,
    /// Block Jacobian evaluations so far: the unit of a solve's work, which fuzzing bounds.
    evaluations: Cell<u64>,
}

/// One stage of the plan, with its tapes.
#[derive(Debug, Clone)]
enum PlanStage {
    Explicit {
        equations: Vec<usize>,
        coordinates: Vec<usize>,
        /// Positions, velocities, accelerations (the latter two if computed).
        levels: [Option<Tape>; 3],
        /// The sines and cosines the stage caches, and where.
        trig: Option<(Tape, Vec<usize>)>,
        /// The multipliers of its equations (force solve).
        multipliers: Option<Tape>,
    },
    Block {
        equations: Vec<usize>,
        coordinates: Vec<usize>,
        pattern: Vec<(usize, usize)>,
        slots: usize,
        /// Residuals, then Jacobian values.
        jacobian: Tape,
        factorization: Option<Factorization>,
        /// The slot of each static pivot (empty without a factorisation).
        pivots: Vec<usize>,
        velocity_rhs: Option<Tape>,
        acceleration_rhs: Option<Tape>,
        trig: Option<(Tape, Vec<usize>)>,
        /// The force solve's right-hand side.
        force_rhs: Option<Tape>,
    },
}

impl PlanStage {
    /// Stage `s` of `plan` (and of the force solve's plan `forces`), its tapes reading the trig
    /// cache as the generated kernels do.
    fn new(
        arena: &mechgen::expr::Arena,
        plan: &Plan,
        forces: Option<&ForceStage>,
        s: usize,
    ) -> Self {
        let tape = |roots: &[mechgen::expr::Id], phase: Phase| {
            Tape::with_inputs(arena, roots, &plan.trig.reads(arena, roots, s, phase))
        };
        let force_tape = |kind_matches: Option<&Vec<mechgen::expr::Id>>| {
            kind_matches.map(|roots| tape(roots, Phase::Final))
        };
        let fills: Vec<usize> = plan.trig.fills(s).collect();
        let trig = (!fills.is_empty()).then(|| {
            let roots: Vec<_> = fills
                .iter()
                .flat_map(|&m| {
                    let (sin, cos) = plan.trig.nodes[m];
                    [sin, cos]
                })
                .collect();
            let slots = fills.iter().flat_map(|&m| [2 * m, 2 * m + 1]).collect();
            (tape(&roots, Phase::Positions), slots)
        });
        match &plan.stages[s] {
            structure::Stage::Explicit(assignments) => {
                let level = |level: fn(&structure::Assignment) -> Option<mechgen::expr::Id>,
                             phase| {
                    let ids: Option<Vec<_>> = assignments.iter().map(level).collect();
                    ids.map(|ids| tape(&ids, phase))
                };
                PlanStage::Explicit {
                    equations: assignments.iter().map(|a| a.equation).collect(),
                    coordinates: assignments.iter().map(|a| a.coordinate).collect(),
                    levels: [
                        level(|a| Some(a.position), Phase::Positions),
                        level(|a| a.velocity, Phase::After),
                        level(|a| a.acceleration, Phase::After),
                    ],
                    trig,
                    multipliers: force_tape(match forces {
                        Some(ForceStage::Explicit(values)) => Some(values),
                        _ => None,
                    }),
                }
            }
            structure::Stage::Block(block) => {
                let roots: Vec<_> = block
                    .residuals
                    .iter()
                    .copied()
                    .chain(block.entries.iter().map(|e| e.2))
                    .collect();
                PlanStage::Block {
                    equations: block.equations.clone(),
                    coordinates: block.coordinates.clone(),
                    pattern: block.entries.iter().map(|&(r, c, _)| (r, c)).collect(),
                    slots: block.slots(),
                    jacobian: tape(&roots, Phase::Positions),
                    factorization: block.factorization.clone(),
                    pivots: block
                        .factorization
                        .as_ref()
                        .map(Factorization::pivots)
                        .unwrap_or_default(),
                    velocity_rhs: block.velocity_rhs.as_deref().map(|v| tape(v, Phase::After)),
                    acceleration_rhs: block
                        .acceleration_rhs
                        .as_deref()
                        .map(|v| tape(v, Phase::After)),
                    trig,
                    force_rhs: force_tape(match forces {
                        Some(ForceStage::Block(values)) => Some(values),
                        _ => None,
                    }),
                }
            }
        }
    }

    fn tapes(&self) -> impl Iterator<Item = &Tape> {
        let (levels, block, trig): (&[Option<Tape>], [Option<&Tape>; 4], _) = match self {
            PlanStage::Explicit {
                levels,
                trig,
                multipliers,
                ..
            } => (&levels[..], [multipliers.as_ref(), None, None, None], trig),
            PlanStage::Block {
                jacobian,
                velocity_rhs,
                acceleration_rhs,
                trig,
                force_rhs,
                ..
            } => (
                &[][..],
                [
                    Some(jacobian),
                    velocity_rhs.as_ref(),
                    acceleration_rhs.as_ref(),
                    force_rhs.as_ref(),
                ],
                trig,
            ),
        };
        levels
            .iter()
            .flatten()
            .chain(block.into_iter().flatten())
            .chain(trig.iter().map(|(tape, _)| tape))
    }

    fn trig(&self) -> Option<&(Tape, Vec<usize>)> {
        match self {
            PlanStage::Explicit { trig, .. } | PlanStage::Block { trig, .. } => trig.as_ref(),
        }
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
        let plan: &Plan = &scene.plan;
        let force_stages = scene.forces.as_ref().map(|f| &f.stages);
        let stages: Vec<PlanStage> = (0..plan.stages.len())
            .map(|s| PlanStage::new(arena, plan, force_stages.and_then(|f| f.get(s)), s))
            .collect();
        let forces = scene.forces.as_ref().map(|f| {
            (
                Tape::new(arena, &f.generalized),
                Tape::new(arena, &f.reactions),
            )
        });
        let cached_markers = {
            let reads = plan
                .trig
                .reads(arena, &kin.markers, plan.stages.len(), Phase::Final);
            Tape::with_inputs(arena, &kin.markers, &reads)
        };
        let markers = (Tape::new(arena, &kin.markers), cached_markers);
        let load_witnesses = Tape::new(arena, &scene.load_witnesses);
        let force_storage = scene.forces.as_ref().map_or(0, |_| {
            model.dim() + plan.blocks().map(structure::Block::slots).sum::<usize>()
        });
        let cached_branches: Vec<Tape> = kin
            .branches
            .iter()
            .map(|&b| {
                let cached = plan
                    .trig
                    .reads(arena, &[b], plan.stages.len(), Phase::Positions);
                Tape::with_inputs(arena, &[b], &cached)
            })
            .collect();
        let slots = tapes
            .iter()
            .chain(&nu)
            .chain(&gamma)
            .chain(forces.iter().flat_map(|(f, r)| [f, r]))
            .chain([&markers.0, &markers.1, &load_witnesses])
            .chain([&lengths, &geometry_values, &physics_values])
            .chain(&branches)
            .chain(&cached_branches)
            .chain(stages.iter().flat_map(PlanStage::tapes))
            .map(Tape::len)
            .max()
            .unwrap_or(0);
        let values = both
            .len()
            .max(model.dim())
            .max(kin.length_scale.dependent.len())
            .max(kin.geometry.len())
            .max(kin.physics.len())
            .max(plan.largest_block() + plan.largest_slots())
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
            cached_branches,
            stages,
            reads: plan.reads.clone(),
            largest: (
                plan.largest_block(),
                plan.largest_slots(),
                plan.trig.len(),
                force_storage,
            ),
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
        self.run(&self.markers.0, inputs, |v| {
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
                mechgen_runtime::codegen::check_geometry(
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
        VecBuffers::new(
            self.largest.0,
            self.largest.1,
            self.stages.len().max(1),
            self.coordinates.len(),
            self.largest.2,
            self.largest.3,
        )
    }

    fn stage_count(&self) -> usize {
        self.stages.len()
    }

    fn stage(&self, index: usize) -> Option<Stage<'_>> {
        let reads = self.reads.get(index)?;
        Some(match self.stages.get(index)? {
            PlanStage::Explicit {
                equations,
                coordinates,
                ..
            } => Stage::Explicit {
                equations,
                coordinates,
                reads,
            },
            PlanStage::Block {
                equations,
                coordinates,
                pattern,
                slots,
                pivots,
                ..
            } => Stage::Block(Block {
                equations,
                coordinates,
                pattern: Pattern::Sparse(pattern),
                slots: *slots,
                pivots,
                reads,
            }),
        })
    }

    fn assign_positions(&self, stage: usize, q: &mut Vector<Dyn>, trig: &[f64], t: f64) {
        let inputs = self.inputs_with(q.as_slice(), &[], &[], trig, t);
        if self.evaluate_level(stage, 0, inputs) {
            self.write_level(stage, q);
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
        if self.evaluate_level(stage, 1, inputs) {
            self.write_level(stage, qd);
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
        if self.evaluate_level(stage, 2, inputs) {
            self.write_level(stage, qdd);
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
        if let Some(PlanStage::Block {
            jacobian, pattern, ..
        }) = self.stages.get(stage)
        {
            let inputs = self.inputs_with(q.as_slice(), &[], &[], trig, t);
            self.run(jacobian, inputs, |v| {
                let (residuals, entries) = v.split_at(phi.len());
                phi.copy_from_slice(residuals);
                values[..pattern.len()].copy_from_slice(&entries[..pattern.len()]);
            });
        }
    }

    fn fill_trig(&self, stage: usize, q: &Vector<Dyn>, trig: &mut [f64]) {
        if let Some((tape, slots)) = self.stages.get(stage).and_then(PlanStage::trig) {
            self.run(tape, self.inputs(q.as_slice(), &[], 0.0), |v| {
                for (&slot, &value) in slots.iter().zip(v) {
                    trig[slot] = value;
                }
            });
        }
    }

    fn branch(&self, index: usize, q: &Vector<Dyn>, trig: &[f64]) -> f64 {
        let Some(tape) = self.cached_branches.get(index) else {
            return f64::NAN;
        };
        let mut value = f64::NAN;
        let inputs = self.inputs_with(q.as_slice(), &[], &[], trig, 0.0);
        self.run(tape, inputs, |v| {
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
        let inputs = self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), trig, t);
        self.run(&self.markers.1, inputs, |v| {
            out.iter_mut().zip(v).for_each(|(o, v)| *o = *v);
        });
    }

    fn factor(&self, stage: usize, values: &mut [f64], tiny: f64, limit: f64) -> Result<(), usize> {
        match self.factorization(stage) {
            Some(f) if values.len() >= f.slots => f.factor(values, tiny, limit),
            _ => Err(0),
        }
    }

    fn solve(&self, stage: usize, values: &[f64], x: &mut [f64]) {
        if let Some(f) = self.factorization(stage) {
            f.solve(values, x);
        }
    }

    fn solve_transpose(&self, stage: usize, values: &[f64], x: &mut [f64]) {
        if let Some(f) = self.factorization(stage) {
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
        match self.stages.get(stage) {
            Some(PlanStage::Block {
                velocity_rhs: Some(tape),
                ..
            }) => {
                let inputs = self.inputs_with(q.as_slice(), qd.as_slice(), &[], trig, t);
                self.run(tape, inputs, |v| out.copy_from_slice(&v[..out.len()]));
            }
            _ => out.fill(f64::NAN),
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
        match self.stages.get(stage) {
            Some(PlanStage::Block {
                acceleration_rhs: Some(tape),
                ..
            }) => {
                let inputs = self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), trig, t);
                self.run(tape, inputs, |v| out.copy_from_slice(&v[..out.len()]));
            }
            _ => out.fill(f64::NAN),
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
        let Some(PlanStage::Explicit {
            equations,
            multipliers,
            ..
        }) = self.stages.get(stage)
        else {
            return;
        };
        let inputs = Inputs {
            lambda,
            ..self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), trig, t)
        };
        // Every multiplier is computed before any is written, as generated code loads first.
        let mut scratch = self.scratch.borrow_mut();
        let Scratch { slots, values } = &mut *scratch;
        match multipliers {
            Some(tape) => tape.eval(inputs, slots, values),
            None => values.fill(f64::NAN),
        }
        for (&e, &v) in equations.iter().zip(values.iter()) {
            if let Some(l) = lambda.get_mut(e) {
                *l = v;
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
        match self.stages.get(stage) {
            Some(PlanStage::Block {
                force_rhs: Some(tape),
                ..
            }) => {
                let inputs = Inputs {
                    lambda,
                    ..self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), trig, t)
                };
                self.run(tape, inputs, |v| out.copy_from_slice(&v[..out.len()]));
            }
            _ => out.fill(f64::NAN),
        }
    }
}

impl Interpreted {
    fn factorization(&self, stage: usize) -> Option<&Factorization> {
        match self.stages.get(stage)? {
            PlanStage::Block { factorization, .. } => factorization.as_ref(),
            PlanStage::Explicit { .. } => None,
        }
    }

    /// Evaluates level `level` (positions, velocities, accelerations) of an explicit stage into
    /// the scratch values; false if the stage has no such level. Every value is computed
    /// before [`Interpreted::write_level`] writes any back, as generated code loads its inputs
    /// first.
    fn evaluate_level(&self, stage: usize, level: usize, inputs: Inputs<'_>) -> bool {
        let Some(PlanStage::Explicit { levels, .. }) = self.stages.get(stage) else {
            return false;
        };
        let Some(tape) = &levels[level] else {
            return false;
        };
        let mut scratch = self.scratch.borrow_mut();
        let Scratch { slots, values } = &mut *scratch;
        tape.eval(inputs, slots, values);
        true
    }

    /// Writes the values of [`Interpreted::evaluate_level`] to the stage's coordinates of `out`.
    fn write_level(&self, stage: usize, out: &mut Vector<Dyn>) {
        if let Some(PlanStage::Explicit { coordinates, .. }) = self.stages.get(stage) {
            let scratch = self.scratch.borrow();
            for (&c, &v) in coordinates.iter().zip(&scratch.values) {
                out[c] = v;
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
