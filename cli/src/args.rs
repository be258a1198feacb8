//! Command-line arguments, declared with clap's derive API (per-subcommand help, suggestions
//! for misspelt commands and flags, short usage errors), then turned into a [`Command`], the
//! plain description the rest of the CLI works from.

use std::ffi::OsString;
use std::path::PathBuf;

use clap::{ArgGroup, Args, CommandFactory, Parser, Subcommand};

use mechgen::syntax::limits::Limits;

use crate::output::Format;

pub mod simulate;

/// Exit status text shared by every help page.
const EXIT_STATUS: &str = "\
FILE may be `-` to read the scene from standard input.
Exit status: 0 on success, 1 when the scene has errors or cannot be solved, 2 for a bad command
line.";

/// How the equally spaced times of `solve` are computed, shown in its help.
const TIMES_HELP: &str = "\
Sample times, one of:
  --t-end T --steps N [--t0 T0]   N + 1 equally spaced times t_k = T0 + k·h with
                                  h = (T − T0)/N for k < N, and t_N = T exactly
  --at T1,T2,…                    the given times, solved at exactly these doubles
  --times FILE                    one time per line (blank lines and `#` comments skipped)
Listed times must be finite and strictly increasing; the mechanism is assembled at the first.
Every time is written back in the `t` column in shortest round-trip form, bit for bit.";

/// `mechgen`: compile, inspect and solve planar mechanisms written in `.mech` files.
#[derive(Debug, Parser)]
#[command(
    name = "mechgen",
    version,
    about = "Compile, inspect, solve and simulate planar mechanisms written in .mech files",
    after_help = EXIT_STATUS,
    arg_required_else_help = true,
    propagate_version = true
)]
struct Cli {
    #[command(subcommand)]
    command: Sub,
    /// Read scenes up to BYTES long (default 8 MiB: larger files are refused before they are
    /// read)
    #[arg(long, global = true, value_name = "BYTES", value_parser = clap::value_parser!(u64).range(1..))]
    max_file_size: Option<u64>,
    /// Read scenes of up to N statements (default 100000)
    #[arg(long, global = true, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    max_statements: Option<u64>,
}

#[derive(Debug, Subcommand)]
enum Sub {
    /// Print the Rust code generated for the scene
    #[command(after_help = EXIT_STATUS)]
    Expand {
        /// The scene (a .mech file, or `-` for standard input)
        #[arg(value_name = "FILE")]
        file: PathBuf,
    },
    /// Print the coordinates, equations, degrees of freedom, Jacobian sparsity and parameters
    /// of the scene
    #[command(after_help = EXIT_STATUS)]
    Check {
        /// The scene (a .mech file, or `-` for standard input)
        #[arg(value_name = "FILE")]
        file: PathBuf,
        /// Also print the operation counts of each generated function (text only)
        #[arg(long)]
        stats: bool,
        /// Output format: the readable report, or JSON (the same facts, schema in the README)
        #[arg(long, value_enum, default_value_t = CheckFormat::Text)]
        format: CheckFormat,
    },
    /// Solve positions, velocities and accelerations (and the forces, for a scene with masses or
    /// loads) over time with the interpreter and the runtime solver, and write them as CSV or
    /// JSON
    ///
    /// CSV columns, in order: `t`; every coordinate (`piston.x`, …), then the same names with
    /// `_dot` and `_ddot` when the scene computes them; every marker's values (`tip.x`, `tip.y`,
    /// `tip.x_dot`, …, `gap.angle`, …); for a scene with forces, one reaction per equation in
    /// the order `mechgen check` numbers the equations (`crank_pin.fx`, `crank_pin.fy`, …,
    /// `slide.normal`, `slide.torque`, `crank_angle.effort`); with `--diagnostics`, the
    /// per-step columns. JSON lists the same names under `coordinates`, `markers` and
    /// `reactions`, then the states.
    #[command(after_help = format!("{TIMES_HELP}\n\n{EXIT_STATUS}"))]
    Solve(SolveFlags),
    /// Simulate the motion of a scene's free degrees of freedom under its forces (forward
    /// dynamics) with the runtime's integrator, and write it as CSV or JSON
    ///
    /// The scene declares its free degrees of freedom where drivers would go (`free swing:
    /// angle(arm) from 0.3 speed 0;`); the integrator (generalized-α on the equations reduced
    /// to them, the constraints solved exactly at every step) chooses its steps by a local
    /// error estimate (`--rtol`, `--atol`), or takes fixed ones (`--step H`), and lands exactly
    /// on each sample time. CSV columns: those of `solve`, then `energy.kinetic`,
    /// `energy.gravity`, `energy.springs`, `energy.loads_work`, `energy.drivers_work`,
    /// `energy.dissipated` and `energy.total` (kinetic + potentials − work of loads and
    /// drivers + dissipated: constant up to the integrator's error), then each free degree of
    /// freedom's `NAME.value` and `NAME.rate`. JSON lists the same names under `energy` and
    /// `free`, the values in each state, and the integrator's totals under `stats`.
    #[command(after_help = format!("{TIMES_HELP}\n\n{EXIT_STATUS}"))]
    Simulate(simulate::SimulateFlags),
    /// Print a completion script for a shell (e.g. `mechgen completions bash > mechgen.bash`)
    Completions {
        /// The shell
        shell: clap_complete::Shell,
    },
}

/// The flags `solve` and `simulate` share: the scene, the sample times, the parameter
/// overrides and where and how the results are written.
#[derive(Debug, Args)]
#[command(group(ArgGroup::new("schedule").required(true).args(["t_end", "at", "times"])))]
struct RunFlags {
    /// The scene (a .mech file, or `-` for standard input)
    #[arg(value_name = "FILE")]
    file: PathBuf,
    /// End time of equally spaced samples (seconds; a number or a constant expression such as
    /// `2*pi/10`)
    #[arg(long, value_name = "T", allow_hyphen_values = true, value_parser = time_value,
          requires = "steps")]
    t_end: Option<f64>,
    /// Number of equal steps, at least 1 (N + 1 rows are written)
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..),
          requires = "t_end")]
    steps: Option<u32>,
    /// Start time of equally spaced samples, where the mechanism is assembled
    #[arg(long, value_name = "T0", allow_hyphen_values = true, value_parser = time_value,
          default_value_t = 0.0, requires = "t_end")]
    t0: f64,
    /// Solve at exactly these times (comma-separated, strictly increasing; each a number or a
    /// constant expression)
    #[arg(long, value_name = "T1,T2,…", allow_hyphen_values = true)]
    at: Vec<String>,
    /// Solve at the times listed in FILE, one a line
    #[arg(long, value_name = "FILE")]
    times: Option<PathBuf>,
    /// Override a parameter's default (repeatable; `mechgen check FILE` lists them; the value
    /// a number or a constant expression such as `30deg`)
    #[arg(long = "set", value_name = "NAME=VALUE", value_parser = set_value)]
    sets: Vec<(String, f64)>,
    /// Write the results to OUT instead of standard output (`-`: standard output)
    #[arg(long, value_name = "OUT", visible_alias = "csv")]
    out: Option<PathBuf>,
    /// Output format
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    format: Format,
}

#[derive(Debug, Args)]
struct SolveFlags {
    #[command(flatten)]
    run: RunFlags,
    /// Add per-step columns: Newton iterations, sub-steps, evaluations, static-pivot
    /// fallbacks, condition estimate and the sign of det Φ_q
    #[arg(long)]
    diagnostics: bool,
}

/// What the command line asks for.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Print the generated Rust of a scene.
    Expand {
        /// The scene.
        input: Input,
        /// The limits it is read within.
        limits: Limits,
    },
    /// Describe a scene.
    Check {
        /// The scene.
        input: Input,
        /// The limits it is read within.
        limits: Limits,
        /// Also print operation counts of the generated functions.
        stats: bool,
        /// Text report or JSON.
        format: CheckFormat,
    },
    /// Solve a scene over time and write CSV.
    Solve(SolveArgs),
    /// Simulate a scene's free motion and write CSV or JSON.
    Simulate(simulate::SimulateArgs),
    /// Print a completion script.
    Completions(clap_complete::Shell),
}

/// Where a scene is read from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Input {
    /// Standard input (`-`).
    Stdin,
    /// A file.
    File(PathBuf),
}

/// How `check` writes its report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum CheckFormat {
    /// The readable report
    #[default]
    Text,
    /// The same facts as one JSON object (fields listed in the README's command-line section)
    Json,
}

/// Where the results go.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Output {
    /// Standard output (no `--out`, or `--out -`).
    Stdout,
    /// A file, created or truncated.
    File(PathBuf),
}

/// The times `solve` samples.
#[derive(Debug, Clone, PartialEq)]
pub enum Times {
    /// `steps + 1` equally spaced times from `t0` to `t_end` (see
    /// [`mechgen_runtime::sample_time`]).
    Equal {
        /// Start time (the mechanism is assembled there).
        t0: f64,
        /// End time.
        t_end: f64,
        /// Number of equal steps (≥ 1).
        steps: usize,
    },
    /// The times given with `--at`.
    Listed(Vec<f64>),
    /// The file given with `--times`, read when the command runs.
    File(PathBuf),
}

/// What `solve` and `simulate` share: the scene, the sample times, the parameter overrides,
/// and where and how the results are written.
#[derive(Debug, Clone, PartialEq)]
pub struct RunArgs {
    /// The scene.
    pub input: Input,
    /// The limits it is read within.
    pub limits: Limits,
    /// The sample times.
    pub times: Times,
    /// Parameter overrides in command-line order: names are checked against the scene later,
    /// so that the error can list the parameters it declares.
    pub sets: Vec<(String, f64)>,
    /// Where the results go.
    pub out: Output,
    /// CSV or JSON.
    pub format: Format,
}

/// Arguments of `mechgen solve`.
#[derive(Debug, Clone, PartialEq)]
pub struct SolveArgs {
    /// The scene, times, overrides and output.
    pub run: RunArgs,
    /// Whether to add the per-step diagnostic columns.
    pub diagnostics: bool,
}

/// Parses the arguments that follow the program name.
///
/// # Errors
/// clap's error: a usage error (exit status 2), or the help or version text it asks to print
/// ([`clap::Error::use_stderr`] is false for those, exit status 0).
pub fn parse(args: impl IntoIterator<Item = OsString>) -> Result<Command, clap::Error> {
    let program = std::iter::once(OsString::from("mechgen"));
    let cli = Cli::try_parse_from(program.chain(args))?;
    let defaults = Limits::default();
    let limit = |value: Option<u64>, default: usize| {
        value.map_or(default, |v| usize::try_from(v).unwrap_or(usize::MAX))
    };
    let limits = Limits {
        bytes: limit(cli.max_file_size, defaults.bytes),
        statements: limit(cli.max_statements, defaults.statements),
    };
    Ok(match cli.command {
        Sub::Expand { file } => Command::Expand {
            input: input(file),
            limits,
        },
        Sub::Check {
            file,
            stats,
            format,
        } => Command::Check {
            input: input(file),
            limits,
            stats,
            format,
        },
        Sub::Completions { shell } => Command::Completions(shell),
        Sub::Solve(flags) => Command::Solve(SolveArgs {
            run: run_args(flags.run, limits, "solve")?,
            diagnostics: flags.diagnostics,
        }),
        Sub::Simulate(flags) => Command::Simulate(flags.resolve(limits)?),
    })
}

/// Writes the completion script for `shell`.
pub fn completions(shell: clap_complete::Shell, out: &mut dyn std::io::Write) {
    clap_complete::generate(shell, &mut Cli::command(), "mechgen", out);
}

fn input(file: PathBuf) -> Input {
    if file.as_os_str() == "-" {
        Input::Stdin
    } else {
        Input::File(file)
    }
}

/// The shared flags checked and resolved; `command` names the subcommand in usage errors.
fn run_args(flags: RunFlags, limits: Limits, command: &str) -> Result<RunArgs, clap::Error> {
    let invalid = |message: String| usage_error(command, message);
    let times = match (flags.t_end, flags.steps, flags.times) {
        (Some(t_end), Some(steps), _) => {
            if t_end == flags.t0 {
                return Err(invalid(format!(
                    "`--t-end` ({}) equals the start time ({}): give an end time that \
                     differs from `--t0` (which defaults to 0)",
                    time(t_end),
                    time(flags.t0)
                )));
            }
            resolved_steps(flags.t0, t_end, steps).map_err(invalid)?;
            Times::Equal {
                t0: flags.t0,
                t_end,
                steps: steps as usize,
            }
        }
        (_, _, Some(file)) => Times::File(file),
        _ => {
            let mut times = Vec::new();
            for list in &flags.at {
                for item in split_top_level(list) {
                    let t = time_value(item)
                        .map_err(|e| invalid(format!("`--at` item `{}`: {e}", item.trim())))?;
                    times.push(t);
                }
            }
            Times::Listed(increasing(times, "`--at`").map_err(invalid)?)
        }
    };
    for (k, (name, _)) in flags.sets.iter().enumerate() {
        if flags.sets[..k].iter().any(|(n, _)| n == name) {
            return Err(invalid(format!(
                "parameter `{name}` is set twice with `--set`: keep one"
            )));
        }
    }
    let out = match flags.out {
        None => Output::Stdout,
        Some(path) if path.as_os_str() == "-" => Output::Stdout,
        Some(path) if path.as_os_str().is_empty() => {
            return Err(invalid(
                "`--out` needs a file name (or `-` for standard output)".to_owned(),
            ));
        }
        Some(path) => Output::File(path),
    };
    Ok(RunArgs {
        input: input(flags.file),
        limits,
        times,
        sets: flags.sets,
        out,
        format: flags.format,
    })
}

/// A usage error of `mechgen COMMAND` with clap's formatting (`Usage: mechgen solve …`, exit
/// status 2).
pub(crate) fn usage_error(command: &str, message: String) -> clap::Error {
    let mut cli = Cli::command();
    // Building gives the subcommand its full name (`mechgen solve`) for the usage line.
    cli.build();
    cli.find_subcommand(command)
        .cloned()
        .unwrap_or(cli)
        .error(clap::error::ErrorKind::ValueValidation, message)
}

/// Largest time magnitude accepted, in seconds: beyond it doubles are more than 0.1 s apart
/// (at 1e15 s, 0.125 s), so times cannot be resolved, and any motion driven by `t` would be
/// far beyond what the solver resolves anyway (`Unresolved`).
pub const MAX_TIME: f64 = 1e15;

/// A time written in shortest round-trip form, with an exponent for huge and tiny ones.
pub fn time(t: f64) -> String {
    if t != 0.0 && !(1e-4..1e6).contains(&t.abs()) {
        format!("{t:e}")
    } else {
        format!("{t}")
    }
}

/// Equal steps from `t0` to `t_end` that double precision resolves: the span is finite and
/// each step covers several doubles, so the sample times increase strictly.
fn resolved_steps(t0: f64, t_end: f64, steps: u32) -> Result<(), String> {
    let h = (t_end - t0) / f64::from(steps);
    let largest = t0.abs().max(t_end.abs());
    // The distance from `largest` to the next double.
    let spacing = f64::from_bits(largest.to_bits() + 1) - largest;
    if h.abs() > 4.0 * spacing {
        return Ok(());
    }
    Err(format!(
        "{steps} equal steps from t = {} to {} are {} s each, which double precision cannot \
         resolve at t = {} (doubles there are {} s apart): give fewer `--steps` or a longer \
         time span",
        time(t0),
        time(t_end),
        time(h),
        time(largest),
        time(spacing)
    ))
}

/// `text` split at the commas outside parentheses (`0, atan2(1, 2)` is two items).
fn split_top_level(text: &str) -> Vec<&str> {
    let (mut items, mut depth, mut start) = (Vec::new(), 0i32, 0);
    for (i, c) in text.char_indices() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            ',' if depth == 0 => {
                items.push(&text[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    items.push(&text[start..]);
    items
}

/// `times` if non-empty and strictly increasing; otherwise what is wrong with them.
///
/// # Errors
/// A message naming the first offending time (`what` says where they came from).
pub fn increasing(times: Vec<f64>, what: &str) -> Result<Vec<f64>, String> {
    if times.is_empty() {
        return Err(format!("{what} lists no times: give at least one"));
    }
    if let Some(pair) = times.windows(2).find(|w| w[1] <= w[0]) {
        return Err(format!(
            "{what}: the times must be strictly increasing, but {} follows {}",
            time(pair[1]),
            time(pair[0])
        ));
    }
    Ok(times)
}

/// The times of a `--times` file: one per line, blank lines and `#` comments skipped.
///
/// # Errors
/// A message naming the line that is not a finite number, or the order problem.
pub fn parse_times(text: &str, name: &str) -> Result<Vec<f64>, String> {
    let mut times = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        match time_value(line) {
            Ok(t) => times.push(t),
            Err(e) => return Err(format!("{name}:{}: `{line}`: {e}", number + 1)),
        }
    }
    increasing(times, name)
}

/// A time: a number or a constant expression (`2*pi/10`), within ±[`MAX_TIME`].
fn time_value(text: &str) -> Result<f64, String> {
    let t = mechgen::check::constant_value(text)
        .map_err(|e| format!("expected a finite time in seconds, e.g. `0.02` or `2*pi/10`: {e}"))?;
    if t.abs() > MAX_TIME {
        return Err(format!(
            "{} s cannot be resolved: times beyond ±{} s are more than 0.1 s apart in double \
             precision; give a smaller time (shift the time origin with `--t0` and the \
             drivers' phase)",
            time(t),
            time(MAX_TIME)
        ));
    }
    Ok(t)
}

/// `NAME=VALUE`; the value only has to be a finite number here (the name is checked against
/// the scene, whose error lists the declared parameters).
fn set_value(set: &str) -> Result<(String, f64), String> {
    let Some((name, value)) = set.split_once('=') else {
        return Err("expected NAME=VALUE, e.g. `--set omega=100`".to_owned());
    };
    let name = name.trim();
    if name.is_empty() {
        return Err("no parameter name before `=`: e.g. `--set omega=100`".to_owned());
    }
    match mechgen::check::constant_value(value) {
        Ok(v) => Ok((name.to_owned(), v)),
        Err(e) => Err(format!(
            "`{value}` is not a finite number ({e}); e.g. `--set {name}=100` or \
             `--set {name}=30deg`"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_strs(args: &[&str]) -> Result<Command, clap::Error> {
        parse(args.iter().map(OsString::from))
    }

    fn error(args: &[&str]) -> String {
        match parse_strs(args) {
            Err(e) => e.render().to_string(),
            Ok(c) => panic!("expected an error, got {c:?}"),
        }
    }

    #[test]
    fn the_declaration_is_consistent() {
        Cli::command().debug_assert();
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
            "--diagnostics",
        ]);
        let expected = SolveArgs {
            run: RunArgs {
                input: Input::File("s.mech".into()),
                limits: Limits::default(),
                times: Times::Equal {
                    t0: -0.5,
                    t_end: 0.5,
                    steps: 10,
                },
                sets: vec![("omega".into(), 2.0), ("l".into(), 300.0)],
                out: Output::File("out.csv".into()),
                format: Format::Csv,
            },
            diagnostics: true,
        };
        assert_eq!(command.unwrap(), Command::Solve(expected));
    }

    #[test]
    fn listed_times_and_defaults() {
        let args = [
            "solve",
            "-",
            "--at",
            "-1,0.1,0.30000000000000004",
            "--csv",
            "-",
        ];
        let Ok(Command::Solve(SolveArgs {
            run: args,
            diagnostics,
        })) = parse_strs(&args)
        else {
            panic!("parses");
        };
        assert_eq!(
            args.times,
            Times::Listed(vec![-1.0, 0.1, 0.30000000000000004])
        );
        assert_eq!((args.input, args.out), (Input::Stdin, Output::Stdout));
        assert!(!diagnostics);
        let Ok(Command::Solve(SolveArgs { run: args, .. })) =
            parse_strs(&["solve", "s", "--times", "t.txt"])
        else {
            panic!("parses");
        };
        assert_eq!(args.times, Times::File("t.txt".into()));
    }

    #[test]
    fn bad_command_lines_say_what_to_do() {
        assert!(error(&["chek", "x"]).contains("similar subcommand"));
        assert!(error(&["check", "a", "--stat"]).contains("similar argument"));
        assert!(error(&["check"]).contains("<FILE>"));
        assert!(error(&["check", "a", "b"]).contains("unexpected argument 'b'"));
        assert!(error(&["solve", "a", "--steps", "3"]).contains("--t-end"));
        assert!(error(&["solve", "a"]).contains("--t-end"));
        assert!(error(&["solve", "a", "--t-end", "x", "--steps", "3"]).contains("finite"));
        assert!(error(&["solve", "a", "--t-end", "inf", "--steps", "3"]).contains("finite"));
        assert!(error(&["solve", "a", "--t-end", "1", "--steps", "0"]).contains("0"));
        assert!(error(&["solve", "a", "--t-end", "0", "--steps", "2"]).contains("differs"));
        assert!(
            error(&["solve", "a", "--t-end", "1", "--steps", "2", "--at", "1"])
                .contains("cannot be used with")
        );
        assert!(error(&["solve", "a", "--at", "1,1"]).contains("strictly increasing"));
        assert!(error(&["solve", "a", "--at", "1,x"]).contains("finite"));
        let set = |s: &str| error(&["solve", "a", "--t-end", "1", "--steps", "2", "--set", s]);
        assert!(set("omega").contains("NAME=VALUE"));
        assert!(set("=1").contains("no parameter name"));
        assert!(set("omega=fast").contains("not a finite number"));
        let twice = error(&[
            "solve", "a", "--t-end", "1", "--steps", "2", "--set", "w=1", "--set", "w=2",
        ]);
        assert!(twice.contains("set twice"));
        // Short: the usage line and a pointer to --help, not the whole manual.
        assert!(error(&["chek", "x"]).lines().count() <= 8);
    }

    #[test]
    fn times_and_values_are_constant_expressions() {
        let pi = core::f64::consts::PI;
        let Ok(Command::Solve(SolveArgs { run: args, .. })) = parse_strs(&[
            "solve",
            "s",
            "--t-end",
            "2*pi/10",
            "--steps",
            "4",
            "--t0",
            "-pi/10",
            "--set",
            "gamma=30deg",
        ]) else {
            panic!("parses");
        };
        let expected = Times::Equal {
            t0: -pi / 10.0,
            t_end: 2.0 * pi / 10.0,
            steps: 4,
        };
        assert_eq!(args.times, expected);
        assert_eq!(args.sets, [("gamma".to_owned(), pi / 6.0)]);
        let Ok(Command::Solve(SolveArgs { run: args, .. })) =
            parse_strs(&["solve", "s", "--at", "0, atan2(1, 1),pi/2", "--at", "2"])
        else {
            panic!("parses");
        };
        assert_eq!(
            args.times,
            Times::Listed(vec![0.0, pi / 4.0, pi / 2.0, 2.0])
        );
        assert!(error(&["solve", "a", "--at", "0,t"]).contains("`t` is not a number"));
    }

    #[test]
    fn unresolvable_times_are_refused_in_short_form() {
        let huge = error(&["solve", "a", "--t-end", "1e308", "--steps", "2"]);
        assert!(huge.contains("1e308 s cannot be resolved"), "{huge}");
        assert!(!huge.contains("000000000000"), "{huge}");
        let fine = error(&[
            "solve",
            "a",
            "--t0",
            "1e9",
            "--t-end",
            "1e9 + 1e-6",
            "--steps",
            "100",
        ]);
        assert!(fine.contains("double precision cannot resolve"), "{fine}");
        assert!(fine.contains("t = 1e9"), "{fine}");
        assert_eq!(time(1e308), "1e308");
        assert_eq!(time(0.02), "0.02");
        assert_eq!(time(-1.5e-7), "-1.5e-7");
    }

    #[test]
    fn usage_errors_name_the_program() {
        let order = error(&["solve", "a", "--at", "0.2,0.1"]);
        assert!(order.contains("Usage: mechgen solve"), "{order}");
    }

    #[test]
    fn times_files() {
        let times = parse_times("# t\n0\n\n0.1 # first\n  0.30000000000000004\npi\n", "f").unwrap();
        assert_eq!(
            times,
            [0.0, 0.1, 0.30000000000000004, core::f64::consts::PI]
        );
        assert!(parse_times("0\nx\n", "f").unwrap_err().contains("f:2"));
        assert!(
            parse_times("0.2\n0.1\n", "f")
                .unwrap_err()
                .contains("increasing")
        );
        assert!(
            parse_times("# none\n", "f")
                .unwrap_err()
                .contains("no times")
        );
    }
}
