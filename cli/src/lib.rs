//! Tools over the interpreter: the `mechgen` command line (`expand`, `check`, `solve`) and the
//! [`Interpreted`] adapter that runs `.mech` scenes through the runtime's solver.
//!
//! The binary is a thin wrapper around [`run`]; the pieces are public so that tests and reports
//! can reuse them. Equally spaced sample times come from [`mechgen_runtime::sample_time`], as
//! in the examples; listed ones (`--at`, `--times`) are solved at exactly the doubles given.

pub mod args;
pub mod diagnostics;
pub mod inspect;
mod interpreted;
mod names;
pub mod solve;

use std::ffi::OsString;
use std::io::{self, Read, Write};
use std::path::Path;

pub use args::Command;
pub use interpreted::Interpreted;

use args::{Input, Output, SolveArgs, Times};
use mechgen_runtime::sample_time;

/// Exit status for a bad command line.
pub const EXIT_USAGE: u8 = 2;
/// Exit status for a scene with errors, an unreadable file or a failed solve.
pub const EXIT_FAILURE: u8 = 1;

/// How a command failed.
#[derive(Debug)]
enum Failure {
    /// A bad command line: clap's message, with the usage line.
    Usage(String),
    /// Anything else: the complete text for stderr.
    Failed(String),
    /// Standard output was closed by the reader (`mechgen solve … | head`): stop quietly.
    BrokenPipe,
}

fn failed(message: impl core::fmt::Display) -> Failure {
    Failure::Failed(format!("error: {message}"))
}

/// Runs the command line `args` (without the program name), writing results to `stdout` and
/// messages to `stderr`, and returns the exit status: 0, [`EXIT_FAILURE`] or [`EXIT_USAGE`].
pub fn run(
    args: impl IntoIterator<Item = OsString>,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> u8 {
    let outcome = match args::parse(args) {
        Ok(command) => execute(command, stdout, stderr),
        // `--help` and `--version` arrive as "errors" that belong on stdout.
        Err(error) if !error.use_stderr() => print(stdout, &error.render().to_string()),
        Err(error) => Err(Failure::Usage(error.render().to_string())),
    };
    let outcome = outcome.and_then(|()| stdout.flush().map_err(|e| write_failure(&e, "stdout")));
    // Nothing sensible is left to do if stderr itself cannot be written.
    match outcome {
        Ok(()) | Err(Failure::BrokenPipe) => 0,
        Err(Failure::Usage(message)) => {
            let _ = write!(stderr, "{message}");
            EXIT_USAGE
        }
        Err(Failure::Failed(message)) => {
            let _ = writeln!(stderr, "{message}");
            EXIT_FAILURE
        }
    }
}

fn execute(
    command: Command,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> Result<(), Failure> {
    match command {
        Command::Completions(shell) => {
            let mut script = Vec::new();
            args::completions(shell, &mut script);
            stdout
                .write_all(&script)
                .map_err(|e| write_failure(&e, "stdout"))
        }
        Command::Expand { input } => {
            let source = read_source(&input)?;
            let code = mechgen::expand_pretty(&source.text)
                .map_err(|errors| compile_failure(&source, &errors))?;
            print(stdout, &code)
        }
        Command::Check {
            input,
            stats,
            format,
        } => {
            let source = read_source(&input)?;
            let scene = compile(&source)?;
            let text = match format {
                args::CheckFormat::Text => inspect::report(&scene, &source.name, stats),
                args::CheckFormat::Json => inspect::json(&scene, &source.name),
            };
            print(stdout, &text)
        }
        Command::Solve(args) => solve(&args, stdout, stderr),
    }
}

fn print(stdout: &mut dyn Write, text: &str) -> Result<(), Failure> {
    stdout
        .write_all(text.as_bytes())
        .map_err(|e| write_failure(&e, "stdout"))
}

fn write_failure(error: &io::Error, destination: &str) -> Failure {
    if error.kind() == io::ErrorKind::BrokenPipe && destination == "stdout" {
        Failure::BrokenPipe
    } else {
        failed(format_args!("cannot write to {destination}: {error}"))
    }
}

/// A scene's text and the name its errors are reported under.
struct Source {
    name: String,
    text: String,
}

fn read_source(input: &Input) -> Result<Source, Failure> {
    match input {
        Input::Stdin => {
            let mut text = String::new();
            io::stdin()
                .read_to_string(&mut text)
                .map_err(|e| read_failure("standard input", &e))?;
            Ok(Source {
                name: "<stdin>".to_owned(),
                text,
            })
        }
        Input::File(path) => {
            let name = path.display().to_string();
            let text = std::fs::read_to_string(path).map_err(|e| read_failure(&name, &e))?;
            Ok(Source { name, text })
        }
    }
}

fn read_failure(name: &str, error: &io::Error) -> Failure {
    let hint = match error.kind() {
        io::ErrorKind::NotFound => "check the path (it is relative to the current directory)",
        io::ErrorKind::InvalidData => "the file must be UTF-8 text: re-save it as UTF-8",
        io::ErrorKind::PermissionDenied => "check the file's permissions",
        io::ErrorKind::IsADirectory => "give a .mech file, not a directory",
        _ => "give a readable .mech file",
    };
    failed(format_args!(
        "cannot read `{name}`: {error}\n  hint: {hint}"
    ))
}

fn compile(source: &Source) -> Result<mechgen::Scene, Failure> {
    mechgen::compile_str(&source.text).map_err(|errors| compile_failure(source, &errors))
}

fn compile_failure(source: &Source, errors: &mechgen::Errors) -> Failure {
    Failure::Failed(diagnostics::render(&source.name, &source.text, errors))
}

fn solve(args: &SolveArgs, stdout: &mut dyn Write, stderr: &mut dyn Write) -> Result<(), Failure> {
    let source = read_source(&args.input)?;
    let scene = compile(&source)?;
    let schedule = Schedule::resolve(&args.times)?;
    let mut mechanism = Interpreted::new(&scene);
    solve::apply_sets(&mut mechanism, &args.sets).map_err(failed)?;
    // Assemble before touching the output, so that a scene that cannot move leaves an existing
    // CSV file as it was.
    let mut simulation = solve::assemble(mechanism, schedule.start()).map_err(failed)?;

    let mut file;
    let (out, destination): (&mut dyn Write, String) = match &args.out {
        Output::Stdout => (stdout, "stdout".to_owned()),
        Output::File(path) => {
            refuse_to_overwrite_input(&args.input, path)?;
            let name = path.display().to_string();
            file = io::BufWriter::new(std::fs::File::create(path).map_err(|e| {
                failed(format_args!(
                    "cannot create `{name}`: {e}\n  hint: check that its directory exists \
                     and is writable"
                ))
            })?);
            (&mut file, format!("`{name}`"))
        }
    };

    let outcome = solve::run(
        &mut simulation,
        schedule.after_start(),
        args.format,
        args.diagnostics,
        out,
    );
    let range = schedule.describe();
    match outcome {
        Ok(summary) => {
            let _ = writeln!(
                stderr,
                "mechgen: wrote {} to {destination} ({range}); {} in total; largest residual \
                 ‖Φ‖∞ = {}",
                count(summary.rows, "row"),
                count(summary.iterations, "Newton iteration"),
                readable(summary.max_residual)
            );
            Ok(())
        }
        Err(solve::RunError::Write(e)) => Err(write_failure(&e, &destination)),
        Err(solve::RunError::Solve { message, summary }) => Err(failed(format_args!(
            "{message}\n  note: wrote {} to {destination} ({}) before the failure",
            count(summary.rows, "row"),
            count(summary.iterations, "Newton iteration"),
        ))),
    }
}

/// The sample times of a run, with a `--times` file read.
enum Schedule {
    /// `steps` equal steps from `t0` to `t_end` ([`sample_time`]).
    Equal { t0: f64, t_end: f64, steps: usize },
    /// Listed times, at least one, strictly increasing.
    Listed(Vec<f64>),
}

impl Schedule {
    fn resolve(times: &Times) -> Result<Self, Failure> {
        Ok(match times {
            &Times::Equal { t0, t_end, steps } => Schedule::Equal { t0, t_end, steps },
            Times::Listed(times) => Schedule::Listed(times.clone()),
            Times::File(path) => Schedule::Listed(read_times(path)?),
        })
    }

    /// Where the mechanism is assembled.
    fn start(&self) -> f64 {
        match self {
            Schedule::Equal { t0, .. } => *t0,
            Schedule::Listed(times) => times.first().copied().unwrap_or(0.0),
        }
    }

    /// The times stepped to after the start.
    fn after_start(&self) -> Box<dyn ExactSizeIterator<Item = f64> + '_> {
        match *self {
            Schedule::Equal { t0, t_end, steps } => {
                Box::new((1..steps + 1).map(move |k| sample_time(t0, t_end, steps, k)))
            }
            Schedule::Listed(ref times) => Box::new(times.iter().skip(1).copied()),
        }
    }

    /// For the summary line: `t = 0 to 0.02 in 360 equal steps`.
    fn describe(&self) -> String {
        match self {
            Schedule::Equal { t0, t_end, steps } => {
                format!("t = {t0} to {t_end} in {}", count(*steps, "equal step"))
            }
            Schedule::Listed(times) => format!(
                "{} from t = {} to {}",
                count(times.len(), "listed time"),
                self.start(),
                times.last().copied().unwrap_or(0.0)
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

/// `1 row`, `3 rows`.
fn count(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

/// A residual for people: `0`, or two significant digits (`1.4e-14`).
fn readable(x: f64) -> String {
    if x == 0.0 {
        "0".to_owned()
    } else {
        format!("{x:.1e}")
    }
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
