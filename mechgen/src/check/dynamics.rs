//! Checking the dynamics part of a spec: mass properties, gravity and loads, lowered into the
//! model, each problem reported at its tokens with a fix (the rules are in `docs/grammar.md`).
//!
//! Masses, inertias, centres, gravity and spring constants are geometry-like: constants or
//! parameters, never `t`. Force and torque values may also depend on `t`.

use proc_macro2::Span;
use syn::Ident;

use super::Checker;
use crate::expr::Id;
use crate::model::{Load, LoadKind, MassProperties, Outputs, Point};
use crate::syntax::spec::{BodyDecl, Expr, LoadDecl, PointRef, Spec};

/// Names of the accessors generated for a scene that computes forces (`state.reactions()`,
/// `state.efforts()`), which a body's accessor of the same name would make ambiguous.
const FORCE_ACCESSORS: [&str; 2] = ["reactions", "efforts"];

/// Whether the spec declares anything that produces a force: a moving body's mass properties
/// or a load (gravity alone acts on nothing).
pub(super) fn declared(spec: &Spec) -> bool {
    spec.bodies.iter().any(|b| b.mass.is_some() && !b.ground) || !spec.loads.is_empty()
}

impl Checker {
    /// A body's mass properties: mass and inertia at least zero, the centre a body-fixed point
    /// (the reference point by default); a ground body carries none.
    pub(super) fn mass(&mut self, body: &BodyDecl) -> Option<MassProperties> {
        let decl = body.mass.as_ref()?;
        if body.ground {
            self.errors.push(
                decl.span,
                format!(
                    "ground body `{}` never moves, so its mass does not enter the forces; give \
                     mass properties to moving bodies (`body NAME near (x, y, angle) mass M \
                     inertia I;`) or remove this clause",
                    body.name
                ),
            );
            return None;
        }
        if decl.mass.is_none()
            && let Some((_, span)) = &decl.centre
        {
            self.errors.push(
                *span,
                "a centre of mass without a mass has no effect; add `mass M` to this body",
            );
        }
        let mass = self.non_negative(decl.mass.as_ref(), "a mass");
        let inertia = self.non_negative(decl.inertia.as_ref(), "a moment of inertia");
        let centre = match &decl.centre {
            Some((xy, _)) => [self.geometry(&xy[0]), self.geometry(&xy[1])],
            None => [self.arena.zero(), self.arena.zero()],
        };
        Some(MassProperties {
            mass,
            inertia,
            centre,
        })
    }

    /// `gravity (gx, gy);`, zero when not declared.
    pub(super) fn gravity(&mut self, spec: &Spec) -> [Id; 2] {
        match &spec.gravity {
            Some(g) => [self.geometry(&g.value[0]), self.geometry(&g.value[1])],
            None => [self.arena.zero(), self.arena.zero()],
        }
    }

    /// A load: forces and torques on moving bodies, springs between two bodies not both fixed.
    pub(super) fn load(&mut self, decl: &LoadDecl) -> Option<Load> {
        let kind = match &decl.kind {
            crate::syntax::spec::LoadKind::Force {
                point,
                value,
                local,
            } => {
                let value = [self.lower(&value[0], true), self.lower(&value[1], true)];
                let point = self.loaded_point(point)?;
                LoadKind::Force {
                    point,
                    value,
                    local: *local,
                }
            }
            crate::syntax::spec::LoadKind::Torque { body, value } => {
                let value = self.lower(value, true);
                let body = self.loaded_body(body)?;
                LoadKind::Torque { body, value }
            }
            crate::syntax::spec::LoadKind::Spring {
                a,
                b,
                stiffness,
                length,
                damping,
            } => self.spring(decl.kind_span, a, b, [stiffness, length, damping])?,
        };
        Some(Load {
            name: decl.name.to_string(),
            kind,
        })
    }

    /// A spring-damper: two points on different bodies, not both fixed; a stiffness with its
    /// free length, or a damping, or both, none of them negative.
    fn spring(
        &mut self,
        span: Span,
        a: &PointRef,
        b: &PointRef,
        [stiffness, length, damping]: [&Option<Expr>; 3],
    ) -> Option<LoadKind> {
        let constants = [
            self.non_negative(stiffness.as_ref(), "a stiffness"),
            self.non_negative(length.as_ref(), "a free length"),
            self.non_negative(damping.as_ref(), "a damping coefficient"),
        ];
        let (pa, pb) = (self.point(a), self.point(b));
        let (pa, pb) = (pa?, pb?);
        let terms = self.spring_terms(span, stiffness, length, damping);
        let ends = self.spring_ends(a, b, pa, pb);
        let valid = terms && ends;
        let [stiffness, length, damping] = constants;
        valid.then_some(LoadKind::Spring {
            a: pa,
            b: pb,
            stiffness,
            length,
            damping,
        })
    }

    /// A stiffness with its free length, or a damping, or both; reports what is missing.
    fn spring_terms(
        &mut self,
        span: Span,
        stiffness: &Option<Expr>,
        length: &Option<Expr>,
        damping: &Option<Expr>,
    ) -> bool {
        let mut valid = true;
        if stiffness.is_none() && damping.is_none() {
            self.errors.push(
                span,
                "this spring exerts no force: give it a `stiffness k` (with its free \
                 `length L`), a `damping c`, or both",
            );
            valid = false;
        }
        match (stiffness, length) {
            (Some(k), None) => {
                self.errors.push(
                    k.span,
                    "a spring with a stiffness needs its free length: add `length L`",
                );
                valid = false;
            }
            (None, Some(l)) => {
                self.errors.push(
                    l.span,
                    "`length` is the free length of a spring with a `stiffness`; add \
                     `stiffness k` or remove it",
                );
                valid = false;
            }
            _ => {}
        }
        valid
    }

    /// Two ends on different bodies, not both fixed; reports which rule they break.
    fn spring_ends(&mut self, a: &PointRef, b: &PointRef, pa: Point, pb: Point) -> bool {
        let mut valid = true;
        if pa.body == pb.body {
            self.errors.push(
                b.body.span(),
                format!(
                    "this spring joins `{}` to itself and exerts no force on it; join two \
                     different bodies",
                    a.body
                ),
            );
            valid = false;
        } else if self.ground[pa.body] && self.ground[pb.body] {
            self.errors.push(
                b.body.span(),
                format!(
                    "this spring joins two ground bodies (`{}` and `{}`), which never move; \
                     attach at least one end to a moving body",
                    a.body, b.body
                ),
            );
            valid = false;
        }
        valid
    }

    /// The point a force acts at, on a moving body.
    fn loaded_point(&mut self, point: &PointRef) -> Option<Point> {
        self.loaded_body(&point.body)?;
        self.point(point)
    }

    /// The body a load acts on, a moving one.
    fn loaded_body(&mut self, name: &Ident) -> Option<usize> {
        let body = self.body(name)?;
        if self.ground[body] {
            self.errors.push(
                name.span(),
                format!(
                    "a load on ground body `{name}` does nothing: it never moves; apply the \
                     load to a moving body (declared with `body`)"
                ),
            );
            return None;
        }
        Some(body)
    }

    /// An optional geometry-like value (parameters allowed, not `t`), zero when absent; a
    /// negative constant is an error naming `what` it is.
    fn non_negative(&mut self, e: Option<&Expr>, what: &str) -> Id {
        let Some(e) = e else {
            return self.arena.zero();
        };
        let id = self.geometry(e);
        if let Some(value) = self.arena.as_const(id)
            && value < 0.0
        {
            self.errors.push(
                e.span,
                format!("{what} cannot be negative; write {}", -value),
            );
        }
        id
    }

    /// The rules of the `forces` output: something must produce a force, and no body may take
    /// the name of a force accessor.
    pub(super) fn check_forces(&mut self, spec: &Spec, outputs: Outputs) {
        if outputs < Outputs::Forces {
            return;
        }
        if !declared(spec)
            && let Some(forces) = spec.outputs.iter().flatten().find(|n| *n == "forces")
        {
            self.errors.push(
                forces.span(),
                "nothing in this scene produces a force, so every reaction would be zero: give \
                 moving bodies their mass (`body NAME near (x, y, angle) mass M inertia I;`, with \
                 `gravity (gx, gy);` if it acts) or declare a load (`load NAME: \
                 force(body @ (x, y)) = (fx, fy);`)",
            );
        }
        // Bodies and markers both get accessors on the state.
        let names = (spec.bodies.iter().map(|b| (&b.name, "body")))
            .chain(spec.markers.iter().map(|m| (&m.name, "marker")));
        for (name, what) in names {
            if FORCE_ACCESSORS.iter().any(|a| name == a) {
                self.errors.push(
                    name.span(),
                    format!(
                        "a scene that computes forces generates `state.{name}()`, which a \
                         {what} named `{name}` would make ambiguous; rename the {what}"
                    ),
                );
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::model::{LoadKind, Outputs};
    use crate::syntax::source::parse_str;

    const ARM: &str = "
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass 2 inertia 0.5 centre (0.5, 0);
        joint pivot: revolute(frame, arm);
        driver spin: angle(arm) = t;
    ";

    fn errors(extra: &str) -> String {
        let source = format!("mechanism M {{ {ARM} {extra} }}");
        let spec = parse_str(&source).unwrap_or_else(|e| panic!("syntax: {e}"));
        match super::super::check(&spec) {
            Ok(_) => String::new(),
            Err(e) => e.messages().join("\n"),
        }
    }

    fn model(extra: &str) -> crate::Model {
        let source = format!("mechanism M {{ {ARM} {extra} }}");
        let spec = parse_str(&source).unwrap_or_else(|e| panic!("syntax: {e}"));
        super::super::check(&spec).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn masses_loads_and_gravity_lower_into_the_model() {
        let m = model(
            "param k = 3;
             gravity (0, -9.81);
             load push: local_force(arm @ (1, 0)) = (t, 2 * t);
             load twist: torque(arm) = k;
             load coil: spring(frame @ (0, 1), arm, stiffness k, length 1, damping 0.1);",
        );
        let mass = m.bodies[1].mass.expect("arm has a mass");
        assert_eq!(m.arena.as_const(mass.mass), Some(2.0));
        assert_eq!(m.arena.as_const(mass.centre[0]), Some(0.5));
        assert_eq!(m.arena.as_const(m.gravity[1]), Some(-9.81));
        assert_eq!(m.loads.len(), 3);
        assert!(matches!(
            m.loads[0].kind,
            LoadKind::Force { local: true, .. }
        ));
        assert!(matches!(m.loads[2].kind, LoadKind::Spring { .. }));
        // Declared masses make forces the default output.
        assert_eq!(m.outputs, Outputs::Forces);
        let plain = model("outputs positions, velocities, accelerations;");
        assert_eq!(plain.outputs, Outputs::Accelerations);
    }

    #[test]
    fn every_rule_is_reported_at_its_tokens() {
        let all = errors(
            "body reactions near (2, 0, 0) inertia 1 centre (0, 1);
             joint hinge: revolute(arm @ (1, 0), reactions);
             driver wave: angle(reactions) = t;
             load a: torque(frame) = 1;
             load b: spring(arm, arm @ (1, 0), stiffness 2, length 1);
             load c: spring(arm, frame, length 3);
             load d: spring(arm, frame, stiffness 3);
             load e: spring(arm, frame, damping -1);
             load f: force(frame @ (1, 1)) = (t, 0);
             load g: torque(arm) = 1;
             load g: torque(arm) = 2;",
        );
        for expected in [
            "a centre of mass without a mass has no effect",
            "a load on ground body `frame` does nothing",
            "this spring joins `arm` to itself",
            "this spring exerts no force",
            "`length` is the free length of a spring with a `stiffness`",
            "a spring with a stiffness needs its free length",
            "a damping coefficient cannot be negative; write 1",
            "a body named `reactions` would make ambiguous",
            "duplicate name `g`: a load of that name",
        ] {
            assert!(all.contains(expected), "missing `{expected}` in:\n{all}");
        }
        let ground = errors("").is_empty();
        assert!(ground, "the plain arm checks");
        let spec = parse_str(
            "mechanism G { ground frame at (0, 0, 0) mass 3; body b near (0, 0, 0) mass -1;
               joint p: revolute(frame, b); driver d: angle(b) = t; }",
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let messages = super::super::check(&spec)
            .err()
            .map(|e| e.messages().join("\n"))
            .unwrap_or_default();
        assert!(
            messages.contains("ground body `frame` never moves"),
            "{messages}"
        );
        assert!(
            messages.contains("a mass cannot be negative; write 1"),
            "{messages}"
        );
    }

    #[test]
    fn the_forces_output_needs_something_that_produces_a_force() {
        let source = "mechanism N { ground f at (0, 0, 0); body b near (0, 0, 0);
            joint p: revolute(f, b); driver d: angle(b) = t; gravity (0, -9.8);
            outputs positions, velocities, accelerations, forces; }";
        let spec = parse_str(source).unwrap_or_else(|e| panic!("{e}"));
        let messages = super::super::check(&spec)
            .err()
            .map(|e| e.messages().join("\n"))
            .unwrap_or_default();
        assert!(
            messages.contains("nothing in this scene produces a force"),
            "{messages}"
        );
        assert!(
            errors("outputs positions, forces;").contains("list outputs in order"),
            "a level cannot be skipped"
        );
    }
}
