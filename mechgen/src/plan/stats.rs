//! What generated code computes, for review (doc comments, snapshots, `mechgen check --stats`):
//! the operation counts of each function, so that a regression shows up in review rather than
//! only in a benchmark, and the solve structure (stages, block sizes, fill-in).

use std::fmt;

use crate::expr::tape::topological_order;
use crate::expr::{Arena, Func, Id, Node};
use crate::plan::Scene;
use crate::plan::closed::ClosedKind;
use crate::plan::structure::{Assignment, Block, Plan, Stage};

/// How many operations of each kind a straight-line evaluation performs (each DAG node once).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct OpCounts {
    /// sin, cos, tan calls.
    pub trig: usize,
    /// sqrt calls.
    pub sqrt: usize,
    /// exp and ln calls.
    pub exp_ln: usize,
    /// Multiplications (an integer power counts as its multiplications).
    pub mul: usize,
    /// Additions and subtractions.
    pub add: usize,
    /// Divisions.
    pub div: usize,
    /// Negations.
    pub neg: usize,
    /// Other calls: atan2, asin, acos, real powers, branch selections and spline lookups.
    pub other: usize,
}

impl OpCounts {
    /// Counts the operations of the nodes in `order` (each evaluated once).
    pub fn of(arena: &Arena, order: &[Id]) -> Self {
        let mut c = OpCounts::default();
        for &id in order {
            match arena.node(id) {
                Node::Const(_) | Node::Param(_) | Node::Var(_) | Node::Free { .. } => {}
                Node::Neg(_) => c.neg += 1,
                Node::Add(..) | Node::Sub(..) => c.add += 1,
                Node::Mul(..) => c.mul += 1,
                Node::Div(..) => c.div += 1,
                Node::Powi(_, n) => {
                    // Repeated squaring: ⌊log2 n⌋ squarings plus one product per extra set bit.
                    let e = n.unsigned_abs();
                    if e > 1 {
                        c.mul += (31 - e.leading_zeros()) as usize + e.count_ones() as usize - 1;
                    }
                    if n < 0 {
                        c.div += 1;
                    }
                }
                Node::Call(f, _) => match f {
                    Func::Sin | Func::Cos | Func::Tan => c.trig += 1,
                    Func::Sqrt => c.sqrt += 1,
                    Func::Exp | Func::Ln => c.exp_ln += 1,
                    Func::Asin | Func::Acos => c.other += 1,
                },
                Node::Call2(..) | Node::Select(..) | Node::Spline { .. } => c.other += 1,
            }
        }
        c
    }
}

impl OpCounts {
    /// Counts the operations of evaluating `roots` as trees: every use of a shared
    /// sub-expression evaluated again (the naive baseline, without common-subexpression
    /// elimination).
    pub fn of_tree(arena: &Arena, roots: &[Id]) -> Self {
        let order = topological_order(arena, roots);
        let mut subtree = vec![OpCounts::default(); arena.len()];
        for &id in &order {
            let own = OpCounts::of(arena, &[id]);
            subtree[id.index()] = arena
                .children(id)
                .fold(own, |total, child| total + subtree[child.index()]);
        }
        roots.iter().fold(OpCounts::default(), |total, root| {
            total + subtree[root.index()]
        })
    }
}

impl core::ops::Add for OpCounts {
    type Output = OpCounts;

    fn add(self, other: OpCounts) -> OpCounts {
        OpCounts {
            trig: self.trig + other.trig,
            sqrt: self.sqrt + other.sqrt,
            exp_ln: self.exp_ln + other.exp_ln,
            mul: self.mul + other.mul,
            add: self.add + other.add,
            div: self.div + other.div,
            neg: self.neg + other.neg,
            other: self.other + other.other,
        }
    }
}

impl fmt::Display for OpCounts {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} trig, {} sqrt, {} exp/ln, {} mul, {} add, {} div, {} neg",
            self.trig, self.sqrt, self.exp_ln, self.mul, self.add, self.div, self.neg
        )?;
        // Only scenes that use them show the other calls (the others' docs are unchanged).
        if self.other > 0 {
            write!(f, ", {} other", self.other)?;
        }
        Ok(())
    }
}

/// Operation counts of one generated function.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FunctionCounts {
    /// The generated function's name (`phi`, `jacobian`, `phi_and_jacobian`, `nu`, `gamma`, and
    /// for a scene that computes forces `generalized_forces`, `reactions`).
    pub function: &'static str,
    /// Non-zero outputs it writes (zeros come from one `fill(0.0)`).
    pub outputs: usize,
    /// Operations, each shared sub-expression once.
    pub counts: OpCounts,
}

/// Operation counts of every generated kinematic function, counted exactly as the emitter does
/// for its doc comments: over the DAG reachable from the non-zero outputs, each node once.
pub fn function_counts(scene: &Scene) -> Vec<FunctionCounts> {
    let arena = &scene.model.arena;
    // A naive scene (unsimplified arena) is emitted without sharing: count its trees.
    let naive = !arena.simplifies();
    let forces = scene.forces.iter().flat_map(|f| f.function_outputs(arena));
    scene
        .kinematics
        .function_outputs(arena)
        .into_iter()
        .chain(forces)
        .map(|(function, roots)| FunctionCounts {
            function,
            outputs: roots.len(),
            counts: if naive {
                OpCounts::of_tree(arena, &roots)
            } else {
                OpCounts::of(arena, &topological_order(arena, &roots))
            },
        })
        .collect()
}

/// [`function_counts`] as a text table (CLI `check --stats`, snapshots).
pub fn table(scene: &Scene) -> String {
    let functions = function_counts(scene);
    // Wide enough for the longest name, and never narrower than the kinematic functions need.
    let width = functions
        .iter()
        .map(|f| f.function.len() + 1)
        .fold(17, usize::max);
    // The column of other calls only for scenes that make them.
    let others = functions.iter().any(|f| f.counts.other > 0);
    let other = |value: String| {
        if others {
            format!("{value:>7}")
        } else {
            String::new()
        }
    };
    let mut out = format!(
        "{:<width$}{:>8}{:>6}{:>6}{:>8}{:>6}{:>6}{:>6}{:>6}{}\n",
        "function",
        "outputs",
        "trig",
        "sqrt",
        "exp/ln",
        "mul",
        "add",
        "div",
        "neg",
        other("other".to_owned())
    );
    for f in functions {
        let c = f.counts;
        out += &format!(
            "{:<width$}{:>8}{:>6}{:>6}{:>8}{:>6}{:>6}{:>6}{:>6}{}\n",
            f.function,
            f.outputs,
            c.trig,
            c.sqrt,
            c.exp_ln,
            c.mul,
            c.add,
            c.div,
            c.neg,
            other(c.other.to_string())
        );
    }
    out
}

/// The solve structure as text: a summary line, then one line per stage (kind, size, the static
/// LU's entries, fill-in and updates, and what it solves); scenes with many stages show the
/// first and last ones and a histogram of block sizes.
pub fn structure(scene: &Scene) -> String {
    const SHOWN: usize = 24;
    let (model, plan) = (&scene.model, &scene.plan);
    let (coordinates, equations) = (model.coordinate_names(), model.equation_names());
    let mut out = summary(scene);
    out += &format!(
        "{:>6}  {:<13}{:>5}{:>9}{:>6}{:>9}  solves (coordinate ← equation)\n",
        "stage", "kind", "size", "entries", "fill", "updates"
    );
    let count = plan.stages.len();
    for (s, stage) in plan.stages.iter().enumerate() {
        if count > SHOWN && s == SHOWN - 8 {
            out += &format!("{:>6}  … {} more stages\n", "", count - SHOWN);
        }
        if count > SHOWN && s >= SHOWN - 8 && s < count - 8 {
            continue;
        }
        out += &stage_line(&model.arena, s, stage, &coordinates, &equations);
    }
    if count > SHOWN {
        out += &block_sizes(plan);
    }
    out
}

/// Whether an explicit stage's values are fixed (invariant: no coordinate, no time).
fn fixed(arena: &Arena, assignments: &[Assignment]) -> bool {
    assignments.iter().all(|a| arena.is_invariant(a.position))
}

/// The summary: how the coordinates split into explicit and block stages, the static LUs'
/// size, the trig cache, and for a scene that computes forces the force solve.
fn summary(scene: &Scene) -> String {
    let (model, plan) = (&scene.model, &scene.plan);
    let arena = &model.arena;
    let explicit: usize = plan.assignments().count();
    let fixed_count: usize = plan
        .stages
        .iter()
        .filter_map(|s| match s {
            Stage::Explicit(a) if fixed(arena, a) => Some(a.len()),
            _ => None,
        })
        .sum();
    let blocks: Vec<&Block> = plan.blocks().collect();
    let in_blocks: usize = blocks.iter().map(|b| b.equations.len()).sum();
    let (entries, fill, updates) =
        blocks
            .iter()
            .fold((0, 0, 0), |(e, f, u), b| match &b.factorization {
                Some(lu) => (e + lu.entries, f + lu.fill(), u + lu.updates()),
                None => (e + b.entries.len(), f, u),
            });
    let dense = blocks.iter().filter(|b| b.factorization.is_none()).count();
    let mut out = format!(
        "{} coordinates in {} stages: {explicit} explicit ({fixed_count} fixed), {in_blocks} in \
         {} Newton block{} (largest {})\nstatic LU: {entries} Jacobian entries, {fill} fill-in, \
         {updates} update{}{}; trig cache: {} angle{}\n",
        model.dim(),
        plan.stages.len(),
        blocks.len(),
        if blocks.len() == 1 { "" } else { "s" },
        blocks.iter().map(|b| b.equations.len()).max().unwrap_or(0),
        if updates == 1 { "" } else { "s" },
        if dense > 0 {
            format!(
                " ({dense} block{} factored with partial pivoting)",
                if dense == 1 { "" } else { "s" }
            )
        } else {
            String::new()
        },
        scene.kernels.trig.angles.len(),
        if scene.kernels.trig.angles.len() == 1 {
            ""
        } else {
            "s"
        },
    );
    out += &closed_summary(&blocks);
    if scene.forces.is_some() {
        out += &format!(
            "force solve, stages in reverse: {explicit} multipliers in closed form, {in_blocks} by \
             transposed solves with the blocks' archived factors ({} values)\n",
            blocks.iter().map(|b| b.slots()).sum::<usize>()
        );
    }
    out
}

/// "closed form: 2 of 3 blocks (1 circle–line, 1 circle–circle), Newton verifies", or nothing
/// for a scene without blocks.
fn closed_summary(blocks: &[&Block]) -> String {
    if blocks.is_empty() {
        return String::new();
    }
    let kinds = [
        ClosedKind::CircleLine,
        ClosedKind::CircleCircle,
        ClosedKind::Linear,
    ];
    let counts: Vec<String> = kinds
        .iter()
        .filter_map(|&kind| {
            let n = (blocks.iter())
                .filter(|b| b.closed.as_ref().is_some_and(|c| c.kind == kind))
                .count();
            (n > 0).then(|| format!("{n} {}", kind.name()))
        })
        .collect();
    let closed = blocks.iter().filter(|b| b.closed.is_some()).count();
    let detail = if counts.is_empty() {
        String::new()
    } else {
        format!(
            " ({}), each started there and verified by Newton",
            counts.join(", ")
        )
    };
    format!(
        "closed form: {closed} of {} block{}{detail}\n",
        blocks.len(),
        if blocks.len() == 1 { "" } else { "s" }
    )
}

/// One stage's line of the table.
fn stage_line(
    arena: &Arena,
    s: usize,
    stage: &Stage,
    coordinates: &[String],
    equations: &[String],
) -> String {
    let pairs = |cs: &[usize], es: &[usize]| {
        let shown: Vec<String> = cs
            .iter()
            .zip(es)
            .take(3)
            .map(|(&c, &e)| format!("{} ← {}", coordinates[c], equations[e]))
            .collect();
        let more = if cs.len() > 3 { ", …" } else { "" };
        format!("{}{more}", shown.join(", "))
    };
    match stage {
        Stage::Explicit(a) => {
            let cs: Vec<usize> = a.iter().map(|a| a.coordinate).collect();
            let es: Vec<usize> = a.iter().map(|a| a.equation).collect();
            let kind = if fixed(arena, a) { "fixed" } else { "explicit" };
            format!(
                "{s:>6}  {kind:<13}{:>5}{:>9}{:>6}{:>9}  {}\n",
                a.len(),
                "",
                "",
                "",
                pairs(&cs, &es)
            )
        }
        Stage::Block(b) => {
            let (e, f, u) = match &b.factorization {
                Some(lu) => (
                    lu.entries.to_string(),
                    lu.fill().to_string(),
                    lu.updates().to_string(),
                ),
                None => (b.entries.len().to_string(), "-".into(), "dense".into()),
            };
            // A block with a closed form is named by its kind; Newton only verifies it.
            let kind = b.closed.as_ref().map_or("block", |c| c.kind.name());
            format!(
                "{s:>6}  {kind:<13}{:>5}{e:>9}{f:>6}{u:>9}  {}\n",
                b.equations.len(),
                pairs(&b.coordinates, &b.equations)
            )
        }
    }
}

/// "block sizes: 3 of 1, 1 of 4": how many blocks of each size.
fn block_sizes(plan: &Plan) -> String {
    let blocks: Vec<&Block> = plan.blocks().collect();
    let mut sizes: Vec<usize> = blocks.iter().map(|b| b.equations.len()).collect();
    sizes.sort_unstable();
    let mut histogram = Vec::new();
    for size in sizes {
        match histogram.last_mut() {
            Some((s, n)) if *s == size => *n += 1,
            _ => histogram.push((size, 1)),
        }
    }
    let histogram: Vec<String> = histogram
        .iter()
        .map(|(size, n)| format!("{n} of {size}"))
        .collect();
    format!("block sizes: {}\n", histogram.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::Var;

    #[test]
    fn integer_powers_count_their_multiplications() {
        let mut a = Arena::unsimplified();
        let x = a.var(Var::Q(0));
        let count = |a: &Arena, id| OpCounts::of(a, &[id]).mul;
        for (n, muls) in [(0, 0), (1, 0), (2, 1), (3, 2), (4, 2), (5, 3), (-2, 1)] {
            let p = a.powi(x, n);
            assert_eq!(count(&a, p), muls, "x^{n}");
        }
    }

    #[test]
    fn trees_count_every_use_and_dags_count_once() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let s = a.sin(x);
        let two_uses = a.mul(s, s);
        let dag = OpCounts::of(&a, &topological_order(&a, &[two_uses]));
        let tree = OpCounts::of_tree(&a, &[two_uses]);
        assert_eq!((dag.trig, dag.mul), (1, 1));
        assert_eq!((tree.trig, tree.mul), (2, 1));
    }
}
