//! `mechgen solve`: steps a scene through time with the interpreter behind the runtime's own
//! [`Solver`] and [`Simulation`] (the code generated scenes use), writing one CSV row per time.

use std::io::Write;

use mechgen_runtime::nalgebra::DVector;
use mechgen_runtime::{Mechanism, Simulation, SolveError, Solver, State, write_csv_header};

use crate::Interpreted;

/// Totals over a run, for the summary line.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Summary {
    /// CSV data rows written (one per solved time).
    pub rows: usize,
    /// Newton updates over all position solves, assembly included.
    pub iterations: usize,
    /// Largest ‖Φ‖∞ at any solved positions.
    pub max_residual: f64,
}

/// Why a run stopped early.
#[derive(Debug)]
pub enum RunError {
    /// Writing a row failed.
    Write(std::io::Error),
    /// A solve failed; the message already names the time, equations and coordinates.
    Solve {
        /// The named description of the solver error, with a hint.
        message: String,
        /// What was done before the failure.
        summary: Summary,
    },
}

/// Sets the `--set` overrides on `mechanism`, all or none.
///
/// # Errors
/// A message naming the bad override and listing the parameters the scene declares.
pub fn apply_sets(mechanism: &mut Interpreted, sets: &[(String, f64)]) -> Result<(), String> {
    // Checked before any is set, so that the list in the message shows the scene's defaults.
    for (name, value) in sets {
        let declared = (0..mechanism.parameter_count())
            .any(|i| mechanism.parameter_name(i) == Some(name.as_str()));
        let problem = if !declared {
            format!("the scene declares no parameter `{name}`")
        } else if !value.is_finite() {
            "parameter values must be finite numbers".to_owned()
        } else {
            continue;
        };
        return Err(format!(
            "`--set {name}={value}`: {problem}; {}",
            declared_parameters(mechanism)
        ));
    }
    for (name, value) in sets {
        mechanism
            .set_parameter(name, *value)
            .map_err(|error| format!("`--set {name}={value}`: {error}"))?;
    }
    Ok(())
}

fn declared_parameters(mechanism: &Interpreted) -> String {
    let list: Vec<String> = (0..mechanism.parameter_count())
        .filter_map(|i| {
            let name = mechanism.parameter_name(i)?;
            let value = mechanism.parameter(i)?;
            Some(format!("`{name}` (default {value})"))
        })
        .collect();
    if list.is_empty() {
        "the scene declares no parameters, so `--set` cannot be used with it".to_owned()
    } else {
        format!("declared parameters: {}", list.join(", "))
    }
}

/// Assembles `mechanism` at `t0`.
///
/// # Errors
/// The solver's error, described with the scene's names and a hint.
pub fn assemble(mechanism: Interpreted, t0: f64) -> Result<Simulation<Interpreted>, String> {
    Simulation::new(Solver::new(mechanism), t0).map_err(|failure| {
        format!(
            "cannot assemble `{}`: {failure}\n  hint: {}",
            failure.solver.mechanism().name(),
            assembly_hint(&failure.error)
        )
    })
}

const GEOMETRY_HINT: &str = "change the named parameter with `--set NAME=VALUE` (its default is in the scene; \
     `mechgen check FILE` lists the parameters)";

fn assembly_hint(error: &SolveError) -> &'static str {
    match error {
        SolveError::NoConvergence { .. } => {
            "move the `near (x, y, angle)` guesses of the moving bodies closer to an assembled \
             pose, or check the dimensions: the joints may not be able to close at all"
        }
        SolveError::Singular { .. } => {
            "the named equation is redundant or conflicts with others at this pose: check the \
             joints, or move the `near` guesses away from a dead-centre position"
        }
        SolveError::NoAssembly { .. } => {
            "the joints cannot all close with these dimensions: check the lengths, the \
             parameters and the drivers' values at the start time"
        }
        SolveError::BranchFlip { .. } => {
            "the guesses lead to another assembly branch than the scene's `branch` declares: \
             move the `near` guesses towards the declared branch"
        }
        SolveError::Unresolved { .. } => {
            "a coordinate is too large to resolve: give `near` angles within a turn and \
             positions near the scene's size, and check parameters that set huge values"
        }
        SolveError::Geometry { .. } | SolveError::Physics { .. } => GEOMETRY_HINT,
        _ => "check the parameter values and the `near` guesses for divisions by zero",
    }
}

fn step_hint(error: &SolveError) -> &'static str {
    match error {
        SolveError::NoConvergence { .. } => {
            "the mechanism may stop being able to assemble here (a joint cannot close), or the \
             time step is too large: try more `--steps`"
        }
        SolveError::Singular { .. } => {
            "the mechanism reaches a singular position (dead centre or a locked joint): check \
             the dimensions, or end the run before this time"
        }
        SolveError::NoAssembly { .. } => {
            "the mechanism cannot close here (a driver beyond the reachable range?): check the \
             dimensions and the drivers, or end the run before this time"
        }
        SolveError::BranchFlip { .. } => {
            "the motion would leave the declared assembly branch (through a singular position, \
             or the steps are too coarse even after sub-stepping): try more `--steps`"
        }
        SolveError::Unresolved { .. } => {
            "a coordinate has grown too large to resolve (a driven angle after very many \
             turns?): start the run at a smaller time, or drive the angle with a periodic law"
        }
        SolveError::Geometry { .. } | SolveError::Physics { .. } => GEOMETRY_HINT,
        _ => "a value became NaN or infinite: check the parameter values and the time range",
    }
}

/// The per-step diagnostic columns of `--diagnostics`, after the kinematic ones.
pub const DIAGNOSTIC_COLUMNS: &str = "iterations,substeps,evaluations,fallbacks,condition,det_sign";

/// How `solve` writes its results. CSV: a header line, then one line per time (`t`, q, q_dot,
/// q_ddot, the reactions of a scene with forces, and with `--diagnostics` the
/// [`DIAGNOSTIC_COLUMNS`]). JSON: one document, `{"mechanism", "coordinates", "outputs",
/// ["reactions",] "states": [State…], "error"}`, each state as the runtime serialises it (`t`,
/// `q`, `q_dot`, `q_ddot`, `reactions`, `iterations`, `evaluations`, `substeps`, `condition`,
/// `fallbacks`, `det_sign`), and `error` `null` or
/// `{"step", "message", "kind"}`; written as the run goes, so a failed run still leaves a
/// complete document. (The variants' docs are the CLI's help.)
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Format {
    /// A header line, then one line per time
    #[default]
    Csv,
    /// One JSON document with every state, and the error if a step fails
    Json,
}

/// Writes one run's rows in a [`Format`].
struct Rows<'a> {
    format: Format,
    diagnostics: bool,
    out: &'a mut dyn Write,
    line: String,
    rows: usize,
}

impl Rows<'_> {
    fn start(&mut self, m: &Interpreted) -> std::io::Result<()> {
        self.line.clear();
        match self.format {
            Format::Csv => {
                // Writing to a String cannot fail.
                let _ = write_csv_header(m, &mut self.line);
                if self.diagnostics {
                    self.line.pop();
                    self.line.push(',');
                    self.line.push_str(DIAGNOSTIC_COLUMNS);
                    self.line.push('\n');
                }
            }
            Format::Json => {
                let coordinates: Vec<&str> =
                    (0..m.len()).filter_map(|i| m.coordinate_name(i)).collect();
                let mut head = serde_json::json!({
                    "mechanism": m.name(),
                    "coordinates": coordinates,
                    "outputs": m.outputs(),
                });
                let reactions: Vec<&str> =
                    (0..m.len()).filter_map(|i| m.reaction_name(i)).collect();
                if !reactions.is_empty() {
                    head["reactions"] = serde_json::json!(reactions);
                }
                let head = head.to_string();
                // `{…}` without its closing brace, then the states array.
                self.line.push_str(&head[..head.len() - 1]);
                self.line.push_str(",\"states\":[\n");
            }
        }
        self.out.write_all(self.line.as_bytes())
    }

    fn row(&mut self, state: &State<Interpreted>) -> std::io::Result<()> {
        self.line.clear();
        match self.format {
            Format::Csv => {
                let _ = state.write_csv_row(&mut self.line);
                if self.diagnostics {
                    self.line.pop();
                    let _ = write_diagnostics(state, &mut self.line);
                }
            }
            Format::Json => {
                if self.rows > 0 {
                    self.line.push_str(",\n");
                }
                // A state is numbers and arrays of numbers: it always serialises.
                self.line
                    .push_str(&serde_json::to_string(state).unwrap_or_default());
            }
        }
        self.rows += 1;
        self.out.write_all(self.line.as_bytes())
    }

    /// Ends the document (JSON), with the error that stopped the run at `step`, if any.
    fn finish(&mut self, failure: Option<(usize, &SolveError, &str)>) -> std::io::Result<()> {
        if self.format == Format::Json {
            let error = failure.map(|(step, kind, message)| {
                serde_json::json!({ "step": step, "message": message, "kind": kind })
            });
            let tail = format!("\n],\"error\":{}}}\n", serde_json::json!(error));
            self.out.write_all(tail.as_bytes())?;
        }
        self.out.flush()
    }
}

/// Writes the header and one row per time: the assembled state (at its own time), then a step
/// to each of `times`, ending the output even when a solve fails. With `diagnostics`, each
/// CSV row ends with the [`DIAGNOSTIC_COLUMNS`] of its solve (JSON states always carry them).
///
/// # Errors
/// [`RunError::Write`] when `out` fails, [`RunError::Solve`] when a step does.
pub fn run(
    simulation: &mut Simulation<Interpreted>,
    times: impl ExactSizeIterator<Item = f64>,
    format: Format,
    diagnostics: bool,
    out: &mut dyn Write,
) -> Result<Summary, RunError> {
    let mut rows = Rows {
        format,
        diagnostics,
        out,
        line: String::new(),
        rows: 0,
    };
    rows.start(simulation.solver().mechanism())
        .map_err(RunError::Write)?;
    let dim = simulation.solver().mechanism().len();
    let mut phi = DVector::zeros(dim);
    let mut summary = Summary::default();
    let mut record = |simulation: &Simulation<Interpreted>,
                      rows: &mut Rows<'_>,
                      summary: &mut Summary|
     -> Result<(), RunError> {
        let state = simulation.state();
        rows.row(state).map_err(RunError::Write)?;
        // The state does not keep the solver's residual; Φ at the returned q is that residual.
        simulation
            .solver()
            .mechanism()
            .phi(&state.q, state.t, &mut phi);
        summary.rows += 1;
        summary.iterations += state.iterations;
        summary.max_residual = summary.max_residual.max(phi.amax());
        Ok(())
    };

    record(simulation, &mut rows, &mut summary)?;
    let steps = times.len();
    for (k, t) in (1..).zip(times) {
        if let Err(error) = simulation.step_to(t) {
            let message = format!(
                "solve failed at step {k} of {steps}: {}\n  hint: {}",
                error.describe(simulation.solver().mechanism()),
                step_hint(&error)
            );
            rows.finish(Some((k, &error, &message)))
                .map_err(RunError::Write)?;
            return Err(RunError::Solve { message, summary });
        }
        record(simulation, &mut rows, &mut summary)?;
    }
    rows.finish(None).map_err(RunError::Write)?;
    Ok(summary)
}

/// `,iterations,substeps,evaluations,fallbacks,condition,det_sign` of a state, and the newline.
fn write_diagnostics(state: &State<Interpreted>, out: &mut String) -> core::fmt::Result {
    use core::fmt::Write as _;
    writeln!(
        out,
        ",{},{},{},{},{:?},{}",
        state.iterations,
        state.substeps,
        state.evaluations,
        state.fallbacks,
        state.condition,
        state.orientation
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overrides_name_the_declared_parameters() {
        let scene = mechgen::compile_str(
            "mechanism M { param w = 3; ground g at (0, 0, 0); body b near (0, 0, 0);
             joint j: revolute(g, b); driver d: angle(b) = w * t; }",
        )
        .expect("compiles");
        let mut mechanism = Interpreted::new(&scene);
        assert!(apply_sets(&mut mechanism, &[("w".into(), 5.0)]).is_ok());
        assert_eq!(mechanism.parameter(0), Some(5.0));
        let mut fresh = Interpreted::new(&scene);
        let sets = [("w".into(), 7.0), ("v".into(), 1.0)];
        let unknown = apply_sets(&mut fresh, &sets).unwrap_err();
        assert!(unknown.contains("no parameter `v`"), "{unknown}");
        assert!(unknown.contains("`w` (default 3)"), "{unknown}");
        assert_eq!(fresh.parameter(0), Some(3.0), "all or none");
        let infinite = apply_sets(&mut mechanism, &[("w".into(), f64::INFINITY)]).unwrap_err();
        assert!(infinite.contains("finite"), "{infinite}");
    }
}
