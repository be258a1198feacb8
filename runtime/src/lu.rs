//! LU factorisation with partial pivoting and a relative singularity test, reusable without allocation.

use nalgebra::{DefaultAllocator, Dim, OVector, U1};

use crate::mechanism::{Matrix, Storage, Vector};

/// Default relative pivot tolerance; see [`Lu::set_pivot_tolerance`].
///
/// About 450 ε: round-off pivots of an exactly singular, well-scaled n × n Jacobian stay a few
/// n·ε·max|a| in size, while genuine near-toggle pivots (sin of a small angle times a length)
/// remain well above it until the angle is below ~1e-12 rad.
pub const DEFAULT_PIVOT_TOLERANCE: f64 = 1e-13;

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
    /// The matrix has a NaN or infinite entry.
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

/// Packed `P A = L U` factorisation (unit lower `L` below the diagonal, `U` on and above it).
///
/// Storage is allocated once by [`Lu::new`]; [`Lu::factor`] and [`Lu::factor_with`] overwrite it,
/// so a solver can refactor every Newton iteration without touching the heap.
#[derive(Debug, Clone)]
pub struct Lu<D: Dim>
where
    DefaultAllocator: Storage<D>,
{
    lu: Matrix<D>,
    /// LAPACK-style swap sequence: at step `k`, row `k` was exchanged with row `swaps[k]`.
    /// Kept as swaps rather than a permutation so solves (and a future transpose solve for the
    /// 1-norm condition estimator) permute in place without scratch space.
    swaps: OVector<usize, D>,
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
            pivot_tolerance: DEFAULT_PIVOT_TOLERANCE,
            pivot_range: None,
        }
    }

    /// The relative pivot tolerance.
    pub fn pivot_tolerance(&self) -> f64 {
        self.pivot_tolerance
    }

    /// Sets the relative pivot tolerance τ: a pivot counts as zero when
    /// `|u_kk| ≤ τ · n · max|a_ij|` (max over the matrix before elimination).
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

    /// Rough condition estimate `max|u_kk| / min|u_kk|` of the last successful factorisation.
    ///
    /// A lower bound on the 2-norm condition number that can underestimate it badly; treat it
    /// as a warning sign, not a bound. `None` if there is no successful factorisation.
    pub fn rough_condition(&self) -> Option<f64> {
        self.pivot_range
            .map(|(min, max)| if max == 0.0 { 1.0 } else { max / min })
    }

    /// Copies `matrix` into the internal storage and factors it.
    ///
    /// # Errors
    /// [`LuError::DimensionMismatch`] if `matrix` is not the size given to [`Lu::new`], otherwise
    /// as [`Lu::factor_with`].
    pub fn factor(&mut self, matrix: &Matrix<D>) -> Result<(), LuError> {
        let n = self.lu.nrows();
        if matrix.shape() != (n, n) {
            self.pivot_range = None;
            return Err(LuError::DimensionMismatch {
                expected: n,
                found: matrix.nrows(),
            });
        }
        self.factor_with(|storage| storage.copy_from(matrix))
    }

    /// Lets `fill` write the matrix straight into the internal storage, then factors it.
    ///
    /// This is how the solver evaluates Φ_q without keeping a second n × n matrix around.
    ///
    /// # Errors
    /// [`LuError::NonFinite`] for NaN or infinite entries, [`LuError::Singular`] when a column
    /// has no pivot above the tolerance, [`LuError::DimensionMismatch`] if `fill` replaced the
    /// storage with a matrix of another size.
    pub fn factor_with(&mut self, fill: impl FnOnce(&mut Matrix<D>)) -> Result<(), LuError> {
        self.pivot_range = None;
        fill(&mut self.lu);
        let n = self.swaps.nrows();
        if self.lu.shape() != (n, n) {
            return Err(LuError::DimensionMismatch {
                expected: n,
                found: self.lu.nrows(),
            });
        }

        // Plain slices, column-major (a[i + j·n] is row i, column j): nalgebra's element
        // iterators and tuple indexing cost an order of magnitude more in these loops.
        let a = self.lu.as_mut_slice();
        let Some(largest) = max_abs_if_finite(a) else {
            return Err(LuError::NonFinite);
        };
        // `n as f64` is exact for any size that fits in memory.
        let threshold = self.pivot_tolerance * n as f64 * largest;
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
                    row: self.likeliest_dependent_row(k),
                    column: k,
                    pivot: best,
                });
            }
            self.swaps[k] = pivot_row;
            if pivot_row != k {
                for j in 0..n {
                    a.swap(j * n + k, j * n + pivot_row);
                }
            }
            (min_pivot, max_pivot) = (min_pivot.min(best), max_pivot.max(best));

            let pivot = a[column_k + k];
            for i in k + 1..n {
                a[column_k + i] /= pivot;
            }
            // Column-oriented update; Jacobians are sparse, so whole columns are skipped when the
            // pivot row has a structural zero there.
            let (left, right) = a.split_at_mut(column_k + n);
            let l = &left[column_k + k + 1..column_k + n];
            for column in right.chunks_exact_mut(n) {
                let u_kj = column[k];
                if u_kj != 0.0 {
                    for (x, &l_ik) in column[k + 1..].iter_mut().zip(l) {
                        *x -= l_ik * u_kj;
                    }
                }
            }
        }
        self.pivot_range = Some((min_pivot, max_pivot));
        Ok(())
    }

    /// Overwrites `b` with the solution `x` of `A x = b`.
    ///
    /// # Errors
    /// [`LuError::NotFactored`] without a successful factorisation, [`LuError::DimensionMismatch`]
    /// if `b` has the wrong length.
    pub fn solve_in_place(&self, b: &mut Vector<D>) -> Result<(), LuError> {
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
        let (a, x) = (self.lu.as_slice(), b.as_mut_slice());
        for (k, &swap) in self.swaps.as_slice().iter().enumerate() {
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
        Ok(())
    }

    /// Among rows `k..n` after `k` elimination steps, the original index of the one whose
    /// remaining entries are smallest: it is (nearly) a combination of the pivot rows already used.
    fn likeliest_dependent_row(&self, k: usize) -> usize {
        let n = self.lu.nrows();
        let mut best = (k, f64::INFINITY);
        for i in k..n {
            let size = (k..n).fold(0.0_f64, |m, j| m.max(self.lu[(i, j)].abs()));
            if size < best.1 {
                best = (i, size);
            }
        }
        // Undo the swaps of steps 0..k to find where that row started.
        let mut row = best.0;
        for (step, &swap) in self.swaps.iter().enumerate().take(k).rev() {
            if row == step {
                row = swap;
            } else if row == swap {
                row = step;
            }
        }
        row
    }
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

#[cfg(test)]
mod tests {
    use super::*;

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
    use nalgebra::{Matrix3, U3, Vector3};

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
}
