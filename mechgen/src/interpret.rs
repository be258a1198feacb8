//! The interpreter: evaluates the IR directly, for tests, the CLI and as the baseline that a
//! run-time (non-generated) library would be.
//!
//! A [`Tape`] linearises the DAG reachable from a set of outputs once (topological order, each
//! node once) and then evaluates it into a reusable scratch buffer: the same sharing the emitter
//! gets from `let` bindings.

use crate::expr::{Arena, Id, Node, Var};

/// Values of everything an expression can refer to.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Env {
    /// Coordinates q.
    pub q: Vec<f64>,
    /// Velocities q̇ (only read by γ).
    pub qd: Vec<f64>,
    /// Time.
    pub t: f64,
    /// Parameter values by declaration index.
    pub params: Vec<f64>,
}

/// Inputs of one evaluation, borrowed (so callers need not copy into an [`Env`]).
#[derive(Debug, Clone, Copy)]
pub struct Inputs<'a> {
    /// Coordinates q.
    pub q: &'a [f64],
    /// Velocities q̇ (empty when the outputs do not need them).
    pub qd: &'a [f64],
    /// Time.
    pub t: f64,
    /// Parameter values by declaration index.
    pub params: &'a [f64],
}

impl Env {
    /// Borrows the environment as [`Inputs`].
    pub fn inputs(&self) -> Inputs<'_> {
        Inputs {
            q: &self.q,
            qd: &self.qd,
            t: self.t,
            params: &self.params,
        }
    }
}

/// Evaluates one expression (convenience for tests; builds a tape each call).
pub fn eval(arena: &Arena, id: Id, env: &Env) -> f64 {
    let tape = Tape::new(arena, &[id]);
    let mut scratch = tape.scratch();
    let mut out = [0.0];
    tape.eval(env.inputs(), &mut scratch, &mut out);
    out[0]
}

/// One instruction: a node with its operands renumbered to tape slots.
#[derive(Debug, Clone, Copy)]
enum Op {
    Const(f64),
    Param(usize),
    Q(usize),
    Qd(usize),
    T,
    Neg(usize),
    Add(usize, usize),
    Sub(usize, usize),
    Mul(usize, usize),
    Div(usize, usize),
    Powi(usize, i32),
    Call(crate::expr::Func, usize),
}

/// A set of outputs compiled to straight-line instructions.
#[derive(Debug, Clone)]
pub struct Tape {
    ops: Vec<Op>,
    outputs: Vec<usize>,
}

impl Tape {
    /// Compiles the outputs `roots` (in order) of `arena`.
    pub fn new(arena: &Arena, roots: &[Id]) -> Self {
        let order = topological_order(arena, roots);
        let mut slot = vec![usize::MAX; arena.len()];
        let mut ops = Vec::with_capacity(order.len());
        for &id in &order {
            let s = |x: Id| slot[x.index()];
            let op = match arena.node(id) {
                Node::Const(bits) => Op::Const(f64::from_bits(bits)),
                Node::Param(i) => Op::Param(i as usize),
                Node::Var(Var::Q(k)) => Op::Q(k as usize),
                Node::Var(Var::Qd(k)) => Op::Qd(k as usize),
                Node::Var(Var::T) => Op::T,
                Node::Neg(a) => Op::Neg(s(a)),
                Node::Add(a, b) => Op::Add(s(a), s(b)),
                Node::Sub(a, b) => Op::Sub(s(a), s(b)),
                Node::Mul(a, b) => Op::Mul(s(a), s(b)),
                Node::Div(a, b) => Op::Div(s(a), s(b)),
                Node::Powi(a, n) => Op::Powi(s(a), n),
                Node::Call(f, a) => Op::Call(f, s(a)),
            };
            slot[id.index()] = ops.len();
            ops.push(op);
        }
        let outputs = roots.iter().map(|r| slot[r.index()]).collect();
        Tape { ops, outputs }
    }

    /// A scratch buffer of the right size for [`Tape::eval`].
    pub fn scratch(&self) -> Vec<f64> {
        vec![0.0; self.ops.len()]
    }

    /// Number of instructions.
    pub fn len(&self) -> usize {
        self.ops.len()
    }

    /// True if the tape computes nothing.
    pub fn is_empty(&self) -> bool {
        self.ops.is_empty()
    }

    /// Evaluates every output into `out` (one value per root, in order).
    ///
    /// `scratch` must come from [`Tape::scratch`]; indices into `inputs` come from the same model
    /// that built the tape. Out-of-range inputs read as NaN rather than panicking, so a mismatch
    /// surfaces as a non-finite result the solver reports.
    pub fn eval(&self, inputs: Inputs<'_>, scratch: &mut [f64], out: &mut [f64]) {
        let get = |v: &[f64], i: usize| v.get(i).copied().unwrap_or(f64::NAN);
        for (i, op) in self.ops.iter().enumerate() {
            let value = match *op {
                Op::Const(c) => c,
                Op::Param(p) => get(inputs.params, p),
                Op::Q(k) => get(inputs.q, k),
                Op::Qd(k) => get(inputs.qd, k),
                Op::T => inputs.t,
                Op::Neg(a) => -scratch[a],
                Op::Add(a, b) => scratch[a] + scratch[b],
                Op::Sub(a, b) => scratch[a] - scratch[b],
                Op::Mul(a, b) => scratch[a] * scratch[b],
                Op::Div(a, b) => scratch[a] / scratch[b],
                Op::Powi(a, n) => scratch[a].powi(n),
                Op::Call(f, a) => f.apply(scratch[a]),
            };
            scratch[i] = value;
        }
        for (o, &slot) in out.iter_mut().zip(&self.outputs) {
            *o = scratch[slot];
        }
    }
}

/// Nodes reachable from `roots`, each once, every node after its operands. Deterministic:
/// depends only on the DAG and the order of `roots`.
pub fn topological_order(arena: &Arena, roots: &[Id]) -> Vec<Id> {
    let mut visited = vec![false; arena.len()];
    let mut order = Vec::new();
    // Iterative post-order DFS: deep chains (large scenes) must not overflow the stack.
    let mut stack: Vec<(Id, bool)> = Vec::new();
    for &root in roots {
        stack.push((root, false));
        while let Some((id, expanded)) = stack.pop() {
            if expanded {
                order.push(id);
                continue;
            }
            if visited[id.index()] {
                continue;
            }
            visited[id.index()] = true;
            stack.push((id, true));
            let children: Vec<Id> = arena.children(id).collect();
            for child in children.into_iter().rev() {
                if !visited[child.index()] {
                    stack.push((child, false));
                }
            }
        }
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::Func;

    #[test]
    fn evaluates_shared_subexpressions_once_in_order() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let p = a.param(0);
        let t = a.var(Var::T);
        let s = a.call(Func::Sin, x);
        let e1 = a.mul(s, p);
        let e2 = a.add(s, t);
        let tape = Tape::new(&a, &[e1, e2]);
        // x, sin x, p, sin x · p, t, sin x + t
        assert_eq!(tape.len(), 6);
        let env = Env {
            q: vec![0.5],
            qd: vec![],
            t: 2.0,
            params: vec![3.0],
        };
        let mut scratch = tape.scratch();
        let mut out = [0.0; 2];
        tape.eval(env.inputs(), &mut scratch, &mut out);
        assert_eq!(out, [0.5f64.sin() * 3.0, 0.5f64.sin() + 2.0]);
    }

    #[test]
    fn missing_inputs_read_as_nan_not_panic() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(7));
        let env = Env::default();
        assert!(eval(&a, x, &env).is_nan());
    }
}
