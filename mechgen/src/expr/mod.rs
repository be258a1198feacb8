//! The expression IR: a hash-consed DAG of scalar expressions over q, q̇, q̈, λ, t and
//! parameters.
//!
//! Every node lives once in an [`Arena`]; structurally equal expressions get the same [`Id`], so
//! common sub-expressions (each sin θ, cos θ, products of them) are shared by construction and the
//! emitter binds each of them once. The constructors simplify as they build (constant folding,
//! `x·0`, `x·1`, `x+0`, `−(−x)`, functions of constants), so no separate simplification pass can be
//! forgotten and no identically-zero expression survives as anything but [`Arena::zero`].
//!
//! Around the arena: symbolic derivatives ([`diff`]), evaluation by tape ([`tape`]) and the
//! cubic spline tables that `spline(...)` values read ([`spline`]).

pub mod diff;
pub mod spline;
pub mod tape;

use std::collections::{HashMap, HashSet};

/// Handle of a node in an [`Arena`]. Ids are dense and ordered by creation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Id(u32);

impl Id {
    /// Position of the node in the arena (creation order).
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// A variable an expression can be differentiated with respect to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Var {
    /// Coordinate q_k.
    Q(u32),
    /// Coordinate velocity q̇_k (an independent symbol when forming γ).
    Qd(u32),
    /// Coordinate acceleration q̈_k (read by the structured solve's acceleration right-hand
    /// sides, where earlier stages' accelerations are known).
    Qdd(u32),
    /// Lagrange multiplier λ_i of equation i (read by the force solve, where later stages'
    /// multipliers are known).
    Lambda(u32),
    /// Time.
    T,
}

/// The `u32` index a [`Var`] carries for coordinate, equation or parameter `k`.
///
/// A scene has far fewer than 2³² of each (the generated arrays would not compile otherwise).
pub(crate) fn var_index(k: usize) -> u32 {
    u32::try_from(k).expect("a scene has fewer than 2^32 coordinates and equations")
}

/// Elementary functions of one argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Func {
    /// Sine.
    Sin,
    /// Cosine.
    Cos,
    /// Tangent.
    Tan,
    /// Natural exponential.
    Exp,
    /// Natural logarithm.
    Ln,
    /// Square root.
    Sqrt,
    /// Arcsine, in [−π/2, π/2].
    Asin,
    /// Arccosine, in [0, π].
    Acos,
}

impl Func {
    /// Every function.
    pub const ALL: [Func; 8] = [
        Func::Sin,
        Func::Cos,
        Func::Tan,
        Func::Exp,
        Func::Ln,
        Func::Sqrt,
        Func::Asin,
        Func::Acos,
    ];

    /// The name used in specs and in generated code (`::mechgen_runtime::codegen::math::NAME`).
    pub fn name(self) -> &'static str {
        match self {
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Exp => "exp",
            Func::Ln => "ln",
            Func::Sqrt => "sqrt",
            Func::Asin => "asin",
            Func::Acos => "acos",
        }
    }

    /// Looks a function up by its spec name.
    pub fn from_name(name: &str) -> Option<Func> {
        Func::ALL.into_iter().find(|f| f.name() == name)
    }

    /// Evaluates the function (used for constant folding and by the interpreter).
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Tan => x.tan(),
            Func::Exp => x.exp(),
            Func::Ln => x.ln(),
            Func::Sqrt => x.sqrt(),
            Func::Asin => x.asin(),
            Func::Acos => x.acos(),
        }
    }
}

/// Elementary functions of two arguments.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Func2 {
    /// `atan2(y, x)`: the angle of the vector (x, y), in (−π, π].
    Atan2,
    /// `pow(a, b)` = a^b for a real exponent (NaN for a negative base).
    Pow,
}

impl Func2 {
    /// The name in generated code (`::mechgen_runtime::codegen::math::NAME`).
    pub fn name(self) -> &'static str {
        match self {
            Func2::Atan2 => "atan2",
            Func2::Pow => "pow",
        }
    }

    /// Evaluates the function (constant folding, the interpreter).
    pub fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Func2::Atan2 => a.atan2(b),
            Func2::Pow => a.powf(b),
        }
    }
}

/// `if a <= b { x } else { y }`, and NaN (`a + b`) when `a` or `b` is NaN: the one branching
/// node (min, max, abs and the clamped motion laws lower to it), shared by folding and the
/// interpreter; generated code calls `::mechgen_runtime::codegen::math::select`, the same rule.
pub fn select(a: f64, b: f64, x: f64, y: f64) -> f64 {
    if a <= b {
        x
    } else if b < a {
        y
    } else {
        a + b
    }
}

/// One node of the DAG. Constants are stored as bit patterns so nodes can be hashed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Node {
    /// A finite literal (bits of an `f64`).
    Const(u64),
    /// Run-time parameter by declaration index.
    Param(u32),
    /// A variable: q_k, q̇_k or t.
    Var(Var),
    /// −a
    Neg(Id),
    /// a + b
    Add(Id, Id),
    /// a − b
    Sub(Id, Id),
    /// a · b
    Mul(Id, Id),
    /// a / b
    Div(Id, Id),
    /// a raised to an integer power (|n| ≥ 2 after simplification).
    Powi(Id, i32),
    /// f(a)
    Call(Func, Id),
    /// f(a, b)
    Call2(Func2, Id, Id),
    /// `if a <= b { x } else { y }` (see [`select`]): its derivative is the selected branch's,
    /// so at a kink (a = b) it is the one-sided derivative of the `x` branch.
    Select(Id, Id, Id, Id),
    /// The `order`-th derivative (0: the value) of spline table `table` at `x`
    /// ([`Arena::spline_table`]).
    Spline {
        /// Index of the table in the arena.
        table: u32,
        /// Derivative order, 0 to 3.
        order: u8,
        /// The argument.
        x: Id,
    },
    /// The integrator's state of free degree of freedom `dof`: its value, rate or
    /// acceleration (`order` 0, 1, 2) at time `t` ([`Arena::free`]). A function of time only,
    /// like a driver's law: it carries `t` as its operand so that every rule about time
    /// dependence (ν, γ, what the trig cache may hold) sees it as time-dependent.
    Free {
        /// Index of the free degree of freedom, in declaration order.
        dof: u32,
        /// 0: the value u, 1: the rate u̇, 2: the acceleration ü.
        order: u8,
        /// The time variable.
        t: Id,
    },
}

/// The arena holding every node; see the module docs.
#[derive(Debug, Clone)]
pub struct Arena {
    nodes: Vec<Node>,
    lookup: HashMap<Node, Id>,
    zero: Id,
    one: Id,
    /// False only for the naive baseline ([`Arena::unsimplified`]).
    simplify: bool,
    /// The spline tables [`Node::Spline`] refers to.
    splines: Vec<crate::expr::spline::SplineTable>,
}

impl Default for Arena {
    fn default() -> Self {
        Self::new()
    }
}

impl Arena {
    /// An arena holding the constants 0 and 1.
    pub fn new() -> Self {
        let mut arena = Arena {
            nodes: Vec::new(),
            lookup: HashMap::new(),
            zero: Id(0),
            one: Id(0),
            simplify: true,
            splines: Vec::new(),
        };
        arena.zero = arena.intern(Node::Const(0f64.to_bits()));
        arena.one = arena.intern(Node::Const(1f64.to_bits()));
        arena
    }

    /// An arena whose constructors neither fold nor simplify: the naive baseline that shows
    /// what folding and simplification save (operation counts, benchmarks). Never used for
    /// the generated code users get.
    pub fn unsimplified() -> Self {
        Arena {
            simplify: false,
            ..Arena::new()
        }
    }

    /// True unless this is the naive baseline.
    pub fn simplifies(&self) -> bool {
        self.simplify
    }

    /// The node behind an id.
    pub fn node(&self, id: Id) -> Node {
        self.nodes[id.index()]
    }

    /// Number of nodes created so far.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// True if only the built-in constants exist.
    pub fn is_empty(&self) -> bool {
        self.nodes.len() <= 2
    }

    fn intern(&mut self, node: Node) -> Id {
        if let Some(&id) = self.lookup.get(&node) {
            return id;
        }
        let id = Id(u32::try_from(self.nodes.len()).expect("expression arena exceeds u32 nodes"));
        self.nodes.push(node);
        self.lookup.insert(node, id);
        id
    }

    /// The id of `node`, if the arena holds it (nothing is created).
    pub fn find(&self, node: Node) -> Option<Id> {
        self.lookup.get(&node).copied()
    }

    /// The constant 0.
    pub fn zero(&self) -> Id {
        self.zero
    }

    /// The constant 1.
    pub fn one(&self) -> Id {
        self.one
    }

    /// The constant value of a node, if it is one.
    pub fn as_const(&self, id: Id) -> Option<f64> {
        match self.node(id) {
            Node::Const(bits) => Some(f64::from_bits(bits)),
            _ => None,
        }
    }

    /// True if the node is the constant 0 (identically zero after simplification).
    pub fn is_zero(&self, id: Id) -> bool {
        self.as_const(id) == Some(0.0)
    }

    /// A literal. Callers guarantee finiteness (user literals are checked, folding refuses
    /// non-finite results); −0 is normalised to 0 so both share one node.
    pub fn constant(&mut self, value: f64) -> Id {
        let value = if value == 0.0 { 0.0 } else { value };
        self.intern(Node::Const(value.to_bits()))
    }

    /// Folds `value` if it is finite, otherwise keeps the symbolic `node` (run time will then
    /// report the non-finite value instead of the generator inventing one).
    fn fold_or(&mut self, value: f64, node: Node) -> Id {
        if value.is_finite() {
            self.constant(value)
        } else {
            self.intern(node)
        }
    }

    /// A run-time parameter.
    pub fn param(&mut self, index: u32) -> Id {
        self.intern(Node::Param(index))
    }

    /// A variable (q_k, q̇_k or t).
    pub fn var(&mut self, var: Var) -> Id {
        self.intern(Node::Var(var))
    }

    /// −a
    pub fn neg(&mut self, a: Id) -> Id {
        if !self.simplify {
            return self.intern(Node::Neg(a));
        }
        match self.node(a) {
            Node::Const(bits) => self.constant(-f64::from_bits(bits)),
            Node::Neg(inner) => inner,
            Node::Sub(x, y) => self.sub(y, x),
            // −(c·x) = (−c)·x: the constant absorbs the sign.
            Node::Mul(c, x) if self.as_const(c).is_some() => self.negate_product(c, x),
            _ => self.intern(Node::Neg(a)),
        }
    }

    /// a + b
    pub fn add(&mut self, a: Id, b: Id) -> Id {
        if !self.simplify {
            return self.intern(Node::Add(a, b));
        }
        match (self.node(a), self.node(b)) {
            (Node::Const(x), Node::Const(y)) => {
                let value = f64::from_bits(x) + f64::from_bits(y);
                self.fold_or(value, Node::Add(a, b))
            }
            _ if self.is_zero(a) => b,
            _ if self.is_zero(b) => a,
            (_, Node::Neg(y)) => self.sub(a, y),
            (Node::Neg(x), _) => self.sub(b, x),
            // a + (−c)·y = a − c·y: signs live in the operator, constants stay positive.
            (_, Node::Mul(c, y)) if self.as_const(c).is_some_and(|c| c < 0.0) => {
                let positive = self.negate_product(c, y);
                self.sub(a, positive)
            }
            (Node::Mul(c, x), _) if self.as_const(c).is_some_and(|c| c < 0.0) => {
                let positive = self.negate_product(c, x);
                self.sub(b, positive)
            }
            // Commutative: one canonical operand order so a+b and b+a share a node.
            _ if b < a => self.intern(Node::Add(b, a)),
            _ => self.intern(Node::Add(a, b)),
        }
    }

    /// a − b
    pub fn sub(&mut self, a: Id, b: Id) -> Id {
        if !self.simplify {
            return self.intern(Node::Sub(a, b));
        }
        match (self.node(a), self.node(b)) {
            (Node::Const(x), Node::Const(y)) => {
                let value = f64::from_bits(x) - f64::from_bits(y);
                self.fold_or(value, Node::Sub(a, b))
            }
            _ if a == b => self.zero,
            _ if self.is_zero(b) => a,
            _ if self.is_zero(a) => self.neg(b),
            (_, Node::Neg(y)) => self.add(a, y),
            (_, Node::Mul(c, y)) if self.as_const(c).is_some_and(|c| c < 0.0) => {
                let positive = self.negate_product(c, y);
                self.add(a, positive)
            }
            _ => self.intern(Node::Sub(a, b)),
        }
    }

    /// (−c)·x for a constant node c.
    fn negate_product(&mut self, c: Id, x: Id) -> Id {
        let negated = self.constant(-self.as_const(c).unwrap_or(0.0));
        self.mul(negated, x)
    }

    /// a · b
    pub fn mul(&mut self, a: Id, b: Id) -> Id {
        if !self.simplify {
            return self.intern(Node::Mul(a, b));
        }
        match (self.node(a), self.node(b)) {
            (Node::Const(x), Node::Const(y)) => {
                let value = f64::from_bits(x) * f64::from_bits(y);
                self.fold_or(value, Node::Mul(a, b))
            }
            _ if self.is_zero(a) || self.is_zero(b) => self.zero,
            _ if a == self.one => b,
            _ if b == self.one => a,
            (_, Node::Const(_)) => self.mul(b, a),
            (Node::Const(c), _) if f64::from_bits(c) == -1.0 => self.neg(b),
            // c1 · (c2 · x) = (c1 c2) · x
            (Node::Const(c1), Node::Mul(inner, x)) if self.as_const(inner).is_some() => {
                let value = f64::from_bits(c1) * self.as_const(inner).unwrap_or(1.0);
                if value.is_finite() {
                    let c = self.constant(value);
                    self.mul(c, x)
                } else {
                    self.intern(Node::Mul(a, b))
                }
            }
            // Pull negations out so that −x·y and x·(−y) share x·y.
            (Node::Neg(x), _) => {
                let product = self.mul(x, b);
                self.neg(product)
            }
            (_, Node::Neg(y)) => {
                let product = self.mul(a, y);
                self.neg(product)
            }
            (Node::Const(_), _) => self.intern(Node::Mul(a, b)),
            _ if b < a => self.intern(Node::Mul(b, a)),
            _ => self.intern(Node::Mul(a, b)),
        }
    }

    /// a / b
    pub fn div(&mut self, a: Id, b: Id) -> Id {
        if !self.simplify {
            return self.intern(Node::Div(a, b));
        }
        match (self.node(a), self.node(b)) {
            (Node::Const(x), Node::Const(y)) => {
                let value = f64::from_bits(x) / f64::from_bits(y);
                self.fold_or(value, Node::Div(a, b))
            }
            _ if b == self.one => a,
            _ if self.as_const(b) == Some(-1.0) => self.neg(a),
            _ if self.is_zero(a) && !self.is_zero(b) => self.zero,
            _ if a == b && self.as_const(a).is_none() => self.one,
            _ => self.intern(Node::Div(a, b)),
        }
    }

    /// a raised to the integer power n.
    pub fn powi(&mut self, a: Id, n: i32) -> Id {
        if !self.simplify {
            return self.intern(Node::Powi(a, n));
        }
        match n {
            0 => self.one,
            1 => a,
            _ => match self.node(a) {
                Node::Const(bits) => {
                    let value = f64::from_bits(bits).powi(n);
                    self.fold_or(value, Node::Powi(a, n))
                }
                _ => self.intern(Node::Powi(a, n)),
            },
        }
    }

    /// f(a)
    pub fn call(&mut self, f: Func, a: Id) -> Id {
        if !self.simplify {
            return self.intern(Node::Call(f, a));
        }
        match self.node(a) {
            Node::Const(bits) => {
                let value = f.apply(f64::from_bits(bits));
                self.fold_or(value, Node::Call(f, a))
            }
            _ => self.intern(Node::Call(f, a)),
        }
    }

    /// sin a
    pub fn sin(&mut self, a: Id) -> Id {
        self.call(Func::Sin, a)
    }

    /// cos a
    pub fn cos(&mut self, a: Id) -> Id {
        self.call(Func::Cos, a)
    }

    /// f(a, b)
    pub fn call2(&mut self, f: Func2, a: Id, b: Id) -> Id {
        if !self.simplify {
            return self.intern(Node::Call2(f, a, b));
        }
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => self.fold_or(f.apply(x, y), Node::Call2(f, a, b)),
            // a^1 = a, a^0 = 1 (for every a, as powf has it).
            (_, Some(1.0)) if f == Func2::Pow => a,
            (_, Some(0.0)) if f == Func2::Pow => self.one,
            _ => self.intern(Node::Call2(f, a, b)),
        }
    }

    /// `if a <= b { x } else { y }` (see [`select`]).
    pub fn select(&mut self, a: Id, b: Id, x: Id, y: Id) -> Id {
        if !self.simplify {
            return self.intern(Node::Select(a, b, x, y));
        }
        match (self.as_const(a), self.as_const(b)) {
            (Some(p), Some(q)) if p <= q => x,
            (Some(p), Some(q)) if q < p => y,
            _ if x == y => x,
            _ => self.intern(Node::Select(a, b, x, y)),
        }
    }

    /// Adds a spline table, returning its index for [`Arena::spline`].
    pub fn add_spline(&mut self, table: crate::expr::spline::SplineTable) -> u32 {
        self.splines.push(table);
        u32::try_from(self.splines.len() - 1).expect("spline tables exceed u32")
    }

    /// The spline tables, by index.
    pub fn spline_tables(&self) -> &[crate::expr::spline::SplineTable] {
        &self.splines
    }

    /// Spline table `table`, if it exists.
    pub fn spline_table(&self, table: u32) -> Option<&crate::expr::spline::SplineTable> {
        self.splines.get(table as usize)
    }

    /// The `order`-th derivative of spline `table` at `x` (zero beyond the third: the cubic's
    /// fourth derivative).
    pub fn spline(&mut self, table: u32, order: u8, x: Id) -> Id {
        if order > 3 && self.simplify {
            return self.zero;
        }
        let node = Node::Spline { table, order, x };
        match (self.simplify, self.as_const(x), self.spline_table(table)) {
            (true, Some(value), Some(spline)) => {
                let folded = spline.eval(value, order);
                self.fold_or(folded, node)
            }
            _ => self.intern(node),
        }
    }

    /// The `order`-th time derivative of free degree of freedom `dof`'s state at `t` (the
    /// variable `t`). Orders above 2 are zero: the integrator's state ends at the acceleration,
    /// and nothing needs more (γ differentiates a driver's value twice, from order 0).
    pub fn free(&mut self, dof: u32, order: u8, t: Id) -> Id {
        if order > 2 {
            return self.zero;
        }
        self.intern(Node::Free { dof, order, t })
    }

    /// The operands of a node, in order.
    pub fn children(&self, id: Id) -> impl Iterator<Item = Id> {
        let operands: [Option<Id>; 4] = match self.node(id) {
            Node::Const(_) | Node::Param(_) | Node::Var(_) => [None; 4],
            Node::Neg(a)
            | Node::Powi(a, _)
            | Node::Call(_, a)
            | Node::Spline { x: a, .. }
            | Node::Free { t: a, .. } => [Some(a), None, None, None],
            Node::Add(a, b)
            | Node::Sub(a, b)
            | Node::Mul(a, b)
            | Node::Div(a, b)
            | Node::Call2(_, a, b) => [Some(a), Some(b), None, None],
            Node::Select(a, b, x, y) => [Some(a), Some(b), Some(x), Some(y)],
        };
        operands.into_iter().flatten()
    }

    /// `e` with every variable of `map` replaced by its expression, rebuilt through the
    /// simplifying constructors (so substituting constants folds); `memo` remembers rebuilt
    /// nodes for this `map` across calls. Iterative: deep expressions cannot overflow the stack.
    pub fn substitute(&mut self, e: Id, map: &HashMap<Var, Id>, memo: &mut HashMap<Id, Id>) -> Id {
        let mut stack = vec![(e, false)];
        while let Some((id, expanded)) = stack.pop() {
            if memo.contains_key(&id) {
                continue;
            }
            let node = self.node(id);
            if !expanded {
                stack.push((id, true));
                stack.extend(self.children(id).map(|c| (c, false)));
                continue;
            }
            let get = |x: Id| memo.get(&x).copied().unwrap_or(x);
            let rebuilt = match node {
                Node::Var(v) => map.get(&v).copied().unwrap_or(id),
                Node::Const(_) | Node::Param(_) => id,
                _ if self.children(id).all(|c| get(c) == c) => id,
                Node::Neg(a) => self.neg(get(a)),
                Node::Add(a, b) => self.add(get(a), get(b)),
                Node::Sub(a, b) => self.sub(get(a), get(b)),
                Node::Mul(a, b) => self.mul(get(a), get(b)),
                Node::Div(a, b) => self.div(get(a), get(b)),
                Node::Powi(a, n) => self.powi(get(a), n),
                Node::Call(f, a) => self.call(f, get(a)),
                Node::Call2(f, a, b) => self.call2(f, get(a), get(b)),
                Node::Select(a, b, x, y) => self.select(get(a), get(b), get(x), get(y)),
                Node::Spline { table, order, x } => self.spline(table, order, get(x)),
                // Substituting a value for `t` leaves the state a function of the time it is
                // read at: the node keeps its operand.
                Node::Free { .. } => id,
            };
            memo.insert(id, rebuilt);
        }
        memo.get(&e).copied().unwrap_or(e)
    }

    /// True if the expression reads no variable (a constant or an expression in parameters).
    pub fn is_invariant(&self, id: Id) -> bool {
        !self.any_node(id, |node| matches!(node, Node::Var(_)))
    }

    /// True if `var` occurs in the expression.
    pub fn depends_on(&self, id: Id, var: Var) -> bool {
        self.any_node(id, |node| node == Node::Var(var))
    }

    /// True if some node reachable from `id` satisfies `pred`.
    pub fn any_node(&self, id: Id, pred: impl Fn(Node) -> bool) -> bool {
        // A set rather than an arena-sized vector: the cost follows the expression, not the
        // arena (large scenes ask this of thousands of small expressions).
        let mut seen = HashSet::new();
        let mut stack = vec![id];
        while let Some(next) = stack.pop() {
            if !seen.insert(next) {
                continue;
            }
            if pred(self.node(next)) {
                return true;
            }
            stack.extend(self.children(next));
        }
        false
    }

    /// The variables occurring in an expression, sorted.
    pub fn variables(&self, id: Id) -> Vec<Var> {
        let mut seen = HashSet::new();
        let mut stack = vec![id];
        let mut vars = Vec::new();
        while let Some(next) = stack.pop() {
            if !seen.insert(next) {
                continue;
            }
            if let Node::Var(v) = self.node(next) {
                vars.push(v);
            }
            stack.extend(self.children(next));
        }
        vars.sort_unstable();
        vars
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn setup() -> (Arena, Id, Id) {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let y = a.var(Var::Q(1));
        (a, x, y)
    }

    #[test]
    fn identical_expressions_share_one_node() {
        let (mut a, x, y) = setup();
        let s1 = a.sin(x);
        let s2 = a.sin(x);
        assert_eq!(s1, s2);
        assert_eq!(a.add(x, y), a.add(y, x));
        assert_eq!(a.mul(x, y), a.mul(y, x));
    }

    #[test]
    fn algebra_laws_simplify_on_construction() {
        let (mut a, x, y) = setup();
        let (zero, one) = (a.zero(), a.one());
        assert_eq!(a.add(x, zero), x);
        assert_eq!(a.add(zero, x), x);
        assert_eq!(a.mul(x, zero), zero);
        assert_eq!(a.mul(one, x), x);
        assert_eq!(a.sub(x, x), zero);
        assert_eq!(a.sub(x, zero), x);
        let neg_x = a.neg(x);
        assert_eq!(a.neg(neg_x), x);
        assert_eq!(a.sub(zero, x), neg_x);
        assert_eq!(a.add(y, neg_x), a.sub(y, x));
        let minus_one = a.constant(-1.0);
        assert_eq!(a.mul(minus_one, x), neg_x);
        assert_eq!(a.powi(x, 1), x);
        assert_eq!(a.powi(x, 0), one);
        assert_eq!(a.div(x, one), x);
        assert_eq!(a.div(zero, x), zero);
        let neg_y = a.neg(y);
        let xy = a.mul(x, y);
        let neg_xy = a.neg(xy);
        assert_eq!(a.mul(neg_x, y), neg_xy);
        assert_eq!(a.mul(x, neg_y), neg_xy);
    }

    #[test]
    fn constants_fold_including_functions() {
        let mut a = Arena::new();
        let c2 = a.constant(2.0);
        let c3 = a.constant(3.0);
        let sum = a.add(c2, c3);
        assert_eq!(a.as_const(sum), Some(5.0));
        let product = a.mul(c2, c3);
        assert_eq!(a.as_const(product), Some(6.0));
        let zero = a.zero();
        let s = a.sin(zero);
        assert_eq!(a.as_const(s), Some(0.0));
        let cube = a.powi(c2, 3);
        assert_eq!(a.as_const(cube), Some(8.0));
        let x = a.var(Var::T);
        let three_x = a.mul(c3, x);
        let six_x = a.mul(c2, three_x);
        let six = a.constant(6.0);
        assert_eq!(six_x, a.mul(six, x));
    }

    #[test]
    fn non_finite_results_are_not_folded() {
        let mut a = Arena::new();
        let zero = a.zero();
        let one = a.one();
        let inf = a.div(one, zero);
        assert_eq!(a.as_const(inf), None);
        let ln0 = a.call(Func::Ln, zero);
        assert_eq!(a.as_const(ln0), None);
    }

    #[test]
    fn the_unsimplified_arena_keeps_every_operation() {
        let mut a = Arena::unsimplified();
        let x = a.var(Var::Q(0));
        let zero = a.zero();
        let product = a.mul(x, zero);
        assert!(!a.is_zero(product));
        let c = a.constant(2.0);
        let folded = a.add(c, c);
        assert_eq!(a.as_const(folded), None);
    }

    #[test]
    fn negative_zero_is_zero() {
        let mut a = Arena::new();
        let z = a.constant(-0.0);
        assert_eq!(z, a.zero());
    }

    #[test]
    fn variables_and_dependencies() {
        let (mut a, x, y) = setup();
        let t = a.var(Var::T);
        let s = a.sin(x);
        let e = a.mul(s, t);
        assert_eq!(a.variables(e), vec![Var::Q(0), Var::T]);
        assert!(a.depends_on(e, Var::T));
        assert!(!a.depends_on(e, Var::Q(1)));
        assert!(a.depends_on(y, Var::Q(1)));
    }
}
