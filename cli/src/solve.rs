//! `mechgen solve`: steps a scene through time with the interpreter behind the runtime's own
//! [`Solver`] and [`Simulation`] (the code generated scenes use), writing one CSV row per time.

use std::io::Write;

use mechgen_interp::Interpreted;
use mechgen_runtime::nalgebra::DVector;
use mechgen_runtime::{
    GUESS_TIME, Mechanism, Quantity, Simulation, SolveError, Solver, State, write_csv_header,
};

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

/// Why `--set` overrides were refused.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SetError {
    /// A name the scene does not declare: a bad command line (exit status 2).
    Unknown(String),
    /// A value the scene refuses.
    Invalid(String),
}

impl core::fmt::Display for SetError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SetError::Unknown(message) | SetError::Invalid(message) => f.write_str(message),
        }
    }
}

/// Sets the `--set` overrides on `mechanism`, all or none.
///
/// # Errors
/// A message naming the bad override, suggesting the declared name closest to a misspelt one
/// and listing the parameters the scene declares.
pub fn apply_sets(mechanism: &mut Interpreted, sets: &[(String, f64)]) -> Result<(), SetError> {
    // Checked before any is set, so that the list in the message shows the scene's defaults.
    for (name, value) in sets {
        let names: Vec<&str> = (0..mechanism.parameter_count())
            .filter_map(|i| mechanism.parameter_name(i))
            .collect();
        if mechanism.derived_parameter_names().contains(name) {
            return Err(SetError::Unknown(format!(
                "`--set {name}={value}`: `{name}` is a derived parameter, computed from others \
                 (`mechgen check FILE` shows it): set the parameters it is computed from; {}",
                declared_parameters(mechanism)
            )));
        }
        if !names.contains(&name.as_str()) {
            let hint = mechgen::check::did_you_mean(name, names.iter().copied())
                .map(|close| format!("did you mean `{close}`? "))
                .unwrap_or_default();
            return Err(SetError::Unknown(format!(
                "`--set {name}={value}`: the scene declares no parameter `{name}`; {hint}{}",
                declared_parameters(mechanism)
            )));
        }
        if !value.is_finite() {
            return Err(SetError::Invalid(format!(
                "`--set {name}={value}`: parameter values must be finite numbers; {}",
                declared_parameters(mechanism)
            )));
        }
    }
    for (name, value) in sets {
        mechanism
            .set_parameter(name, *value)
            .map_err(|error| SetError::Invalid(format!("`--set {name}={value}`: {error}")))?;
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

/// A scene that could not be assembled: what to tell the user, and what a JSON document
/// records of it.
pub struct Unassembled {
    /// The solver's error, described with the scene's names and a hint.
    pub message: String,
    /// The solver's error.
    pub error: SolveError,
    /// The scene, for the document's header.
    pub mechanism: Interpreted,
}

/// Assembles `mechanism` at `t0`.
///
/// # Errors
/// The solver's error, described with the scene's names and a hint.
pub fn assemble(
    mechanism: Interpreted,
    t0: f64,
) -> Result<Simulation<Interpreted>, Box<Unassembled>> {
    Simulation::new(Solver::new(mechanism), t0).map_err(|failure| {
        // Between t = 0 and t0 the failure is a step of the motion followed to the start.
        let time = failure.error.time().unwrap_or(t0);
        let (context, hint) = if time != t0 && time != GUESS_TIME {
            (
                format!(
                    " at t0 = {t0} (the `near` guesses describe t = 0; following the motion \
                     from there, it stopped at t = {time})"
                ),
                step_hint(&failure.error),
            )
        } else {
            (String::new(), assembly_hint(&failure.error))
        };
        let message = format!(
            "cannot assemble `{}`{context}: {failure}\n  hint: {hint}",
            failure.solver.mechanism().name(),
        );
        Box::new(Unassembled {
            message,
            error: failure.error,
            mechanism: failure.solver.into_mechanism(),
        })
    })
}

/// Writes the JSON document of a run that could not assemble: the header, no states, and the
/// error at step 0 (CSV has nothing to write).
///
/// # Errors
/// Whatever `out` returns.
pub fn write_unassembled(
    failure: &Unassembled,
    format: Format,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    if format != Format::Json {
        return Ok(());
    }
    let mut rows = Rows {
        format,
        diagnostics: false,
        out,
        line: String::new(),
        rows: 0,
    };
    rows.start(&failure.mechanism)?;
    rows.finish(Some((0, &failure.error, &failure.message)))
}

const GEOMETRY_HINT: &str = "change the named parameter with `--set NAME=VALUE` (its default is in the scene; \
     `mechgen check FILE` lists the parameters)";

const LOAD_HINT: &str = "the named load is not finite at this time: check its expression and the \
     parameters it reads (with `--set NAME=VALUE`); a spring with a free length or damping needs \
     its ends apart";

fn assembly_hint(error: &SolveError) -> &'static str {
    match error {
        SolveError::NoConvergence { .. } => {
            "no solution found from these guesses (the residual was still decreasing): move \
             the `near (x, y, angle)` guesses of the bodies in the named equation's joint \
             closer to an assembled pose"
        }
        SolveError::Singular { .. } => {
            "the named equation is redundant or conflicts with others at this pose: check the \
             joints, or move the `near` guesses away from a dead-centre position"
        }
        SolveError::NoAssembly { .. } => {
            "the residual above is a minimum no direction reduces (a guess with links in line \
             is left along its free direction, so the guesses' shape is not the cause): the \
             joints cannot all close with these dimensions; check the lengths, the parameters \
             and the drivers' values at the start time"
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
        SolveError::Unreachable { .. } => {
            "start the run nearer t = 0 (`--t0`), or write the drivers so that the motion of \
             interest starts near t = 0"
        }
        SolveError::NonFinite {
            quantity: Quantity::LoadValue(_) | Quantity::SpringEnds(_),
            ..
        } => LOAD_HINT,
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
        SolveError::NonFinite {
            quantity: Quantity::LoadValue(_) | Quantity::SpringEnds(_),
            ..
        } => LOAD_HINT,
        _ => "a value became NaN or infinite: check the parameter values and the time range",
    }
}

/// The per-step diagnostic columns of `--diagnostics`, after the kinematic ones.
pub const DIAGNOSTIC_COLUMNS: &str = "iterations,substeps,evaluations,fallbacks,condition,det_sign";

/// How `solve` writes its results. CSV: a header line, then one line per time (`t`, q, q_dot,
/// q_ddot, the marker values, the reactions of a scene with forces, and with `--diagnostics`
/// the [`DIAGNOSTIC_COLUMNS`]). JSON: one document, `{"mechanism", "coordinates", "outputs",
/// ["markers",] ["reactions",] "states": [State…], "error"}`, each state as the runtime
/// serialises it (`t`, `q`, `q_dot`, `q_ddot`, `markers`, `reactions`, `iterations`,
/// `evaluations`, `substeps`, `condition`, `fallbacks`, `det_sign`), and `error` `null` or
/// `{"step", "message", "kind"}` (step 0: the assembly); written as the run goes, so a failed
/// run still leaves a complete document. (The variants' docs are the CLI's help.)
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
                let markers: Vec<&str> = (0..).map_while(|i| m.marker_name(i)).collect();
                if !markers.is_empty() {
                    head["markers"] = serde_json::json!(markers);
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
                let json = serde_json::to_string(state).unwrap_or_default();
                self.line.push_str(&positive_zeros(&json));
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

/// `json` with every number −0.0 written as 0.0 (a velocity of −0 reads as a sign where there
/// is none; CSV rows do the same). serde_json writes −0 as `-0.0`, between delimiters.
fn positive_zeros(json: &str) -> String {
    let mut out = String::with_capacity(json.len());
    let mut rest = json;
    while let Some(at) = rest.find("-0.0") {
        let before = rest[..at]
            .chars()
            .next_back()
            .or_else(|| out.chars().next_back());
        let after = rest[at + 4..].chars().next();
        out.push_str(&rest[..at]);
        let number =
            matches!(before, Some('[' | ',' | ':')) && matches!(after, Some(',' | ']' | '}'));
        out.push_str(if number { "0.0" } else { "-0.0" });
        rest = &rest[at + 4..];
    }
    out.push_str(rest);
    out
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
    fn negative_zeros_become_zeros_only_as_whole_numbers() {
        assert_eq!(
            positive_zeros(r#"{"q":[-0.0,-0.05,-0.0],"t":-0.0,"x":-10.0}"#),
            r#"{"q":[0.0,-0.05,0.0],"t":0.0,"x":-10.0}"#
        );
    }

    #[test]
    fn overrides_name_the_declared_parameters() {
        let scene = mechgen::compile(
            mechgen::Input::Text(
                "mechanism M { param w = 3; ground g at (0, 0, 0); body b near (0, 0, 0);
             joint j: revolute(g, b); driver d: angle(b) = w * t; }",
            ),
            &mechgen::Options::default(),
        )
        .expect("compiles");
        let mut mechanism = Interpreted::new(&scene);
        assert!(apply_sets(&mut mechanism, &[("w".into(), 5.0)]).is_ok());
        assert_eq!(mechanism.parameter(0), Some(5.0));
        let mut fresh = Interpreted::new(&scene);
        let sets = [("w".into(), 7.0), ("v".into(), 1.0)];
        let unknown = apply_sets(&mut fresh, &sets).unwrap_err().to_string();
        assert!(unknown.contains("no parameter `v`"), "{unknown}");
        assert!(unknown.contains("`w` (default 3)"), "{unknown}");
        assert_eq!(fresh.parameter(0), Some(3.0), "all or none");
        let infinite = apply_sets(&mut mechanism, &[("w".into(), f64::INFINITY)])
            .unwrap_err()
            .to_string();
        assert!(infinite.contains("finite"), "{infinite}");
    }
}
