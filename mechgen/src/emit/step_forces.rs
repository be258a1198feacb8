//! What the straight step of a scene that computes forces adds, as code, over the block
//! factors it archives, with the kernels called directly (no dispatch on the stage index):
//! - its force solve, `straight_forces`: the stages in reverse, as the runtime's force solve
//!   (`forces.rs`) runs them. An explicit stage assigns its multipliers in closed form; a
//!   block solves `Φ_q[b, b]ᵀ λ_b = F_b − Φ_q[later, b]ᵀ λ_later` with its archived factors
//!   (`StepContext::multipliers`). The runtime then turns the multipliers into reactions and
//!   checks them once;
//! - `Structured::straight_velocities`: the velocities again at the solved positions, each
//!   block's with its archived factors (the integrator's columns of `∂q̇/∂u̇`, one velocity
//!   solve per free degree of freedom).

use core::ops::Range;

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::body::Context;
use super::idx;
use super::plan::Kernel;
use super::step::{StageCalls, block_scales, trig_view, unused};
use crate::plan::kernels::{Kernels, Method};

/// Where each stage's factors go in the force solve's archive (after the multipliers): a
/// block's slots in stage order, as the runtime's sweep archives them; `None` for an
/// explicit stage.
pub(super) fn archive_ranges(kernels: &Kernels) -> Vec<Option<Range<usize>>> {
    let mut end = 0;
    let ranges = kernels.shapes.iter().map(|shape| {
        let slots = shape.block.as_ref()?.slots;
        let range = end..end + slots;
        end = range.end;
        Some(range)
    });
    ranges.collect()
}

/// `straight_forces`, the inherent function the straight step ends with: the multipliers of
/// every stage in reverse into `lambda`, the blocks' factors read from `archive`. `None` when
/// a block has no static LU (the step then has none either). It takes the motion's
/// arguments its kernels read.
pub(super) fn straight_forces(
    cx: &Context<'_>,
    kernels: &Kernels,
    functions: &[&Kernel],
) -> Option<ForceSolve> {
    let ranges = archive_ranges(kernels);
    let code = Pass::Forces.stages(cx, kernels, functions, &ranges)?;
    let blocks = ranges.iter().any(Option::is_some);
    let force_kernels = of_methods(kernels, functions, &[Method::Multipliers, Method::ForceRhs]);
    let reads = |name: &str| force_kernels.iter().any(|f| f.arguments.contains(&name));
    // The motion's arguments the kernels read, in the caller's order.
    let vector = cx.vector_type();
    let motion: Vec<(Ident, TokenStream)> = [("t", quote!(f64)), ("q", quote!(&#vector))]
        .into_iter()
        .chain(["qd", "qdd"].map(|name| (name, quote!(&#vector))))
        .filter(|(name, _)| reads(name))
        .map(|(name, ty)| (format_ident!("{}", name), ty))
        .collect();
    // The trig cache is viewed as its array again: the step's end checks read it whole.
    let (trig_cache, view) = trig_parameter(kernels, reads("trig"));
    let (archive, context) = (unused(blocks, "archive"), unused(blocks, "context"));
    let (dim, archived): (Literal, Literal) = (
        idx(cx.model.dim()),
        idx(ranges.iter().flatten().map(|r| r.len()).sum()),
    );
    let parameters = motion.iter().map(|(name, ty)| quote!(#name: #ty));
    let arguments = motion.iter().map(|(name, _)| name);
    let call = quote! {
        self.straight_forces(#(#arguments,)* trig_cache, lambda, archive, context)?;
    };
    let function = quote! {
        /// The straight step's force solve: every stage's multipliers, in reverse (see
        /// `Structured::straight_step`).
        #[allow(clippy::too_many_arguments)]
        fn straight_forces(
            &self,
            #(#parameters,)*
            #trig_cache: &[f64],
            lambda: &mut [f64; #dim],
            #archive: &[f64; #archived],
            #context: &::mechgen_runtime::codegen::StepContext,
        ) -> ::core::result::Result<(), usize> {
            #view
            #(#code)*
            ::core::result::Result::Ok(())
        }
    };
    let storage = quote! {
        let ::core::option::Option::Some((lambda, archive)) =
            forces.split_first_chunk_mut::<#dim>()
        else {
            return ::core::result::Result::Err(0);
        };
        let ::core::option::Option::Some(archive) = archive.first_chunk_mut::<#archived>() else {
            return ::core::result::Result::Err(0);
        };
    };
    Some(ForceSolve {
        storage,
        call,
        function,
    })
}

/// The straight step's force solve: the step's view of the force storage as the multipliers'
/// and the archive's arrays, its call of the force solve after the end checks, and the
/// function.
pub(super) struct ForceSolve {
    pub(super) storage: TokenStream,
    pub(super) call: TokenStream,
    pub(super) function: TokenStream,
}

/// `Structured::straight_velocities`: the stages in order, each explicit one's velocities
/// kernel, each block's velocity right-hand side solved with its archived factors. `None`
/// when a block has no static LU. It names `_t`, `_q`, … the arguments no kernel reads.
pub(super) fn straight_velocities(
    cx: &Context<'_>,
    kernels: &Kernels,
    functions: &[&Kernel],
) -> Option<TokenStream> {
    let ranges = archive_ranges(kernels);
    let code = Pass::Velocities.stages(cx, kernels, functions, &ranges)?;
    let velocity_kernels = of_methods(
        kernels,
        functions,
        &[Method::Velocities, Method::VelocityRhs],
    );
    let reads = |name: &str| velocity_kernels.iter().any(|f| f.arguments.contains(&name));
    let blocks = ranges.iter().any(Option::is_some);
    let [t, q] = ["t", "q"].map(|name| unused(reads(name), name));
    let (forces, context) = (unused(blocks, "forces"), unused(blocks, "context"));
    let (dim, archived) = (
        idx(cx.model.dim()),
        idx(ranges.iter().flatten().map(|r| r.len()).sum()),
    );
    let (trig_cache, view) = trig_parameter(kernels, reads("trig"));
    let archive = blocks.then(|| {
        quote! {
            let ::core::option::Option::Some(archive) =
                forces.get(#dim..).and_then(|a| a.first_chunk::<#archived>())
            else {
                return ::core::result::Result::Err(0);
            };
        }
    });
    let vector = quote!(::mechgen_runtime::Vector<Self::Dim>);
    Some(quote! {
        fn straight_velocities(
            &self,
            #t: f64,
            #q: &#vector,
            #trig_cache: &[f64],
            qd: &mut #vector,
            #forces: &[f64],
            #context: &::mechgen_runtime::codegen::StepContext,
        ) -> ::core::result::Result<(), usize> {
            #view
            #archive
            #(#code)*
            ::core::result::Result::Ok(())
        }
    })
}

/// A pass over the stages with the blocks' archived factors.
#[derive(Clone, Copy)]
enum Pass {
    /// The force solve: the stages in reverse, multipliers.
    Forces,
    /// The velocities: the stages in order.
    Velocities,
}

impl Pass {
    /// Each stage's code, in the pass's order: an explicit stage's kernel, a block's
    /// right-hand side solved with its archived factors (`archive`, at `ranges`) and written
    /// to its equations' multipliers or its coordinates' velocities. `None` for a block
    /// without a static LU.
    fn stages(
        self,
        cx: &Context<'_>,
        kernels: &Kernels,
        functions: &[&Kernel],
        ranges: &[Option<Range<usize>>],
    ) -> Option<Vec<TokenStream>> {
        let (explicit, rhs) = match self {
            Pass::Forces => (Method::Multipliers, Method::ForceRhs),
            Pass::Velocities => (Method::Velocities, Method::VelocityRhs),
        };
        let mut code = Vec::new();
        for (s, shape) in kernels.shapes.iter().enumerate() {
            let calls = StageCalls::of(kernels, functions, s);
            let Some(block) = &shape.block else {
                code.push(calls.call(explicit));
                continue;
            };
            let (stage, slots) = (idx(s), idx(block.slots));
            let start = idx(ranges[s].as_ref()?.start);
            let n = idx(shape.coordinates.len());
            let scales = block_scales(cx, shape);
            let rhs = calls.call(rhs);
            let factorization = block.factorization?;
            let (solve, targets) = match self {
                Pass::Forces => {
                    let solve = format_ident!("solve_transpose_{}", factorization);
                    let solve =
                        quote!(context.multipliers(out, &scales, |x| Self::#solve(values, x)));
                    (solve, (quote!(lambda), &shape.equations))
                }
                Pass::Velocities => {
                    let solve = format_ident!("solve_{}", factorization);
                    let solve =
                        quote!(context.rates(#stage, out, &scales, |x| Self::#solve(values, x))?);
                    (solve, (quote!(qd), &shape.coordinates))
                }
            };
            let (target, indices) = targets;
            let (indices, locals) = (indices.iter().map(|&i| idx(i)), (0..indices.len()).map(idx));
            code.push(quote! {
                {
                    let ::core::option::Option::Some(values) =
                        archive[#start..].first_chunk::<#slots>()
                    else {
                        return ::core::result::Result::Err(#stage);
                    };
                    let scales = #scales;
                    let out = &mut [0.0_f64; #n];
                    #rhs
                    let x = #solve;
                    #(#target[#indices] = x[#locals];)*
                }
            });
        }
        if let Pass::Forces = self {
            code.reverse();
        }
        Some(code)
    }
}

/// The trig cache parameter of a pass's function (`_trig_cache` where no kernel reads it,
/// `used`) and its view as the array the kernels take.
fn trig_parameter(kernels: &Kernels, used: bool) -> (Ident, TokenStream) {
    if used {
        (format_ident!("trig_cache"), trig_view(kernels, false))
    } else {
        (format_ident!("_trig_cache"), TokenStream::new())
    }
}

/// The functions of the kernels of `methods`.
fn of_methods<'k>(
    kernels: &Kernels,
    functions: &[&'k Kernel],
    methods: &[Method],
) -> Vec<&'k Kernel> {
    let kernels = kernels.stages.iter().zip(functions);
    kernels
        .filter(|(k, _)| methods.contains(&k.method))
        .map(|(_, &f)| f)
        .collect()
}
