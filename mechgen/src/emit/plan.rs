//! The solve structure as code: `impl Structured` for a scene, rendered from the kernel list
//! (`crate::plan::kernels`). Each kernel becomes a function (`stage_3_positions`); each `Structured`
//! method a dispatch on the stage index over the kernels it runs; the stage table and the
//! static LUs come from `stages` and `lu`.

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::body::{Context, Function};
use super::dispatch::Dispatch;
use super::idx;
use super::lu::lu_functions;
use super::stages::stage_table;
use super::step::straight_step;
use crate::expr::Id;
use crate::plan::kernels::{Buffer, Kernels, Method, StageKernel};
use crate::plan::structure::Plan;

/// A `Structured` method written by the emitter: a kernel method, or one of the three that run
/// a block's static LU.
#[derive(Clone, Copy)]
enum Item {
    Kernel(Method),
    Lu(Lu),
}

/// The methods that run a block's static LU.
#[derive(Clone, Copy)]
enum Lu {
    Factor,
    Solve,
    SolveTranspose,
}

/// The methods in the order generated code lists them.
const ITEMS: [Item; 13] = [
    Item::Kernel(Method::Positions),
    Item::Kernel(Method::Velocities),
    Item::Kernel(Method::Accelerations),
    Item::Kernel(Method::ClosedForm),
    Item::Kernel(Method::Jacobian),
    Item::Kernel(Method::FillTrig),
    Item::Lu(Lu::Factor),
    Item::Lu(Lu::Solve),
    Item::Lu(Lu::SolveTranspose),
    Item::Kernel(Method::VelocityRhs),
    Item::Kernel(Method::AccelerationRhs),
    Item::Kernel(Method::Multipliers),
    Item::Kernel(Method::ForceRhs),
];

/// `impl Structured` and the inherent items it dispatches to.
// Kept whole: half of it is the `impl` template, which reads best in one piece.
pub(super) fn structured_impl(cx: &Context<'_>, plan: &Plan, kernels: &Kernels) -> TokenStream {
    let name = &cx.model.name;
    let table = stage_table(cx.model, plan, &kernels.shapes);
    let functions: Vec<(TokenStream, Kernel)> = kernels
        .stages
        .iter()
        .map(|k| kernel_function(cx, kernels, k))
        .collect();
    let sizes = &kernels.sizes;
    let (trig_len, n_lit) = (idx(sizes.trig), idx(sizes.coordinates));
    let views = [("trig", &trig_len), ("lambda", &n_lit)];
    let methods = ITEMS.map(|item| {
        let (params, result, required) = signature(item);
        let dispatch = match item {
            Item::Kernel(method) => kernel_dispatch(kernels, &functions, method),
            Item::Lu(lu) => lu_dispatch(kernels, lu),
        };
        dispatch.method(name_of(item), &params, result, required, &views)
    });
    let factor_functions = kernels
        .factorizations
        .iter()
        .enumerate()
        .flat_map(|(k, f)| lu_functions(cx, k, f));
    let branch = branch_method(cx, kernels);
    let (straight_stages, straight_step) = straight_step(cx, kernels, &functions).unzip();
    let markers = cx.markers_method(kernels);
    let functions = functions.iter().map(|(function, _)| function);
    let (b, s, k, n) = (
        idx(sizes.largest_block),
        idx(sizes.largest_slots),
        idx(sizes.stages),
        idx(sizes.coordinates),
    );
    let stage_count = idx(kernels.shapes.len());
    let forces = sizes.forces.map(|r| {
        let r = idx(r);
        quote!(, #r)
    });
    quote! {
        impl #name {
            #table
            #(#functions)*
            #(#factor_functions)*
            #straight_stages
        }

        impl ::mechgen_runtime::Structured for #name {
            type Workspace = ::mechgen_runtime::codegen::Buffers<#b, #s, #k, #n, #trig_len #forces>;

            fn workspace(&self) -> Self::Workspace {
                ::mechgen_runtime::codegen::Buffers::new()
            }

            fn stage_count(&self) -> usize {
                #stage_count
            }

            fn stage(&self, index: usize) -> ::core::option::Option<::mechgen_runtime::codegen::Stage<'_>> {
                Self::STAGES.get(index).copied()
            }

            #(#methods)*
            #straight_step
            #branch
            #markers
        }
    }
}

/// The trait method's name.
fn name_of(item: Item) -> &'static str {
    match item {
        Item::Kernel(Method::Positions) => "assign_positions",
        Item::Kernel(Method::Velocities) => "assign_velocities",
        Item::Kernel(Method::Accelerations) => "assign_accelerations",
        Item::Kernel(Method::ClosedForm) => "closed_form",
        Item::Kernel(Method::Jacobian) => "block_jacobian",
        Item::Kernel(Method::VelocityRhs) => "velocity_rhs",
        Item::Kernel(Method::AccelerationRhs) => "acceleration_rhs",
        Item::Kernel(Method::FillTrig) => "fill_trig",
        Item::Kernel(Method::Multipliers) => "assign_multipliers",
        Item::Kernel(Method::ForceRhs) => "force_rhs",
        Item::Lu(Lu::Factor) => "factor",
        Item::Lu(Lu::Solve) => "solve",
        Item::Lu(Lu::SolveTranspose) => "solve_transpose",
    }
}

/// The trait method's parameters after `stage` (name, type) as the runtime's trait declares
/// them, its result type, and whether it is written even when no stage needs it (the trait
/// has no default).
fn signature(item: Item) -> (Vec<(&'static str, TokenStream)>, Option<TokenStream>, bool) {
    let vector = quote!(&::mechgen_runtime::Vector<Self::Dim>);
    let mut_vector = quote!(&mut ::mechgen_runtime::Vector<Self::Dim>);
    let (slice, mut_slice, t) = (quote!(&[f64]), quote!(&mut [f64]), quote!(f64));
    let (q, trig) = (("q", vector.clone()), ("trig", slice.clone()));
    let (qd, qdd) = (("qd", vector.clone()), ("qdd", vector));
    let (t, out) = (("t", t), ("out", mut_slice.clone()));
    let params = match item {
        Item::Kernel(Method::Positions) => vec![("q", mut_vector), trig, t],
        Item::Kernel(Method::Velocities) => vec![q, trig, ("qd", mut_vector), t],
        Item::Kernel(Method::Accelerations) => vec![q, trig, qd, ("qdd", mut_vector), t],
        Item::Kernel(Method::ClosedForm) => vec![q, trig, t, out],
        Item::Kernel(Method::Jacobian) => {
            vec![
                q,
                trig,
                t,
                ("phi", mut_slice.clone()),
                ("values", mut_slice),
            ]
        }
        Item::Kernel(Method::FillTrig) => vec![q, ("trig", mut_slice)],
        Item::Kernel(Method::VelocityRhs) => vec![q, trig, qd, t, out],
        Item::Kernel(Method::AccelerationRhs) => vec![q, trig, qd, qdd, t, out],
        Item::Kernel(Method::Multipliers) => vec![q, trig, qd, qdd, ("lambda", mut_slice), t],
        Item::Kernel(Method::ForceRhs) => vec![q, trig, qd, qdd, ("lambda", slice), t, out],
        Item::Lu(Lu::Factor) => vec![
            ("values", mut_slice),
            ("tiny", quote!(f64)),
            ("limit", quote!(f64)),
        ],
        Item::Lu(Lu::Solve) | Item::Lu(Lu::SolveTranspose) => {
            vec![("values", slice), ("x", mut_slice)]
        }
    };
    let result =
        matches!(item, Item::Lu(Lu::Factor)).then(|| quote!(::core::result::Result<(), usize>));
    let required = matches!(item, Item::Kernel(Method::Positions | Method::Jacobian));
    (params, result, required)
}

/// A kernel's function as generated: its name, and the arguments its caller passes (by name,
/// in order).
pub(super) struct Kernel {
    function: Ident,
    pub(super) arguments: Vec<&'static str>,
}

impl Kernel {
    /// `self.function(arguments…)`.
    pub(super) fn call(&self) -> TokenStream {
        let function = &self.function;
        let arguments = self.arguments.iter().map(|a| format_ident!("{}", a));
        quote!(self.#function(#(#arguments),*))
    }
}

/// The function of kernel `k`, named after its method.
fn kernel_function(cx: &Context<'_>, kernels: &Kernels, k: &StageKernel) -> (TokenStream, Kernel) {
    named_kernel_function(cx, kernels, k, naming(k.method))
}

/// The function `stage_{s}_{suffix}` of kernel `k`, documented as doing `description`: it
/// takes the state its body reads, the trig cache if it reads it, and time, then the output
/// parameters its method gives it.
// Kept whole: the kernel's parameters follow from its body, built just before them.
pub(super) fn named_kernel_function(
    cx: &Context<'_>,
    kernels: &Kernels,
    k: &StageKernel,
    (suffix, description): (&str, &str),
) -> (TokenStream, Kernel) {
    let outputs: Vec<(TokenStream, Id)> = k
        .kernel
        .outputs
        .iter()
        .zip(&k.kernel.roots)
        .map(|(&(buffer, i), &value)| {
            let (buffer, i) = (format_ident!("{}", buffer.name()), idx(i));
            (quote!(#buffer[#i]), value)
        })
        .collect();
    let outs = output_parameters(cx, kernels, k);
    let zeros = zero_stores(cx, &outputs);
    let vector = cx.vector_type();
    let (trig_len, n) = (idx(kernels.sizes.trig), idx(kernels.sizes.coordinates));
    let typed: Vec<(&'static str, TokenStream)> = k
        .method
        .inputs()
        .iter()
        .map(|input| input.name())
        .chain(["trig"])
        .map(|input| {
            let ty = match input {
                "trig" => quote!(&[f64; #trig_len]),
                "lambda" => quote!(&[f64; #n]),
                _ => quote!(&#vector),
            };
            (input, ty)
        })
        .collect();
    let name = format!("stage_{}_{suffix}", k.stage);
    let f = cx.bounded(&name, &outputs, zeros, &outs, &typed, &k.kernel.cached);
    let mut params = Vec::new();
    let mut arguments = Vec::new();
    for (input, ty) in typed.iter().chain(&[("t", quote!(f64))]) {
        if outs.iter().any(|(o, _)| o == input) || f.args.get(input) != *input {
            continue;
        }
        let ident = format_ident!("{}", input);
        params.push(quote!(#ident: #ty));
        arguments.push(*input);
    }
    for (out, ty) in &outs {
        let ident = format_ident!("{}", out);
        params.push(quote!(#ident: #ty));
        arguments.push(*out);
    }
    let function = format_ident!("{}", name);
    let (doc, body) = (kernel_doc(k.stage, description, &f), &f.body);
    let code = quote! {
        #doc
        fn #function(&self, #(#params),*) {
            #body
        }
    };
    (
        code,
        Kernel {
            function,
            arguments,
        },
    )
}

/// A kernel's name after `stage_s_`, and what it does (its documentation).
fn naming(method: Method) -> (&'static str, &'static str) {
    match method {
        Method::Positions => ("positions", "assigns the positions"),
        Method::Velocities => ("velocities", "assigns the velocities"),
        Method::Accelerations => ("accelerations", "assigns the accelerations"),
        Method::ClosedForm => (
            "closed_form",
            "the block's two solutions in closed form (Newton's starting points)",
        ),
        Method::Jacobian => ("jacobian", "the block's residual and Jacobian values"),
        Method::VelocityRhs => ("velocity_rhs", "the block's velocity right-hand side"),
        Method::AccelerationRhs => (
            "acceleration_rhs",
            "the block's acceleration right-hand side",
        ),
        Method::FillTrig => ("trig", "caches the sines and cosines of its angles"),
        Method::Multipliers => (
            "multipliers",
            "assigns its equations' multipliers (force solve)",
        ),
        Method::ForceRhs => ("force_rhs", "the block's force right-hand side"),
    }
}

/// The output parameters of a kernel of `k`'s method: the state vector it writes, or arrays
/// of the lengths the kernel list gives.
fn output_parameters(
    cx: &Context<'_>,
    kernels: &Kernels,
    k: &StageKernel,
) -> Vec<(&'static str, TokenStream)> {
    let array = |buffer: Buffer| {
        let len = idx(kernels.buffer_len(k.stage, buffer));
        (buffer.name(), quote!(&mut [f64; #len]))
    };
    match k.method {
        Method::Positions | Method::Velocities | Method::Accelerations => {
            let vector = cx.vector_type();
            vec![(k.method.target().name(), quote!(&mut #vector))]
        }
        Method::Jacobian => vec![array(Buffer::Phi), array(Buffer::Values)],
        method => vec![array(method.target())],
    }
}

/// A kernel method's arms: each stage with a kernel calls it, viewing the runtime's slices as
/// the kernel's arrays first (a slice that does not fit leaves NaN, never stale values).
fn kernel_dispatch(
    kernels: &Kernels,
    functions: &[(TokenStream, Kernel)],
    method: Method,
) -> Dispatch {
    let some = quote!(::core::option::Option::Some);
    let mut dispatch = Dispatch::default();
    for (k, (_, kernel)) in kernels.stages.iter().zip(functions) {
        if k.method != method {
            continue;
        }
        let call = kernel.call();
        let len = |buffer: Buffer| idx(kernels.buffer_len(k.stage, buffer));
        let equations = len(Buffer::Out);
        let arm = match method {
            Method::Positions | Method::Velocities | Method::Accelerations => call,
            Method::FillTrig | Method::Multipliers => quote!(#call;),
            Method::Jacobian => {
                let slots = len(Buffer::Values);
                quote! {
                    let (#some(phi), #some(values)) =
                        (phi.first_chunk_mut::<#equations>(), values.first_chunk_mut::<#slots>())
                    else {
                        phi.fill(f64::NAN);
                        values.fill(f64::NAN);
                        return;
                    };
                    #call;
                }
            }
            Method::ClosedForm
            | Method::VelocityRhs
            | Method::AccelerationRhs
            | Method::ForceRhs => {
                let len = len(method.target());
                quote! {
                    let #some(out) = out.first_chunk_mut::<#len>() else {
                        out.fill(f64::NAN);
                        return;
                    };
                    #call;
                }
            }
        };
        dispatch.push(k.stage, arm, &kernel.arguments);
    }
    dispatch
}

/// `factor`, `solve` or `solve_transpose`: each block with a static LU calls its shared
/// functions over the block's value slots.
fn lu_dispatch(kernels: &Kernels, lu: Lu) -> Dispatch {
    let some = quote!(::core::option::Option::Some);
    let mut dispatch = Dispatch::default();
    for (s, shape) in kernels.shapes.iter().enumerate() {
        let Some((block, k)) = shape
            .block
            .as_ref()
            .and_then(|b| Some((b, b.factorization?)))
        else {
            continue;
        };
        let (n, slots) = (idx(shape.equations.len()), idx(block.slots));
        match lu {
            Lu::Factor => {
                let factor = format_ident!("factor_{}", k);
                dispatch.push(
                    s,
                    quote! {
                        let #some(values) = values.first_chunk_mut::<#slots>() else {
                            return ::core::result::Result::Err(0);
                        };
                        Self::#factor(values, tiny, limit)
                    },
                    &["values", "tiny", "limit"],
                );
            }
            Lu::Solve | Lu::SolveTranspose => {
                let function = match lu {
                    Lu::Solve => format_ident!("solve_{}", k),
                    _ => format_ident!("solve_transpose_{}", k),
                };
                dispatch.push(
                    s,
                    quote! {
                        let (#some(values), #some(x)) =
                            (values.first_chunk::<#slots>(), x.first_chunk_mut::<#n>())
                        else {
                            x.fill(f64::NAN);
                            return;
                        };
                        Self::#function(values, x);
                    },
                    &["values", "x"],
                );
            }
        }
    }
    dispatch
}

/// `branch`: the branch invariants at the solved positions, reading the trig cache (every
/// stage has filled it by then); nothing for a scene without invariants.
fn branch_method(cx: &Context<'_>, kernels: &Kernels) -> TokenStream {
    let branches = &kernels.branches;
    if branches.is_empty() {
        return TokenStream::new();
    }
    let (arms, q, trig) = cx.branch_arms(branches.iter().map(|b| (b.roots[0], &b.cached)));
    let trig_len = idx(kernels.sizes.trig);
    let view = (trig == "trig").then(|| {
        quote! {
            let ::core::option::Option::Some(trig) = trig.first_chunk::<#trig_len>() else {
                return f64::NAN;
            };
        }
    });
    quote! {
        /// The invariant's value, signed to be positive on the declared branch.
        fn branch(
            &self,
            index: usize,
            #q: &::mechgen_runtime::Vector<Self::Dim>,
            #trig: &[f64],
        ) -> f64 {
            #view
            match index {
                #(#arms)*
                _ => f64::NAN,
            }
        }
    }
}

/// `Stage s: what.` and the kernel's operation counts, as doc lines.
fn kernel_doc(s: usize, what: &str, f: &Function) -> TokenStream {
    let (what, cost) = (
        format!(" Stage {s}: {what}."),
        format!(" Operations: {}.", f.counts),
    );
    quote! { #[doc = #what] #[doc = ""] #[doc = #cost] }
}

/// `target = 0.0;` for the outputs that are identically zero: explicit stages and right-hand
/// sides write every entry they own (the buffers they write into hold other values).
fn zero_stores(cx: &Context<'_>, outputs: &[(TokenStream, Id)]) -> TokenStream {
    let stores = outputs
        .iter()
        .filter(|(_, v)| cx.arena().is_zero(*v))
        .map(|(target, _)| quote! { #target = 0.0; });
    quote!(#(#stores)*)
}
