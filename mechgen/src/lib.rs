//! mechgen: compiles a declarative planar mechanism into specialised, allocation-free Rust.
//!
//! The pipeline runs one way, one module per stage:
//!
//! ```text
//! tokens / .mech ─parse─▶ Spec ─check─▶ Model ─kinematics─▶ Φ, Φ_q, ν, γ (IR) ─structure─▶ Plan
//!        (scenes that compute forces) ─dynamics─▶ F ─reactions─▶ reverse stages, reactions
//!                                                  ─emit─▶ Rust tokens
//!                                                  └─interpret─▶ numbers
//! ```
//!
//! [`expand`] is that pipeline; the `mechanism!` macro (crate `mechgen-macros`) is a thin
//! adapter over it, and the `mechgen` CLI runs the same stages on `.mech` files. The grammar is
//! documented in [`parse`].
#![deny(missing_docs)]

pub mod builder;
pub mod check;
pub mod emit;
pub mod error;
pub mod expr;
pub mod model;
pub mod plan;
pub mod sparse;
pub mod syntax;

use proc_macro2::TokenStream;

pub use emit::CodegenOptions;
pub use error::Errors;
pub use model::Model;
pub use model::kinematics::Kinematics;
use model::{dynamics, kinematics};
pub use plan::Scene;
use plan::{reactions, structure};
use syntax::{limits, parse, source, spec};

/// Parses, checks and differentiates a spec given as tokens.
///
/// # Errors
/// A syntax error, or every semantic error found, each at its span.
pub fn compile(tokens: TokenStream) -> Result<Scene, Errors> {
    let spec = parse::parse_tokens(tokens)?;
    scene(&spec)
}

/// Parses, checks and differentiates a spec given as text (the contents of a `.mech` file).
///
/// # Errors
/// As [`compile`].
pub fn compile_str(source: &str) -> Result<Scene, Errors> {
    let spec = source::parse_str(source)?;
    scene(&spec)
}

/// Checks and differentiates a parsed spec (read from text with [`source::read`], whose
/// locations place the errors' spans in the text).
///
/// # Errors
/// Every semantic error found, each at its span.
pub fn compile_spec(spec: &spec::Spec) -> Result<Scene, Errors> {
    scene(spec)
}

fn scene(spec: &spec::Spec) -> Result<Scene, Errors> {
    let model = check::check(spec)?;
    Ok(Scene::derive(model))
}

impl Scene {
    /// The stages after `check`: kinematics, the solve structure, and for a scene that
    /// computes forces its dynamics and the force solve's structure.
    fn derive(mut model: Model) -> Self {
        let kinematics = kinematics::derive(&mut model);
        let mut plan = structure::plan(&mut model, &kinematics);
        let forces = (model.outputs >= model::Outputs::Forces).then(|| {
            let generalized = dynamics::derive(&mut model);
            let forces = reactions::plan(&mut model, &kinematics, &plan, generalized);
            let reads: Vec<expr::Id> = kinematics
                .markers
                .iter()
                .chain(forces.kernel_roots())
                .copied()
                .collect();
            let n = model.dim();
            plan.cache_final_reads(&mut model.arena, n, &reads);
            forces
        });
        let load_witnesses = match forces {
            Some(_) => dynamics::load_witnesses(&mut model),
            None => Vec::new(),
        };
        Scene {
            model,
            kinematics,
            plan,
            forces,
            load_witnesses,
        }
    }
}

/// The whole pipeline: spec tokens to generated Rust tokens.
///
/// # Errors
/// As [`compile`].
pub fn expand(tokens: TokenStream) -> Result<TokenStream, Errors> {
    let scene = compile(tokens)?;
    Ok(emit::emit(&scene))
}

/// [`expand`] for the proc macro: errors become `compile_error!`s at their spans, and a panic in
/// the generator (a bug) is reported as an internal error instead of crashing rustc's macro
/// expansion.
pub fn expand_or_errors(tokens: TokenStream) -> TokenStream {
    let result = std::panic::catch_unwind(move || expand(tokens));
    match result {
        Ok(Ok(code)) => code,
        Ok(Err(errors)) => errors.to_compile_errors(),
        Err(_) => syn::Error::new(
            proc_macro2::Span::call_site(),
            "internal error in mechgen (a bug): please report this scene",
        )
        .to_compile_error(),
    }
}

/// Parses, checks and differentiates a `.mech` source for emission with `options` (the naive
/// baseline compiles into an unsimplified arena). The text is read without the size and count
/// limits (nesting and statement length still apply): this is the path for scenes a program
/// writes, such as `builder`'s.
///
/// # Errors
/// As [`compile_str`].
pub fn compile_str_with(source: &str, options: &emit::CodegenOptions) -> Result<Scene, Errors> {
    // Text a program wrote (`builder`, a build script): size and count are the caller's call.
    let spec = source::read(source, &limits::Limits::UNBOUNDED_SIZE).spec?;
    let arena = if options.naive {
        expr::Arena::unsimplified()
    } else {
        expr::Arena::new()
    };
    let model = check::check_into(&spec, arena)?;
    Ok(Scene::derive(model))
}

/// Generated code for a `.mech` source with explicit options, as tokens: what a `build.rs`
/// writes into `OUT_DIR` (see the `builder` module for assembling large scenes in code).
///
/// # Errors
/// As [`compile_str`].
pub fn expand_str_with(
    source: &str,
    options: &emit::CodegenOptions,
) -> Result<TokenStream, Errors> {
    let scene = compile_str_with(source, options)?;
    Ok(emit::emit_with(&scene, options))
}

/// Generated code for a `.mech` source, formatted for reading (CLI `expand`, snapshots).
///
/// # Errors
/// As [`compile_str`].
#[cfg(feature = "pretty")]
pub fn expand_pretty(source: &str) -> Result<String, Errors> {
    let scene = compile_str(source)?;
    Ok(pretty(emit::emit(&scene)))
}

/// Formats generated tokens with prettyplease.
#[cfg(feature = "pretty")]
pub fn pretty(tokens: TokenStream) -> String {
    match syn::parse2::<syn::File>(tokens.clone()) {
        Ok(file) => prettyplease::unparse(&file),
        Err(_) => tokens.to_string(),
    }
}

#[cfg(test)]
mod tests {
    /// Same input, byte-identical output: every arena and name table below is a fresh
    /// `HashMap`/`HashSet` with its own random seed, so any hash-order dependence would show.
    #[test]
    fn expansion_is_deterministic() {
        let source = "/// Doc.
            pub mechanism M {
                param w = 2;
                ground frame at (0, 0, 0);
                body crank near (0, 0, 0);
                body slider near (3, 0, 0);
                joint pivot: revolute(frame, crank);
                joint guide: prismatic(frame, slider, along (1, 0));
                joint rod: distance(crank @ (1, 0), slider, 2.5);
                driver spin: angle(crank) = w * t + sin(t)^2;
            }";
        let expand = || {
            let tokens: proc_macro2::TokenStream = source.parse().expect("lexes");
            super::expand(tokens)
                .unwrap_or_else(|e| panic!("{e}"))
                .to_string()
        };
        let first = expand();
        for _ in 0..5 {
            assert_eq!(expand(), first);
        }
    }
}
