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
//!
//! One concept per file: [`Lu`] (`matrix.rs`) owns its storage and wraps the slice kernels the
//! solver's blocks also call directly: partial-pivoting factor and solves (`factor.rs`), the
//! Hager–Higham estimate (`condition.rs`), the complete-pivoting rank reveal (`rank.rs`) and
//! the finiteness-checked magnitude scans both eliminations start with (`scan.rs`).

mod condition;
mod error;
mod factor;
mod matrix;
mod rank;
mod scan;

pub(crate) use condition::inverse_one_norm_estimate;
pub use error::LuError;
pub(crate) use factor::{
    determinant_sign, factor_in_place, solve_factors, solve_transposed_factors,
};
pub use matrix::{DEFAULT_PIVOT_TOLERANCE, Lu};
pub(crate) use rank::{reveal_rank_in_place, sort_indices};
