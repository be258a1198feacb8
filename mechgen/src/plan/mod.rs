//! Planning the solve, once per scene at generation time: the stages that decide the
//! coordinates ([`structure`]) and the blocks among them solved in closed form ([`closed`]), the force solve that runs them in reverse ([`reactions`]), the
//! planned [`Scene`] that the emitter and the interpreter read, its equations of motion
//! ([`motion`]), and its operation counts ([`stats`]).

pub mod closed;
pub mod kernels;
pub mod motion;
pub mod reactions;
pub mod scene;
pub mod stats;
pub mod structure;
pub mod trig;

pub use scene::Scene;
