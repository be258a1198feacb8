//! What a `NonFinite` error names: the quantity found to be NaN or infinite, and the first
//! faulty load of a scene's load witnesses.

use core::fmt;

use super::lookup::{Lookup, write_name};

use crate::names::Names;

/// The quantity found to be NaN or infinite.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Quantity {
    /// The time passed in.
    Time,
    /// A run-time parameter of the scene (its index).
    Parameter(usize),
    /// The initial guess, or the positions passed to a velocity or acceleration solve.
    Guess,
    /// The constraint vector Φ.
    Phi,
    /// The Jacobian Φ_q.
    Jacobian,
    /// The velocity right-hand side ν.
    Nu,
    /// The acceleration right-hand side γ.
    Gamma,
    /// The Newton step Δq (the iteration is diverging).
    Step,
    /// The velocities q̇ (solved, or passed to an acceleration solve).
    Velocity,
    /// The solved accelerations q̈.
    Acceleration,
    /// A branch invariant of the scene (its index).
    Branch(usize),
    /// The generalised applied and inertial forces F of the force solve as a whole, when no
    /// single load explains them ([`Quantity::LoadValue`] and [`Quantity::SpringEnds`] name
    /// one): the masses' inertia or gravity overflowing.
    Load,
    /// The solved reactions (Lagrange multipliers) of the force solve.
    Reaction,
    /// A marker's value or rate (its index among the marker values).
    Marker(usize),
    /// One load's force or moment (its index among the scene's loads): its expression or the
    /// parameters it reads (a moment of 1e310, a division by zero).
    LoadValue(usize),
    /// A spring's force where its ends coincide (its index among the scene's loads): with a
    /// non-zero free length or damping its direction, and so its force, is undefined there.
    SpringEnds(usize),
}

/// The first load, among [`crate::Mechanism::load_fault`]'s witnesses (two values per load:
/// the sum of its contributions to F, and for a spring the squared distance between its ends,
/// else 1), whose contribution is not finite: [`Quantity::SpringEnds`] when the ends meet,
/// [`Quantity::LoadValue`] otherwise. Generated scenes and the interpreter call it.
pub fn first_load_fault(witnesses: &[f64]) -> Option<Quantity> {
    witnesses
        .chunks_exact(2)
        .position(|w| !w[0].is_finite())
        .map(|load| {
            if witnesses.get(2 * load + 1).is_some_and(|&d| d == 0.0) {
                Quantity::SpringEnds(load)
            } else {
                Quantity::LoadValue(load)
            }
        })
}

impl Quantity {
    /// Writes the quantity, naming a parameter, branch or marker from `names` (its index
    /// otherwise).
    pub(super) fn write(self, f: &mut fmt::Formatter<'_>, names: &dyn Lookup) -> fmt::Result {
        let (label, name, index) = match self {
            Self::Parameter(i) => ("parameter ", names.parameter(i), i),
            Self::Branch(i) => ("branch invariant ", names.branch(i), i),
            Self::Marker(i) => ("marker value ", names.marker(i), i),
            Self::LoadValue(i) => ("the force or moment of load ", names.load(i), i),
            Self::SpringEnds(i) => ("the force of spring ", names.load(i), i),
            _ => return f.write_str(self.text()),
        };
        f.write_str(label)?;
        write_name(f, name, index)
    }

    /// What an unindexed quantity is called.
    fn text(self) -> &'static str {
        match self {
            Self::Time => "the time",
            Self::Guess => "the positions q (initial guess)",
            Self::Phi => "the constraints Φ",
            Self::Jacobian => "the Jacobian Φ_q",
            Self::Nu => "the velocity right-hand side ν",
            Self::Gamma => "the acceleration right-hand side γ",
            Self::Step => "the Newton step Δq",
            Self::Velocity => "the velocities q̇",
            Self::Acceleration => "the accelerations q̈",
            Self::Load => "the applied and inertial forces F (loads, springs, masses)",
            Self::Reaction => "the reactions (constraint forces and driver efforts)",
            Self::Parameter(_)
            | Self::Branch(_)
            | Self::Marker(_)
            | Self::LoadValue(_)
            | Self::SpringEnds(_) => "",
        }
    }
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.write(f, &Names::NONE)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_non_finite_load_is_named_with_its_cause() {
        let nan = f64::NAN;
        assert_eq!(first_load_fault(&[1.0, 1.0, 2.0, 0.0]), None);
        assert_eq!(
            first_load_fault(&[1.0, 1.0, nan, 0.0, nan, 1.0]),
            Some(Quantity::SpringEnds(1))
        );
        assert_eq!(
            first_load_fault(&[f64::INFINITY, 1.0, nan, 0.0]),
            Some(Quantity::LoadValue(0))
        );
    }
}
