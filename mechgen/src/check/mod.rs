//! Checking: resolve names, lower values to the IR, count degrees of freedom, and report every
//! problem at the tokens that caused it, with a hint on how to fix it.
//!
//! All errors are collected and returned together (serde's `Ctxt` habit), so a user fixing a
//! scene sees everything at once rather than one error per build. The dynamics part of a spec
//! (mass properties, gravity, loads) is checked in `check/dynamics.rs`.

mod constant;
mod dynamics;
mod functions;
mod library;
mod points;
mod redundancy;
pub mod resolution;

pub use constant::constant_value;

use std::collections::{HashMap, HashSet};

use proc_macro2::Span;
use syn::Ident;

use crate::error::Errors;
use crate::expr::{Arena, Id, Node, Var};
use crate::model::{
    Body, Branch, Constraint, ConstraintKind, Derived, Model, Outputs, Param, Point,
};
use crate::sparse::graph::{self, UNMATCHED};
use crate::syntax::spec::{BinOp, BranchDecl, Expr, ExprKind, PointRef, Spec};
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
    let mut cx = Checker {
        errors,
        arena,
        bodies: HashMap::new(),
        params: HashMap::new(),
        derived: HashMap::new(),
        computing: None,
        points: HashMap::new(),
        prismatic: HashMap::new(),
        ground: Vec::new(),
        lengths: Lengths::default(),
    };
    cx.check_names(spec);
    let outputs = cx.outputs(spec);

    let (params, derived) = cx.parameters(spec);
    cx.ground = spec.bodies.iter().map(|b| b.ground).collect();

    let bodies: Vec<Body> = spec
        .bodies
        .iter()
        .map(|b| Body {
            name: b.name.clone(),
            docs: b.docs.clone(),
            ground: b.ground,
            pose: {
                // A ground body's position is scene geometry; a guess is only a start.
                let [x, y, angle] = &b.pose;
                let (x, y) = if b.ground {
                    (cx.length(x), cx.length(y))
                } else {
                    (cx.geometry(x), cx.geometry(y))
                };
                [x, y, cx.angle(angle)]
            },
            mass: cx.mass(b),
        })
        .collect();

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
        if let Some(kind) = cx.joint(&joint.name, &joint.kind) {
            constraints.push(Constraint {
                name: joint.name.to_string(),
                kind,
            });
        }
    }
    for driver in &spec.drivers {
        let driven = cx.driven(driver.kind_span, &driver.kind);
        let value = cx.lower(&driver.value, true);
        if let Some(driven) = driven {
            constraints.push(Constraint {
                name: driver.name.to_string(),
                kind: ConstraintKind::Driver { driven, value },
            });
        }
    }
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
    };
    if count {
        let rows = Structure::rows_of(&mut model);
        let structure = Structure::of_pattern(&rows, model.dim());
        cx.check_mobility(spec, &model, &structure, &rows);
    }
    cx.lengths.check(&mut cx.errors);
    cx.errors.finish()?;
    Ok(model)
}

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
    /// Constant lengths, for the range and resolution rules.
    lengths: Lengths,
}

impl Checker {
    /// Every declared name is unique across parameters, bodies, joints, drivers, branches,
    /// loads and markers (they share the generated namespace: fields, accessors, equation,
    /// branch and column names); `t` and `pi` are reserved.
    fn check_names(&mut self, spec: &Spec) {
        let mut seen: HashMap<String, &str> = HashMap::new();
        let names = spec
            .params
            .iter()
            .map(|p| (&p.name, "parameter"))
            .chain(spec.bodies.iter().map(|b| (&b.name, "body")))
            .chain(spec.joints.iter().map(|j| (&j.name, "joint")))
            .chain(spec.drivers.iter().map(|d| (&d.name, "driver")))
            .chain(spec.branches.iter().map(|b| (&b.name, "branch")))
            .chain(spec.loads.iter().map(|l| (&l.name, "load")))
            .chain(spec.markers.iter().map(|m| (&m.name, "marker")))
            .chain(spec.points.iter().map(|p| (&p.name, "point")));
        for (name, what) in names {
            let key = name.to_string();
            if key == "t" || key == "pi" {
                let meaning = if key == "t" {
                    "`t` is time"
                } else {
                    "`pi` is π"
                };
                self.errors.push(
                    name.span(),
                    format!("{meaning}; give this {what} another name"),
                );
                continue;
            }
            if let Some(first) = seen.get(&key) {
                self.errors.push(
                    name.span(),
                    format!(
                        "duplicate name `{key}`: a {first} of that name is declared above; \
                         every parameter, body, joint, driver, branch, load, marker and point needs its own name"
                    ),
                );
            } else {
                seen.insert(key, what);
            }
        }
        for (i, body) in spec.bodies.iter().enumerate() {
            self.bodies.entry(body.name.to_string()).or_insert(i);
        }
        for point in &spec.points {
            self.points
                .entry(point.name.to_string())
                .or_insert_with(|| point.point.body.to_string());
        }
        // A parameter whose default names another is derived; the others are run-time
        // parameters, indexed in declaration order.
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
        if !spec.bodies.iter().any(|b| !b.ground) {
            self.errors.push(
                spec.name.span(),
                "the mechanism has no moving body; declare one with `body NAME near (x, y, angle);`",
            );
        }
    }

    /// `outputs positions[, velocities[, accelerations[, forces]]];`: a prefix of the four
    /// levels, in order, since each needs the one before (velocities solve at the positions,
    /// …). Without the statement: everything the scene can compute (forces when it declares
    /// masses or loads).
    fn outputs(&mut self, spec: &Spec) -> Outputs {
        let Some(names) = &spec.outputs else {
            return if dynamics::declared(spec) {
                Outputs::Forces
            } else {
                Outputs::Accelerations
            };
        };
        for (k, name) in names.iter().enumerate() {
            let expected = Outputs::NAMES.get(k);
            if expected.is_some_and(|e| name == e) {
                continue;
            }
            let message = if !Outputs::NAMES.contains(&name.to_string().as_str()) {
                format!(
                    "unknown output `{name}`; the outputs are `positions`, `velocities`, \
                     `accelerations` and `forces`"
                )
            } else {
                "list outputs in order, each with the ones it needs: `outputs positions;`, \
                 `outputs positions, velocities;`, `outputs positions, velocities, \
                 accelerations;` or `outputs positions, velocities, accelerations, forces;`"
                    .to_owned()
            };
            self.errors.push(name.span(), message);
            return Outputs::Accelerations;
        }
        Outputs::ALL[names.len().clamp(1, Outputs::ALL.len()) - 1]
    }

    /// Names every moving body that no joint joins and no driver moves: it floats freely, and
    /// the degree-of-freedom count would blame the drivers for it. Returns whether there is one.
    fn check_floating(&mut self, spec: &Spec) -> bool {
        let joined = |body: &Ident| spec.joints.iter().any(|j| j.kind.bodies().contains(&body));
        let driven = |body: &Ident| spec.drivers.iter().any(|d| d.kind.bodies().contains(&body));
        let anchor = spec
            .bodies
            .iter()
            .find(|b| b.ground)
            .map_or_else(|| "OTHER".to_owned(), |b| b.name.to_string());
        let mut floating = false;
        for body in spec.bodies.iter().filter(|b| !b.ground) {
            if joined(&body.name) || driven(&body.name) {
                continue;
            }
            floating = true;
            self.errors.push(
                body.name.span(),
                format!(
                    "body `{0}` is not connected: no joint joins it and no driver moves it, so \
                     its three coordinates are free; connect it, e.g. `joint {0}_pin: \
                     revolute({0}, {anchor} @ (x, y));`, or remove it",
                    body.name
                ),
            );
        }
        floating
    }

    fn body(&mut self, name: &Ident) -> Option<usize> {
        let found = self.bodies.get(&name.to_string()).copied();
        if let (None, Some(body)) = (found, self.points.get(&name.to_string())) {
            self.errors.push(
                name.span(),
                format!("`{name}` is a named point (of `{body}`), not a body: name the body here"),
            );
        } else if found.is_none() {
            let known: Vec<String> = {
                let mut v: Vec<(&String, &usize)> = self.bodies.iter().collect();
                v.sort_by_key(|(_, i)| **i);
                v.into_iter().map(|(n, _)| format!("`{n}`")).collect()
            };
            let candidates = self.bodies.keys().map(String::as_str);
            let hint = match did_you_mean(&name.to_string(), candidates) {
                Some(close) => format!("did you mean `{close}`? "),
                None => String::new(),
            };
            self.errors.push(
                name.span(),
                format!(
                    "unknown body `{name}`; {hint}declared bodies are {}",
                    if known.is_empty() {
                        "none".to_owned()
                    } else {
                        known.join(", ")
                    }
                ),
            );
        }
        found
    }

    fn point(&mut self, p: &PointRef) -> Option<Point> {
        let body = self.body(&p.body)?;
        let local = match &p.local {
            Some(xy) => [self.length(&xy[0]), self.length(&xy[1])],
            None => [self.arena.zero(), self.arena.zero()],
        };
        Some(Point { body, local })
    }

    /// A branch invariant: known bodies, points without `t`, the literal 0 on the right, no
    /// vector from a point to itself, and at least one vector that can turn.
    fn branch(&mut self, decl: &BranchDecl) -> Option<Branch> {
        if !matches!(decl.zero.kind, ExprKind::Number(v) if v == 0.0) {
            self.errors.push(
                decl.zero.span,
                format!(
                    "compare the branch invariant with `0`: only its sign tells the branches \
                     apart; write `{}(…) > 0` or `{}(…) < 0`",
                    decl.product.name(),
                    decl.product.name()
                ),
            );
        }
        let [u0, u1, v0, v1] =
            [&decl.u[0], &decl.u[1], &decl.v[0], &decl.v[1]].map(|p| self.point(p));
        let (u, v) = ([u0?, u1?], [v0?, v1?]);
        let mut valid = true;
        for (points, refs) in [(u, &decl.u), (v, &decl.v)] {
            if self.same_point(points[0], points[1]) {
                self.errors.push(
                    refs[1].body.span(),
                    format!(
                        "this vector goes from a point of `{}` to the same point, so it has no \
                         direction; give two different points",
                        refs[0].body
                    ),
                );
                valid = false;
            }
        }
        let fixed = |points: [Point; 2]| points.iter().all(|p| self.ground[p.body]);
        if valid && fixed(u) && fixed(v) {
            self.errors.push(
                decl.product_span,
                "both vectors join points of ground bodies, so this invariant never changes; \
                 use points on moving bodies",
            );
            valid = false;
        }
        valid.then(|| Branch {
            name: decl.name.to_string(),
            docs: decl.docs.clone(),
            product: decl.product,
            u,
            v,
            sign: decl.sign,
        })
    }

    /// True if two points are structurally the same: one body, equal body-frame coordinates
    /// (the same node, or the same constant in an arena that does not fold).
    fn same_point(&self, a: Point, b: Point) -> bool {
        let constant = |id: Id| {
            let arena = &self.arena;
            arena.as_const(id).or_else(|| {
                (!arena.any_node(id, |n| matches!(n, Node::Var(_) | Node::Param(_))))
                    .then(|| crate::expr::tape::eval(arena, id, &crate::expr::tape::Env::default()))
            })
        };
        a.body == b.body
            && (0..2).all(|k| {
                a.local[k] == b.local[k]
                    || matches!((constant(a.local[k]), constant(b.local[k])), (Some(x), Some(y)) if x == y)
            })
    }

    /// Gruebler count: each moving body has 3 coordinates, each joint removes its equations
    /// (ground bodies bring 3 coordinates and 3 equations, which cancel); drivers must take up
    /// exactly the rest so that the system is square. A square system must then also be
    /// structurally non-singular ([`Structure`]): no group of constraints may over-determine
    /// some bodies while others keep free coordinates.
    fn check_mobility(
        &mut self,
        spec: &Spec,
        model: &Model,
        structure: &Structure,
        rows: &[Vec<usize>],
    ) {
        if self.check_floating(spec) {
            // A count would only blame the drivers for a body nothing holds.
            return;
        }
        let moving = spec.bodies.iter().filter(|b| !b.ground).count();
        let joint_equations: usize = spec.joints.iter().map(|j| j.kind.equations()).sum();
        let dof = 3 * moving as i64 - joint_equations as i64;
        let drivers = spec.drivers.len() as i64;
        let count = format!(
            "Gruebler count: 3 × {moving} moving bod{} − {joint_equations} joint equation{} = {}",
            if moving == 1 { "y" } else { "ies" },
            plural(joint_equations as i64),
            if dof < 0 {
                format!("−{}", -dof)
            } else {
                dof.to_string()
            },
        );
        // The joints (and drivers) whose equations the others already impose, last declared
        // first: the likeliest to have been added by mistake.
        // A pin repeating an earlier one comes first, alone (its equations are the other's).
        let over = structure.over_constraints(model);
        let mut removable = redundancy::removable(model, rows, structure.rank, &over);
        removable.reverse();
        if let Some(&(later, earlier)) = redundancy::repeated_pins(model, &over).last() {
            removable = vec![later, earlier];
        }
        let ground = model.bodies.iter().filter(|b| b.ground).count();
        let joints: Vec<&Ident> = removable
            .iter()
            .filter_map(|&k| spec.joints.get(k.checked_sub(ground)?).map(|j| &j.name))
            .collect();
        if dof < 0 {
            let part = if structure.over_equations.is_empty() {
                String::new()
            } else {
                format!(
                    "; {} over-determine {} ({})",
                    structure.statements(model),
                    structure.over_bodies(model),
                    structure.over_count(),
                )
            };
            // No joint whose equations are all redundant (without drivers, removing any
            // joint frees a coordinate): the error goes to the last joint of the part.
            let last = over
                .iter()
                .rev()
                .find_map(|&k| spec.joints.get(k.checked_sub(ground)?));
            let (span, fix) = match (joints.split_first(), last) {
                (Some((first, others)), _) => (
                    first.span(),
                    format!(
                        "{}: the other constraints already impose its equations",
                        remove_joint(first, others)
                    ),
                ),
                (None, Some(last)) => (last.name.span(), "remove joints or add bodies".to_owned()),
                (None, None) => (spec.name.span(), "remove joints or add bodies".to_owned()),
            };
            self.errors.push(
                span,
                format!("the joints over-constrain the mechanism ({count}){part}; {fix}"),
            );
        } else if dof == 0 && drivers > 0 && !joints.is_empty() {
            // Drivers on a mechanism its joints hold rigid: a joint closed a loop twice.
            self.joint_takes_drivers_freedom(spec, &joints, dof, &count);
        } else if drivers < dof {
            let missing = dof - drivers;
            let example = spec
                .bodies
                .iter()
                .find(|b| !b.ground)
                .map_or_else(|| "BODY".to_owned(), |b| b.name.to_string());
            let taken = |name: &str| {
                let params = spec.params.iter().map(|p| &p.name);
                let joints = spec.joints.iter().map(|j| &j.name);
                let drivers = spec.drivers.iter().map(|d| &d.name);
                self.bodies.contains_key(name)
                    || params.chain(joints).chain(drivers).any(|n| n == name)
            };
            let spin = (1..)
                .map(|k| {
                    if k == 1 {
                        "spin".to_owned()
                    } else {
                        format!("spin{k}")
                    }
                })
                .find(|name| !taken(name))
                .unwrap_or_default();
            self.errors.push(
                spec.name.span(),
                format!(
                    "`{}` has {dof} degree{} of freedom but {drivers} driver{} ({count}); add \
                     {missing} driver{}, e.g. `driver {spin}: angle({example}) = t;`",
                    spec.name,
                    plural(dof),
                    plural(drivers),
                    plural(missing),
                ),
            );
        } else if drivers > dof {
            let extra = drivers - dof;
            for driver in spec.drivers.iter().skip(dof as usize) {
                self.errors.push(
                    driver.name.span(),
                    format!(
                        "too many drivers: `{}` has {dof} degree{} of freedom but {drivers} \
                         driver{} ({count}); remove {extra} driver{}, such as `{}`",
                        spec.name,
                        plural(dof),
                        plural(drivers),
                        plural(extra),
                        driver.name,
                    ),
                );
            }
        } else if !structure.over_equations.is_empty() {
            let free: Vec<String> = structure
                .under_free
                .iter()
                .map(|&c| format!("`{}`", coordinate_name(model, c)))
                .collect();
            let under = structure.under_bodies(model);
            let message = format!(
                "structurally redundant constraints: {} over-determine {} ({}) while {} keep{} \
                 {} coordinate{} free ({}), so the Jacobian is singular in every position \
                 although the Gruebler count matches; remove one of these constraints and \
                 constrain {} instead",
                structure.statements(model),
                structure.over_bodies(model),
                structure.over_count(),
                under,
                if structure.under_body_count(model) == 1 {
                    "s"
                } else {
                    ""
                },
                free.len(),
                plural(free.len() as i64),
                free.join(", "),
                under,
            );
            let ground = model.bodies.iter().filter(|b| b.ground).count();
            for &k in &structure.over_constraints(model) {
                let span = match k.checked_sub(ground) {
                    Some(j) if j < spec.joints.len() => spec.joints[j].name.span(),
                    Some(j) => spec
                        .drivers
                        .get(j - spec.joints.len())
                        .map_or(spec.name.span(), |d| d.name.span()),
                    None => spec.name.span(),
                };
                self.errors.push(span, &message);
            }
        }
    }

    /// The run-time parameters with their defaults, and the derived ones lowered in declaration
    /// order (each may use run-time parameters and derived ones declared before it).
    fn parameters(&mut self, spec: &Spec) -> (Vec<Param>, Vec<Derived>) {
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

    /// Drivers on a mechanism its joints hold rigid, where some joint's equations are ones the
    /// other constraints already impose (a loop closed twice): the joint is named first, at its
    /// name, with the drivers as the other way out. (With freedom left, the drivers are what
    /// is too many.)
    fn joint_takes_drivers_freedom(
        &mut self,
        spec: &Spec,
        joints: &[&Ident],
        dof: i64,
        count: &str,
    ) {
        let drivers = spec.drivers.len() as i64;
        let extra = drivers - dof;
        let (first, others) = joints.split_first().expect("a removable joint");
        let driver = spec
            .drivers
            .get(dof as usize)
            .map_or_else(String::new, |d| {
                format!(
                    ", or remove {extra} driver{}, such as `{}`",
                    plural(extra),
                    d.name
                )
            });
        self.errors.push(
            first.span(),
            format!(
                "too many constraints: `{}` has {dof} degree{} of freedom but {drivers} \
                 driver{} ({count}), and joint `{first}` over-constrains it: the other joints \
                 and the drivers already impose its equations; {}{driver}",
                spec.name,
                plural(dof),
                plural(drivers),
                remove_joint(first, others),
            ),
        );
    }

    /// A parameter default: a constant expression.
    fn constant(&mut self, e: &Expr) -> f64 {
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

    /// Geometry: parameters allowed, time not.
    fn geometry(&mut self, e: &Expr) -> Id {
        self.lower_with(e, true, false)
    }

    /// A length of the scene's geometry: a constant one is recorded for the range and
    /// resolution rules ([`resolution`]).
    fn length(&mut self, e: &Expr) -> Id {
        let id = self.geometry(e);
        if let Some(value) = self.arena.as_const(id) {
            self.lengths.record(value, e.span);
        }
        id
    }

    /// An angle that only enters through its sine and cosine (a pose, a guess): a constant one
    /// beyond a half turn is reduced to (−π, π].
    fn angle(&mut self, e: &Expr) -> Id {
        let id = self.geometry(e);
        match self.arena.as_const(id) {
            Some(value) => self.arena.constant(resolution::reduce_angle(value)),
            None => id,
        }
    }

    /// Reports a constant expression that folded to NaN or infinity (the arena keeps such a
    /// node unfolded): `result` computed from constant `operands` must be a constant.
    fn check_folded(&mut self, span: Span, result: Id, operands: &[Id], hint: &str) {
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
    fn lower(&mut self, e: &Expr, allow_t: bool) -> Id {
        self.lower_with(e, true, allow_t)
    }

    fn lower_with(&mut self, e: &Expr, allow_params: bool, allow_t: bool) -> Id {
        match &e.kind {
            ExprKind::Number(v) => self.arena.constant(*v),
            ExprKind::Name(name) => {
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
                        let close =
                            did_you_mean(&key, names.iter().map(|(n, _)| n.as_str()).chain(["t"]));
                        let hint = if let Some(close) = close {
                            format!("did you mean `{close}`?")
                        } else if names.is_empty() {
                            "declare it with `param NAME = VALUE;`".to_owned()
                        } else {
                            let list: Vec<String> =
                                names.iter().map(|(n, _)| format!("`{n}`")).collect();
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
}

impl Checker {
    /// A use of derived parameter `name`: its value, or an error where that cannot be (in a
    /// parameter's constant default, or before the derived parameter is computed).
    fn derived_value(&mut self, name: &Ident, value: Option<Id>, allow_params: bool) -> Id {
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
fn names_any(e: &Expr, names: &HashSet<String>) -> bool {
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

/// The structure of the Jacobian's sparsity pattern: which coordinates each equation touches
/// (ground bodies enter joints as constant poses, so only their own equations touch them), a
/// maximum matching of equations to coordinates, and from it the coarse Dulmage–Mendelsohn
/// decomposition.
///
/// A perfect matching means the Jacobian can be non-singular; otherwise it is singular at every
/// position, whatever the dimensions. Equations reachable from an unmatched equation by
/// alternating paths (equation → a coordinate it touches → the equation matched to that
/// coordinate → …) form the *over-determined* part: more equations than the coordinates they
/// touch. Coordinates reachable the same way from an unmatched coordinate form the
/// *under-determined* part.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Structure {
    /// Size of the maximum matching: the structural rank of Φ_q.
    pub rank: usize,
    /// Equations of the over-determined part, ascending.
    pub over_equations: Vec<usize>,
    /// Coordinates of the over-determined part, ascending.
    pub over_coordinates: Vec<usize>,
    /// Coordinates of the under-determined part, ascending.
    pub under_coordinates: Vec<usize>,
    /// The unmatched coordinates (free whatever the constraints do), ascending.
    pub under_free: Vec<usize>,
}

impl Structure {
    /// The structure of a model's Φ: the equations are built into the model's arena (the same
    /// hash-consed nodes `kinematics` derives from later) and each one's coordinates read off.
    pub fn of_model(model: &mut Model) -> Self {
        let rows = Self::rows_of(model);
        Self::of_pattern(&rows, model.dim())
    }

    /// The coordinates each of a model's equations touches, in Φ order.
    pub fn rows_of(model: &mut Model) -> Vec<Vec<usize>> {
        let phi = crate::model::kinematics::constraint_equations(model);
        phi.iter()
            .map(|&e| {
                model
                    .arena
                    .variables(e)
                    .into_iter()
                    .filter_map(|v| match v {
                        Var::Q(k) => Some(k as usize),
                        _ => None,
                    })
                    .collect()
            })
            .collect()
    }

    /// The structure of a pattern: `rows[i]` lists the coordinates (`< columns`) equation `i`
    /// touches.
    ///
    /// Augmenting paths from a greedy start, each search a depth-first walk with a look-ahead
    /// for a free coordinate and visit stamps: O(equations × non-zeros) at worst, near linear on
    /// the chains and trees of real mechanisms.
    pub fn of_pattern(rows: &[Vec<usize>], columns: usize) -> Self {
        let matching = graph::maximum_matching(rows, columns);
        let (row_match, col_match) = (&matching.row, &matching.column);
        let mut structure = Structure {
            rank: matching.size(),
            ..Structure::default()
        };
        // Over-determined: alternating walks from unmatched equations.
        let mut seen_row = vec![false; rows.len()];
        let mut seen_col = vec![false; columns];
        let mut queue: Vec<usize> = (0..rows.len())
            .filter(|&r| row_match[r] == UNMATCHED)
            .collect();
        for &r in &queue {
            seen_row[r] = true;
        }
        while let Some(r) = queue.pop() {
            for &c in &rows[r] {
                if !std::mem::replace(&mut seen_col[c], true) {
                    let next = col_match[c];
                    if next != UNMATCHED && !std::mem::replace(&mut seen_row[next], true) {
                        queue.push(next);
                    }
                }
            }
        }
        structure.over_equations = (0..rows.len()).filter(|&r| seen_row[r]).collect();
        structure.over_coordinates = (0..columns).filter(|&c| seen_col[c]).collect();
        // Under-determined: alternating walks from unmatched coordinates.
        let mut touching: Vec<Vec<usize>> = vec![Vec::new(); columns];
        for (r, cols) in rows.iter().enumerate() {
            for &c in cols {
                touching[c].push(r);
            }
        }
        let mut seen_row = vec![false; rows.len()];
        let mut seen_col = vec![false; columns];
        structure.under_free = (0..columns)
            .filter(|&c| col_match[c] == UNMATCHED)
            .collect();
        let mut queue = structure.under_free.clone();
        for &c in &queue {
            seen_col[c] = true;
        }
        while let Some(c) = queue.pop() {
            for &r in &touching[c] {
                if !std::mem::replace(&mut seen_row[r], true) {
                    let next = row_match[r];
                    if next != UNMATCHED && !std::mem::replace(&mut seen_col[next], true) {
                        queue.push(next);
                    }
                }
            }
        }
        structure.under_coordinates = (0..columns).filter(|&c| seen_col[c]).collect();
        structure
    }

    /// The constraints (indices into `model.constraints`) owning the over-determined equations.
    fn over_constraints(&self, model: &Model) -> Vec<usize> {
        let mut owner = Vec::with_capacity(model.dim());
        for (k, c) in model.constraints.iter().enumerate() {
            owner.extend(std::iter::repeat_n(k, c.kind.equation_suffixes().len()));
        }
        let mut constraints: Vec<usize> = self
            .over_equations
            .iter()
            .filter_map(|&e| owner.get(e).copied())
            .collect();
        constraints.dedup();
        constraints
    }

    /// "joints `a`, `b` and driver `d`": the over-determined part's statements.
    fn statements(&self, model: &Model) -> String {
        let mut groups: [(&str, Vec<String>); 3] = [
            ("ground bod", Vec::new()),
            ("joint", Vec::new()),
            ("driver", Vec::new()),
        ];
        for k in self.over_constraints(model) {
            let c = &model.constraints[k];
            let group = match c.kind {
                ConstraintKind::Ground { .. } => 0,
                ConstraintKind::Driver { .. } => 2,
                _ => 1,
            };
            groups[group].1.push(format!("`{}`", c.name));
        }
        let parts: Vec<String> = groups
            .iter()
            .filter(|(_, names)| !names.is_empty())
            .map(|(what, names)| {
                let what = match (*what, names.len()) {
                    ("ground bod", 1) => "ground body".to_owned(),
                    ("ground bod", _) => "ground bodies".to_owned(),
                    (what, 1) => what.to_owned(),
                    (what, _) => format!("{what}s"),
                };
                format!("{what} {}", names.join(", "))
            })
            .collect();
        match parts.as_slice() {
            [] => "no constraint".to_owned(),
            [one] => one.clone(),
            [init @ .., last] => format!("{} and {last}", init.join(", ")),
        }
    }

    /// "(7 equations for 6 coordinates)"
    fn over_count(&self) -> String {
        format!(
            "{} equation{} for {} coordinate{}",
            self.over_equations.len(),
            plural(self.over_equations.len() as i64),
            self.over_coordinates.len(),
            plural(self.over_coordinates.len() as i64),
        )
    }

    fn over_bodies(&self, model: &Model) -> String {
        bodies_of(model, &self.over_coordinates)
    }

    fn under_bodies(&self, model: &Model) -> String {
        bodies_of(model, &self.under_coordinates)
    }

    fn under_body_count(&self, model: &Model) -> usize {
        let mut bodies: Vec<usize> = self.under_coordinates.iter().map(|c| c / 3).collect();
        bodies.dedup();
        bodies.len().min(model.bodies.len())
    }
}

/// "body `a`" or "bodies `a`, `b`": the bodies owning `coordinates` (ascending).
fn bodies_of(model: &Model, coordinates: &[usize]) -> String {
    let mut names: Vec<String> = Vec::new();
    let mut last = None;
    for &c in coordinates {
        if last != Some(c / 3) {
            last = Some(c / 3);
            if let Some(body) = model.bodies.get(c / 3) {
                names.push(format!("`{}`", body.name));
            }
        }
    }
    match names.len() {
        0 => "no body".to_owned(),
        1 => format!("body {}", names[0]),
        _ => format!("bodies {}", names.join(", ")),
    }
}

fn coordinate_name(model: &Model, coordinate: usize) -> String {
    model
        .coordinate_names()
        .get(coordinate)
        .cloned()
        .unwrap_or_default()
}

/// "remove joint `a` (or `b`, `c`)".
fn remove_joint(first: &Ident, others: &[&Ident]) -> String {
    let or = if others.is_empty() {
        String::new()
    } else {
        let names: Vec<String> = others.iter().map(|j| format!("`{j}`")).collect();
        format!(" (or {})", names.join(", "))
    };
    format!("remove joint `{first}`{or}")
}

fn plural(n: i64) -> &'static str {
    if n == 1 { "" } else { "s" }
}

/// The candidate closest to a misspelt `name`, if it is plausibly a typo (edit distance ≤ 2 and
/// less than half the name). Public for the command line's suggestions.
pub fn did_you_mean<'a>(name: &str, candidates: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    candidates
        .map(|c| (edit_distance(name, c), c))
        .filter(|&(d, _)| d <= 2 && 2 * d < name.chars().count().max(2))
        .min()
        .map(|(_, c)| c)
}

/// Levenshtein distance (names are short; the quadratic table is fine).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let substitution = diagonal + usize::from(ca != cb);
            diagonal = row[j + 1];
            row[j + 1] = substitution.min(row[j] + 1).min(row[j + 1] + 1);
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
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
