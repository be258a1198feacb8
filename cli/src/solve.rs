//! `mechgen solve`: steps a scene through time with the interpreter behind the runtime's own
//! [`Solver`] and [`Simulation`] (the code generated scenes use), writing one row per time.

use std::io::Write;

use mechgen_interp::Interpreted;
use mechgen_runtime::{GUESS_TIME, Simulation, Solver};

use crate::args::SolveArgs;
use crate::failure::Failure;
use crate::hints::{assembly_hint, step_hint};
use crate::output::{Layout, Rows, Stopped};
use crate::session::{self, RunError, StartFailure, Summary, Tally};
use crate::words::count;

/// Runs `mechgen solve`: the rows to the destination, the summary line to `stderr`.
pub(crate) fn solve(
    args: &SolveArgs,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> Result<(), Failure> {
    let (mechanism, schedule) = session::prepare(&args.run, "solve")?;
    let layout = Layout::new(args.run.format, args.diagnostics, &mechanism, &[]);
    // Assemble before touching the output, so that a scene that cannot move leaves an existing
    // CSV file as it was (a JSON document still records the failure).
    let assembled = assemble(mechanism, schedule.start());
    let (mut simulation, mut destination) = session::open(&args.run, &layout, assembled, stdout)?;
    let outcome = layout
        .start(destination.writer())
        .map_err(RunError::Write)
        .and_then(|rows| run(&mut simulation, schedule.after_start(), rows));
    session::finish(outcome, &schedule, &destination.name, stderr, |summary| {
        count(summary.iterations, "Newton iteration")
    })
}

/// Assembles `mechanism` at `t0`.
///
/// # Errors
/// The solver's error, described with the scene's names and a hint.
fn assemble(mechanism: Interpreted, t0: f64) -> Result<Simulation<Interpreted>, StartFailure> {
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
        StartFailure {
            message: format!(
                "cannot assemble `{}`{context}: {failure}\n  hint: {hint}",
                failure.solver.mechanism().name(),
            ),
            kind: serde_json::json!(failure.error),
        }
    })
}

/// Writes one row per time: the assembled state (at its own time), then a step to each of
/// `times`, ending the output even when a solve fails.
///
/// # Errors
/// [`RunError::Write`] when the output fails, [`RunError::Step`] when a step does.
fn run(
    simulation: &mut Simulation<Interpreted>,
    times: impl ExactSizeIterator<Item = f64>,
    mut rows: Rows<'_>,
) -> Result<Summary, RunError> {
    let mut tally = Tally::new(simulation.solver().mechanism());
    record(simulation, &mut rows, &mut tally)?;
    let steps = times.len();
    for (k, t) in (1..).zip(times) {
        if let Err(error) = simulation.step_to(t) {
            let message = format!(
                "solve failed at step {k} of {steps}: {}\n  hint: {}",
                error.describe(simulation.solver().mechanism()),
                step_hint(&error)
            );
            let stopped = Stopped {
                step: k,
                kind: serde_json::json!(error),
                message: &message,
            };
            rows.finish(Some(&stopped), &[]).map_err(RunError::Write)?;
            return Err(RunError::Step {
                message,
                summary: tally.summary,
            });
        }
        record(simulation, &mut rows, &mut tally)?;
    }
    rows.finish(None, &[]).map_err(RunError::Write)?;
    Ok(tally.summary)
}

/// Writes the simulation's current state as a row and counts it.
fn record(
    simulation: &Simulation<Interpreted>,
    rows: &mut Rows<'_>,
    tally: &mut Tally,
) -> Result<(), RunError> {
    let state = simulation.state();
    rows.row(state, &[]).map_err(RunError::Write)?;
    tally.record(simulation.solver().mechanism(), state);
    Ok(())
}
