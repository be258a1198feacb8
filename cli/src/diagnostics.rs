//! Rendering of mechgen's spanned errors for a `.mech` file, rustc-style: `FILE:LINE:COL: error:
//! MESSAGE`, the offending source line, and carets under the span.

use core::fmt::Write;

use mechgen::syntax::source::Locations;
use proc_macro2::{LineColumn, Span};

/// proc-macro2's lexer error carries no hint; this one says what usually causes it.
const LEX_ERROR: &str = "cannot parse string into token stream";
/// Errors shown per file; past this the rest are counted (a broken generator script can produce
/// thousands, and the first ones are the useful ones).
const MAX_SHOWN: usize = 50;
/// Characters of a source line shown around the column; longer lines are elided with `…`.
const LINE_WINDOW: usize = 100;
const LEX_HINT: &str = "cannot split the file into tokens here: look for an unbalanced or \
                        mismatched bracket, an unterminated string or block comment, or a \
                        character that is not allowed (such as a backtick)";

/// Renders every error of `errors` (one block each) for the file `name` with contents `source`,
/// followed by a one-line summary.
///
/// The spans must come from reading `source` in this process with
/// [`mechgen::syntax::source::read`], whose `locations` place them in the text.
pub fn render(name: &str, source: &str, locations: &Locations, errors: &mechgen::Errors) -> String {
    let mut out = String::new();
    let mut count = 0usize;
    for error in errors.iter() {
        // A combined syn::Error holds several messages, each with its own span.
        for single in error {
            count += 1;
            if count > MAX_SHOWN {
                continue;
            }
            let message = single.to_string();
            let message = if message == LEX_ERROR {
                LEX_HINT.to_owned()
            } else {
                message
            };
            block(&mut out, name, source, locations, single.span(), &message);
        }
    }
    if count > MAX_SHOWN {
        let _ = writeln!(out, "note: {} more errors not shown\n", count - MAX_SHOWN);
    }
    let plural = if count == 1 { "" } else { "s" };
    // Writing to a String cannot fail.
    let _ = write!(
        out,
        "error: could not compile `{name}` ({count} error{plural}); fix the lines above and retry"
    );
    out
}

fn block(
    out: &mut String,
    name: &str,
    source: &str,
    locations: &Locations,
    span: Span,
    message: &str,
) {
    let Some((start, end)) = location(source, locations, span) else {
        let _ = writeln!(out, "{name}: error: {message}\n");
        return;
    };
    let line_text = source.lines().nth(start.line - 1).unwrap_or("");
    // A byte-order mark counts as a column for proc-macro2 but is invisible: drop both.
    let (line_text, column) = match line_text.strip_prefix('\u{feff}') {
        Some(rest) if start.line == 1 => (rest, start.column.saturating_sub(1)),
        _ => (line_text, start.column),
    };
    let _ = writeln!(
        out,
        "{name}:{}:{}: error: {message}",
        start.line,
        column + 1
    );
    let number = start.line.to_string();
    let gutter = " ".repeat(number.len());
    let width = match end {
        Some(end) if end.line == start.line && end.column > start.column => {
            end.column - start.column
        }
        _ => 1,
    };
    let (shown, column, width) = window(line_text, column, width);
    let _ = writeln!(out, "{number} | {shown}");
    // Tabs are copied so the caret lines up whatever the terminal's tab width.
    let pad: String = shown
        .chars()
        .take(column)
        .map(|c| if c == '\t' { '\t' } else { ' ' })
        .collect();
    let _ = writeln!(out, "{gutter} | {pad}{}\n", "^".repeat(width));
}

/// The part of a long line around `column` (with `…` where cut), and the column and caret
/// width within it.
fn window(line: &str, column: usize, width: usize) -> (String, usize, usize) {
    let length = line.chars().count();
    if length <= LINE_WINDOW {
        return (line.to_owned(), column, width);
    }
    let first = column
        .saturating_sub(LINE_WINDOW / 2)
        .min(length - LINE_WINDOW);
    let last = first + LINE_WINDOW;
    let mut shown: String = line.chars().skip(first).take(LINE_WINDOW).collect();
    let mut column = column - first;
    if first > 0 {
        shown.insert(0, '…');
        column += 1;
    }
    if last < length {
        shown.push('…');
    }
    let width = width.min(LINE_WINDOW.saturating_sub(column).max(1));
    (shown, column, width)
}

/// Start (1-based line, 0-based character column) and, if known, end of `span` in `source`.
fn location(
    source: &str,
    locations: &Locations,
    span: Span,
) -> Option<(LineColumn, Option<LineColumn>)> {
    // Only call-site spans have no source text; syn uses them for "unexpected end of input",
    // which is best shown at the end of the file.
    if span.source_text().is_none() {
        return Some((end_of_file(source), None));
    }
    // The text was lexed in chunks: place the chunk-relative position.
    let origin = locations.origin(span)?;
    let place = |at: LineColumn| {
        let (line, column) = origin.place(at.line, at.column);
        LineColumn { line, column }
    };
    let start = place(span.start());
    let lines = source.lines().count().max(1);
    if start.line == 0 || start.line > lines {
        return None;
    }
    Some((start, Some(place(span.end()))))
}

/// Just after the last character of the last non-blank line.
fn end_of_file(source: &str) -> LineColumn {
    source
        .lines()
        .enumerate()
        .filter(|(_, text)| !text.trim().is_empty())
        .last()
        .map_or(LineColumn { line: 1, column: 0 }, |(index, text)| {
            LineColumn {
                line: index + 1,
                column: text.trim_end().chars().count(),
            }
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rendered(source: &str) -> String {
        let read =
            mechgen::syntax::source::read(source, &mechgen::syntax::limits::Limits::default());
        let errors = match read.spec {
            Ok(spec) => mechgen::compile(mechgen::Input::Spec(&spec), &mechgen::Options::default())
                .err()
                .expect("errors"),
            Err(error) => error.into(),
        };
        render("scene.mech", source, &read.locations, &errors)
    }

    #[test]
    fn points_at_the_offending_token() {
        let out = rendered("mechanism M {\n\tjoint j: hinge(a, b);\n}\n");
        assert!(
            out.starts_with("scene.mech:2:11: error: unknown joint kind `hinge`"),
            "{out}"
        );
        assert!(
            out.contains("\n2 | \tjoint j: hinge(a, b);\n  | \t         ^^^^^\n"),
            "{out}"
        );
        assert!(
            out.ends_with("(1 error); fix the lines above and retry"),
            "{out}"
        );
    }

    #[test]
    fn end_of_input_points_at_the_end_of_the_file() {
        let out = rendered("/// docs\nmechanism M\n\n");
        assert!(
            out.starts_with("scene.mech:2:12: error: unexpected end of input"),
            "{out}"
        );
    }

    #[test]
    fn long_lines_are_cut_around_the_column_and_errors_capped() {
        let source = format!("mechanism M {{ param p = 1{} + q; }}", " + 1".repeat(100));
        let out = rendered(&source);
        let mut lines = out
            .lines()
            .skip_while(|l| !l.contains("unknown name `q`"))
            .skip(1);
        let (line, caret) = (lines.next().unwrap_or(""), lines.next().unwrap_or(""));
        assert!(
            line.starts_with("1 | …") && line.ends_with(" + q; }"),
            "{out}"
        );
        // Both lines in characters: `…` is one character but three bytes.
        let q = line.chars().position(|c| c == 'q');
        assert_eq!(caret.chars().position(|c| c == '^'), q, "{out}");

        let params: String = (0..60).map(|i| format!("param p{i} = t;\n")).collect();
        let out = rendered(&format!("mechanism M {{\n{params}}}"));
        assert_eq!(out.matches(": error: ").count(), MAX_SHOWN, "{out}");
        assert!(out.contains(" more errors not shown"), "{out}");
    }

    #[test]
    fn lexer_errors_get_a_hint() {
        let out = rendered("mechanism M {\n  param p = (1;\n}\n");
        assert!(out.contains("unbalanced or mismatched bracket"), "{out}");
        assert!(out.contains("scene.mech:"), "{out}");
    }
}
