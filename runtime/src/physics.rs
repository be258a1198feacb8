//! The run-time check of a scene's mass properties and load constants written in parameters:
//! the same rules `mechgen` applies to constants at compile time (a mass, an inertia, a
//! stiffness, a free length or a damping cannot be negative), applied before every solve with
//! the current parameter values, so that `--set m=-1` is refused instead of solving for a body
//! of −1 kg. The geometry's counterpart is [`crate::codegen::check_geometry`]; the rules are
//! [`Requirement`]s.

use crate::geometry::Requirement;

/// What a checked value belongs to.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Subject {
    /// Body `index` in declaration order (its coordinates are `3 · index ..`): its mass,
    /// inertia or centre of mass.
    Body(usize),
    /// Load `index` in declaration order (named by [`crate::Names::load`]): a spring's
    /// constants, or a point a load acts at.
    Load(usize),
}

/// A parameter-dependent mass property or load constant that breaks its [`Requirement`].
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhysicsFault {
    /// The body or load the value belongs to.
    pub subject: Subject,
    /// The first parameter (by index) the value is computed from.
    pub parameter: usize,
    /// The value with the current parameters.
    pub value: f64,
    /// What it must be.
    pub requirement: Requirement,
}

impl PhysicsFault {
    /// The fault as the error of a solve at `time`.
    pub fn at(self, time: f64) -> crate::SolveError {
        crate::SolveError::Physics {
            time,
            subject: self.subject,
            parameter: self.parameter,
            value: self.value,
            requirement: self.requirement,
            names: &crate::Names::NONE,
        }
    }
}

/// `Ok` when `value` meets `requirement`, otherwise the fault naming `subject` and
/// `parameter`: the check generated scenes call for each parameter-dependent value.
///
/// # Errors
/// The [`PhysicsFault`] when the requirement does not hold.
#[inline]
pub fn check_physics(
    value: f64,
    requirement: Requirement,
    subject: Subject,
    parameter: usize,
) -> Result<(), PhysicsFault> {
    if requirement.holds(value) {
        Ok(())
    } else {
        Err(PhysicsFault {
            subject,
            parameter,
            value,
            requirement,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fault_names_its_subject_and_parameter() {
        let fault = check_physics(-1.0, Requirement::Mass, Subject::Body(2), 0).unwrap_err();
        assert_eq!(
            (fault.subject, fault.parameter, fault.value),
            (Subject::Body(2), 0, -1.0)
        );
        assert_eq!(
            check_physics(0.0, Requirement::Mass, Subject::Body(2), 0),
            Ok(())
        );
        assert!(check_physics(-0.1, Requirement::Damping, Subject::Load(1), 3).is_err());
    }
}
