//! The elementary functions generated code calls: `libm`, so that it needs no `std`.
//!
//! Generated code uses these through absolute paths (`::mechgen_runtime::codegen::math::sin`), never
//! `f64::sin`, which is unavailable in `no_std` builds.

/// Sine.
#[inline]
pub fn sin(x: f64) -> f64 {
    libm::sin(x)
}

/// Cosine.
#[inline]
pub fn cos(x: f64) -> f64 {
    libm::cos(x)
}

/// Sine and cosine of one argument, sharing its reduction: bit for bit `(sin(x), cos(x))`, for
/// less than half their cost.
#[inline]
pub fn sincos(x: f64) -> (f64, f64) {
    libm::sincos(x)
}

/// Tangent.
#[inline]
pub fn tan(x: f64) -> f64 {
    libm::tan(x)
}

/// Natural exponential.
#[inline]
pub fn exp(x: f64) -> f64 {
    libm::exp(x)
}

/// Natural logarithm.
#[inline]
pub fn ln(x: f64) -> f64 {
    libm::log(x)
}

/// Square root.
#[inline]
pub fn sqrt(x: f64) -> f64 {
    libm::sqrt(x)
}

/// Arcsine, in [−π/2, π/2] (NaN beyond ±1).
#[inline]
pub fn asin(x: f64) -> f64 {
    libm::asin(x)
}

/// Arccosine, in [0, π] (NaN beyond ±1).
#[inline]
pub fn acos(x: f64) -> f64 {
    libm::acos(x)
}

/// The angle of the vector `(x, y)`, in (−π, π].
#[inline]
pub fn atan2(y: f64, x: f64) -> f64 {
    libm::atan2(y, x)
}

/// `x` raised to a real power (NaN for a negative `x` and a non-integer `y`).
#[inline]
pub fn pow(x: f64, y: f64) -> f64 {
    libm::pow(x, y)
}

/// `if a <= b { x } else { y }`, and NaN when `a` or `b` is NaN (never a silent choice): what
/// `min`, `max`, `abs` and the clamped motion laws (`cycloidal`, `poly345`) compile to.
#[inline]
pub fn select(a: f64, b: f64, x: f64, y: f64) -> f64 {
    if a <= b {
        x
    } else if b < a {
        y
    } else {
        a + b
    }
}

/// A natural cubic spline as generated code stores it: the knots, and per segment the cubic's
/// coefficients `[a, b, c, d]` of `a + b u + c u² + d u³` in the distance `u` from the
/// segment's base knot. Segment 0 extrapolates left of the first knot (linearly), segment k
/// spans knots k − 1 … k, the last extrapolates right of the last knot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spline<'a> {
    /// Strictly increasing knots (at least two).
    pub knots: &'a [f64],
    /// `knots.len() + 1` segments.
    pub segments: &'a [[f64; 4]],
}

impl Spline<'_> {
    /// The derivative of `order` (0: the value) at `x`; NaN for a NaN `x` or a malformed
    /// table.
    pub fn eval(&self, x: f64, order: u8) -> f64 {
        let k = self.knots.partition_point(|&knot| knot <= x);
        let (Some(&base), Some(&[a, b, c, d])) =
            (self.knots.get(k.max(1) - 1), self.segments.get(k))
        else {
            return f64::NAN;
        };
        let u = x - base;
        match order {
            0 => a + u * (b + u * (c + u * d)),
            1 => b + u * (2.0 * c + u * (3.0 * d)),
            2 => 2.0 * c + u * (6.0 * d),
            3 => 6.0 * d + u * 0.0,
            _ => u * 0.0,
        }
    }
}

/// `x` raised to an integer power (repeated multiplication, exact for small exponents).
#[inline]
pub fn powi(x: f64, n: i32) -> f64 {
    let mut base = if n < 0 { 1.0 / x } else { x };
    let mut e = n.unsigned_abs();
    let mut acc = 1.0;
    while e > 0 {
        if e & 1 == 1 {
            acc *= base;
        }
        base *= base;
        e >>= 1;
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn select_chooses_and_never_hides_a_nan() {
        assert_eq!(select(1.0, 2.0, 10.0, 20.0), 10.0);
        assert_eq!(select(2.0, 2.0, 10.0, 20.0), 10.0);
        assert_eq!(select(3.0, 2.0, 10.0, 20.0), 20.0);
        assert!(select(f64::NAN, 2.0, 10.0, 20.0).is_nan());
        assert!(select(1.0, f64::NAN, 10.0, 20.0).is_nan());
    }

    #[test]
    fn splines_evaluate_segments_and_refuse_malformed_tables() {
        // The line y = 1 + 2x as a two-knot natural spline.
        let spline = Spline {
            knots: &[0.0, 1.0],
            segments: &[
                [1.0, 2.0, 0.0, 0.0],
                [1.0, 2.0, 0.0, 0.0],
                [3.0, 2.0, 0.0, 0.0],
            ],
        };
        for x in [-1.0, 0.0, 0.5, 1.0, 4.0] {
            assert_eq!(spline.eval(x, 0), 1.0 + 2.0 * x);
            assert_eq!(spline.eval(x, 1), 2.0);
        }
        let broken = Spline {
            knots: &[0.0, 1.0],
            segments: &[],
        };
        assert!(broken.eval(0.5, 0).is_nan());
    }

    #[test]
    fn sincos_is_sin_and_cos_to_the_bit() {
        let mut x = -1e3_f64;
        while x < 1e3 {
            let (s, c) = sincos(x);
            assert_eq!(
                (s.to_bits(), c.to_bits()),
                (sin(x).to_bits(), cos(x).to_bits()),
                "{x}"
            );
            x += 0.137;
        }
    }

    #[test]
    fn powi_matches_repeated_multiplication() {
        assert_eq!(powi(3.0, 0), 1.0);
        assert_eq!(powi(3.0, 1), 3.0);
        assert_eq!(powi(3.0, 4), 81.0);
        assert_eq!(powi(2.0, -2), 0.25);
        assert_eq!(powi(-2.0, 3), -8.0);
    }
}
