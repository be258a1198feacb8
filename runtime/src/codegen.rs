//! The contract with generated code: what `mechanism!` (through `mechgen`'s emitter) and the
//! interpreter (`mechgen-interp`) name to implement [`crate::Structured`], and nothing a user
//! writes.
//!
//! A scene's solve plan as the solver walks it ([`Stage`], [`Block`], [`Pattern`]), the
//! solver's scratch storage ([`Workspace`] and its implementations, with the [`Parts`] it
//! lends), the checks a scene's generated `check_geometry`, `check_physics` and `load_fault`
//! call, the context, checks and report of a scene's straight kinematic step ([`StepContext`],
//! [`StepContext::choose`]), and the elementary functions generated expressions use ([`math`]). Generated code
//! names these by absolute paths (`::mechgen_runtime::codegen::Buffers`); they change with the
//! code generator, not with the user-facing API at the crate's root.

pub mod math;
mod step;

pub use crate::dense::DenseBuffers;
pub use crate::error::first_load_fault;
pub use crate::geometry::check_geometry;
pub use crate::physics::check_physics;
pub use crate::step::{BlockScales, StepContext, StepReport};
pub use crate::structure::{Block, Pattern, Stage};
#[cfg(feature = "alloc")]
pub use crate::workspace::VecBuffers;
pub use crate::workspace::{Buffers, Parts, StepParts, Workspace};
pub use step::Choice;
