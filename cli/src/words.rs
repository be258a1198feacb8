//! Counts and numbers as the command line writes them for people: `3 rows`, `1.4e-14`.

/// `1 row`, `3 rows`, for a count of any integer type.
pub(crate) fn count(n: impl core::fmt::Display, noun: &str) -> String {
    let n = n.to_string();
    if n == "1" {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

/// A residual for people: `0`, or two significant digits (`1.4e-14`).
pub(crate) fn readable(x: f64) -> String {
    if x == 0.0 {
        "0".to_owned()
    } else {
        format!("{x:.1e}")
    }
}
