//! What a scene's straight kinematic step ([`crate::Structured::straight_step`]) calls: the
//! solver's settings it checks against ([`StepContext`]), what it reports back
//! ([`StepReport`]), and the safeguards of a closed-form block, each the same rule the
//! stage sweep applies to that block's Newton start; for a scene that computes forces, the
//! transposed solve of its force solve ([`StepContext::multipliers`]).
//!
//! The generated step runs every stage in the sweep's order with the scene's kernels called
//! directly. A block takes its closed-form solution nearest the guess
//! ([`StepContext::choose`], the rule of the sweep's closed-form start), its unit-scaled
//! Jacobian is factored with the static pivots under the same thresholds
//! ([`StepContext::scale_jacobian`]), and the solution must
//! pass what Newton's first iteration from it would check ([`StepContext::accept`]): a
//! residual within the tolerances, a Newton correction within the step tolerance (so the
//! sweep would stop there), and the condition limit; the whole solution passes the sweep's end
//! checks ([`StepContext::check_rounding`], [`StepContext::check_end`]). Any check that fails
//! makes the step return `Err(stage)`; the solver then runs the stage sweep from the original guess, whose
//! answers and errors are unchanged.

use nalgebra::DefaultAllocator;

use crate::acceptance::COEFFICIENT_ROOM;
use crate::block::{SCALE_FLOOR, bounded_condition, exact_inverse_norm};
use crate::block_signs::block_code;
use crate::finite::all_finite;
use crate::mechanism::{Storage, Unit, Vector};
use crate::position::nearest;
use crate::step::{BlockScales, StepContext, StepReport};
use crate::structure::Structured;

impl StepContext {
    /// The sweep's end checks at the step's solution `q`: every rate finite, every branch
    /// invariant of `m` positive (read from the filled trig cache `trig`). `rates` are the
    /// rates the explicit stages computed (constants left out); the blocks' were checked by
    /// [`StepContext::rates`], the positions by [`StepContext::check_rounding`].
    ///
    /// # Errors
    /// `stage` (the stage count) where one fails: the sweep reports it.
    pub fn check_end<M: Structured>(
        &self,
        stage: usize,
        m: &M,
        q: &Vector<M::Dim>,
        rates: &[f64],
        trig: &[f64],
    ) -> Result<(), usize>
    where
        DefaultAllocator: Storage<M::Dim>,
    {
        let finite = all_finite(rates);
        // NaN is not positive either.
        let branches = (0..m.branch_count()).all(|b| m.branch(b, q, trig) > 0.0);
        if finite && branches {
            Ok(())
        } else {
            Err(stage)
        }
    }

    /// The closed-form solution of block `stage` at `guess` that the sweep would start Newton
    /// from: of the two `candidates` (the generated code's layout, see
    /// [`Structured::closed_form`]), the nearest, with its angles (`angles[j]`) moved to the
    /// guess's turn, trying first the candidate the last step took; recorded in `report`.
    /// `None` where the sweep would start from the guess itself (near a toggle, a guess
    /// between the solutions, a loop that cannot close, or `candidates` not `4 N` long).
    // Inlined so that the block's constant `angles` fold away.
    #[inline(always)]
    pub fn choose<const N: usize, const C: usize>(
        &self,
        stage: usize,
        guess: [f64; N],
        candidates: &[f64; C],
        angles: [bool; N],
        scales: &BlockScales<N>,
        report: &mut StepReport,
    ) -> Option<Choice<N>> {
        if C != 4 * N {
            return None;
        }
        let mut units = [[[0.0; 2]; N]; 2];
        for (unit, &value) in units
            .as_flattened_mut()
            .as_flattened_mut()
            .iter_mut()
            .zip(candidates)
        {
            *unit = value;
        }
        let bit = 1 << (stage % 64);
        let first = usize::from(self.choices & bit != 0);
        let (chosen, values) = nearest(&guess, &units, &angles, &scales.inverse_cols, first)?;
        if chosen == 1 {
            report.choices |= bit;
        }
        Some(Choice {
            values,
            units: units[chosen],
            angles,
        })
    }

    /// The unit scales of a block with these equation and coordinate units.
    #[inline]
    pub fn scales<const N: usize>(
        &self,
        equations: [Unit; N],
        coordinates: [Unit; N],
    ) -> BlockScales<N> {
        BlockScales {
            rows: equations.map(|u| self.length.inverse_of(u)),
            cols: coordinates.map(|u| self.length.of(u)),
            inverse_cols: coordinates.map(|u| self.length.inverse_of(u)),
        }
    }

    /// Scales the block Jacobian's `values` (entries at `pattern`, (row, column)) to
    /// `S = D_r J D_c` and returns the static pivots' `tiny` (as the sweep's factorisation
    /// computes it) and `‖S‖₁`.
    ///
    /// # Errors
    /// `stage` for a non-finite entry.
    #[inline]
    pub fn scale_jacobian<const N: usize, const S: usize>(
        &self,
        stage: usize,
        values: &mut [f64; S],
        pattern: &[(usize, usize); S],
        scales: &BlockScales<N>,
    ) -> Result<(f64, f64), usize> {
        let (mut largest, mut sums, mut finite) = (0.0_f64, [0.0; N], true);
        for (value, &(i, j)) in values.iter_mut().zip(pattern) {
            *value *= scales.rows[i] * scales.cols[j];
            let magnitude = value.abs();
            // NaN fails this test (and `max` would drop it).
            finite &= magnitude <= f64::MAX;
            largest = largest.max(magnitude);
            sums[j] += magnitude;
        }
        if !finite {
            return Err(stage);
        }
        let tiny = self.pivot_tolerance * N as f64 * largest.max(SCALE_FLOOR);
        Ok((tiny, sums.iter().fold(0.0_f64, |m, &s| m.max(s))))
    }

    /// The static pivots' multiplier limit.
    #[inline]
    pub fn limit(&self) -> f64 {
        self.limit
    }

    /// The checks at a block's closed-form solution `chosen`, whose unscaled residual is `phi`
    /// and whose scaled Jacobian has static factors with pivots `pivots` (values of the
    /// factored slots) and norm `norm1`; `solve` is `x ← S⁻¹ x` with those factors. Passes
    /// where Newton from `chosen` would stop at its first iteration (residual within
    /// `residual_tolerance` and the acceptance tolerance, correction within
    /// `step_tolerance`), and the condition estimate is within `max_condition`; records the
    /// block in `report`.
    ///
    /// # Errors
    /// `stage` when a check fails.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn accept<const N: usize>(
        &self,
        stage: usize,
        phi: &[f64; N],
        chosen: &[f64; N],
        scales: &BlockScales<N>,
        pivots: &[f64],
        norm1: f64,
        mut solve: impl FnMut(&mut [f64; N]),
        report: &mut StepReport,
    ) -> Result<(), usize> {
        let magnitude = scaled_max(chosen, &scales.inverse_cols).max(1.0);
        let mut step = [0.0; N];
        for ((s, &p), &r) in step.iter_mut().zip(phi).zip(&scales.rows) {
            *s = p * r;
        }
        let residual = step.iter().fold(0.0_f64, |m, s| larger(m, s.abs()));
        let small = residual <= self.residual_tolerance * magnitude && residual <= self.acceptance;
        // The Newton correction S⁻¹ D_r Φ is D_c⁻¹ Δq: in scene lengths and radians already.
        solve(&mut step);
        let length = step.iter().fold(0.0_f64, |m, s| larger(m, s.abs()));
        if !(small && length <= self.step_tolerance * magnitude) {
            return Err(stage);
        }
        let condition = if self.estimate_condition {
            let mut x = [0.0; N];
            let inverse_norm = exact_inverse_norm(&mut x, |x| {
                if let Some(x) = x.first_chunk_mut::<N>() {
                    solve(x);
                }
            });
            let condition = bounded_condition(inverse_norm, norm1);
            if condition.is_nan() || condition > self.max_condition {
                return Err(stage);
            }
            larger(report.condition, condition)
        } else {
            f64::NAN
        };
        let negative = pivots.iter().fold(false, |n, &p| n ^ (p < 0.0));
        if negative {
            report.orientation = -report.orientation;
            report.block_signs ^= block_code(stage);
        }
        report.condition = condition;
        report.residual = report
            .residual
            .max(phi.iter().fold(0.0_f64, |m, p| m.max(p.abs())));
        report.blocks += 1;
        Ok(())
    }

    /// A block's rates from its right-hand side `rhs` (unscaled, row order): `J⁻¹ rhs`, with
    /// `solve` (`x ← S⁻¹ x`) of the block's factors.
    ///
    /// # Errors
    /// `stage` for a non-finite right-hand side or rate.
    #[inline]
    pub fn rates<const N: usize>(
        &self,
        stage: usize,
        rhs: &[f64; N],
        scales: &BlockScales<N>,
        solve: impl FnOnce(&mut [f64; N]),
    ) -> Result<[f64; N], usize> {
        let mut x = [0.0; N];
        for ((x, &b), &r) in x.iter_mut().zip(rhs).zip(&scales.rows) {
            *x = b * r;
        }
        solve(&mut x);
        for (x, &c) in x.iter_mut().zip(&scales.cols) {
            *x *= c;
        }
        if x.iter().all(|x| x.is_finite()) {
            Ok(x)
        } else {
            Err(stage)
        }
    }

    /// A block's multipliers from its force right-hand side `rhs` (unscaled, column order):
    /// `J⁻ᵀ rhs`, with `solve_transpose` (`x ← S⁻ᵀ x`) of the block's factors, as the runtime's
    /// force solve computes them (its one finiteness check, on the reactions, follows).
    #[inline]
    pub fn multipliers<const N: usize>(
        &self,
        rhs: &[f64; N],
        scales: &BlockScales<N>,
        solve_transpose: impl FnOnce(&mut [f64; N]),
    ) -> [f64; N] {
        let mut x = [0.0; N];
        for ((x, &b), &c) in x.iter_mut().zip(rhs).zip(&scales.cols) {
            *x = b * c;
        }
        solve_transpose(&mut x);
        for (x, &r) in x.iter_mut().zip(&scales.rows) {
            *x *= r;
        }
        x
    }

    /// Whether explicit assignments can be accepted unevaluated at the step's positions (the
    /// sweep's rounding bound, see [`crate::acceptance`]): every scaled coordinate below it.
    /// Above, the sweep's evaluation of the explicit residuals decides. `lengths` and `angles`
    /// are the coordinates of each unit (those assigned a constant 0 left out).
    ///
    /// # Errors
    /// `stage` above the bound (or for a non-finite coordinate).
    #[inline]
    pub fn check_rounding(
        &self,
        stage: usize,
        lengths: &[f64],
        angles: &[f64],
    ) -> Result<(), usize> {
        let bound = self.acceptance / (f64::EPSILON * COEFFICIENT_ROOM);
        // The length scale is a power of two: `|x| L⁻¹ ≤ bound` exactly where `|x| ≤ bound L`.
        // NaN fails the comparison; no branch per coordinate.
        let within = |v: &[f64], bound: f64| v.iter().fold(true, |ok, x| ok & (x.abs() <= bound));
        if within(lengths, bound * self.length.of(Unit::Length)) & within(angles, bound) {
            Ok(())
        } else {
            Err(stage)
        }
    }
}

/// A block's chosen closed-form solution.
#[derive(Debug, Clone, Copy)]
pub struct Choice<const N: usize> {
    /// The block's coordinates.
    pub values: [f64; N],
    /// Per coordinate, an angle's cosine and sine as the intersection gave them.
    units: [[f64; 2]; N],
    /// Which coordinates are angles.
    angles: [bool; N],
}

impl<const N: usize> Choice<N> {
    /// The cosine and sine of each angle where the intersection gave them on the unit circle
    /// to within rounding (a few units in the last place), so that they can fill the trig
    /// cache in place of a `sin_cos` of the angle; `None` otherwise.
    #[inline]
    pub fn units(&self) -> Option<[[f64; 2]; N]> {
        let on_circle = self
            .units
            .iter()
            .zip(self.angles)
            .all(|(&[cos, sin], angle)| {
                !angle || (cos * cos + sin * sin - 1.0).abs() <= UNIT_ROUNDING
            });
        on_circle.then_some(self.units)
    }
}

/// How far from 1 the squared length of an intersection's unit vector may be for its cosine
/// and sine to stand for the angle's: a few roundings.
const UNIT_ROUNDING: f64 = 8.0 * f64::EPSILON;

/// `max |v_j c_j|`, NaN winning.
fn scaled_max<const N: usize>(v: &[f64; N], c: &[f64; N]) -> f64 {
    v.iter()
        .zip(c)
        .fold(0.0, |m, (x, c)| larger(m, (x * c).abs()))
}

/// The larger of two values, NaN winning.
fn larger(a: f64, b: f64) -> f64 {
    if b > a || b.is_nan() { b } else { a }
}
