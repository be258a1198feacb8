//! What a solve refuses before and after it runs: mis-sized or non-finite inputs, invalid
//! parameters, a solution on another branch.

use nalgebra::{DefaultAllocator, Dim};

use super::api::Solver;

use crate::error::{Quantity, SolveError};
use crate::finite::{check_finite, non_finite};
use crate::mechanism::{Storage, Vector};
use crate::names::Names;
use crate::step::StepContext;
use crate::structure::Structured;

impl<M: Structured> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Every parameter finite, and the geometry and physics written in them valid
    /// ([`Solver::check_parameters`]), and the length scale of the parameters: once after the
    /// mechanism or the options may have changed (`mechanism_mut`, `set_options`), not on
    /// every solve. A failed check is made again by the next solve.
    pub(crate) fn check_mechanism(&mut self, t: f64) -> Result<(), SolveError> {
        if !self.checked {
            self.check_parameters(t)?;
            self.update_scale();
            self.context = StepContext::new(&self.options, self.length, self.context.choices);
            self.checked = true;
        }
        Ok(())
    }

    /// Every parameter finite, and the geometry and physics written in them valid: a NaN set
    /// through a public field, a distance or a mass set negative, is reported as itself, not as
    /// the NaN Φ, the singular Jacobian or the wrong forces it would cause.
    fn check_parameters(&self, t: f64) -> Result<(), SolveError> {
        let m = &self.mechanism;
        match (0..m.parameter_count()).find(|&i| !m.parameter(i).is_some_and(f64::is_finite)) {
            Some(index) => Err(non_finite(t, Quantity::Parameter(index))),
            None => {
                m.check_geometry().map_err(|fault| fault.at(t))?;
                m.check_physics().map_err(|fault| fault.at(t))
            }
        }
    }

    /// Length and finiteness of an input, and finiteness of `t`.
    pub(crate) fn check_inputs(
        &self,
        t: f64,
        v: &Vector<M::Dim>,
        quantity: Quantity,
    ) -> Result<(), SolveError> {
        if !t.is_finite() {
            return Err(non_finite(t, Quantity::Time));
        }
        self.check_len(v)?;
        check_finite(v, t, quantity)
    }

    /// Only a `Dyn` vector can disagree with the mechanism; nalgebra would panic on it.
    pub(crate) fn check_len(&self, v: &Vector<M::Dim>) -> Result<(), SolveError> {
        let expected = self.mechanism.dim().value();
        if v.nrows() == expected {
            Ok(())
        } else {
            Err(SolveError::DimensionMismatch {
                expected,
                found: v.nrows(),
                names: &Names::NONE,
            })
        }
    }
}

/// Every branch invariant positive at `q`.
pub(super) fn check_branches<M: Structured>(
    m: &M,
    q: &Vector<M::Dim>,
    trig: &[f64],
    t: f64,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    for branch in 0..m.branch_count() {
        let value = m.branch(branch, q, trig);
        if !value.is_finite() {
            return Err(non_finite(t, Quantity::Branch(branch)));
        }
        if value <= 0.0 {
            return Err(SolveError::BranchFlip {
                time: t,
                branch,
                value,
                names: &Names::NONE,
            });
        }
    }
    Ok(())
}
