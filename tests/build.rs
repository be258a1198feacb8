//! Generates into `OUT_DIR` what the tests include with options the `mechanism!` macro does not
//! take (the `build.rs` route users take for them): the seed with a tiny `max_function_size`,
//! so that a test can hold split generated functions to the unsplit ones, and the motion
//! kernels' scene with its equations of motion, whole and split (`tests/motion_kernels.rs`).

use std::path::{Path, PathBuf};

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let split = mechgen::CodegenOptions {
        max_function_size: 12,
        ..Default::default()
    };
    generate(
        &root.join("../examples/scenes/piston_crank.mech"),
        split,
        "piston_crank_split.rs",
    );
    let motion = mechgen::CodegenOptions {
        equations_of_motion: true,
        ..Default::default()
    };
    let scene = root.join("data/swing_motion.mech");
    generate(&scene, motion, "swing_motion.rs");
    let motion_split = mechgen::CodegenOptions {
        max_function_size: 12,
        ..motion
    };
    generate(&scene, motion_split, "swing_motion_split.rs");
}

/// Writes the code of the scene at `path`, generated with `codegen`, to `OUT_DIR/file`.
fn generate(path: &Path, codegen: mechgen::CodegenOptions, file: &str) {
    println!("cargo:rerun-if-changed={}", path.display());
    let source = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{} is not readable: {e}", path.display()));
    let options = mechgen::Options {
        codegen,
        ..Default::default()
    };
    let code =
        mechgen::expand(mechgen::Input::Text(&source), &options).unwrap_or_else(|e| panic!("{e}"));
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    std::fs::write(out.join(file), code.to_string()).expect("OUT_DIR is writable");
}
