//! Example scenes for mechgen: the seed piston-crank and a crank-rocker four-bar, declared with
//! `mechanism!`, with their closed-form solutions (the accuracy reference of every test) and the
//! plotting used by the example binaries.

pub mod accuracy;
pub mod closed_form;
pub mod demo;
pub mod plot;
pub mod report;
pub mod scenes;
