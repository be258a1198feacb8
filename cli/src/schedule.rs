//! The sample times of a run: equal steps, or listed times (`--at`, a `--times` file).

use std::path::Path;

use mechgen_runtime::sample_time;

use crate::args::{self, Times};
use crate::failure::{Failure, failed, read_failure};
use crate::words::count;

/// The sample times of a run, with a `--times` file read.
pub(crate) enum Schedule {
    /// `steps` equal steps from `t0` to `t_end` ([`sample_time`]).
    Equal { t0: f64, t_end: f64, steps: usize },
    /// Listed times, at least one, strictly increasing.
    Listed(Vec<f64>),
}

impl Schedule {
    pub(crate) fn resolve(times: &Times) -> Result<Self, Failure> {
        Ok(match times {
            &Times::Equal { t0, t_end, steps } => Schedule::Equal { t0, t_end, steps },
            Times::Listed(times) => Schedule::Listed(times.clone()),
            Times::File(path) => Schedule::Listed(read_times(path)?),
        })
    }

    /// Where the mechanism is assembled.
    pub(crate) fn start(&self) -> f64 {
        match self {
            Schedule::Equal { t0, .. } => *t0,
            Schedule::Listed(times) => times.first().copied().unwrap_or(0.0),
        }
    }

    /// The last time.
    pub(crate) fn end(&self) -> f64 {
        match self {
            Schedule::Equal { t_end, .. } => *t_end,
            Schedule::Listed(times) => times.last().copied().unwrap_or(0.0),
        }
    }

    /// The times stepped to after the start.
    pub(crate) fn after_start(&self) -> Box<dyn ExactSizeIterator<Item = f64> + '_> {
        match *self {
            Schedule::Equal { t0, t_end, steps } => {
                Box::new((1..steps + 1).map(move |k| sample_time(t0, t_end, steps, k)))
            }
            Schedule::Listed(ref times) => Box::new(times.iter().skip(1).copied()),
        }
    }

    /// For the summary line: `t = 0 to 0.02 in 360 equal steps`.
    pub(crate) fn describe(&self) -> String {
        match self {
            Schedule::Equal { t0, t_end, steps } => format!(
                "t = {} to {} in {}",
                args::time(*t0),
                args::time(*t_end),
                count(*steps, "equal step")
            ),
            Schedule::Listed(times) => format!(
                "{} from t = {} to {}",
                count(times.len(), "listed time"),
                args::time(self.start()),
                args::time(self.end())
            ),
        }
    }
}

/// The times of a `--times` file.
fn read_times(path: &Path) -> Result<Vec<f64>, Failure> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| read_failure(&name, &e))?;
    args::parse_times(&text, &name).map_err(failed)
}
