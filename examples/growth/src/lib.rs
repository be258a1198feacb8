//! The scissor lift of `mechgen-scissor` generated at 10, 100 and 1000 stages (72, 612 and 6,012
//! coordinates) by this crate's build script: the scenes of the growth benchmark
//! (`cargo bench -p mechgen-growth`), which times a step at each size and fits how its cost grows,
//! and of the test that solves the largest on a default thread stack.
//!
//! Each module holds one generated `ScissorLift`; [`geometry`] has the closed form. With the
//! `dynamics` feature, `falling` holds the same sizes with masses on every body and the bottom
//! link's angle free (`FallingScissorLift`, written from `falling.rs`): the scenes of the growth
//! benchmark of forward dynamics.

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

/// The lift with masses on every body (links 2 kg, platform 20 kg, slider and roller 0.5 kg),
/// its bottom link's angle free, released from rest at α0 under gravity: one `FallingScissorLift`
/// per size of [`SIZES`].
#[cfg(feature = "dynamics")]
pub mod falling {
    /// The 10-stage falling lift (72 coordinates).
    pub mod n10 {
        include!(concat!(env!("OUT_DIR"), "/falling_lift_10.rs"));
    }

    /// The 100-stage falling lift (612 coordinates).
    pub mod n100 {
        include!(concat!(env!("OUT_DIR"), "/falling_lift_100.rs"));
    }

    /// The 1000-stage falling lift (6,012 coordinates).
    pub mod n1000 {
        include!(concat!(env!("OUT_DIR"), "/falling_lift_1000.rs"));
    }
}
