//! [`Lu`]: the factorisation of one nalgebra matrix, its storage allocated once and reused by
//! every factor, solve, condition estimate and rank reveal.

use nalgebra::{DefaultAllocator, Dim, OVector, U1};

use super::condition::inverse_one_norm_estimate;
use super::error::LuError;
use super::factor::{factor_in_place, solve_factors, solve_transposed_factors};
use super::rank::reveal_rank_in_place;
use crate::mechanism::{Matrix, Storage, Vector};

/// Default relative pivot tolerance; see [`Lu::set_pivot_tolerance`].
///
/// About 450 ε: round-off pivots of an exactly singular, well-scaled n × n Jacobian stay a few
/// n·ε·max|a| in size, while genuine near-toggle pivots (sin of a small angle times a length)
/// remain well above it until the angle is below ~1e-12 rad.
pub const DEFAULT_PIVOT_TOLERANCE: f64 = 1e-13;

/// Packed `P S = L U` factorisation (unit lower `L` below the diagonal, `U` on and above it) of
/// `S = D_r A D_c`, where the diagonal scalings are the identity unless set by
/// [`Lu::factor_scaled_with`].
///
/// Storage, including the scratch space of [`Lu::condition_estimate`] and the permutations of
/// [`Lu::reveal_rank`], is allocated once by [`Lu::new`]; every other method overwrites it, so a
/// solver can refactor every Newton iteration without touching the heap.
#[derive(Debug, Clone)]
pub struct Lu<D: Dim>
where
    DefaultAllocator: Storage<D>,
{
    lu: Matrix<D>,
    /// LAPACK-style swap sequence: at step `k`, row `k` was exchanged with row `swaps[k]`.
    /// Kept as swaps rather than a permutation so solves (forward for `S`, in reverse for `Sᵀ`)
    /// permute in place without scratch space.
    swaps: OVector<usize, D>,
    /// Diagonal of `D_r` (meaningful only while `scaled`).
    row_scale: Vector<D>,
    /// Diagonal of `D_c` (meaningful only while `scaled`).
    col_scale: Vector<D>,
    /// Whether the last factorisation was scaled; unscaled solves skip the multiplications.
    scaled: bool,
    /// `‖S‖₁` (largest column sum of magnitudes) before elimination, for the condition estimate.
    norm1: f64,
    /// Cached [`Lu::condition_estimate`] of the current factorisation.
    condition: Option<f64>,
    /// The column of `S⁻¹` with the largest 1-norm found by the last estimate: the next
    /// factorisation (usually the next Newton iterate or time step, a nearby matrix) starts its
    /// estimate there, which confirms an unchanged maximiser in two solves instead of 4 to 11.
    estimate_hint: Option<usize>,
    /// Scratch vectors of the condition estimator (its iterate, and the sign vector ξ as ±1).
    estimate_x: Vector<D>,
    estimate_signs: Vector<D>,
    /// Full row and column permutations from [`Lu::reveal_rank`]: position `k` holds the
    /// original index of the `k`-th pivot row / column; the tails past the rank are sorted.
    row_order: OVector<usize, D>,
    col_order: OVector<usize, D>,
    /// Numerical rank found by the last successful [`Lu::reveal_rank`].
    revealed_rank: Option<usize>,
    pivot_tolerance: f64,
    pivot_range: Option<(f64, f64)>,
}

impl<D: Dim> Lu<D>
where
    DefaultAllocator: Storage<D>,
{
    /// Allocates storage for `dim × dim` matrices (on the stack for `Const` dimensions).
    pub fn new(dim: D) -> Self {
        Self {
            lu: Matrix::zeros_generic(dim, dim),
            swaps: OVector::from_element_generic(dim, U1, 0),
            row_scale: Vector::from_element_generic(dim, U1, 1.0),
            col_scale: Vector::from_element_generic(dim, U1, 1.0),
            scaled: false,
            norm1: 0.0,
            condition: None,
            estimate_hint: None,
            estimate_x: Vector::zeros_generic(dim, U1),
            estimate_signs: Vector::zeros_generic(dim, U1),
            row_order: OVector::from_fn_generic(dim, U1, |i, _| i),
            col_order: OVector::from_fn_generic(dim, U1, |i, _| i),
            revealed_rank: None,
            pivot_tolerance: DEFAULT_PIVOT_TOLERANCE,
            pivot_range: None,
        }
    }

    /// The relative pivot tolerance.
    pub fn pivot_tolerance(&self) -> f64 {
        self.pivot_tolerance
    }

    /// Sets the relative pivot tolerance τ: a pivot counts as zero when
    /// `|u_kk| ≤ τ · n · max|s_ij|` (max over the scaled matrix `S` before elimination).
    ///
    /// Scaling by the largest entry makes the test independent of the mechanism's length unit;
    /// the factor `n` follows the usual growth of round-off in elimination.
    pub fn set_pivot_tolerance(&mut self, tolerance: f64) {
        self.pivot_tolerance = tolerance;
    }

    /// Whether the last factorisation succeeded (so [`Lu::solve_in_place`] may be used).
    pub fn is_factored(&self) -> bool {
        self.pivot_range.is_some()
    }

    /// Rough condition estimate `max|u_kk| / min|u_kk|` of the last successful factorisation
    /// (of the scaled matrix `S` after [`Lu::factor_scaled_with`]).
    ///
    /// A lower bound on the 2-norm condition number that can underestimate it badly; treat it
    /// as a warning sign, not a bound. [`Lu::condition_estimate`] is far more reliable for a
    /// few more solves. `None` if there is no successful factorisation.
    pub fn rough_condition(&self) -> Option<f64> {
        self.pivot_range
            .map(|(min, max)| if max == 0.0 { 1.0 } else { max / min })
    }

    /// Copies `matrix` into the internal storage and factors it (unscaled).
    ///
    /// # Errors
    /// [`LuError::DimensionMismatch`] if `matrix` is not the size given to [`Lu::new`], otherwise
    /// as [`Lu::factor_with`].
    pub fn factor(&mut self, matrix: &Matrix<D>) -> Result<(), LuError> {
        let n = self.lu.nrows();
        if matrix.shape() != (n, n) {
            self.invalidate();
            return Err(LuError::DimensionMismatch {
                expected: n,
                found: matrix.nrows(),
            });
        }
        self.factor_with(|storage| storage.copy_from(matrix))
    }

    /// Lets `fill` write the matrix straight into the internal storage, then factors it
    /// (unscaled: any scaling from [`Lu::factor_scaled_with`] is dropped).
    ///
    /// This is how the solver evaluates Φ_q without keeping a second n × n matrix around.
    ///
    /// # Errors
    /// [`LuError::NonFinite`] for NaN or infinite entries, [`LuError::Singular`] when a column
    /// has no pivot above the tolerance, [`LuError::DimensionMismatch`] if `fill` replaced the
    /// storage with a matrix of another size.
    pub fn factor_with(&mut self, fill: impl FnOnce(&mut Matrix<D>)) -> Result<(), LuError> {
        self.invalidate();
        self.scaled = false;
        fill(&mut self.lu);
        self.check_storage_shape()?;
        self.eliminate()
    }

    /// Lets `fill` write `A` into the internal storage, then factors `S = D_r A D_c` with
    /// `D_r = diag(rows)`, `D_c = diag(cols)`.
    ///
    /// Equations and coordinates of a mechanism mix units (lengths, angles) and magnitudes;
    /// with scales that bring `S` to entries of similar size, the pivot tolerance (applied to
    /// `S`), [`Lu::rough_condition`] and [`Lu::condition_estimate`] describe the problem rather
    /// than its units. Powers of two make the scaling exact. [`Lu::solve_in_place`] and
    /// [`Lu::solve_transpose_in_place`] still solve with the original `A`.
    ///
    /// # Errors
    /// [`LuError::DimensionMismatch`] if `rows` or `cols` has the wrong length (checked before
    /// `fill` runs); [`LuError::NonFinite`] if a scale is not finite and positive (also checked
    /// first), if `A` has a NaN or infinite entry, or if scaling overflows; otherwise as
    /// [`Lu::factor_with`].
    pub fn factor_scaled_with(
        &mut self,
        rows: &Vector<D>,
        cols: &Vector<D>,
        fill: impl FnOnce(&mut Matrix<D>),
    ) -> Result<(), LuError> {
        self.invalidate();
        self.load_scaled(rows, cols, fill)?;
        self.eliminate()
    }

    /// Overwrites `b` with the solution `x` of `A x = b`.
    ///
    /// With scaling this is `x = D_c S⁻¹ D_r b`.
    ///
    /// # Errors
    /// [`LuError::NotFactored`] without a successful factorisation, [`LuError::DimensionMismatch`]
    /// if `b` has the wrong length.
    pub fn solve_in_place(&self, b: &mut Vector<D>) -> Result<(), LuError> {
        let x = self.checked_rhs(b)?;
        if self.scaled {
            scale_slice(x, self.row_scale.as_slice());
        }
        solve_factors(self.lu.as_slice(), self.swaps.as_slice(), x);
        if self.scaled {
            scale_slice(x, self.col_scale.as_slice());
        }
        Ok(())
    }

    /// Overwrites `b` with the solution `x` of `Aᵀ x = b`.
    ///
    /// Used for adjoint (sensitivity) solves and Lagrange multipliers, where the Jacobian
    /// appears transposed, without factoring `Aᵀ` separately. With scaling,
    /// `Sᵀ = D_c Aᵀ D_r`, so this is `x = D_r S⁻ᵀ D_c b`.
    ///
    /// # Errors
    /// [`LuError::NotFactored`] without a successful factorisation, [`LuError::DimensionMismatch`]
    /// if `b` has the wrong length.
    pub fn solve_transpose_in_place(&self, b: &mut Vector<D>) -> Result<(), LuError> {
        let x = self.checked_rhs(b)?;
        if self.scaled {
            scale_slice(x, self.col_scale.as_slice());
        }
        solve_transposed_factors(self.lu.as_slice(), self.swaps.as_slice(), x);
        if self.scaled {
            scale_slice(x, self.row_scale.as_slice());
        }
        Ok(())
    }

    /// Estimate of the 1-norm condition number `κ₁(S) = ‖S‖₁ ‖S⁻¹‖₁` of the factored (scaled)
    /// matrix; `None` without a successful factorisation.
    ///
    /// `‖S⁻¹‖₁` comes from Hager's method as refined by Higham (1988, Algorithm 4.1; LAPACK
    /// `dlacn2`): at most 5 iterations of solves with `S` and `Sᵀ` plus the alternating-sign
    /// test vector, 4 to 11 solves in all instead of the n of an inverse. Started from the
    /// maximising column of the previous estimate (warm start), an unchanged maximiser is
    /// confirmed in 2 solves; the alternating-sign test is then skipped. It never
    /// exceeds the true value (up to rounding) and is usually exact, rarely low by more than a
    /// factor 3. Unlike LAPACK it keeps the largest of the lower bounds met along the way.
    ///
    /// The result is cached until the next factorisation, hence `&mut self` (the scratch space
    /// lives in `self`, so nothing is allocated). Returns `f64::INFINITY` if a solve overflows,
    /// and 1 for a 0 × 0 matrix (as [`Lu::rough_condition`]).
    pub fn condition_estimate(&mut self) -> Option<f64> {
        self.pivot_range?;
        if let Some(condition) = self.condition {
            return Some(condition);
        }
        let n = self.lu.nrows();
        let condition = if n == 0 {
            1.0
        } else {
            let (a, swaps) = (self.lu.as_slice(), self.swaps.as_slice());
            let (inverse_norm, column) = inverse_one_norm_estimate(
                self.estimate_x.as_mut_slice(),
                self.estimate_signs.as_mut_slice(),
                self.estimate_hint.filter(|&j| j < n),
                |x| solve_factors(a, swaps, x),
                |x| solve_transposed_factors(a, swaps, x),
            );
            self.estimate_hint = Some(column);
            let condition = inverse_norm * self.norm1;
            // Also catches NaN (`0 · ∞` cannot happen: a factored matrix has ‖S‖₁ > 0).
            if condition <= f64::MAX {
                condition
            } else {
                f64::INFINITY
            }
        };
        self.condition = Some(condition);
        Some(condition)
    }

    /// Lets `fill` write `A`, scales it to `S = D_r A D_c` (as [`Lu::factor_scaled_with`]) and
    /// runs Gaussian elimination with complete pivoting until every remaining entry is at most
    /// `tolerance · max|s_ij|` (or exactly zero); returns that numerical rank `r`.
    ///
    /// Partial pivoting ([`LuError::Singular`]) names one suspect row at the first column that
    /// fails; complete pivoting instead picks the largest entry of the whole remaining
    /// submatrix each step, so it finds every redundancy at once:
    /// [`Lu::dependent_rows`] lists the `n − r` equations that are combinations of the others
    /// and [`Lu::undetermined_columns`] the `n − r` coordinates the equations leave free. Use it
    /// to explain a failure, not in the solve loop (it scans the submatrix at every step).
    /// A tolerance of a few `n · f64::EPSILON` finds exact dependencies in well-scaled data; a
    /// NaN tolerance counts only exact zeros as negligible.
    ///
    /// The storage then holds complete-pivoting factors that the solves cannot use, so the
    /// factorisation is marked as not factored ([`Lu::is_factored`] is false; solves return
    /// [`LuError::NotFactored`]) until the next `factor*` call.
    ///
    /// # Errors
    /// As [`Lu::factor_scaled_with`] for sizes, scales and non-finite entries (also if
    /// elimination overflows); [`Lu::dependent_rows`] and [`Lu::undetermined_columns`] are
    /// then empty.
    pub fn reveal_rank(
        &mut self,
        rows: &Vector<D>,
        cols: &Vector<D>,
        tolerance: f64,
        fill: impl FnOnce(&mut Matrix<D>),
    ) -> Result<usize, LuError> {
        self.invalidate();
        self.revealed_rank = None;
        self.load_scaled(rows, cols, fill)?;
        let rank = reveal_rank_in_place(
            self.lu.as_mut_slice(),
            self.row_order.as_mut_slice(),
            self.col_order.as_mut_slice(),
            tolerance,
            0.0,
        )?;
        self.revealed_rank = Some(rank);
        Ok(rank)
    }

    /// Original indices (ascending) of the rows that got no pivot in the last successful
    /// [`Lu::reveal_rank`]: redundant or conflicting equations, each (numerically) a
    /// combination of the pivot rows. Empty before any reveal or after a failed one.
    ///
    /// Which member of a dependent set is reported depends on the pivot order (the row
    /// eliminated last), so any one of the equations involved may be named.
    pub fn dependent_rows(&self) -> &[usize] {
        let rank = self.revealed_rank.unwrap_or(usize::MAX);
        self.row_order.as_slice().get(rank..).unwrap_or(&[])
    }

    /// Original indices (ascending) of the columns that got no pivot in the last successful
    /// [`Lu::reveal_rank`]: coordinates the equations leave (numerically) undetermined. Empty
    /// before any reveal or after a failed one.
    pub fn undetermined_columns(&self) -> &[usize] {
        let rank = self.revealed_rank.unwrap_or(usize::MAX);
        self.col_order.as_slice().get(rank..).unwrap_or(&[])
    }

    /// Forgets the current factorisation and its cached condition estimate.
    fn invalidate(&mut self) {
        self.pivot_range = None;
        self.condition = None;
    }

    /// Checks that `fill` left the storage at the size given to [`Lu::new`].
    fn check_storage_shape(&self) -> Result<(), LuError> {
        let n = self.swaps.nrows();
        if self.lu.shape() == (n, n) {
            Ok(())
        } else {
            Err(LuError::DimensionMismatch {
                expected: n,
                found: self.lu.nrows(),
            })
        }
    }

    /// Validates and stores the scales, runs `fill` and scales the storage in place.
    fn load_scaled(
        &mut self,
        rows: &Vector<D>,
        cols: &Vector<D>,
        fill: impl FnOnce(&mut Matrix<D>),
    ) -> Result<(), LuError> {
        self.scaled = false;
        let n = self.swaps.nrows();
        for scales in [rows, cols] {
            if scales.nrows() != n {
                return Err(LuError::DimensionMismatch {
                    expected: n,
                    found: scales.nrows(),
                });
            }
            // Also false for NaN.
            if !scales.as_slice().iter().all(|&s| s > 0.0 && s <= f64::MAX) {
                return Err(LuError::NonFinite);
            }
        }
        self.row_scale
            .as_mut_slice()
            .copy_from_slice(rows.as_slice());
        self.col_scale
            .as_mut_slice()
            .copy_from_slice(cols.as_slice());
        fill(&mut self.lu);
        self.check_storage_shape()?;
        if n == 0 {
            self.scaled = true;
            return Ok(());
        }
        // Column j of S is c_j · D_r · (column j of A). Overflow or NaN shows up in the
        // finiteness scan that follows.
        for (column, &c) in self
            .lu
            .as_mut_slice()
            .chunks_exact_mut(n)
            .zip(cols.as_slice())
        {
            for (x, &r) in column.iter_mut().zip(rows.as_slice()) {
                *x = *x * r * c;
            }
        }
        self.scaled = true;
        Ok(())
    }

    /// Factors the (already scaled) storage with partial pivoting; the shape is checked.
    fn eliminate(&mut self) -> Result<(), LuError> {
        let factored = factor_in_place(
            self.lu.as_mut_slice(),
            self.swaps.as_mut_slice(),
            self.pivot_tolerance,
            0.0,
        )?;
        self.norm1 = factored.norm1;
        self.pivot_range = Some((factored.min_pivot, factored.max_pivot));
        Ok(())
    }

    /// Checks a right-hand side against the factorisation; its slice on success.
    fn checked_rhs<'b>(&self, b: &'b mut Vector<D>) -> Result<&'b mut [f64], LuError> {
        if self.pivot_range.is_none() {
            return Err(LuError::NotFactored);
        }
        let n = self.lu.nrows();
        if b.nrows() != n {
            return Err(LuError::DimensionMismatch {
                expected: n,
                found: b.nrows(),
            });
        }
        Ok(b.as_mut_slice())
    }
}

/// `x ← diag(scale) x`.
#[inline(always)]
fn scale_slice(x: &mut [f64], scale: &[f64]) {
    for (x, &s) in x.iter_mut().zip(scale) {
        *x *= s;
    }
}
