//! Hand-written mechanisms with closed-form motion, which the integration tests solve through
//! the runtime's public API: a driven pendulum (the smallest scene, with forces) and a
//! slider-crank; and scenes with free degrees of freedom for the integrator (a pendulum, two
//! sliders on springs, a pendulum on a driven cart, a double pendulum, the slider-crank with
//! its crank free), presented through `Scene`.
// Not every test binary uses every fixture.
#![allow(dead_code)]

/// The `Mechanism` methods of a fixture without parameters or markers (declared before the
/// fixtures' modules, which use it inside their `impl Mechanism`).
macro_rules! no_parameters_or_markers {
    () => {
        fn marker_storage(&self) -> [f64; 0] {
            []
        }
        fn parameter_count(&self) -> usize {
            0
        }
        fn parameter_name(&self, _: usize) -> Option<&str> {
            None
        }
        fn parameter(&self, _: usize) -> Option<f64> {
            None
        }
        fn set_parameter<'a>(
            &'a mut self,
            name: &'a str,
            _: f64,
        ) -> Result<(), mechgen_runtime::ParameterError<'a>> {
            Err(mechgen_runtime::ParameterError::Unknown {
                name,
                declared: &[] as &[&str; 0],
            })
        }
    };
}

pub mod cart_pendulum;
pub mod double_pendulum;
pub mod free_pendulum;
pub mod free_slider_crank;
pub mod pendulum;
pub mod scene;
pub mod slider_crank;
pub mod sliders;
