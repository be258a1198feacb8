//! The markers as code: the storage type every scene names (`type Markers = [f64; K]`, K = 0
//! without markers), and for a scene with markers their names (`MARKERS`), the textbook
//! `marker_values`, the `markers` kernel of the solve (reading the trig cache) and the named
//! accessors (`state.tip().x_dot`, `state.swing().angle`).

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::body::{Context, computed};
use super::idx;
use crate::model::{MarkerKind, Outputs};
use crate::plan::kernels::{Kernel, Kernels};

impl Context<'_> {
    /// Number of marker values.
    fn marker_count(&self, values: &[crate::expr::Id]) -> proc_macro2::Literal {
        idx(values.len())
    }

    /// `type Markers`, `marker_storage` and, with markers, `marker_name` and the textbook
    /// `marker_values`, for `impl Mechanism`.
    pub(super) fn marker_methods(&self, values: &[crate::expr::Id]) -> TokenStream {
        let k = self.marker_count(values);
        let storage = quote! {
            type Markers = [f64; #k];

            fn marker_storage(&self) -> [f64; #k] {
                [0.0; #k]
            }
        };
        if values.is_empty() {
            return storage;
        }
        let vector = self.vector_type();
        let outputs = super::vector_outputs(values, &quote!(out));
        let clear = super::clear_if_sparse(self.arena(), values, &quote!(out));
        let f = self.function(&outputs, clear, &computed());
        let (doc, body) = (f.doc("the markers' values and rates"), f.body);
        let (q, qd, qdd, t) = (&f.args.q, &f.args.qd, &f.args.qdd, &f.args.t);
        quote! {
            #storage

            fn marker_name(&self, index: usize) -> ::core::option::Option<&str> {
                Self::MARKERS.get(index).copied()
            }

            #doc
            fn marker_values(
                &self,
                #q: &#vector,
                #qd: &#vector,
                #qdd: &#vector,
                #t: f64,
                out: &mut [f64; #k],
            ) {
                #body
            }
        }
    }

    /// `MARKERS`: the names of the marker values (nothing without markers).
    pub(super) fn marker_names(&self) -> TokenStream {
        let names = self.model.marker_names();
        if names.is_empty() {
            return TokenStream::new();
        }
        let k = idx(names.len());
        quote! {
            /// The marker values, in the order of `state.marker_values()` and the CSV columns.
            pub const MARKERS: [&'static str; #k] = [#(#names),*];
        }
    }

    /// The `markers` kernel of `impl Structured`: the values from the solve's trig cache
    /// (every stage has filled it by then); nothing without markers.
    pub(super) fn markers_method(&self, kernels: &Kernels) -> TokenStream {
        let Some(Kernel {
            roots: values,
            cached,
            ..
        }) = &kernels.markers
        else {
            return TokenStream::new();
        };
        let (k, trig_len) = (self.marker_count(values), idx(kernels.sizes.trig));
        let outputs = super::vector_outputs(values, &quote!(out));
        let clear = super::clear_if_sparse(self.arena(), values, &quote!(out));
        let f = self.function(&outputs, clear, cached);
        let body = f.body;
        let (q, qd, qdd, t, trig) = (&f.args.q, &f.args.qd, &f.args.qdd, &f.args.t, &f.args.trig);
        let view = (trig == "trig").then(|| {
            quote! {
                let ::core::option::Option::Some(trig) = trig.first_chunk::<#trig_len>() else {
                    out.fill(f64::NAN);
                    return;
                };
            }
        });
        let vector = quote!(::mechgen_runtime::Vector<Self::Dim>);
        quote! {
            /// The markers' values and rates, reading the solve's trig cache.
            fn markers(
                &self,
                #q: &#vector,
                #trig: &[f64],
                #qd: &#vector,
                #qdd: &#vector,
                #t: f64,
                out: &mut [f64; #k],
            ) {
                #view
                #body
            }
        }
    }

    /// The markers' declarations and implementations in the scene's named-access trait.
    pub(super) fn marker_accessors(&self) -> (Vec<TokenStream>, Vec<TokenStream>) {
        let model = self.model;
        let level = match model.outputs {
            Outputs::Positions => 0,
            Outputs::Velocities => 1,
            Outputs::Accelerations | Outputs::Forces => 2,
        };
        let (mut declarations, mut implementations) = (Vec::new(), Vec::new());
        let mut first = 0;
        for marker in &model.markers {
            let suffixes = marker.kind.suffixes(model.outputs);
            let (views, what) = match marker.kind {
                MarkerKind::Point(_) => {
                    (["PointPosition", "PointVelocity", "PointState"], "Position")
                }
                MarkerKind::Angle(..) => {
                    (["AnglePosition", "AngleVelocity", "AngleState"], "Angle")
                }
            };
            let view = format_ident!("{}", views[level]);
            let ident = format_ident!("{}", marker.name);
            let docs = if marker.docs.is_empty() {
                let doc = format!(" {what} of marker `{}` (and its rates).", marker.name);
                quote! { #[doc = #doc] }
            } else {
                let docs = &marker.docs;
                quote! { #(#docs)* }
            };
            let start = first;
            let fields = suffixes.iter().enumerate().map(|(k, suffix)| {
                let (field, k) = (format_ident!("{}", suffix), idx(start + k));
                quote!(#field: values[#k])
            });
            first += suffixes.len();
            declarations.push(quote! { #docs fn #ident(&self) -> ::mechgen_runtime::#view; });
            implementations.push(quote! {
                fn #ident(&self) -> ::mechgen_runtime::#view {
                    let values = self.marker_values();
                    ::mechgen_runtime::#view { #(#fields),* }
                }
            });
        }
        (declarations, implementations)
    }
}
