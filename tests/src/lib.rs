//! Cross-crate integration tests live in `tests/`; this library only compiles the README's
//! examples as doctests, so the front page cannot drift from the code.

#[doc = include_str!("../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
