//! Example scenes for mechgen (the seed piston-crank, a crank-rocker four-bar and a
//! positions-only offset slider), declared with `mechanism!`, with their closed-form solutions
//! (the accuracy reference of every test), the plotting and driver code of the example binaries,
//! and the accuracy-against-run-time report (`report`).

pub mod accuracy;
pub mod closed_form;
pub mod demo;
pub mod plot;
pub mod report;
pub mod scenes;
pub mod stability;
