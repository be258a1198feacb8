//! The `mechgen` command line (`expand`, `check`, `solve`, `simulate`, `completions`): a front
//! end over `mechgen` and the interpreter (`mechgen_interp::Interpreted`), which runs `.mech`
//! scenes through the runtime's solver and integrator. Here: arguments, reading scenes, the
//! commands and their output.
//!
//! The binary is a thin wrapper around [`run`]; the pieces are public so that tests can reuse
//! them. Equally spaced sample times come from [`mechgen_runtime::sample_time`], as
//! in the examples; listed ones (`--at`, `--times`) are solved at exactly the doubles given.

pub mod args;
pub mod diagnostics;
mod failure;
mod hints;
mod input;
pub mod inspect;
pub mod output;
mod schedule;
mod session;
mod sets;
mod simulate;
mod solve;
mod words;

use std::ffi::OsString;
use std::io::Write;

pub use args::Command;

use failure::{Failure, write_failure};
use input::{compile, read_source};

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
        Command::Solve(args) => solve::solve(&args, stdout, stderr),
        Command::Simulate(args) => simulate::simulate(&args, stdout, stderr),
    }
}

fn print(stdout: &mut dyn Write, text: &str) -> Result<(), Failure> {
    stdout
        .write_all(text.as_bytes())
        .map_err(|e| write_failure(&e, "stdout"))
}
