//! The Hager–Higham estimate of `‖S⁻¹‖₁` (LAPACK `dlacn2`) from a few solves with `S` and `Sᵀ`.

use core::ops::ControlFlow;

/// Iteration limit of the 1-norm estimator, as LAPACK's `dlacn2` (`ITMAX`).
const ESTIMATOR_ITERATIONS: usize = 5;

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
        None => match cold_start(x, signs, &mut solve, &mut solve_transposed) {
            ControlFlow::Continue(start) => start,
            ControlFlow::Break(result) => return result,
        },
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
        if same_signs(x, signs) || !improved || n == 1 {
            break;
        }
        take_signs(x, signs);
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
    let alternative = alternating_sign_bound(x, solve);
    if !alternative.is_finite() {
        return (f64::INFINITY, best);
    }
    (estimate.max(alternative), best)
}

/// The estimator's first power step from the uniform vector (no hint): the first bound and the
/// column to try next (`Continue`), or the final answer (`Break`: a 1 × 1 matrix, or a solve
/// that produced a non-finite value).
fn cold_start(
    x: &mut [f64],
    signs: &mut [f64],
    mut solve: impl FnMut(&mut [f64]),
    mut solve_transposed: impl FnMut(&mut [f64]),
) -> ControlFlow<(f64, usize), (f64, usize)> {
    let n = x.len();
    // 1.0 / n as the start vector: `n as f64` is exact for any size that fits in memory.
    x.fill(1.0 / n as f64);
    solve(x);
    let estimate = one_norm(x);
    if !estimate.is_finite() {
        return ControlFlow::Break((f64::INFINITY, 0));
    }
    if n == 1 {
        return ControlFlow::Break((estimate, 0));
    }
    take_signs(x, signs);
    solve_transposed(x);
    let Some(j) = index_of_max_abs(x) else {
        return ControlFlow::Break((f64::INFINITY, 0));
    };
    ControlFlow::Continue((estimate, j))
}

/// The lower bound from the alternating-sign vector x_i = ±(1 + i/(n−1)), ‖x‖₁ = 3n/2 (n ≥ 2):
/// it catches matrices where the iteration stalls on a poor local maximum. Non-finite if the
/// solve overflows.
fn alternating_sign_bound(x: &mut [f64], mut solve: impl FnMut(&mut [f64])) -> f64 {
    let n = x.len();
    let last = (n - 1) as f64;
    let mut alternating = 1.0;
    for (i, x_i) in x.iter_mut().enumerate() {
        *x_i = alternating * (1.0 + i as f64 / last);
        alternating = -alternating;
    }
    solve(x);
    2.0 * one_norm(x) / (3.0 * n as f64)
}

/// ξ = sign(x), into `signs` and into `x` (the next right-hand side).
fn take_signs(x: &mut [f64], signs: &mut [f64]) {
    for (x_i, s_i) in x.iter_mut().zip(signs.iter_mut()) {
        *s_i = sign(*x_i);
        *x_i = *s_i;
    }
}

/// Whether sign(x) is the sign vector `signs` already holds.
fn same_signs(x: &[f64], signs: &[f64]) -> bool {
    x.iter()
        .zip(signs.iter())
        .all(|(&x_i, &s_i)| sign(x_i) == s_i)
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
