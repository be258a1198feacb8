//! What double precision can resolve, checked on the scene's constant geometry at compile time.
//!
//! The solver works in scene lengths: it divides every length by the largest one, L (see the
//! runtime's unit scaling). Two rules follow from that, and a constant that breaks either one is
//! a compile error at its tokens:
//!
//! - **Range.** Every non-zero constant length (point coordinates in a body frame, distances,
//!   ground positions) lies within [`MIN_LENGTH`, `MAX_LENGTH`] in magnitude. Squares and
//!   products of lengths (a distance joint's |d|² − L², a rotated offset) then stay normal
//!   doubles, far from overflow and underflow.
//! - **Resolution.** No non-zero length is smaller than [`RESOLUTION`] × L. Positions are
//!   computed to about ε·L (ε = 2.2e-16) at best, so a length below 1e-12 of the largest carries
//!   under three significant digits. A pin at 1e20 mm on a 43 mm crank loses the crank entirely,
//!   and the solver would report round-off of the large length as a solution.
//!
//! Angles that only enter through their sine and cosine (a ground body's pose, a `near` guess)
//! are reduced to (−π, π] when they exceed a half turn ([`reduce_angle`]). Ground poses of
//! −1e20 rad and guesses of 1e12 rad are therefore the angles they mean, not coordinates too
//! large to resolve.
//!
//! A constant expression that folds to NaN or infinity (`sqrt(0 - 1)`, `ln(0)`, an overflow)
//! is reported where it is written (see `check`). Parameter-dependent geometry is only known at
//! run time, and the runtime reports it as a typed error.

use proc_macro2::Span;

use crate::error::Errors;

/// Largest magnitude of a constant length.
pub const MAX_LENGTH: f64 = 1e100;
/// Smallest magnitude of a non-zero constant length.
pub const MIN_LENGTH: f64 = 1e-100;
/// Smallest non-zero length, relative to the scene's largest.
pub const RESOLUTION: f64 = 1e-12;

/// The scene's constant lengths, with where they were written.
#[derive(Default)]
pub struct Lengths(Vec<(f64, Span)>);

impl Lengths {
    /// Records a constant length.
    pub fn record(&mut self, value: f64, span: Span) {
        self.0.push((value, span));
    }

    /// Checks the range and resolution rules (module docs), pushing one error per length out
    /// of range and one at the largest length when the smallest cannot be resolved beside it.
    pub fn check(&self, errors: &mut Errors) {
        for &(value, span) in &self.0 {
            let magnitude = value.abs();
            if magnitude > MAX_LENGTH || (magnitude > 0.0 && magnitude < MIN_LENGTH) {
                errors.push(
                    span,
                    format!(
                        "length {value:e} is out of the range mechgen resolves: non-zero lengths \
                         must lie between {MIN_LENGTH:e} and {MAX_LENGTH:e} in magnitude; \
                         choose a unit in which the scene's lengths are moderate numbers"
                    ),
                );
            }
        }
        let in_range = || {
            self.0
                .iter()
                .filter(|(v, _)| v.abs() > 0.0 && v.abs() <= MAX_LENGTH && v.abs() >= MIN_LENGTH)
        };
        let largest = in_range().max_by(|a, b| a.0.abs().total_cmp(&b.0.abs()));
        let smallest = in_range().min_by(|a, b| a.0.abs().total_cmp(&b.0.abs()));
        if let (Some(&(large, span)), Some(&(small, _))) = (largest, smallest)
            && small.abs() < RESOLUTION * large.abs()
        {
            errors.push(
                span,
                format!(
                    "this length ({large:e}) is more than {:e} times the scene's smallest \
                     non-zero length ({small:e}): double precision cannot resolve both in one \
                     scene (positions are computed to about 2e-16 of the largest length); \
                     check the value for a typo, or write a negligible length as 0",
                    1.0 / RESOLUTION
                ),
            );
        }
    }
}

/// `angle` reduced to (−π, π] when it exceeds a half turn (exactly, through its sine and
/// cosine, whose argument reduction is exact); smaller angles are kept as written.
pub fn reduce_angle(angle: f64) -> f64 {
    if angle.abs() <= std::f64::consts::PI {
        angle
    } else {
        angle.sin().atan2(angle.cos())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn messages(values: &[f64]) -> Vec<String> {
        let mut lengths = Lengths::default();
        for &v in values {
            lengths.record(v, Span::call_site());
        }
        let mut errors = Errors::default();
        lengths.check(&mut errors);
        errors.messages()
    }

    #[test]
    fn moderate_scenes_pass_and_extreme_ones_are_named() {
        assert!(messages(&[156.8, 41.3, 0.0, -28.0, 1e-6]).is_empty());
        let far = messages(&[1e20, 43.0]);
        assert_eq!(far.len(), 1);
        assert!(
            far[0].contains("1e20") && far[0].contains("4.3e1"),
            "{far:?}"
        );
        let huge = messages(&[1e150, 1e149]);
        assert_eq!(huge.len(), 2, "{huge:?}");
        assert!(huge[0].contains("out of the range"), "{huge:?}");
        assert_eq!(messages(&[1e-120]).len(), 1);
    }

    #[test]
    fn angles_beyond_a_half_turn_reduce_exactly() {
        assert_eq!(reduce_angle(-2.35), -2.35);
        assert_eq!(reduce_angle(std::f64::consts::PI), std::f64::consts::PI);
        let reduced = reduce_angle(-1e20);
        assert!(reduced.abs() <= std::f64::consts::PI);
        assert!((reduced.sin() - (-1e20_f64).sin()).abs() < 1e-15);
        assert!((reduced.cos() - (-1e20_f64).cos()).abs() < 1e-15);
        assert!((reduce_angle(2.0 * std::f64::consts::TAU + 1.0) - 1.0).abs() < 1e-14);
    }
}
