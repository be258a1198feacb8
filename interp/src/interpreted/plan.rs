//! The plan of an interpreted scene: its kernel list (`mechgen::plan::kernels`) compiled into tapes,
//! behind the runtime's `Structured` trait. Where generated code has a `match` on the stage,
//! a method here looks the stage's kernel up in a table.

use mechgen::expr::Var;
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
    /// Where its values go, grouped by buffer (a block's Jacobian writes two).
    groups: Vec<Group>,
    /// The length each buffer it writes must have (`Kernels::buffer_len`, looked up once).
    lengths: Vec<(Buffer, usize)>,
    /// Whether it reads the trig cache and the multipliers.
    reads_trig: bool,
    reads_lambda: bool,
}

impl Compiled {
    /// `kernel` as a tape; `length` gives the length each buffer it writes must have.
    fn new(
        arena: &mechgen::expr::Arena,
        kernel: &kernels::Kernel,
        length: impl Fn(Buffer) -> usize,
    ) -> Self {
        let groups = Group::of(&kernel.outputs);
        Compiled {
            tape: Tape::with_inputs(arena, &kernel.roots, &kernel.cached),
            lengths: groups
                .iter()
                .map(|g| (g.buffer, length(g.buffer)))
                .collect(),
            groups,
            reads_trig: !kernel.cached.is_empty(),
            reads_lambda: kernel
                .roots
                .iter()
                .any(|&root| (arena.variables(root).iter()).any(|v| matches!(v, Var::Lambda(_)))),
        }
    }
}

/// A run of a kernel's values that go to one buffer.
#[derive(Debug, Clone)]
struct Group {
    buffer: Buffer,
    /// The first of its values among the kernel's.
    start: usize,
    /// The index in the buffer of each value; `None` when they are `0, 1, 2, …` (a block's
    /// residuals, its Jacobian values, a right-hand side), copied as one slice.
    at: Option<Vec<usize>>,
    len: usize,
}

impl Group {
    /// The groups of `outputs`, in order.
    fn of(outputs: &[(Buffer, usize)]) -> Vec<Group> {
        let mut groups: Vec<Group> = Vec::new();
        for (k, &(buffer, _)) in outputs.iter().enumerate() {
            match groups.last_mut() {
                Some(g) if g.buffer == buffer => g.len += 1,
                _ => groups.push(Group {
                    buffer,
                    start: k,
                    at: None,
                    len: 1,
                }),
            }
        }
        for g in &mut groups {
            let at: Vec<usize> = outputs[g.start..g.start + g.len]
                .iter()
                .map(|o| o.1)
                .collect();
            if at.iter().enumerate().any(|(j, &i)| i != j) {
                g.at = Some(at);
            }
        }
        groups
    }
}

/// The scene's kernel list (`mechgen::plan::kernels`) compiled: the `Structured` methods look up
/// the kernel of a stage and method in a table, where generated code has a `match`.
#[derive(Debug, Clone)]
pub(super) struct PlanTapes {
    /// The kernel list's stage table, static LUs and workspace sizes (its kernels are below,
    /// compiled).
    list: kernels::Kernels,
    /// Per method (`[method as usize]`): whether any stage has a kernel of it, and whether
    /// any of those reads the trig cache and the multipliers (generated code then views the
    /// runtime's slices as arrays before it dispatches on the stage).
    present: [bool; Method::ALL.len()],
    views: [(bool, bool); Method::ALL.len()],
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
        // The markers and branches are read through their own methods, which check nothing.
        let compile = |kernel: &kernels::Kernel| Compiled::new(arena, kernel, |_| 0);
        let kernels: Vec<Compiled> = (list.stages.iter())
            .map(|k| Compiled::new(arena, &k.kernel, |b| list.buffer_len(k.stage, b)))
            .collect();
        let of = |m: Method| {
            let stages = list.stages.iter().zip(&kernels);
            stages.filter(move |(k, _)| k.method == m).map(|(_, c)| c)
        };
        PlanTapes {
            dispatch,
            present: Method::ALL.map(|m| of(m).next().is_some()),
            views: Method::ALL.map(|m| {
                let lambda = m == Method::Multipliers || of(m).any(|c| c.reads_lambda);
                (of(m).any(|c| c.reads_trig), lambda)
            }),
            kernels,
            markers: list.markers.as_ref().map(compile),
            branches: list.branches.iter().map(compile).collect(),
            list: kernels::Kernels {
                stages: Vec::new(),
                markers: None,
                branches: Vec::new(),
                ..list.clone()
            },
        }
    }

    /// Stage `stage`'s kernel of `method`, if it has one.
    fn kernel(&self, stage: usize, method: Method) -> Option<&Compiled> {
        let k = (*self.dispatch.get(stage)?)[method as usize]?;
        self.kernels.get(k)
    }

    /// What a call of `method` for `stage` finds, given the lengths of the slices it was
    /// passed: the trig cache's and the multipliers' (`views`, which the method views whole
    /// whatever the stage), and each output's (which the stage's kernel views).
    fn find(
        &self,
        stage: usize,
        method: Method,
        views: [usize; 2],
        outputs: &[(Buffer, usize)],
    ) -> Found<'_> {
        let m = method as usize;
        if !self.present[m] {
            return Found::Nowhere;
        }
        let (trig, lambda) = self.views[m];
        let sizes = &self.list.sizes;
        if (trig && views[0] < sizes.trig) || (lambda && views[1] < sizes.coordinates) {
            return Found::Short;
        }
        let Some(kernel) = self.kernel(stage, method) else {
            return Found::Elsewhere;
        };
        let needs = |buffer: Buffer| {
            let length = kernel.lengths.iter().find(|l| l.0 == buffer);
            length.map_or(0, |l| l.1)
        };
        if outputs.iter().all(|&(buffer, len)| len >= needs(buffer)) {
            Found::Kernel(kernel)
        } else {
            Found::Short
        }
    }

    pub(super) fn tapes(&self) -> impl Iterator<Item = &Tape> {
        self.kernels
            .iter()
            .chain(&self.markers)
            .chain(&self.branches)
            .map(|k| &k.tape)
    }
}

/// What a `Structured` method finds for a stage, and so what it writes, as generated code
/// does.
enum Found<'a> {
    /// The stage's kernel: its values.
    Kernel(&'a Compiled),
    /// No kernel here but other stages have one: generated code's `match` falls through,
    /// writing nothing.
    Elsewhere,
    /// No stage has one: generated code has no such method and the trait's default runs.
    Nowhere,
    /// A buffer shorter than the kernel's arrays: generated code cannot view it as one and
    /// writes NaN to its outputs rather than leave stale values.
    Short,
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
        let assigning = self.assigning(stage, Method::Positions, trig.len(), q.as_mut_slice());
        if let Some(kernel) = assigning {
            self.evaluate(kernel, self.inputs_with(q.as_slice(), &[], &[], trig, t));
            self.scatter(kernel, Method::Positions.target(), q.as_mut_slice());
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
        let assigning = self.assigning(stage, Method::Velocities, trig.len(), qd.as_mut_slice());
        if let Some(kernel) = assigning {
            self.evaluate(
                kernel,
                self.inputs_with(q.as_slice(), qd.as_slice(), &[], trig, t),
            );
            self.scatter(kernel, Method::Velocities.target(), qd.as_mut_slice());
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
        let assigning =
            self.assigning(stage, Method::Accelerations, trig.len(), qdd.as_mut_slice());
        if let Some(kernel) = assigning {
            self.evaluate(
                kernel,
                self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), trig, t),
            );
            self.scatter(kernel, Method::Accelerations.target(), qdd.as_mut_slice());
        }
    }

    fn closed_form(&self, stage: usize, q: &Vector<Dyn>, trig: &[f64], t: f64, out: &mut [f64]) {
        let outputs = [(Buffer::Candidates, out.len())];
        match self
            .plan
            .find(stage, Method::ClosedForm, [trig.len(), 0], &outputs)
        {
            Found::Kernel(kernel) => {
                self.evaluate(kernel, self.inputs_with(q.as_slice(), &[], &[], trig, t));
                self.scatter(kernel, Buffer::Candidates, out);
            }
            Found::Short => out.fill(f64::NAN),
            // Without a kernel, generated code leaves the candidates alone (the trait's default).
            Found::Elsewhere | Found::Nowhere => {}
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
        let outputs = [(Buffer::Phi, phi.len()), (Buffer::Values, values.len())];
        match self
            .plan
            .find(stage, Method::Jacobian, [trig.len(), 0], &outputs)
        {
            Found::Kernel(kernel) => {
                self.evaluate(kernel, self.inputs_with(q.as_slice(), &[], &[], trig, t));
                self.scatter(kernel, Buffer::Phi, phi);
                self.scatter(kernel, Method::Jacobian.target(), values);
            }
            Found::Short => {
                phi.fill(f64::NAN);
                values.fill(f64::NAN);
            }
            Found::Elsewhere | Found::Nowhere => {}
        }
    }

    fn fill_trig(&self, stage: usize, q: &Vector<Dyn>, trig: &mut [f64]) {
        let assigning = self.assigning(stage, Method::FillTrig, trig.len(), trig);
        if let Some(kernel) = assigning {
            self.evaluate(kernel, self.inputs(q.as_slice(), &[], 0.0));
            self.scatter(kernel, Method::FillTrig.target(), trig);
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
        let found = self.plan.find(
            stage,
            Method::VelocityRhs,
            [trig.len(), 0],
            &[(Buffer::Out, out.len())],
        );
        let inputs = self.inputs_with(q.as_slice(), qd.as_slice(), &[], trig, t);
        self.right_hand_side(found, inputs, out);
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
        let outputs = [(Buffer::Out, out.len())];
        let found = self
            .plan
            .find(stage, Method::AccelerationRhs, [trig.len(), 0], &outputs);
        let inputs = self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), trig, t);
        self.right_hand_side(found, inputs, out);
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
        let outputs = [(Buffer::Lambda, lambda.len())];
        match self.plan.find(
            stage,
            Method::Multipliers,
            [trig.len(), lambda.len()],
            &outputs,
        ) {
            Found::Kernel(kernel) => {
                let inputs = Inputs {
                    lambda,
                    ..self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), trig, t)
                };
                self.evaluate(kernel, inputs);
                self.scatter(kernel, Method::Multipliers.target(), lambda);
            }
            Found::Short => lambda.fill(f64::NAN),
            Found::Elsewhere => {}
            // The trait's default: an explicit stage's multipliers are unknown.
            Found::Nowhere => {
                let shape = self.plan.list.shapes.get(stage);
                let explicit = shape.filter(|s| s.block.is_none());
                for &e in explicit.into_iter().flat_map(|s| &s.equations) {
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
        let found = self.plan.find(
            stage,
            Method::ForceRhs,
            [trig.len(), lambda.len()],
            &[(Buffer::Out, out.len())],
        );
        let inputs = Inputs {
            lambda,
            ..self.inputs_with(q.as_slice(), qd.as_slice(), qdd.as_slice(), trig, t)
        };
        self.right_hand_side(found, inputs, out);
    }
}

impl Interpreted {
    /// The kernel an assignment of `method` (positions, rates or cache slots, into `out`, with a
    /// trig cache of `trig` slots) runs for `stage`; NaN in `out` where the buffers do not fit;
    /// nothing without a kernel (the trait's default writes nothing).
    fn assigning(
        &self,
        stage: usize,
        method: Method,
        trig: usize,
        out: &mut [f64],
    ) -> Option<&Compiled> {
        let outputs = [(method.target(), out.len())];
        match self.plan.find(stage, method, [trig, 0], &outputs) {
            Found::Kernel(kernel) => Some(kernel),
            Found::Short => {
                out.fill(f64::NAN);
                None
            }
            Found::Elsewhere | Found::Nowhere => None,
        }
    }

    /// A block's right-hand side: the kernel's values, or NaN where the buffers do not fit or
    /// no stage has such a kernel (the trait's default).
    fn right_hand_side(&self, found: Found<'_>, inputs: Inputs<'_>, out: &mut [f64]) {
        match found {
            Found::Kernel(kernel) => {
                self.evaluate(kernel, inputs);
                self.scatter(kernel, Buffer::Out, out);
            }
            Found::Short | Found::Nowhere => out.fill(f64::NAN),
            Found::Elsewhere => {}
        }
    }

    /// Evaluates `kernel` into the scratch values. Every value is computed before
    /// [`Interpreted::scatter`] writes any back, as generated code loads its inputs first.
    fn evaluate(&self, kernel: &Compiled, inputs: Inputs<'_>) {
        let mut scratch = self.scratch.borrow_mut();
        let Scratch { slots, values } = &mut *scratch;
        kernel.tape.eval(inputs, slots, values);
    }

    /// Writes the values of [`Interpreted::evaluate`] that `kernel` sends to `buffer` into
    /// `out`, at their indices.
    fn scatter(&self, kernel: &Compiled, buffer: Buffer, out: &mut [f64]) {
        let scratch = self.scratch.borrow();
        for g in kernel.groups.iter().filter(|g| g.buffer == buffer) {
            let values = scratch.values.get(g.start..g.start + g.len).unwrap_or(&[]);
            match &g.at {
                None => {
                    let n = values.len().min(out.len());
                    out[..n].copy_from_slice(&values[..n]);
                }
                Some(at) => {
                    for (&i, &v) in at.iter().zip(values) {
                        if let Some(o) = out.get_mut(i) {
                            *o = v;
                        }
                    }
                }
            }
        }
    }
}
