//! The force solve as code, for a scene that computes forces: the textbook functions
//! (`generalized_forces`, `reactions`, `reaction_name` in `impl Mechanism`), the `REACTIONS`
//! names, each stage's reverse-sweep kernel (`stage_k_multipliers` for explicit stages,
//! `stage_k_force_rhs` for blocks, dispatched by `assign_multipliers` and `force_rhs`), and the
//! named accessors `state.reactions()` and `state.efforts()`.
//!
//! A scene without the `forces` output gets none of this: its code is exactly what it was.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::body::{Context, computed};
use super::{idx, signature_with};
use crate::model::ConstraintKind;
use crate::plan::reactions::Forces;

impl Context<'_> {
    /// `generalized_forces`, `reactions` and `reaction_name` for `impl Mechanism`.
    // Kept whole: three sibling methods, each its outputs and one template.
    pub(super) fn force_methods(&self, forces: &Forces) -> TokenStream {
        let vector = self.vector_type();
        let n = idx(self.model.dim());
        let generalized = {
            let outputs = super::vector_outputs(&forces.generalized, &quote!(out));
            let clear = super::clear_if_sparse(self.arena(), &forces.generalized, &quote!(out));
            let inputs = [
                ("q", quote!(&#vector)),
                ("qd", quote!(&#vector)),
                ("qdd", quote!(&#vector)),
            ];
            let outs = [("out", quote!(&mut #vector))];
            let f = self.bounded(
                "generalized_forces",
                &outputs,
                clear,
                &outs,
                &inputs,
                &computed(),
            );
            let (qd, qdd) = (&f.args.qd, &f.args.qdd);
            signature_with(
                &f,
                "F(q, q̇, q̈, t) = Q − M q̈ (gravity, loads, springs and inertia per coordinate)",
                quote!(generalized_forces),
                quote!(#qd: &#vector, #qdd: &#vector,),
                quote!(out: &mut #vector),
            )
        };
        let reactions = {
            let outputs = super::vector_outputs(&forces.reactions, &quote!(out));
            let clear = super::clear_if_sparse(self.arena(), &forces.reactions, &quote!(out));
            let f = self.function(&outputs, clear, &computed());
            let (doc, body) = (f.doc("the reported reactions from λ"), f.body);
            let (q, qd, lambda) = (&f.args.q, &f.args.qd, &f.args.lambda);
            quote! {
                #doc
                fn reactions(
                    &self,
                    #q: &#vector,
                    #qd: &#vector,
                    #lambda: &[f64],
                    out: &mut #vector,
                ) {
                    let ::core::option::Option::Some(#lambda) = #lambda.first_chunk::<#n>() else {
                        out.as_mut_slice().fill(f64::NAN);
                        return;
                    };
                    #body
                }
            }
        };
        let load_fault = self.load_fault();
        quote! {
            #generalized
            #reactions
            fn reaction_name(&self, index: usize) -> ::core::option::Option<&str> {
                Self::REACTIONS.get(index).copied()
            }
            #load_fault
        }
    }

    /// `load_fault`, for a scene with loads: their witnesses (`dynamics::load_witnesses`) into
    /// a local array, then the first load whose contribution is not finite. Only the force
    /// solve's failure path calls it.
    fn load_fault(&self) -> TokenStream {
        let witnesses = self.load_witnesses;
        if witnesses.is_empty() {
            return TokenStream::new();
        }
        let vector = self.vector_type();
        let k = idx(witnesses.len());
        let outputs = super::vector_outputs(witnesses, &quote!(out));
        let f = self.function(&outputs, TokenStream::new(), &computed());
        let (body, q, qd, t) = (f.body, &f.args.q, &f.args.qd, &f.args.t);
        quote! {
            fn load_fault(
                &self,
                #q: &#vector,
                #qd: &#vector,
                #t: f64,
            ) -> ::core::option::Option<::mechgen_runtime::Quantity> {
                let mut out = [0.0_f64; #k];
                #body
                ::mechgen_runtime::codegen::first_load_fault(&out)
            }
        }
    }

    /// The `REACTIONS` names.
    pub(super) fn reaction_names(&self) -> TokenStream {
        let names = self.model.reaction_names();
        let n = idx(names.len());
        quote! {
            /// The reaction each equation reports, in Φ order (`state.constraint_forces()`, the
            /// CSV's force columns).
            pub const REACTIONS: [&'static str; #n] = [#(#names),*];
        }
    }

    /// `XReactions` (a field per joint and ground body), `XEfforts` (a field per driver) and
    /// the trait `XForces` giving them from a solved state.
    // Kept whole: one pass over the constraints fills both field lists, then one template.
    pub(super) fn force_accessors(&self) -> TokenStream {
        let model = self.model;
        let (vis, name) = (&model.vis, &model.name);
        let reactions_type = format_ident!("{}Reactions", name);
        let efforts_type = format_ident!("{}Efforts", name);
        let forces_trait = format_ident!("{}Forces", name);
        let runtime = quote!(::mechgen_runtime);
        let (mut reaction_fields, mut reaction_values) = (Vec::new(), Vec::new());
        let (mut effort_fields, mut effort_values) = (Vec::new(), Vec::new());
        let mut row = 0;
        for constraint in &model.constraints {
            let field = format_ident!("{}", constraint.name);
            let suffixes = constraint.kind.reaction_suffixes();
            let rows = row..row + suffixes.len();
            row = rows.end;
            let Some((ty, doc)) = self.reaction_type(&constraint.name, &constraint.kind) else {
                let doc = format!(
                    " Driver `{}`: the generalised force it applies along its coordinate (a \
                     torque for angles, a force for positions, travel and distances).",
                    constraint.name
                );
                let effort = idx(rows.start);
                effort_fields.push(quote! { #[doc = #doc] pub #field: f64, });
                effort_values.push(quote! { #field: r[#effort], });
                continue;
            };
            let ty = format_ident!("{}", ty);
            let values = suffixes.iter().zip(rows).map(|(suffix, k)| {
                let (name, k) = (format_ident!("{}", suffix), idx(k));
                quote!(#name: r[#k])
            });
            reaction_fields.push(quote! { #[doc = #doc] pub #field: #runtime::#ty, });
            reaction_values.push(quote! { #field: #runtime::#ty { #(#values),* }, });
        }
        let reactions_doc = format!(
            " The reactions of a solved [`{name}`] state: a field per joint and ground body, in \
             the scene's units."
        );
        let efforts_doc = format!(
            " The driver efforts of a solved [`{name}`] state: a field per driver, in the \
             scene's units."
        );
        let trait_doc = format!(
            " Named access to the forces of a solved [`{name}`] state: `state.reactions()`, \
             `state.efforts()`."
        );
        quote! {
            #[doc = #reactions_doc]
            #[derive(Debug, Clone, Copy, PartialEq)]
            #vis struct #reactions_type {
                #(#reaction_fields)*
            }

            #[doc = #efforts_doc]
            #[derive(Debug, Clone, Copy, PartialEq)]
            #vis struct #efforts_type {
                #(#effort_fields)*
            }

            #[doc = #trait_doc]
            #vis trait #forces_trait {
                /// The reaction of every joint and the load on every ground body.
                fn reactions(&self) -> #reactions_type;
                /// The effort of every driver.
                fn efforts(&self) -> #efforts_type;
            }

            impl #forces_trait for #runtime::State<#name> {
                fn reactions(&self) -> #reactions_type {
                    let r = self.constraint_forces();
                    #reactions_type { #(#reaction_values)* }
                }

                fn efforts(&self) -> #efforts_type {
                    let r = self.constraint_forces();
                    #efforts_type { #(#effort_values)* }
                }
            }
        }
    }

    /// The runtime type of a constraint's reaction (its fields are the reaction suffixes) and
    /// the accessor field's doc; `None` for a driver (its effort is a number).
    // Kept whole: one arm per joint kind, each its runtime type and doc line.
    fn reaction_type(&self, name: &str, kind: &ConstraintKind) -> Option<(&'static str, String)> {
        let by = |a: usize, b: usize| (self.body_name(b), self.body_name(a));
        Some(match *kind {
            ConstraintKind::Ground { .. } => (
                "GroundLoad",
                format!(
                    " Ground body `{name}`: the force (world axes) and torque (about its \
                     reference point) the mechanism exerts on it."
                ),
            ),
            ConstraintKind::Revolute { a, b } => {
                let (from, on) = by(a.body, b.body);
                (
                    "RevoluteReaction",
                    format!(
                        " Revolute joint `{name}`: the force (world axes) `{from}` exerts on `{on}`."
                    ),
                )
            }
            ConstraintKind::Prismatic { a, b, .. } => {
                let (from, on) = by(a.body, b.body);
                (
                    "PrismaticReaction",
                    format!(
                        " Prismatic joint `{name}`: the normal force and torque `{from}` exerts on `{on}`."
                    ),
                )
            }
            ConstraintKind::Distance { .. } => (
                "DistanceReaction",
                format!(" Distance joint `{name}`: its tension."),
            ),
            ConstraintKind::Slot { a, b, .. } => {
                let (from, on) = by(a.body, b.body);
                (
                    "SlotReaction",
                    format!(
                        " Pin-in-slot joint `{name}`: the normal force the pin of `{from}` exerts on `{on}`."
                    ),
                )
            }
            ConstraintKind::Weld { a, b, .. } => {
                let (from, on) = by(a.body, b.body);
                (
                    "WeldReaction",
                    format!(
                        " Weld `{name}`: the force (world axes) and torque `{from}` exerts on `{on}`."
                    ),
                )
            }
            ConstraintKind::Gear { b, .. } => (
                "GearReaction",
                format!(
                    " Gear pair `{name}`: the torque the mesh applies to `{}`.",
                    self.body_name(b)
                ),
            ),
            ConstraintKind::Rack { b, .. } => (
                "RackReaction",
                format!(
                    " Rack and pinion `{name}`: the force along the axis the pinion applies to `{}`.",
                    self.body_name(b.body)
                ),
            ),
            ConstraintKind::Driver { .. } => return None,
        })
    }

    fn body_name(&self, body: usize) -> String {
        self.model
            .bodies
            .get(body)
            .map_or_else(String::new, |b| b.name.to_string())
    }
}
