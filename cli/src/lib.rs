//! The `mechgen` command line (`expand`, `check`, `solve`, `completions`): a front end over
//! `mechgen` and the interpreter (`mechgen_interp::Interpreted`), which runs `.mech` scenes
//! through the runtime's solver. Here: arguments, reading scenes, the commands and their output.
//!
//! The binary is a thin wrapper around [`run`]; the pieces are public so that tests can reuse
//! them. Equally spaced sample times come from [`mechgen_runtime::sample_time`], as
//! in the examples; listed ones (`--at`, `--times`) are solved at exactly the doubles given.

pub mod args;
pub mod diagnostics;
mod failure;
mod input;
pub mod inspect;
mod schedule;
pub mod solve;
mod words;

use std::ffi::OsString;
use std::io::{self, Write};
use std::path::Path;

pub use args::Command;

use args::{Input, Output, SolveArgs};
use failure::{Failure, failed, write_failure};
use input::{compile, read_source};
use mechgen_interp::Interpreted;
use schedule::Schedule;
use words::{count, readable};

/// Exit status for a bad command line.
pub const EXIT_USAGE: u8 = 2;
/// Exit status for a scene with errors, an unreadable file or a failed solve.
pub const EXIT_FAILURE: u8 = 1;

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
            file = create_output(&args.input, path)?;
            (&mut file, format!("`{}`", path.display()))
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
    finish(outcome, &schedule.describe(), &destination, stderr)
}

/// The summary line on stderr after a complete run, or the failure with what was written
/// before it.
fn finish(
    outcome: Result<solve::Summary, solve::RunError>,
    range: &str,
    destination: &str,
    stderr: &mut dyn Write,
) -> Result<(), Failure> {
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
        Err(solve::RunError::Write(e)) => Err(write_failure(&e, destination)),
        Err(solve::RunError::Solve { message, summary }) => Err(failed(format_args!(
            "{message}\n  note: wrote {} to {destination} ({}) before the failure",
            count(summary.rows, "row"),
            count(summary.iterations, "Newton iteration"),
        ))),
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
