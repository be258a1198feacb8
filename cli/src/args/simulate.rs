//! The flags of `mechgen simulate`: the run flags of `solve`, then how the integrator steps
//! (error-controlled by default, `--step H` for fixed steps) and its numerical damping.

use clap::Args;

use mechgen::syntax::limits::Limits;

use super::{RunArgs, RunFlags, run_args};

/// How the integrator chooses its steps; `None` leaves the runtime's default
/// (`mechgen_runtime::IntegratorOptions::default()`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stepping {
    /// Steps chosen by the local error estimate of the free coordinates (`--rtol`, `--atol`).
    Adaptive {
        /// Relative tolerance.
        rtol: Option<f64>,
        /// Absolute tolerance, in the free coordinates' units.
        atol: Option<f64>,
    },
    /// Steps of `step` seconds, the last before each output time shortened to land on it.
    Fixed {
        /// The step (positive, finite).
        step: f64,
    },
}

/// Arguments of `mechgen simulate`.
#[derive(Debug, Clone, PartialEq)]
pub struct SimulateArgs {
    /// The scene, times, overrides and output.
    pub run: RunArgs,
    /// How the integrator steps.
    pub stepping: Stepping,
    /// Numerical damping ρ∞ in [0, 1]; `None` leaves the runtime's default.
    pub rho_inf: Option<f64>,
}

/// The flags of `mechgen simulate`, as clap reads them.
#[derive(Debug, Args)]
pub struct SimulateFlags {
    #[command(flatten)]
    run: RunFlags,
    /// Relative tolerance of the error-controlled steps, in (0, 1) (default 1e-6)
    #[arg(long, value_name = "TOL", allow_hyphen_values = true, value_parser = relative_tolerance)]
    rtol: Option<f64>,
    /// Absolute tolerance of the error-controlled steps, positive, in the free coordinates'
    /// units (rad, or the scene's length unit; default 1e-9)
    #[arg(long, value_name = "TOL", allow_hyphen_values = true, value_parser = absolute_tolerance)]
    atol: Option<f64>,
    /// Take fixed steps of H seconds instead of error-controlled ones (the last before each
    /// output time shortened to land on it)
    #[arg(long, value_name = "H", allow_hyphen_values = true, value_parser = step_size,
          conflicts_with_all = ["rtol", "atol"])]
    step: Option<f64>,
    /// Numerical damping: the spectral radius at infinite frequency, from 1 (none: energy kept)
    /// down to 0 (high frequencies damped in one step; default 0.9)
    #[arg(long, value_name = "R", allow_hyphen_values = true, value_parser = spectral_radius)]
    rho_inf: Option<f64>,
}

impl SimulateFlags {
    /// The flags checked and resolved; usage errors name `mechgen simulate`.
    ///
    /// # Errors
    /// As for `solve`'s flags: times that are not increasing, a parameter set twice, an empty
    /// `--out`.
    pub fn resolve(self, limits: Limits) -> Result<SimulateArgs, clap::Error> {
        let stepping = match self.step {
            Some(step) => Stepping::Fixed { step },
            None => Stepping::Adaptive {
                rtol: self.rtol,
                atol: self.atol,
            },
        };
        Ok(SimulateArgs {
            run: run_args(self.run, limits, "simulate")?,
            stepping,
            rho_inf: self.rho_inf,
        })
    }
}

/// A positive finite number: a number or a constant expression (`1e-3`, `2*pi/1000`).
fn positive(text: &str, example: &str) -> Result<f64, String> {
    match mechgen::check::constant_value(text) {
        Ok(value) if value > 0.0 => Ok(value),
        Ok(value) => Err(format!("{value} is not positive: give e.g. `{example}`")),
        Err(e) => Err(format!("expected a positive number, e.g. `{example}`: {e}")),
    }
}

fn relative_tolerance(text: &str) -> Result<f64, String> {
    let rtol = positive(text, "1e-6")?;
    if rtol >= 1.0 {
        return Err(format!(
            "a relative tolerance of {rtol} accepts any step (errors as large as the motion \
             itself): give one below 1, e.g. `1e-6`"
        ));
    }
    Ok(rtol)
}

fn absolute_tolerance(text: &str) -> Result<f64, String> {
    positive(text, "1e-9")
}

fn step_size(text: &str) -> Result<f64, String> {
    positive(text, "1e-4")
}

fn spectral_radius(text: &str) -> Result<f64, String> {
    let rho = mechgen::check::constant_value(text)
        .map_err(|e| format!("expected a number from 0 to 1, e.g. `0.9`: {e}"))?;
    if !(0.0..=1.0).contains(&rho) {
        return Err(format!(
            "ρ∞ = {rho} is outside [0, 1]: 1 keeps every frequency undamped, 0 damps the \
             highest ones out in one step; give e.g. `0.9`"
        ));
    }
    Ok(rho)
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use clap::Parser;

    use super::*;
    use crate::args::{Input, Output, Times};
    use crate::output::Format;

    /// The flags on their own, as `mechgen simulate` reads them.
    #[derive(Debug, Parser)]
    #[command(name = "simulate")]
    struct Only {
        #[command(flatten)]
        flags: SimulateFlags,
    }

    fn parse(args: &[&str]) -> Result<SimulateArgs, String> {
        let args = std::iter::once("simulate").chain(args.iter().copied());
        Only::try_parse_from(args)
            .and_then(|only| only.flags.resolve(Limits::default()))
            .map_err(|e| e.render().to_string())
    }

    fn error(args: &[&str]) -> String {
        match parse(args) {
            Err(e) => e,
            Ok(a) => panic!("expected an error, got {a:?}"),
        }
    }

    #[test]
    fn the_declaration_is_consistent() {
        use clap::CommandFactory;
        Only::command().debug_assert();
    }

    #[test]
    fn defaults_are_the_runtimes_error_controlled_steps() {
        let args = parse(&["s.mech", "--t-end", "1", "--steps", "10"]).unwrap();
        let run = RunArgs {
            input: Input::File(PathBuf::from("s.mech")),
            limits: Limits::default(),
            times: Times::Equal {
                t0: 0.0,
                t_end: 1.0,
                steps: 10,
            },
            sets: Vec::new(),
            out: Output::Stdout,
            format: Format::Csv,
        };
        let expected = SimulateArgs {
            run,
            stepping: Stepping::Adaptive {
                rtol: None,
                atol: None,
            },
            rho_inf: None,
        };
        assert_eq!(args, expected);
    }

    #[test]
    fn every_flag() {
        let args = parse(&[
            "-",
            "--at",
            "0,0.5",
            "--rtol",
            "1e-8",
            "--atol",
            "1e-10",
            "--rho-inf",
            "1",
            "--set",
            "m=2",
            "--format",
            "json",
            "--out",
            "o.json",
        ])
        .unwrap();
        assert_eq!(
            args.stepping,
            Stepping::Adaptive {
                rtol: Some(1e-8),
                atol: Some(1e-10)
            }
        );
        assert_eq!(args.rho_inf, Some(1.0));
        assert_eq!(args.run.times, Times::Listed(vec![0.0, 0.5]));
        assert_eq!(args.run.sets, [("m".to_owned(), 2.0)]);
        assert_eq!(args.run.format, Format::Json);
        assert_eq!(args.run.out, Output::File("o.json".into()));
        let fixed = parse(&["s", "--t-end", "1", "--steps", "4", "--step", "1/1000"]).unwrap();
        assert_eq!(fixed.stepping, Stepping::Fixed { step: 1e-3 });
        let zero = parse(&["s", "--at", "0", "--rho-inf", "0"]).unwrap();
        assert_eq!(zero.rho_inf, Some(0.0));
    }

    #[test]
    fn bad_flags_say_what_to_give() {
        let times = ["s", "--t-end", "1", "--steps", "4"];
        let with = |flags: &[&str]| error(&[&times[..], flags].concat());
        assert!(with(&["--rtol", "0"]).contains("not positive"));
        assert!(with(&["--rtol", "-1e-6"]).contains("not positive"));
        assert!(with(&["--rtol", "1"]).contains("below 1"));
        assert!(with(&["--rtol", "inf"]).contains("positive number"));
        assert!(with(&["--atol", "0"]).contains("not positive"));
        assert!(with(&["--atol", "x"]).contains("positive number"));
        assert!(with(&["--step", "0"]).contains("not positive"));
        assert!(with(&["--step", "nan"]).contains("positive number"));
        assert!(with(&["--rho-inf", "1.5"]).contains("outside [0, 1]"));
        assert!(with(&["--rho-inf", "-0.1"]).contains("outside [0, 1]"));
        // Fixed steps take no tolerances.
        let both = with(&["--step", "1e-3", "--rtol", "1e-6"]);
        assert!(both.contains("cannot be used with"), "{both}");
        let both = with(&["--atol", "1e-6", "--step", "1e-3"]);
        assert!(both.contains("cannot be used with"), "{both}");
        // The run flags are checked as for `solve`.
        assert!(error(&["s", "--at", "0.2,0.1"]).contains("strictly increasing"));
        assert!(error(&["s"]).contains("--t-end"));
        let twice = error(&["s", "--at", "0", "--set", "m=1", "--set", "m=2"]);
        assert!(twice.contains("set twice"), "{twice}");
        assert!(error(&["s", "--at", "0", "--diagnostics"]).contains("unexpected argument"));
    }
}
