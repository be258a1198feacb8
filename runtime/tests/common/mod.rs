//! Hand-written mechanisms with closed-form motion, which the integration tests solve through
//! the runtime's public API: a driven pendulum (the smallest scene, with forces) and a
//! slider-crank.
// Not every test binary uses every fixture.
#![allow(dead_code)]

pub mod pendulum;
pub mod slider_crank;
