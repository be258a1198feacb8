//! Unit scaling: the scene's length scale rounded to a power of two, and distances between
//! configurations measured in scene lengths and radians.

use nalgebra::DefaultAllocator;

use super::api::Solver;

use crate::mechanism::{LengthScale, Storage, Unit, Vector};
use crate::structure::{Stage, Structured};

impl<M: Structured> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// ‖D_c⁻¹ (a − b)‖∞: how far apart two configurations are, in scene lengths and radians
    /// (with the length scale of the last solve).
    pub fn scaled_distance(&self, a: &Vector<M::Dim>, b: &Vector<M::Dim>) -> f64 {
        self.distance_over(a, b, 0..a.len().min(b.len()))
    }

    /// [`Solver::scaled_distance`] from `prediction` to `previous` and to `solved` (the
    /// motion predicted and the correction Newton made), over the coordinates of the Newton
    /// blocks only: those on which a solve can choose a branch (explicit assignments have one
    /// solution), so where a jump to another branch shows; and the largest predicted turn of
    /// a block angle (radians).
    pub(crate) fn block_distances(
        &self,
        previous: &Vector<M::Dim>,
        prediction: &Vector<M::Dim>,
        solved: &Vector<M::Dim>,
    ) -> (f64, f64, f64) {
        let m = &self.mechanism;
        let (previous, prediction, solved) = (
            previous.as_slice(),
            prediction.as_slice(),
            solved.as_slice(),
        );
        let (mut motion, mut correction, mut turn) = (0.0, 0.0, 0.0);
        for s in 0..m.stage_count() {
            let Some(Stage::Block(block)) = m.stage(s) else {
                continue;
            };
            for &j in block.coordinates {
                let (Some(x), Some(p), Some(s)) =
                    (prediction.get(j), previous.get(j), solved.get(j))
                else {
                    continue;
                };
                let unit = m.coordinate_unit(j);
                let moved = ((x - p) * self.length.inverse_of(unit)).abs();
                motion = larger(motion, moved);
                if unit == Unit::Angle {
                    turn = larger(turn, moved);
                }
                correction = larger(correction, ((x - s) * self.length.inverse_of(unit)).abs());
            }
        }
        (motion, correction, turn)
    }

    fn distance_over(
        &self,
        a: &Vector<M::Dim>,
        b: &Vector<M::Dim>,
        coordinates: impl Iterator<Item = usize>,
    ) -> f64 {
        let m = &self.mechanism;
        let (a, b) = (a.as_slice(), b.as_slice());
        coordinates.fold(0.0, |largest, j| {
            let (Some(x), Some(y)) = (a.get(j), b.get(j)) else {
                return largest;
            };
            let power = self.length.inverse_of(m.coordinate_unit(j));
            larger(largest, ((x - y) * power).abs())
        })
    }

    /// The scene's length scale from the current parameters, rounded to a power of two so that
    /// scaling adds no rounding error (1 with unit scaling off).
    pub(super) fn update_scale(&mut self) {
        let length = if self.options.scale_units {
            power_of_two(self.mechanism.length_scale())
        } else {
            1.0
        };
        // The same as the last solve's but after a change of parameters or options.
        if length != self.length.of(Unit::Length) {
            self.length = LengthScale::new(length);
        }
    }
}

/// The power of two nearest below `length` (1 for zero, subnormal or non-finite lengths, or
/// ones so extreme that their square would overflow the scaled equations).
fn power_of_two(length: f64) -> f64 {
    let length = length.abs();
    if !(1e-100..=1e100).contains(&length) {
        return 1.0;
    }
    // Clearing the mantissa of a normal positive float leaves its power of two.
    f64::from_bits(length.to_bits() & 0xfff0_0000_0000_0000)
}

/// The larger of two distances, NaN winning.
fn larger(largest: f64, d: f64) -> f64 {
    if d > largest || d.is_nan() {
        d
    } else {
        largest
    }
}
