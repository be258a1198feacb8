//! Reading a `.mech` text within the input limits, statement by statement.
//!
//! Lexing a whole file first (proc-macro2 makes some 40 bytes of tokens per byte of text) costs
//! gigabytes on a 50 MB file before any limit can apply. So a scan over the characters, which
//! makes no tokens, finds the mechanism's body and its `;`-terminated statements and enforces
//! every limit (file size, statement length, bracket nesting, statement count) first; then whole
//! statements are lexed and parsed a chunk at a time, and memory holds the spec being built and
//! one chunk's tokens. Each chunk is lexed as its own text, so its spans count lines and columns
//! from the chunk's start: [`Locations`] maps them back to the file.

use proc_macro2::{Span, TokenStream};
use syn::parse::{ParseStream, Parser};

use crate::syntax::limits::{Limits, MAX_DEPTH, MAX_STATEMENT_TOKENS};
use crate::syntax::spec::Spec;

/// Text lexed at once: large enough that a file has few chunks (a span's chunk is found by a
/// linear search), small enough that its tokens are a few megabytes.
const CHUNK_BYTES: usize = 64 << 10;

/// A scene's text, read: its spec or the first error, and where the spans are in the text.
pub struct Read {
    /// The spec, or the first problem found (a limit, a bracket, a syntax error).
    pub spec: syn::Result<Spec>,
    /// Where each chunk of the text starts, to place any span of this spec (or of errors about
    /// it) in the text.
    pub locations: Locations,
}

/// Where a chunk's first character (line 1, column 0 of its spans) is in the text: 1-based
/// line, 0-based column in characters, as `proc_macro2::LineColumn` counts them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Origin {
    /// Line of the text.
    pub line: usize,
    /// Column of that line, in characters.
    pub column: usize,
}

impl Origin {
    /// The text position of a chunk-relative `line` (1-based) and `column`.
    pub fn place(self, line: usize, column: usize) -> (usize, usize) {
        if line <= 1 {
            (self.line, self.column + column)
        } else {
            (self.line + line - 1, column)
        }
    }
}

/// The chunks a text was lexed in, each with a span inside it (spans of one chunk can be
/// joined, spans of two cannot: that finds a span's chunk).
#[derive(Default)]
pub struct Locations {
    chunks: Vec<(Span, Origin)>,
}

impl Locations {
    /// Where the chunk holding `span` starts in the text; `None` for a span not lexed from it
    /// (`Span::call_site()`). Needs proc-macro2's `span-locations` to tell chunks apart.
    pub fn origin(&self, span: Span) -> Option<Origin> {
        self.chunks
            .iter()
            .find(|(probe, _)| probe.join(span).is_some())
            .map(|&(_, origin)| origin)
    }
}

/// Parses a `mechanism` declaration from source text (a `.mech` file) within the default
/// [`Limits`], statement by statement ([`read`]).
///
/// The spans count lines and columns from the start of the chunk they were lexed in: place
/// them in the text with [`read`]'s locations.
///
/// # Errors
/// The first limit exceeded, bracket problem, lexical or syntax error, at its position.
pub fn parse_str(source: &str) -> syn::Result<Spec> {
    read(source, &Limits::default()).spec
}

/// Reads `source` within `limits`: scans it, then lexes and parses it chunk by chunk.
pub fn read(source: &str, limits: &Limits) -> Read {
    let mut locations = Locations::default();
    let spec = read_into(source, limits, &mut locations);
    Read { spec, locations }
}

fn read_into(source: &str, limits: &Limits, locations: &mut Locations) -> syn::Result<Spec> {
    if source.len() > limits.bytes {
        let at = floor_char_boundary(source, limits.bytes);
        return Err(error_at(
            source,
            at,
            locations,
            format!(
                "the scene is {} bytes, more than the {} bytes mechgen reads (the limit is \
                 reached here); raise the limit to read it (`--max-file-size` on the command \
                 line, `mechgen::Limits` in code)",
                source.len(),
                limits.bytes
            ),
        ));
    }
    let scan = scan(source, limits);
    if let Some(problem) = scan.problem {
        return Err(problem.into_error(source, locations, limits));
    }
    let header_end = scan.open.unwrap_or(source.len());
    let (docs, vis, name) = lex_and_parse(
        &source[..header_end],
        Origin { line: 1, column: 0 },
        locations,
        |input| {
            let header = crate::syntax::parse::header(input)?;
            if !input.is_empty() {
                return Err(input.error("expected `{`: the mechanism's body, `{ … }`"));
            }
            Ok(header)
        },
    )?;
    let (Some(open), Some(close)) = (scan.open, scan.close) else {
        return Err(syn::Error::new(
            Span::call_site(),
            "unexpected end of input, expected `{ … }`: the mechanism's body",
        ));
    };
    let mut spec = Spec::new(docs, vis, name);
    read_statements(source, open..close, &scan.ends, locations, &mut spec)?;
    Ok(spec)
}

/// Parses the statements of the body (`body`: its braces' offsets), whose ends the scan found,
/// into `spec`.
fn read_statements(
    source: &str,
    body: std::ops::Range<usize>,
    ends: &[usize],
    locations: &mut Locations,
    spec: &mut Spec,
) -> syn::Result<()> {
    // Chunks of whole statements, each lexed as `{` + statements + `}` with the braces placed
    // on the characters just before and after it (the previous `;` or the body's `{`, and the
    // next statement or the body's `}`), so that every span lands on real text.
    let (open, close) = (body.start, body.end);
    let mut start = open + 1;
    let mut ends = ends.iter().copied().peekable();
    let mut cursor = Cursor::default();
    loop {
        let mut end = start;
        while let Some(&next) = ends.peek() {
            if end > start && next - start > CHUNK_BYTES {
                break;
            }
            end = next;
            ends.next();
        }
        let last = ends.peek().is_none();
        if last {
            end = close;
        }
        let text = format!("{{{}}}", &source[start..end]);
        let (line, column) = cursor.advance(source, start - 1);
        lex_and_parse(&text, Origin { line, column }, locations, |input| {
            let content;
            syn::braced!(content in input);
            while !content.is_empty() {
                crate::syntax::parse::statement(&content, spec)?;
            }
            Ok(())
        })?;
        if last {
            return Ok(());
        }
        start = end;
    }
}

/// Lexes `text` (a chunk starting at `origin`), records it, checks its tokens and parses them.
fn lex_and_parse<T>(
    text: &str,
    origin: Origin,
    locations: &mut Locations,
    parser: impl FnOnce(ParseStream) -> syn::Result<T>,
) -> syn::Result<T> {
    let tokens: TokenStream = match text.parse() {
        Ok(tokens) => tokens,
        Err(error) => {
            locations.chunks.push((error.span(), origin));
            return Err(syn::Error::new(error.span(), error));
        }
    };
    if let Some(first) = tokens.clone().into_iter().next() {
        locations.chunks.push((first.span(), origin));
    }
    // The scan enforced these already; the token check is exact and cheap.
    crate::syntax::limits::check(&tokens)?;
    parser.parse2(tokens)
}

/// An error at byte `at` of `source` (under the token there), as a one-token chunk placed at
/// that position.
fn error_at(source: &str, at: usize, locations: &mut Locations, message: String) -> syn::Error {
    let (line, column) = position(source, at);
    let width = token_width(source, at);
    let text = "x".repeat(width);
    let span = match text.parse::<TokenStream>() {
        Ok(tokens) => tokens
            .into_iter()
            .next()
            .map_or_else(Span::call_site, |t| t.span()),
        Err(_) => Span::call_site(),
    };
    locations.chunks.push((span, Origin { line, column }));
    syn::Error::new(span, message)
}

/// 1-based line and 0-based character column of byte `at`.
fn position(source: &str, at: usize) -> (usize, usize) {
    let before = &source[..at];
    let line = 1 + before.bytes().filter(|&b| b == b'\n').count();
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[line_start..].chars().count())
}

/// Line and column of increasing offsets, in time linear in the text.
#[derive(Default)]
struct Cursor {
    offset: usize,
    line_start: usize,
    line: usize,
}

impl Cursor {
    fn advance(&mut self, source: &str, to: usize) -> (usize, usize) {
        let passed = &source[self.offset..to];
        if let Some(last) = passed.rfind('\n') {
            self.line += passed.bytes().filter(|&b| b == b'\n').count();
            self.line_start = self.offset + last + 1;
        }
        self.offset = to;
        (self.line + 1, source[self.line_start..to].chars().count())
    }
}

/// Characters of the token starting at `at` on its line (at least 1, at most 100).
fn token_width(source: &str, at: usize) -> usize {
    let bytes = source.as_bytes();
    let end = if at < bytes.len() {
        token_end(bytes, at).unwrap_or(bytes.len())
    } else {
        at
    };
    let text = source.get(at..end).unwrap_or("");
    let text = text.split('\n').next().unwrap_or("");
    text.chars().count().clamp(1, 100)
}

fn floor_char_boundary(source: &str, at: usize) -> usize {
    let mut at = at.min(source.len());
    while !source.is_char_boundary(at) {
        at -= 1;
    }
    at
}

/// What the scan found: the body's braces, the end of every statement (just after its `;`),
/// and the first problem.
struct Scan {
    open: Option<usize>,
    close: Option<usize>,
    ends: Vec<usize>,
    problem: Option<Problem>,
}

/// A problem the scan finds, at a byte offset.
enum Problem {
    /// A closing bracket that does not match the open one.
    Mismatched { open: usize, close: usize },
    /// A bracket never closed.
    Unclosed { open: usize },
    /// A closing bracket with nothing open.
    Unopened { close: usize },
    /// A string, character or block comment that runs to the end of the text.
    Unterminated { start: usize, what: &'static str },
    /// Brackets nested deeper than [`MAX_DEPTH`].
    Deep { open: usize },
    /// A statement of more than [`MAX_STATEMENT_TOKENS`] tokens: where it starts, how many.
    Long { start: usize, tokens: usize },
    /// More statements than the limit: where the first beyond it starts, how many in all.
    Many { start: usize, statements: usize },
    /// Tokens after the mechanism's closing brace.
    Trailing { start: usize },
}

impl Problem {
    fn into_error(self, source: &str, locations: &mut Locations, limits: &Limits) -> syn::Error {
        // Whole: one arm per problem, each its message.
        let describe = |at: usize| {
            let (line, column) = position(source, at);
            format!("line {line}, column {}", column + 1)
        };
        let bracket = |at: usize| char::from(source.as_bytes()[at]);
        let (at, message) = match self {
            Problem::Mismatched { open, close } => (
                close,
                format!(
                    "`{}` does not close the `{}` opened at {}: look for an unbalanced or \
                     mismatched bracket",
                    bracket(close),
                    bracket(open),
                    describe(open)
                ),
            ),
            Problem::Unclosed { open } => (
                open,
                format!(
                    "this `{}` is never closed: look for an unbalanced or mismatched bracket",
                    bracket(open)
                ),
            ),
            Problem::Unopened { close } => (
                close,
                format!(
                    "this `{}` closes nothing: look for an unbalanced or mismatched bracket",
                    bracket(close)
                ),
            ),
            Problem::Unterminated { start, what } => (
                start,
                format!("this {what} is never terminated: close it or remove it"),
            ),
            Problem::Deep { open } => (
                open,
                format!(
                    "brackets nested more than {MAX_DEPTH} levels deep, more than mechgen \
                     accepts: simplify the expression"
                ),
            ),
            Problem::Long { start, tokens } => (
                start,
                format!(
                    "this statement is {tokens} tokens long, longer than the \
                     {MAX_STATEMENT_TOKENS} tokens mechgen accepts in one statement: simplify \
                     the expression, or split it into parameters computed from one another \
                     (`param a = …; param b = 2 * a + …;`)"
                ),
            ),
            Problem::Many { start, statements } => (
                start,
                format!(
                    "the scene has {statements} statements, more than the {} mechgen reads \
                     (this is the first beyond the limit); raise the limit to read it \
                     (`--max-statements` on the command line, `mechgen::syntax::limits::Limits` in \
                     code)",
                    limits.statements
                ),
            ),
            Problem::Trailing { start } => (
                start,
                "unexpected tokens after the mechanism's closing brace: a file holds one \
                 mechanism"
                    .to_owned(),
            ),
        };
        error_at(source, at, locations, message)
    }
}

/// Scans `source` without making tokens. Stops at the first bracket problem; otherwise reports
/// the first statement that is too long, then too many statements, then trailing tokens, with
/// the full size of what is too big (the scan goes on counting, allocating nothing).
fn scan(source: &str, limits: &Limits) -> Scan {
    // Whole: one pass over the text, each branch updating the same state (open brackets, the
    // current statement's tokens, the problems found so far).
    let bytes = source.as_bytes();
    let mut scan = Scan {
        open: None,
        close: None,
        ends: Vec::new(),
        problem: None,
    };
    // Open brackets' offsets; bounded by MAX_DEPTH + 1 (deeper is a problem).
    let mut stack: Vec<usize> = Vec::new();
    let (mut tokens, mut statement_start) = (0usize, None::<usize>);
    let (mut statements, mut long, mut many, mut trailing) = (0usize, None, None, None);
    let mut i = usize::from(source.starts_with('\u{feff}')) * 3;
    while i < bytes.len() {
        let byte = bytes[i];
        let end = match token_end(bytes, i) {
            Ok(end) => end,
            Err(what) => {
                scan.problem = Some(Problem::Unterminated { start: i, what });
                return scan;
            }
        };
        let count = token_count(bytes, i, end);
        if count == 0 {
            i = end;
            continue;
        }
        if scan.close.is_some() {
            trailing.get_or_insert(i);
            i = end;
            continue;
        }
        statement_start.get_or_insert(i);
        // A group counts once, at its opening bracket.
        if !matches!(byte, b')' | b']' | b'}') {
            tokens += count;
        }
        match byte {
            b'(' | b'[' | b'{' => {
                if stack.len() >= MAX_DEPTH {
                    scan.problem = Some(Problem::Deep { open: i });
                    return scan;
                }
                if stack.is_empty() && byte == b'{' && scan.open.is_none() {
                    // The body: the header before it is measured as a statement of its own.
                    note_long(&mut long, statement_start.unwrap_or(i), tokens - 1);
                    scan.open = Some(i);
                    tokens = 0;
                    statement_start = None;
                }
                stack.push(i);
            }
            b')' | b']' | b'}' => {
                let Some(open) = stack.pop() else {
                    scan.problem = Some(Problem::Unopened { close: i });
                    return scan;
                };
                if closing(bytes[open]) != byte {
                    scan.problem = Some(Problem::Mismatched { open, close: i });
                    return scan;
                }
                if stack.is_empty() && Some(open) == scan.open {
                    scan.close = Some(i);
                }
            }
            b';' if stack.len() == 1 && scan.open.is_some() => {
                statements += 1;
                if statements > limits.statements {
                    many.get_or_insert(statement_start.unwrap_or(i));
                } else {
                    scan.ends.push(end);
                }
            }
            _ => {}
        }
        let ended = byte == b';' && stack.len() == 1 && scan.open.is_some() || scan.close.is_some();
        if ended || end >= bytes.len() {
            note_long(&mut long, statement_start.unwrap_or(i), tokens);
            tokens = 0;
            statement_start = None;
        }
        i = end;
    }
    note_long(&mut long, statement_start.unwrap_or(0), tokens);
    scan.problem = if let Some(&open) = stack.last() {
        Some(Problem::Unclosed { open })
    } else if let Some(problem) = long {
        Some(problem)
    } else if let Some(start) = many {
        Some(Problem::Many { start, statements })
    } else {
        trailing.map(|start| Problem::Trailing { start })
    };
    scan
}

/// Records a statement of `tokens` tokens from `start` as the first too long, if it is and no
/// other was.
fn note_long(long: &mut Option<Problem>, start: usize, tokens: usize) {
    if tokens > MAX_STATEMENT_TOKENS && long.is_none() {
        *long = Some(Problem::Long { start, tokens });
    }
}

fn closing(open: u8) -> u8 {
    match open {
        b'(' => b')',
        b'[' => b']',
        _ => b'}',
    }
}

fn is_ident_start(b: u8) -> bool {
    b.is_ascii_alphabetic() || b == b'_' || b >= 0x80
}

fn is_ident_continue(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_' || b >= 0x80
}

/// The end of the token (or whitespace run, or comment) starting at `i`, as proc-macro2 lexes
/// it; `Err` names what is left unterminated.
fn token_end(bytes: &[u8], i: usize) -> Result<usize, &'static str> {
    let at = |k: usize| bytes.get(k).copied().unwrap_or(0);
    let b = bytes[i];
    if b.is_ascii_whitespace() {
        let mut k = i + 1;
        while at(k).is_ascii_whitespace() {
            k += 1;
        }
        return Ok(k);
    }
    if b == b'/' && at(i + 1) == b'/' {
        return Ok(bytes[i..]
            .iter()
            .position(|&c| c == b'\n')
            .map_or(bytes.len(), |n| i + n));
    }
    if b == b'/' && at(i + 1) == b'*' {
        return block_comment_end(bytes, i);
    }
    if b == b'"' {
        return string_end(bytes, i + 1).map(|k| suffix_end(bytes, k));
    }
    if b == b'\'' {
        return Ok(char_end(bytes, i));
    }
    if b.is_ascii_digit() {
        return Ok(number_end(bytes, i));
    }
    if is_ident_start(b) {
        return word_end(bytes, i);
    }
    Ok(i + 1)
}

/// Just after the block comment (nested ones included) that starts at `i`.
fn block_comment_end(bytes: &[u8], i: usize) -> Result<usize, &'static str> {
    let at = |k: usize| bytes.get(k).copied().unwrap_or(0);
    let (mut depth, mut k) = (1usize, i + 2);
    while depth > 0 {
        match (at(k), at(k + 1)) {
            (0, _) if k >= bytes.len() => return Err("block comment"),
            (b'/', b'*') => (depth, k) = (depth + 1, k + 2),
            (b'*', b'/') => (depth, k) = (depth - 1, k + 2),
            _ => k += 1,
        }
    }
    Ok(k)
}

/// Just after the number (with its suffix, fraction and exponent) that starts at `i`.
fn number_end(bytes: &[u8], i: usize) -> usize {
    let at = |k: usize| bytes.get(k).copied().unwrap_or(0);
    let mut k = i + 1;
    loop {
        let c = at(k);
        let fraction = c == b'.' && at(k + 1) != b'.' && !is_ident_start(at(k + 1));
        let exponent_sign = (c == b'+' || c == b'-')
            && matches!(at(k - 1), b'e' | b'E')
            && at(k + 1).is_ascii_digit();
        if is_ident_continue(c) || fraction || exponent_sign {
            k += 1;
        } else {
            return k;
        }
    }
}

/// Just after the word that starts at `i`: an identifier or keyword, a raw identifier, or
/// the prefixed string, raw string or byte character it begins.
fn word_end(bytes: &[u8], i: usize) -> Result<usize, &'static str> {
    let at = |k: usize| bytes.get(k).copied().unwrap_or(0);
    let mut k = i + 1;
    while is_ident_continue(at(k)) {
        k += 1;
    }
    let word = &bytes[i..k];
    let raw = matches!(word, b"r" | b"br" | b"cr");
    if raw && (at(k) == b'"' || at(k) == b'#' && matches!(at(k + 1), b'#' | b'"')) {
        let hashes = bytes[k..].iter().take_while(|&&c| c == b'#').count();
        let mut j = k + hashes + 1;
        loop {
            let Some(n) = bytes
                .get(j..)
                .and_then(|r| r.iter().position(|&c| c == b'"'))
            else {
                return Err("raw string");
            };
            j += n + 1;
            if bytes[j..]
                .iter()
                .take(hashes)
                .filter(|&&c| c == b'#')
                .count()
                == hashes
            {
                return Ok(suffix_end(bytes, j + hashes));
            }
        }
    }
    if word == b"r" && at(k) == b'#' && is_ident_start(at(k + 1)) {
        let mut j = k + 2;
        while is_ident_continue(at(j)) {
            j += 1;
        }
        return Ok(j);
    }
    if matches!(word, b"b" | b"c") && at(k) == b'"' {
        return string_end(bytes, k + 1).map(|j| suffix_end(bytes, j));
    }
    if word == b"b" && at(k) == b'\'' {
        return Ok(char_end(bytes, k));
    }
    Ok(k)
}

/// Just after the closing `"` of a string whose contents start at `k`.
fn string_end(bytes: &[u8], mut k: usize) -> Result<usize, &'static str> {
    loop {
        match bytes.get(k) {
            None => return Err("string"),
            Some(b'\\') => k += 2,
            Some(b'"') => return Ok(k + 1),
            Some(_) => k += 1,
        }
    }
}

/// A literal's suffix (`"…"suffix`), which proc-macro2 lexes as part of it.
fn suffix_end(bytes: &[u8], mut k: usize) -> usize {
    if bytes.get(k).is_some_and(|&b| is_ident_start(b)) {
        while bytes.get(k).is_some_and(|&b| is_ident_continue(b)) {
            k += 1;
        }
    }
    k
}

/// After a character literal at `i` (`'a'`, `'\n'`), or after the `'` of a lifetime.
fn char_end(bytes: &[u8], i: usize) -> usize {
    let rest = &bytes[i + 1..];
    let body = match rest.first() {
        Some(b'\\') => rest
            .iter()
            .skip(2)
            .take(10)
            .position(|&c| c == b'\'')
            .map(|n| n + 2),
        Some(&c) => {
            // One character (1 to 4 bytes of UTF-8), then `'`.
            let width = match c {
                0..0x80 => 1,
                0xE0..0xF0 => 3,
                0xF0.. => 4,
                _ => 2,
            };
            (rest.get(width) == Some(&b'\'')).then_some(width)
        }
        None => None,
    };
    body.map_or(i + 1, |n| suffix_end(bytes, i + 1 + n + 1))
}

/// Tokens proc-macro2 makes of `bytes[i..end]`, as `limits::check` counts them (a group
/// counts once, at its opening bracket; a doc comment is `#`, `!` for inner ones, and a
/// bracketed `doc = "…"`).
fn token_count(bytes: &[u8], i: usize, end: usize) -> usize {
    let piece = &bytes[i..end];
    let doc_line = piece.starts_with(b"///") && !piece.starts_with(b"////");
    let doc_block = piece.starts_with(b"/**") && !piece.starts_with(b"/***") && piece != b"/**/";
    let inner = piece.starts_with(b"//!") || piece.starts_with(b"/*!");
    match piece.first() {
        Some(b) if b.is_ascii_whitespace() => 0,
        Some(b'/') if piece.get(1).is_some_and(|&c| c == b'/' || c == b'*') => {
            if doc_line || doc_block {
                5
            } else if inner {
                6
            } else {
                0
            }
        }
        _ => 1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn problem(source: &str, limits: &Limits) -> String {
        match read(source, limits).spec {
            Ok(_) => panic!("expected an error"),
            Err(e) => e.to_string(),
        }
    }

    const HEAD: &str = "mechanism M {\n    ground g at (0, 0, 0);\n";

    #[test]
    fn counts_tokens_as_the_token_check_does() {
        let count = |s: &str| {
            let b = s.as_bytes();
            let (mut i, mut n) = (0, 0);
            while i < b.len() {
                let end = token_end(b, i).unwrap_or(b.len());
                if !matches!(b[i], b')' | b']' | b'}') {
                    n += token_count(b, i, end);
                }
                i = end;
            }
            n
        };
        for s in [
            "param p = 1.5e-3 * t^2 + 30deg;",
            "/// doc\n param p = (1, 2.);",
            "joint j: revolute(a @ (1, 2), b); // comment",
            "x /* a /* nested */ block */ 'a 'b' b'c' r#raw \"s\\\"\"x r#\"q\"# 1..2",
            "//! inner\n /** outer */ x",
        ] {
            let tokens: TokenStream = s.parse().expect("lexes");
            fn walk(t: TokenStream) -> usize {
                t.into_iter()
                    .map(|t| match t {
                        proc_macro2::TokenTree::Group(g) => 1 + walk(g.stream()),
                        _ => 1,
                    })
                    .sum()
            }
            assert_eq!(count(s), walk(tokens), "{s}");
        }
    }

    #[test]
    fn reads_statements_in_chunks() {
        // Several chunks: every statement parsed once, in order.
        let markers: String = (0..4000)
            .map(|i| format!("    marker m{i}: g @ ({i}, 0); // the {i}th\n"))
            .collect();
        let source = format!("/// Doc.\npub {HEAD}{markers}}}\n");
        assert!(source.len() > 2 * CHUNK_BYTES);
        let read = read(&source, &Limits::default());
        let spec = read.spec.unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(spec.markers.len(), 4000);
        assert_eq!(spec.markers[3999].name, "m3999");
        assert!(read.locations.chunks.len() > 2);
        assert_eq!(spec.docs.len(), 1);
    }

    #[test]
    fn limits_apply_before_lexing_and_say_how_big() {
        let statements: String = (0..20).map(|i| format!("param p{i} = 1;\n")).collect();
        let source = format!("{HEAD}{statements}}}");
        let small = Limits {
            bytes: 1000,
            statements: 10,
        };
        let many = problem(&source, &small);
        assert!(
            many.contains("has 21 statements, more than the 10 mechgen reads"),
            "{many}"
        );
        let tiny = Limits {
            bytes: 100,
            statements: 10,
        };
        let big = problem(&source, &tiny);
        assert!(
            big.contains(&format!(
                "is {} bytes, more than the 100 bytes",
                source.len()
            )),
            "{big}"
        );
        let long = format!("{HEAD}param p = 1{};\n}}", " + 1".repeat(6000));
        let long = problem(&long, &Limits::default());
        assert!(long.contains("is 12005 tokens long"), "{long}");
    }

    #[test]
    fn bracket_problems_are_found_by_the_scan() {
        let d = Limits::default();
        assert!(problem("mechanism M {\n param p = (1;\n}\n", &d).contains("does not close"));
        assert!(problem("mechanism M {\n param p = 1;\n", &d).contains("never closed"));
        assert!(problem(") mechanism M { }", &d).contains("closes nothing"));
        assert!(problem("mechanism M { /* x }", &d).contains("block comment is never"));
        assert!(problem("mechanism M { } x", &d).contains("after the mechanism's closing"));
        assert!(problem("mechanism M", &d).contains("unexpected end of input"));
        assert!(problem("mechanism M (x) { }", &d).contains("expected `{`"));
    }
}
