//! The solver: unit scaling and the solve itself (its options are in `options`), which works through the scene's
//! stages in order. Each explicit stage is assigned in closed form; each block is solved by
//! Newton's method (`position`) and, right after, its velocities and accelerations are
//! solved with the same factors: a block's derivatives depend only on earlier stages, so one
//! block's factors are all the storage a solve needs.
//!
//! One concept per file: the [`Solver`] type and its API (`api.rs`), the stage sweep of a
//! full solve (`sweep.rs`), the rate solves (`rates.rs`), the velocity solve again over a full
//! solve's archived factors (`archived.rs`), the diagnosis of a singularity
//! (`diagnosis.rs`), unit scaling and distances (`scale.rs`), the checks of inputs and results
//! (`checks.rs`) and the report of a position solve (`convergence.rs`).

mod api;
mod archived;
mod checks;
mod convergence;
mod diagnosis;
mod rates;
mod scale;
mod straight;
mod sweep;

pub use api::Solver;
pub use convergence::Convergence;
pub(crate) use scale::larger;
