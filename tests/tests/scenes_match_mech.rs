//! Holds the `mechanism! { … }` invocations in `examples/src/scenes.rs` and the `.mech` files in
//! `examples/scenes/` to the same tokens, so that the macro-built scenes and the CLI's scenes
//! cannot drift apart.
//!
//! Both are compared as token streams (comments and layout do not matter; doc comments do, as
//! they become the generated docs), matched by mechanism name.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

use proc_macro2::{Delimiter, TokenStream, TokenTree};

fn examples_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples")
}

fn tokenize(path: &Path) -> TokenStream {
    let text =
        fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    text.parse()
        .unwrap_or_else(|e| panic!("{} does not tokenize: {e}", path.display()))
}

/// The bodies of the top-level `mechanism ! { … }` invocations of a Rust file. Top level is
/// enough: the scenes are items of their module, not nested in functions.
fn macro_bodies(file: TokenStream) -> Vec<TokenStream> {
    let tokens: Vec<TokenTree> = file.into_iter().collect();
    tokens
        .windows(3)
        .filter_map(|w| match w {
            [
                TokenTree::Ident(name),
                TokenTree::Punct(bang),
                TokenTree::Group(body),
            ] if name == "mechanism"
                && bang.as_char() == '!'
                && body.delimiter() == Delimiter::Brace =>
            {
                Some(body.stream())
            }
            _ => None,
        })
        .collect()
}

/// The name declared by a scene: the identifier after the top-level `mechanism` keyword (doc
/// attributes and `pub` come before it).
fn mechanism_name(scene: &TokenStream) -> String {
    let mut tokens = scene.clone().into_iter();
    while let Some(token) = tokens.next() {
        if matches!(&token, TokenTree::Ident(i) if i == "mechanism")
            && let Some(TokenTree::Ident(name)) = tokens.next()
        {
            return name.to_string();
        }
    }
    panic!("no `mechanism NAME` in scene: {scene}");
}

/// Scenes by mechanism name; a name declared twice is an error (the match would be ambiguous).
fn by_name(
    scenes: impl IntoIterator<Item = (TokenStream, String)>,
) -> BTreeMap<String, (String, String)> {
    let mut map = BTreeMap::new();
    for (scene, origin) in scenes {
        let name = mechanism_name(&scene);
        if let Some((_, first)) = map.insert(name.clone(), (scene.to_string(), origin.clone())) {
            panic!("mechanism `{name}` is declared twice: in {first} and in {origin}");
        }
    }
    map
}

/// Where two token strings first differ, with some context, since a whole-scene `assert_eq!`
/// on one long line is unreadable.
fn first_difference(a: &str, b: &str) -> String {
    let at = a
        .char_indices()
        .zip(b.chars())
        .find(|((_, x), y)| x != y)
        .map_or(a.len().min(b.len()), |((i, _), _)| i);
    let context = |s: &str| {
        let start = s[..at].char_indices().rev().nth(60).map_or(0, |(i, _)| i);
        let end = s[at..]
            .char_indices()
            .nth(60)
            .map_or(s.len(), |(i, _)| at + i);
        format!("…{}⟨here⟩{}…", &s[start..at], &s[at..end])
    };
    format!(
        "first difference:\n  scenes.rs: {}\n  .mech:     {}",
        context(a),
        context(b)
    )
}

#[test]
fn macro_scenes_and_mech_files_have_the_same_tokens() {
    let rust_file = examples_dir().join("src/scenes.rs");
    let in_rust = by_name(
        macro_bodies(tokenize(&rust_file))
            .into_iter()
            .map(|scene| (scene, "examples/src/scenes.rs".to_owned())),
    );
    assert!(
        !in_rust.is_empty(),
        "no `mechanism! {{ … }}` in {}",
        rust_file.display()
    );

    let scenes_dir = examples_dir().join("scenes");
    let mut mech_files: Vec<PathBuf> = fs::read_dir(&scenes_dir)
        .unwrap_or_else(|e| panic!("reading {}: {e}", scenes_dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "mech"))
        .collect();
    mech_files.sort();
    let in_mech = by_name(mech_files.iter().map(|path| {
        let origin = format!(
            "examples/scenes/{}",
            path.file_name()
                .and_then(|n| n.to_str())
                .expect("UTF-8 file name")
        );
        (tokenize(path), origin)
    }));

    // Every scene has both forms: the macro for Rust users, the file for the CLI.
    let rust_names: Vec<&String> = in_rust.keys().collect();
    let mech_names: Vec<&String> = in_mech.keys().collect();
    assert_eq!(
        rust_names, mech_names,
        "examples/src/scenes.rs and examples/scenes/*.mech must declare the same mechanisms"
    );

    for (name, (rust, rust_origin)) in &in_rust {
        let (mech, mech_origin) = &in_mech[name];
        assert!(
            rust == mech,
            "`{name}` differs between {rust_origin} and {mech_origin}; {}",
            first_difference(rust, mech)
        );
    }
}

/// The extraction itself: finds every invocation, names it, keeps doc comments as tokens and
/// ignores layout and plain comments, but sees a one-token change.
#[test]
fn extraction_compares_tokens_not_text() {
    let rust: TokenStream = "use x::mechanism;
        mechanism! {
            /// Docs.
            pub mechanism A { param p = 1.0; } // trailing comment
        }
        fn unrelated() { mechanism(); }
        mechanism! { mechanism B {} }"
        .parse()
        .expect("tokenizes");
    let bodies = macro_bodies(rust);
    let names: Vec<String> = bodies.iter().map(mechanism_name).collect();
    assert_eq!(names, ["A", "B"]);

    let same: TokenStream = "/// Docs.\npub mechanism A {\n    param p = 1.0;\n}\n"
        .parse()
        .expect("tokenizes");
    assert_eq!(bodies[0].to_string(), same.to_string());

    let changed: TokenStream = "/// Docs.\npub mechanism A { param p = 1.5; }"
        .parse()
        .expect("tokenizes");
    let (a, b) = (bodies[0].to_string(), changed.to_string());
    assert_ne!(a, b);
    assert!(first_difference(&a, &b).contains("⟨here⟩"));
}
