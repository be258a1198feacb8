//! Checking: resolve names, lower values to the IR, count degrees of freedom, and report every
//! problem at the tokens that caused it, with a hint on how to fix it.
//!
//! All errors are collected and returned together (serde's `Ctxt` habit), so a user fixing a
//! scene sees everything at once rather than one error per build.
//!
//! [`check_into`] runs the rules in order; each has its file: `points` (named points replaced
//! by what they name, first), `names` (one namespace; bodies and points resolved; typo
//! suggestions), `outputs`, `parameters` (run-time and derived), `lower` (values to the IR),
//! `functions` (calls and splines), `constant` (constant expressions), `library` (joints,
//! drivers, markers), `branches`, `dynamics` (mass properties, gravity, loads), `resolution`
//! (what double precision resolves), `mobility` (connected bodies, the Gruebler count), `rank`
//! (structural rank of Φ_q) and `redundancy` (which constraint to remove).

mod branches;
mod constant;
mod dynamics;
mod free;
mod functions;
mod library;
mod lower;
mod mobility;
mod names;
mod outputs;
mod parameters;
mod points;
mod rank;
mod redundancy;
pub mod resolution;

pub use constant::constant_value;
pub use names::did_you_mean;
pub use rank::Structure;

use std::collections::HashMap;

use crate::error::Errors;
use crate::expr::{Arena, Id};
use crate::model::{Body, Branch, Constraint, ConstraintKind, Model, Point};
use crate::syntax::spec::{DriverValue, Spec};
use resolution::Lengths;

/// Checks a spec and builds its model.
///
/// # Errors
/// Every problem found, each at its span: unknown or duplicate names, joints from a body to
/// itself or between two ground bodies, drivers on ground bodies, zero axes or distances,
/// `t` outside drivers, unknown functions, malformed branch invariants, drivers not matching
/// the degrees of freedom, and structurally redundant constraints (see [`Structure`]).
pub fn check(spec: &Spec) -> Result<Model, Errors> {
    check_into(spec, Arena::new())
}

/// [`check`] building into a given arena ([`Arena::unsimplified`] for the naive baseline).
///
/// # Errors
/// As [`check`].
pub fn check_into(spec: &Spec, arena: Arena) -> Result<Model, Errors> {
    // Named points are replaced by what they name before anything else looks at the spec.
    let mut errors = Errors::default();
    let substituted = points::substitute(spec, &mut errors);
    let spec = substituted.as_ref().unwrap_or(spec);
    let mut cx = Checker::new(errors, arena);
    cx.check_names(spec);
    let outputs = cx.outputs(spec);
    cx.check_free_outputs(spec, outputs);
    cx.check_free_field(spec);

    let (params, derived) = cx.parameters(spec);
    cx.ground = spec.bodies.iter().map(|b| b.ground).collect();

    let bodies = cx.bodies(spec);
    let constraints = cx.constraints(spec, &bodies);
    let branches: Vec<Branch> = spec
        .branches
        .iter()
        .filter_map(|decl| cx.branch(decl))
        .collect();
    let gravity = cx.gravity(spec);
    let loads = spec.loads.iter().filter_map(|decl| cx.load(decl)).collect();
    let markers = spec
        .markers
        .iter()
        .filter_map(|decl| cx.marker(decl))
        .collect();
    cx.check_forces(spec, outputs);
    // A rejected joint or driver would make the degree-of-freedom count misleading: count only a
    // scene whose parts all checked.
    let count = cx.errors.is_empty();
    let mut model = Model {
        docs: spec.docs.clone(),
        vis: spec.vis.clone(),
        name: spec.name.clone(),
        arena: std::mem::take(&mut cx.arena),
        params,
        derived,
        bodies,
        constraints,
        branches,
        gravity,
        loads,
        markers,
        outputs,
        frees: std::mem::take(&mut cx.frees),
    };
    if count {
        let rows = Structure::rows_of(&mut model);
        let structure = Structure::of_pattern(&rows, model.dim());
        cx.check_mobility(spec, &model, &structure, &rows);
        if cx.errors.is_empty() {
            cx.check_free_masses(spec, &model, &rows);
        }
    }
    cx.lengths.check(&mut cx.errors);
    cx.errors.finish()?;
    Ok(model)
}

/// The checker's state while it walks a spec: the errors so far, the arena it lowers into and
/// the name tables.
struct Checker {
    errors: Errors,
    arena: Arena,
    bodies: HashMap<String, usize>,
    params: HashMap<String, u32>,
    /// Derived parameters: their value once lowered, `None` while not yet (declared later, or
    /// the one being lowered).
    derived: HashMap<String, Option<Id>>,
    /// The derived parameter being lowered.
    computing: Option<String>,
    /// Named points, with the names of their bodies.
    points: HashMap<String, String>,
    /// Prismatic joints by name, for `travel` drivers: (a, b, unit axis).
    prismatic: HashMap<String, (Point, Point, [Id; 2])>,
    ground: Vec<bool>,
    /// Free degrees of freedom, as their drivers are checked.
    frees: Vec<crate::model::Free>,
    /// Constant lengths, for the range and resolution rules.
    lengths: Lengths,
}

impl Checker {
    fn new(errors: Errors, arena: Arena) -> Self {
        Checker {
            errors,
            arena,
            bodies: HashMap::new(),
            params: HashMap::new(),
            derived: HashMap::new(),
            computing: None,
            points: HashMap::new(),
            prismatic: HashMap::new(),
            ground: Vec::new(),
            frees: Vec::new(),
            lengths: Lengths::default(),
        }
    }

    /// The bodies with their poses (a ground body's position is scene geometry, a moving
    /// body's a guess) and mass properties.
    fn bodies(&mut self, spec: &Spec) -> Vec<Body> {
        spec.bodies
            .iter()
            .map(|b| Body {
                name: b.name.clone(),
                docs: b.docs.clone(),
                ground: b.ground,
                pose: {
                    // A ground body's position is scene geometry; a guess is only a start.
                    let [x, y, angle] = &b.pose;
                    let (x, y) = if b.ground {
                        (self.length(x), self.length(y))
                    } else {
                        (self.geometry(x), self.geometry(y))
                    };
                    [x, y, self.angle(angle)]
                },
                mass: self.mass(b),
            })
            .collect()
    }

    /// The constraints in equation order: ground poses, then joints, then drivers.
    fn constraints(&mut self, spec: &Spec, bodies: &[Body]) -> Vec<Constraint> {
        let mut constraints: Vec<Constraint> = bodies
            .iter()
            .enumerate()
            .filter(|(_, b)| b.ground)
            .map(|(i, b)| Constraint {
                name: b.name.to_string(),
                kind: ConstraintKind::Ground {
                    body: i,
                    pose: b.pose,
                },
            })
            .collect();
        for joint in &spec.joints {
            if let Some(kind) = self.joint(&joint.name, &joint.kind) {
                constraints.push(Constraint {
                    name: joint.name.to_string(),
                    kind,
                });
            }
        }
        for driver in &spec.drivers {
            let driven = self.driven(driver.kind_span, &driver.kind);
            let value = match &driver.value {
                DriverValue::Prescribed(value) => self.lower(value, true),
                DriverValue::Free { from, speed, .. } => {
                    self.free(driver, from.as_ref(), speed.as_ref(), constraints.len())
                }
            };
            if let Some(driven) = driven {
                constraints.push(Constraint {
                    name: driver.name.to_string(),
                    kind: ConstraintKind::Driver { driven, value },
                });
            }
        }
        constraints
    }
}

fn plural(n: i64) -> &'static str {
    if n == 1 { "" } else { "s" }
}

#[cfg(test)]
mod tests {
    use super::names::edit_distance;
    use super::*;
    use crate::syntax::source::parse_str;

    fn errors(source: &str) -> Vec<String> {
        let spec = parse_str(source).unwrap_or_else(|e| panic!("syntax: {e}"));
        match check(&spec) {
            Ok(_) => Vec::new(),
            Err(e) => e.messages(),
        }
    }

    const SLIDER: &str = "
        param w = 2;
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body rod near (1, 0, 0);
        body slider near (2, 0, 0);
        joint o: revolute(frame, crank);
        joint a: revolute(crank @ (1, 0), rod);
        joint b: revolute(rod @ (2, 0), slider);
        joint s: prismatic(frame, slider, along (1, 0));
    ";

    fn scene(extra: &str) -> String {
        format!("mechanism M {{ {SLIDER} {extra} }}")
    }

    #[test]
    fn the_joint_that_over_constrains_is_named_first() {
        // A distance the loop already imposes: the joint, not the driver, is the culprit.
        let extra = errors(&scene(
            "joint extra: distance(frame, rod @ (2, 0), 3); driver d: angle(crank) = t;",
        ));
        assert_eq!(extra.len(), 1, "{extra:?}");
        assert!(
            extra[0].contains("joint `extra` over-constrains it")
                && extra[0].ends_with("remove joint `extra`, or remove 1 driver, such as `d`"),
            "{extra:?}"
        );
        // A copy of a joint: both are named, the later one first.
        let copy = errors(&scene(
            "joint copy: revolute(rod @ (2, 0), slider); driver d: angle(crank) = t;",
        ));
        assert_eq!(copy.len(), 1, "{copy:?}");
        assert!(copy[0].contains("remove joint `copy` (or `b`)"), "{copy:?}");
        // With freedom left, surplus drivers are still the drivers' fault.
        let drivers = errors(&scene(
            "driver d: angle(crank) = t; driver e: x(slider) = 3 + t;",
        ));
        assert!(drivers[0].starts_with("too many drivers"), "{drivers:?}");
    }

    #[test]
    fn a_valid_scene_checks() {
        let spec = parse_str(&scene("driver d: angle(crank) = w * t;"))
            .unwrap_or_else(|e| panic!("parses: {e}"));
        let model = check(&spec).unwrap_or_else(|e| panic!("checks: {e}"));
        assert_eq!(model.dim(), 12);
        assert_eq!(model.equation_names().len(), 12);
        assert_eq!(model.equation_names()[0], "frame.x");
        assert_eq!(model.equation_names()[11], "d");
        assert_eq!(model.coordinate_names()[3], "crank.x");
    }

    #[test]
    fn reports_every_error_together() {
        let msgs = errors(&scene(
            "joint self_loop: revolute(rod, rod); driver d: angle(wheel) = w * t; \
             driver g: angle(frame) = sin(t); driver h: angle(crank) = q * cosh(t);",
        ));
        let all = msgs.join("\n");
        assert!(all.contains("connects `rod` to itself"), "{all}");
        assert!(all.contains("unknown body `wheel`"), "{all}");
        assert!(all.contains("ground body and never moves"), "{all}");
        assert!(all.contains("unknown name `q`"), "{all}");
        assert!(all.contains("unknown function `cosh`"), "{all}");
    }

    #[test]
    fn unknown_functions_suggest_what_to_write() {
        let msgs = errors(&scene(
            "driver d: angle(crank) = atan(t) + pow(t, 2) + sinn(t) + cosh(t) + frob(t);",
        ));
        let all = msgs.join("\n");
        for expected in [
            "unknown function `atan`; write `atan2(y, x)`",
            "unknown function `pow`; write the power operator: `a^b` for `pow(a, b)`",
            "unknown function `sinn`; did you mean `sin(x)`?",
            "unknown function `cosh`; write `(exp(x) + exp(-x)) / 2`",
            "unknown function `frob`; supported functions are `sin(x)`",
        ] {
            assert!(all.contains(expected), "{expected}: {all}");
        }
    }

    #[test]
    fn spline_knots_must_be_resolvable() {
        let tiny = errors(&scene(
            "driver d: angle(crank) = spline(t, (0, 0), (1e-300, 1));",
        ));
        assert_eq!(
            tiny,
            [
                "a spline's x values 0 and 1e-300 are 1e-300 apart; knots must be spaced at least \
              1e-100 (the spline's slopes and curvatures, its values over the spacing and its \
              square, would overflow): merge the two points or space them further apart"
            ]
        );
        let close = errors(&scene(
            "driver d: angle(crank) = spline(t, (1e6, 0), (1000000.00000001, 1));",
        ));
        assert!(
            close[0].contains("at least 1e-12 of the x values' size"),
            "{close:?}"
        );
        // Spacings double precision resolves are fine, however small the scene's unit.
        assert!(
            errors(&scene(
                "driver d: angle(crank) = spline(t, (0, 0), (1e-90, 1));"
            ))
            .is_empty()
        );
    }

    #[test]
    fn degrees_of_freedom_must_match_drivers() {
        let missing = errors(&scene("")).join("\n");
        assert!(
            missing.contains("1 degree of freedom but 0 drivers"),
            "{missing}"
        );
        let extra = errors(&scene(
            "driver d: angle(crank) = t; driver e: x(slider) = t;",
        ))
        .join("\n");
        assert!(extra.contains("too many drivers"), "{extra}");
    }

    #[test]
    fn duplicate_and_reserved_names() {
        let msgs = errors(&scene("driver crank: angle(crank) = t;")).join("\n");
        assert!(msgs.contains("duplicate name `crank`"), "{msgs}");
        let msgs = errors(&scene("param t = 1; driver d: angle(crank) = t;")).join("\n");
        assert!(msgs.contains("`t` is time"), "{msgs}");
    }

    /// The unit axis of the slider's prismatic joint for `along (ux, uy)`, with `w` set to
    /// `w` (a parameter the axis may read).
    fn unit_axis(along: &str, w: f64) -> [f64; 2] {
        let source = format!(
            "mechanism M {{ param w = {w}; ground f at (0, 0, 0); body b near (0, 0, 0);
               joint p: prismatic(f, b, along ({along})); driver d: travel(p) = t; }}"
        );
        let spec = parse_str(&source).unwrap_or_else(|e| panic!("{e}"));
        let model = check(&spec).unwrap_or_else(|e| panic!("{along}: {e}"));
        let axis = model.constraints.iter().find_map(|c| match c.kind {
            ConstraintKind::Prismatic { axis, .. } => Some(axis),
            _ => None,
        });
        let env = crate::expr::tape::Env {
            params: vec![w],
            ..Default::default()
        };
        axis.expect("a prismatic joint")
            .map(|id| crate::expr::tape::eval(&model.arena, id, &env))
    }

    #[test]
    fn axes_are_normalised_without_squaring_their_length() {
        // 1e-170² underflows to zero and 1e160² overflows: both are the direction (0, 1).
        for along in ["0, 1e-170", "0, 1e160", "0, w", "0, 1"] {
            for w in [1e-170, 1e160, 3.0] {
                assert_eq!(unit_axis(along, w), [0.0, 1.0], "along ({along}), w = {w}");
            }
        }
        let [x, y] = unit_axis("-3e200, 4e200", 1.0);
        assert!(
            (x + 0.6).abs() < 1e-15 && (y - 0.8).abs() < 1e-15,
            "{x}, {y}"
        );
        let [x, y] = unit_axis("3 * w, -4 * w", 1e-200);
        assert!(
            (x - 0.6).abs() < 1e-15 && (y + 0.8).abs() < 1e-15,
            "{x}, {y}"
        );
    }

    #[test]
    fn geometry_cannot_depend_on_time_and_axes_cannot_vanish() {
        let msgs = errors(
            "mechanism M { ground f at (t, 0, 0); body b near (0,0,0);
               joint p: prismatic(f, b, along (0, 0)); joint l: distance(f, b, 0);
               driver d: angle(b) = t; }",
        )
        .join("\n");
        assert!(msgs.contains("time `t` can only appear"), "{msgs}");
        assert!(msgs.contains("zero vector"), "{msgs}");
        assert!(msgs.contains("distance of zero"), "{msgs}");
    }

    #[test]
    fn typos_get_a_suggestion() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(
            did_you_mean("omgea", ["omega", "t"].into_iter()),
            Some("omega")
        );
        assert_eq!(did_you_mean("x", ["t"].into_iter()), None);
        let msgs = errors(&scene("driver d: angle(crnk) = w * t;")).join("\n");
        assert!(msgs.contains("did you mean `crank`?"), "{msgs}");
    }

    #[test]
    fn travel_needs_a_prismatic_joint() {
        let msgs = errors(&scene("driver d: travel(o) = t;")).join("\n");
        assert!(msgs.contains("not a prismatic joint"), "{msgs}");
        assert!(errors(&scene("driver d: travel(s) = 1 + t;")).is_empty());
    }

    #[test]
    fn branch_invariants_check_their_parts() {
        let ok = "branch out: dot(frame -> crank @ (1, 0), rod -> rod @ (2, 0)) > 0; \
                  branch turn: cross(crank -> crank @ (1, 0), frame -> slider) < 0;";
        let spec = parse_str(&scene(&format!("driver d: angle(crank) = w * t; {ok}")))
            .unwrap_or_else(|e| panic!("parses: {e}"));
        let model = check(&spec).unwrap_or_else(|e| panic!("checks: {e}"));
        assert_eq!(model.branches.len(), 2);
        assert_eq!(model.branches[1].sign, crate::model::Sign::Negative);

        let msgs = errors(&scene(
            "driver d: angle(crank) = w * t; \
             branch a: cross(crnk -> rod, rod -> slider) > 0; \
             branch b: dot(crank -> rod, rod -> slider) > 1; \
             branch c: dot(crank @ (t, 0) -> rod, rod -> slider) > 0; \
             branch d: dot(rod @ (1, 2) -> rod @ (1, 2), rod -> slider) > 0; \
             branch e: cross(frame -> frame @ (1, 0), frame @ (0, 1) -> frame) > 0;",
        ))
        .join("\n");
        assert!(
            msgs.contains("unknown body `crnk`; did you mean `crank`?"),
            "{msgs}"
        );
        assert!(
            msgs.contains("compare the branch invariant with `0`"),
            "{msgs}"
        );
        assert!(msgs.contains("time `t` can only appear"), "{msgs}");
        assert!(msgs.contains("to the same point"), "{msgs}");
        assert!(msgs.contains("never changes"), "{msgs}");
        assert!(msgs.contains("duplicate name `d`"), "{msgs}");
    }

    #[test]
    fn matching_finds_the_over_and_under_determined_parts() {
        // Equations 0–2 touch coordinates 0 and 1 only; equation 3 touches 2 and 3.
        let rows = [vec![0, 1], vec![0, 1], vec![1], vec![2, 3]];
        let s = Structure::of_pattern(&rows, 4);
        assert_eq!(s.rank, 3);
        assert_eq!(s.over_equations, [0, 1, 2]);
        assert_eq!(s.over_coordinates, [0, 1]);
        assert_eq!(s.under_coordinates, [2, 3]);
        assert_eq!(s.under_free.len(), 1);
        // A chain needing an augmenting path through every earlier equation.
        let n = 2000;
        let mut rows: Vec<Vec<usize>> = (0..n - 1).map(|i| vec![i, i + 1]).collect();
        rows.push(vec![0]);
        let s = Structure::of_pattern(&rows, n);
        assert_eq!(s.rank, n);
        assert!(s.over_equations.is_empty() && s.under_coordinates.is_empty());
    }

    #[test]
    fn structurally_redundant_joints_are_reported_though_gruebler_matches() {
        // a and b are pinned together twice (and a to the ground), while c keeps its angle free:
        // 12 coordinates, 12 equations, but a singular Jacobian.
        let msgs = errors(
            "mechanism M {
                ground g at (0, 0, 0);
                body a near (1, 0, 0);
                body b near (2, 0, 0);
                body c near (0, 1, 0);
                joint pivot: revolute(g, a @ (-1, 0));
                joint pin_1: revolute(a @ (1, 0), b @ (-1, 0));
                joint pin_2: revolute(a @ (1, 1), b @ (-1, 1));
                joint hinge: revolute(g, c);
                driver spin: angle(a) = t;
            }",
        );
        assert_eq!(msgs.len(), 4, "{msgs:#?}");
        let expected = "structurally redundant constraints: joints `pivot`, `pin_1`, `pin_2` and \
                        driver `spin` over-determine bodies `a`, `b` (7 equations for 6 \
                        coordinates) while body `c` keeps 1 coordinate free (`c.theta`)";
        for message in &msgs {
            assert!(message.starts_with(expected), "{message}");
        }
        // The over-constrained pendulum names its joints.
        let msgs = errors(
            "mechanism P { ground f at (0, 0, 0); body bob near (1, 0, 0);
               joint pivot: revolute(f, bob @ (-1, 0)); joint stop: revolute(f @ (1, 0), bob); }",
        )
        .join("\n");
        assert!(
            msgs.contains("joints `pivot`, `stop` over-determine body `bob` (4 equations for 3"),
            "{msgs}"
        );
    }
}
