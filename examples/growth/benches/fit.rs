//! The growth exponent both growth benchmarks print: the least-squares slope p of
//! log(time) over log(N), time ∝ Nᵖ.

/// The slope through `points` of (N, time), at least two with distinct N.
pub fn exponent(points: &[(f64, f64)]) -> f64 {
    let logs: Vec<(f64, f64)> = points.iter().map(|(n, t)| (n.ln(), t.ln())).collect();
    let mean_x = logs.iter().map(|p| p.0).sum::<f64>() / logs.len() as f64;
    let mean_y = logs.iter().map(|p| p.1).sum::<f64>() / logs.len() as f64;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (x, y) in &logs {
        sxy += (x - mean_x) * (y - mean_y);
        sxx += (x - mean_x) * (x - mean_x);
    }
    sxy / sxx
}
