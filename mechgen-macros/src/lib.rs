//! The `mechanism!` procedural macro: parse nothing here, hand the tokens to `mechgen::expand`,
//! and turn its errors into `compile_error!` at their spans.

use proc_macro::TokenStream;

/// Declares a planar mechanism and generates its kinematics (Φ, Φ_q, ν, γ) as straight-line Rust.
///
/// The grammar is documented in `mechgen::parse`; errors are reported at the offending tokens.
#[proc_macro]
pub fn mechanism(input: TokenStream) -> TokenStream {
    mechgen::expand_or_errors(input.into()).into()
}
