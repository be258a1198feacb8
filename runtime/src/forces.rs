//! The force solve (inverse dynamics): with the motion solved, the reactions of the
//! constraints and the efforts of the drivers balance the applied and inertial forces,
//! `Φ_qᵀ λ = F(q, q̇, q̈, t)`: one more linear solve, with the Jacobian of the step.
//!
//! Φ_q is block lower triangular in the scene's stage order (a stage's equations read only its
//! own and earlier coordinates), so Φ_qᵀ is block upper triangular and the stages are solved
//! in reverse. A stage's coordinates are touched only by its own equations and by later
//! stages', whose multipliers are known by then: an explicit stage gives its multipliers in
//! closed form ([`Structured::assign_multipliers`]), and a block solves
//! `Φ_q[b, b]ᵀ λ_b = F_b − Φ_q[later, b]ᵀ λ_later` ([`Structured::force_rhs`]) with the static
//! factors its Newton iteration ended with, which the forward sweep archived ([`archive`]). A
//! block without archived factors (partial pivoting after a static pivot failed, or the dense
//! reference) is factored once more at the solution. The multipliers then become the reported
//! reactions ([`crate::Mechanism::reactions`]). This is the stage sweep's force solve; a scene
//! with a straight step runs the same passes as its generated code, over an archive of the
//! same layout ([`Structured::straight_step`]).

use nalgebra::DefaultAllocator;

use crate::block::{BlockSolve, Factors};
use crate::error::{Quantity, SolveError};
use crate::finite::{all_finite, check_finite, non_finite};
use crate::mechanism::{LengthScale, Storage, Vector};
use crate::names::Names;
use crate::options::SolverOptions;
use crate::position::Newton;
use crate::structure::{Stage, Structured};
use crate::workspace::Parts;

/// Keeps a copy of block `bs`'s static factors (valid at the solved positions) for the force
/// solve, after the multipliers (`n` of them) and the `filled` values archived before it;
/// returns the archive's new length. Partial-pivoting factors are not kept: the force solve
/// factors such a block again.
pub(crate) fn archive<M: Structured>(
    bs: &BlockSolve<'_, M>,
    factors: Factors,
    parts: &mut Parts<'_>,
    n: usize,
    filled: usize,
) -> usize
where
    DefaultAllocator: Storage<M::Dim>,
{
    let slots = bs.block.slots;
    let start = n + filled;
    let target = parts.forces.get_mut(start..start + slots);
    let kept = match (factors, target) {
        (Factors::Static { .. }, Some(target)) => {
            target.copy_from_slice(&parts.factors.values[..slots]);
            true
        }
        _ => false,
    };
    if let Some(flag) = parts.archived.get_mut(bs.stage) {
        *flag = kept;
    }
    filled + slots
}

/// The motion the forces are solved for.
pub(crate) struct Motion<'v, M: Structured>
where
    DefaultAllocator: Storage<M::Dim>,
{
    pub t: f64,
    pub q: &'v Vector<M::Dim>,
    pub qd: &'v Vector<M::Dim>,
    pub qdd: &'v Vector<M::Dim>,
}

/// Solves `Φ_qᵀ λ = F` stage by stage in reverse and writes the reported reactions into
/// `reactions`. `archived` is the archive's length after the forward sweep.
///
/// # Errors
/// [`SolveError::NonFinite`] for a non-finite F ([`Quantity::Load`]) or multiplier
/// ([`Quantity::Reaction`], naming the first equation), or the error of factoring a block
/// again.
pub(crate) fn solve<M: Structured>(
    m: &M,
    parts: &mut Parts<'_>,
    options: &SolverOptions,
    length: &LengthScale,
    motion: &Motion<'_, M>,
    archived: usize,
    reactions: &mut Vector<M::Dim>,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    let n = motion.q.len();
    // The multipliers and the archive are borrowed apart from the rest of the workspace, which
    // a block's refactorisation needs.
    let storage = core::mem::take(&mut parts.forces);
    // The generated workspace sizes the storage for the multipliers and the archive.
    debug_assert!(
        storage.len() >= n,
        "force storage shorter than the multipliers"
    );
    let result = match storage.len().checked_sub(n) {
        Some(_) => {
            let (lambda, archive) = storage.split_at_mut(n);
            let solved = reverse(m, parts, options, length, motion, lambda, archive, archived);
            solved.and_then(|()| {
                m.reactions(motion.q, motion.qd, lambda, reactions);
                // The reactions are finite exactly when the multipliers are (and F, which
                // the springs' pull on the frame shares): one check serves both.
                check_finite(reactions, motion.t, Quantity::Reaction)
                    .map_err(|_| non_finite_multiplier(m, lambda, motion.t))
            })
        }
        None => Err(non_finite(motion.t, Quantity::Reaction)),
    };
    parts.forces = storage;
    result.map_err(|error| blame_loads(m, motion, reactions, error))
}

/// A non-finite multiplier most often comes from a non-finite F (a load's expression, a
/// spring whose ends meet), which the stages' kernels fold in without a check of their own:
/// only on this failure path is F evaluated whole (into `scratch`), and the error then names
/// the load and the cause ([`crate::Mechanism::load_fault`]), or F as a whole (the inertia of
/// the masses).
fn blame_loads<M: Structured>(
    m: &M,
    motion: &Motion<'_, M>,
    scratch: &mut Vector<M::Dim>,
    error: SolveError,
) -> SolveError
where
    DefaultAllocator: Storage<M::Dim>,
{
    if !matches!(error, SolveError::NonFinite { .. }) {
        return error;
    }
    m.generalized_forces(motion.q, motion.qd, motion.qdd, motion.t, scratch);
    if all_finite(scratch.as_slice()) {
        error
    } else {
        let load = m.load_fault(motion.q, motion.qd, motion.t);
        non_finite(motion.t, load.unwrap_or(Quantity::Load))
    }
}

/// The stages in reverse: each explicit stage's multipliers in closed form, each block's by a
/// transposed solve. Finiteness is checked once, on the reactions (a NaN propagates into every
/// multiplier that reads it); only a failure looks for where it began.
#[allow(clippy::too_many_arguments)]
fn reverse<M: Structured>(
    m: &M,
    parts: &mut Parts<'_>,
    options: &SolverOptions,
    length: &LengthScale,
    motion: &Motion<'_, M>,
    lambda: &mut [f64],
    archive: &[f64],
    mut end: usize,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    let Motion { t, q, qd, qdd } = *motion;
    for s in (0..m.stage_count()).rev() {
        match m.stage(s) {
            Some(Stage::Explicit { .. }) => {
                m.assign_multipliers(s, q, parts.trig, qd, qdd, lambda, t);
            }
            Some(Stage::Block(block)) => {
                let bs = BlockSolve { m, stage: s, block };
                let slots = block.slots;
                end = end.saturating_sub(slots);
                bs.set_scales(&mut parts.scales, length);
                let stored =
                    parts.archived.get(s).copied().unwrap_or(false) && archive.len() >= end + slots;
                let factors = if stored {
                    None
                } else {
                    let again = BlockSolve { m, stage: s, block };
                    Some(Newton::new(again, parts, options, t).factor_at(q)?)
                };
                let rhs = &mut parts.newton.trial[..block.len()];
                m.force_rhs(s, q, parts.trig, qd, qdd, lambda, t, rhs);
                match factors {
                    None => {
                        bs.solve_transpose_static(&archive[end..end + slots], &parts.scales, rhs)
                    }
                    Some(factors) => {
                        bs.solve_transpose(factors, &parts.factors, &parts.scales, rhs)
                    }
                }
                for (&x, &e) in rhs.iter().zip(block.equations) {
                    if let Some(l) = lambda.get_mut(e) {
                        *l = x;
                    }
                }
            }
            None => break,
        }
    }
    Ok(())
}

/// The error for non-finite multipliers: the first stage's, in reverse solve order (where the
/// NaN began), naming its first such equation.
fn non_finite_multiplier<M: Structured>(m: &M, lambda: &[f64], t: f64) -> SolveError
where
    DefaultAllocator: Storage<M::Dim>,
{
    let first = (0..m.stage_count()).rev().find_map(|s| {
        let equations = match m.stage(s)? {
            Stage::Explicit { equations, .. } => equations,
            Stage::Block(block) => block.equations,
        };
        equations
            .iter()
            .copied()
            .find(|&e| !lambda.get(e).is_some_and(|l| l.is_finite()))
    });
    SolveError::NonFinite {
        time: t,
        quantity: Quantity::Reaction,
        equation: first,
        names: &Names::NONE,
    }
}
