//! The `mechanism!` procedural macro: parse nothing here, hand the tokens to `mechgen::expand`,
//! and turn its errors into `compile_error!` at their spans.

use proc_macro::TokenStream;

/// Declares a planar mechanism and generates its kinematics (Φ, Φ_q, ν, γ) as straight-line Rust.
/// Errors are reported at the offending tokens, with a hint.
///
#[doc = include_str!("../../docs/grammar.md")]
#[proc_macro]
pub fn mechanism(input: TokenStream) -> TokenStream {
    mechgen::expand_or_errors(input.into()).into()
}
