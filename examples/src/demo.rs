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
    /// Parses `--csv PATH` and `--svg PATH` (default `target/NAME.svg` in the workspace).
    ///
    /// # Errors
    /// A message naming the unknown flag or missing value.
    pub fn from_args(name: &str, args: impl IntoIterator<Item = String>) -> Result<Self, String> {
        let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let target = workspace.canonicalize().unwrap_or(workspace).join("target");
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

    /// Writes the SVG plot (a failure is a warning: the table was printed already) and, when
    /// asked for, the CSV (a failure exits with status 1).
    pub fn write_outputs(
        &self,
        options: &Options,
        title: &str,
        x_label: &str,
        panels: &[Panel<'_>],
    ) {
        match plot::write_svg(&options.svg, title, x_label, panels) {
            Ok(()) => println!("plot: {}", options.svg.display()),
            Err(e) => eprintln!("warning: {e} ({})", options.svg.display()),
        }
        if let Some(path) = &options.csv {
            match self.write_csv(path) {
                Ok(()) => println!("csv: {} ({} rows)", path.display(), self.states.len()),
                Err(e) => {
                    eprintln!("error: writing {}: {e}", path.display());
                    std::process::exit(1);
                }
            }
        }
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
        let _ = writeln!(
            s,
            "cost: {:.2} µs per step (position + velocity + acceleration; best of {} runs), \
             {} steps, {:.2} Newton iterations per step",
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
