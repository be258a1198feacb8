//! Writes the scissor lift at each size of `SIZES` to `$OUT_DIR/lift_N.rs`, with the scene
//! builder of `mechgen-scissor` (its `scene.rs` and geometry, shared by path); with the
//! `dynamics` feature also the falling lift (`falling.rs`) to `$OUT_DIR/falling_lift_N.rs`.

#[allow(dead_code)]
#[path = "../scissor/src/geometry.rs"]
mod geometry;
#[path = "../scissor/scene.rs"]
mod scene;
// Only with the `dynamics` feature (the `free` grammar of forward dynamics).
#[allow(dead_code)]
mod falling;

use std::error::Error;

/// Stage counts: keep in step with `src/lib.rs`.
const SIZES: [usize; 3] = [10, 100, 1000];

fn main() -> Result<(), Box<dyn Error>> {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=../scissor/scene.rs");
    println!("cargo:rerun-if-changed=../scissor/src/geometry.rs");
    println!("cargo:rerun-if-changed=falling.rs");
    let dynamics = std::env::var_os("CARGO_FEATURE_DYNAMICS").is_some();
    for stages in SIZES {
        scene::scissor_lift(stages).write_to_out_dir(
            &format!("lift_{stages}.rs"),
            &mechgen::CodegenOptions::default(),
        )?;
        if dynamics {
            falling::falling_scissor_lift(stages).write_to_out_dir(
                &format!("falling_lift_{stages}.rs"),
                &mechgen::CodegenOptions::default(),
            )?;
        }
    }
    Ok(())
}
