//! Tools over the interpreter: the `mechgen` command line (`expand`, `check`, `solve`) and the
//! [`Interpreted`] adapter that runs `.mech` scenes through the runtime's solver.
//!
//! The binary is a thin wrapper around [`run`]; the pieces are public so that tests and reports
//! can reuse them. Equally spaced sample times come from [`mechgen_runtime::sample_time`], as
//! in the examples; listed ones (`--at`, `--times`) are solved at exactly the doubles given.

pub mod args;
pub mod diagnostics;
pub mod inspect;
pub mod solve;

use std::ffi::OsString;
use std::io::{self, Read, Write};
use std::path::Path;

pub use args::Command;
pub use mechgen_interp::Interpreted;

use args::{Input, Output, SolveArgs, Times};
use mechgen::syntax::limits::Limits;
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
        Command::Expand { input, limits } => {
            let source = read_source(&input, &limits)?;
            let scene = compile(&source, &limits)?;
            print(stdout, &mechgen::pretty(mechgen::emit::emit(&scene)))
        }
        Command::Check {
            input,
            limits,
            stats,
            format,
        } => {
            let source = read_source(&input, &limits)?;
            let scene = compile(&source, &limits)?;
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

/// Reads a scene, at most `limits.bytes` of it: a larger file is refused before it is read
/// (by its size), a larger standard input once the limit is passed.
fn read_source(input: &Input, limits: &Limits) -> Result<Source, Failure> {
    let (name, reader, size): (String, Box<dyn Read>, Option<u64>) = match input {
        Input::Stdin => ("<stdin>".to_owned(), Box::new(io::stdin()), None),
        Input::File(path) => {
            let name = path.display().to_string();
            let file = std::fs::File::open(path).map_err(|e| read_failure(&name, &e))?;
            let size = file
                .metadata()
                .ok()
                .filter(|m| m.is_file())
                .map(|m| m.len());
            (name, Box::new(file), size)
        }
    };
    let limit = u64::try_from(limits.bytes).unwrap_or(u64::MAX);
    if let Some(size) = size.filter(|&size| size > limit) {
        return Err(too_large(&name, &size.to_string(), limits));
    }
    let mut bytes = Vec::new();
    reader
        .take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| read_failure(&name, &e))?;
    if bytes.len() > limits.bytes {
        return Err(too_large(
            &name,
            &format!("more than {}", limits.bytes),
            limits,
        ));
    }
    let text = String::from_utf8(bytes)
        .map_err(|e| read_failure(&name, &io::Error::new(io::ErrorKind::InvalidData, e)))?;
    Ok(Source { name, text })
}

fn too_large(name: &str, size: &str, limits: &Limits) -> Failure {
    failed(format_args!(
        "`{name}` is {size} bytes, more than the {} bytes mechgen reads (`--max-file-size`, \
         default {})\n  hint: pass `--max-file-size BYTES` to read a larger scene (checking \
         takes about 2 s and 70 MB per 100 000 statements); scenes this \
         large are better built in code with `mechgen::builder`",
        limits.bytes,
        mechgen::syntax::limits::MAX_SOURCE_BYTES
    ))
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

/// Reads the scene's text within `limits` (statement by statement) and compiles it.
fn compile(source: &Source, limits: &Limits) -> Result<mechgen::Scene, Failure> {
    let read = mechgen::syntax::source::read(&source.text, limits);
    read.spec
        .map_err(mechgen::Errors::from)
        .and_then(|spec| {
            mechgen::compile(mechgen::Input::Spec(&spec), &mechgen::Options::default())
        })
        .map_err(|errors| {
            Failure::Failed(diagnostics::render(
                &source.name,
                &source.text,
                &read.locations,
                &errors,
            ))
        })
}

fn solve(args: &SolveArgs, stdout: &mut dyn Write, stderr: &mut dyn Write) -> Result<(), Failure> {
    let source = read_source(&args.input, &args.limits)?;
    let scene = compile(&source, &args.limits)?;
    let schedule = Schedule::resolve(&args.times)?;
    let mut mechanism = Interpreted::new(&scene);
    solve::apply_sets(&mut mechanism, &args.sets).map_err(|error| match error {
        solve::SetError::Unknown(message) => {
            Failure::Usage(args::invalid(message).render().to_string())
        }
        solve::SetError::Invalid(message) => failed(message),
    })?;
    // Assemble before touching the output, so that a scene that cannot move leaves an existing
    // CSV file as it was (a JSON document still records the failure).
    let assembled = solve::assemble(mechanism, schedule.start());
    if let Err(failure) = &assembled
        && args.format == solve::Format::Csv
    {
        return Err(failed(&failure.message));
    }

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

    let mut simulation = match assembled {
        Ok(simulation) => simulation,
        Err(failure) => {
            solve::write_unassembled(&failure, args.format, out)
                .and_then(|()| out.flush())
                .map_err(|e| write_failure(&e, &destination))?;
            return Err(failed(&failure.message));
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
                args::time(times.last().copied().unwrap_or(0.0))
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
