//! Generates the seed with a tiny `max_function_size` into `OUT_DIR`, so that a test can hold
//! split generated functions to the unsplit ones (the `build.rs` route users take for big scenes).

use std::path::PathBuf;

fn main() {
    let scene =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/scenes/piston_crank.mech");
    println!("cargo:rerun-if-changed={}", scene.display());
    let source = std::fs::read_to_string(&scene).expect("the seed scene is readable");
    let options = mechgen::Options {
        codegen: mechgen::CodegenOptions {
            max_function_size: 12,
            ..Default::default()
        },
        ..Default::default()
    };
    let code =
        mechgen::expand(mechgen::Input::Text(&source), &options).unwrap_or_else(|e| panic!("{e}"));
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    std::fs::write(out.join("piston_crank_split.rs"), code.to_string())
        .expect("OUT_DIR is writable");
}
