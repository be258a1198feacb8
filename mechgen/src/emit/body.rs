//! Function bodies: the DAG reachable from a function's outputs as straight-line Rust, in a
//! deterministic topological order. A node used more than once, and every elementary function
//! call, becomes a `let`; a node used once is written inline, parenthesised so the code
//! evaluates exactly the DAG's order (the interpreter's rounding). Bodies larger than
//! `max_function_size` are split into helper parts.

use std::cell::RefCell;
use std::collections::{BTreeSet, HashMap, HashSet};

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

use super::{CodegenOptions, idx};
use crate::expr::tape::topological_order_with;
use crate::expr::{Arena, Func, Id, Node, Var};
use crate::model::{COORDINATE_SUFFIXES, Model};
use crate::plan::stats::OpCounts;

/// One generated function body with the names its arguments must take (`q` or `_q` if unused).
pub(super) struct Function {
    pub body: TokenStream,
    /// Argument names for q, q̇, q̈, t (`_q` … when unused).
    pub args: Args,
    pub counts: OpCounts,
}

/// The argument names a body reads its inputs under: `q` or `_q` when it does not read them.
#[derive(Debug, Clone)]
pub(super) struct Args {
    pub q: Ident,
    pub qd: Ident,
    pub qdd: Ident,
    pub lambda: Ident,
    pub trig: Ident,
    pub t: Ident,
}

/// Which inputs a body reads.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Reads {
    pub q: bool,
    pub qd: bool,
    pub qdd: bool,
    pub lambda: bool,
    pub trig: bool,
    pub t: bool,
}

/// No cached nodes: every node is computed.
pub(super) fn computed() -> HashMap<Id, usize> {
    HashMap::new()
}

impl Args {
    /// `q`, `qd`, `qdd`, `lambda`, `trig`, `t`, each with a leading underscore when not read.
    pub fn named(reads: Reads) -> Self {
        let arg = |used: bool, name: &str| {
            if used {
                format_ident!("{}", name)
            } else {
                format_ident!("_{}", name)
            }
        };
        Args {
            q: arg(reads.q, "q"),
            qd: arg(reads.qd, "qd"),
            qdd: arg(reads.qdd, "qdd"),
            lambda: arg(reads.lambda, "lambda"),
            trig: arg(reads.trig, "trig"),
            t: arg(reads.t, "t"),
        }
    }

    /// The name of input `q`, `qd`, `qdd`, `lambda`, `trig` or `t`.
    pub fn get(&self, input: &str) -> &Ident {
        match input {
            "qd" => &self.qd,
            "qdd" => &self.qdd,
            "lambda" => &self.lambda,
            "trig" => &self.trig,
            "t" => &self.t,
            _ => &self.q,
        }
    }
}

impl Function {
    /// Two doc lines: what the function writes, and what it costs.
    pub fn doc(&self, what: &str) -> TokenStream {
        let (what, cost) = (
            format!(" Writes {what}."),
            format!(" Operations: {}.", self.counts),
        );
        quote! { #[doc = #what] #[doc = ""] #[doc = #cost] }
    }
}

pub(super) struct Context<'a> {
    pub model: &'a Model,
    /// The model's equation names, for naming multipliers (`lambda_crank_pin_x`).
    pub equations: Vec<String>,
    /// The force solve, for a scene that computes forces.
    pub forces: Option<&'a crate::plan::reactions::Forces>,
    /// The markers' values (from the kinematics).
    pub markers: &'a [Id],
    /// Two values per load naming the one that makes F non-finite (`Scene::load_witnesses`).
    pub load_witnesses: &'a [Id],
    pub options: &'a CodegenOptions,
    /// Helper functions of split bodies, emitted in an inherent `impl` block.
    pub helpers: RefCell<Vec<TokenStream>>,
}

impl Context<'_> {
    pub fn arena(&self) -> &Arena {
        &self.model.arena
    }

    /// Like [`Context::function`], but a body larger than `max_function_size` operations is
    /// split: its outputs are grouped in order into parts of bounded size, each emitted as a
    /// helper method (recomputing the few shared sub-expressions a part needs), and the body
    /// calls them in turn. `outs` are the output parameters (name, type) passed to each part;
    /// `inputs` the inputs (`q`, `qd`, `qdd`, `trig`, with their types) the body may read, and
    /// `cached` the nodes it reads from the trig cache. An input that is also an output
    /// (explicit assignments read and write `q`) is passed once.
    pub fn bounded(
        &self,
        name: &str,
        outputs: &[(TokenStream, Id)],
        clear: TokenStream,
        outs: &[(&str, TokenStream)],
        inputs: &[(&str, TokenStream)],
        cached: &HashMap<Id, usize>,
    ) -> Function {
        let groups = self.partition(outputs);
        if groups.len() <= 1 {
            return self.function(outputs, clear, cached);
        }
        let mut calls = Vec::new();
        let mut counts = OpCounts::default();
        let inputs: Vec<&(&str, TokenStream)> = inputs
            .iter()
            .filter(|(i, _)| !outs.iter().any(|(o, _)| o == i))
            .collect();
        for (k, group) in groups.iter().enumerate() {
            let part_name = format_ident!("{}_part{}", name, k);
            let (call, part_counts) = self.part(&part_name, group, outs, &inputs, cached);
            counts = counts + part_counts;
            calls.push(call);
        }
        let used =
            |i: &str| inputs.iter().any(|(n, _)| *n == i) || outs.iter().any(|(o, _)| *o == i);
        Function {
            body: quote! { #clear #(#calls)* },
            args: Args::named(Reads {
                q: used("q"),
                qd: used("qd"),
                qdd: used("qdd"),
                lambda: used("lambda"),
                trig: used("trig"),
                t: true,
            }),
            counts,
        }
    }

    /// One part of a split body: its helper method, writing the outputs `group` (pushed to
    /// the helpers), and the statement calling it with `inputs` and the `outs` it writes.
    fn part(
        &self,
        part_name: &Ident,
        group: &[(TokenStream, Id)],
        outs: &[(&str, TokenStream)],
        inputs: &[&(&str, TokenStream)],
        cached: &HashMap<Id, usize>,
    ) -> (TokenStream, OpCounts) {
        // Only the outputs this part writes (a Φ part of `phi_and_jacobian` takes no Φ_q).
        let written: Vec<&(&str, TokenStream)> = outs
            .iter()
            .filter(|(o, _)| group.iter().any(|(target, _)| writes_to(target, o)))
            .collect();
        let out_names: Vec<Ident> = written
            .iter()
            .map(|(o, _)| format_ident!("{}", o))
            .collect();
        let out_types: Vec<&TokenStream> = written.iter().map(|(_, ty)| ty).collect();
        let part = self.function(group, TokenStream::new(), cached);
        let params = inputs.iter().map(|(i, ty)| {
            let ident = part.args.get(i);
            quote!(#ident: #ty,)
        });
        let arguments = inputs.iter().map(|(i, _)| {
            let ident = format_ident!("{}", i);
            quote!(#ident,)
        });
        let t = &part.args.t;
        let body = &part.body;
        self.helpers.borrow_mut().push(quote! {
            #[inline(never)]
            fn #part_name(
                &self,
                #(#params)*
                #t: f64,
                #(#out_names: #out_types),*
            ) {
                #body
            }
        });
        let call = quote! { self.#part_name(#(#arguments)* t, #(#out_names),*); };
        (call, part.counts)
    }

    /// `::mechgen_runtime::Vector<Const<N>>` for this scene.
    pub fn vector_type(&self) -> TokenStream {
        let n = idx(self.model.dim());
        quote!(::mechgen_runtime::Vector<::mechgen_runtime::nalgebra::Const<#n>>)
    }

    /// Non-zero `outputs`, in order, grouped so that each group's DAG nodes plus its output
    /// stores number at most `max_function_size` (an output larger than that on its own is a
    /// group by itself).
    pub fn partition(&self, outputs: &[(TokenStream, Id)]) -> Vec<Vec<(TokenStream, Id)>> {
        let arena = self.arena();
        let max = self.options.max_function_size.max(1);
        // The group whose DAG already holds each node (absent: none yet).
        let mut group_of: HashMap<Id, usize> = HashMap::new();
        let mut groups: Vec<Vec<(TokenStream, Id)>> = vec![Vec::new()];
        let mut size = 0;
        let mut fresh = Vec::new();
        for (target, id) in outputs.iter().filter(|(_, id)| !arena.is_zero(*id)) {
            // Each output is a store as well as the nodes it needs: a part of thousands of
            // stores of shared constants is still a big function for rustc.
            new_nodes(arena, *id, &group_of, groups.len(), &mut fresh);
            if size + fresh.len() + 1 > max && !groups.last().is_some_and(Vec::is_empty) {
                groups.push(Vec::new());
                size = 0;
                new_nodes(arena, *id, &group_of, groups.len(), &mut fresh);
            }
            for node in &fresh {
                group_of.insert(*node, groups.len());
            }
            size += fresh.len() + 1;
            if let Some(group) = groups.last_mut() {
                group.push((target.clone(), *id));
            }
        }
        groups
    }

    /// A function body writing `outputs` (non-zero entries; zeros are cleared in one call).
    ///
    /// An output with an empty target is written as a bare expression: as the last output, it
    /// is the body's value (a block's tail). The cost follows the function's DAG, not the
    /// arena: large scenes emit thousands of small bodies.
    ///
    /// The nodes of `cached` are read from the trig cache (`trig[i]`) instead of computed.
    pub fn function(
        &self,
        outputs: &[(TokenStream, Id)],
        clear: TokenStream,
        cached: &HashMap<Id, usize>,
    ) -> Function {
        let arena = self.arena();
        let nonzero: Vec<&(TokenStream, Id)> = outputs
            .iter()
            .filter(|(_, id)| !arena.is_zero(*id))
            .collect();
        let roots: Vec<Id> = nonzero.iter().map(|(_, id)| *id).collect();
        // A free degree of freedom's state is read from `self`, not computed from its operand
        // `t`: a leaf here, so a body that reads it does not take `t` for it.
        let order = topological_order_with(arena, &roots, |id| {
            cached.contains_key(&id) || matches!(arena.node(id), Node::Free { .. })
        });
        let counts = if self.options.naive {
            OpCounts::of_tree(arena, &roots)
        } else {
            OpCounts::of(arena, &order)
        };
        let mut writer = Writer::new(self, &order, &roots, cached);
        for &id in &order {
            writer.statement(id);
        }
        writer.finish(&nonzero, clear, counts)
    }

    /// A readable name for a bound node: `rod_theta`, `sin_rod_theta`, `piston_x_dot`, or `e`.
    fn suggest(&self, id: Id) -> String {
        let arena = self.arena();
        let coordinate = |k: u32| {
            let k = k as usize;
            let body = &self.model.bodies[k / 3].name;
            format!("{body}_{}", COORDINATE_SUFFIXES[k % 3])
        };
        match arena.node(id) {
            Node::Var(Var::Q(k)) => coordinate(k),
            Node::Var(Var::Qd(k)) => format!("{}_dot", coordinate(k)),
            Node::Var(Var::Qdd(k)) => format!("{}_ddot", coordinate(k)),
            Node::Var(Var::Lambda(i)) => match self.equations.get(i as usize) {
                Some(name) => format!("lambda_{}", name.replace('.', "_")),
                None => "lambda_".to_owned(),
            },
            Node::Call(f, a) => match arena.node(a) {
                Node::Var(Var::Q(k)) => format!("{}_{}", f.name(), coordinate(k)),
                _ => f.name().to_owned() + "_",
            },
            Node::Call2(f, ..) => f.name().to_owned() + "_",
            Node::Spline { .. } => "law_".to_owned(),
            _ => "e".to_owned(),
        }
    }
}

/// True if an output target (`out[3]`, `jacobian[(1, 2)]`) writes to the parameter `name`.
pub(super) fn writes_to(target: &TokenStream, name: &str) -> bool {
    matches!(target.clone().into_iter().next(), Some(proc_macro2::TokenTree::Ident(i)) if i == name)
}

/// The nodes reachable from `root` not yet in group `group`, into `fresh` (iterative: scenes can
/// be deep).
fn new_nodes(
    arena: &Arena,
    root: Id,
    group_of: &HashMap<Id, usize>,
    group: usize,
    fresh: &mut Vec<Id>,
) {
    fresh.clear();
    let mut seen = HashSet::new();
    let mut stack = vec![root];
    while let Some(id) = stack.pop() {
        if group_of.get(&id) == Some(&group) || !seen.insert(id) {
            continue;
        }
        fresh.push(id);
        stack.extend(arena.children(id));
    }
}

/// One body being written, node by node in topological order: what each node became (a bound
/// local or inline tokens), the statements so far, and which inputs and functions it reads.
struct Writer<'w, 'a> {
    cx: &'w Context<'a>,
    /// The nodes read from the trig cache, with their slots.
    cached: &'w HashMap<Id, usize>,
    /// How often each node is read, by the body's nodes and as an output.
    uses: HashMap<Id, usize>,
    /// The body's nodes, for pairing `sin(x)` with `cos(x)`.
    in_order: HashSet<Id>,
    names: Names,
    bound: HashMap<Id, Ident>,
    rendered: HashMap<Id, (TokenStream, Prec)>,
    lets: Vec<TokenStream>,
    // Coordinate loads go first, in q order, then the cached trig: the reader sees the
    // inputs, then the work.
    loads: Vec<(Var, TokenStream)>,
    trig_loads: Vec<(usize, TokenStream)>,
    funcs: BTreeSet<&'static str>,
    reads: Reads,
}

impl<'w, 'a> Writer<'w, 'a> {
    /// A writer for the nodes `order` (topological) computing `roots`.
    fn new(
        cx: &'w Context<'a>,
        order: &[Id],
        roots: &[Id],
        cached: &'w HashMap<Id, usize>,
    ) -> Self {
        let arena = cx.arena();
        let mut uses: HashMap<Id, usize> = HashMap::with_capacity(order.len());
        for &id in order {
            for child in arena.children(id) {
                *uses.entry(child).or_insert(0) += 1;
            }
        }
        for &id in roots {
            *uses.entry(id).or_insert(0) += 1;
        }
        Writer {
            cx,
            cached,
            uses,
            in_order: order.iter().copied().collect(),
            names: Names::default(),
            bound: HashMap::new(),
            rendered: HashMap::new(),
            lets: Vec::new(),
            loads: Vec::new(),
            trig_loads: Vec::new(),
            funcs: BTreeSet::new(),
            reads: Reads::default(),
        }
    }

    /// Node `id`'s statement, or its inline tokens (its operands come before it in order).
    fn statement(&mut self, id: Id) {
        if self.bound.contains_key(&id) {
            // The second of a sin/cos pair, bound with the first.
            return;
        }
        if let Some(&i) = self.cached.get(&id) {
            let ident = self.fresh(id);
            let i_lit = idx(i);
            self.trig_loads
                .push((i, quote! { let #ident = trig[#i_lit]; }));
            self.bound.insert(id, ident);
            return;
        }
        let node = self.cx.arena().node(id);
        if let (Some(other), Node::Call(f, a)) = (self.partner(id), node) {
            self.sincos(id, other, f, a);
            return;
        }
        let (tokens, prec) = self.render(node);
        let is_leaf = matches!(
            node,
            Node::Const(_) | Node::Param(_) | Node::Var(Var::T) | Node::Free { .. }
        );
        // Coordinates are loaded once; the naive baseline shares nothing else.
        let call = matches!(node, Node::Call(..) | Node::Call2(..) | Node::Spline { .. });
        let shared = call || self.uses.get(&id).copied().unwrap_or(0) > 1;
        let bind = !is_leaf && (matches!(node, Node::Var(_)) || (shared && !self.cx.options.naive));
        if bind {
            let ident = self.fresh(id);
            let statement = quote! { let #ident = #tokens; };
            match node {
                Node::Var(v) => self.loads.push((v, statement)),
                _ => self.lets.push(statement),
            }
            self.bound.insert(id, ident);
        } else {
            self.rendered.insert(id, (tokens, prec));
        }
    }

    /// A fresh local named after node `id`.
    fn fresh(&mut self, id: Id) -> Ident {
        self.names.fresh(&self.cx.suggest(id))
    }

    /// The cos of a sin node (or the sin of a cos) when the body computes both: sin(x) and
    /// cos(x) of one argument come from one `sincos(x)`, one argument reduction.
    fn partner(&self, id: Id) -> Option<Id> {
        let arena = self.cx.arena();
        match arena.node(id) {
            Node::Call(Func::Sin, a) => arena.find(Node::Call(Func::Cos, a)),
            Node::Call(Func::Cos, a) => arena.find(Node::Call(Func::Sin, a)),
            _ => None,
        }
        .filter(|p| {
            self.in_order.contains(p) && !self.cached.contains_key(p) && !self.cx.options.naive
        })
    }

    /// Binds `f(a)` (sin or cos) at `id` and its partner `other` from one `sincos(a)`.
    fn sincos(&mut self, id: Id, other: Id, f: Func, a: Id) {
        let (sin, cos) = if f == Func::Sin {
            (id, other)
        } else {
            (other, id)
        };
        let argument = self.operand(a).0;
        let (s, c) = (self.fresh(sin), self.fresh(cos));
        self.funcs.insert("sincos");
        self.lets.push(quote! { let (#s, #c) = sincos(#argument); });
        self.bound.insert(sin, s);
        self.bound.insert(cos, c);
    }

    /// An operand: its local if bound, its tokens otherwise.
    fn operand(&self, x: Id) -> (TokenStream, Prec) {
        match self.bound.get(&x) {
            Some(ident) => (quote!(#ident), Prec::Atom),
            None => self
                .rendered
                .get(&x)
                .cloned()
                .unwrap_or_else(|| (quote!(0.0), Prec::Atom)),
        }
    }

    /// The expression computing `node` from its operands, and how strongly it binds.
    fn render(&mut self, node: Node) -> (TokenStream, Prec) {
        match node {
            Node::Const(bits) => {
                let value = f64::from_bits(bits);
                // Negative literals are written `-c` and parenthesised like a sum in operands.
                let prec = if value < 0.0 { Prec::Sum } else { Prec::Atom };
                (f64_literal(value), prec)
            }
            Node::Param(i) => {
                let name = &self.cx.model.params[i as usize].name;
                (quote!(self.#name), Prec::Atom)
            }
            Node::Var(v) => self.variable(v),
            Node::Neg(a) => {
                let a = self.operand(a).wrap(Prec::Unary);
                (quote!(-#a), Prec::Unary)
            }
            Node::Add(a, b) => binary(self.operand(a), quote!(+), self.operand(b), Prec::Sum),
            Node::Sub(a, b) => binary(self.operand(a), quote!(-), self.operand(b), Prec::Sum),
            Node::Mul(a, b) => binary(self.operand(a), quote!(*), self.operand(b), Prec::Product),
            Node::Div(a, b) => binary(self.operand(a), quote!(/), self.operand(b), Prec::Product),
            Node::Powi(a, n) => {
                self.funcs.insert("powi");
                let a = self.operand(a).0;
                (quote!(powi(#a, #n)), Prec::Atom)
            }
            Node::Call(f, a) => {
                self.funcs.insert(f.name());
                let f_ident = format_ident!("{}", f.name());
                let a = self.operand(a).0;
                (quote!(#f_ident(#a)), Prec::Atom)
            }
            Node::Call2(f, a, b) => {
                self.funcs.insert(f.name());
                let f_ident = format_ident!("{}", f.name());
                let (a, b) = (self.operand(a).0, self.operand(b).0);
                (quote!(#f_ident(#a, #b)), Prec::Atom)
            }
            Node::Select(a, b, x, y) => {
                self.funcs.insert("select");
                let [a, b, x, y] = [a, b, x, y].map(|o| self.operand(o).0);
                (quote!(select(#a, #b, #x, #y)), Prec::Atom)
            }
            Node::Spline { table, order, x } => {
                let table = format_ident!("SPLINE_{}", table);
                let order = Literal::u8_unsuffixed(order);
                let x = self.operand(x).0;
                (quote!(Self::#table.eval(#x, #order)), Prec::Atom)
            }
            Node::Free { dof, order, .. } => {
                let (dof, order) = (idx(dof as usize), idx(usize::from(order)));
                (quote!(self.free[#dof][#order]), Prec::Atom)
            }
        }
    }

    /// An input: `t`, or an element of `q`, `qd`, `qdd` or `lambda` (noted as read).
    fn variable(&mut self, v: Var) -> (TokenStream, Prec) {
        let load = |vector: &str, k: u32| {
            let (vector, k) = (format_ident!("{}", vector), idx(k as usize));
            (quote!(#vector[#k]), Prec::Atom)
        };
        match v {
            Var::T => {
                self.reads.t = true;
                (quote!(t), Prec::Atom)
            }
            Var::Q(k) => {
                self.reads.q = true;
                load("q", k)
            }
            Var::Qd(k) => {
                self.reads.qd = true;
                load("qd", k)
            }
            Var::Qdd(k) => {
                self.reads.qdd = true;
                load("qdd", k)
            }
            Var::Lambda(i) => {
                self.reads.lambda = true;
                load("lambda", i)
            }
        }
    }

    /// The body: the math imports, the input loads (q order, then trig slots), the shared
    /// values, `clear`, then the writes of `outputs`.
    fn finish(
        mut self,
        outputs: &[&(TokenStream, Id)],
        clear: TokenStream,
        counts: OpCounts,
    ) -> Function {
        let writes: Vec<TokenStream> = outputs
            .iter()
            .map(|(target, id)| {
                let value = self.operand(*id).0;
                if target.is_empty() {
                    value
                } else {
                    quote! { #target = #value; }
                }
            })
            .collect();
        let imports = if self.funcs.is_empty() {
            TokenStream::new()
        } else {
            let funcs = self.funcs.iter().map(|f| format_ident!("{}", f));
            quote! { use ::mechgen_runtime::codegen::math::{#(#funcs),*}; }
        };
        self.loads.sort_by_key(|(v, _)| *v);
        self.trig_loads.sort_by_key(|(i, _)| *i);
        self.reads.trig = !self.trig_loads.is_empty();
        let loads = self
            .loads
            .into_iter()
            .map(|(_, statement)| statement)
            .chain(self.trig_loads.into_iter().map(|(_, statement)| statement));
        let lets = self.lets;
        Function {
            body: quote! { #imports #(#loads)* #(#lets)* #clear #(#writes)* },
            args: Args::named(self.reads),
            counts,
        }
    }
}

/// Unique, hygienic local names (numbered where a suggestion repeats).
#[derive(Default)]
struct Names {
    taken: HashSet<String>,
    counter: usize,
}

impl Names {
    fn fresh(&mut self, suggestion: &str) -> Ident {
        let numbered = suggestion.ends_with('_') || suggestion == "e";
        let mut candidate = suggestion.trim_end_matches('_').to_owned();
        if numbered || self.taken.contains(&candidate) || Func::from_name(&candidate).is_some() {
            loop {
                let next = format!("{}{}", candidate.trim_end_matches('_'), self.counter);
                self.counter += 1;
                if !self.taken.contains(&next) {
                    candidate = next;
                    break;
                }
            }
        }
        self.taken.insert(candidate.clone());
        Ident::new(&candidate, Span::mixed_site())
    }
}

/// Binding strength, for parenthesising inlined operands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Prec {
    Sum,
    Product,
    Unary,
    Atom,
}

trait Wrap {
    fn wrap(self, min: Prec) -> TokenStream;
}

impl Wrap for (TokenStream, Prec) {
    fn wrap(self, min: Prec) -> TokenStream {
        let (tokens, prec) = self;
        if prec < min {
            quote!((#tokens))
        } else {
            tokens
        }
    }
}

/// `a op b`, left-associative: the right operand is parenthesised at equal precedence so the
/// generated code evaluates in exactly the DAG's order (same rounding as the interpreter).
fn binary(
    a: (TokenStream, Prec),
    op: TokenStream,
    b: (TokenStream, Prec),
    prec: Prec,
) -> (TokenStream, Prec) {
    let a = a.wrap(prec);
    let b = if b.1 <= prec {
        let tokens = b.0;
        quote!((#tokens))
    } else {
        b.0
    };
    (quote!(#a #op #b), prec)
}

/// An `f64` literal that round-trips exactly (`-c` for negative values; operands that need it
/// are parenthesised by the caller).
pub fn f64_literal(value: f64) -> TokenStream {
    if !value.is_finite() {
        // Unreachable for checked models (literals are validated, folding keeps finiteness);
        // kept total so emission can never panic.
        return if value.is_nan() {
            quote!(f64::NAN)
        } else if value > 0.0 {
            quote!(f64::INFINITY)
        } else {
            quote!(f64::NEG_INFINITY)
        };
    }
    let magnitude = value.abs();
    // `{:?}` is the shortest representation that round-trips, with an exponent for extremes.
    let text = format!("{magnitude:?}");
    let literal: Literal = text
        .parse()
        .unwrap_or_else(|_| Literal::f64_unsuffixed(magnitude));
    // A folded `pi` or `2 * pi` written out would trip clippy's `approx_constant` in the
    // user's crate: the constants are named instead.
    let literal = match named_constant(magnitude) {
        Some(name) => {
            let name = quote::format_ident!("{}", name);
            quote!(::core::f64::consts::#name)
        }
        None => quote!(#literal),
    };
    if value.is_sign_negative() {
        quote!(-#literal)
    } else {
        quote!(#literal)
    }
}

/// The name of the `core::f64::consts` constant equal to `value`, if any (those clippy's
/// `approx_constant` recognises).
fn named_constant(value: f64) -> Option<&'static str> {
    use core::f64::consts as c;
    [
        (c::E, "E"),
        (c::FRAC_1_PI, "FRAC_1_PI"),
        (c::FRAC_1_SQRT_2, "FRAC_1_SQRT_2"),
        (c::FRAC_2_PI, "FRAC_2_PI"),
        (c::FRAC_2_SQRT_PI, "FRAC_2_SQRT_PI"),
        (c::FRAC_PI_2, "FRAC_PI_2"),
        (c::FRAC_PI_3, "FRAC_PI_3"),
        (c::FRAC_PI_4, "FRAC_PI_4"),
        (c::FRAC_PI_6, "FRAC_PI_6"),
        (c::FRAC_PI_8, "FRAC_PI_8"),
        (c::LN_10, "LN_10"),
        (c::LN_2, "LN_2"),
        (c::LOG10_E, "LOG10_E"),
        (c::LOG2_E, "LOG2_E"),
        (c::LOG2_10, "LOG2_10"),
        (c::LOG10_2, "LOG10_2"),
        (c::PI, "PI"),
        (c::SQRT_2, "SQRT_2"),
        (c::TAU, "TAU"),
    ]
    .into_iter()
    .find(|&(constant, _)| constant == value)
    .map(|(_, name)| name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_constants_are_emitted_by_name() {
        assert_eq!(
            f64_literal(-std::f64::consts::TAU).to_string(),
            "- :: core :: f64 :: consts :: TAU"
        );
        assert_eq!(f64_literal(3.0).to_string(), "3.0");
    }

    #[test]
    fn literals_round_trip() {
        for v in [
            0.0,
            1.0,
            156.8,
            1e-6,
            1e-300,
            6.02e23,
            0.1 + 0.2,
            f64::MAX,
            -2.5,
        ] {
            let text = f64_literal(v).to_string().replace(['(', ')', ' '], "");
            assert_eq!(text.parse::<f64>().unwrap(), v, "{text}");
        }
        assert_eq!(f64_literal(-2.5).to_string(), "- 2.5");
        assert_eq!(f64_literal(3.0).to_string(), "3.0");
    }

    #[test]
    fn names_are_unique_and_numbered() {
        let mut names = Names::default();
        assert_eq!(names.fresh("rod_theta").to_string(), "rod_theta");
        assert_eq!(names.fresh("rod_theta").to_string(), "rod_theta0");
        assert_eq!(names.fresh("e").to_string(), "e1");
        assert_eq!(names.fresh("sin_").to_string(), "sin2");
    }
}
