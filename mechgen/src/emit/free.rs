//! The free degrees of freedom of a scene that declares them: the struct's `free` state field,
//! its default, and `impl ::mechgen_runtime::Dynamic` (names, equations, declared initial
//! state, reads and writes of the state the kinematic solve holds them at).

use proc_macro2::TokenStream;
use quote::quote;

use super::body::{Context, computed};
use super::{f64_literal, idx};
use crate::expr::Id;
use crate::expr::tape::{Env, eval};

impl Context<'_> {
    /// The `free` field of the struct (nothing for a scene without free degrees of freedom).
    pub(super) fn free_field(&self) -> TokenStream {
        let count = self.model.frees.len();
        if count == 0 {
            return TokenStream::new();
        }
        let count = idx(count);
        quote! {
            /// The free degrees of freedom's `[value, rate, acceleration]`, in declaration
            /// order: the state the kinematic solve holds them at, set by the integrator
            /// (`mechgen_runtime::Dynamic::set_free`).
            pub free: [[f64; 3]; #count],
        }
    }

    /// The `free` field's default: each declared `from` and `speed` at the parameters'
    /// defaults (0 where not declared: the integrator assembles an undeclared value), at rest.
    pub(super) fn free_default(&self) -> TokenStream {
        let model = self.model;
        if model.frees.is_empty() {
            return TokenStream::new();
        }
        let env = Env {
            params: model.params.iter().map(|p| p.default).collect(),
            ..Env::default()
        };
        let value = |id: Id| f64_literal(eval(&model.arena, id, &env));
        let states = model.frees.iter().map(|f| {
            let from = f.from.map_or_else(|| f64_literal(0.0), value);
            let speed = value(f.speed);
            quote!([#from, #speed, 0.0])
        });
        quote! { free: [#(#states),*], }
    }

    /// `impl ::mechgen_runtime::Dynamic` (nothing for a scene without free degrees of freedom).
    pub(super) fn dynamic_impl(&self) -> TokenStream {
        let model = self.model;
        if model.frees.is_empty() {
            return TokenStream::new();
        }
        let name = &model.name;
        let count = idx(model.frees.len());
        let names = model.frees.iter().map(|f| f.name.to_string());
        // Every free degree of freedom has its equation; were one missing, the array would be
        // short and the generated code would not compile (never a wrong row).
        let equations = (0..model.frees.len()).filter_map(|k| model.free_equation(k).map(idx));
        let initial = model.frees.iter().enumerate().map(|(k, f)| {
            let k = idx(k);
            let from = match f.from {
                Some(from) => {
                    let from = self.value(from);
                    quote!(::core::option::Option::Some(#from))
                }
                None => quote!(::core::option::Option::None),
            };
            let speed = self.value(f.speed);
            quote! { #k => (#from, #speed), }
        });
        quote! {
            impl ::mechgen_runtime::Dynamic for #name {
                type Free = ::mechgen_runtime::nalgebra::Const<#count>;

                fn free(&self) -> Self::Free {
                    ::mechgen_runtime::nalgebra::Const::<#count>
                }

                fn free_name(&self, k: usize) -> ::core::option::Option<&str> {
                    const NAMES: [&str; #count] = [#(#names),*];
                    NAMES.get(k).copied()
                }

                fn free_equation(&self, k: usize) -> usize {
                    const EQUATIONS: [usize; #count] = [#(#equations),*];
                    EQUATIONS.get(k).copied().unwrap_or(usize::MAX)
                }

                fn free_initial(&self, k: usize) -> (::core::option::Option<f64>, f64) {
                    match k {
                        #(#initial)*
                        _ => (::core::option::Option::None, 0.0),
                    }
                }

                fn free_state(&self, k: usize) -> [f64; 3] {
                    self.free.get(k).copied().unwrap_or([f64::NAN; 3])
                }

                fn set_free(&mut self, k: usize, state: [f64; 3]) {
                    if let ::core::option::Option::Some(slot) = self.free.get_mut(k) {
                        *slot = state;
                    }
                }
            }
        }
    }

    /// An expression in parameters as a block reading `self`'s fields.
    fn value(&self, id: Id) -> TokenStream {
        match self.model.arena.as_const(id) {
            Some(constant) => f64_literal(constant),
            None => {
                let function =
                    self.function(&[(TokenStream::new(), id)], TokenStream::new(), &computed());
                let body = function.body;
                quote!({ #body })
            }
        }
    }
}
