//! The velocity solve at the positions of the last full solve, over the block factors that
//! solve archived for its force solve: no block is evaluated or factored again.
//!
//! The integrator asks for `q̇` at the state it has just solved, with only the free degrees of
//! freedom's rates changed (one column of `V = ∂q/∂u` per free degree of freedom): the
//! Jacobian, and so every block's factors, is the one the full solve ended with. Refactoring
//! it was a third of a step's block Jacobians and factorisations, and at 1000 scissor stages
//! a pass of the scene's whole Jacobian code through the caches. Solving with the very factors
//! the state's own `q̇` was solved with also makes `q̇(u̇ + δ) − q̇(u̇)` exactly linear in `δ`.
//!
//! A scene with a straight step solves them by its generated `straight_velocities` (the
//! stages' kernels called directly), others stage by stage here. Where it cannot (no archive
//! at these positions, a block the archive lacks after a partial-pivoting fallback, a
//! non-finite value on the way), it declines and the caller runs the refactoring solve, which
//! also names any error.

use nalgebra::DefaultAllocator;

use super::api::Solver;

use crate::block::BlockSolve;
use crate::finite::all_finite;
use crate::mechanism::{Storage, Vector, Velocities};
use crate::structure::{Stage, Structured};
use crate::workspace::Workspace;

/// Why the archived solve declined (the refactoring solve then runs).
pub(super) struct Declined;

impl<M: Structured + Velocities> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// [`Solver::solve_velocity`] at `q`, which must be the positions of this solver's last
    /// [`Solver::solve_into`] with no parameter changed since but the free degrees of
    /// freedom's rates: over that solve's archived factors where it left them (a scene that
    /// computes forces), otherwise by the refactoring solve.
    ///
    /// # Errors
    /// As [`Solver::solve_velocity`].
    pub(crate) fn solve_velocity_again(
        &mut self,
        q: &Vector<M::Dim>,
        t: f64,
        qd: &mut Vector<M::Dim>,
    ) -> Result<(), crate::SolveError> {
        if self.factors_archived
            && (self.straight_velocities(q, t, qd) || self.archived_velocities(q, t, qd).is_ok())
        {
            return Ok(());
        }
        self.solve_velocity(q, t, qd)
    }

    /// The scene's generated [`Structured::straight_velocities`] where every block's factors
    /// are archived; whether it solved them all, finite.
    fn straight_velocities(&mut self, q: &Vector<M::Dim>, t: f64, qd: &mut Vector<M::Dim>) -> bool {
        let parts = self.workspace.step_parts();
        parts.archived.iter().all(|&kept| kept)
            && self
                .mechanism
                .straight_velocities(t, q, parts.trig, qd, parts.forces, &self.context)
                .is_ok()
            && all_finite(qd.as_slice())
    }

    /// The stages in order: explicit ones assigned, each block's right-hand side solved with
    /// its archived static factors (the trig cache is the last solve's, at these positions).
    fn archived_velocities(
        &mut self,
        q: &Vector<M::Dim>,
        t: f64,
        qd: &mut Vector<M::Dim>,
    ) -> Result<(), Declined> {
        let Self {
            mechanism: m,
            workspace,
            length,
            ..
        } = self;
        let mut parts = workspace.parts();
        let archive = parts.forces.get(q.len()..).ok_or(Declined)?;
        let mut start = 0;
        for s in 0..m.stage_count() {
            match m.stage(s) {
                Some(Stage::Explicit { .. }) => m.assign_velocities(s, q, parts.trig, qd, t),
                Some(Stage::Block(block)) => {
                    let slots = block.slots;
                    let values = archive.get(start..start + slots).ok_or(Declined)?;
                    start += slots;
                    if !parts.archived.get(s).copied().unwrap_or(false) {
                        return Err(Declined);
                    }
                    let bs = BlockSolve { m, stage: s, block };
                    bs.set_scales(&mut parts.scales, length);
                    let rhs = &mut parts.newton.trial[..block.len()];
                    m.velocity_rhs(s, q, parts.trig, qd, t, rhs);
                    bs.solve_static(values, &parts.scales, rhs);
                    if !all_finite(rhs) {
                        return Err(Declined);
                    }
                    let qd = qd.as_mut_slice();
                    for (&x, &j) in rhs.iter().zip(block.coordinates) {
                        qd[j] = x;
                    }
                }
                None => break,
            }
        }
        if all_finite(qd.as_slice()) {
            Ok(())
        } else {
            Err(Declined)
        }
    }
}
