//! Evaluating the IR numerically: the tape every run-time evaluation of an expression goes
//! through (the interpreter crate, the checker's constants, tests), and the baseline that a
//! run-time (non-generated) library would be.
//!
//! A [`Tape`] linearises the DAG reachable from a set of outputs once (topological order, each
//! node once) and then evaluates it into a reusable scratch buffer: the same sharing the emitter
//! gets from `let` bindings.
//!
//! Tapes evaluate over any [`Scalar`], not only `f64`: the accuracy report runs the same Φ tape
//! on dual numbers to get a forward-mode automatically differentiated Jacobian of exactly the
//! equations the generated code evaluates.

use core::ops::{Add, Div, Mul, Neg, Sub};
use std::collections::{HashMap, HashSet};

use crate::expr::spline::SplineTable;
use crate::expr::{Arena, Func, Func2, Id, Node, Var};

/// A number type a [`Tape`] can evaluate over: `f64`, or e.g. a dual number for forward-mode
/// automatic differentiation (implemented by a newtype in the crate that owns the dual type).
pub trait Scalar:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// A constant (literals, parameters and `t` enter the tape as constants).
    fn from_f64(value: f64) -> Self;
    /// `self` raised to an integer power.
    fn powi(self, n: i32) -> Self;
    /// One of the IR's elementary functions.
    fn apply(self, function: Func) -> Self;
    /// One of the IR's functions of two arguments.
    fn apply2(self, function: Func2, other: Self) -> Self;
    /// The plain value (a dual number's real part): what [`Node::Select`] compares and a
    /// spline is evaluated at.
    fn primal(self) -> f64;
}

impl Scalar for f64 {
    #[inline]
    fn from_f64(value: f64) -> Self {
        value
    }
    #[inline]
    fn powi(self, n: i32) -> Self {
        f64::powi(self, n)
    }
    #[inline]
    fn apply(self, function: Func) -> Self {
        function.apply(self)
    }
    #[inline]
    fn apply2(self, function: Func2, other: Self) -> Self {
        function.apply(self, other)
    }
    #[inline]
    fn primal(self) -> f64 {
        self
    }
}

/// Values of everything an expression can refer to.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Env {
    /// Coordinates q.
    pub q: Vec<f64>,
    /// Velocities q̇ (only read by γ).
    pub qd: Vec<f64>,
    /// Accelerations q̈ (only read by the structured solve's acceleration right-hand sides).
    pub qdd: Vec<f64>,
    /// Time.
    pub t: f64,
    /// Parameter values by declaration index.
    pub params: Vec<f64>,
    /// The free degrees of freedom's `[value, rate, acceleration]`, by declaration index.
    pub free: Vec<[f64; 3]>,
}

/// Inputs of one evaluation, borrowed (so callers need not copy into an [`Env`]).
///
/// `S` is the scalar of the coordinates and velocities (`f64` unless evaluating over dual
/// numbers); time and parameters are always plain numbers.
#[derive(Debug, Clone, Copy)]
pub struct Inputs<'a, S = f64> {
    /// Coordinates q.
    pub q: &'a [S],
    /// Velocities q̇ (empty when the outputs do not need them).
    pub qd: &'a [S],
    /// Accelerations q̈ (empty unless evaluating acceleration right-hand sides).
    pub qdd: &'a [S],
    /// The solve's trig cache (sines and cosines of solved angles), for tapes built with
    /// [`Tape::with_inputs`]; empty otherwise.
    pub trig: &'a [f64],
    /// Lagrange multipliers by equation (the force solve's); empty otherwise.
    pub lambda: &'a [f64],
    /// Time.
    pub t: f64,
    /// Parameter values by declaration index.
    pub params: &'a [f64],
    /// The free degrees of freedom's `[value, rate, acceleration]` (empty in a scene without).
    pub free: &'a [[f64; 3]],
}

impl Env {
    /// Borrows the environment as [`Inputs`].
    pub fn inputs(&self) -> Inputs<'_> {
        Inputs {
            q: &self.q,
            qd: &self.qd,
            qdd: &self.qdd,
            trig: &[],
            lambda: &[],
            t: self.t,
            params: &self.params,
            free: &self.free,
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
    Qdd(usize),
    Lambda(usize),
    /// A node read from the trig cache instead of computed.
    Cached(usize),
    T,
    Neg(usize),
    Add(usize, usize),
    Sub(usize, usize),
    Mul(usize, usize),
    Div(usize, usize),
    Powi(usize, i32),
    Call(crate::expr::Func, usize),
    Call2(Func2, usize, usize),
    Select(usize, usize, usize, usize),
    /// A spline table (index into the tape's own), derivative order, argument.
    Spline(usize, u8, usize),
    /// Free degree of freedom, order (its state is an input, like a parameter).
    Free(usize, usize),
}

/// A set of outputs compiled to straight-line instructions.
#[derive(Debug, Clone)]
pub struct Tape {
    ops: Vec<Op>,
    outputs: Vec<usize>,
    /// The spline tables the tape reads (copied, so a tape stands alone).
    splines: Vec<SplineTable>,
}

impl Tape {
    /// Compiles the outputs `roots` (in order) of `arena`.
    pub fn new(arena: &Arena, roots: &[Id]) -> Self {
        Self::with_inputs(arena, roots, &HashMap::new())
    }

    /// Compiles the outputs `roots`, reading the nodes of `cached` from [`Inputs::trig`] (at
    /// the given positions) instead of computing them.
    pub fn with_inputs(arena: &Arena, roots: &[Id], cached: &HashMap<Id, usize>) -> Self {
        let order = topological_order_with(arena, roots, |id| cached.contains_key(&id));
        // A map rather than an arena-sized vector: tapes of a few nodes are built for every
        // stage of large scenes.
        let mut slot: HashMap<Id, usize> = HashMap::with_capacity(order.len());
        let mut ops = Vec::with_capacity(order.len());
        let mut splines = Vec::new();
        let mut copied: HashMap<u32, usize> = HashMap::new();
        for &id in &order {
            let s = |x: Id| slot.get(&x).copied().unwrap_or(usize::MAX);
            let op = match arena.node(id) {
                _ if cached.contains_key(&id) => Op::Cached(cached[&id]),
                Node::Const(bits) => Op::Const(f64::from_bits(bits)),
                Node::Param(i) => Op::Param(i as usize),
                Node::Var(Var::Q(k)) => Op::Q(k as usize),
                Node::Var(Var::Qd(k)) => Op::Qd(k as usize),
                Node::Var(Var::Qdd(k)) => Op::Qdd(k as usize),
                Node::Var(Var::Lambda(i)) => Op::Lambda(i as usize),
                Node::Var(Var::T) => Op::T,
                Node::Neg(a) => Op::Neg(s(a)),
                Node::Add(a, b) => Op::Add(s(a), s(b)),
                Node::Sub(a, b) => Op::Sub(s(a), s(b)),
                Node::Mul(a, b) => Op::Mul(s(a), s(b)),
                Node::Div(a, b) => Op::Div(s(a), s(b)),
                Node::Powi(a, n) => Op::Powi(s(a), n),
                Node::Call(f, a) => Op::Call(f, s(a)),
                Node::Call2(f, a, b) => Op::Call2(f, s(a), s(b)),
                Node::Select(a, b, x, y) => Op::Select(s(a), s(b), s(x), s(y)),
                Node::Spline { table, order, x } => {
                    let index = *copied.entry(table).or_insert_with(|| {
                        let copy = arena.spline_table(table).cloned().unwrap_or(SplineTable {
                            knots: vec![f64::NAN],
                            segments: vec![[f64::NAN; 4]; 2],
                        });
                        splines.push(copy);
                        splines.len() - 1
                    });
                    Op::Spline(index, order, s(x))
                }
                Node::Free { dof, order, .. } => Op::Free(dof as usize, usize::from(order)),
            };
            slot.insert(id, ops.len());
            ops.push(op);
        }
        let outputs = roots
            .iter()
            .map(|r| slot.get(r).copied().unwrap_or(usize::MAX))
            .collect();
        Tape {
            ops,
            outputs,
            splines,
        }
    }

    /// A scratch buffer of the right size for [`Tape::eval`].
    pub fn scratch(&self) -> Vec<f64> {
        vec![0.0; self.ops.len()]
    }

    /// A scratch buffer of the right size for [`Tape::eval_generic`] over `S`.
    pub fn scratch_of<S: Scalar>(&self) -> Vec<S> {
        vec![S::from_f64(0.0); self.ops.len()]
    }

    /// Number of outputs: the values [`Tape::eval`] writes.
    pub fn output_count(&self) -> usize {
        self.outputs.len()
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
        // The f64 instance of the generic loop: monomorphised and inlined, it is the same code
        // as a loop written for f64 alone.
        self.eval_generic(inputs, scratch, out);
    }

    /// [`Tape::eval`] over any [`Scalar`] (e.g. dual numbers).
    ///
    /// `scratch` must hold at least [`Tape::len`] values ([`Tape::scratch_of`]); a shorter one
    /// writes NaN to every output instead of panicking.
    #[inline]
    pub fn eval_generic<S: Scalar>(&self, inputs: Inputs<'_, S>, scratch: &mut [S], out: &mut [S]) {
        let nan = S::from_f64(f64::NAN);
        if scratch.len() < self.ops.len() {
            out.fill(nan);
            return;
        }
        let get = |v: &[S], i: usize| v.get(i).copied().unwrap_or(nan);
        for (i, op) in self.ops.iter().enumerate() {
            let value = match *op {
                Op::Const(c) => S::from_f64(c),
                Op::Param(p) => S::from_f64(inputs.params.get(p).copied().unwrap_or(f64::NAN)),
                Op::Q(k) => get(inputs.q, k),
                Op::Qd(k) => get(inputs.qd, k),
                Op::Qdd(k) => get(inputs.qdd, k),
                Op::Lambda(i) => S::from_f64(inputs.lambda.get(i).copied().unwrap_or(f64::NAN)),
                Op::Cached(k) => S::from_f64(inputs.trig.get(k).copied().unwrap_or(f64::NAN)),
                Op::T => S::from_f64(inputs.t),
                Op::Free(k, order) => S::from_f64(
                    inputs
                        .free
                        .get(k)
                        .and_then(|state| state.get(order))
                        .copied()
                        .unwrap_or(f64::NAN),
                ),
                Op::Neg(a) => -scratch[a],
                Op::Add(a, b) => scratch[a] + scratch[b],
                Op::Sub(a, b) => scratch[a] - scratch[b],
                Op::Mul(a, b) => scratch[a] * scratch[b],
                Op::Div(a, b) => scratch[a] / scratch[b],
                Op::Powi(a, n) => scratch[a].powi(n),
                Op::Call(f, a) => scratch[a].apply(f),
                Op::Call2(f, a, b) => scratch[a].apply2(f, scratch[b]),
                Op::Select(a, b, x, y) => {
                    let (p, q) = (scratch[a].primal(), scratch[b].primal());
                    if p <= q {
                        scratch[x]
                    } else if q < p {
                        scratch[y]
                    } else {
                        scratch[a] + scratch[b]
                    }
                }
                Op::Spline(table, order, a) => {
                    // Value and slope at the primal point: exact for f64, first order for
                    // dual numbers (what forward-mode differentiation needs).
                    let x = scratch[a];
                    let p = x.primal();
                    let spline = &self.splines[table];
                    let (value, slope) = (spline.eval(p, order), spline.eval(p, order + 1));
                    S::from_f64(value) + S::from_f64(slope) * (x - S::from_f64(p))
                }
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
    topological_order_with(arena, roots, |_| false)
}

/// [`topological_order`], with the nodes for which `leaf` holds taken as inputs: listed, but
/// not their operands (unless another node needs them).
pub fn topological_order_with(arena: &Arena, roots: &[Id], leaf: impl Fn(Id) -> bool) -> Vec<Id> {
    // A set rather than an arena-sized vector: the cost follows the expressions, not the arena.
    let mut visited = HashSet::new();
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
            if !visited.insert(id) {
                continue;
            }
            stack.push((id, true));
            if leaf(id) {
                continue;
            }
            let children: Vec<Id> = arena.children(id).collect();
            for child in children.into_iter().rev() {
                if !visited.contains(&child) {
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
            qdd: vec![],
            t: 2.0,
            params: vec![3.0],
            free: Vec::new(),
        };
        let mut scratch = tape.scratch();
        let mut out = [0.0; 2];
        tape.eval(env.inputs(), &mut scratch, &mut out);
        assert_eq!(out, [0.5f64.sin() * 3.0, 0.5f64.sin() + 2.0]);
    }

    /// A minimal forward-mode dual number: value and one derivative.
    #[derive(Debug, Clone, Copy, PartialEq)]
    struct D(f64, f64);
    impl core::ops::Add for D {
        type Output = D;
        fn add(self, o: D) -> D {
            D(self.0 + o.0, self.1 + o.1)
        }
    }
    impl core::ops::Sub for D {
        type Output = D;
        fn sub(self, o: D) -> D {
            D(self.0 - o.0, self.1 - o.1)
        }
    }
    impl core::ops::Mul for D {
        type Output = D;
        fn mul(self, o: D) -> D {
            D(self.0 * o.0, self.1 * o.0 + self.0 * o.1)
        }
    }
    impl core::ops::Div for D {
        type Output = D;
        fn div(self, o: D) -> D {
            D(self.0 / o.0, (self.1 * o.0 - self.0 * o.1) / (o.0 * o.0))
        }
    }
    impl core::ops::Neg for D {
        type Output = D;
        fn neg(self) -> D {
            D(-self.0, -self.1)
        }
    }
    impl Scalar for D {
        fn from_f64(value: f64) -> Self {
            D(value, 0.0)
        }
        fn powi(self, n: i32) -> Self {
            D(self.0.powi(n), f64::from(n) * self.0.powi(n - 1) * self.1)
        }
        fn apply(self, function: Func) -> Self {
            let derivative = match function {
                Func::Sin => self.0.cos(),
                _ => f64::NAN,
            };
            D(function.apply(self.0), derivative * self.1)
        }
        fn apply2(self, function: Func2, other: Self) -> Self {
            D(function.apply(self.0, other.0), f64::NAN)
        }
        fn primal(self) -> f64 {
            self.0
        }
    }

    #[test]
    fn generic_evaluation_differentiates_and_matches_f64() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let p = a.param(0);
        let s = a.call(Func::Sin, x);
        let sx = a.mul(s, x);
        let x2 = a.powi(x, 2);
        let e = a.add(sx, x2);
        let f = a.div(e, p);
        let tape = Tape::new(&a, &[f]);
        let (x0, p0) = (0.7, 3.0);
        let mut out = [D(0.0, 0.0)];
        let inputs = Inputs {
            q: &[D(x0, 1.0)],
            qd: &[],
            qdd: &[],
            trig: &[],
            lambda: &[],
            t: 0.0,
            params: &[p0],
            free: &[],
        };
        tape.eval_generic(inputs, &mut tape.scratch_of(), &mut out);
        let plain = eval(
            &a,
            f,
            &Env {
                q: vec![x0],
                qd: vec![],
                qdd: vec![],
                t: 0.0,
                params: vec![p0],
                free: Vec::new(),
            },
        );
        assert_eq!(out[0].0, plain);
        // d/dx (x sin x + x²) / p
        let exact = (x0.cos() * x0 + x0.sin() + 2.0 * x0) / p0;
        assert!((out[0].1 - exact).abs() < 1e-15, "{} vs {exact}", out[0].1);

        // Too small a scratch buffer: NaN out, no panic.
        tape.eval_generic(inputs, &mut [], &mut out);
        assert!(out[0].0.is_nan());
    }

    #[test]
    fn missing_inputs_read_as_nan_not_panic() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(7));
        let env = Env::default();
        assert!(eval(&a, x, &env).is_nan());
    }

    #[test]
    fn a_free_state_is_read_from_the_inputs_and_missing_reads_nan() {
        let mut a = Arena::new();
        let t = a.var(Var::T);
        let (u, ud) = (a.free(0, 0, t), a.free(0, 1, t));
        let sum = a.add(u, ud);
        let far = a.free(3, 2, t);
        let env = Env {
            free: vec![[0.25, 2.0, 9.0]],
            ..Env::default()
        };
        assert_eq!(eval(&a, sum, &env), 2.25);
        assert!(eval(&a, far, &env).is_nan());
        let third = a.free(0, 3, t);
        assert!(a.is_zero(third));
    }
}
