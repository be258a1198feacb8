//! The straight kinematic step as code: for a scene whose every block has a closed form and
//! whose outputs are the accelerations or the forces, `Structured::straight_step`, one
//! function that runs the stages in the sweep's order by calling their kernels directly (no
//! dispatch on the stage index), with the trig cache viewed as its array once. Each block
//! takes its closed-form solution under the runtime's checks
//! (`::mechgen_runtime::codegen::{choose, StepContext}`), factors its Jacobian with its static
//! LU and solves its rates with those factors; a scene that computes forces also archives
//! the factors for the runtime's force solve (in the sweep's layout). A failed check restores
//! the guess and returns the stage: the solver then runs the stage sweep.

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::body::Context;
use super::idx;
use super::plan::{Kernel, named_kernel_function};
use super::step_forces::{ForceSolve, archive_ranges, straight_forces, straight_velocities};
use crate::expr::Id;
use crate::model::{Outputs, Unit};
use crate::plan::kernels::{Buffer, Kernels, Method, StageKernel, StageShape};
use crate::plan::trig::Phase;

/// The straight step of a scene that can have one: the inherent function that runs the
/// stages, and the `Structured` method that calls it and restores the guess when it fails
/// (with, for a scene that computes forces, `straight_velocities`).
/// `functions` are the kernels' functions, in `kernels.stages` order.
pub(super) fn straight_step(
    cx: &Context<'_>,
    kernels: &Kernels,
    functions: &[(TokenStream, Kernel)],
) -> Option<(TokenStream, TokenStream)> {
    // The solver takes the step for a full solve only (fewer outputs keep the sweep).
    if cx.model.outputs < Outputs::Accelerations {
        return None;
    }
    let functions: Vec<&Kernel> = functions.iter().map(|(_, f)| f).collect();
    let mut stages = Stages::of(cx, kernels, &functions)?;
    let mut methods = trait_method();
    if cx.model.outputs == Outputs::Forces {
        stages.forces = Some(straight_forces(cx, kernels, &functions)?);
        methods.extend(straight_velocities(cx, kernels, &functions)?);
    }
    Some((stages.function(cx, kernels, &functions), methods))
}

/// The step's stages as code, the Jacobian variants its blocks call, and, for a scene that
/// computes forces, its force solve (`straight_forces`).
struct Stages {
    code: Vec<TokenStream>,
    variants: Vec<TokenStream>,
    blocks: bool,
    forces: Option<ForceSolve>,
}

impl Stages {
    /// Every stage's part of the step; `None` if a block has no closed form or static LU.
    fn of(cx: &Context<'_>, kernels: &Kernels, functions: &[&Kernel]) -> Option<Self> {
        let mut stages = Stages {
            code: Vec::new(),
            variants: Vec::new(),
            blocks: false,
            forces: None,
        };
        let forces = cx.model.outputs == Outputs::Forces;
        let archive = archive_ranges(kernels);
        for (s, shape) in kernels.shapes.iter().enumerate() {
            let mut calls = StageCalls::of(kernels, functions, s);
            stages.code.push(match &shape.block {
                None => calls.explicit(),
                Some(block) => {
                    stages.blocks = true;
                    let solved = solved_jacobian(cx, kernels, s);
                    let trig_first = solved.is_some();
                    if let Some((function, kernel)) = solved {
                        stages.variants.push(function);
                        calls.replace(Method::Jacobian, kernel.call());
                    }
                    let block = BlockStep {
                        factorization: block.factorization?,
                        trig_first,
                        archive: archive[s].clone().filter(|_| forces),
                    };
                    block_step(cx, kernels, s, &calls, block)?
                }
            });
        }
        Some(stages)
    }

    /// `straight_stages`, the inherent function that runs them, then the end checks; and the
    /// Jacobian variants, and the force solve's function with its call at the end. Parameters
    /// no kernel reads are named `_t`, `_report`, `_forces`.
    fn function(&self, cx: &Context<'_>, kernels: &Kernels, functions: &[&Kernel]) -> TokenStream {
        let reads = |name: &str| functions.iter().any(|f| f.arguments.contains(&name));
        let (t, report) = (unused(reads("t"), "t"), unused(self.blocks, "report"));
        let forces = unused(self.forces.is_some(), "forces");
        let (storage, force_solve) = self.forces.as_ref().map(|f| (&f.storage, &f.call)).unzip();
        let force_function = self.forces.as_ref().map(|f| &f.function);
        let view = reads("trig").then(|| trig_view(kernels, true));
        let vector = cx.vector_type();
        let (stages, variants) = (&self.code, &self.variants);
        let EndChecks {
            lengths,
            angles,
            rates,
        } = EndChecks::of(cx, kernels);
        quote! {
            /// The straight kinematic step's stages, in solve order (see
            /// `Structured::straight_step`).
            #[allow(clippy::too_many_arguments)]
            fn straight_stages(
                &self,
                #t: f64,
                q: &mut #vector,
                qd: &mut #vector,
                qdd: &mut #vector,
                trig_cache: &mut [f64],
                #forces: &mut [f64],
                context: &::mechgen_runtime::codegen::StepContext,
                #report: &mut ::mechgen_runtime::codegen::StepReport,
            ) -> ::core::result::Result<(), usize> {
                #view
                #storage
                #(#stages)*
                let end = Self::STAGES.len();
                context.check_rounding(end, &[#(#lengths),*], &[#(#angles),*])?;
                context.check_end(end, self, q, &[#(#rates),*], trig_cache)?;
                #force_solve
                ::core::result::Result::Ok(())
            }
            #(#variants)*
            #force_function
        }
    }
}

/// What the step's end checks read: the positions of each unit the rounding bound applies to
/// (a constant 0 always passes), and the rates the explicit stages compute that are not
/// constants (the blocks' rates are checked as they are solved).
struct EndChecks {
    lengths: Vec<TokenStream>,
    angles: Vec<TokenStream>,
    rates: Vec<TokenStream>,
}

impl EndChecks {
    fn of(cx: &Context<'_>, kernels: &Kernels) -> Self {
        let arena = cx.arena();
        let constant = |root: Id| arena.as_const(root).filter(|c| c.is_finite());
        let written = |methods: &[Method], keep: &dyn Fn(Id) -> bool| -> Vec<(Buffer, usize)> {
            let kernels = kernels
                .stages
                .iter()
                .filter(|k| methods.contains(&k.method));
            kernels
                .flat_map(|k| k.kernel.roots.iter().zip(&k.kernel.outputs))
                .filter(|&(&root, _)| keep(root))
                .map(|(_, &output)| output)
                .collect()
        };
        let zeros = written(&[Method::Positions], &|root| constant(root) == Some(0.0));
        let units = cx.model.coordinate_units();
        let (mut lengths, mut angles) = (Vec::new(), Vec::new());
        for (c, &unit) in units.iter().enumerate() {
            if zeros.contains(&(Buffer::Q, c)) {
                continue;
            }
            let c = idx(c);
            match unit {
                Unit::Angle => angles.push(quote!(q[#c])),
                _ => lengths.push(quote!(q[#c])),
            }
        }
        let rates = written(&[Method::Velocities, Method::Accelerations], &|root| {
            constant(root).is_none()
        })
        .into_iter()
        .map(|(buffer, c)| {
            let (name, c) = (format_ident!("{}", buffer.name()), idx(c));
            quote!(#name[#c])
        })
        .collect();
        EndChecks {
            lengths,
            angles,
            rates,
        }
    }
}

/// `Structured::straight_step`: the stages, with the guess restored where they fail.
fn trait_method() -> TokenStream {
    let vector = quote!(::mechgen_runtime::Vector<Self::Dim>);
    quote! {
        fn straight_step(
            &self,
            t: f64,
            q: &mut #vector,
            qd: &mut #vector,
            qdd: &mut #vector,
            trig: &mut [f64],
            forces: &mut [f64],
            context: &::mechgen_runtime::codegen::StepContext,
            report: &mut ::mechgen_runtime::codegen::StepReport,
        ) -> ::core::result::Result<(), usize> {
            // The sweep that runs where the step fails checks and reads the guess as given.
            let guess = *q;
            let result = self.straight_stages(t, q, qd, qdd, trig, forces, context, report);
            if result.is_err() {
                *q = guess;
            }
            result
        }
    }
}

/// `trig`: the trig cache `trig_cache` viewed as the array the kernels take, `mutable` where
/// the stages fill it.
pub(super) fn trig_view(kernels: &Kernels, mutable: bool) -> TokenStream {
    let trig_len = idx(kernels.sizes.trig);
    let chunk = if mutable {
        quote!(first_chunk_mut)
    } else {
        quote!(first_chunk)
    };
    quote! {
        let ::core::option::Option::Some(trig) = trig_cache.#chunk::<#trig_len>() else {
            return ::core::result::Result::Err(0);
        };
    }
}

/// `name`, or `_name` where it is not used (a parameter of generated code).
pub(super) fn unused(used: bool, name: &str) -> Ident {
    format_ident!("{}{}", if used { "" } else { "_" }, name)
}

/// `context.scales(…)`: a block's row and column scales, from its equations' and
/// coordinates' units.
pub(super) fn block_scales(cx: &Context<'_>, shape: &StageShape) -> TokenStream {
    let unit = |u: Unit| {
        let variant = format_ident!("{}", u.name());
        quote!(::mechgen_runtime::Unit::#variant)
    };
    let (coordinate_units, equation_units) =
        (cx.model.coordinate_units(), cx.model.equation_units());
    let equations = shape.equations.iter().map(|&e| unit(equation_units[e]));
    let coordinates = shape.coordinates.iter().map(|&c| unit(coordinate_units[c]));
    quote!(context.scales([#(#equations),*], [#(#coordinates),*]))
}

/// A stage's kernel calls, by method.
pub(super) struct StageCalls {
    calls: Vec<(Method, TokenStream)>,
}

impl StageCalls {
    /// The calls of stage `s`'s kernels.
    pub(super) fn of(kernels: &Kernels, functions: &[&Kernel], s: usize) -> Self {
        let calls = kernels
            .stages
            .iter()
            .zip(functions)
            .filter(|(k, _): &(&StageKernel, _)| k.stage == s)
            .map(|(k, f)| (k.method, f.call()))
            .collect();
        Self { calls }
    }

    /// Calls `call` for `method` instead of the stage's own kernel.
    fn replace(&mut self, method: Method, call: TokenStream) {
        for (m, c) in &mut self.calls {
            if *m == method {
                *c = call.clone();
            }
        }
    }

    /// `call;` for the stage's kernel of `method`, nothing without one.
    pub(super) fn call(&self, method: Method) -> TokenStream {
        let call = self.calls.iter().find(|(m, _)| *m == method);
        call.map(|(_, c)| quote!(#c;)).unwrap_or_default()
    }

    /// An explicit stage: positions, trig, velocities, accelerations.
    fn explicit(&self) -> TokenStream {
        let calls = [
            Method::Positions,
            Method::FillTrig,
            Method::Velocities,
            Method::Accelerations,
        ]
        .map(|m| self.call(m));
        quote!(#(#calls)*)
    }
}

/// Block `s`'s Jacobian kernel reading its own angles' sines and cosines from the trig cache
/// (filled at the chosen solution before it runs), where it has any: the function and its
/// call. In the straight step the solution is final when the Jacobian is evaluated, so each
/// angle's `sin_cos` is computed once, by the trig fill, for the Jacobian and the rates.
fn solved_jacobian(cx: &Context<'_>, kernels: &Kernels, s: usize) -> Option<(TokenStream, Kernel)> {
    let k = kernels
        .stages
        .iter()
        .find(|k| k.stage == s && k.method == Method::Jacobian)?;
    let cached = kernels
        .trig
        .reads(cx.arena(), &k.kernel.roots, s, Phase::After);
    if cached.len() == k.kernel.cached.len() {
        return None;
    }
    let mut solved = k.clone();
    solved.kernel.cached = cached;
    let naming = (
        "solved_jacobian",
        "the block's residual and Jacobian at its solved positions, its own sines and cosines \
         read from the cache",
    );
    Some(named_kernel_function(cx, kernels, &solved, naming))
}

/// How a block's step is made.
struct BlockStep {
    /// The block's static LU (`factor_k`, `solve_k`).
    factorization: usize,
    /// Whether the trig cache is filled from the choice before the Jacobian, which reads it.
    trig_first: bool,
    /// Where its factors go in the force solve's archive, for a scene that computes forces.
    archive: Option<core::ops::Range<usize>>,
}

/// A block's part of the step: candidates → choice → (trig from the choice's unit vectors,
/// when the Jacobian reads it) → Jacobian and Φ at the choice → scaled factors → checks →
/// (archived factors) → (trig) → rates by the static LU.
/// `None` for a block without a closed form.
// Kept whole: most of it is the block's template, which reads best in one piece.
fn block_step(
    cx: &Context<'_>,
    kernels: &Kernels,
    s: usize,
    calls: &StageCalls,
    step: BlockStep,
) -> Option<TokenStream> {
    let BlockStep {
        factorization,
        trig_first,
        archive,
    } = step;
    let shape = &kernels.shapes[s];
    let block = shape.block.as_ref()?;
    if !calls.calls.iter().any(|(m, _)| *m == Method::ClosedForm) {
        return None;
    }
    let n = shape.coordinates.len();
    let (stage, n_lit, candidates, slots) = (idx(s), idx(n), idx(4 * n), idx(block.slots));
    let scales = block_scales(cx, shape);
    let coordinate_units = cx.model.coordinate_units();
    let angles = shape
        .coordinates
        .iter()
        .map(|&c| coordinate_units[c] == Unit::Angle);
    let coordinates: Vec<Literal> = shape.coordinates.iter().map(|&c| idx(c)).collect();
    let locals: Vec<Literal> = (0..n).map(idx).collect();
    let pattern = block.pattern.iter().map(|&(i, j)| {
        let (i, j) = (idx(i), idx(j));
        quote!((#i, #j))
    });
    let pivots = block.pivots.iter().map(|&p| idx(p));
    let (factor, solve): (Ident, Ident) = (
        format_ident!("factor_{}", factorization),
        format_ident!("solve_{}", factorization),
    );
    let [closed_form, jacobian, trig, velocity_rhs, acceleration_rhs] = [
        Method::ClosedForm,
        Method::Jacobian,
        Method::FillTrig,
        Method::VelocityRhs,
        Method::AccelerationRhs,
    ]
    .map(|m| calls.call(m));
    let (trig_before, trig_after) = if trig_first {
        (trig_from_units(kernels, s, trig), TokenStream::new())
    } else {
        (TokenStream::new(), trig)
    };
    let archive = archive.map(|slots| {
        let (start, end) = (idx(slots.start), idx(slots.end));
        quote!(archive[#start..#end].copy_from_slice(values);)
    });
    let scatter = |target: TokenStream| quote!(#(#target[#coordinates] = x[#locals];)*);
    let (to_q, to_qd, to_qdd) = (
        scatter(quote!(q)),
        scatter(quote!(qd)),
        scatter(quote!(qdd)),
    );
    Some(quote! {
        {
            let scales = #scales;
            let out = &mut [0.0_f64; #candidates];
            #closed_form
            let guess = [#(q[#coordinates]),*];
            let ::core::option::Option::Some(choice) =
                context.choose(#stage, guess, out, [#(#angles),*], &scales, report)
            else {
                return ::core::result::Result::Err(#stage);
            };
            let x = choice.values;
            #to_q
            #trig_before
            let (phi, values) = (&mut [0.0_f64; #n_lit], &mut [0.0_f64; #slots]);
            #jacobian
            let (tiny, norm1) =
                context.scale_jacobian(#stage, values, &[#(#pattern),*], &scales)?;
            if Self::#factor(values, tiny, context.limit()).is_err() {
                return ::core::result::Result::Err(#stage);
            }
            let values = &*values;
            let solve = |x: &mut [f64; #n_lit]| Self::#solve(values, x);
            context.accept(#stage, phi, &x, &scales, &[#(values[#pivots]),*], norm1, solve, report)?;
            #archive
            #trig_after
            let out = &mut [0.0_f64; #n_lit];
            #velocity_rhs
            let x = context.rates(#stage, out, &scales, solve)?;
            #to_qd
            #acceleration_rhs
            let x = context.rates(#stage, out, &scales, solve)?;
            #to_qdd
        }
    })
}

/// Block `s`'s trig fill from its chosen solution's unit vectors (the intersection gave each
/// angle's cosine and sine), with `fill` (the stage's `sin_cos` kernel) where they are not on
/// the unit circle to rounding.
fn trig_from_units(kernels: &Kernels, s: usize, fill: TokenStream) -> TokenStream {
    let coordinates = &kernels.shapes[s].coordinates;
    let writes: Option<Vec<TokenStream>> = kernels
        .trig
        .fills(s)
        .map(|m| {
            let j = coordinates
                .iter()
                .position(|&c| c == kernels.trig.angles[m])?;
            let (sin, cos, j) = (idx(2 * m), idx(2 * m + 1), idx(j));
            Some(quote!(trig[#sin] = units[#j][1]; trig[#cos] = units[#j][0];))
        })
        .collect();
    let Some(writes) = writes.filter(|w| !w.is_empty()) else {
        return fill;
    };
    quote! {
        if let ::core::option::Option::Some(units) = choice.units() {
            #(#writes)*
        } else {
            #fill
        }
    }
}
