//! The scissor lift of `mechgen-scissor` generated at 10, 100 and 1000 stages (72, 612 and 6,012
//! coordinates) by this crate's build script: the scenes of the growth benchmark
//! (`cargo bench -p mechgen-growth`), which times a step at each size and fits how its cost grows,
//! and of the test that solves the largest on a default thread stack.
//!
//! Each module holds one generated `ScissorLift`; [`geometry`] has the closed form.

#[path = "../../scissor/src/geometry.rs"]
pub mod geometry;

/// The 10-stage lift (24 bodies, 72 coordinates).
pub mod n10 {
    include!(concat!(env!("OUT_DIR"), "/lift_10.rs"));
}

/// The 100-stage lift (204 bodies, 612 coordinates).
pub mod n100 {
    include!(concat!(env!("OUT_DIR"), "/lift_100.rs"));
}

/// The 1000-stage lift (2,004 bodies, 6,012 coordinates).
pub mod n1000 {
    include!(concat!(env!("OUT_DIR"), "/lift_1000.rs"));
}

/// Stage counts of the generated lifts, smallest first.
pub const SIZES: [usize; 3] = [10, 100, 1000];
