//! Magnitude scans that also reject NaN and infinite entries, run before every elimination.

/// max |x| over `values`, or `None` if any is NaN or infinite.
///
/// Four independent accumulators and plain comparisons: a single `f64::max` chain is a serial
/// dependency with NaN handling, and was most of the cost of factoring a 15 × 15 Jacobian.
pub(super) fn max_abs_if_finite(values: &[f64]) -> Option<f64> {
    let mut largest = [0.0_f64; 4];
    let mut finite = true;
    let mut chunks = values.chunks_exact(4);
    for chunk in &mut chunks {
        for (m, &x) in largest.iter_mut().zip(chunk) {
            let magnitude = x.abs();
            // `magnitude <= f64::MAX` is false exactly for NaN and infinities.
            finite &= magnitude <= f64::MAX;
            *m = if magnitude > *m { magnitude } else { *m };
        }
    }
    for &x in chunks.remainder() {
        let magnitude = x.abs();
        finite &= magnitude <= f64::MAX;
        largest[0] = if magnitude > largest[0] {
            magnitude
        } else {
            largest[0]
        };
    }
    let [a, b, c, d] = largest;
    finite.then(|| a.max(b).max(c.max(d)))
}

/// `(max |a_ij|, max_j Σ_i |a_ij|)` of the column-major n × n `values`, or `None` if any
/// entry is NaN or infinite.
///
/// One pass over four columns at a time: eight independent accumulator chains (a sum and a
/// maximum per column) instead of one serial sum per column. A NaN or infinity makes its column
/// sum non-finite, so the exact per-entry check runs only then (a column sum of finite entries
/// that overflowed is not an error; it just gives an infinite 1-norm).
#[inline(always)]
pub(super) fn max_abs_and_one_norm_if_finite(values: &[f64], n: usize) -> Option<(f64, f64)> {
    if n == 0 {
        return Some((0.0, 0.0));
    }
    let (mut largest, mut norm1, mut sums_finite) = (0.0_f64, 0.0_f64, true);
    let mut groups = values.chunks_exact(4 * n);
    for group in &mut groups {
        let (c0, rest) = group.split_at(n);
        let (c1, rest) = rest.split_at(n);
        let (c2, c3) = rest.split_at(n);
        let (mut sums, mut maxima) = ([0.0_f64; 4], [0.0_f64; 4]);
        for (((&a, &b), &c), &d) in c0.iter().zip(c1).zip(c2).zip(c3) {
            for ((sum, m), x) in sums.iter_mut().zip(maxima.iter_mut()).zip([a, b, c, d]) {
                let magnitude = x.abs();
                *sum += magnitude;
                *m = if magnitude > *m { magnitude } else { *m };
            }
        }
        for (sum, m) in sums.into_iter().zip(maxima) {
            sums_finite &= sum <= f64::MAX;
            norm1 = if sum > norm1 { sum } else { norm1 };
            largest = if m > largest { m } else { largest };
        }
    }
    for column in groups.remainder().chunks_exact(n) {
        let mut sum = 0.0;
        for &x in column {
            let magnitude = x.abs();
            sum += magnitude;
            largest = if magnitude > largest {
                magnitude
            } else {
                largest
            };
        }
        sums_finite &= sum <= f64::MAX;
        norm1 = if sum > norm1 { sum } else { norm1 };
    }
    if !sums_finite {
        max_abs_if_finite(values)?;
    }
    Some((largest, norm1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn max_abs_if_finite_handles_every_length_and_non_finite_values() {
        assert_eq!(max_abs_if_finite(&[]), Some(0.0));
        assert_eq!(max_abs_if_finite(&[-3.0]), Some(3.0));
        assert_eq!(
            max_abs_if_finite(&[1.0, -2.0, 0.5, 4.0, -7.5, 0.0]),
            Some(7.5)
        );
        assert_eq!(max_abs_if_finite(&[1.0, f64::NAN, 0.5, 4.0, 2.0]), None);
        assert_eq!(
            max_abs_if_finite(&[1.0, 2.0, 3.0, 4.0, f64::NEG_INFINITY]),
            None
        );
    }
}
