//! Checking the joint and driver library: each joint or driver of the spec resolved to its
//! bodies and points, its geometry lowered (parameters allowed, not `t`), and every misuse
//! reported at its tokens with a fix (the rules are in `docs/grammar.md`).

use proc_macro2::Span;
use syn::Ident;

use super::Checker;
use crate::expr::{Func, Id};
use crate::model::{ConstraintKind, Driven, Marker, MarkerKind, Point};
use crate::syntax::spec::{DriverKind, Expr, JointKind, MarkerDecl, PointRef};

impl Checker {
    /// A joint of the spec as a constraint of the model.
    pub(super) fn joint(&mut self, name: &Ident, kind: &JointKind) -> Option<ConstraintKind> {
        match kind {
            JointKind::Revolute { a, b } => {
                let (a, b) = self.two_points(a, b, "joint")?;
                Some(ConstraintKind::Revolute { a, b })
            }
            JointKind::Prismatic {
                a,
                b,
                axis,
                axis_span,
            } => {
                let (a, b, axis) = self.points_along(a, b, axis, *axis_span, "joint")?;
                self.prismatic.insert(name.to_string(), (a, b, axis));
                Some(ConstraintKind::Prismatic { a, b, axis })
            }
            JointKind::Slot {
                a,
                b,
                axis,
                axis_span,
            } => {
                let (a, b, axis) = self.points_along(a, b, axis, *axis_span, "joint")?;
                Some(ConstraintKind::Slot { a, b, axis })
            }
            JointKind::Distance { a, b, length } => {
                let points = self.two_points(a, b, "joint");
                let value = self.length(length);
                self.positive_distance(length, value)?;
                let (a, b) = points?;
                Some(ConstraintKind::Distance {
                    a,
                    b,
                    length: value,
                })
            }
            JointKind::Weld { a, b, angle } => {
                let points = self.two_points(a, b, "joint");
                let angle = match angle {
                    Some(angle) => self.angle(angle),
                    None => self.arena.zero(),
                };
                let (a, b) = points?;
                Some(ConstraintKind::Weld { a, b, angle })
            }
            JointKind::Gear {
                a,
                b,
                ratio,
                carrier,
                phase,
            } => self.gear(a, b, ratio, carrier.as_ref(), phase.as_ref()),
            JointKind::Rack {
                joint,
                pinion,
                ratio,
                phase,
            } => self.rack(joint, pinion, ratio, phase.as_ref()),
        }
    }

    /// `rack(joint, pinion, ratio k, phase φ)`: the slider of a `prismatic` joint driven by a
    /// pinion that is not the rack itself, and a ratio that is not zero.
    fn rack(
        &mut self,
        joint: &Ident,
        pinion: &Ident,
        ratio: &Expr,
        phase: Option<&Expr>,
    ) -> Option<ConstraintKind> {
        let ratio_id = self.nonzero_ratio(ratio);
        let phase = self.optional_geometry(phase);
        let guide = self.prismatic_joint(joint, "`rack` couples the slider of a `prismatic` joint");
        let pinion_body = self.body(pinion);
        let (a, b, axis) = guide?;
        let pinion_body = pinion_body?;
        if pinion_body == b.body {
            self.errors.push(
                pinion.span(),
                format!(
                    "`{pinion}` is the rack itself (the slider of `{joint}`); name the \
                     pinion that drives it"
                ),
            );
            return None;
        }
        Some(ConstraintKind::Rack {
            a,
            b,
            axis,
            pinion: pinion_body,
            ratio: ratio_id?,
            phase,
        })
    }

    /// `gear(a, b, ratio k, carrier c, phase φ)`: three different bodies, not all of them
    /// fixed, and a ratio that is not zero.
    fn gear(
        &mut self,
        a: &Ident,
        b: &Ident,
        ratio: &Expr,
        carrier: Option<&Ident>,
        phase: Option<&Expr>,
    ) -> Option<ConstraintKind> {
        let ratio = self.nonzero_ratio(ratio);
        let phase = self.optional_geometry(phase);
        let (ia, ib) = (self.body(a), self.body(b));
        let ic = carrier.map(|c| self.body(c));
        let (ia, ib) = (ia?, ib?);
        let ic = match ic {
            Some(c) => Some(c?),
            None => None,
        };
        let names = [Some(a), Some(b), carrier];
        let indices = [Some(ia), Some(ib), ic];
        for (k, index) in indices.iter().enumerate().skip(1) {
            if index.is_some() && indices[..k].contains(index) {
                let name = names[k].map_or_else(String::new, ToString::to_string);
                self.errors.push(
                    names[k].map_or_else(Span::call_site, Ident::span),
                    format!(
                        "`{name}` is named twice in this gear pair; a gear pair couples two \
                         different gears on a third body, the carrier"
                    ),
                );
                return None;
            }
        }
        if self.ground[ia] && self.ground[ib] {
            self.errors.push(
                b.span(),
                format!(
                    "both gears (`{a}` and `{b}`) are ground bodies, which never turn; gear at \
                     least one moving body"
                ),
            );
            return None;
        }
        Some(ConstraintKind::Gear {
            a: ia,
            b: ib,
            carrier: ic,
            ratio: ratio?,
            phase,
        })
    }

    /// A driver's driven quantity.
    pub(super) fn driven(&mut self, span: Span, kind: &DriverKind) -> Option<Driven> {
        match kind {
            DriverKind::Angle(body) => Some(Driven::Angle(self.moving(body, "the angle")?)),
            DriverKind::RelativeAngle(a, b) => {
                let (ia, ib) = (self.body(a), self.body(b));
                let (ia, ib) = (ia?, ib?);
                if ia == ib {
                    self.errors.push(
                        b.span(),
                        format!("relative angle of `{a}` to itself; name two different bodies"),
                    );
                    return None;
                }
                if self.ground[ia] && self.ground[ib] {
                    self.errors.push(
                        span,
                        "both bodies are ground bodies and never move; drive a moving body",
                    );
                    return None;
                }
                Some(Driven::RelativeAngle(ia, ib))
            }
            DriverKind::X(p) | DriverKind::Y(p) => {
                self.moving(&p.body, "a point")?;
                let point = self.point(p)?;
                Some(if matches!(kind, DriverKind::X(_)) {
                    Driven::X(point)
                } else {
                    Driven::Y(point)
                })
            }
            DriverKind::Travel(joint) => {
                let (a, b, axis) = self
                    .prismatic_joint(joint, "`travel` drives the slider of a `prismatic` joint")?;
                Some(Driven::Travel { a, b, axis })
            }
            DriverKind::Slide {
                a,
                b,
                axis,
                axis_span,
            } => {
                let (a, b, axis) = self.points_along(a, b, axis, *axis_span, "driver")?;
                Some(Driven::Travel { a, b, axis })
            }
            DriverKind::Distance(a, b) => {
                let (a, b) = self.two_points(a, b, "driver")?;
                Some(Driven::Distance(a, b))
            }
        }
    }

    /// A marker: a point on a known body, or the angle between two different bodies.
    pub(super) fn marker(&mut self, decl: &MarkerDecl) -> Option<Marker> {
        let kind = match &decl.kind {
            crate::syntax::spec::MarkerKind::Point(p) => MarkerKind::Point(self.point(p)?),
            crate::syntax::spec::MarkerKind::Angle(a, b) => {
                let (ia, ib) = (self.body(a), self.body(b));
                let (ia, ib) = (ia?, ib?);
                if ia == ib {
                    self.errors.push(
                        b.span(),
                        format!(
                            "the angle of `{a}` to itself is always zero; name two different bodies"
                        ),
                    );
                    return None;
                }
                MarkerKind::Angle(ia, ib)
            }
        };
        Some(Marker {
            name: decl.name.to_string(),
            docs: decl.docs.clone(),
            kind,
        })
    }

    fn moving(&mut self, name: &Ident, what: &str) -> Option<usize> {
        let body = self.body(name)?;
        if self.ground[body] {
            self.errors.push(
                name.span(),
                format!(
                    "cannot drive {what} of `{name}`: it is a ground body and never moves; \
                     drive a moving body (declared with `body`)"
                ),
            );
            return None;
        }
        Some(body)
    }

    /// A prismatic joint declared before, by name: its points and unit axis.
    fn prismatic_joint(&mut self, joint: &Ident, purpose: &str) -> Option<(Point, Point, [Id; 2])> {
        let found = self.prismatic.get(&joint.to_string()).copied();
        if found.is_none() {
            self.errors.push(
                joint.span(),
                format!("`{joint}` is not a prismatic joint declared before this; {purpose}"),
            );
        }
        found
    }

    /// [`Self::two_points`] and a unit axis along which they move (`prismatic`, `slot`,
    /// `slide`): every error of both reported.
    fn points_along(
        &mut self,
        a: &PointRef,
        b: &PointRef,
        axis: &[Expr; 2],
        axis_span: Span,
        what: &str,
    ) -> Option<(Point, Point, [Id; 2])> {
        let points = self.two_points(a, b, what);
        let axis = self.unit_axis(axis, axis_span)?;
        let (a, b) = points?;
        Some((a, b, axis))
    }

    /// Two points on different bodies, not both fixed; `what` (`joint`, `driver`) names the
    /// statement in the errors.
    pub(super) fn two_points(
        &mut self,
        a: &PointRef,
        b: &PointRef,
        what: &str,
    ) -> Option<(Point, Point)> {
        let (pa, pb) = (self.point(a), self.point(b));
        let (pa, pb) = (pa?, pb?);
        if pa.body == pb.body {
            self.errors.push(
                b.body.span(),
                format!(
                    "this {what} connects `{}` to itself; join two different bodies",
                    a.body
                ),
            );
            return None;
        }
        if self.ground[pa.body] && self.ground[pb.body] {
            self.errors.push(
                b.body.span(),
                format!(
                    "this {what} connects two ground bodies (`{}` and `{}`), which cannot move; \
                     connect at least one moving body",
                    a.body, b.body
                ),
            );
            return None;
        }
        Some((pa, pb))
    }

    /// `along (ux, uy)` as a unit vector; the zero vector is an error. The length is never
    /// formed as `ux² + uy²`, whose square underflows to zero for `(0, 1e-170)` (which is a
    /// direction) and overflows for `(0, 1e160)`: constants are divided by their `hypot`, and a
    /// direction in parameters is first scaled by its larger magnitude.
    fn unit_axis(&mut self, axis: &[Expr; 2], span: Span) -> Option<[Id; 2]> {
        let ux = self.geometry(&axis[0]);
        let uy = self.geometry(&axis[1]);
        let zero_vector = |cx: &mut Self| {
            cx.errors.push(
                span,
                "the axis is the zero vector; give a direction such as `along (1, 0)`",
            );
            None
        };
        if !self.arena.simplifies() {
            // The naive baseline (`CodegenOptions::naive`) keeps the textbook formula.
            let (ux2, uy2) = (self.arena.powi(ux, 2), self.arena.powi(uy, 2));
            let norm2 = self.arena.add(ux2, uy2);
            let norm = self.arena.call(Func::Sqrt, norm2);
            return Some([self.arena.div(ux, norm), self.arena.div(uy, norm)]);
        }
        if let (Some(x), Some(y)) = (self.arena.as_const(ux), self.arena.as_const(uy)) {
            let length = x.hypot(y);
            if length == 0.0 {
                return zero_vector(self);
            }
            // A non-finite component folds to NaN here and is reported with the geometry.
            let unit = [x / length, y / length].map(|v| self.arena.constant(v));
            return Some(unit);
        }
        let abs = |arena: &mut crate::expr::Arena, v: Id| {
            let (zero, negative) = (arena.zero(), arena.neg(v));
            arena.select(zero, v, v, negative)
        };
        let (ax, ay) = (abs(&mut self.arena, ux), abs(&mut self.arena, uy));
        let scale = self.arena.select(ay, ax, ax, ay);
        if self.arena.as_const(scale) == Some(0.0) {
            return zero_vector(self);
        }
        let (sx, sy) = (self.arena.div(ux, scale), self.arena.div(uy, scale));
        let (sx2, sy2) = (self.arena.powi(sx, 2), self.arena.powi(sy, 2));
        let norm2 = self.arena.add(sx2, sy2);
        let norm = self.arena.call(Func::Sqrt, norm2);
        Some([self.arena.div(sx, norm), self.arena.div(sy, norm)])
    }

    /// A distance joint's length: neither zero nor negative when constant.
    fn positive_distance(&mut self, length: &Expr, value: Id) -> Option<()> {
        match self.arena.as_const(value) {
            Some(0.0) => {
                self.errors.push(
                    length.span,
                    "a distance of zero makes the constraint degenerate (its Jacobian \
                     vanishes); use `revolute` to make two points coincide",
                );
                None
            }
            Some(negative) if negative < 0.0 => {
                self.errors.push(
                    length.span,
                    format!(
                        "a distance is a length between two points and cannot be negative; \
                         write {}",
                        -negative
                    ),
                );
                None
            }
            _ => Some(()),
        }
    }

    /// An optional geometric value (a phase), zero when absent.
    fn optional_geometry(&mut self, value: Option<&Expr>) -> Id {
        match value {
            Some(value) => self.geometry(value),
            None => self.arena.zero(),
        }
    }

    /// A gear's or rack's ratio: geometry, not zero when constant.
    fn nonzero_ratio(&mut self, ratio: &Expr) -> Option<Id> {
        let id = self.geometry(ratio);
        if self.arena.as_const(id) == Some(0.0) {
            self.errors.push(
                ratio.span,
                "a ratio of zero couples nothing (the driven side would be locked); give the \
                 ratio of the rotations (gears) or the travel per radian (rack)",
            );
            return None;
        }
        Some(id)
    }
}
