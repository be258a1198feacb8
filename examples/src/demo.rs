//! What the example binaries share: solve one revolution with generated code, time it, measure
//! the error against the closed form, and write the CSV and SVG outputs.

use std::error::Error;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{
    Accelerations, Mechanism, Simulation, SolveError, Solver, State, Structured, write_csv_header,
};

use crate::accuracy::{ErrorTracker, RelativeErrors};
use crate::closed_form::Kinematics;
use crate::plot::{self, Panel};

/// Command-line options of the example binaries.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// Write every step as CSV here.
    pub csv: Option<PathBuf>,
    /// Write the SVG plot here.
    pub svg: PathBuf,
}

impl Options {
    /// Parses `--csv PATH` and `--svg PATH`. The plot goes by default to `NAME.svg` in Cargo's
    /// target directory: `$CARGO_TARGET_DIR` when set, else the workspace's `target/`.
    ///
    /// # Errors
    /// A message naming the unknown flag or missing value.
    pub fn from_args(name: &str, args: impl IntoIterator<Item = String>) -> Result<Self, String> {
        Self::parse(name, args, std::env::var_os("CARGO_TARGET_DIR"))
    }

    /// [`Options::from_args`] with the target directory given.
    fn parse(
        name: &str,
        args: impl IntoIterator<Item = String>,
        target_dir: Option<std::ffi::OsString>,
    ) -> Result<Self, String> {
        let target = match target_dir {
            Some(dir) if !dir.is_empty() => PathBuf::from(dir),
            _ => {
                let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
                workspace.canonicalize().unwrap_or(workspace).join("target")
            }
        };
        let mut options = Options {
            csv: None,
            svg: target.join(format!("{name}.svg")),
        };
        let mut args = args.into_iter();
        while let Some(flag) = args.next() {
            let mut value = |flag: &str| {
                args.next()
                    .map(PathBuf::from)
                    .ok_or_else(|| format!("{flag} needs a path"))
            };
            match flag.as_str() {
                "--csv" => options.csv = Some(value("--csv")?),
                "--svg" => options.svg = value("--svg")?,
                other => {
                    return Err(format!(
                        "unknown argument `{other}`; usage: {name} [--csv PATH] [--svg PATH]"
                    ));
                }
            }
        }
        Ok(options)
    }
}

/// Repetitions of the timed run; the fastest is reported.
const TIMING_REPETITIONS: usize = 20;

/// A solved revolution: every state, its error against the closed form and its cost.
pub struct Revolution<M: Mechanism<Dim = Const<N>>, const N: usize> {
    /// The mechanism as solved (parameters included).
    pub mechanism: M,
    /// Every state, t = 0 … period.
    pub states: Vec<State<M>>,
    /// Max relative errors of q, q̇, q̈ against the closed form.
    pub errors: RelativeErrors,
    /// Wall time per step (position, velocity, acceleration), best of repeated runs, seconds.
    pub seconds_per_step: f64,
    /// Total Newton iterations.
    pub iterations: usize,
}

/// Solves `steps` equal steps over one period and compares with `exact`.
///
/// # Errors
/// The first [`SolveError`] (with its time).
pub fn revolution<M, const N: usize>(
    mechanism: M,
    period: f64,
    steps: usize,
    exact: impl Fn(f64) -> Kinematics<N>,
) -> Result<Revolution<M, N>, SolveError>
where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    let mut states = Vec::with_capacity(steps + 1);
    let mut simulation = Simulation::new(Solver::new(mechanism.clone()), 0.0)?;
    simulation.run(period, steps, |state| states.push(state.clone()))?;

    // Cost of stepping alone (assembly is a one-off), best of several repetitions: a single
    // cold run of a few hundred microseconds mostly measures caches and clock ramp-up.
    let mut seconds_per_step = f64::INFINITY;
    for _ in 0..TIMING_REPETITIONS {
        let mut simulation = Simulation::new(Solver::new(mechanism.clone()), 0.0)?;
        let start = Instant::now();
        simulation.run(period, steps, |state| {
            std::hint::black_box(state);
        })?;
        seconds_per_step = seconds_per_step.min(start.elapsed().as_secs_f64() / steps as f64);
    }

    let mut tracker = ErrorTracker::new();
    for state in &states {
        let reference = exact(state.t);
        tracker.add(
            state.q.as_slice(),
            state.qd().as_slice(),
            state.qdd().as_slice(),
            &reference,
        );
    }
    let iterations = states.iter().map(|s| s.iterations).sum();
    Ok(Revolution {
        mechanism,
        states,
        errors: tracker.errors(),
        seconds_per_step,
        iterations,
    })
}

impl<M: Mechanism<Dim = Const<N>>, const N: usize> Revolution<M, N> {
    /// Writes every state as CSV: `t`, then q, q̇, q̈ by coordinate name, full precision.
    ///
    /// # Errors
    /// I/O errors writing `path`.
    pub fn write_csv(&self, path: &Path) -> Result<(), Box<dyn Error>> {
        let mut text = String::new();
        write_csv_header(&self.mechanism, &mut text)?;
        for state in &self.states {
            state.write_csv_row(&mut text)?;
        }
        std::fs::write(path, text)?;
        Ok(())
    }

    /// Writes the SVG plot (creating its directory) and, when asked for, the CSV, printing
    /// where; a failure to write either exits with status 1.
    pub fn write_outputs(
        &self,
        options: &Options,
        title: &str,
        x_label: &str,
        panels: &[Panel<'_>],
    ) {
        if let Err(message) = self.try_write_outputs(options, title, x_label, panels) {
            eprintln!("error: {message}");
            std::process::exit(1);
        }
    }

    /// [`Revolution::write_outputs`] without the exit.
    ///
    /// # Errors
    /// What could not be written, with a hint.
    pub fn try_write_outputs(
        &self,
        options: &Options,
        title: &str,
        x_label: &str,
        panels: &[Panel<'_>],
    ) -> Result<(), String> {
        plot::write_svg(&options.svg, title, x_label, panels).map_err(|e| {
            format!(
                "writing the plot {}: {e}\n  hint: give a writable path with `--svg PATH`",
                options.svg.display()
            )
        })?;
        println!("plot: {}", options.svg.display());
        if let Some(path) = &options.csv {
            self.write_csv(path)
                .map_err(|e| format!("writing {}: {e}", path.display()))?;
            println!("csv: {} ({} rows)", path.display(), self.states.len());
        }
        Ok(())
    }

    /// The accuracy-and-cost summary printed by the examples.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        let e = &self.errors;
        let steps = self.states.len();
        let _ = writeln!(
            s,
            "max error vs closed form (relative to each quantity's largest magnitude):\n  \
             q {:.2e}   q̇ {:.2e}   q̈ {:.2e}",
            e.q, e.qd, e.qdd
        );
        let work = if self.mechanism.outputs() == mechgen_runtime::Outputs::Forces {
            "position + velocity + acceleration + forces"
        } else {
            "position + velocity + acceleration"
        };
        let _ = writeln!(
            s,
            "cost: {:.2} µs per step ({work}; best of {} runs), {} steps, {:.2} Newton \
             iterations per step",
            self.seconds_per_step * 1e6,
            TIMING_REPETITIONS,
            steps,
            self.iterations as f64 / steps.max(1) as f64
        );
        s
    }
}

/// Prints an error with the mechanism's names and exits with status 1.
pub fn exit_with<M: Mechanism>(error: &SolveError, mechanism: &M) -> !
where
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    eprintln!("error: {}", error.describe(mechanism));
    std::process::exit(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::closed_form;
    use crate::plot::Series;
    use crate::scenes::FourBar;

    fn args(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| (*s).to_owned()).collect()
    }

    #[test]
    fn the_plot_goes_to_cargo_s_target_directory_or_where_asked() {
        let options = Options::parse("four_bar", args(&[]), Some("/elsewhere".into())).unwrap();
        assert_eq!(options.svg, Path::new("/elsewhere/four_bar.svg"));
        let options = Options::parse("four_bar", args(&[]), None).unwrap();
        assert!(options.svg.ends_with("target/four_bar.svg"), "{options:?}");
        let options =
            Options::parse("four_bar", args(&["--svg", "p.svg"]), Some("/x".into())).unwrap();
        assert_eq!(options.svg, Path::new("p.svg"));
        assert!(Options::parse("four_bar", args(&["--png"]), None).is_err());
    }

    #[test]
    fn a_plot_that_cannot_be_written_is_an_error() {
        let exact = closed_form::FourBar::default();
        let run = revolution(FourBar::default(), exact.period(), 12, |t| {
            exact.kinematics(t)
        })
        .unwrap();
        let points = [(0.0, 0.0), (1.0, 1.0)];
        let series = [Series {
            name: "line",
            points: &points,
        }];
        let panels = [Panel {
            y_label: "y",
            series: &series,
        }];
        let dir = std::env::temp_dir().join(format!("mechgen-demo-{}", std::process::id()));
        // A missing directory is named, not created.
        let missing = Options {
            csv: None,
            svg: dir.join("new/plot.svg"),
        };
        let error = run
            .try_write_outputs(&missing, "t", "x", &panels)
            .unwrap_err();
        let named = format!("the directory `{}` does not exist", dir.display());
        assert!(error.contains(&named), "{error}");
        assert!(!dir.exists());
        std::fs::create_dir_all(&dir).unwrap();
        let written = Options {
            csv: None,
            svg: dir.join("plot.svg"),
        };
        run.try_write_outputs(&written, "t", "x", &panels).unwrap();
        assert!(written.svg.exists());
        // A path under a regular file: it cannot be written.
        let blocked = Options {
            csv: None,
            svg: written.svg.join("plot.svg"),
        };
        let error = run
            .try_write_outputs(&blocked, "t", "x", &panels)
            .unwrap_err();
        assert!(error.contains("writing the plot"), "{error}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
