//! The diagnosis of a singular configuration: which block, which equations depend on the
//! others, and which coordinates (the block's and those computed from it) are undetermined.

use nalgebra::DefaultAllocator;

use super::api::Solver;

use crate::block::BlockSolve;
use crate::error::SolveError;
use crate::mechanism::{Storage, Vector};
use crate::names::Names;
use crate::position::Newton;
use crate::structure::{Block, Stage, Structured};
use crate::workspace::{Parts, Workspace};

impl<M: Structured> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// The diagnosis of the configuration `q` at `t` (a solution next to a singular one): every
    /// block is factored there, and the one with the largest condition estimate gets the
    /// rank-revealing diagnosis ([`SolveError::Singular`], with the lists behind
    /// [`Solver::dependent_equations`]).
    pub(crate) fn diagnose_at(&mut self, t: f64, q: &Vector<M::Dim>) -> SolveError {
        self.update_scale();
        self.diagnosed = (0, 0);
        let Self {
            mechanism: m,
            options,
            workspace,
            length,
            diagnosed,
            ..
        } = self;
        let mut parts = workspace.parts();
        let mut worst: Option<(usize, Block<'_>, f64)> = None;
        for s in 0..m.stage_count() {
            let block = match m.stage(s) {
                Some(Stage::Explicit { .. }) => {
                    m.fill_trig(s, q, parts.trig);
                    continue;
                }
                Some(Stage::Block(block)) => block,
                None => break,
            };
            let bs = BlockSolve { m, stage: s, block };
            bs.set_scales(&mut parts.scales, length);
            let mut newton = Newton::new(bs, &mut parts, options, t);
            let condition = match newton.factor_at(q) {
                Ok(factors) => newton.condition(factors),
                Err(error) => return record(error, m, s, newton.parts, diagnosed),
            };
            // NaN (estimate off) counts as the worst.
            if worst.is_none_or(|(_, _, c)| condition > c || condition.is_nan()) {
                worst = Some((s, block, condition));
            }
            m.fill_trig(s, q, newton.parts.trig);
        }
        // The trig cache is complete: diagnose the worst block.
        let Some((s, block, condition)) = worst else {
            return SolveError::Singular {
                time: t,
                equation: 0,
                coordinate: 0,
                condition: f64::INFINITY,
                deficiency: 0,
                names: &Names::NONE,
            };
        };
        let bs = BlockSolve { m, stage: s, block };
        bs.set_scales(&mut parts.scales, length);
        let mut newton = Newton::new(bs, &mut parts, options, t);
        let error = newton.diagnose(q, condition);
        record(error, m, s, newton.parts, diagnosed)
    }
}

/// Completes the diagnosis of a singularity found in stage `stage` (for
/// [`Solver::dependent_equations`] and [`Solver::undetermined_coordinates`]): the block's own
/// undetermined coordinates, then every later stage that reads it, directly or not.
pub(super) fn record<M: Structured>(
    error: SolveError,
    m: &M,
    stage: usize,
    parts: &mut Parts<'_>,
    diagnosed: &mut (usize, usize),
) -> SolveError
where
    DefaultAllocator: Storage<M::Dim>,
{
    let SolveError::Singular { deficiency, .. } = error else {
        return error;
    };
    let undetermined = &mut *parts.undetermined;
    let mut count = deficiency.min(undetermined.len());
    undetermined[..count].copy_from_slice(&parts.col_order[..count]);
    let downstream = &mut *parts.downstream;
    downstream.fill(false);
    for t in stage + 1..m.stage_count().min(downstream.len()) {
        let Some(later) = m.stage(t) else {
            break;
        };
        let reads = later.reads();
        if reads
            .iter()
            .any(|&r| r == stage || downstream.get(r) == Some(&true))
        {
            downstream[t] = true;
            for &c in later.coordinates() {
                if count < undetermined.len() {
                    undetermined[count] = c;
                    count += 1;
                }
            }
        }
    }
    crate::lu::sort_indices(&mut undetermined[..count]);
    *diagnosed = (deficiency, count);
    error
}
