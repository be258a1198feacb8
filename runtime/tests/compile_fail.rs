//! Compile-fail tests of the `mechanism!` macro's diagnostics: each `ui/*.rs` case is a small
//! scene with one mistake (or, in `several_errors.rs`, several), and its `.stderr` holds the
//! expected message and span.
//!
//! Regenerate the expectations with `TRYBUILD=overwrite cargo test -p mechgen-runtime --test
//! compile_fail`, then read the diff: the caret must sit under the offending token.

#[test]
fn diagnostics() {
    let cases = trybuild::TestCases::new();
    cases.compile_fail("tests/ui/*.rs");
}
