//! Example scenes for mechgen (the seed piston-crank, the same with its mass properties, a
//! crank-rocker four-bar and a positions-only offset slider), declared with `mechanism!`, with
//! their closed-form solutions and the seed's closed-form inverse dynamics (the accuracy
//! reference of every test), the free seed's reduced-coordinate reference motion (`free_seed`),
//! the plotting and driver code of the example binaries, and the accuracy-against-run-time
//! report (`report`).

pub mod accuracy;
pub mod closed_form;
pub mod demo;
pub mod free_seed;
pub mod inverse_dynamics;
pub mod plot;
pub mod report;
pub mod scenes;
pub mod stability;
pub mod written_out;
