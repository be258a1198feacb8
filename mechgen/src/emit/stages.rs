//! The `STAGES` constant: the runtime's table of the solve's stages, documented stage by
//! stage (what each solves for, from which equations, and how).

use proc_macro2::TokenStream;
use quote::quote;

use super::idx;
use crate::model::Model;
use crate::plan::kernels::StageShape;
use crate::plan::structure::{Block, Plan, Stage};

/// The `STAGES` constant, documented stage by stage: the kernel list's stage shapes, with the
/// plan's stages for the documentation.
pub(super) fn stage_table(model: &Model, plan: &Plan, shapes: &[StageShape]) -> TokenStream {
    let (coordinates, equations) = (model.coordinate_names(), model.equation_names());
    let mut docs = vec![
        " The solve, stage by stage; each stage reads only earlier ones (coordinate ← equation)."
            .to_owned(),
    ];
    for (s, stage) in plan.stages.iter().enumerate() {
        docs.push(String::new());
        let mut lines = stage_lines(stage, &coordinates, &equations).into_iter();
        docs.push(format!(" {s}. {}", lines.next().unwrap_or_default()));
        docs.extend(lines.map(|l| format!(" {l}")));
    }
    let entries: Vec<TokenStream> = shapes.iter().map(stage_entry).collect();
    let count = idx(entries.len());
    quote! {
        #(#[doc = #docs])*
        pub const STAGES: [::mechgen_runtime::codegen::Stage<'static>; #count] = [#(#entries),*];
    }
}

/// One stage of the runtime's table.
fn stage_entry(shape: &StageShape) -> TokenStream {
    let list = |indices: &[usize]| -> TokenStream {
        let indices = indices.iter().map(|&i| idx(i));
        quote!(&[#(#indices),*])
    };
    let (e, c, r) = (
        list(&shape.equations),
        list(&shape.coordinates),
        list(&shape.reads),
    );
    let Some(block) = &shape.block else {
        return quote! {
            ::mechgen_runtime::codegen::Stage::Explicit { equations: #e, coordinates: #c, reads: #r }
        };
    };
    let pattern = block.pattern.iter().map(|&(row, col)| {
        let (row, col) = (idx(row), idx(col));
        quote!((#row, #col))
    });
    let (slots, pivots) = (idx(block.slots), list(&block.pivots));
    quote! {
        ::mechgen_runtime::codegen::Stage::Block(::mechgen_runtime::codegen::Block {
            equations: #e,
            coordinates: #c,
            pattern: ::mechgen_runtime::codegen::Pattern::Sparse(&[#(#pattern),*]),
            slots: #slots,
            pivots: #pivots,
            reads: #r,
        })
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
