//! An n-stage scissor lift too big to write by hand: `build.rs` assembles it with
//! `mechgen::builder` (in `scene.rs`) and writes the generated code to `$OUT_DIR/scissor.rs`,
//! which this crate includes. n is the `MECHGEN_SCISSOR_STAGES` environment variable at build
//! time (default 4).
//!
//! The recipe, for any crate depending on `mechgen-runtime` (and on `mechgen` as a
//! build-dependency):
//!
//! ```ignore
//! // build.rs
//! fn main() -> Result<(), Box<dyn std::error::Error>> {
//!     let mut scene = mechgen::builder::SceneBuilder::new("Lift");
//!     // … scene.body(…), scene.revolute(…), … in loops …
//!     scene.write_to_out_dir("lift.rs", &mechgen::CodegenOptions::default())?;
//!     Ok(())
//! }
//!
//! // src/lib.rs
//! include!(concat!(env!("OUT_DIR"), "/lift.rs"));
//! ```
//!
//! The geometry and its closed form are in [`geometry`]; the generated [`ScissorLift`] solves
//! with `mechgen_runtime::{Solver, Simulation}` like any other scene.

pub mod geometry;

include!(concat!(env!("OUT_DIR"), "/scissor.rs"));

/// Number of stages the included scene was built with: its bodies are the ground `base`, the
/// `slider`, two links per stage, the `platform` and the `roller`.
pub const STAGES: usize = (ScissorLift::DIM - geometry::EXTRA_COORDINATES) / 6;
