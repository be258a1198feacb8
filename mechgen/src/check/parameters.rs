//! Parameters: which are derived (their default names another) and which are set at run time;
//! the run-time ones' constant defaults, and the derived ones lowered as expressions of those
//! declared before them.

use std::collections::HashSet;

use syn::Ident;

use super::Checker;
use crate::expr::{Id, Node};
use crate::model::{Derived, Param};
use crate::syntax::spec::{Expr, ExprKind, Spec};

impl Checker {
    /// Which parameters are derived (their default names another parameter) and which are
    /// run-time parameters, indexed in declaration order.
    pub(super) fn classify_parameters(&mut self, spec: &Spec) {
        let declared: HashSet<String> = spec.params.iter().map(|p| p.name.to_string()).collect();
        let mut index = 0;
        for param in &spec.params {
            let key = param.name.to_string();
            if self.params.contains_key(&key) || self.derived.contains_key(&key) {
                continue;
            }
            if names_any(&param.default, &declared) {
                self.derived.insert(key, None);
            } else {
                self.params.insert(key, crate::expr::var_index(index));
                index += 1;
            }
        }
    }

    /// The run-time parameters with their defaults, and the derived ones lowered in declaration
    /// order (each may use run-time parameters and derived ones declared before it).
    pub(super) fn parameters(&mut self, spec: &Spec) -> (Vec<Param>, Vec<Derived>) {
        let (mut params, mut derived) = (Vec::new(), Vec::new());
        for p in &spec.params {
            let key = p.name.to_string();
            if self.derived.get(&key) == Some(&None) {
                self.computing = Some(key.clone());
                let value = self.lower_with(&p.default, true, false);
                self.computing = None;
                self.derived.insert(key, Some(value));
                derived.push(Derived {
                    name: p.name.clone(),
                    docs: p.docs.clone(),
                    value,
                });
            } else if params.len() < self.params.len() {
                params.push(Param {
                    name: p.name.clone(),
                    docs: p.docs.clone(),
                    default: self.constant(&p.default),
                });
            }
        }
        (params, derived)
    }

    /// A parameter default: a constant expression.
    pub(super) fn constant(&mut self, e: &Expr) -> f64 {
        let before = self.errors.len();
        let id = self.lower_with(e, false, false);
        // An unsimplified arena (naive baseline) does not fold: evaluate instead.
        let value = self.arena.as_const(id).or_else(|| {
            let constant = !self
                .arena
                .any_node(id, |n| matches!(n, Node::Var(_) | Node::Param(_)));
            let value =
                crate::expr::tape::eval(&self.arena, id, &crate::expr::tape::Env::default());
            (constant && value.is_finite()).then_some(value)
        });
        match value {
            Some(v) => v,
            None => {
                if self.errors.len() == before {
                    self.errors.push(
                        e.span,
                        "a parameter default must be a finite constant, such as `314.0`",
                    );
                }
                0.0
            }
        }
    }

    /// A use of derived parameter `name`: its value, or an error where that cannot be (in a
    /// parameter's constant default, or before the derived parameter is computed).
    pub(super) fn derived_value(
        &mut self,
        name: &Ident,
        value: Option<Id>,
        allow_params: bool,
    ) -> Id {
        match value {
            Some(value) if allow_params => value,
            Some(_) => {
                self.errors.push(
                    name.span(),
                    "a parameter default must be a number, not another parameter",
                );
                self.arena.zero()
            }
            None => {
                let message = if self.computing.as_ref() == Some(&name.to_string()) {
                    format!(
                        "`{name}` is computed from itself: compute it from other parameters, \
                         or give it a number to make it a parameter set at run time"
                    )
                } else {
                    format!(
                        "`{name}` is computed from other parameters and is declared after this \
                         use: a parameter can only be computed from parameters declared before \
                         it; move `param {name} = …;` up, or write its expression out"
                    )
                };
                self.errors.push(name.span(), message);
                self.arena.zero()
            }
        }
    }
}

/// Whether `e` names any of `names` (function names excluded).
pub(super) fn names_any(e: &Expr, names: &HashSet<String>) -> bool {
    match &e.kind {
        ExprKind::Number(_) => false,
        ExprKind::Name(name) => names.contains(&name.to_string()),
        ExprKind::Neg(a) | ExprKind::Pow(a, _) => names_any(a, names),
        ExprKind::Binary(_, a, b) | ExprKind::RealPow(a, b) => {
            names_any(a, names) || names_any(b, names)
        }
        ExprKind::Call(_, args) | ExprKind::Tuple(args) => args.iter().any(|a| names_any(a, names)),
    }
}
