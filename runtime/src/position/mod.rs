//! The position solve of one block: Newton–Raphson on the block's unit-scaled equations, kept on
//! track by a step clamp, a backtracking line search and Levenberg–Marquardt steps where
//! Newton's cannot be used; and, when it fails, the diagnosis of why.
//!
//! The safeguards cost nothing on the usual path. A Newton step is applied without evaluating
//! the trial point first; the next iteration's evaluation, needed anyway, doubles as the line
//! search test, and only a step that failed to reduce the residual is taken back and shortened.
//!
//! A Newton iteration that crawls into its root (corrections shrinking linearly from a small
//! residual) has found a singular one: a toggle position or redundant constraints
//! ([`CRAWL_LIMIT`]).
//!
//! Stopping rule. A correction within `step_tolerance` ends the iteration when convergence is
//! evident: the correction shrank to at most a quarter of the previous one (Newton's quadratic
//! phase; a linearly converging iteration, as at a singular root, halves it at best), or, for
//! the first correction, it was taken from a point whose residual was already within
//! `residual_tolerance`. The correction is applied; its size bounds the error before it, so the
//! error after it is of the order of its square. No confirming update follows. The factors the
//! derivative solves need are those at the returned positions: when the last correction was of
//! round-off size (≤ [`NEGLIGIBLE_STEP`]), the factors it was computed with are kept (the
//! Jacobian moved by less than its own rounding); otherwise the block is evaluated and factored
//! once more at the returned positions.
//!
//! One concept per file: the Newton iteration (`newton.rs`), its start from a closed-form
//! solution where the block has one (`closed.rs`), its Levenberg–Marquardt fallback
//! (`marquardt.rs`), the errors and the diagnosis of a failed solve (`failure.rs`), and the
//! scaled norms (`norms.rs`); the tuning constants they share are here.

mod closed;
mod failure;
mod marquardt;
mod newton;
mod norms;

pub(crate) use closed::nearest;
pub(crate) use newton::{Newton, Solved};

/// Armijo constant: a step of length α must reduce the merit ‖D_r Φ_b‖₂ by at least this · α.
const SUFFICIENT_DECREASE: f64 = 1e-4;
/// Shortest fraction of a Newton step tried before switching to Levenberg–Marquardt.
const MIN_STEP_FRACTION: f64 = 1.0 / 64.0;
/// A singular Φ_q at an iterate whose scaled residual is below this is a singular solution
/// (toggle position, redundant constraints); above it, only a bad iterate to step away from.
const SINGULAR_RESIDUAL: f64 = 1e-6;
/// Levenberg–Marquardt steps in a row that reduce the merit by less than [`STALL_DECREASE`]
/// before the residual is declared a nonzero minimum ([`SolveError::NoAssembly`]).
const STALL_LIMIT: usize = 4;
const STALL_DECREASE: f64 = 1e-3;
/// A correction at most this fraction of the previous one shows quadratic convergence.
const CONTRACTION: f64 = 0.25;
/// A full Newton correction at least this fraction of the previous one, taken where the scaled
/// residual is already below [`SINGULAR_RESIDUAL`], is crawling: at a double root (a toggle
/// position) Newton halves the error at every step instead of squaring it, and rounding then
/// stops it about √ε away, where the Jacobian's condition is only ~1/√ε.
const CRAWL_RATIO: f64 = 0.4;
/// This many crawling corrections in a row identify a singular root ([`SolveError::Singular`]).
/// A regular root crawls at most while its error exceeds four times its Jacobian's smallest
/// singular value, so three in a row from a residual below [`SINGULAR_RESIDUAL`] need a
/// condition above ~1e4 as well.
const CRAWL_LIMIT: usize = 3;
/// A last correction this small (scaled) moved the Jacobian by less than its own rounding: its
/// factors serve the derivative solves at the returned positions.
pub(crate) const NEGLIGIBLE_STEP: f64 = 8.0 * f64::EPSILON;
/// Levenberg–Marquardt damping values tried for one step before the residual counts as a
/// minimum: μ grows fourfold per trial from at least 1e-12 of the largest column norm to at
/// most 1e14 of it, which takes at most 43 trials; the cap only guards that arithmetic.
const MAX_DAMPING_TRIALS: usize = 64;
