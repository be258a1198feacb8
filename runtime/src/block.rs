//! One block's linear algebra: the unit-scaled block Jacobian factored with the scene's static
//! pivot order, or with partial pivoting when a static pivot is too small (the fallback); solves
//! with either; the condition estimate; the rank-revealing diagnosis.
//!
//! Scaling (`S = D_r J D_c`, see [`crate::Unit`]) happens here, on the values the scene's
//! kernel writes; the kernels factor and solve `S`, and [`BlockSolve::solve`] returns the
//! solution for the unscaled `J`.
//!
//! A block is judged against the whole unit-scaled Jacobian, not on its own: that Jacobian has
//! entries of 1 (a coordinate's own ±1 in a pin, a ground or a driver equation), so its norm is
//! at least 1. The pivot test, the rank reveal and the condition estimate use
//! `max(1, ‖S_b‖)` as the block's scale ([`SCALE_FLOOR`]). Without the floor, a one-equation
//! block would always have condition 1, however small its one entry: a slider-crank's rod angle
//! near its toggle would look perfectly conditioned. With it, `max(1, ‖S_b‖₁) ‖S_b⁻¹‖₁` is a
//! lower bound of κ₁ of the whole scaled Jacobian (whose inverse has `S_b⁻¹` as a diagonal
//! block), so no singularity the dense estimate caught escapes the block estimate.

use nalgebra::DefaultAllocator;

use crate::lu::{self, LuError};
use crate::mechanism::{LengthScale, Storage, Unit, Vector};
use crate::options::SolverOptions;
use crate::structure::{Block, Pattern, Structured};
use crate::workspace::{Estimator, FactorStorage, Scales, ScalesOf};

/// The scale below which a block's entries count as small: the unit-scaled Jacobian's own.
pub(crate) const SCALE_FLOOR: f64 = 1.0;

/// Blocks up to this size get their exact condition number: n solves cost less than the
/// estimator's iteration for them.
const EXACT_CONDITION: usize = 4;

/// Which factors of the current block are in the storage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Factors {
    /// The scene's static-pivot factors, in the value slots.
    Static {
        /// `‖S‖₁`.
        norm1: f64,
    },
    /// Partial-pivoting factors in the dense buffer.
    Dense {
        /// `‖S‖₁`.
        norm1: f64,
        /// A static order exists, but one of its pivots failed the threshold test.
        fallback: bool,
    },
}

impl Factors {
    /// Whether these factors replaced failed static ones.
    pub(crate) fn fell_back(self) -> bool {
        matches!(self, Factors::Dense { fallback: true, .. })
    }

    fn norm1(self) -> f64 {
        match self {
            Factors::Static { norm1 } | Factors::Dense { norm1, .. } => norm1,
        }
    }
}

/// A block of a structured scene, at its stage.
pub(crate) struct BlockSolve<'m, M> {
    pub m: &'m M,
    pub stage: usize,
    pub block: Block<'m>,
}

impl<M: Structured> BlockSolve<'_, M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Number of equations (= coordinates).
    pub fn n(&self) -> usize {
        self.block.len()
    }

    /// Writes D_r (L⁻ᵖ per equation), D_c (Lᵖ per coordinate) and D_c⁻¹ for the block,
    /// unless `scales` hold them already (units are the scene's: only the block and the
    /// length scale can change them).
    pub fn set_scales(&self, scales: &mut Scales<'_>, length: &LengthScale) {
        let of = ScalesOf(Some((self.stage, length.of(Unit::Length))));
        if *scales.of == of {
            return;
        }
        for (r, &e) in scales.rows.iter_mut().zip(self.block.equations) {
            *r = length.inverse_of(self.m.equation_unit(e));
        }
        let cols = scales.cols.iter_mut().zip(scales.inverse_cols.iter_mut());
        for ((c, inverse), &j) in cols.zip(self.block.coordinates) {
            let unit = self.m.coordinate_unit(j);
            (*c, *inverse) = (length.of(unit), length.inverse_of(unit));
        }
        *scales.of = of;
    }

    /// Evaluates Φ_b into `phi` and the scaled Jacobian `S` into `values`; returns
    /// `(max|s_ij|, ‖S‖₁)`. `sums` is n-long scratch for the column sums.
    ///
    /// # Errors
    /// [`LuError::NonFinite`] for a NaN or infinite Jacobian entry.
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate(
        &self,
        q: &Vector<M::Dim>,
        trig: &[f64],
        t: f64,
        phi: &mut [f64],
        values: &mut [f64],
        scales: &Scales<'_>,
        sums: &mut [f64],
    ) -> Result<(f64, f64), LuError> {
        let (n, slots) = (self.n(), self.block.slots);
        self.m
            .block_jacobian(self.stage, q, trig, t, &mut phi[..n], &mut values[..slots]);
        let sums = &mut sums[..n];
        sums.fill(0.0);
        let (mut largest, mut finite) = (0.0_f64, true);
        let mut scale_entry = |value: &mut f64, i: usize, j: usize, sums: &mut [f64]| {
            let s = *value * scales.rows[i] * scales.cols[j];
            *value = s;
            let magnitude = s.abs();
            finite &= magnitude <= f64::MAX;
            largest = if magnitude > largest {
                magnitude
            } else {
                largest
            };
            sums[j] += magnitude;
        };
        match self.block.pattern {
            Pattern::Sparse(entries) => {
                for (value, &(i, j)) in values.iter_mut().zip(entries) {
                    scale_entry(value, i, j, sums);
                }
            }
            Pattern::Dense => {
                for (j, column) in values[..n * n].chunks_exact_mut(n.max(1)).enumerate() {
                    for (i, value) in column.iter_mut().enumerate() {
                        scale_entry(value, i, j, sums);
                    }
                }
            }
        }
        if !finite {
            return Err(LuError::NonFinite);
        }
        let norm1 = sums.iter().fold(0.0_f64, |m, &s| m.max(s));
        Ok((largest, norm1))
    }

    /// Evaluates the block at `q` (into scratch `phi` and `values`) and returns the first of
    /// its equations with a non-finite value or Jacobian entry: what a `NonFinite` error names.
    pub fn non_finite_equation(
        &self,
        q: &Vector<M::Dim>,
        trig: &[f64],
        t: f64,
        phi: &mut [f64],
        values: &mut [f64],
    ) -> Option<usize> {
        let (n, slots) = (self.n(), self.block.slots);
        let (phi, values) = (&mut phi[..n], &mut values[..slots]);
        self.m.block_jacobian(self.stage, q, trig, t, phi, values);
        let bad = |x: &f64| !x.is_finite();
        let row = phi
            .iter()
            .position(bad)
            .or_else(|| match self.block.pattern {
                Pattern::Sparse(entries) => {
                    let k = values[..entries.len()].iter().position(bad)?;
                    Some(entries[k].0)
                }
                Pattern::Dense => Some(values[..n * n].iter().position(bad)? % n.max(1)),
            })?;
        self.block.equations.get(row).copied()
    }

    /// Evaluates at `q` and factors the scaled block Jacobian: with the static pivot order
    /// while every pivot passes its test, otherwise with partial pivoting.
    ///
    /// # Errors
    /// [`LuError::NonFinite`] for a non-finite entry, [`LuError::Singular`] (local indices) when
    /// partial pivoting finds no usable pivot.
    #[allow(clippy::too_many_arguments)]
    pub fn factor(
        &self,
        q: &Vector<M::Dim>,
        trig: &[f64],
        t: f64,
        phi: &mut [f64],
        storage: &mut FactorStorage<'_>,
        scales: &Scales<'_>,
        sums: &mut [f64],
        options: &SolverOptions,
    ) -> Result<Factors, LuError> {
        let (n, slots) = (self.n(), self.block.slots);
        let (largest, norm1) = self.evaluate(q, trig, t, phi, storage.values, scales, sums)?;
        let fallback = !self.block.pivots.is_empty() && options.static_pivots;
        if fallback {
            // The same singularity test as partial pivoting, plus the threshold on multipliers.
            let tiny = options.pivot_tolerance * n as f64 * largest.max(SCALE_FLOOR);
            let limit = 1.0 / options.static_pivot_threshold;
            if self
                .m
                .factor(self.stage, &mut storage.values[..slots], tiny, limit)
                .is_ok()
            {
                return Ok(Factors::Static { norm1 });
            }
            // The failed attempt overwrote the values: evaluate again.
            self.evaluate(q, trig, t, phi, storage.values, scales, sums)?;
        }
        let lu = &mut storage.lu[..n * n];
        self.scatter(storage.values, lu);
        lu::factor_in_place(
            lu,
            &mut storage.swaps[..n],
            options.pivot_tolerance,
            SCALE_FLOOR,
        )?;
        Ok(Factors::Dense { norm1, fallback })
    }

    /// Copies the block's values into the column-major n × n `dense`, zeros elsewhere.
    pub fn scatter(&self, values: &[f64], dense: &mut [f64]) {
        let n = self.n();
        match self.block.pattern {
            Pattern::Sparse(entries) => {
                dense.fill(0.0);
                for (&value, &(i, j)) in values.iter().zip(entries) {
                    dense[i + j * n] = value;
                }
            }
            Pattern::Dense => dense[..n * n].copy_from_slice(&values[..n * n]),
        }
    }

    /// `x ← J⁻¹ x` (`x` in local row order on entry, column order on return).
    pub fn solve(
        &self,
        factors: Factors,
        storage: &FactorStorage<'_>,
        scales: &Scales<'_>,
        x: &mut [f64],
    ) {
        let n = self.n();
        let x = &mut x[..n];
        scale(x, scales.rows);
        self.solve_scaled(factors, storage, x);
        scale(x, scales.cols);
    }

    /// `x ← J⁻ᵀ x` (`x` in local column order on entry, row order on return): the force
    /// solve's `Jᵀ λ = r`. With `J = D_r⁻¹ S D_c⁻¹`, `λ = D_r S⁻ᵀ D_c r`.
    pub fn solve_transpose(
        &self,
        factors: Factors,
        storage: &FactorStorage<'_>,
        scales: &Scales<'_>,
        x: &mut [f64],
    ) {
        let x = &mut x[..self.n()];
        scale(x, scales.cols);
        self.solve_transpose_scaled(factors, storage, x);
        scale(x, scales.rows);
    }

    /// [`BlockSolve::solve`] with static factors kept elsewhere (`values`: the force solve's
    /// archive of the block's factored slots).
    pub fn solve_static(&self, values: &[f64], scales: &Scales<'_>, x: &mut [f64]) {
        let x = &mut x[..self.n()];
        scale(x, scales.rows);
        self.m.solve(self.stage, values, x);
        scale(x, scales.cols);
    }

    /// [`BlockSolve::solve_transpose`] with static factors kept elsewhere (`values`: the force
    /// solve's archive of the block's factored slots).
    pub fn solve_transpose_static(&self, values: &[f64], scales: &Scales<'_>, x: &mut [f64]) {
        let x = &mut x[..self.n()];
        scale(x, scales.cols);
        self.m.solve_transpose(self.stage, values, x);
        scale(x, scales.rows);
    }

    /// `x ← S⁻¹ x`.
    fn solve_scaled(&self, factors: Factors, storage: &FactorStorage<'_>, x: &mut [f64]) {
        let n = self.n();
        match factors {
            Factors::Static { .. } => {
                self.m
                    .solve(self.stage, &storage.values[..self.block.slots], x);
            }
            Factors::Dense { .. } => {
                lu::solve_factors(&storage.lu[..n * n], &storage.swaps[..n], x);
            }
        }
    }

    /// `x ← S⁻ᵀ x`.
    fn solve_transpose_scaled(&self, factors: Factors, storage: &FactorStorage<'_>, x: &mut [f64]) {
        let n = self.n();
        match factors {
            Factors::Static { .. } => {
                self.m
                    .solve_transpose(self.stage, &storage.values[..self.block.slots], x);
            }
            Factors::Dense { .. } => {
                lu::solve_transposed_factors(&storage.lu[..n * n], &storage.swaps[..n], x);
            }
        }
    }

    /// The sign of det S (+1 or −1) from its factors: with the static order, the product of
    /// the pivots' signs (stored as reciprocals in [`Block::pivots`], no permutation); with
    /// partial pivoting, [`lu::determinant_sign`]. Both are in the block's local order, and the
    /// scalings are positive, so the sign changes only where the block Jacobian is singular.
    pub fn orientation(&self, factors: Factors, storage: &FactorStorage<'_>) -> f64 {
        let n = self.n();
        match factors {
            Factors::Static { .. } => {
                // The parity of the pivots' sign bits: static pivots passed their magnitude
                // test, so none is zero or NaN.
                let values = &*storage.values;
                let negative = (self.block.pivots.iter())
                    .fold(false, |odd, &slot| odd ^ values[slot].is_sign_negative());
                if negative { -1.0 } else { 1.0 }
            }
            Factors::Dense { .. } => {
                lu::determinant_sign(&storage.lu[..n * n], &storage.swaps[..n])
            }
        }
    }

    /// `max(1, ‖S‖₁) ‖S⁻¹‖₁` (see the module documentation): exact for blocks of at most
    /// [`EXACT_CONDITION`] coordinates (one solve per column of `S⁻¹`), otherwise the
    /// Hager–Higham estimate warm-started from `hint` (the maximising column of this block's
    /// last estimate), which it updates. Infinite when a solve overflows.
    pub fn condition(
        &self,
        factors: Factors,
        storage: &FactorStorage<'_>,
        estimator: &mut Estimator<'_>,
        hint: &mut usize,
    ) -> f64 {
        let n = self.n();
        if n == 0 {
            return 1.0;
        }
        let inverse_norm = if n <= EXACT_CONDITION {
            exact_inverse_norm(&mut estimator.x[..n], |x| {
                self.solve_scaled(factors, storage, x);
            })
        } else {
            let (inverse_norm, column) = lu::inverse_one_norm_estimate(
                &mut estimator.x[..n],
                &mut estimator.signs[..n],
                (*hint < n).then_some(*hint),
                |x| self.solve_scaled(factors, storage, x),
                |x| self.solve_transpose_scaled(factors, storage, x),
            );
            *hint = column;
            inverse_norm
        };
        bounded_condition(inverse_norm, factors.norm1())
    }

    /// The rank-revealing diagnosis of the block at `q`: complete pivoting on the scaled block
    /// Jacobian (in `dense`) with relative `tolerance`. Writes the global indices of the
    /// dependent equations and undetermined coordinates, ascending, to the heads of `rows` and
    /// `columns`, and returns how many there are (n − rank).
    ///
    /// # Errors
    /// [`LuError::NonFinite`] for a non-finite entry.
    #[allow(clippy::too_many_arguments)]
    pub fn diagnose(
        &self,
        q: &Vector<M::Dim>,
        trig: &[f64],
        t: f64,
        phi: &mut [f64],
        values: &mut [f64],
        scales: &Scales<'_>,
        sums: &mut [f64],
        dense: &mut [f64],
        rows: &mut [usize],
        columns: &mut [usize],
        tolerance: f64,
    ) -> Result<usize, LuError> {
        let n = self.n();
        self.evaluate(q, trig, t, phi, values, scales, sums)?;
        let dense = &mut dense[..n * n];
        self.scatter(values, dense);
        let (rows, columns) = (&mut rows[..n], &mut columns[..n]);
        let rank = lu::reveal_rank_in_place(dense, rows, columns, tolerance, SCALE_FLOOR)?;
        let deficiency = n - rank;
        // Heads ← global indices of the tails (reading position rank + k before writing k ≤ it).
        for k in 0..deficiency {
            rows[k] = self.block.equations[rows[rank + k]];
            columns[k] = self.block.coordinates[columns[rank + k]];
        }
        crate::lu::sort_indices(&mut rows[..deficiency]);
        crate::lu::sort_indices(&mut columns[..deficiency]);
        Ok(deficiency)
    }
}

/// `‖S⁻¹‖₁` exactly, one solve (`solve`: `x ← S⁻¹ x`) per column, in `x` (n long) as
/// scratch; NaN propagates.
#[inline]
pub(crate) fn exact_inverse_norm(x: &mut [f64], mut solve: impl FnMut(&mut [f64])) -> f64 {
    (0..x.len()).fold(0.0_f64, |largest, j| {
        x.fill(0.0);
        x[j] = 1.0;
        solve(x);
        let norm: f64 = x.iter().map(|v| v.abs()).sum();
        if norm > largest || norm.is_nan() {
            norm
        } else {
            largest
        }
    })
}

/// The block's condition `max(1, ‖S‖₁) ‖S⁻¹‖₁` (see the module documentation), infinite when
/// it overflows or is NaN.
#[inline]
pub(crate) fn bounded_condition(inverse_norm: f64, norm1: f64) -> f64 {
    let condition = inverse_norm * norm1.max(SCALE_FLOOR);
    if condition <= f64::MAX {
        condition
    } else {
        f64::INFINITY
    }
}

/// `x ← diag(s) x`.
#[inline]
fn scale(x: &mut [f64], s: &[f64]) {
    for (x, s) in x.iter_mut().zip(s) {
        *x *= s;
    }
}
