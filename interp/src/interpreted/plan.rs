//! The plan of an interpreted scene: its kernel list (`mechgen::plan::kernels`) compiled into tapes,
//! behind the runtime's `Structured` trait. Where generated code has a `match` on the stage,
//! a method here looks the stage's kernel up in a table.

use mechgen::expr::tape::{Inputs, Tape};
use mechgen::plan::kernels::{self, Buffer, Method};
use mechgen_runtime::codegen::{Block, Pattern, Stage, VecBuffers};
use mechgen_runtime::nalgebra::Dyn;
use mechgen_runtime::{Structured, Vector};

use super::{Interpreted, Scratch};

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

/// The scene's kernel list (`mechgen::plan::kernels`) compiled: the `Structured` methods look up
/// the kernel of a stage and method in a table, where generated code has a `match`.
#[derive(Debug, Clone)]
pub(super) struct PlanTapes {
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
    pub(super) fn new(arena: &mechgen::expr::Arena, list: &kernels::Kernels) -> Self {
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

    pub(super) fn tapes(&self) -> impl Iterator<Item = &Tape> {
        self.kernels
            .iter()
            .chain(&self.markers)
            .chain(&self.branches)
            .map(|k| &k.tape)
    }
}

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
