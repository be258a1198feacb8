//! Complete-pivoting elimination that reveals a matrix's numerical rank, naming its dependent
//! rows and undetermined columns, and the index sort the diagnoses use.

use super::error::LuError;
use super::factor::eliminate_step;
use super::scan::max_abs_if_finite;

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
}
