//! One run of `solve` or `simulate` around its stepping: the scene with its `--set` overrides
//! and sample times; the destination, opened only once the start is known (a scene that cannot
//! start leaves an existing CSV file as it was); the totals, and the summary line on stderr.

use std::io::{self, Write};
use std::path::Path;

use mechgen_interp::Interpreted;
use mechgen_runtime::nalgebra::DVector;
use mechgen_runtime::{Mechanism, State};

use crate::args::{Input, Output, RunArgs};
use crate::failure::{Failure, failed, write_failure};
use crate::input::{compile, read_source};
use crate::output::{Format, Layout, Stopped};
use crate::schedule::Schedule;
use crate::sets;
use crate::words::{count, readable};

/// The scene of `args`, compiled, with its overrides set, and its sample times (a `--times`
/// file read). `command` names the subcommand in usage errors.
pub(crate) fn prepare(args: &RunArgs, command: &str) -> Result<(Interpreted, Schedule), Failure> {
    let source = read_source(&args.input, &args.limits)?;
    let scene = compile(&source, &args.limits)?;
    let schedule = Schedule::resolve(&args.times)?;
    let mut mechanism = Interpreted::new(&scene);
    sets::apply(&mut mechanism, &args.sets, command)?;
    Ok((mechanism, schedule))
}

/// Why a run could not start (the assembly, or the integrator's initial state).
pub(crate) struct StartFailure {
    /// The error described with the scene's names and a hint, for stderr.
    pub(crate) message: String,
    /// The runtime's error as serde writes it, for the JSON document.
    pub(crate) kind: serde_json::Value,
}

/// Where the results go: standard output, or the `--out` file.
pub(crate) struct Destination<'a> {
    stdout: &'a mut dyn Write,
    file: Option<io::BufWriter<std::fs::File>>,
    /// `stdout` or the file's name in backquotes, for messages.
    pub(crate) name: String,
}

impl Destination<'_> {
    pub(crate) fn writer(&mut self) -> &mut dyn Write {
        match &mut self.file {
            Some(file) => file,
            None => &mut *self.stdout,
        }
    }
}

/// Opens the destination of a run whose start is `started`. A run that could not start is a
/// failure: with CSV nothing is written (an existing file is left as it was), with JSON the
/// document records the error at step 0.
pub(crate) fn open<'a, S>(
    args: &RunArgs,
    layout: &Layout,
    started: Result<S, StartFailure>,
    stdout: &'a mut dyn Write,
) -> Result<(S, Destination<'a>), Failure> {
    if let Err(failure) = &started
        && layout.format() == Format::Csv
    {
        return Err(failed(&failure.message));
    }
    let mut destination = match &args.out {
        Output::Stdout => Destination {
            stdout,
            file: None,
            name: "stdout".to_owned(),
        },
        Output::File(path) => Destination {
            stdout,
            file: Some(create_output(&args.input, path)?),
            name: format!("`{}`", path.display()),
        },
    };
    match started {
        Ok(started) => Ok((started, destination)),
        Err(failure) => {
            let stopped = Stopped {
                step: 0,
                kind: failure.kind,
                message: &failure.message,
            };
            let name = destination.name.clone();
            let out = destination.writer();
            layout
                .write_failed_start(&stopped, out)
                .and_then(|()| out.flush())
                .map_err(|e| write_failure(&e, &name))?;
            Err(failed(&failure.message))
        }
    }
}

/// The `--out` file, created (truncated) unless it is the scene itself.
fn create_output(input: &Input, path: &Path) -> Result<io::BufWriter<std::fs::File>, Failure> {
    refuse_to_overwrite_input(input, path)?;
    let name = path.display().to_string();
    let file = std::fs::File::create(path).map_err(|e| {
        failed(format_args!(
            "cannot create `{name}`: {e}\n  hint: check that its directory exists \
             and is writable"
        ))
    })?;
    Ok(io::BufWriter::new(file))
}

fn refuse_to_overwrite_input(input: &Input, out: &Path) -> Result<(), Failure> {
    let Input::File(scene) = input else {
        return Ok(());
    };
    match (scene.canonicalize(), out.canonicalize()) {
        (Ok(a), Ok(b)) if a == b => Err(failed(format_args!(
            "`--out {}` would overwrite the scene itself: give another file name",
            out.display()
        ))),
        _ => Ok(()),
    }
}

/// Totals over a run, for the summary line.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Summary {
    /// Rows written (one per solved time).
    pub(crate) rows: usize,
    /// Newton updates over all position solves, assembly included.
    pub(crate) iterations: usize,
    /// Largest ‖Φ‖∞ at any written positions.
    pub(crate) max_residual: f64,
}

/// The [`Summary`] of the rows written so far.
pub(crate) struct Tally {
    pub(crate) summary: Summary,
    phi: DVector<f64>,
}

impl Tally {
    pub(crate) fn new(m: &Interpreted) -> Self {
        Self {
            summary: Summary::default(),
            phi: DVector::zeros(m.len()),
        }
    }

    /// Counts `state`, written as a row of `m`'s motion.
    pub(crate) fn record(&mut self, m: &Interpreted, state: &State<Interpreted>) {
        // The state does not keep the solver's residual; Φ at the returned q is that residual.
        m.phi(&state.q, state.t, &mut self.phi);
        self.summary.rows += 1;
        self.summary.iterations += state.iterations;
        self.summary.max_residual = self.summary.max_residual.max(self.phi.amax());
    }
}

/// Why a run stopped early.
#[derive(Debug)]
pub(crate) enum RunError {
    /// Writing a row failed.
    Write(io::Error),
    /// A step failed; the message already names the time and the scene's terms.
    Step {
        /// The named description of the error, with a hint.
        message: String,
        /// What was done before the failure.
        summary: Summary,
    },
}

/// The summary line on stderr after a complete run (`wrote 11 rows to stdout (t = 0 to 1 in
/// 10 equal steps); WORK; largest residual ‖Φ‖∞ = …`), or the failure with what was written
/// before it. `work` says what the run took.
pub(crate) fn finish(
    outcome: Result<Summary, RunError>,
    schedule: &Schedule,
    destination: &str,
    stderr: &mut dyn Write,
    work: impl FnOnce(&Summary) -> String,
) -> Result<(), Failure> {
    let range = schedule.describe();
    match outcome {
        Ok(summary) => {
            let _ = writeln!(
                stderr,
                "mechgen: wrote {} to {destination} ({range}); {} in total; largest residual \
                 ‖Φ‖∞ = {}",
                count(summary.rows, "row"),
                work(&summary),
                readable(summary.max_residual)
            );
            Ok(())
        }
        Err(RunError::Write(e)) => Err(write_failure(&e, destination)),
        Err(RunError::Step { message, summary }) => Err(failed(format_args!(
            "{message}\n  note: wrote {} to {destination} ({}) before the failure",
            count(summary.rows, "row"),
            work(&summary),
        ))),
    }
}
