//! Emission: a model and its kinematics as straight-line Rust (`quote!`).
//!
//! Each generated function evaluates the DAG reachable from its outputs once, in a deterministic
//! topological order: a node used more than once, and every elementary function call, becomes a
//! `let`; a node used once is written inline. No loops, no allocation, no `std`, no `unsafe`;
//! elementary functions come from `::mechgen_runtime::math`. Zero entries are never computed: the
//! output is cleared once and only non-zeros are written.

use std::cell::RefCell;
use std::collections::{BTreeSet, HashSet};

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

use crate::expr::{Arena, Func, Id, Node, Var};
use crate::interpret::topological_order;
use crate::kinematics::Kinematics;
use crate::model::{COORDINATE_SUFFIXES, Model, Outputs, Unit};
use crate::stats::OpCounts;

/// Choices that shape the generated code without changing its meaning.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CodegenOptions {
    /// Largest number of operations (DAG nodes plus output stores) one generated function body
    /// may hold; longer
    /// bodies are split into helper functions of about this size. rustc's compile time grows
    /// much faster than linearly in the size of one function, so huge scenes need this.
    pub max_function_size: usize,
    /// The naive baseline, for measuring what the lean emission saves: no constant folding or
    /// algebraic simplification (the scene is compiled into [`Arena::unsimplified`]) and no
    /// shared sub-expressions (every use evaluated again). Never for production code.
    pub naive: bool,
}

impl Default for CodegenOptions {
    fn default() -> Self {
        Self {
            max_function_size: 2_000,
            naive: false,
        }
    }
}

/// Emits the whole item set for a scene with default options (see [`emit_with`]).
pub fn emit(model: &Model, kin: &Kinematics) -> TokenStream {
    emit_with(model, kin, &CodegenOptions::default())
}

/// Emits the whole item set for a scene: the parameter struct, its constants, the `Mechanism`
/// implementation and the named body accessors.
pub fn emit_with(model: &Model, kin: &Kinematics, options: &CodegenOptions) -> TokenStream {
    let name = &model.name;
    let vis = &model.vis;
    let docs = &model.docs;
    let n = model.dim();
    let n_lit = idx(n);
    let coordinate_names = model.coordinate_names();
    let equation_names = model.equation_names();

    let param_fields = model.params.iter().map(|p| {
        let (docs, name) = (&p.docs, &p.name);
        quote! { #(#docs)* pub #name: f64, }
    });
    let param_defaults = model.params.iter().map(|p| {
        let (name, value) = (&p.name, f64_literal(p.default));
        quote! { #name: #value, }
    });
    let param_names: Vec<String> = model.params.iter().map(|p| p.name.to_string()).collect();
    let param_count = idx(param_names.len());
    let param_reads = model.params.iter().enumerate().map(|(i, p)| {
        let (i, name) = (idx(i), &p.name);
        quote! { #i => ::core::option::Option::Some(self.#name), }
    });
    let param_writes = model.params.iter().map(|p| {
        let (name, key) = (&p.name, p.name.to_string());
        quote! {
            #key => {
                self.#name = value;
                ::core::result::Result::Ok(())
            }
        }
    });

    let coordinate_consts = coordinate_names.iter().enumerate().map(|(i, c)| {
        let ident = format_ident!("{}", c.replace('.', "_").to_uppercase());
        let doc = format!(" Index of `{c}` in q.");
        let i = idx(i);
        quote! { #[doc = #doc] pub const #ident: usize = #i; }
    });
    let jacobian_count = idx(kin.jacobian.len());
    let pattern = kin.jacobian.iter().map(|e| {
        let (r, c) = (idx(e.row), idx(e.col));
        quote! { (#r, #c) }
    });

    let cx = Context {
        model,
        options,
        helpers: RefCell::new(Vec::new()),
    };
    let vector_type =
        quote!(&mut ::mechgen_runtime::Vector<::mechgen_runtime::nalgebra::Const<#n_lit>>);
    let matrix_type =
        quote!(&mut ::mechgen_runtime::Matrix<::mechgen_runtime::nalgebra::Const<#n_lit>>);
    let vector = |values: &[Id], target: TokenStream| {
        let clear = clear_if_sparse(&model.arena, values, &target);
        (vector_outputs(values, &target), clear)
    };
    let jacobian_outputs = |target: TokenStream| {
        let outputs: Vec<(TokenStream, Id)> = kin
            .jacobian
            .iter()
            .map(|e| (matrix_target(&target, e.row, e.col), e.value))
            .collect();
        let clear = if kin.jacobian.len() < n * n {
            quote! { #target.as_mut_slice().fill(0.0); }
        } else {
            TokenStream::new()
        };
        (outputs, clear)
    };
    let guess = {
        let (outputs, clear) = vector(&kin.guess, quote!(q));
        cx.function(&outputs, clear)
    };
    let out_vector = [("out", vector_type.clone())];
    let phi = {
        let (outputs, clear) = vector(&kin.phi, quote!(out));
        cx.bounded("phi", &outputs, clear, &out_vector, false)
    };
    let jacobian = {
        let (outputs, clear) = jacobian_outputs(quote!(out));
        cx.bounded(
            "jacobian",
            &outputs,
            clear,
            &[("out", matrix_type.clone())],
            false,
        )
    };
    let phi_and_jacobian = {
        let (mut outputs, mut clear) = vector(&kin.phi, quote!(phi));
        let (jac_outputs, jac_clear) = jacobian_outputs(quote!(jacobian));
        outputs.extend(jac_outputs);
        clear.extend(jac_clear);
        let outs = [
            ("phi", vector_type.clone()),
            ("jacobian", matrix_type.clone()),
        ];
        cx.bounded("phi_and_jacobian", &outputs, clear, &outs, false)
    };
    let nu = kin.nu.as_deref().map(|nu| {
        let (outputs, clear) = vector(nu, quote!(out));
        cx.bounded("nu", &outputs, clear, &out_vector, false)
    });
    let gamma = kin.gamma.as_deref().map(|gamma| {
        let (outputs, clear) = vector(gamma, quote!(out));
        cx.bounded("gamma", &outputs, clear, &out_vector, true)
    });
    let length_scale = cx.length_scale(kin);
    let branches = cx.branches(kin);
    let helpers = cx.helpers.into_inner();
    let helpers_impl = (!helpers.is_empty()).then(|| {
        quote! {
            /// Parts of the kinematic functions, split to keep each function small enough for
            /// rustc (`CodegenOptions::max_function_size`).
            impl #name {
                #(#helpers)*
            }
        }
    });

    let guess_body = guess.body;
    let (phi_doc, phi_body, phi_args) = (phi.doc("Φ(q, t)"), phi.body, phi.args);
    let (jac_doc, jac_body, jac_args) = (jacobian.doc("Φ_q(q, t)"), jacobian.body, jacobian.args);
    let (pj_doc, pj_body, pj_args) = (
        phi_and_jacobian.doc("Φ and Φ_q in one pass, sharing sub-expressions"),
        phi_and_jacobian.body,
        phi_and_jacobian.args,
    );
    let [phi_q, _, phi_t] = phi_args;
    let [jac_q, _, jac_t] = jac_args;
    let [pj_q, _, pj_t] = pj_args;
    let velocities_impl = nu.map(|nu| {
        let (doc, body, [q, _, t]) = (nu.doc("ν = −Φ_t"), nu.body, nu.args);
        quote! {
            impl ::mechgen_runtime::Velocities for #name {
                #doc
                fn nu(
                    &self,
                    #q: &::mechgen_runtime::Vector<Self::Dim>,
                    #t: f64,
                    out: &mut ::mechgen_runtime::Vector<Self::Dim>,
                ) {
                    #body
                }
            }
        }
    });
    let accelerations_impl = gamma.map(|gamma| {
        let (doc, body, [q, qd, t]) = (gamma.doc("γ(q, q̇, t)"), gamma.body, gamma.args);
        quote! {
            impl ::mechgen_runtime::Accelerations for #name {
                #doc
                fn gamma(
                    &self,
                    #q: &::mechgen_runtime::Vector<Self::Dim>,
                    #qd: &::mechgen_runtime::Vector<Self::Dim>,
                    #t: f64,
                    out: &mut ::mechgen_runtime::Vector<Self::Dim>,
                ) {
                    #body
                }
            }
        }
    });
    // The derivative solves the scene asked for; unused arguments get a leading underscore.
    let (outputs_variant, derivative_args, derivatives_body) = match model.outputs {
        Outputs::Positions => (
            quote!(Positions),
            ["_q", "_t", "_factors", "_qd", "_qdd"],
            quote! { ::core::result::Result::Ok(()) },
        ),
        Outputs::Velocities => (
            quote!(Velocities),
            ["q", "t", "factors", "qd", "_qdd"],
            quote! { ::mechgen_runtime::solve_velocities(self, q, t, factors, qd) },
        ),
        Outputs::Accelerations => (
            quote!(Accelerations),
            ["q", "t", "factors", "qd", "qdd"],
            quote! {
                ::mechgen_runtime::solve_velocities(self, q, t, factors, qd)?;
                ::mechgen_runtime::solve_accelerations(self, q, qd, t, factors, qdd)
            },
        ),
    };
    let [d_q, d_t, d_factors, d_qd, d_qdd] = derivative_args.map(|a| format_ident!("{}", a));

    let bodies_trait = format_ident!("{}Bodies", name);
    let bodies_doc = format!(
        " Named access to the bodies of a solved [`{name}`] state: `state.{}().x`.",
        model
            .bodies
            .iter()
            .find(|b| !b.ground)
            .map_or("body".to_owned(), |b| b.name.to_string())
    );
    let (view, what) = match model.outputs {
        Outputs::Positions => (quote!(Pose), "Pose"),
        Outputs::Velocities => (quote!(PoseVelocity), "Pose and velocity"),
        Outputs::Accelerations => (quote!(BodyState), "Pose, velocity and acceleration"),
    };
    let accessor_decls = model.bodies.iter().map(|b| {
        let ident = &b.name;
        let docs = if b.docs.is_empty() {
            let doc = format!(" {what} of `{ident}`.");
            quote! { #[doc = #doc] }
        } else {
            let docs = &b.docs;
            quote! { #(#docs)* }
        };
        quote! { #docs fn #ident(&self) -> ::mechgen_runtime::#view; }
    });
    let accessor_impls = model.bodies.iter().enumerate().map(|(i, b)| {
        let ident = &b.name;
        let [x, y, th] = [3 * i, 3 * i + 1, 3 * i + 2].map(idx);
        let velocity = (model.outputs >= Outputs::Velocities).then(|| {
            quote! { x_dot: self.qd()[#x], y_dot: self.qd()[#y], theta_dot: self.qd()[#th], }
        });
        let acceleration = (model.outputs >= Outputs::Accelerations).then(|| {
            quote! { x_ddot: self.qdd()[#x], y_ddot: self.qdd()[#y], theta_ddot: self.qdd()[#th], }
        });
        quote! {
            fn #ident(&self) -> ::mechgen_runtime::#view {
                ::mechgen_runtime::#view {
                    x: self.q[#x], y: self.q[#y], theta: self.q[#th],
                    #velocity
                    #acceleration
                }
            }
        }
    });

    let unit_list = |units: Vec<Unit>| {
        let units = units.into_iter().map(|u| {
            let variant = format_ident!("{}", u.name());
            quote!(::mechgen_runtime::Unit::#variant)
        });
        quote!([#(#units),*])
    };
    let coordinate_units = unit_list(model.coordinate_units());
    let equation_units = unit_list(model.equation_units());

    let (branch_names_const, branch_methods) = branches.unwrap_or_default();

    let coordinate_doc = format!(
        " Coordinate names in q order ({n} = 3 × {} bodies).",
        model.bodies.len()
    );
    let equation_doc = format!(" Equation names in Φ order ({n} equations).");
    let pattern_doc = format!(
        " Structural non-zeros of Φ_q as (equation, coordinate), row-major: {jacobian_count} of {}.",
        n * n
    );

    quote! {
        #(#docs)*
        #[derive(Debug, Clone, Copy, PartialEq)]
        #vis struct #name {
            #(#param_fields)*
        }

        impl ::core::default::Default for #name {
            fn default() -> Self {
                Self { #(#param_defaults)* }
            }
        }

        impl #name {
            /// Number of coordinates (= number of equations).
            pub const DIM: usize = #n_lit;
            #[doc = #coordinate_doc]
            pub const COORDINATES: [&'static str; #n_lit] = [#(#coordinate_names),*];
            #[doc = #equation_doc]
            pub const EQUATIONS: [&'static str; #n_lit] = [#(#equation_names),*];
            /// Run-time parameter names, in declaration order.
            pub const PARAMETERS: [&'static str; #param_count] = [#(#param_names),*];
            #[doc = #pattern_doc]
            pub const JACOBIAN_PATTERN: [(usize, usize); #jacobian_count] = [#(#pattern),*];
            /// Physical dimension of each coordinate, in q order (x, y lengths, θ angles).
            pub const COORDINATE_UNITS: [::mechgen_runtime::Unit; #n_lit] = #coordinate_units;
            /// Physical dimension of each equation, in Φ order.
            pub const EQUATION_UNITS: [::mechgen_runtime::Unit; #n_lit] = #equation_units;
            #branch_names_const
            #(#coordinate_consts)*
        }

        impl ::mechgen_runtime::Mechanism for #name {
            type Dim = ::mechgen_runtime::nalgebra::Const<#n_lit>;

            fn dim(&self) -> Self::Dim {
                ::mechgen_runtime::nalgebra::Const::<#n_lit>
            }

            fn coordinate_name(&self, index: usize) -> ::core::option::Option<&str> {
                Self::COORDINATES.get(index).copied()
            }

            fn equation_name(&self, index: usize) -> ::core::option::Option<&str> {
                Self::EQUATIONS.get(index).copied()
            }

            fn parameter_count(&self) -> usize {
                #param_count
            }

            fn parameter_name(&self, index: usize) -> ::core::option::Option<&str> {
                Self::PARAMETERS.get(index).copied()
            }

            fn parameter(&self, index: usize) -> ::core::option::Option<f64> {
                match index {
                    #(#param_reads)*
                    _ => ::core::option::Option::None,
                }
            }

            fn set_parameter(
                &mut self,
                name: &str,
                value: f64,
            ) -> ::core::result::Result<(), ::mechgen_runtime::ParameterError> {
                if !value.is_finite() {
                    return ::core::result::Result::Err(::mechgen_runtime::ParameterError::NonFinite);
                }
                match name {
                    #(#param_writes)*
                    _ => ::core::result::Result::Err(::mechgen_runtime::ParameterError::Unknown),
                }
            }

            fn coordinate_unit(&self, index: usize) -> ::mechgen_runtime::Unit {
                Self::COORDINATE_UNITS
                    .get(index)
                    .copied()
                    .unwrap_or(::mechgen_runtime::Unit::Angle)
            }

            fn equation_unit(&self, index: usize) -> ::mechgen_runtime::Unit {
                Self::EQUATION_UNITS
                    .get(index)
                    .copied()
                    .unwrap_or(::mechgen_runtime::Unit::Angle)
            }

            #length_scale

            #branch_methods

            fn initial_guess(&self, q: &mut ::mechgen_runtime::Vector<Self::Dim>) {
                #guess_body
            }

            #phi_doc
            fn phi(
                &self,
                #phi_q: &::mechgen_runtime::Vector<Self::Dim>,
                #phi_t: f64,
                out: &mut ::mechgen_runtime::Vector<Self::Dim>,
            ) {
                #phi_body
            }

            #jac_doc
            fn jacobian(
                &self,
                #jac_q: &::mechgen_runtime::Vector<Self::Dim>,
                #jac_t: f64,
                out: &mut ::mechgen_runtime::Matrix<Self::Dim>,
            ) {
                #jac_body
            }

            #pj_doc
            fn phi_and_jacobian(
                &self,
                #pj_q: &::mechgen_runtime::Vector<Self::Dim>,
                #pj_t: f64,
                phi: &mut ::mechgen_runtime::Vector<Self::Dim>,
                jacobian: &mut ::mechgen_runtime::Matrix<Self::Dim>,
            ) {
                #pj_body
            }

            fn outputs(&self) -> ::mechgen_runtime::Outputs {
                ::mechgen_runtime::Outputs::#outputs_variant
            }

            fn derivatives(
                &self,
                #d_q: &::mechgen_runtime::Vector<Self::Dim>,
                #d_t: f64,
                #d_factors: &::mechgen_runtime::Lu<Self::Dim>,
                #d_qd: &mut ::mechgen_runtime::Vector<Self::Dim>,
                #d_qdd: &mut ::mechgen_runtime::Vector<Self::Dim>,
            ) -> ::core::result::Result<(), ::mechgen_runtime::SolveError> {
                #derivatives_body
            }
        }

        #velocities_impl

        #accelerations_impl

        #helpers_impl

        #[doc = #bodies_doc]
        #vis trait #bodies_trait {
            #(#accessor_decls)*
        }

        impl #bodies_trait for ::mechgen_runtime::State<#name> {
            #(#accessor_impls)*
        }
    }
}

fn vector_outputs(values: &[Id], target: &TokenStream) -> Vec<(TokenStream, Id)> {
    values
        .iter()
        .enumerate()
        .map(|(i, &id)| {
            let i = idx(i);
            (quote!(#target[#i]), id)
        })
        .collect()
}

/// An index or size literal without a `usize` suffix (generated code is read by people).
fn idx(i: usize) -> Literal {
    Literal::usize_unsuffixed(i)
}

/// `out[(r, c)]` for a Jacobian entry.
fn matrix_target(target: &TokenStream, row: usize, col: usize) -> TokenStream {
    let (r, c) = (idx(row), idx(col));
    quote!(#target[(#r, #c)])
}

/// Clears `target` if some of `values` are identically zero (only non-zeros are written).
fn clear_if_sparse(arena: &Arena, values: &[Id], target: &TokenStream) -> TokenStream {
    if values.iter().any(|&v| arena.is_zero(v)) {
        // Slice fill: nalgebra's `fill` goes element by element, ~18× slower for a 15 × 15.
        quote! { #target.as_mut_slice().fill(0.0); }
    } else {
        TokenStream::new()
    }
}

/// One generated function body with the names its arguments must take (`q` or `_q` if unused).
struct Function {
    body: TokenStream,
    /// Argument names for q, q̇, t.
    args: [Ident; 3],
    counts: OpCounts,
}

impl Function {
    /// Two doc lines: what the function writes, and what it costs.
    fn doc(&self, what: &str) -> TokenStream {
        let (what, cost) = (
            format!(" Writes {what}."),
            format!(" Operations: {}.", self.counts),
        );
        quote! { #[doc = #what] #[doc = ""] #[doc = #cost] }
    }
}

struct Context<'a> {
    model: &'a Model,
    options: &'a CodegenOptions,
    /// Helper functions of split bodies, emitted in an inherent `impl` block.
    helpers: RefCell<Vec<TokenStream>>,
}

impl Context<'_> {
    fn arena(&self) -> &Arena {
        &self.model.arena
    }

    /// `length_scale`: the constant lengths folded into one literal, the parameter-dependent
    /// ones evaluated and folded in with `max(|v|)`, in the order of
    /// [`LengthScale::evaluate`](crate::kinematics::LengthScale::evaluate).
    fn length_scale(&self, kin: &Kinematics) -> TokenStream {
        let scale = &kin.length_scale;
        let constant = f64_literal(scale.constant);
        let doc = format!(
            " The largest magnitude among the scene's geometric lengths (body-fixed points, \
             distances, ground positions){}.",
            if scale.dependent.is_empty() {
                String::new()
            } else {
                format!(
                    ": the constant ones folded into `{}`, {} parameter-dependent one{} \
                     evaluated with the current parameters",
                    scale.constant,
                    scale.dependent.len(),
                    if scale.dependent.len() == 1 { "" } else { "s" }
                )
            }
        );
        let body = if scale.dependent.is_empty() {
            constant
        } else {
            let names: Vec<Ident> = (0..scale.dependent.len())
                .map(|k| format_ident!("length{}", k))
                .collect();
            let outputs: Vec<(TokenStream, Id)> = names
                .iter()
                .zip(&scale.dependent)
                .map(|(name, &id)| (quote!(let #name), id))
                .collect();
            let zero = names
                .iter()
                .zip(&scale.dependent)
                .filter(|&(_, &id)| self.arena().is_zero(id))
                .map(|(name, _)| quote! { let #name = 0.0f64; });
            let zero: Vec<TokenStream> = zero.collect();
            let evaluated = self.function(&outputs, TokenStream::new()).body;
            quote! {
                #evaluated
                #(#zero)*
                let scale: f64 = #constant;
                scale #(.max(#names.abs()))*
            }
        };
        quote! {
            #[doc = #doc]
            fn length_scale(&self) -> f64 {
                #body
            }
        }
    }

    /// The `BRANCHES` names and the `branch_*` methods, or `None` for a scene without branch
    /// invariants (the trait's defaults then say "none").
    fn branches(&self, kin: &Kinematics) -> Option<(TokenStream, TokenStream)> {
        if kin.branches.is_empty() {
            return None;
        }
        let names: Vec<&str> = self
            .model
            .branches
            .iter()
            .map(|b| b.name.as_str())
            .collect();
        let count = idx(names.len());
        let mut reads_q = false;
        let arms = kin.branches.iter().enumerate().map(|(i, &id)| {
            let value = if self.arena().is_zero(id) {
                quote!(0.0)
            } else {
                let f = self.function(&[(TokenStream::new(), id)], TokenStream::new());
                reads_q |= f.args[0] == "q";
                let body = f.body;
                quote! { { #body } }
            };
            let i = idx(i);
            quote! { #i => #value, }
        });
        let arms: Vec<TokenStream> = arms.collect();
        let q = if reads_q {
            format_ident!("q")
        } else {
            format_ident!("_q")
        };
        let docs = self.model.branches.iter().map(|b| {
            let line = format!(" - `{}`: `{}`", b.name, self.model.describe_branch(b));
            quote! { #[doc = #line] }
        });
        let names_const = quote! {
            /// Branch invariants, in declaration order:
            ///
            #(#docs)*
            pub const BRANCHES: [&'static str; #count] = [#(#names),*];
        };
        let methods = quote! {
            fn branch_count(&self) -> usize {
                #count
            }

            fn branch_name(&self, index: usize) -> ::core::option::Option<&str> {
                Self::BRANCHES.get(index).copied()
            }

            /// The invariant's value, signed to be positive on the declared branch.
            fn branch_value(
                &self,
                index: usize,
                #q: &::mechgen_runtime::Vector<Self::Dim>,
            ) -> f64 {
                match index {
                    #(#arms)*
                    _ => f64::NAN,
                }
            }
        };
        Some((names_const, methods))
    }

    /// Like [`Context::function`], but a body larger than `max_function_size` operations is
    /// split: its outputs are grouped in order into parts of bounded size, each emitted as a
    /// helper method (recomputing the few shared sub-expressions a part needs), and the body
    /// calls them in turn. `outs` are the output parameters (name, type) passed to each part.
    fn bounded(
        &self,
        name: &str,
        outputs: &[(TokenStream, Id)],
        clear: TokenStream,
        outs: &[(&str, TokenStream)],
        reads_qd: bool,
    ) -> Function {
        let groups = self.partition(outputs);
        if groups.len() <= 1 {
            return self.function(outputs, clear);
        }
        let n = idx(self.model.dim());
        let vector = quote!(::mechgen_runtime::Vector<::mechgen_runtime::nalgebra::Const<#n>>);
        let mut calls = Vec::new();
        let mut counts = OpCounts::default();
        for (k, group) in groups.iter().enumerate() {
            // Only the outputs this part writes (a Φ part of `phi_and_jacobian` takes no Φ_q).
            let written: Vec<&(&str, TokenStream)> = outs
                .iter()
                .filter(|(o, _)| group.iter().any(|(target, _)| writes_to(target, o)))
                .collect();
            let out_names: Vec<Ident> = written
                .iter()
                .map(|(o, _)| format_ident!("{}", o))
                .collect();
            let out_types: Vec<&TokenStream> = written.iter().map(|(_, ty)| ty).collect();
            let part = self.function(group, TokenStream::new());
            counts = counts + part.counts;
            let [q, qd, t] = &part.args;
            let part_name = format_ident!("{}_part{}", name, k);
            let body = part.body;
            let (qd_param, qd_arg) = if reads_qd {
                (quote!(#qd: &#vector,), quote!(qd,))
            } else {
                (TokenStream::new(), TokenStream::new())
            };
            self.helpers.borrow_mut().push(quote! {
                #[inline(never)]
                fn #part_name(
                    &self,
                    #q: &#vector,
                    #qd_param
                    #t: f64,
                    #(#out_names: #out_types),*
                ) {
                    #body
                }
            });
            calls.push(quote! { self.#part_name(q, #qd_arg t, #(#out_names),*); });
        }
        let qd = if reads_qd { "qd" } else { "_qd" };
        Function {
            body: quote! { #clear #(#calls)* },
            args: [
                format_ident!("q"),
                format_ident!("{}", qd),
                format_ident!("t"),
            ],
            counts,
        }
    }

    /// Non-zero `outputs`, in order, grouped so that each group's DAG nodes plus its output
    /// stores number at most `max_function_size` (an output larger than that on its own is a
    /// group by itself).
    fn partition(&self, outputs: &[(TokenStream, Id)]) -> Vec<Vec<(TokenStream, Id)>> {
        let arena = self.arena();
        let max = self.options.max_function_size.max(1);
        // `group_of[node]` is the group whose DAG already holds the node (0: none yet).
        let mut group_of = vec![0usize; arena.len()];
        let mut groups: Vec<Vec<(TokenStream, Id)>> = vec![Vec::new()];
        let mut size = 0;
        let mut fresh = Vec::new();
        for (target, id) in outputs.iter().filter(|(_, id)| !arena.is_zero(*id)) {
            // Each output is a store as well as the nodes it needs: a part of thousands of
            // stores of shared constants is still a big function for rustc.
            new_nodes(arena, *id, &group_of, groups.len(), &mut fresh);
            if size + fresh.len() + 1 > max && !groups.last().is_some_and(Vec::is_empty) {
                groups.push(Vec::new());
                size = 0;
                new_nodes(arena, *id, &group_of, groups.len(), &mut fresh);
            }
            for node in &fresh {
                group_of[node.index()] = groups.len();
            }
            size += fresh.len() + 1;
            if let Some(group) = groups.last_mut() {
                group.push((target.clone(), *id));
            }
        }
        groups
    }

    /// A function body writing `outputs` (non-zero entries; zeros are cleared in one call).
    ///
    /// An output with an empty target is written as a bare expression: as the last output, it
    /// is the body's value (a block's tail).
    fn function(&self, outputs: &[(TokenStream, Id)], clear: TokenStream) -> Function {
        let arena = self.arena();
        let nonzero: Vec<&(TokenStream, Id)> = outputs
            .iter()
            .filter(|(_, id)| !arena.is_zero(*id))
            .collect();
        let roots: Vec<Id> = nonzero.iter().map(|(_, id)| *id).collect();
        let order = topological_order(arena, &roots);

        let mut uses = vec![0usize; arena.len()];
        for &id in &order {
            for child in arena.children(id) {
                uses[child.index()] += 1;
            }
        }
        for &id in &roots {
            uses[id.index()] += 1;
        }

        let mut names = Names::default();
        let mut bound: Vec<Option<Ident>> = vec![None; arena.len()];
        let mut rendered: Vec<Option<(TokenStream, Prec)>> = vec![None; arena.len()];
        let mut lets = Vec::new();
        // Coordinate loads go first, in q order: the reader sees the inputs, then the work.
        let mut loads: Vec<(Var, TokenStream)> = Vec::new();
        let mut funcs = BTreeSet::new();
        let mut used = [false; 3];
        let counts = if self.options.naive {
            OpCounts::of_tree(arena, &roots)
        } else {
            OpCounts::of(arena, &order)
        };

        for &id in &order {
            let node = arena.node(id);
            let operand = |x: Id| -> (TokenStream, Prec) {
                match &bound[x.index()] {
                    Some(ident) => (quote!(#ident), Prec::Atom),
                    None => rendered[x.index()]
                        .clone()
                        .unwrap_or_else(|| (quote!(0.0), Prec::Atom)),
                }
            };
            let (tokens, prec) = match node {
                Node::Const(bits) => {
                    let value = f64::from_bits(bits);
                    // Negative literals are written `-c` and parenthesised like a sum in operands.
                    let prec = if value < 0.0 { Prec::Sum } else { Prec::Atom };
                    (f64_literal(value), prec)
                }
                Node::Param(i) => {
                    let name = &self.model.params[i as usize].name;
                    (quote!(self.#name), Prec::Atom)
                }
                Node::Var(Var::T) => {
                    used[2] = true;
                    (quote!(t), Prec::Atom)
                }
                Node::Var(Var::Q(k)) => {
                    used[0] = true;
                    let k = idx(k as usize);
                    (quote!(q[#k]), Prec::Atom)
                }
                Node::Var(Var::Qd(k)) => {
                    used[1] = true;
                    let k = idx(k as usize);
                    (quote!(qd[#k]), Prec::Atom)
                }
                Node::Neg(a) => {
                    let a = operand(a).wrap(Prec::Unary);
                    (quote!(-#a), Prec::Unary)
                }
                Node::Add(a, b) => binary(operand(a), quote!(+), operand(b), Prec::Sum),
                Node::Sub(a, b) => binary(operand(a), quote!(-), operand(b), Prec::Sum),
                Node::Mul(a, b) => binary(operand(a), quote!(*), operand(b), Prec::Product),
                Node::Div(a, b) => binary(operand(a), quote!(/), operand(b), Prec::Product),
                Node::Powi(a, n) => {
                    funcs.insert("powi");
                    let a = operand(a).0;
                    (quote!(powi(#a, #n)), Prec::Atom)
                }
                Node::Call(f, a) => {
                    funcs.insert(f.name());
                    let f_ident = format_ident!("{}", f.name());
                    let a = operand(a).0;
                    (quote!(#f_ident(#a)), Prec::Atom)
                }
            };
            let is_leaf = matches!(node, Node::Const(_) | Node::Param(_) | Node::Var(Var::T));
            // Coordinates are loaded once; the naive baseline shares nothing else.
            let shared = matches!(node, Node::Call(..)) || uses[id.index()] > 1;
            let bind =
                !is_leaf && (matches!(node, Node::Var(_)) || (shared && !self.options.naive));
            if bind {
                let ident = names.fresh(&self.suggest(id));
                let statement = quote! { let #ident = #tokens; };
                match node {
                    Node::Var(v) => loads.push((v, statement)),
                    _ => lets.push(statement),
                }
                bound[id.index()] = Some(ident);
            } else {
                rendered[id.index()] = Some((tokens, prec));
            }
        }

        let writes = nonzero.iter().map(|(target, id)| {
            let value = match &bound[id.index()] {
                Some(ident) => quote!(#ident),
                None => rendered[id.index()]
                    .clone()
                    .map_or_else(|| quote!(0.0), |(t, _)| t),
            };
            if target.is_empty() {
                value
            } else {
                quote! { #target = #value; }
            }
        });
        let imports = if funcs.is_empty() {
            TokenStream::new()
        } else {
            let funcs = funcs.iter().map(|f| format_ident!("{}", f));
            quote! { use ::mechgen_runtime::math::{#(#funcs),*}; }
        };
        let arg = |used: bool, name: &str| {
            if used {
                format_ident!("{}", name)
            } else {
                format_ident!("_{}", name)
            }
        };
        loads.sort_by_key(|(v, _)| *v);
        let loads = loads.into_iter().map(|(_, statement)| statement);
        Function {
            body: quote! { #imports #(#loads)* #(#lets)* #clear #(#writes)* },
            args: [arg(used[0], "q"), arg(used[1], "qd"), arg(used[2], "t")],
            counts,
        }
    }

    /// A readable name for a bound node: `rod_theta`, `sin_rod_theta`, `piston_x_dot`, or `e`.
    fn suggest(&self, id: Id) -> String {
        let arena = self.arena();
        let coordinate = |k: u32| {
            let k = k as usize;
            let body = &self.model.bodies[k / 3].name;
            format!("{body}_{}", COORDINATE_SUFFIXES[k % 3])
        };
        match arena.node(id) {
            Node::Var(Var::Q(k)) => coordinate(k),
            Node::Var(Var::Qd(k)) => format!("{}_dot", coordinate(k)),
            Node::Call(f, a) => match arena.node(a) {
                Node::Var(Var::Q(k)) => format!("{}_{}", f.name(), coordinate(k)),
                _ => f.name().to_owned() + "_",
            },
            _ => "e".to_owned(),
        }
    }
}

/// True if an output target (`out[3]`, `jacobian[(1, 2)]`) writes to the parameter `name`.
fn writes_to(target: &TokenStream, name: &str) -> bool {
    matches!(target.clone().into_iter().next(), Some(proc_macro2::TokenTree::Ident(i)) if i == name)
}

/// The nodes reachable from `root` not yet in group `group`, into `fresh` (iterative: scenes can
/// be deep).
fn new_nodes(arena: &Arena, root: Id, group_of: &[usize], group: usize, fresh: &mut Vec<Id>) {
    fresh.clear();
    let mut seen = HashSet::new();
    let mut stack = vec![root];
    while let Some(id) = stack.pop() {
        if group_of[id.index()] == group || !seen.insert(id) {
            continue;
        }
        fresh.push(id);
        stack.extend(arena.children(id));
    }
}

/// Unique, hygienic local names (numbered where a suggestion repeats).
#[derive(Default)]
struct Names {
    taken: HashSet<String>,
    counter: usize,
}

impl Names {
    fn fresh(&mut self, suggestion: &str) -> Ident {
        let numbered = suggestion.ends_with('_') || suggestion == "e";
        let mut candidate = suggestion.trim_end_matches('_').to_owned();
        if numbered || self.taken.contains(&candidate) || Func::from_name(&candidate).is_some() {
            loop {
                let next = format!("{}{}", candidate.trim_end_matches('_'), self.counter);
                self.counter += 1;
                if !self.taken.contains(&next) {
                    candidate = next;
                    break;
                }
            }
        }
        self.taken.insert(candidate.clone());
        Ident::new(&candidate, Span::mixed_site())
    }
}

/// Binding strength, for parenthesising inlined operands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Prec {
    Sum,
    Product,
    Unary,
    Atom,
}

trait Wrap {
    fn wrap(self, min: Prec) -> TokenStream;
}

impl Wrap for (TokenStream, Prec) {
    fn wrap(self, min: Prec) -> TokenStream {
        let (tokens, prec) = self;
        if prec < min {
            quote!((#tokens))
        } else {
            tokens
        }
    }
}

/// `a op b`, left-associative: the right operand is parenthesised at equal precedence so the
/// generated code evaluates in exactly the DAG's order (same rounding as the interpreter).
fn binary(
    a: (TokenStream, Prec),
    op: TokenStream,
    b: (TokenStream, Prec),
    prec: Prec,
) -> (TokenStream, Prec) {
    let a = a.wrap(prec);
    let b = if b.1 <= prec {
        let tokens = b.0;
        quote!((#tokens))
    } else {
        b.0
    };
    (quote!(#a #op #b), prec)
}

/// An `f64` literal that round-trips exactly (`-c` for negative values; operands that need it
/// are parenthesised by the caller).
pub fn f64_literal(value: f64) -> TokenStream {
    if !value.is_finite() {
        // Unreachable for checked models (literals are validated, folding keeps finiteness);
        // kept total so emission can never panic.
        return if value.is_nan() {
            quote!(f64::NAN)
        } else if value > 0.0 {
            quote!(f64::INFINITY)
        } else {
            quote!(f64::NEG_INFINITY)
        };
    }
    let magnitude = value.abs();
    // `{:?}` is the shortest representation that round-trips, with an exponent for extremes.
    let text = format!("{magnitude:?}");
    let literal: Literal = text
        .parse()
        .unwrap_or_else(|_| Literal::f64_unsuffixed(magnitude));
    if value.is_sign_negative() {
        quote!(-#literal)
    } else {
        quote!(#literal)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_round_trip() {
        for v in [
            0.0,
            1.0,
            156.8,
            1e-6,
            1e-300,
            6.02e23,
            0.1 + 0.2,
            f64::MAX,
            -2.5,
        ] {
            let text = f64_literal(v).to_string().replace(['(', ')', ' '], "");
            assert_eq!(text.parse::<f64>().unwrap(), v, "{text}");
        }
        assert_eq!(f64_literal(-2.5).to_string(), "- 2.5");
        assert_eq!(f64_literal(3.0).to_string(), "3.0");
    }

    #[test]
    fn names_are_unique_and_numbered() {
        let mut names = Names::default();
        assert_eq!(names.fresh("rod_theta").to_string(), "rod_theta");
        assert_eq!(names.fresh("rod_theta").to_string(), "rod_theta0");
        assert_eq!(names.fresh("e").to_string(), "e1");
        assert_eq!(names.fresh("sin_").to_string(), "sin2");
    }
}
