//! Acceptance of the stages solved in closed form: an explicit assignment's result passes the
//! absolute acceptance rule Newton blocks obey (scaled residual within `acceptance_tolerance`),
//! or the solve fails with [`SolveError::Unresolved`] naming the equation.
//!
//! An assignment `q_c = −g/a` of an equation `a q_c + g = 0` (constant `a`) is exact up to the
//! rounding of the values it combines: its evaluated residual is a few ulps of its largest
//! term. Unit scaling keeps the coefficients of those terms of order one (lengths are at most
//! the scene's length scale, gear and rack ratios are modest), so the terms are within a small
//! factor of the coordinates involved, and the residual within [`COEFFICIENT_ROOM`] · ε times
//! the largest scaled coordinate solved so far. While that bound is below the acceptance
//! tolerance (coordinates below ~4e4 scene lengths and radians, the usual case) nothing is
//! evaluated: the hot path pays one comparison per coordinate. Above it (a weld on an arm
//! driven to 1e12 rad, whose 30° is rounded to 4e-5 rad), Φ is evaluated once at the end of
//! the sweep and every explicit equation is held to the acceptance tolerance.
//!
//! The same look at each solved coordinate tells the sweep whether all of them are finite.

use nalgebra::DefaultAllocator;

use crate::error::SolveError;
use crate::mechanism::{LengthScale, Storage, Vector};
use crate::structure::{Stage, Structured};

/// How far the terms of an explicit equation may exceed the largest coordinate it reads or
/// assigns (scaled), for rounding to stay within ε times this much of that coordinate.
pub(crate) const COEFFICIENT_ROOM: f64 = 1024.0;

/// What a sweep has solved, for deciding whether its explicit stages need their residuals
/// evaluated, and whether every coordinate it solved is finite.
///
/// Both need a look at each solved coordinate; the unit lookup that scales it is skipped for
/// the usual one, whose unscaled size is within `bound` over the largest unit scale (no unit
/// can then scale it past `bound`). A non-finite value fails that comparison too, so both
/// tests cost one comparison per coordinate on the hot path.
pub(crate) struct Rounding {
    /// Largest scaled coordinate below which no explicit residual can reach the tolerance.
    bound: f64,
    /// `bound` over the largest unit scale.
    threshold: f64,
    /// Whether a coordinate solved so far is above `bound` (scaled).
    exceeded: bool,
    /// Whether an explicit stage was assigned after a coordinate above `bound` was solved.
    pending: bool,
    /// Whether every coordinate solved so far is finite.
    finite: bool,
}

impl Rounding {
    /// A sweep accepting scaled residuals up to `acceptance`, with the scene's `length`.
    pub(crate) fn new(acceptance: f64, length: &LengthScale) -> Self {
        let bound = acceptance / (f64::EPSILON * COEFFICIENT_ROOM);
        Self {
            bound,
            threshold: bound / length.largest_inverse(),
            exceeded: false,
            pending: false,
            finite: true,
        }
    }

    /// Records the solved `value` of a coordinate whose scale (L⁻ᵖ) `scale` gives, looked up
    /// only when the value is beyond the threshold or not finite.
    #[inline]
    fn solved(&mut self, value: f64, scale: impl FnOnce() -> f64) {
        let value = value.abs();
        // False for NaN too.
        if value <= self.threshold {
            return;
        }
        self.finite &= value <= f64::MAX;
        self.exceeded |= value * scale() > self.bound;
    }

    /// A block's coordinates, with their scales `inverse_cols` (its own acceptance is
    /// checked by its Newton iteration): an explicit stage reading them later inherits their
    /// size.
    pub(crate) fn block<M: Structured>(
        &mut self,
        coordinates: &[usize],
        inverse_cols: &[f64],
        q: &Vector<M::Dim>,
    ) where
        DefaultAllocator: Storage<M::Dim>,
    {
        let q = q.as_slice();
        for (&j, &c) in coordinates.iter().zip(inverse_cols) {
            self.solved(q[j], || c);
        }
    }

    /// An explicit stage just assigned its `coordinates`.
    pub(crate) fn explicit<M: Structured>(
        &mut self,
        m: &M,
        coordinates: &[usize],
        q: &Vector<M::Dim>,
        length: &LengthScale,
    ) where
        DefaultAllocator: Storage<M::Dim>,
    {
        let q = q.as_slice();
        for &j in coordinates {
            self.solved(q[j], || length.inverse_of(m.coordinate_unit(j)));
        }
        self.pending |= self.exceeded;
    }

    /// Whether an explicit stage's residuals must be evaluated.
    pub(crate) fn pending(&self) -> bool {
        self.pending
    }

    /// Whether every coordinate recorded is finite.
    pub(crate) fn finite(&self) -> bool {
        self.finite
    }
}

/// Holds every explicit equation to the acceptance tolerance at the solved `q`: Φ is evaluated
/// once, and the largest scaled residual of an explicit stage's equation is compared with
/// `acceptance`. Returns the largest unscaled explicit residual (for the solve's report).
///
/// # Errors
/// [`SolveError::Unresolved`] naming the equation with the largest scaled residual, with the
/// unscaled ‖Φ‖∞ of its stage's equations.
pub(crate) fn check_explicit<M: Structured>(
    m: &M,
    q: &Vector<M::Dim>,
    t: f64,
    length: &LengthScale,
    acceptance: f64,
) -> Result<f64, SolveError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    let mut phi = q.clone();
    m.phi(q, t, &mut phi);
    let phi = phi.as_slice();
    let mut largest = 0.0_f64;
    for s in 0..m.stage_count() {
        let Some(Stage::Explicit { equations, .. }) = m.stage(s) else {
            continue;
        };
        // (equation, scaled residual) of the stage's worst equation, and its ‖Φ‖∞.
        let (mut worst, mut stage_max) = ((0, 0.0_f64), 0.0_f64);
        for &e in equations {
            let value = phi.get(e).copied().unwrap_or(f64::NAN);
            let scaled = (value * length.inverse_of(m.equation_unit(e))).abs();
            if scaled > worst.1 || scaled.is_nan() {
                worst = (e, scaled);
            }
            stage_max = larger(stage_max, value.abs());
        }
        // NaN is not within the tolerance either.
        if worst.1 > acceptance || worst.1.is_nan() {
            return Err(SolveError::Unresolved {
                time: t,
                iterations: 0,
                residual: stage_max,
                equation: worst.0,
                names: &crate::Names::NONE,
            });
        }
        largest = largest.max(stage_max);
    }
    Ok(largest)
}

/// The larger of two values, NaN winning (a NaN must not hide behind a finite maximum).
fn larger(a: f64, b: f64) -> f64 {
    if b > a || b.is_nan() { b } else { a }
}
