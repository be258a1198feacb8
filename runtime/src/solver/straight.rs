//! A full solve by the scene's straight kinematic step ([`Structured::straight_step`]) where
//! it has one: the step, then the checks the stage sweep makes at its end, and the report the
//! sweep would give. Where the scene has no straight step, or the step or a check declines,
//! the caller runs the stage sweep.

use nalgebra::DefaultAllocator;

use super::api::{Guess, Solver};
use super::convergence::Convergence;

use crate::error::{Quantity, SolveError};
use crate::finite::{all_finite, non_finite};
use crate::mechanism::Storage;
use crate::options::Rates;
use crate::state::State;
use crate::step::{StepContext, StepReport};
use crate::structure::Structured;
use crate::workspace::Workspace;

impl<M: Structured> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Solves `state` at `t` by the straight step: `Ok(Some(convergence))` when it did,
    /// `Ok(None)` when the stage sweep must (no straight step; it, closed forms or static
    /// pivots switched off; forces or fewer rates asked for; a check declined). The guess is
    /// then as it was, or, past a declined end check, the step's positions, from which every
    /// block takes the same closed-form solution (non-finite markers, which the sweep reports
    /// from the same positions).
    ///
    /// # Errors
    /// The sweep's input checks: a non-finite `t` or, when [`Guess::Given`], guess; an invalid
    /// parameter.
    pub(super) fn straight_solve(
        &mut self,
        t: f64,
        state: &mut State<M>,
        rates: Rates,
        guess: Guess,
    ) -> Result<Option<Convergence>, SolveError> {
        let options = &self.options;
        let enabled = options.straight_step && options.closed_forms && options.static_pivots;
        if !(enabled && rates == Rates::Both) {
            return Ok(None);
        }
        match guess {
            Guess::Given => self.check_inputs(t, &state.q, Quantity::Guess)?,
            Guess::Predicted if !t.is_finite() => return Err(non_finite(t, Quantity::Time)),
            Guess::Predicted => {}
        }
        self.check_mechanism(t)?;
        let context = StepContext {
            choices: self.closed_choices,
            ..self.context
        };
        let mut report = StepReport::new(context.estimate_condition);
        let m = &self.mechanism;
        let trig = self.workspace.trig();
        let (q, qd, qdd) = (
            &mut state.q,
            &mut state.velocities,
            &mut state.accelerations,
        );
        if m.straight_step(t, q, qd, qdd, trig, &context, &mut report)
            .is_err()
        {
            return Ok(None);
        }
        // The step made the sweep's end checks (`StepContext::check_end`) but the markers'.
        if !state.markers.as_ref().is_empty() {
            m.markers(q, trig, qd, qdd, t, &mut state.markers);
            if !all_finite(state.markers.as_ref()) {
                return Ok(None);
            }
        }
        self.diagnosed = (0, 0);
        self.closed_choices = report.choices;
        Ok(Some(Convergence {
            iterations: 0,
            residual: report.residual,
            condition: report.condition,
            fallbacks: 0,
            evaluations: report.blocks,
            orientation: report.orientation,
            block_signs: report.block_signs,
            swept: false,
            closed_forms: report.blocks,
        }))
    }
}
