//! Snapshot tests of the code generated for every example scene (`examples/scenes/*.mech`): the
//! formatted Rust, and a table of the operations each generated function performs.
//!
//! A change to the generator shows up here as a reviewable diff of the emitted code, and a
//! regression in what a function computes (more trigonometry, a lost shared sub-expression) as
//! a diff in the table. Accept intended changes with `INSTA_UPDATE=always cargo test -p
//! mechgen-tests --test snapshots` (or `cargo insta review`) and read the `.snap` diff.

use std::fs;
use std::path::{Path, PathBuf};

use mechgen::expr::Id;
use mechgen::interpret::topological_order;
use mechgen::stats::OpCounts;

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
        let code = mechgen::expand_pretty(&source)
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

/// One row per generated function: outputs written (non-zero entries only, as emitted) and the
/// operations of evaluating their DAG once, shared sub-expressions counted once.
fn operation_table(source: &str) -> Result<String, mechgen::Errors> {
    let mechgen::Scene { model, kinematics } = mechgen::compile_str(source)?;
    let arena = &model.arena;
    // The emitter computes only non-zero outputs (zeros come from one `fill(0.0)`), so count
    // only those; the Jacobian holds its structural non-zeros already.
    let nonzero = |ids: &[Id]| -> Vec<Id> {
        ids.iter()
            .copied()
            .filter(|&id| !arena.is_zero(id))
            .collect()
    };
    let phi = nonzero(&kinematics.phi);
    let jacobian: Vec<Id> = kinematics.jacobian.iter().map(|e| e.value).collect();
    let phi_and_jacobian: Vec<Id> = phi.iter().chain(&jacobian).copied().collect();
    let functions = [
        ("phi", phi),
        ("jacobian", jacobian),
        ("phi_and_jacobian", phi_and_jacobian),
        ("nu", nonzero(&kinematics.nu)),
        ("gamma", nonzero(&kinematics.gamma)),
    ];

    let n = model.dim();
    let mut table = format!(
        "{n} coordinates; Jacobian: {} structural non-zeros of {}\n\n",
        kinematics.jacobian.len(),
        n * n
    );
    table += &format!(
        "{:<16} {:>7} {:>4} {:>4} {:>6} {:>4} {:>4} {:>4} {:>4}\n",
        "function", "outputs", "trig", "sqrt", "exp/ln", "mul", "add", "div", "neg"
    );
    for (name, roots) in &functions {
        let c = OpCounts::of(arena, &topological_order(arena, roots));
        table += &format!(
            "{name:<16} {:>7} {:>4} {:>4} {:>6} {:>4} {:>4} {:>4} {:>4}\n",
            roots.len(),
            c.trig,
            c.sqrt,
            c.exp_ln,
            c.mul,
            c.add,
            c.div,
            c.neg
        );
    }
    Ok(table)
}
