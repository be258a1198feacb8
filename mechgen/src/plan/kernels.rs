//! The plan's kernels as data: every decision about what the staged solve computes, made once
//! per scene, for its two consumers.
//!
//! A kernel is a list of expressions (its roots) evaluated together: what it reads from the
//! trig cache, and where each value goes. The structured solve calls kernels through the
//! runtime's `Structured` trait, one [`Method`] per kind, dispatched on the stage index. The
//! emitter (`emit::plan`) renders each kernel as a function and each method as a `match` over
//! its stages; the interpreter (crate `mechgen-interp`) compiles each kernel into a tape and
//! each method into a table lookup. Neither decides anything this module has not: which phase
//! a level runs in (so which trig slots it may read), a block's roots (residuals, then the
//! Jacobian's entries), which angles the trig cache holds (planned here from the kernels
//! themselves, `trig`), which static LU a block shares, which stages have a force kernel, the
//! buffers' lengths and the workspace's sizes.

use std::collections::HashMap;

use crate::expr::{Arena, Id};
use crate::plan::reactions::{ForceStage, Forces};
use crate::plan::structure::{Assignment, Block, Plan, Stage};
use crate::plan::trig::{self, Phase, TrigCache};
use crate::sparse::factor::Factorization;

/// A kind of per-stage kernel: the `Structured` method that runs it.
///
/// The order is the order of a stage's kernels in generated code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Method {
    /// An explicit stage's positions, written to `q` at its coordinates.
    Positions,
    /// An explicit stage's velocities, written to `qd`.
    Velocities,
    /// An explicit stage's accelerations, written to `qdd`.
    Accelerations,
    /// A block's two closed-form solutions (to `out`, candidate-major), where it has them.
    ClosedForm,
    /// A block's residuals (to `phi`) and Jacobian values (to `values`, in pattern order).
    Jacobian,
    /// A block's velocity right-hand side, to `out`.
    VelocityRhs,
    /// A block's acceleration right-hand side, to `out`.
    AccelerationRhs,
    /// The sines and cosines of the angles a stage solves, to their slots of the trig cache.
    FillTrig,
    /// An explicit stage's multipliers (force solve), to `lambda` at its equations.
    Multipliers,
    /// A block's force right-hand side (force solve), to `out`.
    ForceRhs,
}

impl Method {
    /// Every method, in kernel order.
    pub const ALL: [Method; 10] = [
        Method::Positions,
        Method::Velocities,
        Method::Accelerations,
        Method::ClosedForm,
        Method::Jacobian,
        Method::VelocityRhs,
        Method::AccelerationRhs,
        Method::FillTrig,
        Method::Multipliers,
        Method::ForceRhs,
    ];

    /// When its kernels run, which decides the trig slots they may read ([`Phase::ready`]):
    /// a stage's positions, Jacobian and the sines it fills only from earlier stages, its
    /// rates also from its own, the force solve from every stage.
    pub fn phase(self) -> Phase {
        match self {
            Method::Positions | Method::ClosedForm | Method::Jacobian | Method::FillTrig => {
                Phase::Positions
            }
            Method::Velocities
            | Method::Accelerations
            | Method::VelocityRhs
            | Method::AccelerationRhs => Phase::After,
            Method::Multipliers | Method::ForceRhs => Phase::Final,
        }
    }

    /// The state its kernels may read besides the trig cache and time.
    pub fn inputs(self) -> &'static [Input] {
        match self {
            Method::Positions | Method::ClosedForm | Method::Jacobian | Method::FillTrig => {
                &[Input::Q]
            }
            Method::Velocities | Method::VelocityRhs => &[Input::Q, Input::Qd],
            Method::Accelerations | Method::AccelerationRhs => &[Input::Q, Input::Qd, Input::Qdd],
            Method::Multipliers | Method::ForceRhs => {
                &[Input::Q, Input::Qd, Input::Qdd, Input::Lambda]
            }
        }
    }

    /// The buffer its kernels write (a block's Jacobian also writes [`Buffer::Phi`]).
    pub fn target(self) -> Buffer {
        match self {
            Method::Positions => Buffer::Q,
            Method::Velocities => Buffer::Qd,
            Method::Accelerations => Buffer::Qdd,
            Method::ClosedForm => Buffer::Candidates,
            Method::Jacobian => Buffer::Values,
            Method::VelocityRhs | Method::AccelerationRhs | Method::ForceRhs => Buffer::Out,
            Method::FillTrig => Buffer::Trig,
            Method::Multipliers => Buffer::Lambda,
        }
    }
}

/// State a kernel reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Input {
    /// Positions.
    Q,
    /// Velocities.
    Qd,
    /// Accelerations.
    Qdd,
    /// Multipliers.
    Lambda,
}

impl Input {
    /// The parameter's name in the `Structured` methods.
    pub fn name(self) -> &'static str {
        match self {
            Input::Q => "q",
            Input::Qd => "qd",
            Input::Qdd => "qdd",
            Input::Lambda => "lambda",
        }
    }
}

/// Where a kernel writes: the `Structured` method's output parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Buffer {
    /// Positions, at coordinates.
    Q,
    /// Velocities, at coordinates.
    Qd,
    /// Accelerations, at coordinates.
    Qdd,
    /// Multipliers, at equations.
    Lambda,
    /// The trig cache, at slots.
    Trig,
    /// A block's residuals.
    Phi,
    /// A block's Jacobian values, in pattern order.
    Values,
    /// A right-hand side or a list of values, from 0.
    Out,
    /// A block's closed-form candidates: two solutions of its coordinates, two entries per
    /// coordinate (see [`crate::plan::closed::ClosedForm::candidates`]), from 0.
    Candidates,
}

impl Buffer {
    /// The parameter's name in the `Structured` methods.
    pub fn name(self) -> &'static str {
        match self {
            Buffer::Q => "q",
            Buffer::Qd => "qd",
            Buffer::Qdd => "qdd",
            Buffer::Lambda => "lambda",
            Buffer::Trig => "trig",
            Buffer::Phi => "phi",
            Buffer::Values => "values",
            Buffer::Out | Buffer::Candidates => "out",
        }
    }
}

/// Expressions evaluated together, reading the trig cache where it is filled.
#[derive(Debug, Clone)]
pub struct Kernel {
    /// The values, in output order.
    pub roots: Vec<Id>,
    /// Where each root's value goes (parallel to `roots`).
    pub outputs: Vec<(Buffer, usize)>,
    /// The cached sines and cosines the kernel reads, with their slots.
    pub cached: HashMap<Id, usize>,
}

impl Kernel {
    /// The kernel of `roots` writing `outputs`, run by stage `stage` in `phase`: it reads the
    /// cached sines and cosines that are filled by then.
    fn new(
        arena: &Arena,
        trig: &TrigCache,
        (roots, outputs): Draft,
        stage: usize,
        phase: Phase,
    ) -> Self {
        let cached = trig.reads(arena, &roots, stage, phase);
        Kernel {
            roots,
            outputs,
            cached,
        }
    }

    /// A kernel whose `i`-th value goes to `out[i]`, run after stage `stage - 1`.
    fn listed(arena: &Arena, trig: &TrigCache, roots: &[Id], stage: usize, phase: Phase) -> Self {
        let outputs = (0..roots.len()).map(|i| (Buffer::Out, i)).collect();
        Kernel::new(arena, trig, (roots.to_vec(), outputs), stage, phase)
    }
}

/// A kernel before the trig cache is planned: its roots and where each value goes.
type Draft = (Vec<Id>, Vec<(Buffer, usize)>);

/// A kernel of one stage, run by one method.
#[derive(Debug, Clone)]
pub struct StageKernel {
    /// The stage.
    pub stage: usize,
    /// The method that runs it.
    pub method: Method,
    /// What it computes and where it writes.
    pub kernel: Kernel,
}

/// What the runtime's `Stage` table says about a stage.
#[derive(Debug, Clone)]
pub struct StageShape {
    /// The equations it solves.
    pub equations: Vec<usize>,
    /// The coordinates it solves for, in the same order.
    pub coordinates: Vec<usize>,
    /// The earlier stages it reads.
    pub reads: Vec<usize>,
    /// A Newton block's sparse system; `None` for an explicit stage.
    pub block: Option<BlockShape>,
}

/// A Newton block's sparse system.
#[derive(Debug, Clone)]
pub struct BlockShape {
    /// The Jacobian's structural non-zeros (row, column) in the block, in value order.
    pub pattern: Vec<(usize, usize)>,
    /// Value slots: the entries, then the static LU's fill-in.
    pub slots: usize,
    /// The value slot of each static pivot (empty without a static LU).
    pub pivots: Vec<usize>,
    /// Its static LU, an index into [`Kernels::factorizations`] (shared by blocks with the
    /// same pattern); `None` when the block pivots at run time.
    pub factorization: Option<usize>,
}

/// The storage the structured solve needs (the runtime's `Buffers` parameters).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sizes {
    /// Equations of the largest block.
    pub largest_block: usize,
    /// Value slots of the block with the most.
    pub largest_slots: usize,
    /// Stages (at least 1: the runtime's arrays are never empty).
    pub stages: usize,
    /// Coordinates.
    pub coordinates: usize,
    /// Trig cache slots.
    pub trig: usize,
    /// For a scene that computes forces: the multipliers, then every block's archived factors.
    pub forces: Option<usize>,
}

/// Every kernel of a scene's plan, and what the dispatch needs to run them.
#[derive(Debug, Clone)]
pub struct Kernels {
    /// The per-stage kernels, by stage, then in [`Method`] order.
    pub stages: Vec<StageKernel>,
    /// The runtime's stage table.
    pub shapes: Vec<StageShape>,
    /// The distinct static LUs, in order of first use.
    pub factorizations: Vec<Factorization>,
    /// The markers at the solved state, reading the whole trig cache; `None` without markers.
    pub markers: Option<Kernel>,
    /// Each branch invariant at the solved positions, reading the trig cache.
    pub branches: Vec<Kernel>,
    /// The trig cache the kernels fill and read, planned from them.
    pub trig: TrigCache,
    /// The workspace.
    pub sizes: Sizes,
}

impl Kernels {
    /// The kernels of `method`, in stage order.
    pub fn of(&self, method: Method) -> impl Iterator<Item = &StageKernel> {
        self.stages.iter().filter(move |k| k.method == method)
    }

    /// The length of `buffer` as stage `s`'s kernels see it: a state vector or the
    /// multipliers, one per coordinate; the trig cache; a block's residuals or right-hand
    /// side, one per equation; its value slots.
    pub fn buffer_len(&self, s: usize, buffer: Buffer) -> usize {
        let shape = self.shapes.get(s);
        match buffer {
            Buffer::Q | Buffer::Qd | Buffer::Qdd | Buffer::Lambda => self.sizes.coordinates,
            Buffer::Trig => self.sizes.trig,
            Buffer::Phi | Buffer::Out => shape.map_or(0, |s| s.equations.len()),
            Buffer::Candidates => shape.map_or(0, |s| 4 * s.equations.len()),
            Buffer::Values => shape.and_then(|s| s.block.as_ref()).map_or(0, |b| b.slots),
        }
    }

    /// The static LU of stage `s`, if it is a block that has one.
    pub fn factorization(&self, s: usize) -> Option<&Factorization> {
        let index = self.shapes.get(s)?.block.as_ref()?.factorization?;
        self.factorizations.get(index)
    }
}

/// The kernels of `plan` (and of the force solve, for a scene that computes forces) over `dim`
/// coordinates; `markers` and `branches` are the scene's marker values and branch invariants.
///
/// In three passes: what each stage computes; the trig cache, planned from those kernels and
/// the markers (the sine and cosine nodes it needs are added to the arena); then each stage's
/// trig fill, and what every kernel reads from the cache.
// Kept whole: its three passes in order, each a few lines over the helpers below.
pub fn list(
    arena: &mut Arena,
    dim: usize,
    plan: &Plan,
    forces: Option<&Forces>,
    markers: &[Id],
    branches: &[Id],
) -> Kernels {
    let drafts: Vec<Vec<(Method, Draft)>> = (0..plan.stages.len())
        .map(|s| stage_drafts(plan, s, forces.map(|f| &f.stages[s])))
        .collect();
    let all_filled = plan.stages.len();
    // The naive baseline caches nothing: it is the code without this saving.
    let trig = if arena.simplifies() {
        let stage_kernels = drafts.iter().enumerate().flat_map(|(s, kernels)| {
            kernels
                .iter()
                .map(move |(method, (roots, _))| (s, method.phase(), &roots[..]))
        });
        let after_sweep = (all_filled, Phase::Final, markers);
        trig::plan(arena, &plan.stages, dim, stage_kernels.chain([after_sweep]))
    } else {
        TrigCache::default()
    };
    let arena = &*arena;
    let mut stages = Vec::new();
    for (s, kernels) in drafts.into_iter().enumerate() {
        let fill = fill_draft(&trig, s).map(|draft| (Method::FillTrig, draft));
        let mut kernels: Vec<(Method, Draft)> = kernels.into_iter().chain(fill).collect();
        kernels.sort_by_key(|(method, _)| *method);
        stages.extend(kernels.into_iter().map(|(method, draft)| StageKernel {
            stage: s,
            method,
            kernel: Kernel::new(arena, &trig, draft, s, method.phase()),
        }));
    }
    let mut factorizations = Factorizations::default();
    let shapes = (0..plan.stages.len())
        .map(|s| shape(plan, s, &mut factorizations))
        .collect();
    let markers = (!markers.is_empty())
        .then(|| Kernel::listed(arena, &trig, markers, all_filled, Phase::Final));
    let branches = branches
        .iter()
        .map(|&b| Kernel::listed(arena, &trig, &[b], all_filled, Phase::Positions))
        .collect();
    let sizes = Sizes {
        largest_block: plan.largest_block(),
        largest_slots: plan.largest_slots(),
        stages: plan.stages.len().max(1),
        coordinates: dim,
        trig: trig.len(),
        forces: forces.map(|_| dim + plan.blocks().map(|b| b.slots()).sum::<usize>()),
    };
    Kernels {
        stages,
        shapes,
        factorizations: factorizations.order.into_iter().cloned().collect(),
        markers,
        branches,
        trig,
        sizes,
    }
}

/// What stage `s` computes, but for the trig it fills: its levels or its block's kernels, and
/// its force kernel.
fn stage_drafts(plan: &Plan, s: usize, force: Option<&ForceStage>) -> Vec<(Method, Draft)> {
    let mut kernels = match &plan.stages[s] {
        Stage::Explicit(assignments) => level_drafts(assignments),
        Stage::Block(block) => block_drafts(block),
    };
    match (&plan.stages[s], force) {
        (_, None) => {}
        (Stage::Explicit(assignments), Some(ForceStage::Explicit(values))) => {
            let outputs = assignments
                .iter()
                .map(|a| (Buffer::Lambda, a.equation))
                .collect();
            kernels.push((Method::Multipliers, (values.clone(), outputs)));
        }
        (Stage::Block(_), Some(ForceStage::Block(values))) => {
            let outputs = (0..values.len()).map(|j| (Buffer::Out, j)).collect();
            kernels.push((Method::ForceRhs, (values.clone(), outputs)));
        }
        _ => unreachable!("the force plan follows the kinematic plan stage for stage"),
    }
    kernels
}

/// An explicit stage's positions, velocities and accelerations, each written to its
/// coordinates (a level the scene does not compute has no kernel).
fn level_drafts(assignments: &[Assignment]) -> Vec<(Method, Draft)> {
    let levels = [
        (
            Method::Positions,
            Some(assignments.iter().map(|a| a.position).collect()),
        ),
        (
            Method::Velocities,
            assignments.iter().map(|a| a.velocity).collect(),
        ),
        (
            Method::Accelerations,
            assignments.iter().map(|a| a.acceleration).collect(),
        ),
    ];
    levels
        .into_iter()
        .filter_map(|(method, roots): (Method, Option<Vec<Id>>)| {
            let target = method.target();
            let outputs = assignments.iter().map(|a| (target, a.coordinate)).collect();
            Some((method, (roots?, outputs)))
        })
        .collect()
}

/// A block's residuals then Jacobian values, its closed-form candidates if it has them, and
/// its rate right-hand sides.
fn block_drafts(block: &Block) -> Vec<(Method, Draft)> {
    let roots = block
        .residuals
        .iter()
        .copied()
        .chain(block.entries.iter().map(|e| e.2))
        .collect();
    let outputs = (0..block.residuals.len())
        .map(|r| (Buffer::Phi, r))
        .chain((0..block.entries.len()).map(|k| (Buffer::Values, k)))
        .collect();
    let mut kernels = vec![(Method::Jacobian, (roots, outputs))];
    if let Some(closed) = &block.closed {
        let outputs = (0..closed.candidates.len())
            .map(|k| (Buffer::Candidates, k))
            .collect();
        kernels.push((Method::ClosedForm, (closed.candidates.clone(), outputs)));
    }
    let rates = [
        (Method::VelocityRhs, &block.velocity_rhs),
        (Method::AccelerationRhs, &block.acceleration_rhs),
    ];
    for (method, roots) in rates {
        let Some(roots) = roots else { continue };
        let outputs = (0..roots.len()).map(|r| (Buffer::Out, r)).collect();
        kernels.push((method, (roots.clone(), outputs)));
    }
    kernels
}

/// The sines and cosines stage `s` fills into the cache, if any.
fn fill_draft(trig: &TrigCache, s: usize) -> Option<Draft> {
    let fills: Vec<usize> = trig.fills(s).collect();
    if fills.is_empty() {
        return None;
    }
    let roots = fills
        .iter()
        .flat_map(|&m| {
            let (sin, cos) = trig.nodes[m];
            [sin, cos]
        })
        .collect();
    let outputs = fills
        .iter()
        .flat_map(|&m| [(Buffer::Trig, 2 * m), (Buffer::Trig, 2 * m + 1)])
        .collect();
    Some((roots, outputs))
}

/// The distinct static LUs, numbered in order of first use.
#[derive(Default)]
struct Factorizations<'p> {
    numbers: HashMap<&'p Factorization, usize>,
    order: Vec<&'p Factorization>,
}

impl<'p> Factorizations<'p> {
    fn index(&mut self, f: &'p Factorization) -> usize {
        let next = self.order.len();
        *self.numbers.entry(f).or_insert_with(|| {
            self.order.push(f);
            next
        })
    }
}

/// Stage `s`'s entry in the runtime's stage table; a block's static LU is numbered among
/// `factorizations`, added there if it is the first of its pattern.
fn shape<'p>(plan: &'p Plan, s: usize, factorizations: &mut Factorizations<'p>) -> StageShape {
    let reads = plan.reads[s].clone();
    match &plan.stages[s] {
        Stage::Explicit(assignments) => StageShape {
            equations: assignments.iter().map(|a| a.equation).collect(),
            coordinates: assignments.iter().map(|a| a.coordinate).collect(),
            reads,
            block: None,
        },
        Stage::Block(block) => {
            let factorization = block
                .factorization
                .as_ref()
                .map(|f| factorizations.index(f));
            StageShape {
                equations: block.equations.clone(),
                coordinates: block.coordinates.clone(),
                reads,
                block: Some(BlockShape {
                    pattern: block.entries.iter().map(|&(r, c, _)| (r, c)).collect(),
                    slots: block.slots(),
                    pivots: block
                        .factorization
                        .as_ref()
                        .map(Factorization::pivots)
                        .unwrap_or_default(),
                    factorization,
                }),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Scene;
    use crate::expr::{Func, Node, Var, var_index};

    fn scene(source: &str) -> Scene {
        crate::compile(crate::Input::Text(source), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{e}"))
    }

    const FOUR_BAR: &str = include_str!("../../../examples/scenes/four_bar.mech");
    const DYNAMICS: &str = include_str!("../../../examples/scenes/piston_crank_dynamics.mech");
    const OFFSET_SLIDER: &str = include_str!("../../../examples/scenes/offset_slider.mech");

    /// Two four-bars side by side, each with its own crank: two blocks of one pattern.
    const TWIN_FOUR_BARS: &str = "pub mechanism Twins {
        ground frame at (0, 0, 0);
        body c1 near (0, 0, 0);  body k1 near (40, 0, 0.6);  body r1 near (100, 0, 1.1);
        body c2 near (0, 0, 0);  body k2 near (40, 0, 0.6);  body r2 near (100, 0, 1.1);
        joint p1: revolute(frame, c1);
        joint a1: revolute(c1 @ (40, 0), k1);
        joint b1: revolute(k1 @ (120, 0), r1 @ (80, 0));
        joint q1: revolute(r1, frame @ (100, 0));
        joint p2: revolute(frame @ (0, 300), c2);
        joint a2: revolute(c2 @ (40, 0), k2);
        joint b2: revolute(k2 @ (120, 0), r2 @ (80, 0));
        joint q2: revolute(r2, frame @ (100, 300));
        driver d1: angle(c1) = t;
        driver d2: angle(c2) = 2 * t;
    }";

    /// A kernel of stage `s` reads a cached sine only once it is filled: positions from
    /// earlier stages, rates from earlier stages and its own, the force solve from any.
    #[test]
    fn kernels_read_only_the_trig_slots_their_phase_allows() {
        for source in [FOUR_BAR, DYNAMICS, TWIN_FOUR_BARS] {
            let scene = scene(source);
            let trig = &scene.kernels.trig;
            let mut checked = 0;
            for k in &scene.kernels.stages {
                for &slot in k.kernel.cached.values() {
                    let filled = trig.filled_by[slot / 2];
                    // Written out per method, not read from `Method::phase`: the rule itself
                    // is what is tested.
                    let allowed = match k.method {
                        Method::Positions
                        | Method::ClosedForm
                        | Method::Jacobian
                        | Method::FillTrig => filled < k.stage,
                        Method::Velocities
                        | Method::Accelerations
                        | Method::VelocityRhs
                        | Method::AccelerationRhs => filled <= k.stage,
                        Method::Multipliers | Method::ForceRhs => true,
                    };
                    assert!(
                        allowed,
                        "{:?} of stage {} reads slot {slot}",
                        k.method, k.stage
                    );
                    checked += 1;
                }
            }
            assert!(checked > 0, "the scene reads the trig cache somewhere");
        }
    }

    /// Each kernel writes one value per root to its method's buffer: an explicit stage's levels
    /// to its coordinates, a block's Jacobian its residuals then its pattern's entries.
    #[test]
    fn each_kernel_writes_where_its_stage_says() {
        let scene = scene(DYNAMICS);
        let mut seen = std::collections::HashSet::new();
        for k in &scene.kernels.stages {
            assert!(
                seen.insert((k.stage, k.method)),
                "one kernel per stage and method"
            );
            assert_eq!(k.kernel.roots.len(), k.kernel.outputs.len());
            let shape = &scene.kernels.shapes[k.stage];
            match (&scene.plan.stages[k.stage], k.method) {
                (
                    Stage::Explicit(_),
                    Method::Positions | Method::Velocities | Method::Accelerations,
                ) => {
                    let expected: Vec<_> = shape
                        .coordinates
                        .iter()
                        .map(|&c| (k.method.target(), c))
                        .collect();
                    assert_eq!(k.kernel.outputs, expected);
                }
                (Stage::Explicit(_), Method::Multipliers) => {
                    let expected: Vec<_> = shape
                        .equations
                        .iter()
                        .map(|&e| (Buffer::Lambda, e))
                        .collect();
                    assert_eq!(k.kernel.outputs, expected);
                }
                (Stage::Block(block), Method::Jacobian) => {
                    let roots: Vec<Id> = block
                        .residuals
                        .iter()
                        .copied()
                        .chain(block.entries.iter().map(|e| e.2))
                        .collect();
                    assert_eq!(k.kernel.roots, roots);
                    let phi = k
                        .kernel
                        .outputs
                        .iter()
                        .filter(|o| o.0 == Buffer::Phi)
                        .count();
                    assert_eq!(phi, block.equations.len());
                }
                (
                    Stage::Block(block),
                    Method::VelocityRhs | Method::AccelerationRhs | Method::ForceRhs,
                ) => {
                    assert_eq!(k.kernel.roots.len(), block.equations.len());
                }
                (Stage::Block(block), Method::ClosedForm) => {
                    let closed = block.closed.as_ref().expect("a block with a closed form");
                    assert_eq!(k.kernel.roots, closed.candidates);
                    assert_eq!(k.kernel.roots.len(), 4 * block.equations.len());
                    assert!(k.kernel.outputs.iter().all(|o| o.0 == Buffer::Candidates));
                }
                (_, Method::FillTrig) => {
                    let trig = &scene.kernels.trig;
                    let slots: Vec<usize> = trig
                        .fills(k.stage)
                        .flat_map(|m| [2 * m, 2 * m + 1])
                        .collect();
                    let written: Vec<usize> = k.kernel.outputs.iter().map(|o| o.1).collect();
                    assert_eq!(written, slots);
                    // Each value lands in its own node's slot: a sine where sines are read.
                    for (&root, &(buffer, slot)) in k.kernel.roots.iter().zip(&k.kernel.outputs) {
                        assert_eq!((buffer, Some(&slot)), (Buffer::Trig, trig.slot.get(&root)));
                        let angle = trig.angles[slot / 2];
                        let q = scene.model.arena.find(Node::Var(Var::Q(var_index(angle))));
                        let func = if slot % 2 == 0 { Func::Sin } else { Func::Cos };
                        let node = q.and_then(|q| scene.model.arena.find(Node::Call(func, q)));
                        assert_eq!(node, Some(root), "slot {slot} holds {func:?} of q{angle}");
                    }
                }
                (stage, method) => panic!("{method:?} in {stage:?}"),
            }
        }
        let methods: Vec<Method> = scene.kernels.stages.iter().map(|k| k.method).collect();
        for method in [Method::Multipliers, Method::ForceRhs, Method::Jacobian] {
            assert!(methods.contains(&method), "{method:?}");
        }
    }

    /// The levels a scene did not ask for have no kernels, nor does the force solve of a
    /// scene without forces.
    #[test]
    fn kernels_follow_the_outputs_asked_for() {
        let positions = scene(OFFSET_SLIDER);
        assert!(positions.kernels.stages.iter().all(|k| matches!(
            k.method,
            Method::Positions | Method::ClosedForm | Method::Jacobian | Method::FillTrig
        )));
        assert_eq!(positions.kernels.sizes.forces, None);
        let forces = scene(DYNAMICS);
        let dim = forces.model.dim();
        let archive: usize = forces.plan.blocks().map(|b| b.slots()).sum();
        assert_eq!(forces.kernels.sizes.forces, Some(dim + archive));
        assert_eq!(forces.kernels.sizes.coordinates, dim);
    }

    /// LUs are numbered in order of first use: a four-bar's block and a slider-crank's are
    /// two patterns, the second four-bar's shares the first's.
    #[test]
    fn static_lus_are_numbered_by_first_use() {
        let source = TWIN_FOUR_BARS.replace(
            "driver d2: angle(c2) = 2 * t;",
            "driver d2: angle(c2) = 2 * t;
            body crank near (0, 0, 0);
            body slider near (130, 500, 0);
            joint main: revolute(frame @ (0, 500), crank);
            joint rod: distance(crank @ (40, 0), slider, 100);
            joint line: prismatic(frame @ (0, 500), slider, along (1, 0));
            driver spin: angle(crank) = 3 * t;",
        );
        let scene = scene(&source);
        let numbers: Vec<Option<usize>> = scene
            .kernels
            .shapes
            .iter()
            .filter_map(|s| s.block.as_ref().map(|b| b.factorization))
            .collect();
        let distinct = scene.kernels.factorizations.len();
        assert_eq!(distinct, 2, "{numbers:?}");
        let mut first_use = Vec::new();
        for n in numbers.iter().flatten() {
            if !first_use.contains(n) {
                first_use.push(*n);
            }
        }
        assert_eq!(
            first_use,
            [0, 1],
            "numbered in order of first use: {numbers:?}"
        );
        assert_eq!(numbers.iter().flatten().filter(|&&n| n == 0).count(), 2);
    }

    /// Blocks of one pattern share one static LU; the shape of each block points at it.
    #[test]
    fn blocks_of_one_pattern_share_their_static_lu() {
        let scene = scene(TWIN_FOUR_BARS);
        let blocks: Vec<&BlockShape> = scene
            .kernels
            .shapes
            .iter()
            .filter_map(|s| s.block.as_ref())
            .collect();
        assert_eq!(blocks.len(), 2, "one block per loop");
        assert_eq!(scene.kernels.factorizations.len(), 1);
        for (s, shape) in scene.kernels.shapes.iter().enumerate() {
            if let Some(block) = &shape.block {
                assert_eq!(block.factorization, Some(0));
                assert_eq!(
                    scene.kernels.factorization(s),
                    Some(&scene.kernels.factorizations[0])
                );
                assert_eq!(block.pivots, scene.kernels.factorizations[0].pivots());
            } else {
                assert_eq!(scene.kernels.factorization(s), None);
            }
        }
    }
}
