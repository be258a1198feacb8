//! The run-time counterpart of the compile-time rules for mass properties and loads
//! (`check::dynamics`): masses, inertias, spring stiffnesses, free lengths and dampings written
//! in parameters, and the centres of mass and load points, each with the rule it must satisfy,
//! the body or load it belongs to and a parameter it is computed from.
//!
//! Constants are checked at compile time (a negative mass is refused at its tokens). Values in
//! parameters are only known once the parameters are set, so the generated `check_physics` (and
//! the interpreter) evaluate them before every solve and report the first that breaks its rule
//! as a typed error naming the body or load and the parameter
//! (`mechgen_runtime::SolveError::Physics`). A scene whose physics is constant gets no check.

use std::collections::HashSet;

use crate::model::geometry::{Requirement, first_parameter};
use crate::model::{LoadKind, Model};

/// What a checked value belongs to (mirrors `mechgen_runtime::Subject`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Subject {
    /// Body `index` in declaration order.
    Body(usize),
    /// Load `index` in declaration order.
    Load(usize),
}

/// One parameter-dependent mass property or load constant to check at run time.
pub type Check = crate::model::geometry::Check<Subject>;

/// Every parameter-dependent mass property and load constant of `model`, each once per body or
/// load, in declaration order (bodies, then loads).
pub fn checks(model: &Model) -> Vec<Check> {
    let mut values = Vec::new();
    for (b, body) in model.bodies.iter().enumerate() {
        let Some(mass) = &body.mass else { continue };
        let subject = Subject::Body(b);
        values.push((mass.mass, Requirement::Mass, subject));
        values.push((mass.inertia, Requirement::Inertia, subject));
        values.extend(mass.centre.map(|c| (c, Requirement::Length, subject)));
    }
    for (l, load) in model.loads.iter().enumerate() {
        let subject = Subject::Load(l);
        match &load.kind {
            LoadKind::Force { point, .. } => {
                values.extend(point.local.map(|c| (c, Requirement::Length, subject)));
            }
            LoadKind::Torque { .. } => {}
            LoadKind::Spring {
                a,
                b,
                stiffness,
                length,
                damping,
            } => {
                values.push((*stiffness, Requirement::Stiffness, subject));
                values.push((*length, Requirement::FreeLength, subject));
                values.push((*damping, Requirement::Damping, subject));
                for point in [a, b] {
                    values.extend(point.local.map(|c| (c, Requirement::Length, subject)));
                }
            }
        }
    }
    let mut seen = HashSet::new();
    values
        .into_iter()
        .filter_map(|(value, requirement, subject)| {
            let parameter = first_parameter(&model.arena, value)?;
            seen.insert((value, requirement, subject)).then_some(Check {
                value,
                requirement,
                subject,
                parameter,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_parameter_dependent_physics_is_checked_and_named() {
        let scene = crate::compile(
            crate::Input::Text(
                "mechanism M {
                param m = 2.0;
                param k = 500.0;
                ground frame at (0, 0, 0);
                body crank near (0, 0, 0) mass m inertia 0.01;
                body slider near (0.3, 0, 0) mass 0.7 inertia 2 * m;
                joint pivot: revolute(frame, crank);
                joint guide: prismatic(frame, slider, along (1, 0));
                joint rod: distance(crank @ (0.1, 0), slider, 0.25);
                driver spin: angle(crank) = t;
                load coil: spring(frame @ (0.6, 0.1), slider, stiffness k, length 0.2);
            }",
            ),
            &crate::Options::default(),
        )
        .unwrap_or_else(|e| panic!("{:?}", e.messages()));
        let found: Vec<(Requirement, Subject, usize)> = scene
            .kinematics
            .physics
            .iter()
            .map(|c| (c.requirement, c.subject, c.parameter))
            .collect();
        assert_eq!(
            found,
            [
                (Requirement::Mass, Subject::Body(1), 0),
                (Requirement::Inertia, Subject::Body(2), 0),
                (Requirement::Stiffness, Subject::Load(0), 1),
            ]
        );
    }
}
