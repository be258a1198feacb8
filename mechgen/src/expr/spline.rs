//! Natural cubic splines: the motion law `spline(x, (x0, y0), (x1, y1), …)`.
//!
//! A natural spline is C² (so a driver written with it has a continuous acceleration and γ
//! exists), has zero second derivative at its end knots, and continues linearly beyond them,
//! which keeps it C² everywhere. It is linear in its values: a spline whose values depend on
//! parameters is written as a sum of cardinal splines (through 1 at one knot and 0 at the
//! others) weighted by those values, each a constant table, so parameters stay run-time fields.
//!
//! A table holds the knots and, per segment, the cubic's coefficients in the distance from the
//! segment's base: segment 0 extrapolates left of the first knot (based at it), segment k
//! spans knots k − 1 … k, the last extrapolates right of the last knot. The runtime evaluates
//! the same layout (`mechgen_runtime::codegen::math::Spline`); generated code emits the table as a
//! constant.

/// A natural cubic spline as a table; see the module documentation.
#[derive(Debug, Clone, PartialEq)]
pub struct SplineTable {
    /// The knots, strictly increasing (at least two).
    pub knots: Vec<f64>,
    /// Per segment (`knots.len() + 1` of them), `[a, b, c, d]` of
    /// `a + b u + c u² + d u³`, `u` the distance from the segment's base knot.
    pub segments: Vec<[f64; 4]>,
}

impl SplineTable {
    /// The natural cubic spline through `(knots[i], values[i])`.
    ///
    /// # Errors
    /// Fewer than two knots, different lengths, non-finite numbers, or knots not strictly
    /// increasing: a message saying which.
    pub fn natural(knots: &[f64], values: &[f64]) -> Result<Self, String> {
        let n = knots.len();
        if n < 2 || values.len() != n {
            return Err("a spline needs at least two points `(x, y)`".to_owned());
        }
        if knots.iter().chain(values).any(|v| !v.is_finite()) {
            return Err("a spline's points must be finite numbers".to_owned());
        }
        if let Some(k) = (1..n).find(|&k| knots[k] <= knots[k - 1]) {
            return Err(format!(
                "a spline's x values must increase strictly: {} follows {}",
                knots[k],
                knots[k - 1]
            ));
        }
        let h: Vec<f64> = knots.windows(2).map(|w| w[1] - w[0]).collect();
        let slope: Vec<f64> = (0..n - 1)
            .map(|i| (values[i + 1] - values[i]) / h[i])
            .collect();
        // Second derivatives m, zero at both ends: the tridiagonal system of the inner knots,
        // by the Thomas algorithm (diagonally dominant: no pivoting needed).
        let mut m = vec![0.0; n];
        if n > 2 {
            let inner = n - 2;
            let (mut diagonal, mut rhs) = (vec![0.0; inner], vec![0.0; inner]);
            for i in 0..inner {
                diagonal[i] = 2.0 * (h[i] + h[i + 1]);
                rhs[i] = 6.0 * (slope[i + 1] - slope[i]);
            }
            for i in 1..inner {
                let factor = h[i] / diagonal[i - 1];
                diagonal[i] -= factor * h[i];
                rhs[i] -= factor * rhs[i - 1];
            }
            m[inner] = rhs[inner - 1] / diagonal[inner - 1];
            for i in (0..inner - 1).rev() {
                m[i + 1] = (rhs[i] - h[i + 1] * m[i + 2]) / diagonal[i];
            }
        }
        let mut segments = Vec::with_capacity(n + 1);
        let first_slope = slope[0] - h[0] * (2.0 * m[0] + m[1]) / 6.0;
        segments.push([values[0], first_slope, 0.0, 0.0]);
        for i in 0..n - 1 {
            segments.push([
                values[i],
                slope[i] - h[i] * (2.0 * m[i] + m[i + 1]) / 6.0,
                m[i] / 2.0,
                (m[i + 1] - m[i]) / (6.0 * h[i]),
            ]);
        }
        let last = segments[n - 1];
        let u = h[n - 2];
        let end_slope = last[1] + u * (2.0 * last[2] + 3.0 * last[3] * u);
        segments.push([values[n - 1], end_slope, 0.0, 0.0]);
        Ok(SplineTable {
            knots: knots.to_vec(),
            segments,
        })
    }

    /// The spline's derivative of `order` (0 its value; 3 and above as the piecewise-constant
    /// third derivative, 0 beyond) at `x`; NaN for a NaN `x`.
    pub fn eval(&self, x: f64, order: u8) -> f64 {
        let k = self.knots.partition_point(|&knot| knot <= x);
        let base = self.knots[k.max(1) - 1];
        let [a, b, c, d] = self.segments[k];
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_is_c2_and_continues_linearly() {
        let knots = [0.0, 0.5, 1.2, 2.0, 3.0];
        let values = [0.0, 1.0, -0.5, 0.3, 2.0];
        let s = SplineTable::natural(&knots, &values).expect("valid");
        for (&x, &y) in knots.iter().zip(&values) {
            assert!((s.eval(x, 0) - y).abs() < 1e-15, "{x}");
        }
        // Value, slope and curvature continuous at every knot.
        for &x in &knots {
            for order in 0..3 {
                let (left, right) = (s.eval(x - 1e-12, order), s.eval(x, order));
                assert!((left - right).abs() < 1e-9, "order {order} at {x}");
            }
        }
        // Natural ends, linear beyond them.
        assert!(s.eval(0.0, 2).abs() < 1e-12 && s.eval(3.0, 2).abs() < 1e-12);
        assert_eq!(s.eval(-1.0, 2), 0.0);
        let slope = s.eval(3.0, 1);
        assert!((s.eval(4.0, 0) - (2.0 + slope)).abs() < 1e-12);
        assert!(s.eval(f64::NAN, 0).is_nan());
    }

    #[test]
    fn reproduces_lines_and_refuses_bad_points() {
        let s = SplineTable::natural(&[1.0, 2.0, 4.0], &[3.0, 5.0, 9.0]).expect("valid");
        for x in [-3.0, 1.5, 3.0, 7.0] {
            assert!((s.eval(x, 0) - (1.0 + 2.0 * x)).abs() < 1e-13);
            assert!((s.eval(x, 1) - 2.0).abs() < 1e-13);
        }
        assert!(SplineTable::natural(&[0.0], &[1.0]).is_err());
        assert!(SplineTable::natural(&[0.0, 0.0], &[1.0, 2.0]).is_err());
        assert!(SplineTable::natural(&[0.0, f64::NAN], &[1.0, 2.0]).is_err());
    }
}
