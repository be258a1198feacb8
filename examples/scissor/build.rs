//! Builds the n-stage scissor lift with `mechgen::builder` and writes its generated code to
//! `$OUT_DIR/scissor.rs`, which `src/lib.rs` includes. n is `MECHGEN_SCISSOR_STAGES` (default 4).

// The geometry module also serves the library and tests; not all of it is used here.
#[allow(dead_code)]
#[path = "src/geometry.rs"]
mod geometry;
mod scene;

use std::error::Error;

/// Stages when `MECHGEN_SCISSOR_STAGES` is not set: small enough for the dense solver.
const DEFAULT_STAGES: usize = 4;

fn main() -> Result<(), Box<dyn Error>> {
    println!("cargo:rerun-if-env-changed=MECHGEN_SCISSOR_STAGES");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=scene.rs");
    println!("cargo:rerun-if-changed=src/geometry.rs");
    let stages = match std::env::var("MECHGEN_SCISSOR_STAGES") {
        Ok(text) => match text.trim().parse::<usize>() {
            Ok(n) if n >= 1 => n,
            _ => {
                return Err(format!(
                    "MECHGEN_SCISSOR_STAGES={text:?}: expected a whole number of stages, at least 1"
                )
                .into());
            }
        },
        Err(_) => DEFAULT_STAGES,
    };
    scene::scissor_lift(stages)
        .write_to_out_dir("scissor.rs", &mechgen::CodegenOptions::default())?;
    Ok(())
}
