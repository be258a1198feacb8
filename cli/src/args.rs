//! Command-line arguments: hand-written parsing (no argument-parsing dependency) into a
//! [`Command`], with messages that say how to fix a bad invocation.

use std::ffi::OsString;
use std::path::PathBuf;

/// The usage text printed by `mechgen help`, `mechgen --help` and after every usage error.
pub const USAGE: &str = "\
mechgen: compile, inspect and solve planar mechanisms written in .mech files

Usage:
  mechgen expand FILE
      Print the Rust code generated for the scene.
  mechgen check FILE [--stats]
      Print the coordinates, equations, degrees of freedom, Jacobian sparsity and
      parameters of the scene; --stats adds the operation counts of each generated function.
  mechgen solve FILE --t-end T --steps N [--t0 T0] [--set NAME=VALUE ...] [--csv OUT]
      Solve positions, velocities and accelerations at the N + 1 equally spaced times
      t_k = T0 + k·(T − T0)/N (k = 0..=N) with the interpreter and the runtime solver, and
      write them as CSV (columns t, then q, q_dot, q_ddot of every coordinate).
  mechgen help | --help | -h
      Print this text.
  mechgen --version | -V
      Print the version.

Options of solve:
  --t-end T         end time (seconds, finite, different from T0)
  --steps N         number of equal steps, at least 1 (N + 1 rows are written)
  --t0 T0           start time, where the mechanism is assembled (default 0)
  --set NAME=VALUE  override a parameter's default (repeatable; see `mechgen check FILE`)
  --csv OUT         write the CSV to OUT instead of standard output (`-`: standard output)

FILE may be `-` to read the scene from standard input. Options also accept `--flag=VALUE`;
`--` ends the options. Exit status: 0 on success, 1 when the scene has errors or cannot be
solved, 2 for a bad command line.
";

/// What the command line asks for.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Print [`USAGE`].
    Help,
    /// Print the version.
    Version,
    /// Print the generated Rust of a scene.
    Expand {
        /// The scene.
        input: Input,
    },
    /// Describe a scene.
    Check {
        /// The scene.
        input: Input,
        /// Also print operation counts of the generated functions.
        stats: bool,
    },
    /// Solve a scene over time and write CSV.
    Solve(SolveArgs),
}

/// Where a scene is read from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Input {
    /// Standard input (`-`).
    Stdin,
    /// A file.
    File(PathBuf),
}

/// Where the CSV goes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Output {
    /// Standard output (no `--csv`, or `--csv -`).
    Stdout,
    /// A file, created or truncated.
    File(PathBuf),
}

/// Arguments of `mechgen solve`.
#[derive(Debug, Clone, PartialEq)]
pub struct SolveArgs {
    /// The scene.
    pub input: Input,
    /// Start time (the mechanism is assembled there).
    pub t0: f64,
    /// End time.
    pub t_end: f64,
    /// Number of equal steps (≥ 1); `steps + 1` rows are written.
    pub steps: usize,
    /// Parameter overrides in command-line order: names are checked against the scene later,
    /// so that the error can list the parameters it declares.
    pub sets: Vec<(String, f64)>,
    /// Where the CSV goes.
    pub csv: Output,
}

/// A bad command line; the message says what to change (the caller adds [`USAGE`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UsageError(pub String);

impl core::fmt::Display for UsageError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

fn usage_error<T>(message: impl Into<String>) -> Result<T, UsageError> {
    Err(UsageError(message.into()))
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Expand,
    Check,
    Solve,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Expand => "expand",
            Kind::Check => "check",
            Kind::Solve => "solve",
        }
    }
}

/// Flags that take a value, all of them `solve`'s.
const SOLVE_FLAGS: [&str; 5] = ["--t-end", "--steps", "--t0", "--set", "--csv"];

/// Everything after the command, before per-command validation.
#[derive(Default)]
struct Raw {
    positional: Vec<OsString>,
    stats: bool,
    help: bool,
    t_end: Option<String>,
    steps: Option<String>,
    t0: Option<String>,
    sets: Vec<String>,
    csv: Option<OsString>,
}

/// Parses the arguments that follow the program name.
///
/// # Errors
/// A [`UsageError`] naming the offending argument and what was expected instead.
pub fn parse(args: impl IntoIterator<Item = OsString>) -> Result<Command, UsageError> {
    let mut args = args.into_iter();
    let Some(first) = args.next() else {
        return usage_error("missing command: give `expand`, `check` or `solve`");
    };
    let kind = match first.to_str() {
        Some("help" | "--help" | "-h") => return Ok(Command::Help),
        Some("--version" | "-V") => return Ok(Command::Version),
        Some("expand") => Kind::Expand,
        Some("check") => Kind::Check,
        Some("solve") => Kind::Solve,
        Some(flag) if flag.starts_with('-') => {
            return usage_error(format!(
                "unknown option `{flag}` before the command: write the command first, \
                 e.g. `mechgen check FILE`"
            ));
        }
        Some(other) => {
            return usage_error(format!(
                "unknown command `{other}`: use `expand`, `check` or `solve`"
            ));
        }
        None => {
            return usage_error("the command is not valid UTF-8: use `expand`, `check` or `solve`");
        }
    };
    let mut raw = collect(kind, &mut args)?;
    if raw.help {
        return Ok(Command::Help);
    }
    let input = input(kind, core::mem::take(&mut raw.positional))?;
    Ok(match kind {
        Kind::Expand => Command::Expand { input },
        Kind::Check => Command::Check {
            input,
            stats: raw.stats,
        },
        Kind::Solve => Command::Solve(solve_args(input, raw)?),
    })
}

fn collect(kind: Kind, args: &mut impl Iterator<Item = OsString>) -> Result<Raw, UsageError> {
    let mut raw = Raw::default();
    let mut options_ended = false;
    while let Some(arg) = args.next() {
        let text = match arg.to_str() {
            // Non-UTF-8 can only be a path.
            None => None,
            Some(_) if options_ended => None,
            Some("--") => {
                options_ended = true;
                continue;
            }
            Some(t) if t == "-" || !t.starts_with('-') => None,
            Some(t) => Some(t.to_owned()),
        };
        let Some(text) = text else {
            raw.positional.push(arg);
            continue;
        };
        let (flag, inline) = match text.split_once('=') {
            Some((flag, value)) if flag.starts_with("--") => (flag, Some(value)),
            _ => (text.as_str(), None),
        };
        match flag {
            "-h" | "--help" => raw.help = true,
            "--stats" if kind == Kind::Check => {
                if inline.is_some() {
                    return usage_error("`--stats` takes no value: write just `--stats`");
                }
                raw.stats = true;
            }
            _ if kind == Kind::Solve && SOLVE_FLAGS.contains(&flag) => {
                let value = match inline {
                    Some(v) => OsString::from(v),
                    None => args.next().ok_or_else(|| {
                        UsageError(format!("`{flag}` needs a value, e.g. `{}`", example(flag)))
                    })?,
                };
                store(&mut raw, flag, value)?;
            }
            _ => return Err(unknown_flag(kind, flag)),
        }
    }
    Ok(raw)
}

fn example(flag: &str) -> &'static str {
    match flag {
        "--t-end" => "--t-end 0.02",
        "--steps" => "--steps 100",
        "--t0" => "--t0 0",
        "--set" => "--set omega=100",
        _ => "--csv out.csv",
    }
}

fn store(raw: &mut Raw, flag: &str, value: OsString) -> Result<(), UsageError> {
    if flag == "--csv" {
        return once(&mut raw.csv, flag, value);
    }
    let Ok(value) = value.into_string() else {
        return usage_error(format!(
            "the value of `{flag}` is not valid UTF-8: e.g. `{}`",
            example(flag)
        ));
    };
    match flag {
        "--t-end" => once(&mut raw.t_end, flag, value),
        "--steps" => once(&mut raw.steps, flag, value),
        "--t0" => once(&mut raw.t0, flag, value),
        _ => {
            raw.sets.push(value);
            Ok(())
        }
    }
}

fn once<T>(slot: &mut Option<T>, flag: &str, value: T) -> Result<(), UsageError> {
    if slot.is_some() {
        return usage_error(format!("`{flag}` is given twice: keep one"));
    }
    *slot = Some(value);
    Ok(())
}

fn unknown_flag(kind: Kind, flag: &str) -> UsageError {
    let command = kind.name();
    let message = if SOLVE_FLAGS.contains(&flag) {
        format!("`{flag}` is an option of `mechgen solve`, not of `mechgen {command}`")
    } else if flag == "--stats" {
        format!("`--stats` is an option of `mechgen check`, not of `mechgen {command}`")
    } else {
        format!("unknown option `{flag}` for `mechgen {command}`")
    };
    UsageError(message)
}

fn input(kind: Kind, positional: Vec<OsString>) -> Result<Input, UsageError> {
    let command = kind.name();
    let mut positional = positional.into_iter();
    let Some(file) = positional.next() else {
        return usage_error(format!(
            "missing FILE: `mechgen {command} FILE` (a .mech scene, or `-` for standard input)"
        ));
    };
    if let Some(extra) = positional.next() {
        return usage_error(format!(
            "unexpected extra argument `{}`: `mechgen {command}` takes one FILE",
            extra.to_string_lossy()
        ));
    }
    Ok(if file == "-" {
        Input::Stdin
    } else {
        Input::File(PathBuf::from(file))
    })
}

fn solve_args(input: Input, raw: Raw) -> Result<SolveArgs, UsageError> {
    let Some(t_end) = raw.t_end else {
        return usage_error("missing `--t-end T`: give the end time, e.g. `--t-end 0.02`");
    };
    let Some(steps) = raw.steps else {
        return usage_error("missing `--steps N`: give the number of steps, e.g. `--steps 100`");
    };
    let t_end = time("--t-end", &t_end)?;
    let t0 = match raw.t0 {
        Some(t0) => time("--t0", &t0)?,
        None => 0.0,
    };
    let steps = match steps.trim().parse::<usize>() {
        Ok(n) if n >= 1 => n,
        _ => {
            return usage_error(format!(
                "`--steps` expects a whole number of steps of at least 1, e.g. `--steps 100`, \
                 got `{steps}`"
            ));
        }
    };
    if t_end == t0 {
        return usage_error(format!(
            "`--t-end` ({t_end}) equals the start time ({t0}): give an end time that differs \
             from `--t0` (which defaults to 0)"
        ));
    }
    let mut sets: Vec<(String, f64)> = Vec::with_capacity(raw.sets.len());
    for set in &raw.sets {
        let (name, value) = set_value(set)?;
        if sets.iter().any(|(n, _)| *n == name) {
            return usage_error(format!(
                "parameter `{name}` is set twice with `--set`: keep one"
            ));
        }
        sets.push((name, value));
    }
    let csv = match raw.csv {
        None => Output::Stdout,
        Some(path) if path == "-" => Output::Stdout,
        Some(path) if path.is_empty() => {
            return usage_error("`--csv` needs a file name (or `-` for standard output)");
        }
        Some(path) => Output::File(PathBuf::from(path)),
    };
    Ok(SolveArgs {
        input,
        t0,
        t_end,
        steps,
        sets,
        csv,
    })
}

fn time(flag: &str, text: &str) -> Result<f64, UsageError> {
    match text.trim().parse::<f64>() {
        Ok(t) if t.is_finite() => Ok(t),
        _ => usage_error(format!(
            "`{flag}` expects a finite number of seconds, e.g. `{}`, got `{text}`",
            example(flag)
        )),
    }
}

/// `NAME=VALUE`; the value only has to be a number here (finiteness and the name are checked
/// against the scene, whose error lists the declared parameters).
fn set_value(set: &str) -> Result<(String, f64), UsageError> {
    let Some((name, value)) = set.split_once('=') else {
        return usage_error(format!(
            "`--set` expects NAME=VALUE, e.g. `--set omega=100`, got `{set}`"
        ));
    };
    let name = name.trim();
    if name.is_empty() {
        return usage_error(format!(
            "`--set {set}` has no parameter name before `=`: e.g. `--set omega=100`"
        ));
    }
    match value.trim().parse::<f64>() {
        Ok(v) => Ok((name.to_owned(), v)),
        Err(_) => usage_error(format!(
            "`--set {set}`: `{value}` is not a number; e.g. `--set {name}=100`"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_strs(args: &[&str]) -> Result<Command, UsageError> {
        parse(args.iter().map(OsString::from))
    }

    fn error(args: &[&str]) -> String {
        match parse_strs(args) {
            Err(e) => e.0,
            Ok(c) => panic!("expected an error, got {c:?}"),
        }
    }

    #[test]
    fn help_and_version() {
        for args in [
            &["help"][..],
            &["--help"],
            &["-h"],
            &["solve", "x", "--help"],
        ] {
            assert_eq!(parse_strs(args), Ok(Command::Help), "{args:?}");
        }
        assert_eq!(parse_strs(&["-V"]), Ok(Command::Version));
    }

    #[test]
    fn solve_with_every_option() {
        let command = parse_strs(&[
            "solve",
            "s.mech",
            "--t-end=0.5",
            "--steps",
            "10",
            "--t0",
            "-0.5",
            "--set",
            "omega=2",
            "--set",
            "l = 3e2",
            "--csv",
            "out.csv",
        ]);
        let expected = SolveArgs {
            input: Input::File("s.mech".into()),
            t0: -0.5,
            t_end: 0.5,
            steps: 10,
            sets: vec![("omega".into(), 2.0), ("l".into(), 300.0)],
            csv: Output::File("out.csv".into()),
        };
        assert_eq!(command, Ok(Command::Solve(expected)));
    }

    #[test]
    fn defaults_stdin_and_stdout() {
        let Ok(Command::Solve(args)) =
            parse_strs(&["solve", "-", "--t-end", "1", "--steps", "1", "--csv", "-"])
        else {
            panic!("parses");
        };
        assert_eq!(
            (args.input, args.t0, args.csv),
            (Input::Stdin, 0.0, Output::Stdout)
        );
        assert_eq!(
            parse_strs(&["check", "--", "--odd.mech"]),
            Ok(Command::Check {
                input: Input::File("--odd.mech".into()),
                stats: false
            })
        );
    }

    #[test]
    fn bad_command_lines_say_what_to_do() {
        assert!(error(&[]).contains("missing command"));
        assert!(error(&["run", "x"]).contains("unknown command `run`"));
        assert!(error(&["check"]).contains("missing FILE"));
        assert!(error(&["check", "a", "b"]).contains("extra argument `b`"));
        assert!(error(&["check", "a", "--bogus"]).contains("unknown option `--bogus`"));
        assert!(error(&["expand", "a", "--steps", "3"]).contains("option of `mechgen solve`"));
        assert!(error(&["solve", "a", "--stats"]).contains("option of `mechgen check`"));
        assert!(error(&["solve", "a", "--steps", "3"]).contains("missing `--t-end"));
        assert!(error(&["solve", "a", "--t-end", "1"]).contains("missing `--steps"));
        assert!(error(&["solve", "a", "--t-end", "x", "--steps", "3"]).contains("finite"));
        assert!(error(&["solve", "a", "--t-end", "inf", "--steps", "3"]).contains("finite"));
        assert!(error(&["solve", "a", "--t-end", "1", "--steps", "0"]).contains("at least 1"));
        assert!(error(&["solve", "a", "--t-end", "1", "--steps", "-2"]).contains("at least 1"));
        assert!(error(&["solve", "a", "--t-end", "0", "--steps", "2"]).contains("differs"));
        assert!(error(&["solve", "a", "--t-end", "1", "--t-end", "2"]).contains("twice"));
        assert!(error(&["solve", "a", "--t-end"]).contains("needs a value"));
        let set = |s: &str| error(&["solve", "a", "--t-end", "1", "--steps", "2", "--set", s]);
        assert!(set("omega").contains("NAME=VALUE"));
        assert!(set("=1").contains("no parameter name"));
        assert!(set("omega=fast").contains("not a number"));
        let twice = error(&[
            "solve", "a", "--t-end", "1", "--steps", "2", "--set", "w=1", "--set", "w=2",
        ]);
        assert!(twice.contains("set twice"));
    }
}
