//! Writes the scissor lift at each size of `SIZES` to `$OUT_DIR/lift_N.rs`, with the scene
//! builder of `mechgen-scissor` (its `scene.rs` and geometry, shared by path).

#[allow(dead_code)]
#[path = "../scissor/src/geometry.rs"]
mod geometry;
#[path = "../scissor/scene.rs"]
mod scene;

use std::error::Error;

/// Stage counts: keep in step with `src/lib.rs`.
const SIZES: [usize; 3] = [10, 100, 1000];

fn main() -> Result<(), Box<dyn Error>> {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=../scissor/scene.rs");
    println!("cargo:rerun-if-changed=../scissor/src/geometry.rs");
    for stages in SIZES {
        scene::scissor_lift(stages).write_to_out_dir(
            &format!("lift_{stages}.rs"),
            &mechgen::CodegenOptions::default(),
        )?;
    }
    Ok(())
}
