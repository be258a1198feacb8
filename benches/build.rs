//! Generates the naive baseline of the seed (no folding, no simplification, no shared
//! sub-expressions) into `OUT_DIR`, so benchmarks can time the lean generated code against it
//! in the same run (included by `benches/kinematics.rs`).

use std::path::PathBuf;

fn main() {
    let scene =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/scenes/piston_crank.mech");
    println!("cargo:rerun-if-changed={}", scene.display());
    let source = std::fs::read_to_string(&scene).expect("the seed scene is readable");
    let options = mechgen::Options {
        codegen: mechgen::CodegenOptions {
            naive: true,
            ..Default::default()
        },
        ..Default::default()
    };
    let code =
        mechgen::expand(mechgen::Input::Text(&source), &options).unwrap_or_else(|e| panic!("{e}"));
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    std::fs::write(out.join("piston_crank_naive.rs"), code.to_string())
        .expect("OUT_DIR is writable");
}
