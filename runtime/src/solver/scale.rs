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

    /// How far `solved` moved from `previous` on the coordinates of the Newton blocks only
    /// ([`Solver::scaled_distance`] over them): those on which a solve can choose a branch
    /// (explicit assignments have one solution), so where a jump to another branch shows.
    pub(crate) fn block_motion(&self, previous: &Vector<M::Dim>, solved: &Vector<M::Dim>) -> f64 {
        let (previous, solved) = (previous.as_slice(), solved.as_slice());
        let mut motion = 0.0;
        self.visit_block_coordinates(|j, inverse_scale, _| {
            if let (Some(p), Some(s)) = (previous.get(j), solved.get(j)) {
                motion = larger(motion, ((s - p) * inverse_scale).abs());
            }
        });
        motion
    }

    /// Calls `visit(j, L⁻ᵖ, angle)` for each coordinate `j` of the Newton blocks, in solve
    /// order, with the factor that measures it in scene lengths or radians (at the length scale
    /// of the last solve) and whether it is an angle.
    #[inline]
    pub(crate) fn visit_block_coordinates(&self, mut visit: impl FnMut(usize, f64, bool)) {
        let m = &self.mechanism;
        for s in 0..m.stage_count() {
            let Some(Stage::Block(block)) = m.stage(s) else {
                continue;
            };
            for &j in block.coordinates {
                let unit = m.coordinate_unit(j);
                visit(j, self.length.inverse_of(unit), unit == Unit::Angle);
            }
        }
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
pub(crate) fn larger(largest: f64, d: f64) -> f64 {
    if d > largest || d.is_nan() {
        d
    } else {
        largest
    }
}
