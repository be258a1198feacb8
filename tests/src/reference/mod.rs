//! Reference solutions the forward-dynamics tests compare mechgen with, each independent of
//! mechgen's code: an adaptive Runge–Kutta integrator ([`ode`]) and the equations of motion of
//! the tested mechanisms written out by hand in reduced coordinates: the simple pendulum with
//! its elliptic-function solution ([`pendulum`]), the double pendulum ([`double_pendulum`]) and
//! the free seed piston-crank, with or without a spring ([`seed`]); and the generalized-α
//! method written from its papers ([`generalized_alpha`]), which the runtime's integrator
//! applies to these reduced equations.

pub mod double_pendulum;
pub mod generalized_alpha;
pub mod ode;
pub mod pendulum;
pub mod seed;
