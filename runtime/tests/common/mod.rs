//! Hand-written mechanisms with closed-form motion, which the integration tests solve through
//! the runtime's public API: a driven pendulum (the smallest scene, with forces) and a
//! slider-crank; and scenes with free degrees of freedom for the integrator (a pendulum, two
//! sliders on springs, a pendulum on a driven cart, a double pendulum, the slider-crank with
//! its crank free), presented through `Scene`.
// Not every test binary uses every fixture.
#![allow(dead_code)]

pub mod cart_pendulum;
pub mod double_pendulum;
pub mod free_pendulum;
pub mod free_slider_crank;
pub mod pendulum;
pub mod scene;
pub mod slider_crank;
pub mod sliders;
