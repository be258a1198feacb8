//! The README's excerpts of generated code: every block marked `<!-- excerpt: PATH -->` must
//! appear in the file at PATH, line for line and in order (lines with `…` stand for the lines
//! left out; a `// comment` after code is the README's note). The README's Rust blocks are
//! compiled and run as doctests of this crate (`src/lib.rs`).

use std::path::Path;

const MARKER: &str = "<!-- excerpt: ";

/// `(path, lines)` of every marked excerpt.
fn excerpts(readme: &str) -> Vec<(String, Vec<String>)> {
    let mut found = Vec::new();
    let mut lines = readme.lines();
    while let Some(line) = lines.next() {
        let Some(path) = line
            .strip_prefix(MARKER)
            .and_then(|rest| rest.strip_suffix(" -->"))
        else {
            continue;
        };
        let fence = lines.next().unwrap_or_default();
        assert!(fence.starts_with("```"), "a fenced block follows {line}");
        let body: Vec<String> = lines
            .by_ref()
            .take_while(|l| !l.starts_with("```"))
            .map(str::to_owned)
            .collect();
        found.push((path.to_owned(), body));
    }
    found
}

/// The code of an excerpt line, without the README's trailing note; `None` for an elision.
fn code(line: &str) -> Option<&str> {
    let line = line.trim();
    if line.is_empty() || line.contains('…') {
        return None;
    }
    let code = match line.find(" // ") {
        Some(at) if !line.starts_with("//") => &line[..at],
        _ => line,
    };
    Some(code.trim_end())
}

/// Finds every line of `excerpt` in `source`, in order; returns the first that is missing.
fn missing<'a>(excerpt: &'a [String], source: &str) -> Option<&'a str> {
    let mut source = source.lines().map(str::trim);
    excerpt
        .iter()
        .filter_map(|line| code(line))
        .find(|wanted| !source.any(|line| line == *wanted))
}

#[test]
fn readme_excerpts_are_in_the_generated_code() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let readme = std::fs::read_to_string(root.join("README.md")).expect("README");
    let excerpts = excerpts(&readme);
    assert!(excerpts.len() >= 2, "the README marks its excerpts");
    for (path, lines) in &excerpts {
        let source =
            std::fs::read_to_string(root.join(path)).unwrap_or_else(|e| panic!("{path}: {e}"));
        if let Some(line) = missing(lines, &source) {
            panic!("README excerpt line `{line}` is not in {path} (in this order)");
        }
    }
}

#[test]
fn a_changed_line_is_caught() {
    let excerpt = ["a;".to_owned(), "// …".to_owned(), "c; // note".to_owned()];
    assert_eq!(missing(&excerpt, "a;\nb;\nc;\n"), None);
    assert_eq!(missing(&excerpt, "a;\nb;\nc + 1;\n"), Some("c;"));
    // Order matters.
    assert_eq!(missing(&excerpt, "c;\na;\n"), Some("c;"));
}
