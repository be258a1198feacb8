//! Sparse LU of a block with its pivot order fixed at generation time.
//!
//! [`order`] chooses the pivots: Markowitz's rule (fewest fill-in candidates, (r − 1)(c − 1))
//! among the entries that pass threshold partial pivoting (at least [`THRESHOLD`] times the
//! largest entry of their column) at a representative configuration, preferring entries that
//! are constants (a coordinate's own ±1, which never vanish). [`Factorization::new`] then
//! computes the fill-in and writes the elimination as a list of operations over value slots:
//! the Jacobian's structural non-zeros first (in the order the block's kernel writes them),
//! then the fill-in. The emitter turns that list into straight-line code; the interpreter
//! ([`Factorization::factor`], [`Factorization::solve`], [`Factorization::solve_transpose`])
//! runs it as data. Both perform the same floating-point operations in the same order.
//!
//! A static pivot that is good at one configuration can vanish at another, so the factorisation
//! checks every pivot at run time (non-negligible, and multipliers at most 1/u) and reports the
//! first that fails; the solver then refactors that block with partial pivoting.

use std::collections::{BTreeMap, BTreeSet, HashMap};

/// Threshold u of the pivot choice: an entry may pivot when it is at least u times the largest
/// entry of its column in the remaining submatrix. The runtime's default check uses the same.
pub const THRESHOLD: f64 = 0.1;

/// One elimination step: pivot on the diagonal slot, divide the column below it, update the
/// remaining submatrix.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Step {
    /// Slot of the pivot u_kk.
    pub pivot: usize,
    /// `(row i > k, slot)` of each multiplier l_ik, rows ascending.
    pub lower: Vec<(usize, usize)>,
    /// `target −= lower · upper`, column by column.
    pub updates: Vec<Update>,
}

/// `v[target] −= v[lower] · v[upper]`, or `v[target] = −(v[lower] · v[upper])` for the first
/// write of a fill-in slot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Update {
    /// Slot updated.
    pub target: usize,
    /// Slot of the multiplier l_ik.
    pub lower: usize,
    /// Slot of u_kj.
    pub upper: usize,
    /// First write of a fill-in slot (it holds no value yet).
    pub fill: bool,
}

/// A block's static LU: `A = L U` with unit lower `L`, rows and columns already in pivot order
/// (the block's local order), so that no permutation is applied at run time.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Factorization {
    /// Order of the block.
    pub n: usize,
    /// Number of Jacobian entries (the first slots).
    pub entries: usize,
    /// Number of slots, fill-in included.
    pub slots: usize,
    /// One step per pivot.
    pub steps: Vec<Step>,
    /// For each column k, `(row i < k, slot)` of U's entries above the diagonal, rows
    /// ascending: the back substitutions read U by columns.
    pub upper_columns: Vec<Vec<(usize, usize)>>,
}

/// The pivot sequence of a block: `(rows[k], columns[k])` is the k-th pivot, in the block's
/// original local indices.
///
/// `pattern[e]` is the position of entry `e`, `values[e]` its value at a representative
/// configuration and `constant[e]` whether it is a constant. Among the entries of the remaining
/// submatrix that pass the threshold test at those values, the pivot minimises the Markowitz
/// count; ties go to constants, then to the entry largest relative to its column, then to the
/// first row and column (so the order is deterministic). Entries that vanish at the
/// representative configuration are used only when a whole column does.
pub fn order(
    n: usize,
    pattern: &[(usize, usize)],
    values: &[f64],
    constant: &[bool],
) -> (Vec<usize>, Vec<usize>) {
    // The active submatrix, row-wise and column-wise: value and whether it is still a constant.
    let mut rows: Vec<BTreeMap<usize, (f64, bool)>> = vec![BTreeMap::new(); n];
    let mut columns: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
    for ((&(i, j), &value), &is_constant) in pattern.iter().zip(values).zip(constant) {
        let value = if value.is_finite() { value } else { 0.0 };
        rows[i].insert(j, (value, is_constant));
        columns[j].insert(i);
    }
    let (mut pivot_rows, mut pivot_columns) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for _ in 0..n {
        let Some((p, q)) = choose(&rows, &columns) else {
            break;
        };
        pivot_rows.push(p);
        pivot_columns.push(q);
        eliminate(&mut rows, &mut columns, p, q);
    }
    // A structurally singular block (never after a perfect matching) keeps its leftovers in
    // natural order so the result is still a permutation.
    for (chosen, len) in [(&mut pivot_rows, n), (&mut pivot_columns, n)] {
        let missing: Vec<usize> = (0..len).filter(|x| !chosen.contains(x)).collect();
        chosen.extend(missing);
    }
    (pivot_rows, pivot_columns)
}

/// A candidate pivot's rank: (vanishes at the sample, Markowitz count, not a constant, minus
/// its ratio to its column's largest entry).
type Key = (bool, usize, bool, f64);

/// The best pivot of the active submatrix; see [`order`].
fn choose(
    rows: &[BTreeMap<usize, (f64, bool)>],
    columns: &[BTreeSet<usize>],
) -> Option<(usize, usize)> {
    let column_max: Vec<f64> = columns
        .iter()
        .enumerate()
        .map(|(j, members)| {
            members
                .iter()
                .map(|&i| rows[i].get(&j).map_or(0.0, |e| e.0.abs()))
                .fold(0.0, f64::max)
        })
        .collect();
    // Smallest wins: (vanishes, Markowitz count, not constant, −ratio); then the first seen.
    let mut best: Option<(Key, (usize, usize))> = None;
    for (i, row) in rows.iter().enumerate() {
        let row_count = row.len();
        for (&j, &(value, is_constant)) in row {
            let largest = column_max[j];
            let ratio = if largest > 0.0 {
                value.abs() / largest
            } else {
                0.0
            };
            if largest > 0.0 && ratio < THRESHOLD {
                continue;
            }
            let vanishes = value == 0.0;
            let count = (row_count - 1) * (columns[j].len() - 1);
            let key: Key = (vanishes, count, !is_constant, -ratio);
            let better = match &best {
                None => true,
                Some((k, _)) => {
                    (key.0, key.1, key.2) < (k.0, k.1, k.2)
                        || ((key.0, key.1, key.2) == (k.0, k.1, k.2) && key.3 < k.3)
                }
            };
            if better {
                best = Some((key, (i, j)));
            }
        }
    }
    best.map(|(_, position)| position)
}

/// Eliminates with pivot `(p, q)` at the representative values, recording the fill-in.
fn eliminate(
    rows: &mut [BTreeMap<usize, (f64, bool)>],
    columns: &mut [BTreeSet<usize>],
    p: usize,
    q: usize,
) {
    let pivot_row = std::mem::take(&mut rows[p]);
    let pivot = pivot_row.get(&q).map_or(0.0, |e| e.0);
    for &j in pivot_row.keys() {
        columns[j].remove(&p);
    }
    let below: Vec<usize> = columns[q].iter().copied().collect();
    for i in below {
        let Some((value, _)) = rows[i].remove(&q) else {
            continue;
        };
        let multiplier = if pivot != 0.0 { value / pivot } else { 0.0 };
        for (&j, &(u, _)) in &pivot_row {
            if j == q {
                continue;
            }
            let entry = rows[i].entry(j).or_insert((0.0, false));
            *entry = (entry.0 - multiplier * u, false);
            columns[j].insert(i);
        }
    }
    columns[q].clear();
}

impl Factorization {
    /// The static factorisation of an n × n block whose entry `e` sits at `pattern[e]` (rows and
    /// columns in pivot order, so the k-th pivot is `(k, k)`); slots `0..pattern.len()` hold
    /// the entries in this order, the fill-in follows.
    pub fn new(n: usize, pattern: &[(usize, usize)]) -> Self {
        let mut slot: HashMap<(usize, usize), usize> = pattern
            .iter()
            .enumerate()
            .map(|(s, &position)| (position, s))
            .collect();
        let mut row_sets: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
        let mut column_sets: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
        for &(i, j) in pattern {
            row_sets[i].insert(j);
            column_sets[j].insert(i);
        }
        let mut slots = pattern.len();
        let mut steps = Vec::with_capacity(n);
        for k in 0..n {
            // A structurally missing pivot (only for a singular pattern) gets a slot of its
            // own; the run-time check then rejects it.
            let pivot = *slot.entry((k, k)).or_insert_with(|| {
                slots += 1;
                slots - 1
            });
            let lower_rows: Vec<usize> = column_sets[k].range(k + 1..).copied().collect();
            let upper_columns: Vec<usize> = row_sets[k].range(k + 1..).copied().collect();
            let lower = lower_rows.iter().map(|&i| (i, slot[&(i, k)])).collect();
            let mut updates = Vec::new();
            for &j in &upper_columns {
                for &i in &lower_rows {
                    let fill = !slot.contains_key(&(i, j));
                    if fill {
                        slot.insert((i, j), slots);
                        slots += 1;
                        row_sets[i].insert(j);
                        column_sets[j].insert(i);
                    }
                    updates.push(Update {
                        target: slot[&(i, j)],
                        lower: slot[&(i, k)],
                        upper: slot[&(k, j)],
                        fill,
                    });
                }
            }
            steps.push(Step {
                pivot,
                lower,
                updates,
            });
        }
        let upper_columns = (0..n)
            .map(|j| {
                column_sets[j]
                    .range(..j)
                    .map(|&i| (i, slot[&(i, j)]))
                    .collect()
            })
            .collect();
        Factorization {
            n,
            entries: pattern.len(),
            slots,
            steps,
            upper_columns,
        }
    }

    /// Number of fill-in slots.
    pub fn fill(&self) -> usize {
        self.slots - self.entries
    }

    /// The slot of each pivot, in pivot order (the runtime reads the determinant's sign from
    /// their signs).
    pub fn pivots(&self) -> Vec<usize> {
        self.steps.iter().map(|step| step.pivot).collect()
    }

    /// Number of multiply-subtract updates of the factorisation.
    pub fn updates(&self) -> usize {
        self.steps.iter().map(|s| s.updates.len()).sum()
    }

    /// Factors `v` (at least [`Factorization::slots`] long) in place: L's multipliers below the
    /// diagonal, U above, and each pivot's reciprocal on the diagonal.
    ///
    /// # Errors
    /// The first step whose pivot is not above `tiny` in magnitude or one of whose multipliers
    /// exceeds `limit` in magnitude (NaN fails both).
    // `!(x > tiny)` and `!(x <= limit)`: NaN fails the tests.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub fn factor(&self, v: &mut [f64], tiny: f64, limit: f64) -> Result<(), usize> {
        for (k, step) in self.steps.iter().enumerate() {
            let pivot = v[step.pivot];
            if !(pivot.abs() > tiny) {
                return Err(k);
            }
            // Stored as its reciprocal: one division per pivot, none in the solves.
            let inverse = 1.0 / pivot;
            v[step.pivot] = inverse;
            for &(_, s) in &step.lower {
                v[s] *= inverse;
            }
            if !step.lower.iter().all(|&(_, s)| v[s].abs() <= limit) {
                return Err(k);
            }
            for u in &step.updates {
                let product = v[u.lower] * v[u.upper];
                v[u.target] = if u.fill {
                    -product
                } else {
                    v[u.target] - product
                };
            }
        }
        Ok(())
    }

    /// Solves `A x = b` in place with the factors in `v`.
    pub fn solve(&self, v: &[f64], x: &mut [f64]) {
        for (k, step) in self.steps.iter().enumerate() {
            for &(i, s) in &step.lower {
                x[i] -= v[s] * x[k];
            }
        }
        for (k, step) in self.steps.iter().enumerate().rev() {
            x[k] *= v[step.pivot];
            for &(i, s) in &self.upper_columns[k] {
                x[i] -= v[s] * x[k];
            }
        }
    }

    /// Solves `Aᵀ x = b` in place with the factors in `v`.
    pub fn solve_transpose(&self, v: &[f64], x: &mut [f64]) {
        for (k, step) in self.steps.iter().enumerate() {
            for &(i, s) in &self.upper_columns[k] {
                x[k] -= v[s] * x[i];
            }
            x[k] *= v[step.pivot];
        }
        for (k, step) in self.steps.iter().enumerate().rev() {
            for &(i, s) in &step.lower {
                x[k] -= v[s] * x[i];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Dense column-major product of the factors, to compare against the original matrix.
    fn reconstruct(f: &Factorization, v: &[f64]) -> Vec<f64> {
        let n = f.n;
        let mut l = vec![0.0; n * n];
        let mut u = vec![0.0; n * n];
        for (k, step) in f.steps.iter().enumerate() {
            l[k + k * n] = 1.0;
            u[k + k * n] = 1.0 / v[step.pivot];
            for &(i, s) in &step.lower {
                l[i + k * n] = v[s];
            }
            for &(i, s) in &f.upper_columns[k] {
                u[i + k * n] = v[s];
            }
        }
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i + j * n] = (0..n).map(|k| l[i + k * n] * u[k + j * n]).sum();
            }
        }
        a
    }

    /// An arrow matrix: dense last row and column, diagonal elsewhere. Pivoting on the dense
    /// corner first would fill everything; Markowitz leaves it for last.
    fn arrow(n: usize) -> (Vec<(usize, usize)>, Vec<f64>) {
        let mut pattern = Vec::new();
        let mut values = Vec::new();
        for i in 0..n {
            pattern.push((i, i));
            values.push(4.0 + i as f64);
            if i + 1 < n {
                pattern.push((n - 1, i));
                values.push(1.0);
                pattern.push((i, n - 1));
                values.push(1.0);
            }
        }
        (pattern, values)
    }

    #[test]
    fn markowitz_avoids_fill_in_and_the_factors_reproduce_the_matrix() {
        let n = 6;
        let (mut pattern, values) = arrow(n);
        // Put the dense row and column first: natural order would fill the whole matrix.
        for (i, j) in &mut pattern {
            *i = n - 1 - *i;
            *j = n - 1 - *j;
        }
        let (rows, columns) = order(n, &pattern, &values, &vec![false; pattern.len()]);
        // The dense corner waits for the final 2 × 2, where every choice costs the same.
        let corner = (0..n).find(|&k| (rows[k], columns[k]) == (0, 0));
        assert!(corner >= Some(n - 2), "{rows:?} {columns:?}");
        let (rank_of_row, rank_of_column) = (inverse(&rows), inverse(&columns));
        let permuted: Vec<(usize, usize)> = pattern
            .iter()
            .map(|&(i, j)| (rank_of_row[i], rank_of_column[j]))
            .collect();
        let f = Factorization::new(n, &permuted);
        assert_eq!(f.fill(), 0);
        let mut v = values.clone();
        v.resize(f.slots, 0.0);
        f.factor(&mut v, 1e-300, 10.0).unwrap();
        let product = reconstruct(&f, &v);
        for (e, &(i, j)) in permuted.iter().enumerate() {
            assert!((product[i + j * n] - values[e]).abs() < 1e-14);
        }
    }

    fn inverse(permutation: &[usize]) -> Vec<usize> {
        let mut inverse = vec![0; permutation.len()];
        for (k, &p) in permutation.iter().enumerate() {
            inverse[p] = k;
        }
        inverse
    }

    #[test]
    fn solves_and_transposed_solves_invert_the_matrix() {
        // A 3 × 3 with fill-in in natural order.
        let pattern = vec![(0, 0), (1, 0), (2, 0), (0, 1), (1, 1), (0, 2), (2, 2)];
        let values = vec![4.0, 1.0, 2.0, 1.0, 3.0, -1.0, 5.0];
        let f = Factorization::new(3, &pattern);
        assert_eq!(f.fill(), 2, "(2, 1) and (1, 2)");
        let mut v = values.clone();
        v.resize(f.slots, 0.0);
        f.factor(&mut v, 1e-300, 10.0).unwrap();
        let dense = |i: usize, j: usize| {
            pattern
                .iter()
                .position(|&p| p == (i, j))
                .map_or(0.0, |e| values[e])
        };
        let b = [1.0, -2.0, 0.5];
        let mut x = b;
        f.solve(&v, &mut x);
        for (i, b_i) in b.iter().enumerate() {
            let ax: f64 = (0..3).map(|j| dense(i, j) * x[j]).sum();
            assert!((ax - b_i).abs() < 1e-14, "row {i}");
        }
        let mut y = b;
        f.solve_transpose(&v, &mut y);
        for (j, b_j) in b.iter().enumerate() {
            let aty: f64 = (0..3).map(|i| dense(i, j) * y[i]).sum();
            assert!((aty - b_j).abs() < 1e-14, "column {j}");
        }
    }

    #[test]
    fn small_pivots_and_large_multipliers_are_refused() {
        let pattern = vec![(0, 0), (1, 0), (0, 1), (1, 1)];
        let f = Factorization::new(2, &pattern);
        // Pivot 1e-3 under an entry of 1: multiplier 1000 > 10.
        let mut v = vec![1e-3, 1.0, 1.0, 1.0];
        assert_eq!(f.factor(&mut v, 1e-12, 10.0), Err(0));
        // A vanishing second pivot.
        let mut v = vec![1.0, 1.0, 1.0, 1.0];
        assert_eq!(f.factor(&mut v, 1e-12, 10.0), Err(1));
        let mut v = vec![f64::NAN, 1.0, 1.0, 1.0];
        assert_eq!(f.factor(&mut v, 1e-12, 10.0), Err(0));
    }

    #[test]
    fn the_threshold_steers_the_order_away_from_small_entries_and_towards_constants() {
        // Column 0 holds 0.01 (row 0) and 1 (row 1): row 0 may not pivot there.
        let pattern = vec![(0, 0), (1, 0), (0, 1), (1, 1)];
        let (rows, columns) = order(2, &pattern, &[0.01, 1.0, 1.0, 0.5], &[false; 4]);
        assert_ne!((rows[0], columns[0]), (0, 0));
        assert_ne!((rows[1], columns[1]), (0, 0));
        // Equal counts and magnitudes: the constant entry wins.
        let (rows, columns) = order(
            2,
            &pattern,
            &[1.0, 1.0, 1.0, 1.0],
            &[false, false, true, false],
        );
        assert_eq!((rows[0], columns[0]), (0, 1));
    }
}
