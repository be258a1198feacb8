//! How `solve` and `simulate` write their states: CSV (a header line, then one line per state)
//! or one JSON document written as the run goes, each state with its scene's columns, then the
//! columns a command adds after them (the energies of `simulate`).

use core::fmt::Write as _;
use std::io::{self, Write};

use mechgen_interp::Interpreted;
use mechgen_runtime::{Mechanism, State, write_csv_header};

/// The per-step diagnostic columns of `solve --diagnostics`, after the kinematic ones.
pub const DIAGNOSTIC_COLUMNS: &str = "iterations,substeps,evaluations,fallbacks,condition,det_sign";

/// How results are written. CSV: a header line, then one line per time (`t`, q, q_dot,
/// q_ddot, the marker values, the reactions of a scene with forces, then the command's own
/// columns, and with `--diagnostics` the [`DIAGNOSTIC_COLUMNS`]). JSON: one document,
/// `{"mechanism", "coordinates", "outputs", ["markers",] ["reactions",] …, "states":
/// [State…], …, "error"}`, each state as the runtime serialises it (`t`, `q`, `q_dot`,
/// `q_ddot`, `markers`, `reactions`, `iterations`, `evaluations`, `substeps`, `condition`,
/// `fallbacks`, `det_sign`) with the command's own members after it, and `error` `null` or
/// `{"step", "message", "kind"}` (step 0: the start); written as the run goes, so a failed run
/// still leaves a complete document. (The variants' docs are the CLI's help.)
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Format {
    /// A header line, then one line per time
    #[default]
    Csv,
    /// One JSON document with every state, and the error if a step fails
    Json,
}

/// Columns a command writes after a state's own: in CSV, `columns` after the scene's; in
/// JSON, the member `key`, listing `columns` in the header and the values in each state.
pub(crate) struct Extra {
    pub(crate) key: &'static str,
    pub(crate) columns: Vec<String>,
}

/// What stopped a run, for the JSON document: the output step (0: the start), the runtime's
/// error as serde writes it, and the message shown on stderr.
pub(crate) struct Stopped<'a> {
    pub(crate) step: usize,
    pub(crate) kind: serde_json::Value,
    pub(crate) message: &'a str,
}

/// The format and the header of a run's output, prepared from the scene before it is
/// assembled (so that a failed start still gets its JSON document).
pub(crate) struct Layout {
    format: Format,
    diagnostics: bool,
    header: String,
    keys: Vec<&'static str>,
}

impl Layout {
    /// The layout of `m`'s states followed by `extras`; with `diagnostics`, CSV rows end with
    /// the [`DIAGNOSTIC_COLUMNS`].
    pub(crate) fn new(
        format: Format,
        diagnostics: bool,
        m: &Interpreted,
        extras: &[Extra],
    ) -> Self {
        let header = match format {
            Format::Csv => csv_header(m, extras, diagnostics),
            Format::Json => json_header(m, extras),
        };
        Self {
            format,
            diagnostics,
            header,
            keys: extras.iter().map(|extra| extra.key).collect(),
        }
    }

    pub(crate) fn format(&self) -> Format {
        self.format
    }

    /// Writes the header to `out` and returns the writer of the rows.
    pub(crate) fn start<'a>(&self, out: &'a mut dyn Write) -> io::Result<Rows<'a>> {
        out.write_all(self.header.as_bytes())?;
        Ok(Rows {
            format: self.format,
            diagnostics: self.diagnostics,
            keys: self.keys.clone(),
            out,
            line: String::new(),
            rows: 0,
        })
    }

    /// Writes the document of a run that could not start: the header, no states, and the
    /// error at step 0 (CSV has nothing to write).
    pub(crate) fn write_failed_start(
        &self,
        stopped: &Stopped<'_>,
        out: &mut dyn Write,
    ) -> io::Result<()> {
        if self.format != Format::Json {
            return Ok(());
        }
        self.start(out)?.finish(Some(stopped), &[])
    }
}

fn csv_header(m: &Interpreted, extras: &[Extra], diagnostics: bool) -> String {
    let mut line = String::new();
    // Writing to a String cannot fail.
    let _ = write_csv_header(m, &mut line);
    line.pop();
    for column in extras.iter().flat_map(|extra| &extra.columns) {
        line.push(',');
        line.push_str(column);
    }
    if diagnostics {
        line.push(',');
        line.push_str(DIAGNOSTIC_COLUMNS);
    }
    line.push('\n');
    line
}

/// `{…` of the document up to its states array, opened.
fn json_header(m: &Interpreted, extras: &[Extra]) -> String {
    let coordinates: Vec<&str> = (0..m.len()).filter_map(|i| m.coordinate_name(i)).collect();
    let mut head = serde_json::json!({
        "mechanism": m.name(),
        "coordinates": coordinates,
        "outputs": m.outputs(),
    });
    let reactions: Vec<&str> = (0..m.len()).filter_map(|i| m.reaction_name(i)).collect();
    if !reactions.is_empty() {
        head["reactions"] = serde_json::json!(reactions);
    }
    let markers: Vec<&str> = (0..).map_while(|i| m.marker_name(i)).collect();
    if !markers.is_empty() {
        head["markers"] = serde_json::json!(markers);
    }
    for extra in extras {
        head[extra.key] = serde_json::json!(extra.columns);
    }
    let head = head.to_string();
    // `{…}` without its closing brace, then the states array.
    format!("{},\"states\":[\n", &head[..head.len() - 1])
}

/// Writes one run's rows in a [`Format`].
pub(crate) struct Rows<'a> {
    format: Format,
    diagnostics: bool,
    keys: Vec<&'static str>,
    out: &'a mut dyn Write,
    line: String,
    rows: usize,
}

impl Rows<'_> {
    /// Writes `state` and the values of the layout's extra columns, one slice per [`Extra`].
    pub(crate) fn row(&mut self, state: &State<Interpreted>, extras: &[&[f64]]) -> io::Result<()> {
        debug_assert_eq!(extras.len(), self.keys.len(), "one slice per extra group");
        self.line.clear();
        match self.format {
            Format::Csv => {
                let _ = state.write_csv_row(&mut self.line);
                self.line.pop();
                for value in extras.iter().copied().flatten() {
                    // As the state's own columns: shortest round trip, −0 written as 0.
                    let _ = write!(self.line, ",{:?}", value + 0.0);
                }
                if self.diagnostics {
                    let _ = write_diagnostics(state, &mut self.line);
                }
                self.line.push('\n');
            }
            Format::Json => {
                if self.rows > 0 {
                    self.line.push_str(",\n");
                }
                // A state is numbers and arrays of numbers: it always serialises.
                let mut json = serde_json::to_string(state).unwrap_or_default();
                if !extras.is_empty() {
                    json.pop();
                    let members = self.extra_members(extras);
                    json.push_str(&members);
                    json.push('}');
                }
                self.line.push_str(&positive_zeros(&json));
            }
        }
        self.rows += 1;
        self.out.write_all(self.line.as_bytes())
    }

    /// `,"energy":[…],…` for a JSON state; the keys are the header's, in its order.
    fn extra_members(&self, extras: &[&[f64]]) -> String {
        self.keys
            .iter()
            .zip(extras)
            .map(|(key, values)| format!(",\"{key}\":{}", serde_json::json!(values)))
            .collect()
    }

    /// Ends the document (JSON) with `members` after the states (`"stats": {…}`) and the
    /// error that stopped the run, if any.
    pub(crate) fn finish(
        &mut self,
        stopped: Option<&Stopped<'_>>,
        members: &[(&str, serde_json::Value)],
    ) -> io::Result<()> {
        if self.format == Format::Json {
            let error = stopped.map(|stopped| {
                serde_json::json!({
                    "step": stopped.step, "message": stopped.message, "kind": stopped.kind
                })
            });
            let mut tail = String::from("\n]");
            for (key, value) in members {
                tail.push_str(&format!(",{}:{value}", serde_json::json!(key)));
            }
            tail.push_str(&format!(",\"error\":{}}}\n", serde_json::json!(error)));
            self.out.write_all(tail.as_bytes())?;
        }
        self.out.flush()
    }
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

/// `,iterations,substeps,evaluations,fallbacks,condition,det_sign` of a state.
fn write_diagnostics(state: &State<Interpreted>, out: &mut String) -> core::fmt::Result {
    write!(
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
    use mechgen_runtime::{Simulation, Solver};

    use super::*;

    /// A driven arm at rest, assembled at t = 0.
    fn arm() -> Simulation<Interpreted> {
        let scene = mechgen::compile(
            mechgen::Input::Text(
                "mechanism Arm { ground g at (0, 0, 0); body b near (0, 0, 0);
                 joint j: revolute(g, b); driver d: angle(b) = 0.5; }",
            ),
            &mechgen::Options::default(),
        )
        .expect("compiles");
        Simulation::new(Solver::new(Interpreted::new(&scene)), 0.0).expect("assembles")
    }

    fn extras() -> [Extra; 2] {
        let columns = |names: &[&str]| names.iter().map(|&n| n.to_owned()).collect();
        [
            Extra {
                key: "energy",
                columns: columns(&["energy.kinetic", "energy.total"]),
            },
            Extra {
                key: "free",
                columns: columns(&["swing.value"]),
            },
        ]
    }

    #[test]
    fn extra_columns_follow_the_states_own_in_csv() {
        let simulation = arm();
        let m = simulation.solver().mechanism();
        let layout = Layout::new(Format::Csv, false, m, &extras());
        let mut out = Vec::new();
        let mut rows = layout.start(&mut out).unwrap();
        rows.row(simulation.state(), &[&[1.5, -0.0], &[0.25]])
            .unwrap();
        rows.finish(None, &[("stats", serde_json::json!({"steps": 3}))])
            .unwrap();
        let csv = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 2, "{csv}");
        assert!(
            lines[0].ends_with(",energy.kinetic,energy.total,swing.value"),
            "{csv}"
        );
        assert!(lines[1].ends_with(",1.5,0.0,0.25"), "{csv}");
        let (header, row) = (lines[0].split(',').count(), lines[1].split(',').count());
        assert_eq!(header, row);
    }

    #[test]
    fn extra_members_follow_the_states_own_in_json() {
        let simulation = arm();
        let m = simulation.solver().mechanism();
        let layout = Layout::new(Format::Json, false, m, &extras());
        let mut out = Vec::new();
        let mut rows = layout.start(&mut out).unwrap();
        for _ in 0..2 {
            rows.row(simulation.state(), &[&[1.5, -0.0], &[0.25]])
                .unwrap();
        }
        let stopped = Stopped {
            step: 2,
            kind: serde_json::json!("Kind"),
            message: "stopped",
        };
        rows.finish(
            Some(&stopped),
            &[("stats", serde_json::json!({"steps": 3}))],
        )
        .unwrap();
        let document: serde_json::Value = serde_json::from_slice(&out).unwrap();
        assert_eq!(document["mechanism"], "Arm");
        assert_eq!(
            document["energy"],
            serde_json::json!(["energy.kinetic", "energy.total"])
        );
        assert_eq!(document["free"], serde_json::json!(["swing.value"]));
        let states = document["states"].as_array().unwrap();
        assert_eq!(states.len(), 2);
        assert_eq!(states[1]["energy"], serde_json::json!([1.5, 0.0]));
        assert_eq!(states[1]["free"], serde_json::json!([0.25]));
        assert_eq!(states[1]["q"], document["states"][0]["q"]);
        assert_eq!(document["stats"]["steps"], 3);
        assert_eq!(document["error"]["step"], 2);
        assert_eq!(document["error"]["kind"], "Kind");
    }

    #[test]
    fn negative_zeros_become_zeros_only_as_whole_numbers() {
        assert_eq!(
            positive_zeros(r#"{"q":[-0.0,-0.05,-0.0],"t":-0.0,"x":-10.0}"#),
            r#"{"q":[0.0,-0.05,0.0],"t":0.0,"x":-10.0}"#
        );
    }
}
