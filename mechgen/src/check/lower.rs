//! Lowering values to the IR: names to parameters and time, operators to arena nodes, with the
//! rules on where time and parameters may appear, constant lengths recorded for the resolution
//! rules, and constants that fold to NaN or infinity reported.

use proc_macro2::Span;
use syn::Ident;

use super::names::did_you_mean;
use super::{Checker, resolution};
use crate::expr::{Id, Var};
use crate::syntax::spec::{BinOp, Expr, ExprKind};

impl Checker {
    /// Geometry: parameters allowed, time not.
    pub(super) fn geometry(&mut self, e: &Expr) -> Id {
        self.lower_with(e, true, false)
    }

    /// A length of the scene's geometry: a constant one is recorded for the range and
    /// resolution rules ([`resolution`]).
    pub(super) fn length(&mut self, e: &Expr) -> Id {
        let id = self.geometry(e);
        if let Some(value) = self.arena.as_const(id) {
            self.lengths.record(value, e.span);
        }
        id
    }

    /// An angle that only enters through its sine and cosine (a pose, a guess): a constant one
    /// beyond a half turn is reduced to (−π, π].
    pub(super) fn angle(&mut self, e: &Expr) -> Id {
        let id = self.geometry(e);
        match self.arena.as_const(id) {
            Some(value) => self.arena.constant(resolution::reduce_angle(value)),
            None => id,
        }
    }

    /// Reports a constant expression that folded to NaN or infinity (the arena keeps such a
    /// node unfolded): `result` computed from constant `operands` must be a constant.
    pub(super) fn check_folded(&mut self, span: Span, result: Id, operands: &[Id], hint: &str) {
        // The naive baseline folds nothing: the same scene was checked folded.
        if !self.arena.simplifies() {
            return;
        }
        let constant = |id: &Id| self.arena.as_const(*id).is_some();
        if operands.iter().all(constant) && !constant(&result) {
            self.errors.push(
                span,
                format!("this constant expression is NaN or infinite: {hint}"),
            );
        }
    }

    /// A driver's value: parameters and time allowed.
    pub(super) fn lower(&mut self, e: &Expr, allow_t: bool) -> Id {
        self.lower_with(e, true, allow_t)
    }

    pub(super) fn lower_with(&mut self, e: &Expr, allow_params: bool, allow_t: bool) -> Id {
        match &e.kind {
            ExprKind::Number(v) => self.arena.constant(*v),
            ExprKind::Name(name) => self.lower_name(name, allow_params, allow_t),
            ExprKind::Neg(a) => {
                let a = self.lower_with(a, allow_params, allow_t);
                self.arena.neg(a)
            }
            ExprKind::Binary(op, a, b) => {
                let a = self.lower_with(a, allow_params, allow_t);
                let b = self.lower_with(b, allow_params, allow_t);
                let result = match op {
                    BinOp::Add => self.arena.add(a, b),
                    BinOp::Sub => self.arena.sub(a, b),
                    BinOp::Mul => self.arena.mul(a, b),
                    BinOp::Div => {
                        if self.arena.as_const(b) == Some(0.0) {
                            self.errors.push(e.span, "division by zero");
                            return self.arena.div(a, b);
                        }
                        self.arena.div(a, b)
                    }
                };
                self.check_folded(e.span, result, &[a, b], "the result overflows an f64");
                result
            }
            ExprKind::Pow(a, n) => {
                let a = self.lower_with(a, allow_params, allow_t);
                let result = self.arena.powi(a, *n);
                self.check_folded(
                    e.span,
                    result,
                    &[a],
                    "the power overflows an f64, or is a negative power of zero",
                );
                result
            }
            ExprKind::Call(f, args) => self.call(e.span, f, args, allow_params, allow_t),
            ExprKind::RealPow(base, exponent) => {
                let base = self.lower_with(base, allow_params, allow_t);
                let exponent = self.lower_with(exponent, allow_params, allow_t);
                self.real_power(e.span, base, exponent)
            }
            ExprKind::Tuple(_) => {
                self.errors.push(
                    e.span,
                    "a pair `(x, y)` only appears as a spline's point, as in \
                     `spline(t, (0, 0), (1, 2))`",
                );
                self.arena.zero()
            }
        }
    }

    /// A name in a value: `pi`, `t` (where time is allowed), a derived or a run-time parameter
    /// (where parameters are allowed), or an error with the name meant.
    fn lower_name(&mut self, name: &Ident, allow_params: bool, allow_t: bool) -> Id {
        let key = name.to_string();
        if key == "pi" {
            return self.arena.constant(core::f64::consts::PI);
        }
        if key == "t" {
            if !allow_t {
                self.errors.push(
                    name.span(),
                    "time `t` can only appear in a driver's value; geometry and \
                     defaults are constant or use parameters",
                );
            }
            return self.arena.var(Var::T);
        }
        if let Some(&value) = self.derived.get(&key) {
            return self.derived_value(name, value, allow_params);
        }
        match self.params.get(&key) {
            Some(&index) if allow_params => self.arena.param(index),
            Some(_) => {
                self.errors.push(
                    name.span(),
                    "a parameter default must be a number, not another parameter",
                );
                self.arena.zero()
            }
            None => {
                let mut names: Vec<(&String, &u32)> = self.params.iter().collect();
                names.sort_by_key(|(_, i)| **i);
                let close = did_you_mean(&key, names.iter().map(|(n, _)| n.as_str()).chain(["t"]));
                let hint = if let Some(close) = close {
                    format!("did you mean `{close}`?")
                } else if names.is_empty() {
                    "declare it with `param NAME = VALUE;`".to_owned()
                } else {
                    let list: Vec<String> = names.iter().map(|(n, _)| format!("`{n}`")).collect();
                    format!("declared parameters are {}", list.join(", "))
                };
                self.errors.push(
                    name.span(),
                    format!("unknown name `{key}`: not `t` or a parameter; {hint}"),
                );
                self.arena.zero()
            }
        }
    }
}
