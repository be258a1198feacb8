//! Generated tokens as source text for `include!`: one statement or brace per line, in one
//! linear pass.

use std::fmt::Write as _;

use proc_macro2::{Delimiter, Spacing, TokenStream, TokenTree};

/// Generated tokens as source text, one statement or brace per line: what
/// [`SceneBuilder::write_to`](super::SceneBuilder::write_to) writes. Linear in the size of the
/// code, unlike formatting.
///
/// Why not `TokenStream::to_string()`: it puts everything on one line, and rustc's cost of
/// locating a span (every bounds check's panic location) grows with the length of its line, so
/// a multi-megabyte line makes the including crate's release build several times slower
/// (measured: 22 s against 4 s for a 600 kB scene).
pub fn source_text(tokens: TokenStream) -> String {
    let mut text = String::new();
    // Iterative: generated code nests shallowly, but this must not recurse on its input anyway.
    // Each open group: its tokens, its delimiter, and whether it is an attribute (`#[…]`, which
    // ends its line: doc comments come in long runs).
    let mut stack = vec![(tokens.into_iter(), Delimiter::None, false)];
    while let Some((iter, delimiter, attribute)) = stack.last_mut() {
        let (delimiter, attribute) = (*delimiter, *attribute);
        match iter.next() {
            None => {
                stack.pop();
                match delimiter {
                    Delimiter::Brace => text.push_str("}\n"),
                    Delimiter::Parenthesis => text.push_str(") "),
                    Delimiter::Bracket if attribute => text.push_str("]\n"),
                    Delimiter::Bracket => text.push_str("] "),
                    Delimiter::None => {}
                }
            }
            Some(TokenTree::Group(group)) => {
                let attribute = text.ends_with("# ") || text.ends_with('#');
                match group.delimiter() {
                    Delimiter::Brace => text.push_str("{\n"),
                    Delimiter::Parenthesis => text.push('('),
                    Delimiter::Bracket => text.push('['),
                    Delimiter::None => {}
                }
                stack.push((group.stream().into_iter(), group.delimiter(), attribute));
            }
            Some(TokenTree::Punct(punct)) => {
                text.push(punct.as_char());
                match (punct.spacing(), punct.as_char()) {
                    // Joint: part of `::`, `->`, `'a`, …; no space inside.
                    (Spacing::Joint, _) => {}
                    // A statement's end, but not `[T; N]`.
                    (Spacing::Alone, ';') if delimiter != Delimiter::Bracket => text.push('\n'),
                    // Long lists (the Jacobian's pattern, the coordinate names) wrap.
                    (Spacing::Alone, ',') if text.len() - line_start(&text) > 100 => {
                        text.push('\n');
                    }
                    (Spacing::Alone, _) => text.push(' '),
                }
            }
            Some(TokenTree::Ident(ident)) => {
                let _ = write!(text, "{ident} ");
            }
            Some(TokenTree::Literal(literal)) => {
                let _ = write!(text, "{literal} ");
            }
        }
    }
    text
}

/// Byte offset at which the last line of `text` starts.
fn line_start(text: &str) -> usize {
    text.rfind('\n').map_or(0, |i| i + 1)
}
