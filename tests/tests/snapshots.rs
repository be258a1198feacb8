//! Snapshot tests of the code generated for every example scene (`examples/scenes/*.mech`): the
//! formatted Rust, a table of the operations each generated function performs, and the solve
//! structure (stages, blocks, their static LU).
//!
//! A change to the generator shows up here as a reviewable diff of the emitted code, and a
//! regression in what a function computes (more trigonometry, a lost shared sub-expression) as
//! a diff in the table. Accept intended changes with `INSTA_UPDATE=always cargo test -p
//! mechgen-tests --test snapshots` (or `cargo insta review`) and read the `.snap` diff.

use std::fs;
use std::path::{Path, PathBuf};

/// The example scenes, sorted by file name so that snapshot order (and failure order) is stable;
/// a new `.mech` file gets its snapshots without touching this test.
fn scenes() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/scenes");
    // Canonical, so that snapshot headers read `examples/scenes/…` rather than `tests/../…`.
    let dir = dir
        .canonicalize()
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    let mut paths: Vec<PathBuf> = fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("reading {}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "mech"))
        .collect();
    paths.sort();
    assert!(!paths.is_empty(), "no .mech scenes in {}", dir.display());
    paths
}

/// Snapshot name of a scene: its file stem (`piston_crank`).
fn stem(path: &Path) -> String {
    path.file_stem()
        .and_then(|s| s.to_str())
        .expect("UTF-8 file name")
        .to_owned()
}

/// Runs `check` under insta settings that record which scene a snapshot came from.
fn with_scene_settings(path: &Path, check: impl FnOnce()) {
    let mut settings = insta::Settings::clone_current();
    // Recorded relative to the workspace root, so the header is the same on every machine.
    settings.set_input_file(path);
    settings.set_omit_expression(true);
    settings.bind(check);
}

#[test]
fn generated_code() {
    for path in scenes() {
        let source = fs::read_to_string(&path).expect("readable scene");
        let code = mechgen::expand(mechgen::Input::Text(&source), &mechgen::Options::default())
            .map(mechgen::pretty)
            .unwrap_or_else(|e| panic!("{} does not compile:\n{e}", path.display()));
        with_scene_settings(&path, || insta::assert_snapshot!(stem(&path), code));
    }
}

#[test]
fn operation_counts() {
    for path in scenes() {
        let source = fs::read_to_string(&path).expect("readable scene");
        let table = operation_table(&source)
            .unwrap_or_else(|e| panic!("{} does not compile:\n{e}", path.display()));
        let name = format!("{}_operations", stem(&path));
        with_scene_settings(&path, || insta::assert_snapshot!(name, table));
    }
}

/// The Jacobian's sparsity and the operation table of every generated function, lean (what
/// users get) and naive (no folding, no simplification, no sharing: the baseline it saves on).
fn operation_table(source: &str) -> Result<String, mechgen::Errors> {
    let lean = mechgen::compile(mechgen::Input::Text(source), &mechgen::Options::default())?;
    let naive_options = mechgen::Options {
        codegen: mechgen::CodegenOptions {
            naive: true,
            ..Default::default()
        },
        ..Default::default()
    };
    let naive = mechgen::compile(mechgen::Input::Text(source), &naive_options)?;
    let n = lean.model.dim();
    let mut table = format!(
        "{n} coordinates; Jacobian: {} structural non-zeros of {} (naive: {})\n\n",
        lean.kinematics.jacobian.len(),
        n * n,
        naive.kinematics.jacobian.len()
    );
    table += "lean (folded, simplified, shared sub-expressions):\n";
    table += &mechgen::plan::stats::table(&lean);
    table += "\nnaive (no folding or simplification, every use evaluated):\n";
    table += &mechgen::plan::stats::table(&naive);
    Ok(table)
}

#[test]
fn solve_structure() {
    for path in scenes() {
        let source = fs::read_to_string(&path).expect("readable scene");
        let scene = mechgen::compile(mechgen::Input::Text(&source), &mechgen::Options::default())
            .unwrap_or_else(|e| panic!("{} does not compile:\n{e}", path.display()));
        let structure = mechgen::plan::stats::structure(&scene);
        with_scene_settings(&path, || {
            insta::assert_snapshot!(format!("{}_structure", stem(&path)), structure);
        });
    }
}
