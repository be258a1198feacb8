//! Cross-crate integration tests live in `tests/`. This library compiles the README's examples
//! as doctests, so the front page cannot drift from the code, and holds the fuzzing harness the
//! CI test and the `cargo fuzz` targets share.

pub mod fuzzing;

/// A scene both as generated code (`mechanism! { … }`) and as `.mech` text for the interpreter
/// (`const $text: &str`), from one source: `twin! { TEXT, mechanism Name { … } }`.
#[macro_export]
macro_rules! twin {
    ($text:ident, $($scene:tt)*) => {
        ::mechgen_runtime::mechanism! { $($scene)* }
        const $text: &str = stringify!($($scene)*);
    };
}

#[doc = include_str!("../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
