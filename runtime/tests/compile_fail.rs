//! Compile-fail tests of the `mechanism!` macro's diagnostics: each `ui/*.rs` case is a small
//! scene with one mistake (or, in `several_errors.rs`, several), and its `.stderr` holds the
//! expected message and span.
//!
//! Regenerate the expectations with `TRYBUILD=overwrite cargo test -p mechgen-runtime --test
//! compile_fail`, then read the diff: the caret must sit under the offending token.

#[test]
fn diagnostics() {
    // trybuild passes when a glob matches nothing: make sure this one finds the cases.
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/ui");
    let count = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .filter_map(Result::ok)
        .filter(|entry| entry.path().extension().is_some_and(|e| e == "rs"))
        .count();
    assert!(count >= 40, "only {count} compile-fail cases in {dir}");
    let cases = trybuild::TestCases::new();
    cases.compile_fail("tests/ui/*.rs");
}
