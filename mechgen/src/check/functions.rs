//! The spec language's functions, lowered to the IR: the elementary ones (`sin`, …, `asin`,
//! `acos`), `atan2`, real powers, `abs`, `min`, `max` (as selections, whose derivative is the
//! selected branch's), `deg`, the motion laws `cycloidal` and `poly345`, and `spline` (natural
//! cubic tables). Arity and constant-folding mistakes are reported at the call's tokens.
//!
//! At a kink, a selection's derivative is its first branch's: `abs` has slope +1 at 0 (its
//! derivative from the right), `min(a, b)` and `max(a, b)` follow `a` on a tie. The motion laws
//! are C² (zero slope and curvature where they start and stop), so a driver built from them has
//! continuous accelerations.

use proc_macro2::Span;
use syn::Ident;

use super::Checker;
use super::resolution::{MIN_LENGTH, RESOLUTION};
use crate::expr::spline::SplineTable;
use crate::expr::{Func, Func2, Id};
use crate::syntax::spec::{Expr, ExprKind};

/// Every function name, with how it is called, for error messages.
const FUNCTIONS: [&str; 16] = [
    "sin(x)",
    "cos(x)",
    "tan(x)",
    "exp(x)",
    "ln(x)",
    "sqrt(x)",
    "asin(x)",
    "acos(x)",
    "atan2(y, x)",
    "abs(x)",
    "min(a, b)",
    "max(a, b)",
    "deg(x)",
    "cycloidal(u)",
    "poly345(u)",
    "spline(x, (x0, y0), (x1, y1), …)",
];

/// Functions of other languages, with what to write instead.
const ALIASES: [(&str, &str); 20] = [
    (
        "atan",
        "`atan2(y, x)` (the angle of (x, y) in all four quadrants; `atan(u)` is `atan2(u, 1)`)",
    ),
    (
        "arctan",
        "`atan2(y, x)` (the angle of (x, y) in all four quadrants; `atan(u)` is `atan2(u, 1)`)",
    ),
    ("atan2f", "`atan2(y, x)`"),
    ("pow", "the power operator: `a^b` for `pow(a, b)`"),
    ("powf", "the power operator: `a^b` for `powf(a, b)`"),
    ("powi", "the power operator: `a^n` for `powi(a, n)`"),
    ("power", "the power operator: `a^b` for `power(a, b)`"),
    ("sqr", "`x^2`"),
    ("cbrt", "`x^(1 / 3)` (for positive x)"),
    ("log", "`ln(x)` (the natural logarithm)"),
    ("log10", "`ln(x) / ln(10)`"),
    ("arcsin", "`asin(x)`"),
    ("arccos", "`acos(x)`"),
    ("fabs", "`abs(x)`"),
    ("hypot", "`sqrt(x^2 + y^2)`"),
    ("sinh", "`(exp(x) - exp(-x)) / 2`"),
    ("cosh", "`(exp(x) + exp(-x)) / 2`"),
    ("tanh", "`(exp(x) - exp(-x)) / (exp(x) + exp(-x))`"),
    (
        "rad",
        "`x * pi / 180`, or `deg(x)`, or a literal in degrees such as `30deg`",
    ),
    (
        "radians",
        "`deg(x)` (x in degrees, as radians), or a literal such as `30deg`",
    ),
];

/// How to fix a call of the unknown function `name`, with the separator before the list of
/// functions: another language's name for a function of the spec language, or the nearest
/// name by edit distance.
fn suggestion(name: &str) -> String {
    if let Some((_, fix)) = ALIASES.iter().find(|(alias, _)| *alias == name) {
        return format!("; write {fix};");
    }
    let names = FUNCTIONS.iter().filter_map(|u| u.split('(').next());
    let usage = super::did_you_mean(name, names).and_then(|nearest| {
        FUNCTIONS
            .iter()
            .find(|u| u.split('(').next() == Some(nearest))
    });
    match usage {
        Some(usage) => format!("; did you mean `{usage}`?"),
        None => ";".to_owned(),
    }
}

/// A number as a user would write it: plain near 1, in exponent form far from it.
fn number(v: f64) -> String {
    if v == 0.0 || (1e-4..1e15).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

impl Checker {
    /// `f(args…)`, lowered.
    pub(super) fn call(
        &mut self,
        span: Span,
        f: &Ident,
        args: &[Expr],
        allow_params: bool,
        allow_t: bool,
    ) -> Id {
        let name = f.to_string();
        let Some(usage) = FUNCTIONS
            .iter()
            .find(|u| u.split('(').next() == Some(&name))
        else {
            let list: Vec<String> = FUNCTIONS.iter().map(|u| format!("`{u}`")).collect();
            self.errors.push(
                f.span(),
                format!(
                    "unknown function `{f}`{} supported functions are {}",
                    suggestion(&name),
                    list.join(", ")
                ),
            );
            return self.arena.zero();
        };
        if name == "spline" {
            return self.spline(span, args, allow_params, allow_t);
        }
        let arity = if usage.contains(',') { 2 } else { 1 };
        if args.len() != arity {
            self.errors.push(
                span,
                format!(
                    "`{name}` takes {} argument{}: `{usage}`",
                    if arity == 1 { "one" } else { "two" },
                    if arity == 1 { "" } else { "s" }
                ),
            );
            return self.arena.zero();
        }
        let lowered: Vec<Id> = args
            .iter()
            .map(|a| self.lower_with(a, allow_params, allow_t))
            .collect();
        let a = lowered[0];
        let b = lowered.get(1).copied().unwrap_or(a);
        self.apply(span, &name, a, b)
    }

    /// A built-in function of one or two lowered arguments (`b` is `a` for one), with the
    /// constant-folding check where its domain is limited.
    fn apply(&mut self, span: Span, name: &str, a: Id, b: Id) -> Id {
        match name {
            "atan2" => {
                let result = self.arena.call2(Func2::Atan2, a, b);
                self.check_folded(span, result, &[a, b], "the result overflows an f64");
                result
            }
            "abs" => {
                let (zero, negative) = (self.arena.zero(), self.arena.neg(a));
                self.arena.select(zero, a, a, negative)
            }
            "min" => self.arena.select(a, b, a, b),
            "max" => self.arena.select(b, a, a, b),
            "deg" => {
                let per_degree = self.arena.constant(core::f64::consts::PI / 180.0);
                self.arena.mul(a, per_degree)
            }
            "cycloidal" => {
                // u − sin(2πu)/(2π) between 0 and 1.
                let two_pi = self.arena.constant(core::f64::consts::TAU);
                let angle = self.arena.mul(two_pi, a);
                let sine = self.arena.sin(angle);
                let wave = self.arena.div(sine, two_pi);
                let rise = self.arena.sub(a, wave);
                self.clamped(a, rise)
            }
            "poly345" => {
                // u³ (10 − 15u + 6u²) between 0 and 1.
                let [six, fifteen, ten] = [6.0, 15.0, 10.0].map(|c| self.arena.constant(c));
                let u2 = self.arena.powi(a, 2);
                let quadratic = self.arena.mul(six, u2);
                let linear = self.arena.mul(fifteen, a);
                let inner = self.arena.sub(ten, linear);
                let inner = self.arena.add(inner, quadratic);
                let u3 = self.arena.powi(a, 3);
                let rise = self.arena.mul(u3, inner);
                self.clamped(a, rise)
            }
            _ => {
                let func = Func::from_name(name).unwrap_or(Func::Sqrt);
                let result = self.arena.call(func, a);
                let hint = match func {
                    Func::Sqrt => "`sqrt` needs an argument ≥ 0",
                    Func::Ln => "`ln` needs a positive argument",
                    Func::Tan => "`tan` is infinite at odd multiples of π/2",
                    Func::Asin | Func::Acos => "`asin` and `acos` need an argument in [−1, 1]",
                    _ => "the result overflows an f64",
                };
                self.check_folded(span, result, &[a], hint);
                result
            }
        }
    }

    /// A rise from 0 to 1 as `u` goes from 0 to 1: 0 before, `rise` between, 1 after.
    /// Whether every spacing of increasing knots is one double precision resolves, reporting
    /// the first that is not at the later knot: at least [`MIN_LENGTH`] (a spline's slopes
    /// and curvatures are its values over the spacing and its square, which a smaller one
    /// overflows, as `(0, 0), (1e-300, 1)` does: a NaN at run time) and at least
    /// [`RESOLUTION`] of the knots' magnitude (closer knots differ only in rounding).
    /// Knots out of order are left to the table's own message.
    fn resolved_knots(&mut self, knots: &[f64], spans: &[Span]) -> bool {
        for k in 1..knots.len().min(spans.len()) {
            let (a, b) = (knots[k - 1], knots[k]);
            let spacing = b - a;
            if spacing <= 0.0 || !spacing.is_finite() {
                continue;
            }
            let size = a.abs().max(b.abs());
            let rule = if spacing < MIN_LENGTH {
                format!(
                    "at least {MIN_LENGTH:e} (the spline's slopes and curvatures, its values \
                         over the spacing and its square, would overflow)"
                )
            } else if spacing < RESOLUTION * size {
                format!(
                    "at least {RESOLUTION:e} of the x values' size (closer knots differ only \
                         in rounding)"
                )
            } else {
                continue;
            };
            self.errors.push(
                spans[k],
                format!(
                    "a spline's x values {} and {} are {} apart; knots must be spaced {rule}: \
                     merge the two points or space them further apart",
                    number(a),
                    number(b),
                    number(spacing),
                ),
            );
            return false;
        }
        true
    }

    fn clamped(&mut self, u: Id, rise: Id) -> Id {
        let (zero, one) = (self.arena.zero(), self.arena.one());
        let upper = self.arena.select(u, one, rise, one);
        self.arena.select(u, zero, zero, upper)
    }

    /// `base ^ exponent` for an exponent that is not an integer literal: an integer power when
    /// it folds to a small integer, otherwise a real power (positive bases only).
    pub(super) fn real_power(&mut self, span: Span, base: Id, exponent: Id) -> Id {
        if let Some(n) = self.arena.as_const(exponent)
            && n == n.trunc()
            && n.abs() <= 64.0
        {
            return self.arena.powi(base, n as i32);
        }
        let result = self.arena.call2(Func2::Pow, base, exponent);
        self.check_folded(
            span,
            result,
            &[base, exponent],
            "a real power needs a positive base (write an integer exponent for a negative one)",
        );
        result
    }

    /// `spline(x, (x0, y0), (x1, y1), …)`: constant, strictly increasing knots; values that
    /// may use parameters (each such value weights its cardinal spline).
    fn spline(&mut self, span: Span, args: &[Expr], allow_params: bool, allow_t: bool) -> Id {
        let usage = "write `spline(x, (x0, y0), (x1, y1), …)` with at least two points";
        let Some((x, points)) = args.split_first().filter(|(_, p)| p.len() >= 2) else {
            self.errors.push(
                span,
                format!("a spline needs its argument and points: {usage}"),
            );
            return self.arena.zero();
        };
        let x = self.lower_with(x, allow_params, allow_t);
        let (knots, knot_spans, values) =
            match self.spline_points(points, usage, allow_params, allow_t) {
                Some(points) => points,
                None => return self.arena.zero(),
            };
        if !self.resolved_knots(&knots, &knot_spans) {
            return self.arena.zero();
        }
        self.spline_sum(span, usage, x, &knots, &values)
    }

    /// A spline's points: the constant knots with their spans, and the lowered values; `None`
    /// after an error (reported).
    fn spline_points(
        &mut self,
        points: &[Expr],
        usage: &str,
        allow_params: bool,
        allow_t: bool,
    ) -> Option<(Vec<f64>, Vec<Span>, Vec<Id>)> {
        let mut knots = Vec::with_capacity(points.len());
        let mut knot_spans = Vec::with_capacity(points.len());
        let mut values = Vec::with_capacity(points.len());
        for point in points {
            let ExprKind::Tuple(pair) = &point.kind else {
                self.errors.push(
                    point.span,
                    format!("a spline point is a pair `(x, y)`; {usage}"),
                );
                return None;
            };
            let [knot, value] = pair.as_slice() else {
                self.errors.push(
                    point.span,
                    format!("a spline point is a pair `(x, y)`; {usage}"),
                );
                return None;
            };
            // Parameters are let through here so that the message below names the rule.
            let knot_id = self.lower_with(knot, true, false);
            match self.arena.as_const(knot_id) {
                Some(k) => {
                    knots.push(k);
                    knot_spans.push(knot.span);
                }
                None => {
                    self.errors.push(
                        knot.span,
                        "a spline's x values must be constant numbers (they fix its knots); its \
                         y values may use parameters",
                    );
                    return None;
                }
            }
            values.push(self.lower_with(value, allow_params, allow_t));
        }
        Some((knots, knot_spans, values))
    }

    /// The spline of `x` through `knots` and `values`: the constant values in one table, each
    /// other value weighting its cardinal spline.
    fn spline_sum(&mut self, span: Span, usage: &str, x: Id, knots: &[f64], values: &[Id]) -> Id {
        let constants: Vec<f64> = values
            .iter()
            .map(|&v| self.arena.as_const(v).unwrap_or(0.0))
            .collect();
        let mut sum = self.arena.zero();
        let mut terms: Vec<(Vec<f64>, Option<Id>)> = Vec::new();
        if constants.iter().any(|&c| c != 0.0) {
            terms.push((constants, None));
        }
        for (j, &v) in values.iter().enumerate() {
            if self.arena.as_const(v).is_none() {
                let cardinal = (0..values.len())
                    .map(|i| f64::from(u8::from(i == j)))
                    .collect();
                terms.push((cardinal, Some(v)));
            }
        }
        for (table_values, weight) in terms {
            let table = match SplineTable::natural(knots, &table_values) {
                Ok(table) => table,
                Err(message) => {
                    self.errors.push(span, format!("{message}; {usage}"));
                    return self.arena.zero();
                }
            };
            let table = self.arena.add_spline(table);
            let law = self.arena.spline(table, 0, x);
            let term = match weight {
                Some(w) => self.arena.mul(w, law),
                None => law,
            };
            sum = self.arena.add(sum, term);
        }
        sum
    }
}
