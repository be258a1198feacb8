//! The rate solves: a stage's velocities and accelerations (explicit ones assigned, a block's
//! solved with its factors), and the sweep that solves only them at given positions.

use nalgebra::{DefaultAllocator, Dim};

use super::api::Solver;
use super::diagnosis::record;

use crate::block::{BlockSolve, Factors};
use crate::error::{Quantity, SolveError};
use crate::finite::{all_finite, check_finite, check_slice};
use crate::mechanism::{Storage, Vector};
use crate::names::Names;
use crate::options::Rates;
use crate::origin;
use crate::position::Newton;
use crate::structure::{Stage, Structured};
use crate::workspace::{Parts, Workspace};

impl<M: Structured> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Evaluates and factors every block at the given positions and solves the rates asked for
    /// ([`Solver::solve_velocity`], [`Solver::solve_acceleration`]); `q̇` is an input when only
    /// accelerations are asked for.
    pub(super) fn rate_stages(
        &mut self,
        t: f64,
        q: &Vector<M::Dim>,
        qd: &mut Vector<M::Dim>,
        qdd: &mut Vector<M::Dim>,
        rates: Rates,
    ) -> Result<(), SolveError> {
        self.check_mechanism(t)?;
        // The trig cache is refilled at these positions: the archive's solve no longer has its.
        self.factors_archived = false;
        let mut reached = 0;
        self.rate_sweep(t, q, qd, qdd, rates, &mut reached)
            .map_err(|e| origin::trace(&self.mechanism, reached, [q, qd, qdd], rates, e))
    }

    /// The stages of [`Solver::rate_stages`] in order, recording in `reached` the stage being
    /// solved.
    fn rate_sweep(
        &mut self,
        t: f64,
        q: &Vector<M::Dim>,
        qd: &mut Vector<M::Dim>,
        qdd: &mut Vector<M::Dim>,
        rates: Rates,
        reached: &mut usize,
    ) -> Result<(), SolveError> {
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
        for s in 0..m.stage_count() {
            *reached = s;
            match m.stage(s) {
                Some(Stage::Explicit { .. }) => {
                    m.fill_trig(s, q, parts.trig);
                    assign_rates(m, s, q, parts.trig, qd, qdd, t, rates);
                }
                Some(Stage::Block(block)) => {
                    let bs = BlockSolve { m, stage: s, block };
                    bs.set_scales(&mut parts.scales, length);
                    let mut newton = Newton::new(bs, &mut parts, options, t);
                    let factors = newton
                        .factor_at(q)
                        .map_err(|e| record(e, m, s, newton.parts, diagnosed))?;
                    m.fill_trig(s, q, newton.parts.trig);
                    block_rates(&newton.bs, factors, newton.parts, q, qd, qdd, t, rates)?;
                }
                None => break,
            }
        }
        *reached = m.stage_count();
        check_rates(qd, qdd, t, rates)
    }
}

/// The rates of an explicit stage's coordinates (checked at the end of the sweep).
#[allow(clippy::too_many_arguments)]
pub(super) fn assign_rates<M: Structured>(
    m: &M,
    stage: usize,
    q: &Vector<M::Dim>,
    trig: &[f64],
    qd: &mut Vector<M::Dim>,
    qdd: &mut Vector<M::Dim>,
    t: f64,
    rates: Rates,
) where
    DefaultAllocator: Storage<M::Dim>,
{
    if rates != Rates::None {
        m.assign_velocities(stage, q, trig, qd, t);
    }
    if rates >= Rates::Both {
        m.assign_accelerations(stage, q, trig, qd, qdd, t);
    }
}

/// The rates asked for are finite.
pub(super) fn check_rates<D: Dim>(
    qd: &Vector<D>,
    qdd: &Vector<D>,
    t: f64,
    rates: Rates,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<D>,
{
    if rates != Rates::None {
        check_finite(qd, t, Quantity::Velocity)?;
    }
    if rates >= Rates::Both {
        check_finite(qdd, t, Quantity::Acceleration)?;
    }
    Ok(())
}

/// A block's velocities, then accelerations, with its factors at the solved `q`.
#[allow(clippy::too_many_arguments)]
pub(super) fn block_rates<M: Structured>(
    bs: &BlockSolve<'_, M>,
    factors: Factors,
    parts: &mut Parts<'_>,
    q: &Vector<M::Dim>,
    qd: &mut Vector<M::Dim>,
    qdd: &mut Vector<M::Dim>,
    t: f64,
    rates: Rates,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    if rates == Rates::None {
        return Ok(());
    }
    let n = bs.n();
    let rhs = &mut parts.newton.trial[..n];
    bs.m.velocity_rhs(bs.stage, q, parts.trig, qd, t, rhs);
    check_rhs(bs, rhs, t, Quantity::Nu)?;
    bs.solve(factors, &parts.factors, &parts.scales, rhs);
    scatter(rhs, bs.block.coordinates, qd, t, Quantity::Velocity)?;
    if rates >= Rates::Both {
        bs.m.acceleration_rhs(bs.stage, q, parts.trig, qd, qdd, t, rhs);
        check_rhs(bs, rhs, t, Quantity::Gamma)?;
        bs.solve(factors, &parts.factors, &parts.scales, rhs);
        scatter(rhs, bs.block.coordinates, qdd, t, Quantity::Acceleration)?;
    }
    Ok(())
}

/// A block's right-hand side is finite; otherwise the error names its first non-finite row's
/// equation.
fn check_rhs<M: Structured>(
    bs: &BlockSolve<'_, M>,
    rhs: &[f64],
    t: f64,
    quantity: Quantity,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    if all_finite(rhs) {
        return Ok(());
    }
    let row = rhs.iter().position(|x| !x.is_finite());
    Err(SolveError::NonFinite {
        time: t,
        quantity,
        equation: row.and_then(|i| bs.block.equations.get(i).copied()),
        names: &Names::NONE,
    })
}

/// `v[coordinates[j]] ← x[j]`, finite.
fn scatter<D: Dim>(
    x: &[f64],
    coordinates: &[usize],
    v: &mut Vector<D>,
    t: f64,
    quantity: Quantity,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<D>,
{
    check_slice(x, t, quantity)?;
    let v = v.as_mut_slice();
    for (&x, &j) in x.iter().zip(coordinates) {
        v[j] = x;
    }
    Ok(())
}
