//! A `Structured` method as code: its arms, one per stage with a kernel, dispatched on the
//! stage index, and the parameters they read (the others get a leading underscore).

use std::collections::btree_map::Entry;
use std::collections::{BTreeMap, BTreeSet};

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::idx;

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
    // Kept whole: the parameter names, the views and the body are one template's parts.
    pub(super) fn method(
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
                let arms = merged(arms).into_iter().map(|(stages, statements)| {
                    let stages = runs(&stages).into_iter().map(|(first, last)| {
                        let (a, b) = (idx(first), idx(last));
                        if first == last {
                            quote!(#a)
                        } else {
                            quote!(#a..=#b)
                        }
                    });
                    quote! { #(#stages)|* => { #statements } }
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

/// The arms with the same statements as one arm of all their stages, in the order of each
/// statement's first stage: stages whose blocks share a static LU call the same function on
/// views of the same lengths, and one arm for all of them keeps the method's code from
/// growing with the scene (1000 copies of an inlined 6 × 6 solve were 139 kB of the 1000-stage
/// scissor lift's code, read on every solve).
fn merged(arms: &[(usize, TokenStream)]) -> Vec<(Vec<usize>, &TokenStream)> {
    let mut merged: Vec<(Vec<usize>, &TokenStream)> = Vec::new();
    let mut first: BTreeMap<String, usize> = BTreeMap::new();
    for (s, statements) in arms {
        match first.entry(statements.to_string()) {
            Entry::Occupied(arm) => merged[*arm.get()].0.push(*s),
            Entry::Vacant(slot) => {
                slot.insert(merged.len());
                merged.push((vec![*s], statements));
            }
        }
    }
    merged
}

/// Ascending `stages` as runs of consecutive stages, `(first, last)` each: an arm's pattern
/// names a run as a range (`4..=6`, not `4 | 5 | 6`).
fn runs(stages: &[usize]) -> Vec<(usize, usize)> {
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for &s in stages {
        match runs.last_mut() {
            Some((_, last)) if *last + 1 == s => *last = s,
            _ => runs.push((s, s)),
        }
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;

    fn render(dispatch: &Dispatch, required: bool) -> String {
        let params = [
            ("q", quote!(&Q)),
            ("trig", quote!(&[f64])),
            ("out", quote!(&mut [f64])),
        ];
        let eight = idx(8);
        let views = [("trig", &eight)];
        dispatch
            .method("m", &params, None, required, &views)
            .to_string()
    }

    #[test]
    fn a_method_no_stage_needs_is_left_to_the_default_unless_required() {
        let empty = Dispatch::default();
        assert_eq!(render(&empty, false), "");
        let required = render(&empty, true);
        assert!(
            required.starts_with("fn m (& self , _stage : usize , _q : & Q"),
            "{required}"
        );
        assert!(
            required.contains("_trig") && required.contains("_out"),
            "{required}"
        );
    }

    #[test]
    fn one_stage_is_an_if_and_unread_parameters_are_underscored() {
        let mut one = Dispatch::default();
        one.push(3, quote!(self.k(q, out);), &["q", "out"]);
        let code = render(&one, false);
        assert!(
            code.contains("if stage == 3 { self . k (q , out) ; }"),
            "{code}"
        );
        assert!(
            code.contains("_trig : & [f64]") && !code.contains("match"),
            "{code}"
        );
        assert!(
            !code.contains("first_chunk"),
            "no view of an unread trig: {code}"
        );
    }

    #[test]
    fn several_stages_match_and_a_read_view_poisons_the_outputs_when_short() {
        let mut two = Dispatch::default();
        two.push(0, quote!(self.a(trig, out);), &["trig", "out"]);
        two.push(2, quote!(self.b(q);), &["q"]);
        let code = render(&two, false);
        assert!(code.contains("match stage { 0 =>"), "{code}");
        assert!(
            code.contains("2 => { self . b (q) ; } _ => { } }"),
            "{code}"
        );
        assert!(
            code.contains(
                "trig . first_chunk :: < 8 > () else { out . fill (f64 :: NAN) ; return ; }"
            ),
            "{code}"
        );
    }

    #[test]
    fn stages_with_the_same_statements_share_one_arm_in_first_stage_order() {
        let mut shared = Dispatch::default();
        shared.push(2, quote!(Self::solve_1(values, x);), &["values", "x"]);
        shared.push(3, quote!(Self::solve_0(values, x);), &["values", "x"]);
        shared.push(5, quote!(Self::solve_1(values, x);), &["values", "x"]);
        shared.push(6, quote!(Self::solve_1(values, x);), &["values", "x"]);
        let code = render(&shared, false);
        assert!(
            code.contains(
                "match stage { 2 | 5 ..= 6 => { Self :: solve_1 (values , x) ; } \
                 3 => { Self :: solve_0 (values , x) ; } _ => { } }"
            ),
            "{code}"
        );
    }

    #[test]
    fn a_fallible_method_answers_err_where_no_stage_or_view_serves() {
        let mut one = Dispatch::default();
        one.push(
            1,
            quote!(Self::factor_0(values, tiny, limit)),
            &["values", "tiny"],
        );
        let params = [("values", quote!(&mut [f64])), ("tiny", quote!(f64))];
        let result = Some(quote!(::core::result::Result<(), usize>));
        let code = one
            .method("factor", &params, result, false, &[])
            .to_string();
        assert!(
            code.contains("if stage == 1 { Self :: factor_0 (values , tiny , limit) } else { :: core :: result :: Result :: Err (0) }"),
            "{code}"
        );
        let mut view = Dispatch::default();
        view.push(0, quote!(self.k(trig);), &["trig"]);
        view.push(4, quote!(self.k(trig);), &["trig"]);
        let params = [("trig", quote!(&mut [f64]))];
        let three = idx(3);
        let code = view
            .method("fill", &params, None, false, &[("trig", &three)])
            .to_string();
        assert!(
            code.contains(
                "trig . first_chunk_mut :: < 3 > () else { trig . fill (f64 :: NAN) ; return ; }"
            ),
            "a mutable view, poisoned when short: {code}"
        );
    }
}
