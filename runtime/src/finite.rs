//! Finiteness checks and the `NonFinite` error they give, shared by the solver, the block
//! Newton iteration and the force solve.

use nalgebra::{DefaultAllocator, Dim};

use crate::error::{Quantity, SolveError};
use crate::mechanism::{Storage, Vector};
use crate::names::Names;

/// A non-finite `quantity` that no single equation produced (an input, a step).
pub(crate) fn non_finite(time: f64, quantity: Quantity) -> SolveError {
    SolveError::NonFinite {
        time,
        quantity,
        equation: None,
        names: &Names::NONE,
    }
}

pub(crate) fn check_finite<D: Dim>(
    v: &Vector<D>,
    t: f64,
    quantity: Quantity,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<D>,
{
    check_slice(v.as_slice(), t, quantity)
}

#[inline]
pub(crate) fn check_slice(v: &[f64], t: f64, quantity: Quantity) -> Result<(), SolveError> {
    if all_finite(v) {
        Ok(())
    } else {
        Err(non_finite(t, quantity))
    }
}

/// Whether every entry is finite, without a branch per entry and without floating-point
/// arithmetic: adding one to the exponent field carries into the sign bit exactly when the
/// exponent is all ones (infinite or NaN). Integer AND, ADD and OR vectorise on the host as the
/// floating-point test `x · 0` did, and on a controller without a double-precision FPU they
/// are a few instructions where `x · 0` was two soft-float calls.
#[inline]
pub(crate) fn all_finite(v: &[f64]) -> bool {
    const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
    const EXPONENT_ONE: u64 = 1 << 52;
    let carried = v
        .iter()
        .fold(0, |acc, x| acc | ((x.to_bits() & EXPONENT) + EXPONENT_ONE));
    carried >> 63 == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_finite_finds_any_infinite_or_nan_entry() {
        for n in 0..=9 {
            let mut storage = [1.5; 9];
            let v = &mut storage[..n];
            assert!(all_finite(v));
            for k in 0..n {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    v[k] = bad;
                    assert!(!all_finite(v), "{bad} at {k} of {n}");
                }
                v[k] = -f64::MAX;
            }
            assert!(all_finite(v));
        }
        // The extremes of the finite range, either sign, subnormal and zero, are finite.
        let extremes = [
            f64::MAX,
            -f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            -5e-324,
            -0.0,
        ];
        assert!(all_finite(&extremes));
    }
}
