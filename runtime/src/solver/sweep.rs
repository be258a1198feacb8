//! The stage sweep of a full solve: each stage in order, explicit ones assigned, blocks solved
//! by Newton's method and their rates with the same factors, then the checks at the end, the
//! force solve and the markers.

use nalgebra::DefaultAllocator;

use super::api::Solver;
use super::checks::check_branches;
use super::convergence::Convergence;
use super::diagnosis::record;
use super::rates::{assign_rates, block_rates, check_rates};

use crate::acceptance::{self, Rounding};
use crate::block::BlockSolve;
use crate::error::{Quantity, SolveError};
use crate::finite::non_finite;
use crate::forces;
use crate::mechanism::{Mechanism, Storage, Vector};
use crate::options::Rates;
use crate::origin;
use crate::position::Newton;
use crate::structure::{Stage, Structured};
use crate::workspace::Workspace;

/// What a full solve writes besides the motion: the reactions (for a scene that computes
/// forces) and the marker values.
pub(crate) struct Extras<'a, M: Mechanism>
where
    DefaultAllocator: Storage<M::Dim>,
{
    pub(super) reactions: &'a mut Vector<M::Dim>,
    pub(super) markers: &'a mut M::Markers,
}

impl<M: Structured> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// The stage sweep of [`Solver::solve_into`] and [`Solver::solve_position`], with a
    /// non-finite value traced to where it began.
    pub(super) fn solve_stages(
        &mut self,
        t: f64,
        q: &mut Vector<M::Dim>,
        qd: &mut Vector<M::Dim>,
        qdd: &mut Vector<M::Dim>,
        rates: Rates,
        extras: Option<Extras<'_, M>>,
    ) -> Result<Convergence, SolveError> {
        self.check_inputs(t, q, Quantity::Guess)?;
        self.check_mechanism(t)?;
        let mut reached = 0;
        self.sweep(t, q, qd, qdd, rates, extras, &mut reached)
            .map_err(|e| origin::trace(&self.mechanism, reached, [q, qd, qdd], rates, e))
    }

    /// Solves the stages in order, recording in `reached` the stage being solved, then into
    /// `extras` (a full solve's) the force solve in reverse for [`Rates::Forces`] and the
    /// marker values.
    #[allow(clippy::too_many_arguments)]
    fn sweep(
        &mut self,
        t: f64,
        q: &mut Vector<M::Dim>,
        qd: &mut Vector<M::Dim>,
        qdd: &mut Vector<M::Dim>,
        rates: Rates,
        extras: Option<Extras<'_, M>>,
        reached: &mut usize,
    ) -> Result<Convergence, SolveError> {
        // Kept whole: one pass over the stages; its arms share the solver and the running totals.
        self.diagnosed = (0, 0);
        let Self {
            mechanism: m,
            options,
            workspace,
            length,
            diagnosed,
            escape_side,
            ..
        } = self;
        let mut parts = workspace.parts();
        let mut total = Convergence::start(options.estimate_condition);
        // A looser residual tolerance asked for loosens acceptance with it (as in `position`).
        let acceptance = options.acceptance_tolerance.max(options.residual_tolerance);
        let mut rounding = Rounding::new(acceptance, length);
        // How much of the force solve's archive the blocks have filled.
        let mut archived = 0;
        for s in 0..m.stage_count() {
            *reached = s;
            match m.stage(s) {
                Some(Stage::Explicit { coordinates, .. }) => {
                    m.assign_positions(s, q, parts.trig, t);
                    rounding.explicit(m, coordinates, q, length);
                    m.fill_trig(s, q, parts.trig);
                    assign_rates(m, s, q, parts.trig, qd, qdd, t, rates);
                }
                Some(Stage::Block(block)) => {
                    let bs = BlockSolve { m, stage: s, block };
                    bs.set_scales(&mut parts.scales, length);
                    let mut newton = Newton::new(bs, &mut parts, options, t);
                    newton.escape_side = *escape_side;
                    let solved = newton
                        .solve(q, rates != Rates::None)
                        .map_err(|e| record(e, m, s, newton.parts, diagnosed))?;
                    let counts = (newton.fallbacks, newton.evaluations, newton.closed_form);
                    total.add(s, &solved, counts);
                    rounding.block::<M>(block.coordinates, newton.parts.scales.inverse_cols, q);
                    m.fill_trig(s, q, newton.parts.trig);
                    block_rates(
                        &newton.bs,
                        solved.factors,
                        newton.parts,
                        q,
                        qd,
                        qdd,
                        t,
                        rates,
                    )?;
                    if rates == Rates::Forces {
                        let n = q.len();
                        archived =
                            forces::archive(&newton.bs, solved.factors, newton.parts, n, archived);
                    }
                }
                None => break,
            }
        }
        // Every coordinate a stage solved went through `rounding`, which saw whether it is
        // finite (a coordinate no stage solves keeps the guess, checked on entry): an explicit
        // assignment's non-finite value shows here (or earlier, as the non-finite Φ or rate of
        // a block that reads it).
        *reached = m.stage_count();
        if !rounding.finite() {
            return Err(non_finite(t, Quantity::Phi));
        }
        if rounding.pending() {
            let explicit = acceptance::check_explicit(m, q, t, length, acceptance)?;
            total.residual = total.residual.max(explicit);
        }
        check_rates(qd, qdd, t, rates)?;
        check_branches(m, q, parts.trig, t)?;
        if let Some(Extras { reactions, markers }) = extras {
            if rates == Rates::Forces {
                let motion = forces::Motion { t, q, qd, qdd };
                forces::solve(m, &mut parts, options, length, &motion, archived, reactions)?;
            }
            if !markers.as_ref().is_empty() {
                m.markers(q, parts.trig, qd, qdd, t, markers);
                let bad = markers.as_ref().iter().position(|v| !v.is_finite());
                if let Some(index) = bad {
                    return Err(non_finite(t, Quantity::Marker(index)));
                }
            }
        }
        Ok(total)
    }
}
