//! Free degrees of freedom (`free NAME: KIND(…) from u0 speed v0;`): the driver-like equation
//! `g(q) − u(t)` each adds, and the rules forward dynamics needs of the scene: masses, a mass
//! that each free degree of freedom moves, and forces among the outputs.

use super::Checker;
use crate::expr::{Arena, Id, Var, var_index};
use crate::model::{Body, Free, Model, Outputs};
use crate::sparse::graph::{self, UNMATCHED};
use proc_macro2::Span;

use crate::syntax::spec::{DriverDecl, Expr, ExprKind, Spec};

impl Checker {
    /// Records free degree of freedom `decl` (its driver is constraint `constraint`) and returns
    /// the value its equation holds the driven quantity at: the state `u(t)`.
    pub(super) fn free(
        &mut self,
        decl: &DriverDecl,
        from: Option<&Expr>,
        speed: Option<&Expr>,
        constraint: usize,
    ) -> Id {
        let from = from.map(|e| self.initial(e, "from"));
        let speed = match speed {
            Some(e) => self.initial(e, "speed"),
            None => self.arena.zero(),
        };
        let dof = var_index(self.frees.len());
        self.frees.push(Free {
            name: decl.name.clone(),
            constraint,
            from,
            speed,
        });
        let t = self.arena.var(Var::T);
        self.arena.free(dof, 0, t)
    }

    /// A `from` or `speed` value: numbers and parameters, `t` refused at its token (the
    /// initial state is read once, before time runs).
    fn initial(&mut self, value: &Expr, keyword: &str) -> Id {
        if let Some(span) = time_in(value) {
            self.errors.push(
                span,
                format!(
                    "`{keyword}` gives the free degree of freedom's initial state, before time \
                     runs: write it in numbers and parameters, without `t`"
                ),
            );
        }
        self.lower(value, true)
    }

    /// A parameter named `free` in a scene with free degrees of freedom: the generated struct
    /// holds both as fields.
    pub(super) fn check_free_field(&mut self, spec: &Spec) {
        if !spec.drivers.iter().any(|d| d.free_keyword().is_some()) {
            return;
        }
        for param in spec.params.iter().filter(|p| p.name == "free") {
            self.errors.push(
                param.name.span(),
                "a scene with `free` degrees of freedom keeps their state in a field named \
                 `free`; rename this parameter",
            );
        }
    }

    /// A scene with free degrees of freedom needs forces among its outputs; run before the
    /// model is built (the outputs decide what it derives).
    pub(super) fn check_free_outputs(&mut self, spec: &Spec, outputs: Outputs) {
        let Some(names) = &spec.outputs else {
            return;
        };
        // Only a valid list (one that an error has not already named) that stops short.
        let listed = Outputs::ALL.get(names.len().wrapping_sub(1)) == Some(&outputs);
        let free = spec.drivers.iter().any(|d| d.free_keyword().is_some());
        if free && listed && outputs < Outputs::Forces {
            self.errors.push(
                names[0].span(),
                "a scene with `free` degrees of freedom moves under its forces, so it computes \
                 them: write `outputs positions, velocities, accelerations, forces;` or remove \
                 the `outputs` statement",
            );
        }
    }

    /// The rules on masses, for a scene whose system is square and structurally regular
    /// (`rows`: the coordinates each equation touches): some body has mass, and each free
    /// degree of freedom moves a body with mass (else its reduced mass is zero and the
    /// integrator cannot find its acceleration).
    pub(super) fn check_free_masses(&mut self, spec: &Spec, model: &Model, rows: &[Vec<usize>]) {
        let Some(first) = spec.drivers.iter().find_map(|d| d.free_keyword()) else {
            return;
        };
        if !model.bodies.iter().any(|b| has_mass(&model.arena, b)) {
            self.errors.push(
                first,
                "forward dynamics needs masses: a `free` degree of freedom moves under its \
                 forces, and nothing here has mass; give the bodies `mass`/`inertia` \
                 (`body NAME near (x, y, angle) mass M inertia I;`)",
            );
            return;
        }
        let matching = graph::maximum_matching(rows, model.dim());
        if !matching.is_perfect() {
            return;
        }
        for (k, free) in model.frees.iter().enumerate() {
            let Some(row) = model.free_equation(k) else {
                continue;
            };
            let moved = moved_bodies(rows, &matching.row, row, model.dim());
            if moved
                .iter()
                .any(|&b| has_mass(&model.arena, &model.bodies[b]))
            {
                continue;
            }
            let names: Vec<String> = moved
                .iter()
                .map(|&b| format!("`{}`", model.bodies[b].name))
                .collect();
            self.errors.push(
                free.name.span(),
                format!(
                    "free degree of freedom `{}` moves only massless bodies ({}), so nothing \
                     resists its acceleration; give one of them `mass`/`inertia`, or make it \
                     a `driver`",
                    free.name,
                    names.join(", ")
                ),
            );
        }
    }
}

/// Where `value` reads time `t`, if it does.
fn time_in(value: &Expr) -> Option<Span> {
    match &value.kind {
        ExprKind::Number(_) => None,
        ExprKind::Name(name) => (name == "t").then(|| name.span()),
        ExprKind::Neg(a) | ExprKind::Pow(a, _) => time_in(a),
        ExprKind::Binary(_, a, b) | ExprKind::RealPow(a, b) => time_in(a).or_else(|| time_in(b)),
        ExprKind::Call(_, args) | ExprKind::Tuple(args) => args.iter().find_map(time_in),
    }
}

/// True unless the body has no mass properties or both its mass and inertia are the constant
/// zero (a mass in parameters may be non-zero at run time).
fn has_mass(arena: &Arena, body: &Body) -> bool {
    body.mass
        .is_some_and(|m| !(arena.is_zero(m.mass) && arena.is_zero(m.inertia)))
}

/// The moving bodies whose coordinates change with the value equation `row` holds, in body
/// order: the coordinate the (perfect) matching assigns to `row`, then, to a fixed point,
/// the coordinate of every equation that touches a changed one. That is the downstream closure
/// of `row`'s block in the block-triangular order, whichever perfect matching is used.
fn moved_bodies(rows: &[Vec<usize>], matched: &[usize], row: usize, dim: usize) -> Vec<usize> {
    let mut touching: Vec<Vec<usize>> = vec![Vec::new(); dim];
    for (r, columns) in rows.iter().enumerate() {
        for &c in columns {
            touching[c].push(r);
        }
    }
    let mut moved = vec![false; dim];
    let mut stack = vec![matched[row]];
    while let Some(c) = stack.pop() {
        if c == UNMATCHED || std::mem::replace(&mut moved[c], true) {
            continue;
        }
        stack.extend(touching[c].iter().map(|&r| matched[r]));
    }
    let mut bodies: Vec<usize> = (0..dim).filter(|&c| moved[c]).map(|c| c / 3).collect();
    bodies.dedup();
    bodies
}

#[cfg(test)]
mod tests {
    use crate::syntax::source::parse_str;

    const PENDULUM: &str = "
        ground frame at (0, 0, 0);
        body arm near (0.6, 0.5, 0.7) mass 1.5 inertia 0.02;
        joint pivot: revolute(frame, arm @ (-0.8, 0));
    ";

    /// The messages of checking a pendulum scene with `extra` statements.
    fn errors(extra: &str) -> Vec<String> {
        let source = format!("mechanism M {{ {PENDULUM} {extra} }}");
        let spec = parse_str(&source).unwrap_or_else(|e| panic!("syntax: {e}"));
        match crate::check::check(&spec) {
            Ok(_) => Vec::new(),
            Err(e) => e.messages(),
        }
    }

    #[test]
    fn a_free_pendulum_expands() {
        let source = format!(
            "mechanism M {{ {PENDULUM} free swing: angle(arm) from 0.3; gravity (0, -9.8); }}"
        );
        // The naive baseline (unsimplified arena) too: γ reads the acceleration ü.
        for naive in [false, true] {
            let options = crate::Options {
                codegen: crate::CodegenOptions {
                    naive,
                    ..crate::CodegenOptions::default()
                },
                ..crate::Options::default()
            };
            let expanded = crate::expand(crate::Input::Text(&source), &options);
            let code = expanded.map_err(|e| e.messages()).map(|c| c.to_string());
            assert!(
                code.is_ok_and(|c| c.contains("self . free [0] [2]")),
                "naive: {naive}"
            );
        }
    }

    /// The mobility count speaks of free degrees of freedom in a scene that has them.
    #[test]
    fn the_mobility_count_names_free_degrees_of_freedom() {
        let many =
            errors("free swing: angle(arm) from 0.3; free spin: angle(arm); gravity (0, -9.8);");
        assert!(
            many.iter().any(
                |m| m.starts_with("too many drivers and free degrees of freedom")
                    && m.contains("remove 1, such as `spin`")
            ),
            "{many:?}"
        );
        let few = errors(
            "body bob near (0, -2, 0) mass 1; joint hinge: revolute(arm @ (0.8, 0), bob @ (0, 1));
             free swing: angle(arm); gravity (0, -9.8);",
        );
        assert!(
            few.iter()
                .any(|m| m.contains("drivers and free degrees of freedom")
                    && m.contains("e.g. `free spin: angle(arm);`")),
            "{few:?}"
        );
    }

    #[test]
    fn a_scene_without_masses_is_refused_at_the_first_free() {
        let source = "mechanism M { ground frame at (0, 0, 0); body arm near (1, 0, 0);
            joint pivot: revolute(frame, arm @ (-1, 0)); free swing: angle(arm); }";
        let spec = parse_str(source).unwrap_or_else(|e| panic!("syntax: {e}"));
        let messages = crate::check::check(&spec).err().map(|e| e.messages());
        let messages = messages.unwrap_or_default();
        assert_eq!(messages.len(), 1, "{messages:?}");
        assert!(
            messages[0].starts_with("forward dynamics needs masses")
                && messages[0].contains("give the bodies `mass`/`inertia`"),
            "{messages:?}"
        );
    }

    #[test]
    fn a_free_degree_of_freedom_that_moves_only_massless_bodies_is_named() {
        // `other` hangs from the ground on its own pivot: `spin` moves it alone, and it has no
        // mass (zero mass and inertia count as none); `swing` moves the massive arm.
        let extra = "body other near (0, 1, 0) mass 0 inertia 0; body tip near (0, 2, 0);
            joint hinge: revolute(frame, other); joint stick: weld(other @ (0, 1), tip);
            free swing: angle(arm); free spin: angle(other);";
        let messages = errors(extra);
        assert_eq!(messages.len(), 1, "{messages:?}");
        assert!(
            messages[0].starts_with(
                "free degree of freedom `spin` moves only massless bodies \
                 (`other`, `tip`)"
            ),
            "{messages:?}"
        );
        assert!(errors("free swing: angle(arm);").is_empty());
    }

    #[test]
    fn a_free_scene_computes_forces() {
        let messages = errors("free swing: angle(arm); outputs positions, velocities;");
        assert_eq!(messages.len(), 1, "{messages:?}");
        assert!(
            messages[0].contains("write `outputs positions, velocities, accelerations, forces;`")
        );
        let listed =
            "free swing: angle(arm); outputs positions, velocities, accelerations, forces;";
        assert!(errors(listed).is_empty());
    }

    #[test]
    fn initial_values_are_in_parameters_not_time() {
        let messages = errors("free swing: angle(arm) from t speed 2 * t;");
        assert_eq!(messages.len(), 2, "{messages:?}");
        let from = "`from` gives the free degree of freedom's initial state, before time runs";
        assert!(messages[0].starts_with(from), "{messages:?}");
        assert!(messages[1].starts_with("`speed` gives"), "{messages:?}");
    }

    #[test]
    fn a_free_degree_of_freedom_counts_as_a_driver() {
        let messages = errors("free swing: angle(arm); free again: angle(arm);");
        assert!(messages[0].starts_with("too many drivers"), "{messages:?}");
        let messages = errors("free swing: angle(arm); driver swing: angle(arm) = t;");
        assert!(messages[0].contains("`swing`"), "{messages:?}");
    }

    #[test]
    fn a_prescribed_value_on_a_free_degree_of_freedom_is_a_syntax_error() {
        let source = format!("mechanism M {{ {PENDULUM} free swing: angle(arm) = t; }}");
        let error = parse_str(&source).err().map(|e| e.to_string());
        assert!(
            error
                .is_some_and(|e| e.starts_with("a free degree of freedom has no prescribed value")),
        );
    }

    #[test]
    fn a_parameter_named_free_is_refused_in_a_free_scene() {
        let messages = errors("param free = 1; free swing: angle(arm) from free;");
        assert_eq!(messages.len(), 1, "{messages:?}");
        assert!(
            messages[0].contains("rename this parameter"),
            "{messages:?}"
        );
    }
}
