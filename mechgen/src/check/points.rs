//! Named body points: `point pin: crank @ (0, 43);` then `pin` wherever a point is written
//! (joints, drivers, markers, branches, loads). Each use is replaced by the point as declared
//! before checking, so every rule applies to it as if written out; the body's name takes the
//! use's span, so that an error about the use (a joint from a body to itself, a driver on a
//! ground body) points at the use.

use std::collections::HashMap;

use proc_macro2::Ident;

use crate::error::Errors;
use crate::syntax::spec::{DriverKind, JointKind, LoadKind, MarkerKind, PointRef, Spec};

/// `spec` with every use of a named point replaced by the point; `None` when it declares none.
/// Reports a point declared on an unknown body or on another named point, and a use with an
/// offset (`pin @ (1, 0)`).
pub(super) fn substitute(spec: &Spec, errors: &mut Errors) -> Option<Spec> {
    if spec.points.is_empty() {
        return None;
    }
    let points = declared(spec, errors);
    let mut spec = spec.clone();
    let replace = |p: &mut PointRef| {
        let Some(point) = points.get(&p.body.to_string()) else {
            return;
        };
        let body = Ident::new(&point.body.to_string(), p.body.span());
        if p.local.is_some() {
            errors.push(
                p.body.span(),
                format!(
                    "`{}` is a named point, which takes no `@ (x, y)`: for another point of its \
                     body write `{} @ (x, y)`",
                    p.body, point.body
                ),
            );
            // Checked on as that point of the body, so that this is the only error.
            p.body = body;
            return;
        }
        *p = PointRef {
            body,
            local: point.local.clone(),
        };
    };
    for_each_use(&mut spec, replace);
    Some(spec)
}

/// The declared points by name; reports a point declared on an unknown body or on another
/// named point.
fn declared(spec: &Spec, errors: &mut Errors) -> HashMap<String, PointRef> {
    let bodies: Vec<String> = spec.bodies.iter().map(|b| b.name.to_string()).collect();
    let mut points: HashMap<String, PointRef> = HashMap::new();
    for decl in &spec.points {
        let body = decl.point.body.to_string();
        if !bodies.contains(&body) {
            let what = if spec.points.iter().any(|p| p.name == body) {
                format!("`{body}` is a named point; a point is declared on a body")
            } else {
                format!("unknown body `{body}`")
            };
            errors.push(
                decl.point.body.span(),
                format!(
                    "{what}: write `point {}: BODY @ (x, y);` with one of the bodies {}",
                    decl.name,
                    list(&bodies)
                ),
            );
        }
        points
            .entry(decl.name.to_string())
            .or_insert_with(|| decl.point.clone());
    }
    points
}

/// Calls `replace` on every point written in `spec`'s joints, drivers, markers, branches and
/// loads.
fn for_each_use(spec: &mut Spec, mut replace: impl FnMut(&mut PointRef)) {
    for joint in &mut spec.joints {
        match &mut joint.kind {
            JointKind::Revolute { a, b }
            | JointKind::Prismatic { a, b, .. }
            | JointKind::Distance { a, b, .. }
            | JointKind::Slot { a, b, .. }
            | JointKind::Weld { a, b, .. } => [a, b].into_iter().for_each(&mut replace),
            JointKind::Gear { .. } | JointKind::Rack { .. } => {}
        }
    }
    for driver in &mut spec.drivers {
        match &mut driver.kind {
            DriverKind::X(p) | DriverKind::Y(p) => replace(p),
            DriverKind::Distance(a, b) | DriverKind::Slide { a, b, .. } => {
                [a, b].into_iter().for_each(&mut replace);
            }
            DriverKind::Angle(_) | DriverKind::RelativeAngle(..) | DriverKind::Travel(_) => {}
        }
    }
    for marker in &mut spec.markers {
        if let MarkerKind::Point(p) = &mut marker.kind {
            replace(p);
        }
    }
    for branch in &mut spec.branches {
        branch
            .u
            .iter_mut()
            .chain(&mut branch.v)
            .for_each(&mut replace);
    }
    for load in &mut spec.loads {
        match &mut load.kind {
            LoadKind::Force { point, .. } => replace(point),
            LoadKind::Spring { a, b, .. } => [a, b].into_iter().for_each(&mut replace),
            LoadKind::Torque { .. } => {}
        }
    }
}

fn list(names: &[String]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    quoted.join(", ")
}
