//! The run-time counterpart of [`crate::check::resolution`]: the scene's geometry written in parameters
//! (body-fixed points, distances, ground poses, prismatic axes, gear and rack ratios), each value
//! with the rule it must satisfy, the joint it belongs to and a parameter it is computed from.
//!
//! Constant geometry is checked at compile time, at its tokens. These values are only known
//! once the parameters are set, so the generated `check_geometry` (and the interpreter) evaluate
//! them before every solve and report the first one that breaks its rule as a typed error naming
//! the joint's equation and the parameter (`mechgen_runtime::SolveError::Geometry`). A scene
//! whose geometry is constant gets no check at all.

use std::cell::Cell;
use std::collections::HashSet;

use crate::expr::{Arena, Id, Node};
use crate::model::{ConstraintKind, Driven, Model};

/// What a value must be (mirrors `mechgen_runtime::Requirement`, which generated code names).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Requirement {
    /// A point coordinate or a ground position: finite and within the length range.
    Length,
    /// A distance joint's length: positive and within the length range.
    Distance,
    /// A ground body's angle: finite.
    Angle,
    /// A component of a unit axis: finite (the axis written is not the zero vector).
    Axis,
    /// A gear's or rack's ratio: finite and not zero.
    Ratio,
    /// A body's mass: finite, at least zero ([`crate::model::physics`]).
    Mass,
    /// A body's moment of inertia: finite, at least zero.
    Inertia,
    /// A spring's stiffness: finite, at least zero.
    Stiffness,
    /// A spring's free length: at least zero, within the length range.
    FreeLength,
    /// A spring's damping coefficient: finite, at least zero.
    Damping,
}

impl Requirement {
    /// The variant's name, as in `mechgen_runtime::Requirement`.
    pub fn name(self) -> &'static str {
        match self {
            Requirement::Length => "Length",
            Requirement::Distance => "Distance",
            Requirement::Angle => "Angle",
            Requirement::Axis => "Axis",
            Requirement::Ratio => "Ratio",
            Requirement::Mass => "Mass",
            Requirement::Inertia => "Inertia",
            Requirement::Stiffness => "Stiffness",
            Requirement::FreeLength => "FreeLength",
            Requirement::Damping => "Damping",
        }
    }
}

/// One parameter-dependent value to check at run time: geometry (here, `S` the first equation
/// of the constraint it belongs to, the first constraint's if several share it) or a mass
/// property or load constant ([`crate::model::physics`], `S` the body or load).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Check<S = usize> {
    /// The value, an expression in parameters.
    pub value: Id,
    /// Its rule.
    pub requirement: Requirement,
    /// What it belongs to, which the runtime's fault names.
    pub subject: S,
    /// The lowest-indexed parameter it reads.
    pub parameter: usize,
}

/// Every parameter-dependent geometric value of `model`, each once, in declaration order.
pub fn checks(model: &Model) -> Vec<Check> {
    let mut checks = Vec::new();
    let mut seen = HashSet::new();
    let mut equation = 0;
    for constraint in &model.constraints {
        for (value, requirement) in values(&constraint.kind) {
            if let Some(parameter) = first_parameter(&model.arena, value)
                && seen.insert((value, requirement))
            {
                checks.push(Check {
                    value,
                    requirement,
                    subject: equation,
                    parameter,
                });
            }
        }
        equation += constraint.kind.equation_units().len();
    }
    checks
}

/// A constraint's geometric values and their rules (not a driver's prescribed value, which
/// depends on time: a NaN there is named by the solver's `NonFinite` error).
fn values(kind: &ConstraintKind) -> Vec<(Id, Requirement)> {
    let mut values: Vec<(Id, Requirement)> = kind
        .points()
        .iter()
        .flat_map(|p| p.local)
        .map(|id| (id, Requirement::Length))
        .collect();
    match *kind {
        ConstraintKind::Ground { pose, .. } => {
            values.push((pose[0], Requirement::Length));
            values.push((pose[1], Requirement::Length));
            values.push((pose[2], Requirement::Angle));
        }
        ConstraintKind::Prismatic { axis, .. }
        | ConstraintKind::Slot { axis, .. }
        | ConstraintKind::Rack { axis, .. }
        | ConstraintKind::Driver {
            driven: Driven::Travel { axis, .. },
            ..
        } => values.extend(axis.map(|id| (id, Requirement::Axis))),
        ConstraintKind::Distance { length, .. } => values.push((length, Requirement::Distance)),
        ConstraintKind::Weld { angle, .. } => values.push((angle, Requirement::Angle)),
        ConstraintKind::Gear { ratio, .. } => values.push((ratio, Requirement::Ratio)),
        ConstraintKind::Revolute { .. } | ConstraintKind::Driver { .. } => {}
    }
    if let ConstraintKind::Rack { ratio, .. } = *kind {
        values.push((ratio, Requirement::Ratio));
    }
    values
}

/// The lowest-indexed parameter `id` reads; `None` for a constant.
pub(crate) fn first_parameter(arena: &Arena, id: Id) -> Option<usize> {
    let lowest = Cell::new(None::<u32>);
    arena.any_node(id, |node| {
        if let Node::Param(i) = node {
            lowest.set(Some(lowest.get().map_or(i, |l| l.min(i))));
        }
        false
    });
    lowest.get().map(|i| i as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checks_of(source: &str) -> (Vec<Check>, crate::Scene) {
        let scene = crate::compile(crate::Input::Text(source), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{:?}", e.messages()));
        (scene.kinematics.geometry.clone(), scene)
    }

    #[test]
    fn only_parameter_dependent_geometry_is_checked_and_named() {
        let (checks, scene) = checks_of(
            "mechanism M {
                param offset = 12.0;
                param rod = 80.0;
                param swing = 0.5;
                ground frame at (0, 0, 0);
                body crank near (0, 0, 0);
                body slider near (100, 12, 0);
                joint pivot: revolute(frame, crank);
                joint tie: distance(crank @ (30, 0), slider, rod + offset);
                joint guide: prismatic(frame @ (0, offset), slider, along (1, 0));
                driver d: angle(crank) = swing * t;
            }",
        );
        let found: Vec<(Requirement, usize, usize)> = checks
            .iter()
            .map(|c| (c.requirement, c.subject, c.parameter))
            .collect();
        // Ground equations 0..3, pivot 3..5, tie 5, guide 6..8: `rod + offset` reads parameters
        // 0 and 1 and names the lower; the driver's value depends on t and is not geometry.
        assert_eq!(
            found,
            [(Requirement::Distance, 5, 0), (Requirement::Length, 6, 0)],
            "{checks:?}"
        );
        assert!(scene.model.arena.as_const(checks[0].value).is_none());
    }
}
