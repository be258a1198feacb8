//! The interpreter: a compiled [`mechgen::Scene`] evaluated at run time behind the runtime's
//! `Mechanism` and `Structured` traits.
//!
//! It consumes the same kernel list as the emitter (`mechgen::plan::kernels`), compiling each kernel
//! into a tape where the emitter writes a function, so the command line, the tests and the
//! report drive the one solver of `mechgen-runtime` with scenes read from `.mech` files, and
//! agree with generated code to the bit.

mod interpreted;
mod names;

pub use interpreted::Interpreted;
