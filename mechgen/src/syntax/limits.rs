//! Size limits on the input, checked before parsing: the parser, the checker and
//! differentiation recurse once per nesting level and per operator of a chain, so without them a
//! pathological scene (thousands of nested brackets, a million-term sum) would overflow the stack
//! and abort rustc or the CLI instead of getting an error message; and a file's size and
//! statement count bound the time and memory a scene costs before anything is lexed (the text
//! path, `source`, applies every limit while scanning characters, before it makes tokens).

use proc_macro2::{Span, TokenStream, TokenTree};

/// Deepest bracket nesting accepted; hand-written scenes stay in single digits.
pub const MAX_DEPTH: usize = 64;
/// Most tokens accepted in one `;`-terminated statement (brackets included); a long driver
/// expression has a few hundred.
pub const MAX_STATEMENT_TOKENS: usize = 10_000;

/// Largest `.mech` text read by default: 8 MiB, about 100 000 statements of typical length
/// (a 1000-stage scissor lift written out by `builder` is under 1 MiB).
pub const MAX_SOURCE_BYTES: usize = 8 << 20;
/// Most statements read by default; `mechgen check` takes about 2 s and 70 MB on 100 000
/// markers.
pub const MAX_STATEMENTS: usize = 100_000;

/// The limits a scene's text is read within. Nesting depth and statement length protect the
/// stack and are fixed ([`MAX_DEPTH`], [`MAX_STATEMENT_TOKENS`]); size and count only bound the
/// cost, so a caller that means to read a larger scene can raise them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Largest text, in bytes.
    pub bytes: usize,
    /// Most statements in the mechanism's body.
    pub statements: usize,
}

impl Default for Limits {
    /// [`MAX_SOURCE_BYTES`] and [`MAX_STATEMENTS`].
    fn default() -> Self {
        Limits {
            bytes: MAX_SOURCE_BYTES,
            statements: MAX_STATEMENTS,
        }
    }
}

impl Limits {
    /// No limit on size or count (the depth and statement-length limits still apply): for
    /// text a program wrote, such as `builder`'s.
    pub const UNBOUNDED_SIZE: Limits = Limits {
        bytes: usize::MAX,
        statements: usize::MAX,
    };
}

/// Checks `tokens` against [`MAX_DEPTH`] and [`MAX_STATEMENT_TOKENS`].
///
/// # Errors
/// The first violation, at its span, with a message saying how to fix it.
pub fn check(tokens: &TokenStream) -> syn::Result<()> {
    match first_violation(tokens.clone()) {
        None => Ok(()),
        Some((span, message)) => Err(syn::Error::new(span, message)),
    }
}

fn first_violation(tokens: TokenStream) -> Option<(Span, String)> {
    // Iterative on purpose: this must not recurse on the input it protects against.
    let mut stack = vec![tokens.into_iter()];
    let mut statement_tokens = 0usize;
    while let Some(top) = stack.last_mut() {
        let Some(token) = top.next() else {
            stack.pop();
            continue;
        };
        statement_tokens += 1;
        if statement_tokens > MAX_STATEMENT_TOKENS {
            return Some((
                token.span(),
                format!(
                    "this statement is longer than {MAX_STATEMENT_TOKENS} tokens, more than \
                     mechgen accepts: simplify the expression"
                ),
            ));
        }
        match token {
            TokenTree::Punct(p) if p.as_char() == ';' => statement_tokens = 0,
            TokenTree::Group(group) => {
                // This group's nesting level (the outermost bracket is level 1).
                if stack.len() > MAX_DEPTH {
                    return Some((
                        group.span_open(),
                        format!(
                            "brackets nested more than {MAX_DEPTH} levels deep, more than \
                             mechgen accepts: simplify the expression"
                        ),
                    ));
                }
                stack.push(group.stream().into_iter());
            }
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(source: &str) -> syn::Result<()> {
        super::check(&source.parse().expect("lexes"))
    }

    fn nested(depth: usize) -> String {
        format!(
            "mechanism M {{ param p = {}1{}; }}",
            "(".repeat(depth),
            ")".repeat(depth)
        )
    }

    #[test]
    fn accepts_up_to_the_limits() {
        // The mechanism's braces are one level.
        assert!(check(&nested(MAX_DEPTH - 1)).is_ok());
        let long = format!("mechanism M {{ param p = 1{}; }}", "+1".repeat(4000));
        assert!(check(&long).is_ok());
    }

    #[test]
    fn rejects_beyond_the_limits() {
        let deep = check(&nested(MAX_DEPTH)).expect_err("too deep").to_string();
        assert!(deep.contains("nested more than 64"), "{deep}");
        let long = format!("mechanism M {{ param p = 1{}; }}", "+1".repeat(5000));
        let long = check(&long).expect_err("too long").to_string();
        assert!(long.contains("longer than 10000 tokens"), "{long}");
    }
}
