//! The static LUs as code: each distinct factorisation of the plan becomes straight-line
//! `factor_k`, `solve_k` and `solve_transpose_k` functions over a block's value slots, shared
//! by the blocks with the same pattern.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::body::Context;
use super::idx;
use crate::sparse::factor::Factorization;

/// `v[s]`: value slot `s`.
fn v(s: usize) -> TokenStream {
    let s = idx(s);
    quote!(v[#s])
}

/// `x[i]`: entry `i` of the right-hand side, solved in place.
fn x(i: usize) -> TokenStream {
    let i = idx(i);
    quote!(x[#i])
}

/// [`Factorization::factor`]'s operations: each pivot tested and replaced by its reciprocal,
/// its multipliers scaled and bounded, the updates of the rest.
fn factor_statements(f: &Factorization) -> Vec<TokenStream> {
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
    factor
}

/// [`Factorization::solve`]'s operations: forward with L, then back with U.
fn solve_statements(f: &Factorization) -> Vec<TokenStream> {
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
    solve
}

/// [`Factorization::solve_transpose`]'s operations: forward with Uᵀ, then back with Lᵀ.
fn transpose_statements(f: &Factorization) -> Vec<TokenStream> {
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
    transpose
}

/// The static LU `k` as straight-line code: the same operations, in the same order, as
/// [`Factorization::factor`], [`Factorization::solve`] and [`Factorization::solve_transpose`].
// Kept whole: the three functions' signatures and docs, around the statement builders above.
pub(super) fn lu_functions(cx: &Context<'_>, k: usize, f: &Factorization) -> [TokenStream; 3] {
    let (n, slots) = (idx(f.n), idx(f.slots));
    let (factor, solve, transpose) = (
        factor_statements(f),
        solve_statements(f),
        transpose_statements(f),
    );
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
