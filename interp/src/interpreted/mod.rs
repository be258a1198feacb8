//! A compiled scene evaluated by the interpreter, behind the runtime's `Mechanism` (the
//! textbook functions, `textbook`), `Structured` (the plan's kernels, `plan`) and
//! `EquationsOfMotion` (`motion`) traits.
//!
//! This is what a run-time (non-generated) library would do: the same IR and the same kernel
//! list as the generated code, walked at run time (tapes for the expressions, the static LU's
//! operation list for the factorisations). It lets the CLI, the tests and the report drive the
//! one solver implementation of `mechgen-runtime` with scenes read from `.mech` files, and it
//! agrees with generated code to the bit.

mod free;
mod motion;
mod plan;
mod textbook;

use std::cell::{Cell, RefCell};

use mechgen::Scene;
use mechgen::expr::tape::{Inputs, Tape};
use mechgen::model::geometry;
use mechgen::model::kinematics::LengthScale;
use mechgen::model::physics;
use mechgen_runtime::nalgebra::Dyn;
use mechgen_runtime::{Matrix, Names, Outputs, Unit};

use free::FreeDofs;
use motion::MotionTapes;
use plan::PlanTapes;
use textbook::{Textbook, unit};

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
    reaction_names: Vec<String>,
    marker_names: Vec<String>,
    branch_names: Vec<String>,
    /// Every name, `'static` for the errors the solver returns (interned, see `names`).
    names: &'static Names,
    outputs: Outputs,
    /// Structural non-zeros of Φ_q, in the order the Jacobian tape produces them.
    pattern: Vec<(usize, usize)>,
    coordinate_units: Vec<Unit>,
    equation_units: Vec<Unit>,
    /// The folded constant lengths (the parameter-dependent ones are a textbook tape).
    length_scale: LengthScale,
    /// The rules of the geometry and of the physics written in parameters.
    geometry: Vec<geometry::Check>,
    physics: Vec<physics::Check>,
    /// The functions of the whole state.
    textbook: Textbook,
    /// The plan's kernels as tapes.
    plan: PlanTapes,
    /// The equations of motion, for a scene compiled with them.
    motion: Option<MotionTapes>,
    /// The free degrees of freedom, with the state the tapes read.
    free: FreeDofs,
    /// Tape slots and output values, reused by every call (evaluation is `&self`).
    scratch: RefCell<Scratch>,
    /// Block Jacobian evaluations so far: the unit of a solve's work, which fuzzing bounds.
    evaluations: Cell<u64>,
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
        let textbook = Textbook::new(scene);
        let plan = PlanTapes::new(&model.arena, &scene.kernels);
        let motion = (scene.motion.as_ref()).map(|m| MotionTapes::new(&model.arena, m));
        let free = FreeDofs::new(scene);
        // One scratch serves every tape: the most instructions and the most outputs of any.
        let tapes = || {
            (textbook.tapes().chain(plan.tapes()))
                .chain(motion.iter().flat_map(MotionTapes::tapes))
                .chain([free.tape()])
        };
        let slots = tapes().map(Tape::len).max().unwrap_or(0);
        let values = tapes().map(Tape::output_count).max().unwrap_or(0).max(1);
        let outputs = match model.outputs {
            mechgen::model::Outputs::Positions => Outputs::Positions,
            mechgen::model::Outputs::Velocities => Outputs::Velocities,
            mechgen::model::Outputs::Accelerations => Outputs::Accelerations,
            mechgen::model::Outputs::Forces => Outputs::Forces,
        };
        let parameters: Vec<String> = model.params.iter().map(|p| p.name.to_string()).collect();
        let branches: Vec<String> = model.branches.iter().map(|b| b.name.clone()).collect();
        Interpreted {
            name: model.name.to_string(),
            coordinates: model.coordinate_names(),
            equations: model.equation_names(),
            params: model.params.iter().map(|p| p.default).collect(),
            derived_names: model.derived.iter().map(|d| d.name.to_string()).collect(),
            reaction_names: model.reaction_names(),
            marker_names: model.marker_names(),
            names: crate::names::intern([
                vec![model.name.to_string()],
                model.coordinate_names(),
                model.equation_names(),
                parameters.clone(),
                branches.clone(),
                model.marker_names(),
                model.loads.iter().map(|l| l.name.clone()).collect(),
            ]),
            param_names: parameters,
            branch_names: branches,
            outputs,
            pattern: kin.jacobian.iter().map(|e| (e.row, e.col)).collect(),
            coordinate_units: model.coordinate_units().into_iter().map(unit).collect(),
            equation_units: model.equation_units().into_iter().map(unit).collect(),
            length_scale: kin.length_scale.clone(),
            geometry: kin.geometry.clone(),
            physics: kin.physics.clone(),
            textbook,
            plan,
            motion,
            free,
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
            free: &self.free.state,
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
