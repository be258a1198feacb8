//! The rules a scene's parameter-dependent geometry (and, with [`crate::PhysicsFault`], its
//! parameter-dependent mass properties and load constants) must satisfy when it is solved.
//!
//! `mechgen` checks constant geometry at compile time, at its tokens: a length folding to NaN,
//! a distance that is not positive, a length out of range. Geometry written in parameters is
//! only known once they are set, so a generated scene checks it with the current values before
//! every solve ([`crate::Mechanism::check_geometry`]), and the solver reports a violation as
//! [`crate::SolveError::Geometry`], naming the joint's equation and the parameter, instead of
//! the NaN Φ or the singular Jacobian it would cause later. The same limit as the compile-time
//! range rule applies ([`MAX_LENGTH`]).

/// Largest magnitude of a length (the compile-time rule's bound): squares and products of
/// lengths then stay far from overflow.
pub const MAX_LENGTH: f64 = 1e100;

/// What a parameter-dependent geometric value must be.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Requirement {
    /// A body-fixed coordinate of a point or a ground position: finite, at most
    /// [`MAX_LENGTH`] in magnitude.
    Length,
    /// A distance joint's length: positive and at most [`MAX_LENGTH`].
    Distance,
    /// An angle (a ground body's pose): finite.
    Angle,
    /// A component of a prismatic joint's unit axis: finite (the direction written is
    /// not the zero vector, nor overflowing).
    Axis,
    /// A gear's or rack's ratio: finite and not zero (a ratio of zero locks the driven side).
    Ratio,
    /// A body's mass: finite and at least zero.
    Mass,
    /// A body's moment of inertia: finite and at least zero.
    Inertia,
    /// A spring's stiffness: finite and at least zero.
    Stiffness,
    /// A spring's free length: at least zero and at most [`MAX_LENGTH`].
    FreeLength,
    /// A spring's damping coefficient: finite and at least zero.
    Damping,
}

impl Requirement {
    /// Whether `value` satisfies the requirement (NaN never does).
    pub fn holds(self, value: f64) -> bool {
        match self {
            Self::Length => value.abs() <= MAX_LENGTH,
            Self::Distance => value > 0.0 && value <= MAX_LENGTH,
            Self::Angle | Self::Axis => value.is_finite(),
            Self::Ratio => value.is_finite() && value != 0.0,
            Self::Mass | Self::Inertia | Self::Stiffness | Self::Damping => {
                value.is_finite() && value >= 0.0
            }
            Self::FreeLength => (0.0..=MAX_LENGTH).contains(&value),
        }
    }

    /// The value's role and the rule, as a sentence fragment.
    pub(crate) fn describe(self) -> &'static str {
        match self {
            Self::Length => "a length, which must be finite and at most 1e100 in magnitude",
            Self::Distance => "a distance, which must be positive and at most 1e100",
            Self::Angle => "an angle, which must be finite",
            Self::Axis => {
                "a component of the unit axis, which must be finite (the direction must not \
                 be the zero vector)"
            }
            Self::Ratio => "a gear or rack ratio, which must be finite and not zero",
            Self::Mass => "a mass, which must be finite and at least zero",
            Self::Inertia => "a moment of inertia, which must be finite and at least zero",
            Self::Stiffness => "a stiffness, which must be finite and at least zero",
            Self::FreeLength => "a free length, which must be at least zero and at most 1e100",
            Self::Damping => "a damping coefficient, which must be finite and at least zero",
        }
    }
}

/// A parameter-dependent geometric value that breaks its [`Requirement`].
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeometryFault {
    /// The first equation of the joint (or driver) the value belongs to.
    pub equation: usize,
    /// The first parameter (by index) the value is computed from.
    pub parameter: usize,
    /// The value with the current parameters.
    pub value: f64,
    /// What it must be.
    pub requirement: Requirement,
}

/// `Ok` when `value` meets `requirement`, otherwise the fault naming `equation` and
/// `parameter`: the check generated scenes call for each parameter-dependent value.
///
/// # Errors
/// The [`GeometryFault`] when the requirement does not hold.
#[inline]
pub fn check_geometry(
    value: f64,
    requirement: Requirement,
    equation: usize,
    parameter: usize,
) -> Result<(), GeometryFault> {
    if requirement.holds(value) {
        Ok(())
    } else {
        Err(GeometryFault {
            equation,
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
    fn each_requirement_refuses_what_it_says() {
        use Requirement::*;
        for requirement in [Length, Distance, Angle, Axis, Ratio, Mass] {
            assert!(!requirement.holds(f64::NAN));
            assert!(!requirement.holds(f64::INFINITY));
            assert!(requirement.holds(1.5));
        }
        assert!(Length.holds(-3.0) && Length.holds(0.0) && !Length.holds(2e100));
        assert!(!Distance.holds(0.0) && !Distance.holds(-1.0) && !Distance.holds(1e101));
        assert!(Angle.holds(-1e20) && Axis.holds(0.0));
        assert!(!Ratio.holds(0.0) && Ratio.holds(-2.0));
        for rule in [Mass, Inertia, Stiffness, FreeLength, Damping] {
            assert!(rule.holds(0.0) && !rule.holds(-1e-300), "{rule:?}");
            assert!(
                !rule.holds(f64::NAN) && !rule.holds(f64::INFINITY),
                "{rule:?}"
            );
        }
        assert!(Mass.holds(1e200) && !FreeLength.holds(1e101));
        let fault = check_geometry(-2.0, Distance, 7, 1).unwrap_err();
        assert_eq!((fault.equation, fault.parameter, fault.value), (7, 1, -2.0));
        assert_eq!(check_geometry(2.0, Distance, 7, 1), Ok(()));
    }
}
