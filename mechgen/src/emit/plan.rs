//! The solve structure as code: `impl Structured` for a scene. Its stages become a constant
//! (`STAGES`); each stage gets its kernels (explicit assignments of positions, velocities and
//! accelerations; a block's residual and Jacobian values and its rate right-hand sides); each
//! distinct static LU becomes straight-line factor and solve functions over the block's value
//! slots, shared by the blocks with the same pattern. The trait methods dispatch on the stage
//! index.

use std::collections::{BTreeSet, HashMap};

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::body::{Context, Function};
use super::idx;
use crate::expr::Id;
use crate::factor::Factorization;
use crate::model::Model;
use crate::structure::{Assignment, Block, Phase, Plan, Stage, TrigCache};

/// `impl Structured` and the inherent items it dispatches to.
pub(super) fn structured_impl(cx: &Context<'_>, plan: &Plan) -> TokenStream {
    let name = &cx.model.name;
    let table = stage_table(cx.model, plan);
    let mut kernels = Kernels::new(&plan.trig);
    let mut shared = Factorizations::default();
    for (s, stage) in plan.stages.iter().enumerate() {
        match stage {
            Stage::Explicit(assignments) => kernels.explicit(cx, s, assignments),
            Stage::Block(block) => kernels.block(cx, s, block, &mut shared),
        }
        kernels.fill_trig(cx, s);
        if let Some(forces) = cx.forces {
            kernels.force_stage(cx, s, stage, &forces.stages[s]);
        }
    }
    let trig_len = idx(plan.trig.len());
    let n_lit = idx(cx.model.dim());
    let views = [("trig", &trig_len), ("lambda", &n_lit)];
    let factor_functions = shared.functions(cx);
    let branch = branch_method(cx, plan);
    let markers = cx.markers_method(cx.markers, plan);
    let vector = quote!(::mechgen_runtime::Vector<Self::Dim>);
    let slice = quote!([f64]);
    let k = &kernels;
    let trig = ("trig", quote!(&#slice));
    let methods = [
        k.positions.method(
            "assign_positions",
            &[
                ("q", quote!(&mut #vector)),
                trig.clone(),
                ("t", quote!(f64)),
            ],
            None,
            true,
            &views,
        ),
        k.velocities.method(
            "assign_velocities",
            &[
                ("q", quote!(&#vector)),
                trig.clone(),
                ("qd", quote!(&mut #vector)),
                ("t", quote!(f64)),
            ],
            None,
            false,
            &views,
        ),
        k.accelerations.method(
            "assign_accelerations",
            &[
                ("q", quote!(&#vector)),
                trig.clone(),
                ("qd", quote!(&#vector)),
                ("qdd", quote!(&mut #vector)),
                ("t", quote!(f64)),
            ],
            None,
            false,
            &views,
        ),
        k.jacobian.method(
            "block_jacobian",
            &[
                ("q", quote!(&#vector)),
                trig.clone(),
                ("t", quote!(f64)),
                ("phi", quote!(&mut #slice)),
                ("values", quote!(&mut #slice)),
            ],
            None,
            true,
            &views,
        ),
        k.fill_trig.method(
            "fill_trig",
            &[("q", quote!(&#vector)), ("trig", quote!(&mut #slice))],
            None,
            false,
            &views,
        ),
        k.factor.method(
            "factor",
            &[
                ("values", quote!(&mut #slice)),
                ("tiny", quote!(f64)),
                ("limit", quote!(f64)),
            ],
            Some(quote!(::core::result::Result<(), usize>)),
            false,
            &views,
        ),
        k.solve.method(
            "solve",
            &[("values", quote!(&#slice)), ("x", quote!(&mut #slice))],
            None,
            false,
            &views,
        ),
        k.solve_transpose.method(
            "solve_transpose",
            &[("values", quote!(&#slice)), ("x", quote!(&mut #slice))],
            None,
            false,
            &views,
        ),
        k.velocity_rhs.method(
            "velocity_rhs",
            &[
                ("q", quote!(&#vector)),
                trig.clone(),
                ("qd", quote!(&#vector)),
                ("t", quote!(f64)),
                ("out", quote!(&mut #slice)),
            ],
            None,
            false,
            &views,
        ),
        k.acceleration_rhs.method(
            "acceleration_rhs",
            &[
                ("q", quote!(&#vector)),
                trig.clone(),
                ("qd", quote!(&#vector)),
                ("qdd", quote!(&#vector)),
                ("t", quote!(f64)),
                ("out", quote!(&mut #slice)),
            ],
            None,
            false,
            &views,
        ),
        k.multipliers.method(
            "assign_multipliers",
            &[
                ("q", quote!(&#vector)),
                trig.clone(),
                ("qd", quote!(&#vector)),
                ("qdd", quote!(&#vector)),
                ("lambda", quote!(&mut #slice)),
                ("t", quote!(f64)),
            ],
            None,
            false,
            &views,
        ),
        k.force_rhs.method(
            "force_rhs",
            &[
                ("q", quote!(&#vector)),
                trig.clone(),
                ("qd", quote!(&#vector)),
                ("qdd", quote!(&#vector)),
                ("lambda", quote!(&#slice)),
                ("t", quote!(f64)),
                ("out", quote!(&mut #slice)),
            ],
            None,
            false,
            &views,
        ),
    ];
    let functions = &kernels.functions;
    let (b, s, k, n) = (
        idx(plan.largest_block()),
        idx(plan.largest_slots()),
        idx(plan.stages.len().max(1)),
        idx(cx.model.dim()),
    );
    let stage_count = idx(plan.stages.len());
    // The force solve's storage: the multipliers, then every block's archived factors.
    let forces = cx.forces.map(|_| {
        let archive: usize = plan.blocks().map(Block::slots).sum();
        let r = idx(cx.model.dim() + archive);
        quote!(, #r)
    });
    quote! {
        impl #name {
            #table
            #(#functions)*
            #(#factor_functions)*
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
            #branch
            #markers
        }
    }
}

/// `branch`: the branch invariants at the solved positions, reading the trig cache (every
/// stage has filled it by then); nothing for a scene without invariants.
fn branch_method(cx: &Context<'_>, plan: &Plan) -> TokenStream {
    let branches = &cx.kinematics_branches;
    if branches.is_empty() {
        return TokenStream::new();
    }
    let all_filled = plan.stages.len();
    let (mut reads_q, mut reads_trig) = (false, false);
    let arms: Vec<TokenStream> = branches
        .iter()
        .enumerate()
        .map(|(i, &id)| {
            let value = if cx.arena().is_zero(id) {
                quote!(0.0)
            } else {
                let cached = plan
                    .trig
                    .reads(cx.arena(), &[id], all_filled, Phase::Positions);
                let f = cx.function(&[(TokenStream::new(), id)], TokenStream::new(), &cached);
                reads_q |= f.args.q == "q";
                reads_trig |= f.args.trig == "trig";
                let body = f.body;
                quote! { { #body } }
            };
            let i = idx(i);
            quote! { #i => #value, }
        })
        .collect();
    let q = if reads_q {
        format_ident!("q")
    } else {
        format_ident!("_q")
    };
    let trig_len = idx(plan.trig.len());
    let (trig, view) = if reads_trig {
        (
            format_ident!("trig"),
            quote! {
                let ::core::option::Option::Some(trig) = trig.first_chunk::<#trig_len>() else {
                    return f64::NAN;
                };
            },
        )
    } else {
        (format_ident!("_trig"), TokenStream::new())
    };
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

/// A trait method's arms (stage, statements), and the parameters they read.
#[derive(Default)]
pub(super) struct Dispatch {
    arms: Vec<(usize, TokenStream)>,
    reads: BTreeSet<&'static str>,
}

impl Dispatch {
    /// The statements for stage `s`, calling a kernel with `arguments` (by name).
    pub(super) fn push(&mut self, s: usize, statements: TokenStream, arguments: &[&'static str]) {
        self.arms.push((s, statements));
        self.reads.insert("stage");
        self.reads.extend(arguments);
    }

    /// The trait method, or nothing when no stage needs it and the trait's default serves
    /// (`required` methods are written anyway, reading nothing). Parameters no arm reads get a
    /// leading underscore.
    ///
    /// The kernels take the trig cache (`trig`) and the multipliers (`lambda`) as arrays of
    /// the lengths in `views`: when one reads such a parameter, the method views the
    /// runtime's slice as that array first.
    fn method(
        &self,
        name: &str,
        params: &[(&'static str, TokenStream)],
        result: Option<TokenStream>,
        required: bool,
        views: &[(&str, &Literal)],
    ) -> TokenStream {
        if self.arms.is_empty() && !required {
            return TokenStream::new();
        }
        let named = |param: &str| {
            if self.reads.contains(param) {
                format_ident!("{}", param)
            } else {
                format_ident!("_{}", param)
            }
        };
        let stage = named("stage");
        // A view that does not fit leaves no stale output behind: the outputs read NaN.
        let poisoned = params
            .iter()
            .filter(|(p, ty)| self.reads.contains(p) && ty.to_string().contains("mut"))
            .map(|(p, _)| format_ident!("{}", p));
        let early = if result.is_some() {
            quote!(return ::core::result::Result::Err(0))
        } else {
            quote!(#(#poisoned.fill(f64::NAN);)* return)
        };
        let conversions: Vec<TokenStream> = views
            .iter()
            .filter(|(view, _)| self.reads.contains(view))
            .filter_map(|(view, len)| {
                let (_, ty) = params.iter().find(|(p, _)| p == view)?;
                let chunk = if ty.to_string().contains("mut") {
                    quote!(first_chunk_mut)
                } else {
                    quote!(first_chunk)
                };
                let view = format_ident!("{}", view);
                Some(quote! {
                    let ::core::option::Option::Some(#view) = #view.#chunk::<#len>() else {
                        #early;
                    };
                })
            })
            .collect();
        let params = params.iter().map(|(param, ty)| {
            let param = named(param);
            quote!(#param: #ty)
        });
        let name = format_ident!("{}", name);
        let arrow = result.as_ref().map(|r| quote!(-> #r));
        let fallback = result
            .is_some()
            .then(|| quote!(::core::result::Result::Err(0)));
        let body = match &self.arms[..] {
            [] => quote!(#fallback),
            // One stage: `if`, not a one-arm `match` (clippy's `single_match` in included code).
            [(s, statements)] => {
                let s = idx(*s);
                let otherwise = fallback.as_ref().map(|f| quote!(else { #f }));
                quote! { #(#conversions)* if #stage == #s { #statements } #otherwise }
            }
            arms => {
                let arms = arms.iter().map(|(s, statements)| {
                    let s = idx(*s);
                    quote! { #s => { #statements } }
                });
                let fallback = fallback.unwrap_or_else(|| quote!({}));
                quote! { #(#conversions)* match #stage { #(#arms)* _ => #fallback } }
            }
        };
        quote! {
            fn #name(&self, #stage: usize, #(#params),*) #arrow {
                #body
            }
        }
    }
}

/// The `STAGES` constant, documented stage by stage.
fn stage_table(model: &Model, plan: &Plan) -> TokenStream {
    let (coordinates, equations) = (model.coordinate_names(), model.equation_names());
    let list = |indices: &[usize]| -> TokenStream {
        let indices = indices.iter().map(|&i| idx(i));
        quote!(&[#(#indices),*])
    };
    let mut docs = vec![
        " The solve, stage by stage; each stage reads only earlier ones (coordinate ← equation)."
            .to_owned(),
    ];
    let entries = plan.stages.iter().enumerate().map(|(s, stage)| {
        docs.push(String::new());
        let mut lines = stage_lines(stage, &coordinates, &equations).into_iter();
        docs.push(format!(" {s}. {}", lines.next().unwrap_or_default()));
        docs.extend(lines.map(|l| format!(" {l}")));
        match stage {
            Stage::Explicit(assignments) => {
                let eqs: Vec<usize> = assignments.iter().map(|a| a.equation).collect();
                let coords: Vec<usize> = assignments.iter().map(|a| a.coordinate).collect();
                let (e, c, r) = (list(&eqs), list(&coords), list(&plan.reads[s]));
                quote! {
                    ::mechgen_runtime::codegen::Stage::Explicit { equations: #e, coordinates: #c, reads: #r }
                }
            }
            Stage::Block(block) => {
                let (e, c, reads) = (
                    list(&block.equations),
                    list(&block.coordinates),
                    list(&plan.reads[s]),
                );
                let pattern = block.entries.iter().map(|&(r, c, _)| {
                    let (r, c) = (idx(r), idx(c));
                    quote!((#r, #c))
                });
                let slots = idx(block.slots());
                let pivots = block.factorization.as_ref().map(Factorization::pivots);
                let pivots = list(&pivots.unwrap_or_default());
                quote! {
                    ::mechgen_runtime::codegen::Stage::Block(::mechgen_runtime::codegen::Block {
                        equations: #e,
                        coordinates: #c,
                        pattern: ::mechgen_runtime::codegen::Pattern::Sparse(&[#(#pattern),*]),
                        slots: #slots,
                        pivots: #pivots,
                        reads: #reads,
                    })
                }
            }
        }
    });
    let entries: Vec<TokenStream> = entries.collect();
    let count = idx(entries.len());
    quote! {
        #(#[doc = #docs])*
        pub const STAGES: [::mechgen_runtime::codegen::Stage<'static>; #count] = [#(#entries),*];
    }
}

/// `` `a` ← `e` `` pairs (or the names alone), three to a doc line, at most two lines, then
/// how many there are in all.
fn name_lines(
    indices: &[usize],
    names: &[String],
    by: Option<(&[usize], &[String])>,
) -> Vec<String> {
    const PER_LINE: usize = 3;
    const LINES: usize = 2;
    let pair = |k: usize, i: usize| match by {
        Some((from, from_names)) => format!("`{}` ← `{}`", names[i], from_names[from[k]]),
        None => format!("`{}`", names[i]),
    };
    let shown: Vec<String> = indices
        .iter()
        .enumerate()
        .take(PER_LINE * LINES)
        .map(|(k, &i)| pair(k, i))
        .collect();
    let mut lines: Vec<String> = shown
        .chunks(PER_LINE)
        .map(|c| format!("    {}", c.join(", ")))
        .collect();
    if indices.len() > PER_LINE * LINES {
        lines.push(format!("    … ({} in all)", indices.len()));
    }
    lines
}

/// The headline of a block: its size and factorisation.
fn block_headline(block: &Block) -> String {
    let lu = match &block.factorization {
        Some(f) if f.fill() == 0 => format!("{} entries, no fill-in, static pivots", f.entries),
        Some(f) => format!("{} entries, {} fill-in, static pivots", f.entries, f.fill()),
        None => format!("{} entries, partial pivoting", block.entries.len()),
    };
    format!(
        "Newton block of {} ({lu}), pivots in order:",
        block.equations.len()
    )
}

/// The doc lines of a stage: a headline, then what it solves for.
fn stage_lines(stage: &Stage, coordinates: &[String], equations: &[String]) -> Vec<String> {
    let (headline, coords, eqs) = match stage {
        Stage::Explicit(assignments) => (
            format!(
                "explicit, {} coordinate{}:",
                assignments.len(),
                if assignments.len() == 1 { "" } else { "s" }
            ),
            assignments.iter().map(|a| a.coordinate).collect::<Vec<_>>(),
            assignments.iter().map(|a| a.equation).collect::<Vec<_>>(),
        ),
        Stage::Block(block) => (
            block_headline(block),
            block.coordinates.clone(),
            block.equations.clone(),
        ),
    };
    let mut lines = vec![headline];
    lines.extend(name_lines(&coords, coordinates, Some((&eqs, equations))));
    lines
}

/// A level of a stage's kernels: its name, its outputs' values (if the scene computes it) and
/// the inputs it may read.
type Level = (&'static str, Option<Vec<Id>>, &'static [&'static str]);

/// The per-stage functions and the trait methods' dispatch.
pub(super) struct Kernels<'p> {
    trig: &'p TrigCache,
    functions: Vec<TokenStream>,
    fill_trig: Dispatch,
    positions: Dispatch,
    velocities: Dispatch,
    accelerations: Dispatch,
    jacobian: Dispatch,
    factor: Dispatch,
    solve: Dispatch,
    solve_transpose: Dispatch,
    velocity_rhs: Dispatch,
    acceleration_rhs: Dispatch,
    /// The force solve's (`emit/forces.rs`).
    pub(super) multipliers: Dispatch,
    pub(super) force_rhs: Dispatch,
}

/// A generated kernel: its function, and the inputs its caller passes (by name, in order).
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

/// The `'static` name of a kernel input.
fn static_name(input: &str) -> &'static str {
    ["q", "qd", "qdd", "lambda", "trig", "t"]
        .into_iter()
        .find(|&n| n == input)
        .unwrap_or("q")
}

impl<'p> Kernels<'p> {
    fn new(trig: &'p TrigCache) -> Self {
        Kernels {
            trig,
            functions: Vec::new(),
            fill_trig: Dispatch::default(),
            positions: Dispatch::default(),
            velocities: Dispatch::default(),
            accelerations: Dispatch::default(),
            jacobian: Dispatch::default(),
            factor: Dispatch::default(),
            solve: Dispatch::default(),
            solve_transpose: Dispatch::default(),
            velocity_rhs: Dispatch::default(),
            acceleration_rhs: Dispatch::default(),
            multipliers: Dispatch::default(),
            force_rhs: Dispatch::default(),
        }
    }

    /// `stage_s_trig`: the sines and cosines of the angles stage `s` solves, into the cache.
    fn fill_trig(&mut self, cx: &Context<'_>, s: usize) {
        let outputs: Vec<(TokenStream, Id)> = self
            .trig
            .fills(s)
            .flat_map(|m| {
                let (sin, cos) = self.trig.nodes[m];
                let (i, j) = (idx(2 * m), idx(2 * m + 1));
                [(quote!(trig[#i]), sin), (quote!(trig[#j]), cos)]
            })
            .collect();
        if outputs.is_empty() {
            return;
        }
        let trig_len = idx(self.trig.len());
        // It computes what later kernels read: from the positions, not from the cache.
        let kernel = self.kernel(
            cx,
            s,
            Phase::Positions,
            "caches the sines and cosines of its angles",
            &format!("stage_{s}_trig"),
            &outputs,
            &["q"],
            &[("trig", quote!(&mut [f64; #trig_len]))],
        );
        let call = kernel.call();
        self.fill_trig.push(s, quote!(#call;), &kernel.arguments);
    }

    /// A kernel writing `outputs`: it takes the `inputs` (`q`, `qd`, `qdd`, `lambda`, `t`) its
    /// body reads, then the outputs `outs`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn kernel(
        &mut self,
        cx: &Context<'_>,
        s: usize,
        phase: Phase,
        what: &str,
        name: &str,
        outputs: &[(TokenStream, Id)],
        inputs: &[&'static str],
        outs: &[(&'static str, TokenStream)],
    ) -> Kernel {
        let zeros = zero_stores(cx, outputs);
        let roots: Vec<Id> = outputs.iter().map(|o| o.1).collect();
        let cached = self.trig.reads(cx.arena(), &roots, s, phase);
        let vector = cx.vector_type();
        let trig_len = idx(self.trig.len());
        let n = idx(cx.model.dim());
        let typed: Vec<(&str, TokenStream)> = inputs
            .iter()
            .chain(&["trig"])
            .map(|&input| {
                let ty = match input {
                    "trig" => quote!(&[f64; #trig_len]),
                    "lambda" => quote!(&[f64; #n]),
                    _ => quote!(&#vector),
                };
                (input, ty)
            })
            .collect();
        let f = cx.bounded(name, outputs, zeros, outs, &typed, &cached);
        let mut params = Vec::new();
        let mut arguments = Vec::new();
        for (input, ty) in typed.iter().chain(&[("t", quote!(f64))]) {
            if outs.iter().any(|(o, _)| o == input) || f.args.get(input) != input {
                continue;
            }
            let ident = format_ident!("{}", input);
            params.push(quote!(#ident: #ty));
            arguments.push(static_name(input));
        }
        for (out, ty) in outs {
            let ident = format_ident!("{}", out);
            params.push(quote!(#ident: #ty));
            arguments.push(*out);
        }
        let function = format_ident!("{}", name);
        let (doc, body) = (kernel_doc(s, what, &f), &f.body);
        self.functions.push(quote! {
            #doc
            fn #function(&self, #(#params),*) {
                #body
            }
        });
        Kernel {
            function,
            arguments,
        }
    }

    fn explicit(&mut self, cx: &Context<'_>, s: usize, assignments: &[Assignment]) {
        let vector = cx.vector_type();
        let levels: [Level; 3] = [
            (
                "positions",
                Some(assignments.iter().map(|a| a.position).collect()),
                &["q"],
            ),
            (
                "velocities",
                assignments.iter().map(|a| a.velocity).collect(),
                &["q", "qd"],
            ),
            (
                "accelerations",
                assignments.iter().map(|a| a.acceleration).collect(),
                &["q", "qd", "qdd"],
            ),
        ];
        for (level, (what, values, inputs)) in levels.into_iter().enumerate() {
            let Some(values) = values else {
                continue;
            };
            let target = ["q", "qd", "qdd"][level];
            let target_ident = format_ident!("{}", target);
            let outputs: Vec<(TokenStream, Id)> = assignments
                .iter()
                .zip(&values)
                .map(|(a, &v)| {
                    let c = idx(a.coordinate);
                    (quote!(#target_ident[#c]), v)
                })
                .collect();
            let phase = if level == 0 {
                Phase::Positions
            } else {
                Phase::After
            };
            let kernel = self.kernel(
                cx,
                s,
                phase,
                &format!("assigns the {what}"),
                &format!("stage_{s}_{what}"),
                &outputs,
                inputs,
                &[(target, quote!(&mut #vector))],
            );
            let call = kernel.call();
            let dispatch = [
                &mut self.positions,
                &mut self.velocities,
                &mut self.accelerations,
            ];
            dispatch[level].push(s, call, &kernel.arguments);
        }
    }

    fn block<'b>(
        &mut self,
        cx: &Context<'_>,
        s: usize,
        block: &'b Block,
        shared: &mut Factorizations<'b>,
    ) {
        let (n, slots) = (idx(block.equations.len()), idx(block.slots()));
        let some = quote!(::core::option::Option::Some);

        // Residual and Jacobian values.
        let mut outputs: Vec<(TokenStream, Id)> = block
            .residuals
            .iter()
            .enumerate()
            .map(|(r, &v)| {
                let r = idx(r);
                (quote!(phi[#r]), v)
            })
            .collect();
        outputs.extend(block.entries.iter().enumerate().map(|(k, &(_, _, v))| {
            let k = idx(k);
            (quote!(values[#k]), v)
        }));
        let kernel = self.kernel(
            cx,
            s,
            Phase::Positions,
            "the block's residual and Jacobian values",
            &format!("stage_{s}_jacobian"),
            &outputs,
            &["q"],
            &[
                ("phi", quote!(&mut [f64; #n])),
                ("values", quote!(&mut [f64; #slots])),
            ],
        );
        let call = kernel.call();
        self.jacobian.push(
            s,
            quote! {
                let (#some(phi), #some(values)) =
                    (phi.first_chunk_mut::<#n>(), values.first_chunk_mut::<#slots>())
                else {
                    phi.fill(f64::NAN);
                    values.fill(f64::NAN);
                    return;
                };
                #call;
            },
            &kernel.arguments,
        );

        // Rate right-hand sides.
        let rates: [Level; 2] = [
            ("velocity", block.velocity_rhs.clone(), &["q", "qd"]),
            (
                "acceleration",
                block.acceleration_rhs.clone(),
                &["q", "qd", "qdd"],
            ),
        ];
        for (level, (what, values, inputs)) in rates.into_iter().enumerate() {
            let Some(values) = values else {
                continue;
            };
            let outputs: Vec<(TokenStream, Id)> = values
                .iter()
                .enumerate()
                .map(|(r, &v)| {
                    let r = idx(r);
                    (quote!(out[#r]), v)
                })
                .collect();
            let kernel = self.kernel(
                cx,
                s,
                Phase::After,
                &format!("the block's {what} right-hand side"),
                &format!("stage_{s}_{what}_rhs"),
                &outputs,
                inputs,
                &[("out", quote!(&mut [f64; #n]))],
            );
            let call = kernel.call();
            let arm = quote! {
                let #some(out) = out.first_chunk_mut::<#n>() else {
                    out.fill(f64::NAN);
                    return;
                };
                #call;
            };
            [&mut self.velocity_rhs, &mut self.acceleration_rhs][level].push(
                s,
                arm,
                &kernel.arguments,
            );
        }

        // The static LU, shared with the blocks of the same pattern.
        if let Some(factorization) = &block.factorization {
            let k = shared.index(factorization);
            let (factor, solve, solve_transpose) = (
                format_ident!("factor_{}", k),
                format_ident!("solve_{}", k),
                format_ident!("solve_transpose_{}", k),
            );
            self.factor.push(
                s,
                quote! {
                    let #some(values) = values.first_chunk_mut::<#slots>() else {
                        return ::core::result::Result::Err(0);
                    };
                    Self::#factor(values, tiny, limit)
                },
                &["values", "tiny", "limit"],
            );
            for (dispatch, function) in [
                (&mut self.solve, solve),
                (&mut self.solve_transpose, solve_transpose),
            ] {
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

/// The distinct static factorisations, numbered in order of first use.
#[derive(Default)]
struct Factorizations<'p> {
    numbers: HashMap<&'p Factorization, usize>,
    order: Vec<&'p Factorization>,
}

impl<'p> Factorizations<'p> {
    fn index(&mut self, f: &'p Factorization) -> usize {
        let next = self.order.len();
        *self.numbers.entry(f).or_insert_with(|| {
            self.order.push(f);
            next
        })
    }

    /// `factor_k`, `solve_k` and `solve_transpose_k` for each factorisation.
    fn functions(&self, cx: &Context<'_>) -> Vec<TokenStream> {
        self.order
            .iter()
            .enumerate()
            .flat_map(|(k, f)| lu_functions(cx, k, f))
            .collect()
    }
}

/// The static LU `k` as straight-line code: the same operations, in the same order, as
/// [`Factorization::factor`], [`Factorization::solve`] and [`Factorization::solve_transpose`].
fn lu_functions(cx: &Context<'_>, k: usize, f: &Factorization) -> [TokenStream; 3] {
    let (n, slots) = (idx(f.n), idx(f.slots));
    let v = |s: usize| {
        let s = idx(s);
        quote!(v[#s])
    };
    let x = |i: usize| {
        let i = idx(i);
        quote!(x[#i])
    };
    let mut factor = Vec::new();
    for (step, s) in f.steps.iter().enumerate() {
        let (pivot, k_lit) = (v(s.pivot), idx(step));
        factor.push(quote! {
            if !(#pivot.abs() > tiny) {
                return ::core::result::Result::Err(#k_lit);
            }
        });
        // The pivot's reciprocal replaces it: one division per pivot here, none in the solves.
        factor.push(quote! { #pivot = 1.0 / #pivot; });
        for &(_, l) in &s.lower {
            let l = v(l);
            factor.push(quote! { #l *= #pivot; });
        }
        if !s.lower.is_empty() {
            let checks = s.lower.iter().map(|&(_, l)| {
                let l = v(l);
                quote!(#l.abs() <= limit)
            });
            factor.push(quote! {
                if !(#(#checks)&&*) {
                    return ::core::result::Result::Err(#k_lit);
                }
            });
        }
        for u in &s.updates {
            let (target, lower, upper) = (v(u.target), v(u.lower), v(u.upper));
            factor.push(if u.fill {
                quote! { #target = -(#lower * #upper); }
            } else {
                quote! { #target -= #lower * #upper; }
            });
        }
    }
    let mut solve = Vec::new();
    for (step_k, s) in f.steps.iter().enumerate() {
        for &(i, l) in &s.lower {
            let (xi, l, xk) = (x(i), v(l), x(step_k));
            solve.push(quote! { #xi -= #l * #xk; });
        }
    }
    for (step_k, s) in f.steps.iter().enumerate().rev() {
        let (xk, pivot) = (x(step_k), v(s.pivot));
        solve.push(quote! { #xk *= #pivot; });
        for &(i, u) in &f.upper_columns[step_k] {
            let (xi, u) = (x(i), v(u));
            solve.push(quote! { #xi -= #u * #xk; });
        }
    }
    let mut transpose = Vec::new();
    for (step_k, s) in f.steps.iter().enumerate() {
        let xk = x(step_k);
        for &(i, u) in &f.upper_columns[step_k] {
            let (xi, u) = (x(i), v(u));
            transpose.push(quote! { #xk -= #u * #xi; });
        }
        let pivot = v(s.pivot);
        transpose.push(quote! { #xk *= #pivot; });
    }
    for (step_k, s) in f.steps.iter().enumerate().rev() {
        let xk = x(step_k);
        for &(i, l) in &s.lower {
            let (xi, l) = (x(i), v(l));
            transpose.push(quote! { #xk -= #l * #xi; });
        }
    }
    let uses_limit = f.steps.iter().any(|s| !s.lower.is_empty());
    let limit = if uses_limit {
        format_ident!("limit")
    } else {
        format_ident!("_limit")
    };
    let summary = [
        format!(
            " Static LU {k}: {n} × {n}, {} entries, {} fill-in, {} update{}.",
            f.entries,
            f.fill(),
            f.updates(),
            if f.updates() == 1 { "" } else { "s" },
            n = f.n
        ),
        String::new(),
        " Pivots on the diagonal in the block's order, each above `tiny` (then stored as its"
            .to_owned(),
        " reciprocal), its multipliers at most `limit`; returns the first step that fails."
            .to_owned(),
    ];
    let factor_name = format_ident!("factor_{}", k);
    let factor = split(
        cx,
        &factor_name,
        factor,
        quote!(v: &mut [f64; #slots], tiny: f64, #limit: f64),
        quote!(v, tiny, #limit),
        true,
    );
    let solve_name = format_ident!("solve_{}", k);
    let solve = split(
        cx,
        &solve_name,
        solve,
        quote!(v: &[f64; #slots], x: &mut [f64; #n]),
        quote!(v, x),
        false,
    );
    let transpose_name = format_ident!("solve_transpose_{}", k);
    let transpose = split(
        cx,
        &transpose_name,
        transpose,
        quote!(v: &[f64; #slots], x: &mut [f64; #n]),
        quote!(v, x),
        false,
    );
    let solve_doc = format!(" Solves `A x = b` in place with the factors of static LU {k}.");
    let transpose_doc = format!(" Solves `Aᵀ x = b` in place with the factors of static LU {k}.");
    [
        quote! { #(#[doc = #summary])* #factor },
        quote! { #[doc = #solve_doc] #solve },
        quote! { #[doc = #transpose_doc] #transpose },
    ]
}

/// A function of straight-line `statements`; beyond `max_function_size` statements, split into
/// parts called in turn (factor parts return early with `?`).
fn split(
    cx: &Context<'_>,
    name: &proc_macro2::Ident,
    statements: Vec<TokenStream>,
    params: TokenStream,
    arguments: TokenStream,
    fallible: bool,
) -> TokenStream {
    let max = cx.options.max_function_size.max(1);
    let result = fallible.then(|| quote!(-> ::core::result::Result<(), usize>));
    let ok = fallible.then(|| quote!(::core::result::Result::Ok(())));
    // The factor's tests read `!(|pivot| > tiny)`, `!(|l| <= limit)`: NaN fails them.
    let allow = fallible.then(|| quote!(#[allow(clippy::neg_cmp_op_on_partial_ord)]));
    if statements.len() <= max {
        return quote! {
            #allow
            fn #name(#params) #result {
                #(#statements)*
                #ok
            }
        };
    }
    let mut parts = Vec::new();
    let mut calls = Vec::new();
    for (p, chunk) in statements.chunks(max).enumerate() {
        let part = format_ident!("{}_part{}", name, p);
        let question = fallible.then(|| quote!(?));
        calls.push(quote! { Self::#part(#arguments) #question; });
        parts.push(quote! {
            #[inline(never)]
            #[allow(unused_variables)]
            #allow
            fn #part(#params) #result {
                #(#chunk)*
                #ok
            }
        });
    }
    cx.helpers.borrow_mut().extend(parts);
    quote! {
        fn #name(#params) #result {
            #(#calls)*
            #ok
        }
    }
}
