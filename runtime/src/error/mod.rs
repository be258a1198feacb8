//! Why a solve failed, naming the scene's equations, coordinates, branches and parameters
//! from the [`Names`] the solver attaches to every error it returns.
//!
//! One concept per file: [`SolveError`] and its API (`solve_error.rs`), the [`Quantity`] a
//! `NonFinite` error names (`quantity.rs`), where messages find names (`lookup.rs`), and the
//! messages themselves with [`Described`] (`message.rs`).

mod lookup;
mod message;
mod quantity;
mod solve_error;

pub use message::Described;
pub use quantity::{Quantity, first_load_fault};
pub use solve_error::SolveError;
