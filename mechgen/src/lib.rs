//! mechgen: compiles a declarative planar mechanism into specialised, allocation-free Rust.
//!
//! The pipeline runs one way, a folder per stage, over the shared tools ([`expr`]: the
//! expression IR with its derivatives and evaluator; [`sparse`]: matching, components and the
//! static LU):
//!
//! ```text
//! tokens / .mech ─syntax─▶ Spec ─check─▶ Model ─model::kinematics─▶ Φ, Φ_q, ν, γ ─plan::structure─▶ Plan
//!   (scenes that compute forces) ─model::dynamics─▶ F ─plan::reactions─▶ reverse stages, reactions
//!   (scenes that need them) F ─model::{motion, energy}─▶ M, Q, K, C, energies ─plan::motion─▶ M v, K v, C v
//!   Scene (model, kinematics, plan, forces) ─plan::kernels─▶ kernel list ─emit─▶ Rust tokens
//!                                                                       └─(mechgen-interp)─▶ numbers
//! ```
//!
//! - [`syntax`]: the input limits, the bounded reader of `.mech` text, the grammar (documented
//!   in [`syntax::parse`]) and the [`Spec`] it builds;
//! - [`check`]: names resolved, values lowered to the IR, degrees of freedom counted, every
//!   error at its span; its result is a [`Model`];
//! - [`model`]: the checked model and what is derived from it: Φ and its derivatives, markers,
//!   the generalised forces, the run-time rules on parameters;
//! - [`plan`]: the solve planned once per scene (stages, blocks, the force solve, the kernel
//!   list) into the [`Scene`] that both consumers read, and its operation counts;
//! - [`emit`]: the scene as Rust tokens;
//! - [`builder`]: scenes assembled in code and written for a `build.rs`.
//!
//! [`compile`] and [`expand`] are the front door: one input ([`Input`]: tokens, text or a
//! parsed spec) and one set of [`Options`]. The `mechanism!` macro (crate `mechgen-macros`) is
//! a thin adapter over [`expand_or_errors`], and the `mechgen` CLI runs the same stages on
//! `.mech` files.
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
pub use plan::Scene;
pub use syntax::limits::Limits;

use model::{dynamics, kinematics};
use plan::{kernels, motion, reactions, structure};
use syntax::spec::Spec;

/// What [`compile`] and [`expand`] read.
pub enum Input<'a> {
    /// The body of a `mechanism!` invocation (or a whole `mechanism` declaration as tokens):
    /// checked against the token limits only (nesting and statement length).
    Tokens(TokenStream),
    /// The contents of a `.mech` file, read within [`Options::limits`].
    Text(&'a str),
    /// A spec already parsed, for instance read with [`syntax::source::read`] so that the
    /// errors' spans can be placed in the text.
    Spec(&'a Spec),
}

/// How [`compile`] and [`expand`] read the input and shape the generated code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Options {
    /// The size and count limits on [`Input::Text`] (nesting and statement length always
    /// apply). Text a program wrote, such as [`builder`]'s, is read with
    /// [`Limits::UNBOUNDED_SIZE`].
    pub limits: Limits,
    /// The shape of the generated code; its `naive` flag also compiles the scene into an
    /// unsimplified arena.
    pub codegen: CodegenOptions,
}

/// Reads, checks, differentiates and plans a scene: everything needed to emit or interpret
/// it.
///
/// # Errors
/// A limit exceeded or a syntax error, at its position; or every semantic error found, each
/// at its span.
pub fn compile(input: Input<'_>, options: &Options) -> Result<Scene, Errors> {
    let parsed;
    let spec = match input {
        Input::Tokens(tokens) => {
            parsed = syntax::parse::parse_tokens(tokens)?;
            &parsed
        }
        Input::Text(text) => {
            parsed = syntax::source::read(text, &options.limits).spec?;
            &parsed
        }
        Input::Spec(spec) => spec,
    };
    let arena = if options.codegen.naive {
        expr::Arena::unsimplified()
    } else {
        expr::Arena::new()
    };
    let model = check::check_into(spec, arena)?;
    Ok(scene(model, &options.codegen))
}

/// The stages after `check`: kinematics, the solve structure, for a scene that computes
/// forces its dynamics and the force solve's structure, and for one that needs them its
/// equations of motion.
fn scene(mut model: Model, codegen: &CodegenOptions) -> Scene {
    let kinematics = kinematics::derive(&mut model);
    let plan = structure::plan(&mut model, &kinematics);
    let forces = (model.outputs >= model::Outputs::Forces).then(|| {
        let generalized = dynamics::derive(&mut model);
        reactions::plan(&mut model, &kinematics, &plan, generalized)
    });
    let motion = match &forces {
        Some(forces) if motion::needs_motion(&model, codegen.equations_of_motion) => {
            Some(motion::plan(&mut model, &forces.generalized))
        }
        _ => None,
    };
    let dim = model.dim();
    let kernels = kernels::list(
        &mut model.arena,
        dim,
        &plan,
        forces.as_ref(),
        &kinematics.markers,
        &kinematics.branches,
    );
    let load_witnesses = match forces {
        Some(_) => dynamics::load_witnesses(&mut model),
        None => Vec::new(),
    };
    Scene {
        model,
        kinematics,
        plan,
        forces,
        motion,
        kernels,
        load_witnesses,
    }
}

/// The whole pipeline: [`compile`], then [`emit`] with [`Options::codegen`]. What a `build.rs`
/// writes into `OUT_DIR` (see [`builder`] for assembling large scenes in code); `pretty`
/// (feature `pretty`) formats it for reading.
///
/// # Errors
/// As [`compile`].
pub fn expand(input: Input<'_>, options: &Options) -> Result<TokenStream, Errors> {
    let scene = compile(input, options)?;
    Ok(emit::emit_with(&scene, &options.codegen))
}

/// [`expand`] for the proc macro: errors become `compile_error!`s at their spans, and a panic in
/// the generator (a bug) is reported as an internal error instead of crashing rustc's macro
/// expansion.
pub fn expand_or_errors(tokens: TokenStream) -> TokenStream {
    let result =
        std::panic::catch_unwind(move || expand(Input::Tokens(tokens), &Options::default()));
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
            super::expand(super::Input::Tokens(tokens), &super::Options::default())
                .unwrap_or_else(|e| panic!("{e}"))
                .to_string()
        };
        let first = expand();
        for _ in 0..5 {
            assert_eq!(expand(), first);
        }
    }
}
