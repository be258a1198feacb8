//! `P S = L U` with partial pivoting in place on a column-major slice, and the solves with its
//! packed factors (`S y = x`, `Sᵀ y = x`) and the sign of its determinant.

use super::error::LuError;
use super::scan::max_abs_and_one_norm_if_finite;

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

/// Elimination step `k` on column-major `a` (n × n) whose pivot is already at `(k, k)`:
/// stores the multipliers below it and updates the trailing submatrix.
#[inline(always)]
pub(super) fn eliminate_step(a: &mut [f64], n: usize, k: usize) {
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
