//! Reads the figures of the last `cargo bench -p mechgen-benches --bench kinematics` run, so
//! the report can print them beside its own: the benchmarks time the same calls (Φ+Φ_q, one
//! step at the reference setting) for the same methods.
//!
//! Two figures per benchmark: criterion's median, and its fastest sample (each of criterion's
//! samples times a batch of iterations; the fastest batch is the figure comparable to the
//! report's, which keeps the fastest stretches of its runs). On a machine whose speed varies,
//! the median mixes fast and slow spells and runs higher.
//!
//! Best effort by design: without a benchmark run (or with criterion's file layout changed) the
//! report simply shows no criterion figures. `estimates.json` and `sample.json` are read by
//! string search, which avoids a JSON dependency.

use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// One criterion benchmark's figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Median time per iteration, seconds.
    pub seconds: f64,
    /// Time per iteration of the fastest sample, seconds (`None` without `sample.json`).
    pub fastest: Option<f64>,
    /// When criterion wrote it.
    pub written: Option<SystemTime>,
}

/// Criterion's output directory: `$CARGO_TARGET_DIR/criterion`, else `target/criterion` at the
/// workspace root.
pub fn directory() -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| super::workspace_root().join("target"));
    target.join("criterion")
}

/// The benchmark group of a scene and method, as `benches/kinematics.rs` names it.
pub fn group(scene: &str, method: super::Method) -> String {
    format!("{scene}/{}", method.slug())
}

/// The last estimate of `function` in `group`, if criterion left one in `directory`.
pub fn read(directory: &Path, group: &str, function: &str) -> Option<Estimate> {
    let run = directory
        .join(safe_name(group))
        .join(safe_name(function))
        .join("new");
    let path = run.join("estimates.json");
    let text = std::fs::read_to_string(&path).ok()?;
    let nanoseconds = point_estimate(&text, "median")?;
    let written = std::fs::metadata(&path).and_then(|m| m.modified()).ok();
    let fastest = std::fs::read_to_string(run.join("sample.json"))
        .ok()
        .and_then(|samples| fastest_sample(&samples));
    Some(Estimate {
        seconds: nanoseconds * 1e-9,
        fastest: fastest.map(|ns| ns * 1e-9),
        written,
    })
}

/// `{"iters":[…],"times":[…]}` → the smallest times[i] / iters[i] (ns), if any is valid.
fn fastest_sample(json: &str) -> Option<f64> {
    let iters = number_array(json, "iters")?;
    let times = number_array(json, "times")?;
    iters
        .iter()
        .zip(&times)
        .filter(|(n, t)| **n > 0.0 && t.is_finite() && **t > 0.0)
        .map(|(n, t)| t / n)
        .min_by(f64::total_cmp)
}

/// The numbers of `"key":[a,b,…]`; `None` if absent or malformed.
fn number_array(json: &str, key: &str) -> Option<Vec<f64>> {
    let start = json.find(&format!("\"{key}\":["))? + key.len() + 4;
    let rest = &json[start..];
    let end = rest.find(']')?;
    rest[..end]
        .split(',')
        .map(|v| v.trim().parse::<f64>().ok())
        .collect()
}

/// Criterion's directory name for an id: characters unsafe in file names become `_`.
fn safe_name(id: &str) -> String {
    id.chars()
        .map(|c| match c {
            '?' | '"' | '/' | '\\' | '*' | '<' | '>' | ':' | '|' | '^' => '_',
            c => c,
        })
        .collect()
}

/// `"<statistic>":{… "point_estimate":X …}` → X (finite and positive only).
fn point_estimate(json: &str, statistic: &str) -> Option<f64> {
    let start = json.find(&format!("\"{statistic}\""))?;
    let rest = &json[start..];
    let key = "\"point_estimate\":";
    let value = &rest[rest.find(key)? + key.len()..];
    let end = value
        .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '-' | '+')))
        .unwrap_or(value.len());
    let number: f64 = value[..end].trim().parse().ok()?;
    (number.is_finite() && number > 0.0).then_some(number)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_median_point_estimate() {
        let json = r#"{"mean":{"confidence_interval":{"confidence_level":0.95,"lower_bound":1.0,"upper_bound":3.0},"point_estimate":2.0,"standard_error":0.1},"median":{"confidence_interval":{"confidence_level":0.95,"lower_bound":1.5,"upper_bound":1.9},"point_estimate":1.75e1,"standard_error":0.1}}"#;
        assert_eq!(point_estimate(json, "median"), Some(17.5));
        assert_eq!(point_estimate(json, "slope"), None);
        assert_eq!(
            point_estimate("{\"median\":{\"point_estimate\":NaN}}", "median"),
            None
        );
        assert_eq!(safe_name("seed/generated"), "seed_generated");
        let samples =
            r#"{"sampling_mode":"Linear","iters":[10.0,20.0,0.0],"times":[50.0,80.0,1.0]}"#;
        assert_eq!(fastest_sample(samples), Some(4.0));
        assert_eq!(fastest_sample(r#"{"iters":[1.0],"times":[x]}"#), None);
        assert_eq!(fastest_sample("{}"), None);
        assert!(read(Path::new("/nonexistent"), "a", "b").is_none());
    }
}
