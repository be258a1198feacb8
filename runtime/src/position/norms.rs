//! The norms a block's solve measures residuals and steps with, in scene units.

/// (‖D_r v‖₂, ‖D_r v‖∞).
#[inline]
pub(crate) fn scaled_norms(v: &[f64], rows: &[f64]) -> (f64, f64) {
    let (mut sum, mut max) = (0.0_f64, 0.0_f64);
    for (x, r) in v.iter().zip(rows) {
        let y = x * r;
        sum += y * y;
        max = max.max(y.abs());
    }
    (libm::sqrt(sum), max)
}

/// ‖D_c⁻¹ v‖∞: a step or a position in scene lengths and radians; a NaN entry makes it NaN, so
/// that callers see a non-finite step rather than a small one.
#[inline]
pub(crate) fn scaled_max(v: &[f64], inverse_cols: &[f64]) -> f64 {
    scaled_max_iter(v.iter().copied(), inverse_cols)
}

pub(super) fn scaled_max_iter(v: impl Iterator<Item = f64>, inverse_cols: &[f64]) -> f64 {
    v.zip(inverse_cols).fold(0.0, |m, (x, c)| {
        let y = (x * c).abs();
        if y > m || y.is_nan() { y } else { m }
    })
}

/// ‖v‖∞.
#[inline]
pub(crate) fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}
