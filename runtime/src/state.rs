//! A solved kinematic state, per-body views of it, and heap-free CSV output.

use core::fmt::{self, Write};
use core::marker::PhantomData;

use nalgebra::{DefaultAllocator, Dim};

use crate::mechanism::{Mechanism, Storage, Vector};

/// Positions, velocities and accelerations of a mechanism at time `t`.
///
/// Typed by the mechanism (not just its dimension) so generated code can add named accessors
/// such as `state.piston()` for its own scene only.
pub struct State<M: Mechanism>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Time.
    pub t: f64,
    /// Positions q.
    pub q: Vector<M::Dim>,
    /// Velocities q̇.
    pub qd: Vector<M::Dim>,
    /// Accelerations q̈.
    pub qdd: Vector<M::Dim>,
    /// Newton updates the position solve needed.
    pub iterations: usize,
    // `fn() -> M` keeps `State` Send/Sync/Clone regardless of `M`.
    mechanism: PhantomData<fn() -> M>,
}

/// One body's pose and its first two time derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyState {
    /// Reference point x.
    pub x: f64,
    /// Reference point y.
    pub y: f64,
    /// Orientation θ (radians).
    pub theta: f64,
    /// ẋ.
    pub x_dot: f64,
    /// ẏ.
    pub y_dot: f64,
    /// θ̇.
    pub theta_dot: f64,
    /// ẍ.
    pub x_ddot: f64,
    /// ÿ.
    pub y_ddot: f64,
    /// θ̈.
    pub theta_ddot: f64,
}

impl<M: Mechanism> State<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// An all-zero state at `t = 0` (allocates for `Dyn`, lives on the stack for `Const`).
    pub fn zeros(dim: M::Dim) -> Self {
        Self {
            t: 0.0,
            q: Vector::zeros_generic(dim, nalgebra::U1),
            qd: Vector::zeros_generic(dim, nalgebra::U1),
            qdd: Vector::zeros_generic(dim, nalgebra::U1),
            iterations: 0,
            mechanism: PhantomData,
        }
    }

    /// Body `index` (declaration order), read from coordinates `3·index .. 3·index + 2`;
    /// `None` past the end.
    pub fn body(&self, index: usize) -> Option<BodyState> {
        let first = index.checked_mul(3)?;
        let at = |v: &Vector<M::Dim>, offset: usize| v.get(first.checked_add(offset)?).copied();
        Some(BodyState {
            x: at(&self.q, 0)?,
            y: at(&self.q, 1)?,
            theta: at(&self.q, 2)?,
            x_dot: at(&self.qd, 0)?,
            y_dot: at(&self.qd, 1)?,
            theta_dot: at(&self.qd, 2)?,
            x_ddot: at(&self.qdd, 0)?,
            y_ddot: at(&self.qdd, 1)?,
            theta_ddot: at(&self.qdd, 2)?,
        })
    }

    /// Writes `t, q…, q̇…, q̈…` as one CSV line ending in `\n`, matching [`write_csv_header`].
    ///
    /// Numbers use `f64`'s `Display`: the shortest string that parses back to the same value,
    /// never in exponent form. A NaN or infinity (which a successful solve never produces) is
    /// written as `NaN`/`inf`/`-inf`, which Rust's and most CSV readers' float parsers accept.
    ///
    /// # Errors
    /// Whatever `out` returns.
    pub fn write_csv_row<W: Write>(&self, out: &mut W) -> fmt::Result {
        // `{:?}` is the shortest round-trip form, with an exponent for tiny and huge values
        // (`5.2e-30`, not thirty zeros).
        write!(out, "{:?}", self.t)?;
        for value in self.q.iter().chain(&self.qd).chain(&self.qdd) {
            write!(out, ",{value:?}")?;
        }
        out.write_char('\n')
    }
}

/// Writes the CSV header line: `t`, every coordinate name, then the names with `_dot`, then
/// with `_ddot` (`t,piston.x,…,piston.x_dot,…,piston.x_ddot,…\n`).
///
/// A coordinate without a name is written as `q<index>`.
///
/// # Errors
/// Whatever `out` returns.
pub fn write_csv_header<M: Mechanism, W: Write>(mechanism: &M, out: &mut W) -> fmt::Result
where
    DefaultAllocator: Storage<M::Dim>,
{
    out.write_char('t')?;
    let n = mechanism.dim().value();
    for suffix in ["", "_dot", "_ddot"] {
        for index in 0..n {
            match mechanism.coordinate_name(index) {
                Some(name) => write!(out, ",{name}{suffix}")?,
                None => write!(out, ",q{index}{suffix}")?,
            }
        }
    }
    out.write_char('\n')
}

impl<M: Mechanism> Clone for State<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn clone(&self) -> Self {
        Self {
            t: self.t,
            q: self.q.clone(),
            qd: self.qd.clone(),
            qdd: self.qdd.clone(),
            iterations: self.iterations,
            mechanism: PhantomData,
        }
    }
}

impl<M: Mechanism> fmt::Debug for State<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("State")
            .field("t", &self.t)
            .field("q", &self.q.as_slice())
            .field("qd", &self.qd.as_slice())
            .field("qdd", &self.qdd.as_slice())
            .field("iterations", &self.iterations)
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pendulum::Pendulum;
    use std::string::String;

    fn sample() -> State<Pendulum> {
        let mut state = State::zeros(nalgebra::Const);
        state.t = 0.5;
        state.q = Vector::from([1.0, 2.0, 3.0]);
        state.qd = Vector::from([0.1, -0.0, 1e-20]);
        state.qdd = Vector::from([-1.5, 2.5, 1e20]);
        state
    }

    #[test]
    fn body_reads_three_coordinates() {
        let state = sample();
        let body = state.body(0).unwrap();
        assert_eq!((body.x, body.y, body.theta), (1.0, 2.0, 3.0));
        assert_eq!(body.theta_ddot, 1e20);
        assert_eq!(state.body(1), None);
        assert_eq!(state.body(usize::MAX), None);
    }

    #[test]
    fn csv_header_and_row_line_up_and_round_trip() {
        let mut header = String::new();
        write_csv_header(&Pendulum::default(), &mut header).unwrap();
        assert_eq!(
            header,
            "t,rod.x,rod.y,rod.theta,rod.x_dot,rod.y_dot,rod.theta_dot,\
             rod.x_ddot,rod.y_ddot,rod.theta_ddot\n"
        );

        let state = sample();
        let mut row = String::new();
        state.write_csv_row(&mut row).unwrap();
        let values: std::vec::Vec<f64> = row
            .trim_end_matches('\n')
            .split(',')
            .map(|field| field.parse().unwrap())
            .collect();
        let expected = [state.t]
            .into_iter()
            .chain(state.q.iter().copied())
            .chain(state.qd.iter().copied())
            .chain(state.qdd.iter().copied());
        assert!(values.iter().copied().eq(expected));
        assert_eq!(header.split(',').count(), values.len());
    }
}
