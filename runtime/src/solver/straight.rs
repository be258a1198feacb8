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
use crate::workspace::{StepParts, Workspace};

impl<M: Structured> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Solves `state` at `t` by the straight step: `Ok(Some(convergence))` when it did,
    /// `Ok(None)` when the stage sweep must (no straight step; it, closed forms or static
    /// pivots switched off; fewer rates than both asked for; a check declined, or the
    /// reactions are not finite). The guess is then as it was, or, past a declined end
    /// check, the step's positions, from which every block takes the same closed-form
    /// solution (non-finite markers or reactions, which the sweep reports from the same
    /// positions).
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
        if !(enabled && matches!(rates, Rates::Both | Rates::Forces)) {
            return Ok(None);
        }
        match guess {
            Guess::Given => self.check_inputs(t, &state.q, Quantity::Guess)?,
            Guess::Predicted if !t.is_finite() => return Err(non_finite(t, Quantity::Time)),
            Guess::Predicted => {}
        }
        self.check_mechanism(t)?;
        let Self {
            mechanism: m,
            workspace,
            context,
            ..
        } = self;
        let mut report = StepReport::new(context.estimate_condition);
        let parts = workspace.step_parts();
        let done = if rates == Rates::Forces {
            straight_forces(m, parts, t, state, context, &mut report)
        } else {
            let (q, qd, qdd) = (
                &mut state.q,
                &mut state.velocities,
                &mut state.accelerations,
            );
            m.straight_step(t, q, qd, qdd, parts.trig, &mut [], context, &mut report)
                .is_ok()
                && markers(m, t, state, parts.trig)
        };
        if !done {
            return Ok(None);
        }
        context.choices = report.choices;
        self.diagnosed = (0, 0);
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

/// The straight step of a scene that computes forces: the step, which also archives every
/// block's factors as the sweep archives them (for the integrator's velocity solves over
/// them) and ends with the force solve's multipliers, then the reactions and the markers;
/// whether all of it succeeded (non-finite reactions leave the sweep to name their cause).
fn straight_forces<M: Structured>(
    m: &M,
    parts: StepParts<'_>,
    t: f64,
    state: &mut State<M>,
    context: &StepContext,
    report: &mut StepReport,
) -> bool
where
    DefaultAllocator: Storage<M::Dim>,
{
    let (q, qd, qdd) = (
        &mut state.q,
        &mut state.velocities,
        &mut state.accelerations,
    );
    let forces = &mut *parts.forces;
    if m.straight_step(t, q, qd, qdd, parts.trig, forces, context, report)
        .is_err()
    {
        return false;
    }
    // Every block of a straight step is factored with its static pivots.
    parts.archived.fill(true);
    let lambda = parts.forces.get(..q.len()).unwrap_or_default();
    m.reactions(q, qd, lambda, &mut state.reactions);
    all_finite(state.reactions.as_slice()) && markers(m, t, state, parts.trig)
}

/// The markers at the step's solved state, which the step's own end checks leave out;
/// whether they are finite (the sweep reports them otherwise).
fn markers<M: Structured>(m: &M, t: f64, state: &mut State<M>, trig: &[f64]) -> bool
where
    DefaultAllocator: Storage<M::Dim>,
{
    if state.markers.as_ref().is_empty() {
        return true;
    }
    let (q, qd, qdd) = (&state.q, &state.velocities, &state.accelerations);
    m.markers(q, trig, qd, qdd, t, &mut state.markers);
    all_finite(state.markers.as_ref())
}
