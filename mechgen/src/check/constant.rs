//! A lone constant expression, outside any scene: the values a command line gives (`--t-end
//! "2*pi/10"`, `--set gamma=30deg`), written in the scene grammar's expressions without names
//! other than `pi`, and folded to a number by the same lowering as scene values.

use super::Checker;
use crate::error::Errors;
use crate::expr::{Arena, Node};
use crate::syntax::spec::{Expr, ExprKind};

/// The value of `text`, a constant expression: numbers, `pi`, degrees (`30deg`), `+ - * / ^`
/// and the scene grammar's functions (`sqrt(2)`, `atan2(1, 2)`).
///
/// # Errors
/// A message saying what is wrong: a syntax error, a name (a constant expression has no
/// parameters or `t`), or a value that is not a finite number.
pub fn constant_value(text: &str) -> Result<f64, String> {
    let expr: Expr = syn::parse_str(text.trim()).map_err(|e| match e.to_string() {
        m if m.starts_with("unexpected end of input") => "the expression is incomplete".to_owned(),
        m => m,
    })?;
    if let Some(name) = first_name(&expr) {
        return Err(format!(
            "`{name}` is not a number: a value here is a constant expression of numbers, `pi`, \
             degrees and functions, such as `2*pi/10`, `30deg` or `sqrt(2)`"
        ));
    }
    let mut cx = Checker::new(Errors::default(), Arena::new());
    let id = cx.lower_with(&expr, false, false);
    if let Some(message) = cx.errors.messages().into_iter().next() {
        return Err(message);
    }
    let constant = !cx
        .arena
        .any_node(id, |n| matches!(n, Node::Var(_) | Node::Param(_)));
    let value = crate::expr::tape::eval(&cx.arena, id, &crate::expr::tape::Env::default());
    if constant && value.is_finite() {
        // No negative zero in what is written back.
        Ok(value + 0.0)
    } else {
        Err("the expression is not a finite number".to_owned())
    }
}

/// The first name other than `pi` in `expr` (function names are not names).
fn first_name(expr: &Expr) -> Option<String> {
    match &expr.kind {
        ExprKind::Number(_) => None,
        ExprKind::Name(name) => (name != "pi").then(|| name.to_string()),
        ExprKind::Neg(a) | ExprKind::Pow(a, _) => first_name(a),
        ExprKind::Binary(_, a, b) | ExprKind::RealPow(a, b) => {
            first_name(a).or_else(|| first_name(b))
        }
        ExprKind::Call(_, args) | ExprKind::Tuple(args) => args.iter().find_map(first_name),
    }
}

#[cfg(test)]
mod tests {
    use super::constant_value;

    #[test]
    fn folds_the_scene_grammar() {
        let pi = core::f64::consts::PI;
        assert_eq!(constant_value("2*pi/10"), Ok(2.0 * pi / 10.0));
        assert_eq!(constant_value(" 0.02 "), Ok(0.02));
        assert_eq!(constant_value("-1e-3"), Ok(-1e-3));
        assert_eq!(constant_value("90deg"), Ok(pi / 2.0));
        assert_eq!(
            constant_value("sqrt(2)^2 + atan2(1, 1)"),
            Ok(2.0_f64.sqrt().powi(2) + pi / 4.0)
        );
        assert_eq!(constant_value("-0"), Ok(0.0));
        assert!(constant_value("-0").is_ok_and(|v| v.is_sign_positive()));
    }

    #[test]
    fn says_what_is_wrong() {
        let err = |s: &str| constant_value(s).expect_err(s);
        assert!(err("2*pi/").contains("incomplete"), "{}", err("2*pi/"));
        assert!(err("2*t").contains("`t` is not a number"));
        assert!(err("omega").contains("constant expression"));
        assert!(
            err("sqrt(-1)").contains("NaN or infinite"),
            "{}",
            err("sqrt(-1)")
        );
        assert!(
            err("1e308 * 10").contains("NaN or infinite"),
            "{}",
            err("1e308*10")
        );
        assert!(err("sinn(1)").contains("sinn"), "{}", err("sinn(1)"));
        assert!(err("1 2").contains("unexpected token"), "{}", err("1 2"));
    }
}
