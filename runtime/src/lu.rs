//! LU factorisation reusable without allocation, with the diagnostics a kinematic solver needs.
//!
//! * [`Lu::factor`] / [`Lu::factor_with`]: `P A = L U` with partial pivoting and a relative
//!   singularity test; [`Lu::solve_in_place`] and [`Lu::solve_transpose_in_place`] then solve
//!   `A x = b` and `Aᵀ x = b`.
//! * [`Lu::factor_scaled_with`]: the same for `S = D_r A D_c` with caller-chosen diagonal
//!   scalings (equation and coordinate units), so the pivot test and the condition estimate
//!   judge the problem in natural units; solves still return the solution for `A`.
//! * [`Lu::condition_estimate`]: Hager–Higham estimate of `κ₁(S)` (LAPACK `dlacn2`), a few
//!   extra solves and no allocation.
//! * [`Lu::reveal_rank`]: complete-pivoting elimination of a singular or nearly singular matrix
//!   that names the redundant equations ([`Lu::dependent_rows`]) and the coordinates left
//!   undetermined ([`Lu::undetermined_columns`]).
//!
//! All storage is allocated by [`Lu::new`]; every loop runs on contiguous column-major slices
//! (nalgebra's element iterators and tuple indexing cost an order of magnitude more).

use nalgebra::{DefaultAllocator, Dim, OVector, U1};

use crate::mechanism::{Matrix, Storage, Vector};

/// Default relative pivot tolerance; see [`Lu::set_pivot_tolerance`].
///
/// About 450 ε: round-off pivots of an exactly singular, well-scaled n × n Jacobian stay a few
/// n·ε·max|a| in size, while genuine near-toggle pivots (sin of a small angle times a length)
/// remain well above it until the angle is below ~1e-12 rad.
pub const DEFAULT_PIVOT_TOLERANCE: f64 = 1e-13;

/// Iteration limit of the 1-norm estimator, as LAPACK's `dlacn2` (`ITMAX`).
const ESTIMATOR_ITERATIONS: usize = 5;

/// Why a factorisation or solve failed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LuError {
    /// Column `column` has no pivot above the tolerance among the rows not yet eliminated.
    ///
    /// `row` is the original index of the remaining row whose eliminated part is smallest: the
    /// likeliest redundant or conflicting equation. `pivot` is the largest candidate magnitude.
    Singular {
        /// Original row (equation) index.
        row: usize,
        /// Column (coordinate) index.
        column: usize,
        /// Magnitude of the best available pivot.
        pivot: f64,
    },
    /// The matrix has a NaN or infinite entry (also: a scale that is not finite and positive,
    /// or scaling that overflowed).
    NonFinite,
    /// `solve_in_place` was called without a successful `factor` since the last failure.
    NotFactored,
    /// A matrix or vector does not have the size of the factorisation.
    DimensionMismatch {
        /// The factorisation's size.
        expected: usize,
        /// The size that was passed.
        found: usize,
    },
}

impl core::fmt::Display for LuError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Singular { row, column, pivot } => write!(
                f,
                "singular matrix: no usable pivot in column {column} (row {row}, |pivot| = {pivot:e})"
            ),
            Self::NonFinite => f.write_str("matrix has a NaN or infinite entry"),
            Self::NotFactored => f.write_str("no successful factorisation to solve with"),
            Self::DimensionMismatch { expected, found } => {
                write!(
                    f,
                    "size {found} does not match the factorisation's {expected}"
                )
            }
        }
    }
}

impl core::error::Error for LuError {}

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

/// Pivot statistics of a successful [`factor_in_place`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Factored {
    /// `‖S‖₁` before elimination.
    pub norm1: f64,
    /// Smallest and largest pivot magnitude.
    pub min_pivot: f64,
    pub max_pivot: f64,
}

/// `P S = L U` with partial pivoting, in place on the column-major n × n `a` (n = `swaps.len()`,
/// `a.len() == n²`); a pivot is unusable when `|u_kk| ≤ tolerance · n · max(floor, max|s_ij|)`
/// (`floor` is the scale below which entries count as small: 0 for a matrix on its own, 1 for a
/// block of a unit-scaled Jacobian, whose other blocks hold entries of 1).
///
/// # Errors
/// [`LuError::NonFinite`] for a NaN or infinite entry, [`LuError::Singular`] for a column without
/// a usable pivot (its `row` is the likeliest dependent equation).
pub(crate) fn factor_in_place(
    a: &mut [f64],
    swaps: &mut [usize],
    tolerance: f64,
    floor: f64,
) -> Result<Factored, LuError> {
    let n = swaps.len();
    // Plain slices, column-major (a[i + j·n] is row i, column j): nalgebra's element
    // iterators and tuple indexing cost an order of magnitude more in these loops.
    let Some((largest, norm1)) = max_abs_and_one_norm_if_finite(a, n) else {
        return Err(LuError::NonFinite);
    };
    // `n as f64` is exact for any size that fits in memory.
    let threshold = tolerance * n as f64 * largest.max(floor);
    let (mut min_pivot, mut max_pivot) = (f64::INFINITY, 0.0_f64);
    for k in 0..n {
        let column_k = k * n;
        let (mut pivot_row, mut best) = (k, a[column_k + k].abs());
        for i in k + 1..n {
            let candidate = a[column_k + i].abs();
            if candidate > best {
                (pivot_row, best) = (i, candidate);
            }
        }
        // An exact zero is singular whatever the tolerance (even a NaN or negative one).
        if best <= threshold || best == 0.0 {
            return Err(LuError::Singular {
                row: likeliest_dependent_row(a, swaps, k),
                column: k,
                pivot: best,
            });
        }
        swaps[k] = pivot_row;
        if pivot_row != k {
            for j in 0..n {
                a.swap(j * n + k, j * n + pivot_row);
            }
        }
        (min_pivot, max_pivot) = (min_pivot.min(best), max_pivot.max(best));
        eliminate_step(a, n, k);
    }
    Ok(Factored {
        norm1,
        min_pivot,
        max_pivot,
    })
}

/// Among rows `k..n` after `k` elimination steps of [`factor_in_place`], the original index of
/// the one whose remaining entries are smallest: it is (nearly) a combination of the pivot rows
/// already used.
fn likeliest_dependent_row(a: &[f64], swaps: &[usize], k: usize) -> usize {
    let n = swaps.len();
    let mut best = (k, f64::INFINITY);
    for i in k..n {
        let size = (k..n).fold(0.0_f64, |m, j| m.max(a[i + j * n].abs()));
        if size < best.1 {
            best = (i, size);
        }
    }
    // Undo the swaps of steps 0..k to find where that row started.
    let mut row = best.0;
    for (step, &swap) in swaps.iter().enumerate().take(k).rev() {
        if row == step {
            row = swap;
        } else if row == swap {
            row = step;
        }
    }
    row
}

/// Gaussian elimination with complete pivoting of the column-major n × n `a` (n =
/// `row_order.len()`) until every remaining entry is at most `tolerance · max(floor, max|a_ij|)`
/// (or exactly zero); returns that numerical rank `r`. `row_order[k]` / `col_order[k]` receive the original
/// index of the `k`-th pivot row / column; the tails past the rank are sorted.
///
/// # Errors
/// [`LuError::NonFinite`] for a NaN or infinite entry (also if elimination overflows).
pub(crate) fn reveal_rank_in_place(
    a: &mut [f64],
    row_order: &mut [usize],
    col_order: &mut [usize],
    tolerance: f64,
    floor: f64,
) -> Result<usize, LuError> {
    let n = row_order.len();
    let Some(largest) = max_abs_if_finite(a) else {
        return Err(LuError::NonFinite);
    };
    let threshold = tolerance * largest.max(floor);
    for (i, (row, col)) in row_order.iter_mut().zip(col_order.iter_mut()).enumerate() {
        (*row, *col) = (i, i);
    }
    let mut rank = n;
    for k in 0..n {
        // Largest entry of the trailing submatrix (first one on ties, for stable reports).
        let (mut pivot_row, mut pivot_col, mut best) = (k, k, 0.0_f64);
        let mut finite = true;
        for (j, column) in a.chunks_exact(n).enumerate().skip(k) {
            for (i, &x) in column.iter().enumerate().skip(k) {
                let magnitude = x.abs();
                finite &= magnitude <= f64::MAX;
                if magnitude > best {
                    (pivot_row, pivot_col, best) = (i, j, magnitude);
                }
            }
        }
        if !finite {
            return Err(LuError::NonFinite);
        }
        if best <= threshold || best == 0.0 {
            rank = k;
            break;
        }
        if pivot_row != k {
            for column in a.chunks_exact_mut(n) {
                column.swap(k, pivot_row);
            }
            row_order.swap(k, pivot_row);
        }
        if pivot_col != k {
            let (left, right) = a.split_at_mut(pivot_col * n);
            left[k * n..(k + 1) * n].swap_with_slice(&mut right[..n]);
            col_order.swap(k, pivot_col);
        }
        eliminate_step(a, n, k);
    }
    sort_indices(&mut row_order[rank..]);
    sort_indices(&mut col_order[rank..]);
    Ok(rank)
}

/// Sorts indices in place, for the diagnoses of a failed solve: an insertion sort, linear on
/// the nearly sorted lists they produce, and a tenth of the code of `sort_unstable`, whose
/// quicksort took 2 kB of a Cortex-M4 firmware's flash for a path only a failure takes.
pub(crate) fn sort_indices(indices: &mut [usize]) {
    for i in 1..indices.len() {
        let mut j = i;
        while j > 0 && indices[j - 1] > indices[j] {
            indices.swap(j - 1, j);
            j -= 1;
        }
    }
}

/// Elimination step `k` on column-major `a` (n × n) whose pivot is already at `(k, k)`:
/// stores the multipliers below it and updates the trailing submatrix.
#[inline(always)]
fn eliminate_step(a: &mut [f64], n: usize, k: usize) {
    let column_k = k * n;
    let pivot = a[column_k + k];
    for x in &mut a[column_k + k + 1..column_k + n] {
        *x /= pivot;
    }
    // Column-oriented update; Jacobians are sparse, so whole columns are skipped when the
    // pivot row has a structural zero there.
    let (left, right) = a.split_at_mut(column_k + n);
    let l = &left[column_k + k + 1..];
    for column in right.chunks_exact_mut(n) {
        let u_kj = column[k];
        if u_kj != 0.0 {
            for (x, &l_ik) in column[k + 1..].iter_mut().zip(l) {
                *x -= l_ik * u_kj;
            }
        }
    }
}

/// `x ← diag(scale) x`.
#[inline(always)]
fn scale_slice(x: &mut [f64], scale: &[f64]) {
    for (x, &s) in x.iter_mut().zip(scale) {
        *x *= s;
    }
}

/// The sign of det S (+1 or −1) from the packed factors of `P S = L U` (non-singular): the
/// signs of U's diagonal times that of the row swaps. Positive scalings leave it unchanged, so
/// it is the sign of the block Jacobian's determinant in the block's local order.
pub(crate) fn determinant_sign(a: &[f64], swaps: &[usize]) -> f64 {
    let n = swaps.len();
    swaps.iter().enumerate().fold(1.0, |sign, (k, &swap)| {
        let flip = if swap == k { 1.0 } else { -1.0 };
        sign * flip * a[k * n + k].signum()
    })
}

/// Solves `S y = x` in place with the packed factors `a` (n × n, column-major) of `P S = L U`.
///
/// The caller guarantees `a.len() == n²` and `swaps.len() == n == x.len()`, `swaps[k] < n`.
#[inline(always)]
pub(crate) fn solve_factors(a: &[f64], swaps: &[usize], x: &mut [f64]) {
    // Index loops over `n = x.len()`, as in the original solve: once inlined for a `Const`
    // dimension, `n` is a constant and these compile to straight-line code (the iterator
    // form measured ~40% slower on a 15 × 15 system).
    let n = x.len();
    for (k, &swap) in swaps.iter().enumerate() {
        x.swap(k, swap);
    }
    // Forward substitution with unit-diagonal L, then back substitution with U, by columns.
    for k in 0..n {
        let x_k = x[k];
        if x_k != 0.0 {
            let column = &a[k * n..(k + 1) * n];
            for i in k + 1..n {
                x[i] -= column[i] * x_k;
            }
        }
    }
    for k in (0..n).rev() {
        let column = &a[k * n..(k + 1) * n];
        x[k] /= column[k];
        let x_k = x[k];
        for i in 0..k {
            x[i] -= column[i] * x_k;
        }
    }
}

/// Solves `Sᵀ y = x` in place with the packed factors of `P S = L U`.
///
/// `Sᵀ = Uᵀ Lᵀ P`: forward substitution with `Uᵀ`, back substitution with the unit `Lᵀ`, then
/// `y = Pᵀ w`, i.e. the swaps in reverse order. Row `k` of `Uᵀ` (of `Lᵀ`) is column `k` of `U`
/// (of `L`), so both are contiguous dot products. Same preconditions as [`solve_factors`].
#[inline(always)]
pub(crate) fn solve_transposed_factors(a: &[f64], swaps: &[usize], x: &mut [f64]) {
    let n = x.len();
    for k in 0..n {
        let column = &a[k * n..(k + 1) * n];
        let mut z_k = x[k];
        for i in 0..k {
            z_k -= column[i] * x[i];
        }
        x[k] = z_k / column[k];
    }
    for k in (0..n).rev() {
        let column = &a[k * n..(k + 1) * n];
        let mut w_k = x[k];
        for i in k + 1..n {
            w_k -= column[i] * x[i];
        }
        x[k] = w_k;
    }
    for (k, &swap) in swaps.iter().enumerate().rev() {
        x.swap(k, swap);
    }
}

/// Lower-bound estimate of `‖S⁻¹‖₁` given solves with `S` and `Sᵀ`: Higham's Algorithm 4.1
/// (LAPACK `dlacn2`), keeping the largest bound found, with the column of the bound. `x` and
/// `signs` are n-long scratch, n ≥ 1; `hint` is a column to start from (warm start: no first
/// power step, no alternating-sign test); `f64::INFINITY` if a solve produces a non-finite value.
pub(crate) fn inverse_one_norm_estimate(
    x: &mut [f64],
    signs: &mut [f64],
    hint: Option<usize>,
    mut solve: impl FnMut(&mut [f64]),
    mut solve_transposed: impl FnMut(&mut [f64]),
) -> (f64, usize) {
    let n = x.len();
    let (mut estimate, mut j) = match hint {
        // Warm start: no sign vector yet (0 never equals ±1, so the first one is not "repeated").
        Some(j) => {
            signs.fill(0.0);
            (0.0, j)
        }
        None => {
            // 1.0 / n as the start vector: `n as f64` is exact for any size that fits in memory.
            x.fill(1.0 / n as f64);
            solve(x);
            let estimate = one_norm(x);
            if !estimate.is_finite() {
                return (f64::INFINITY, 0);
            }
            if n == 1 {
                return (estimate, 0);
            }
            for (x_i, s_i) in x.iter_mut().zip(signs.iter_mut()) {
                *s_i = sign(*x_i);
                *x_i = *s_i;
            }
            solve_transposed(x);
            let Some(j) = index_of_max_abs(x) else {
                return (f64::INFINITY, 0);
            };
            (estimate, j)
        }
    };
    let mut best = j;
    let mut iteration = 2;
    loop {
        x.fill(0.0);
        x[j] = 1.0;
        solve(x);
        let latest = one_norm(x);
        if !latest.is_finite() {
            return (f64::INFINITY, j);
        }
        let improved = latest > estimate;
        if improved {
            (estimate, best) = (latest, j);
        }
        // A repeated sign vector means convergence; no growth means cycling.
        let repeated = x
            .iter()
            .zip(signs.iter())
            .all(|(&x_i, &s_i)| sign(x_i) == s_i);
        if repeated || !improved || n == 1 {
            break;
        }
        for (x_i, s_i) in x.iter_mut().zip(signs.iter_mut()) {
            *s_i = sign(*x_i);
            *x_i = *s_i;
        }
        solve_transposed(x);
        let last = j;
        let Some(next) = index_of_max_abs(x) else {
            return (f64::INFINITY, best);
        };
        j = next;
        // Stop when the previous column is still (one of) the largest: no better one in sight.
        if x[last] == x[j].abs() || iteration >= ESTIMATOR_ITERATIONS {
            break;
        }
        iteration += 1;
    }
    if hint.is_some() {
        return (estimate, best);
    }
    // Alternating-sign vector x_i = ±(1 + i/(n−1)), ‖x‖₁ = 3n/2: catches matrices where the
    // iteration stalls on a poor local maximum.
    let last = (n - 1) as f64;
    let mut alternating = 1.0;
    for (i, x_i) in x.iter_mut().enumerate() {
        *x_i = alternating * (1.0 + i as f64 / last);
        alternating = -alternating;
    }
    solve(x);
    let alternative = 2.0 * one_norm(x) / (3.0 * n as f64);
    if !alternative.is_finite() {
        return (f64::INFINITY, best);
    }
    (estimate.max(alternative), best)
}

/// `sign(x)` as in `dlacn2`: −1 for negative values beyond the underflow threshold, else +1.
fn sign(x: f64) -> f64 {
    if x < -f64::MIN_POSITIVE { -1.0 } else { 1.0 }
}

/// Σ |x_i|.
fn one_norm(x: &[f64]) -> f64 {
    x.iter().map(|x| x.abs()).sum()
}

/// Index of the first entry of largest magnitude, or `None` if any entry is NaN or infinite.
fn index_of_max_abs(x: &[f64]) -> Option<usize> {
    let (mut index, mut best, mut finite) = (0, -1.0_f64, true);
    for (i, &x_i) in x.iter().enumerate() {
        let magnitude = x_i.abs();
        finite &= magnitude <= f64::MAX;
        if magnitude > best {
            (index, best) = (i, magnitude);
        }
    }
    finite.then_some(index)
}

/// max |x| over `values`, or `None` if any is NaN or infinite.
///
/// Four independent accumulators and plain comparisons: a single `f64::max` chain is a serial
/// dependency with NaN handling, and was most of the cost of factoring a 15 × 15 Jacobian.
fn max_abs_if_finite(values: &[f64]) -> Option<f64> {
    let mut largest = [0.0_f64; 4];
    let mut finite = true;
    let mut chunks = values.chunks_exact(4);
    for chunk in &mut chunks {
        for (m, &x) in largest.iter_mut().zip(chunk) {
            let magnitude = x.abs();
            // `magnitude <= f64::MAX` is false exactly for NaN and infinities.
            finite &= magnitude <= f64::MAX;
            *m = if magnitude > *m { magnitude } else { *m };
        }
    }
    for &x in chunks.remainder() {
        let magnitude = x.abs();
        finite &= magnitude <= f64::MAX;
        largest[0] = if magnitude > largest[0] {
            magnitude
        } else {
            largest[0]
        };
    }
    let [a, b, c, d] = largest;
    finite.then(|| a.max(b).max(c.max(d)))
}

/// `(max |a_ij|, max_j Σ_i |a_ij|)` of the column-major n × n `values`, or `None` if any
/// entry is NaN or infinite.
///
/// One pass over four columns at a time: eight independent accumulator chains (a sum and a
/// maximum per column) instead of one serial sum per column. A NaN or infinity makes its column
/// sum non-finite, so the exact per-entry check runs only then (a column sum of finite entries
/// that overflowed is not an error; it just gives an infinite 1-norm).
#[inline(always)]
pub(crate) fn max_abs_and_one_norm_if_finite(values: &[f64], n: usize) -> Option<(f64, f64)> {
    if n == 0 {
        return Some((0.0, 0.0));
    }
    let (mut largest, mut norm1, mut sums_finite) = (0.0_f64, 0.0_f64, true);
    let mut groups = values.chunks_exact(4 * n);
    for group in &mut groups {
        let (c0, rest) = group.split_at(n);
        let (c1, rest) = rest.split_at(n);
        let (c2, c3) = rest.split_at(n);
        let (mut sums, mut maxima) = ([0.0_f64; 4], [0.0_f64; 4]);
        for (((&a, &b), &c), &d) in c0.iter().zip(c1).zip(c2).zip(c3) {
            for ((sum, m), x) in sums.iter_mut().zip(maxima.iter_mut()).zip([a, b, c, d]) {
                let magnitude = x.abs();
                *sum += magnitude;
                *m = if magnitude > *m { magnitude } else { *m };
            }
        }
        for (sum, m) in sums.into_iter().zip(maxima) {
            sums_finite &= sum <= f64::MAX;
            norm1 = if sum > norm1 { sum } else { norm1 };
            largest = if m > largest { m } else { largest };
        }
    }
    for column in groups.remainder().chunks_exact(n) {
        let mut sum = 0.0;
        for &x in column {
            let magnitude = x.abs();
            sum += magnitude;
            largest = if magnitude > largest {
                magnitude
            } else {
                largest
            };
        }
        sums_finite &= sum <= f64::MAX;
        norm1 = if sum > norm1 { sum } else { norm1 };
    }
    if !sums_finite {
        max_abs_if_finite(values)?;
    }
    Some((largest, norm1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sort_indices_sorts_every_permutation_of_five_and_duplicates() {
        // Every permutation of 0..5 by Heap's algorithm, each against `sort_unstable`.
        let mut items = [4, 1, 3, 0, 2];
        let mut counters = [0usize; 5];
        let mut checked = 0;
        let mut check = |items: &[usize; 5]| {
            let mut sorted = *items;
            sort_indices(&mut sorted);
            assert_eq!(sorted, [0, 1, 2, 3, 4], "from {items:?}");
            checked += 1;
        };
        check(&items);
        let mut i = 1;
        while i < items.len() {
            if counters[i] < i {
                items.swap(if i % 2 == 0 { 0 } else { counters[i] }, i);
                check(&items);
                counters[i] += 1;
                i = 1;
            } else {
                counters[i] = 0;
                i += 1;
            }
        }
        assert_eq!(checked, 120);
        let mut repeated = [3, 1, 3, 0, 1, 0];
        sort_indices(&mut repeated);
        assert_eq!(repeated, [0, 0, 1, 1, 3, 3]);
        sort_indices(&mut []);
    }

    #[test]
    fn max_abs_if_finite_handles_every_length_and_non_finite_values() {
        assert_eq!(max_abs_if_finite(&[]), Some(0.0));
        assert_eq!(max_abs_if_finite(&[-3.0]), Some(3.0));
        assert_eq!(
            max_abs_if_finite(&[1.0, -2.0, 0.5, 4.0, -7.5, 0.0]),
            Some(7.5)
        );
        assert_eq!(max_abs_if_finite(&[1.0, f64::NAN, 0.5, 4.0, 2.0]), None);
        assert_eq!(
            max_abs_if_finite(&[1.0, 2.0, 3.0, 4.0, f64::NEG_INFINITY]),
            None
        );
    }
    use nalgebra::{Matrix2, Matrix3, U2, U3, Vector2, Vector3};

    fn factored(m: Matrix3<f64>) -> Lu<U3> {
        let mut lu = Lu::new(U3);
        lu.factor(&m).expect("test matrix is regular");
        lu
    }

    #[test]
    fn solves_a_hand_checked_system() {
        // 2x + y = 5, x + 3y + z = 10.5, y + 4z = 14  →  x = 1.5, y = 2, z = 3
        let m = Matrix3::new(2.0, 1.0, 0.0, 1.0, 3.0, 1.0, 0.0, 1.0, 4.0);
        let mut b = Vector3::new(5.0, 10.5, 14.0);
        factored(m).solve_in_place(&mut b).unwrap();
        assert!((b - Vector3::new(1.5, 2.0, 3.0)).amax() < 1e-15);
    }

    #[test]
    fn determinant_sign_counts_pivot_signs_and_row_swaps() {
        // Column-major 3 × 3 matrices with known determinants, factored in place.
        let cases: [([f64; 9], f64); 3] = [
            ([2.0, 1.0, 0.0, 1.0, 3.0, 1.0, 0.0, 1.0, 4.0], 1.0), // det 18
            ([0.0, 0.0, 4.0, 1.0, 0.0, 0.0, 0.0, 2.0, 0.0], 1.0), // det 8, two swaps
            ([0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -3.0], 1.0), // det 3, one swap, U₂₂ < 0
        ];
        for (mut a, expected) in cases {
            let mut swaps = [0; 3];
            factor_in_place(&mut a, &mut swaps, 1e-13, 0.0).unwrap();
            assert_eq!(determinant_sign(&a, &swaps), expected);
        }
        let mut a = [0.0, 1.0, 1.0, 0.0]; // [[0, 1], [1, 0]]: det −1
        let mut swaps = [0; 2];
        factor_in_place(&mut a, &mut swaps, 1e-13, 0.0).unwrap();
        assert_eq!(determinant_sign(&a, &swaps), -1.0);
    }

    #[test]
    fn pivots_past_a_zero_diagonal() {
        // A permuted identity-like system: without row exchanges the first pivot would be 0.
        let m = Matrix3::new(0.0, 1.0, 0.0, 0.0, 0.0, 2.0, 4.0, 0.0, 0.0);
        let mut b = Vector3::new(7.0, 6.0, 8.0);
        let lu = factored(m);
        lu.solve_in_place(&mut b).unwrap();
        assert_eq!(b, Vector3::new(2.0, 7.0, 3.0));
        assert_eq!(lu.rough_condition(), Some(4.0));
    }

    #[test]
    fn reports_the_dependent_row_and_column() {
        // Row 2 = row 0 + row 1: elimination runs out of pivots in column 2.
        let m = Matrix3::new(1.0, 2.0, 3.0, 0.0, 1.0, 1.0, 1.0, 3.0, 4.0);
        let mut lu = Lu::new(U3);
        match lu.factor(&m) {
            Err(LuError::Singular { row, column, pivot }) => {
                assert_eq!((row, column), (2, 2));
                assert!(pivot < 1e-15);
            }
            other => panic!("expected a singular matrix, got {other:?}"),
        }
        assert!(!lu.is_factored());
        assert_eq!(
            lu.solve_in_place(&mut Vector3::zeros()),
            Err(LuError::NotFactored)
        );
    }

    #[test]
    fn tolerance_is_relative_to_the_largest_entry() {
        let tiny = Matrix3::from_diagonal_element(1e-200);
        assert!(Lu::new(U3).factor(&tiny).is_ok());
        let graded = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 1e-14));
        assert!(matches!(
            Lu::new(U3).factor(&graded),
            Err(LuError::Singular { column: 2, .. })
        ));
        assert!(matches!(
            Lu::new(U3).factor(&Matrix3::zeros()),
            Err(LuError::Singular { column: 0, .. })
        ));
    }

    #[test]
    fn names_the_remaining_row_that_depends_on_the_pivot_rows() {
        // Row 2 = row 0 / 2; row 1 is independent. After the first step both remain, and the
        // dependent one (all zero) is not the one in pivot position 1.
        let m = Matrix3::new(2.0, 1.0, 0.0, 1.0, 0.5, 1.0, 1.0, 0.5, 0.0);
        match Lu::new(U3).factor(&m) {
            Err(LuError::Singular { row, column, .. }) => assert_eq!((row, column), (2, 1)),
            other => panic!("expected a singular matrix, got {other:?}"),
        }
    }

    #[test]
    fn rank_reveal_refuses_an_elimination_that_overflows() {
        // Finite entries whose first elimination step overflows to infinity (2 · MAX).
        let big = f64::MAX;
        let m = Matrix2::new(big, big, -big, big);
        let ones = Vector2::new(1.0, 1.0);
        let result = Lu::new(U2).reveal_rank(&ones, &ones, 1e-12, |a| a.copy_from(&m));
        assert_eq!(result, Err(LuError::NonFinite));
    }

    #[test]
    fn rejects_non_finite_entries() {
        let m = Matrix3::from_diagonal_element(f64::NAN);
        assert_eq!(Lu::new(U3).factor(&m), Err(LuError::NonFinite));
    }

    #[test]
    fn refactoring_reuses_the_storage() {
        let mut lu = Lu::new(U3);
        lu.factor(&Matrix3::from_diagonal_element(2.0)).unwrap();
        lu.factor_with(|m| m.fill_with_identity()).unwrap();
        let mut b = Vector3::new(1.0, 2.0, 3.0);
        lu.solve_in_place(&mut b).unwrap();
        assert_eq!(b, Vector3::new(1.0, 2.0, 3.0));
    }

    use nalgebra::{Matrix4, SMatrix, SVector, U4, U5, U6, Vector4};

    /// max_j Σ_i |m_ij|.
    fn one_norm_of<const N: usize>(m: &SMatrix<f64, N, N>) -> f64 {
        m.column_iter()
            .map(|c| c.iter().map(|x| x.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    }

    /// A nonsymmetric, diagonally weighted 5 × 5 test matrix with small integer entries.
    fn mixed5() -> SMatrix<f64, 5, 5> {
        SMatrix::from_fn(|i, j| {
            ((7 * i + 13 * j + 3) % 11) as f64 - 5.0 + if i == j { 9.0 } else { 0.0 }
        })
    }

    /// Checks the estimate against `exact` = κ₁: a lower bound up to rounding (`slack`), and
    /// within a factor 10 of it.
    fn assert_estimate_brackets(estimate: f64, exact: f64, slack: f64) {
        assert!(
            estimate <= exact * (1.0 + slack) && estimate >= exact / 10.0,
            "estimate {estimate:e} vs exact {exact:e}"
        );
    }

    /// Rounding slack for κ₁ computed through solves: 1e-12 plus the forward-error size 64·κ·ε.
    fn slack_for(exact: f64) -> f64 {
        1e-12 + 64.0 * exact * f64::EPSILON
    }

    fn check_estimate_against_inverse<const N: usize>(m: SMatrix<f64, N, N>)
    where
        nalgebra::Const<N>: nalgebra::DimMin<nalgebra::Const<N>, Output = nalgebra::Const<N>>,
    {
        let inverse = m.try_inverse().expect("test matrix is regular");
        let exact = one_norm_of(&m) * one_norm_of(&inverse);
        let mut lu = Lu::new(nalgebra::Const::<N>);
        lu.factor(&m).unwrap();
        let estimate = lu.condition_estimate().unwrap();
        assert_estimate_brackets(estimate, exact, slack_for(exact));
    }

    #[test]
    fn condition_estimate_brackets_the_exact_condition_number() {
        check_estimate_against_inverse(Matrix3::new(4.0, 1.0, -2.0, 1.0, 3.0, 0.5, -2.0, 0.5, 5.0));
        check_estimate_against_inverse(Matrix3::new(0.0, 2.0, 1.0, 3.0, -1.0, 0.0, 1.0, 1.0, 1.0));
        check_estimate_against_inverse(mixed5());
        check_estimate_against_inverse(mixed5().transpose());
        // Upper triangular with growing off-diagonal entries: κ grows like 2ⁿ.
        check_estimate_against_inverse(SMatrix::<f64, 5, 5>::from_fn(|i, j| match i.cmp(&j) {
            core::cmp::Ordering::Less => -1.0,
            core::cmp::Ordering::Equal => 1.0,
            core::cmp::Ordering::Greater => 0.0,
        }));
    }

    #[test]
    fn condition_estimate_of_a_tiny_pivot_matrix() {
        // The 2 × 2 block has determinant 2⁻³⁰, so the LU and the inverse are exact:
        // A⁻¹ = [[2³⁰ + 1, −2³⁰], [−2³⁰, 2³⁰]] ⊕ [1].
        let delta = 2.0_f64.powi(-30);
        let m = Matrix3::new(1.0, 1.0, 0.0, 1.0, 1.0 + delta, 0.0, 0.0, 0.0, 1.0);
        let exact = (2.0 + delta) * (2.0_f64.powi(31) + 1.0);
        let mut lu = factored(m);
        let estimate = lu.condition_estimate().unwrap();
        assert_estimate_brackets(estimate, exact, 1e-12);
        assert!(estimate > 4e9);
    }

    /// Binomial coefficient, exact for the small arguments used here.
    fn binomial(n: u64, k: u64) -> u64 {
        (0..k).fold(1, |c, i| c * (n - i) / (i + 1))
    }

    #[test]
    fn condition_estimate_of_the_hilbert_matrix() {
        // 27720 = lcm(1..=11), so K = 27720·H₆ has integer entries and is stored exactly; its
        // inverse is H₆⁻¹ / 27720 with the classical integer formula for H₆⁻¹.
        const N: u64 = 6;
        let k = SMatrix::<f64, 6, 6>::from_fn(|i, j| 27720.0 / (i + j + 1) as f64);
        let hilbert_inverse = SMatrix::<f64, 6, 6>::from_fn(|i, j| {
            let (i, j) = (i as u64 + 1, j as u64 + 1);
            let magnitude = (i + j - 1)
                * binomial(N + i - 1, N - j)
                * binomial(N + j - 1, N - i)
                * binomial(i + j - 2, i - 1).pow(2);
            let sign = if (i + j) % 2 == 0 { 1.0 } else { -1.0 };
            sign * magnitude as f64
        });
        let h = k / 27720.0;
        assert!((h * hilbert_inverse - SMatrix::<f64, 6, 6>::identity()).amax() < 1e-6);
        let exact = one_norm_of(&k) * one_norm_of(&hilbert_inverse) / 27720.0;
        let mut lu = Lu::new(U6);
        lu.factor(&k).unwrap();
        let estimate = lu.condition_estimate().unwrap();
        assert_estimate_brackets(estimate, exact, slack_for(exact));
        assert!(estimate > 2e7);
    }

    #[test]
    fn condition_estimate_is_cached_per_factorisation() {
        let mut lu = Lu::new(U3);
        assert_eq!(lu.condition_estimate(), None);
        lu.factor(&Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 8.0)))
            .unwrap();
        assert_eq!(lu.condition_estimate(), Some(8.0));
        assert_eq!(lu.condition_estimate(), Some(8.0));
        lu.factor_with(|m| m.fill_with_identity()).unwrap();
        assert_eq!(lu.condition_estimate(), Some(1.0));
        assert!(lu.factor(&Matrix3::zeros()).is_err());
        assert_eq!(lu.condition_estimate(), None);
    }

    #[test]
    fn condition_estimate_handles_one_by_one_and_overflow() {
        let mut lu = Lu::new(nalgebra::U1);
        lu.factor(&nalgebra::Matrix1::new(-4.0)).unwrap();
        assert_eq!(lu.condition_estimate(), Some(1.0));
        // ‖A‖₁ · ‖A⁻¹‖₁ = 1e300 · 1e10 overflows (accepted only with a zero tolerance).
        let mut lu = Lu::new(U3);
        lu.set_pivot_tolerance(0.0);
        lu.factor(&Matrix3::from_diagonal(&Vector3::new(1e300, 1.0, 1e-10)))
            .unwrap();
        assert_eq!(lu.condition_estimate(), Some(f64::INFINITY));
    }

    /// A well-conditioned 3 × 3 matrix made badly scaled by its rows.
    fn badly_scaled() -> (Matrix3<f64>, Matrix3<f64>, Vector3<f64>) {
        let well = Matrix3::new(4.0, 1.0, -2.0, 1.0, 3.0, 0.5, -2.0, 0.5, 5.0);
        let weights = Vector3::new(1e-6, 1.0, 1e4);
        (well, Matrix3::from_diagonal(&weights) * well, weights)
    }

    #[test]
    fn scaling_undoes_bad_row_scaling_in_the_condition_estimate() {
        let (well, a, weights) = badly_scaled();
        let mut lu = Lu::new(U3);
        lu.factor(&a).unwrap();
        assert!(lu.condition_estimate().unwrap() > 1e9);

        let rows = weights.map(|w| 1.0 / w);
        lu.factor_scaled_with(&rows, &Vector3::repeat(1.0), |m| m.copy_from(&a))
            .unwrap();
        let exact = one_norm_of(&well) * one_norm_of(&well.try_inverse().unwrap());
        let estimate = lu.condition_estimate().unwrap();
        assert!(estimate < 10.0, "{estimate}");
        assert_estimate_brackets(estimate, exact, 1e-9);
        assert!(lu.rough_condition().unwrap() < 10.0);
    }

    #[test]
    fn scaled_solves_return_the_solution_of_the_original_system() {
        let (_, a, weights) = badly_scaled();
        let (rows, cols) = (weights.map(|w| 1.0 / w), Vector3::new(0.5, 4.0, 1e3));
        let mut lu = Lu::new(U3);
        lu.factor_scaled_with(&rows, &cols, |m| m.copy_from(&a))
            .unwrap();
        let expected = Vector3::new(1.5, -2.0, 0.25);

        let mut x = a * expected;
        lu.solve_in_place(&mut x).unwrap();
        assert!((x - expected).amax() < 1e-13, "{x}");

        // Aᵀ = Bᵀ diag(1e-6, 1, 1e4) is badly scaled by its columns, which the row scaling does
        // not undo: x₀ is only good to about 1e-16 · 1e10 in the forward error, so check the
        // backward error (residual against |Aᵀ| |y|) instead.
        let c = a.transpose() * expected;
        let mut y = c;
        lu.solve_transpose_in_place(&mut y).unwrap();
        let scale = (a.transpose().abs() * y.abs()).amax();
        assert!((a.transpose() * y - c).amax() < 1e-15 * scale, "{y}");
        assert!((y - expected).amax() < 1e-6, "{y}");
    }

    #[test]
    fn transpose_solve_matches_factoring_the_transpose() {
        let m = mixed5();
        let b = SVector::<f64, 5>::new(1.0, -2.0, 0.5, 3.0, -0.25);
        let mut lu = Lu::new(U5);
        lu.factor(&m).unwrap();
        let mut x = b;
        lu.solve_transpose_in_place(&mut x).unwrap();
        let mut transposed = Lu::new(U5);
        transposed.factor(&m.transpose()).unwrap();
        let mut expected = b;
        transposed.solve_in_place(&mut expected).unwrap();
        assert!((x - expected).amax() < 1e-14);
        assert!((m.transpose() * x - b).amax() < 1e-13);
        // A pivoting case: the permuted identity of `pivots_past_a_zero_diagonal`.
        let p = Matrix3::new(0.0, 1.0, 0.0, 0.0, 0.0, 2.0, 4.0, 0.0, 0.0);
        let mut c = Vector3::new(8.0, 7.0, 6.0);
        factored(p).solve_transpose_in_place(&mut c).unwrap();
        assert_eq!(p.transpose() * c, Vector3::new(8.0, 7.0, 6.0));
        assert_eq!(
            Lu::new(U3).solve_transpose_in_place(&mut c),
            Err(LuError::NotFactored)
        );
    }

    #[test]
    fn pivot_tolerance_applies_to_the_scaled_matrix() {
        let graded = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 1e-14));
        let mut lu = Lu::new(U3);
        assert!(lu.factor(&graded).is_err());
        let rows = Vector3::new(1.0, 1.0, 1e14);
        lu.factor_scaled_with(&rows, &Vector3::repeat(1.0), |m| m.copy_from(&graded))
            .unwrap();
        let mut b = Vector3::new(1.0, 2.0, 3e-14);
        lu.solve_in_place(&mut b).unwrap();
        assert!((b - Vector3::new(1.0, 2.0, 3.0)).amax() < 1e-14);
        // An unscaled refactor drops the scaling again.
        lu.factor_with(|m| m.fill_with_identity()).unwrap();
        let mut b = Vector3::new(1.0, 2.0, 3.0);
        lu.solve_in_place(&mut b).unwrap();
        assert_eq!(b, Vector3::new(1.0, 2.0, 3.0));
    }

    #[test]
    fn rejects_bad_scales_before_filling() {
        let ones = Vector3::repeat(1.0);
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, -0.0] {
            let scales = Vector3::new(1.0, bad, 1.0);
            let mut lu = Lu::new(U3);
            let mut filled = false;
            let result = lu.factor_scaled_with(&scales, &ones, |m| {
                filled = true;
                m.fill_with_identity();
            });
            assert_eq!(result, Err(LuError::NonFinite));
            assert!(!filled);
            assert_eq!(
                lu.factor_scaled_with(&ones, &scales, |m| m.fill_with_identity()),
                Err(LuError::NonFinite)
            );
            assert_eq!(
                lu.reveal_rank(&ones, &scales, 1e-12, |m| m.fill_with_identity()),
                Err(LuError::NonFinite)
            );
            assert!(!lu.is_factored());
        }
    }

    #[test]
    fn scaled_factor_rejects_non_finite_entries_and_overflow() {
        let ones = Vector3::repeat(1.0);
        let mut lu = Lu::new(U3);
        assert_eq!(
            lu.factor_scaled_with(&ones, &ones, |m| {
                m.fill_with_identity();
                m[(1, 2)] = f64::NAN;
            }),
            Err(LuError::NonFinite)
        );
        let big = Vector3::repeat(1e10);
        assert_eq!(
            lu.factor_scaled_with(&big, &ones, |m| *m = Matrix3::from_diagonal_element(1e300)),
            Err(LuError::NonFinite)
        );
        assert!(!lu.is_factored());
    }

    /// Rows 0, 1, 2 generic; row 3 = row 0 + row 2.
    fn one_dependent_row() -> Matrix4<f64> {
        Matrix4::new(
            2.0, -1.0, 0.5, 3.0, //
            1.0, 4.0, -2.0, 0.0, //
            0.0, 1.5, 3.0, -1.0, //
            2.0, 0.5, 3.5, 2.0,
        )
    }

    #[test]
    fn reveals_a_row_that_is_a_sum_of_two_others() {
        let m = one_dependent_row();
        let ones = Vector4::repeat(1.0);
        let mut lu = Lu::new(U4);
        assert_eq!(lu.dependent_rows(), &[] as &[usize]);
        assert_eq!(
            lu.reveal_rank(&ones, &ones, 1e-12, |s| s.copy_from(&m)),
            Ok(3)
        );
        let dependent = lu.dependent_rows();
        assert_eq!(dependent.len(), 1);
        assert!([0, 2, 3].contains(&dependent[0]), "{dependent:?}");
        assert_eq!(lu.undetermined_columns().len(), 1);
        // The storage now holds complete-pivoting factors: no solves with it.
        assert!(!lu.is_factored());
        assert_eq!(lu.condition_estimate(), None);
        assert_eq!(
            lu.solve_in_place(&mut Vector4::zeros()),
            Err(LuError::NotFactored)
        );
        // A regular matrix has full rank and nothing to report.
        assert_eq!(
            lu.reveal_rank(&ones, &ones, 1e-12, |s| s.fill_with_identity()),
            Ok(4)
        );
        assert!(lu.dependent_rows().is_empty() && lu.undetermined_columns().is_empty());
    }

    #[test]
    fn reveals_duplicate_rows_and_a_zero_column() {
        // Rows 1 and 4 are equal and column 2 is zero: one deficiency seen from both sides.
        let mut m = mixed5();
        m.set_row(4, &m.row(1).clone_owned());
        m.set_column(2, &SVector::zeros());
        let ones = SVector::<f64, 5>::repeat(1.0);
        let mut lu = Lu::new(U5);
        assert_eq!(
            lu.reveal_rank(&ones, &ones, 1e-12, |s| s.copy_from(&m)),
            Ok(4)
        );
        let rows = lu.dependent_rows();
        assert!(rows == [1] || rows == [4], "{rows:?}");
        assert_eq!(lu.undetermined_columns(), &[2]);

        // Also row 3 = row 0 + 2 · row 2: rank 5 − 2.
        m.set_row(3, &(m.row(0) + m.row(2) * 2.0));
        assert_eq!(
            lu.reveal_rank(&ones, &ones, 1e-12, |s| s.copy_from(&m)),
            Ok(3)
        );
        let (rows, cols) = (lu.dependent_rows(), lu.undetermined_columns());
        assert_eq!((rows.len(), cols.len()), (2, 2));
        assert!(rows.contains(&1) ^ rows.contains(&4), "{rows:?}");
        assert!(rows.iter().any(|r| [0, 2, 3].contains(r)), "{rows:?}");
        assert!(cols.contains(&2), "{cols:?}");
        assert!(rows[0] < rows[1] && cols[0] < cols[1]);
    }

    #[test]
    fn reveals_rank_zero_and_rejects_non_finite_entries() {
        let ones = Vector3::repeat(1.0);
        let mut lu = Lu::new(U3);
        assert_eq!(lu.reveal_rank(&ones, &ones, 1e-12, |s| s.fill(0.0)), Ok(0));
        assert_eq!(lu.dependent_rows(), &[0, 1, 2]);
        assert_eq!(lu.undetermined_columns(), &[0, 1, 2]);
        assert_eq!(
            lu.reveal_rank(&ones, &ones, 1e-12, |s| s.fill(f64::NAN)),
            Err(LuError::NonFinite)
        );
        assert!(lu.dependent_rows().is_empty() && lu.undetermined_columns().is_empty());
        // A NaN tolerance only counts exact zeros as negligible.
        let graded = Matrix3::from_diagonal(&Vector3::new(1.0, 1e-200, 0.0));
        assert_eq!(
            lu.reveal_rank(&ones, &ones, f64::NAN, |s| s.copy_from(&graded)),
            Ok(2)
        );
        assert_eq!(lu.dependent_rows(), &[2]);
    }

    #[test]
    fn scaling_decides_the_revealed_rank() {
        let regular = Matrix4::new(
            4.0, 1.0, 0.0, -1.0, //
            1.0, 5.0, 2.0, 0.0, //
            0.0, -1.0, 3.0, 1.0, //
            2.0, 0.0, 1.0, 6.0,
        );
        let weights = Vector4::new(1e8, 1e8, 1e8, 1e-2);
        let badly_scaled = Matrix4::from_diagonal(&weights) * regular;
        let (ones, inverse) = (Vector4::repeat(1.0), weights.map(|w| 1.0 / w));
        let mut lu = Lu::new(U4);
        // Unscaled, the small last equation drowns below the tolerance …
        assert_eq!(
            lu.reveal_rank(&ones, &ones, 1e-9, |s| s.copy_from(&badly_scaled)),
            Ok(3)
        );
        assert_eq!(lu.dependent_rows(), &[3]);
        // … scaled back, the matrix is regular …
        assert_eq!(
            lu.reveal_rank(&inverse, &ones, 1e-9, |s| s.copy_from(&badly_scaled)),
            Ok(4)
        );
        // … and a genuine dependency (row 3 ∝ row 0 + row 1) is still found.
        let mut dependent = regular;
        dependent.set_row(3, &(regular.row(0) + regular.row(1)));
        let badly_scaled = Matrix4::from_diagonal(&weights) * dependent;
        assert_eq!(
            lu.reveal_rank(&inverse, &ones, 1e-12, |s| s.copy_from(&badly_scaled)),
            Ok(3)
        );
        assert!([0, 1, 3].contains(&lu.dependent_rows()[0]));
    }

    #[cfg(feature = "alloc")]
    #[test]
    fn dynamic_sizes_are_checked() {
        use nalgebra::{DMatrix, DVector, Dyn};
        let mut lu = Lu::new(Dyn(3));
        let (three, two) = (DVector::repeat(3, 1.0), DVector::repeat(2, 1.0));
        let expected = Err(LuError::DimensionMismatch {
            expected: 3,
            found: 2,
        });
        assert_eq!(
            lu.factor_scaled_with(&two, &three, |m| m.fill_with_identity()),
            expected
        );
        assert_eq!(
            lu.factor_scaled_with(&three, &two, |m| m.fill_with_identity()),
            expected
        );
        assert_eq!(
            lu.reveal_rank(&three, &two, 0.0, |m| m.fill_with_identity())
                .map(|_| ()),
            expected
        );
        assert_eq!(
            lu.factor_scaled_with(&three, &three, |m| *m = DMatrix::identity(2, 2)),
            expected
        );
        lu.factor_scaled_with(&three, &three, |m| *m = DMatrix::identity(3, 3))
            .unwrap();
        assert_eq!(lu.solve_transpose_in_place(&mut two.clone()), expected);
        // 0 × 0 works throughout.
        let mut empty = Lu::new(Dyn(0));
        let none = DVector::<f64>::zeros(0);
        empty.factor_scaled_with(&none, &none, |_| ()).unwrap();
        assert_eq!(empty.condition_estimate(), Some(1.0));
        let mut b = none.clone();
        empty.solve_in_place(&mut b).unwrap();
        empty.solve_transpose_in_place(&mut b).unwrap();
        assert_eq!(empty.reveal_rank(&none, &none, 0.0, |_| ()), Ok(0));
    }
}
