//! The equations of motion as code, for a scene that carries them (`plan::motion`):
//! `impl EquationsOfMotion` with `mass_times`, `stiffness_times` and `damping_times` (each only
//! when its matrix has entries; otherwise the trait's default says there is none) and
//! `energy_terms`. Each is one straight-line body over the planned products, written like the
//! other whole-state functions (shared sub-expressions, sines with their cosines, split when
//! large).
//!
//! The products read their vector `v` in q̈'s slot, so in these bodies a `…_ddot` local is a
//! component of `v` (`plan::motion`).

use proc_macro2::TokenStream;
use quote::quote;

use super::body::{Context, computed};
use crate::expr::Id;
use crate::plan::motion::EquationsOfMotion;

impl Context<'_> {
    /// `impl ::mechgen_runtime::EquationsOfMotion for X`.
    pub(super) fn motion_impl(&self, eom: &EquationsOfMotion) -> TokenStream {
        let name = &self.model.name;
        let mass = self.mass_times(&eom.mass_times);
        let stiffness = eom.stiffness_times.as_deref().map(|values| {
            self.product(
                "stiffness_times",
                values,
                "K v, K = −∂Q/∂q the tangent stiffness (v read as `qdd`)",
            )
        });
        let damping = eom.damping_times.as_deref().map(|values| {
            self.product(
                "damping_times",
                values,
                "C v, C = −∂Q/∂q̇ the tangent damping (v read as `qdd`)",
            )
        });
        let energy = self.energy_terms(&eom.energy.terms());
        quote! {
            impl ::mechgen_runtime::EquationsOfMotion for #name {
                #mass
                #stiffness
                #damping
                #energy
            }
        }
    }

    /// `mass_times`: `M(q) v`.
    fn mass_times(&self, values: &[Id]) -> TokenStream {
        let vector = self.vector_type();
        let outputs = super::vector_outputs(values, &quote!(out));
        let clear = super::clear_if_sparse(self.arena(), values, &quote!(out));
        let inputs = [("q", quote!(&#vector)), ("qdd", quote!(&#vector))];
        let outs = [("out", quote!(&mut #vector))];
        let f = self.bounded("mass_times", &outputs, clear, &outs, &inputs, &computed());
        let (doc, body) = (
            f.doc("M(q) v (v read as `qdd`: M q̈ is the inertia force)"),
            f.body,
        );
        let (q, v, t) = (&f.args.q, &f.args.qdd, &f.args.t);
        // M is time-free; only the parts of a split body take a time.
        let time = (t == "t").then(|| quote!(let t = 0.0;));
        quote! {
            #doc
            fn mass_times(&self, #q: &#vector, #v: &#vector, out: &mut #vector) {
                #time
                #body
            }
        }
    }

    /// `stiffness_times` or `damping_times`: `A(q, q̇, t) v`, returning `true`.
    fn product(&self, name: &str, values: &[Id], what: &str) -> TokenStream {
        let vector = self.vector_type();
        let outputs = super::vector_outputs(values, &quote!(out));
        let clear = super::clear_if_sparse(self.arena(), values, &quote!(out));
        let inputs = [
            ("q", quote!(&#vector)),
            ("qd", quote!(&#vector)),
            ("qdd", quote!(&#vector)),
        ];
        let outs = [("out", quote!(&mut #vector))];
        let f = self.bounded(name, &outputs, clear, &outs, &inputs, &computed());
        let (doc, body) = (f.doc(what), f.body);
        let (q, qd, t, v) = (&f.args.q, &f.args.qd, &f.args.t, &f.args.qdd);
        let name = quote::format_ident!("{}", name);
        quote! {
            #doc
            fn #name(
                &self,
                #q: &#vector,
                #qd: &#vector,
                #t: f64,
                #v: &#vector,
                out: &mut #vector,
            ) -> bool {
                #body
                true
            }
        }
    }

    /// `energy_terms`: the four values into a local array, then the struct.
    fn energy_terms(&self, terms: &[Id; 4]) -> TokenStream {
        let vector = self.vector_type();
        let outputs = super::vector_outputs(terms, &quote!(out));
        let inputs = [("q", quote!(&#vector)), ("qd", quote!(&#vector))];
        let outs = [("out", quote!(&mut [f64; 4]))];
        let f = self.bounded(
            "energy_terms",
            &outputs,
            TokenStream::new(),
            &outs,
            &inputs,
            &computed(),
        );
        let (doc, body) = (
            f.doc("the potentials of gravity and the springs, the powers of the loads and dampers"),
            f.body,
        );
        let (q, qd, t) = (&f.args.q, &f.args.qd, &f.args.t);
        quote! {
            #doc
            fn energy_terms(
                &self,
                #q: &#vector,
                #qd: &#vector,
                #t: f64,
            ) -> ::mechgen_runtime::EnergyTerms {
                let out = &mut [0.0_f64; 4];
                #body
                ::mechgen_runtime::EnergyTerms {
                    gravity: out[0],
                    springs: out[1],
                    loads: out[2],
                    dampers: out[3],
                }
            }
        }
    }
}
