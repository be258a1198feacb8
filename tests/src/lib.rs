//! Cross-crate integration tests live in `tests/`. This library compiles the README's examples
//! as doctests, so the front page cannot drift from the code, and holds the fuzzing harness the
//! CI test and the `cargo fuzz` targets share.

pub mod fuzzing;

#[doc = include_str!("../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
