//! `mechgen simulate`: moves a scene's free degrees of freedom under its forces with the
//! runtime's [`Integrator`] (generalized-α on the equations reduced to the free coordinates,
//! the constraints solved exactly at every step) and writes, at exactly each requested time,
//! the state as `solve` does, then the energies and each free coordinate's value and rate.

use std::io::Write;

use mechgen_interp::Interpreted;
use mechgen_runtime::nalgebra::Dim;
use mechgen_runtime::{
    Dynamic, DynamicsError, Integrator, IntegratorOptions, IntegratorStats, SolveError, Solver,
    StepControl,
};

use crate::args::simulate::{SimulateArgs, Stepping};
use crate::args::{self, usage_error};
use crate::failure::Failure;
use crate::hints::{assembly_hint, step_hint};
use crate::output::{Extra, Layout, Rows, Stopped};
use crate::schedule::Schedule;
use crate::session::{self, RunError, StartFailure, Summary, Tally};
use crate::words::count;

/// The energy columns, in the order of [`energies`].
const ENERGIES: [&str; 7] = [
    "energy.kinetic",
    "energy.gravity",
    "energy.springs",
    "energy.loads_work",
    "energy.drivers_work",
    "energy.dissipated",
    "energy.total",
];

/// Most fixed steps a run may take: beyond it a `--step` is a slip (a run of hours), refused
/// before it starts.
const MAX_FIXED_STEPS: f64 = 1e7;

/// Runs `mechgen simulate`: the rows to the destination, the summary line to `stderr`.
pub(crate) fn simulate(
    args: &SimulateArgs,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> Result<(), Failure> {
    let (mechanism, schedule) = session::prepare(&args.run, "simulate")?;
    let free = free_names(&mechanism)?;
    let options = options(args, &schedule)?;
    let layout = Layout::new(args.run.format, false, &mechanism, &extras(&free));
    // Start before touching the output, as `solve` assembles first.
    let started = start(mechanism, schedule.start(), options);
    let (mut integrator, mut destination) = session::open(&args.run, &layout, started, stdout)?;
    let outcome = layout
        .start(destination.writer())
        .map_err(RunError::Write)
        .and_then(|rows| run(&mut integrator, schedule.after_start(), rows));
    let stats = integrator.stats();
    session::finish(outcome, &schedule, &destination.name, stderr, |_| {
        effort(&stats)
    })
}

/// The names of the scene's free degrees of freedom; a scene without any is refused (a usage
/// error: it is `solve`'s).
fn free_names(mechanism: &Interpreted) -> Result<Vec<String>, Failure> {
    let free = Dynamic::free(mechanism).value();
    if free == 0 {
        let message = format!(
            "`{}` has no free degrees of freedom: declare one where a driver would go, \
             e.g. `free NAME: angle(body);` (any driver kind; `from VALUE` and `speed RATE` \
             set its initial state), or use `mechgen solve` for a motion the drivers prescribe",
            mechanism.name()
        );
        return Err(Failure::Usage(
            usage_error("simulate", message).render().to_string(),
        ));
    }
    Ok((0..free)
        .map(|k| {
            mechanism
                .free_name(k)
                .map_or_else(|| format!("free{k}"), str::to_owned)
        })
        .collect())
}

/// The columns after the state's: the energies, then each free coordinate's value and rate.
fn extras(free: &[String]) -> [Extra; 2] {
    let columns = free
        .iter()
        .flat_map(|name| [format!("{name}.value"), format!("{name}.rate")])
        .collect();
    [
        Extra {
            key: "energy",
            columns: ENERGIES.map(str::to_owned).to_vec(),
        },
        Extra {
            key: "free",
            columns,
        },
    ]
}

/// The integrator's options: the runtime's defaults with the flags given.
fn options(args: &SimulateArgs, schedule: &Schedule) -> Result<IntegratorOptions, Failure> {
    let mut options = IntegratorOptions::default();
    if let Some(rho_inf) = args.rho_inf {
        options.rho_inf = rho_inf;
    }
    match args.stepping {
        Stepping::Fixed { step } => {
            refuse_endless(step, schedule)?;
            options.control = StepControl::Fixed { step };
        }
        // The runtime's default control is the error-controlled one: only the tolerances
        // given replace its own.
        Stepping::Adaptive { rtol, atol } => {
            if let StepControl::Adaptive {
                rtol: default_rtol,
                atol: default_atol,
                ..
            } = &mut options.control
            {
                *default_rtol = rtol.unwrap_or(*default_rtol);
                *default_atol = atol.unwrap_or(*default_atol);
            }
        }
    }
    Ok(options)
}

/// Refuses fixed steps so small that the run would take more than [`MAX_FIXED_STEPS`].
fn refuse_endless(step: f64, schedule: &Schedule) -> Result<(), Failure> {
    let steps = (schedule.end() - schedule.start()) / step;
    if steps <= MAX_FIXED_STEPS {
        return Ok(());
    }
    let message = format!(
        "`--step {}` takes {steps:.1e} steps from t = {} to {}, more than the {MAX_FIXED_STEPS:e} \
         `mechgen simulate` takes: give a larger step, or leave out `--step` for \
         error-controlled steps",
        args::time(step),
        args::time(schedule.start()),
        args::time(schedule.end()),
    );
    Err(Failure::Usage(
        usage_error("simulate", message).render().to_string(),
    ))
}

/// The integrator at `t0`: the scene assembled with its free coordinates at their declared
/// (or guessed) values and rates, its accelerations solved.
fn start(
    mechanism: Interpreted,
    t0: f64,
    options: IntegratorOptions,
) -> Result<Integrator<Interpreted>, StartFailure> {
    // The scene names the error's terms; the solver takes the mechanism.
    let names = mechanism.clone();
    Integrator::new(Solver::new(mechanism), t0, options).map_err(|error| StartFailure {
        message: format!(
            "cannot start the simulation of `{}` at t = {}: {}\n  hint: {}",
            names.name(),
            args::time(t0),
            error.describe(&names),
            hint(&error, true)
        ),
        kind: serde_json::json!(error),
    })
}

/// Writes one row per time: the start, then the integrator stepped onto each of `times`,
/// ending the output (with the integrator's totals in JSON) even when a step fails.
///
/// # Errors
/// [`RunError::Write`] when the output fails, [`RunError::Step`] when a step does.
fn run(
    integrator: &mut Integrator<Interpreted>,
    times: impl ExactSizeIterator<Item = f64>,
    mut rows: Rows<'_>,
) -> Result<Summary, RunError> {
    let mut tally = Tally::new(integrator.solver().mechanism());
    let outputs = times.len();
    for (k, t) in (0..).zip(std::iter::once(None).chain(times.map(Some))) {
        if let Err(error) = advance(integrator, t) {
            let message = format!(
                "simulation failed at output {k} of {outputs}: {}\n  hint: {}",
                error.describe(integrator.solver().mechanism()),
                hint(&error, false)
            );
            let stopped = Stopped {
                step: k,
                kind: serde_json::json!(error),
                message: &message,
            };
            let stats = [("stats", totals(&integrator.stats()))];
            rows.finish(Some(&stopped), &stats)
                .map_err(RunError::Write)?;
            return Err(RunError::Step {
                message,
                summary: tally.summary,
            });
        }
        record(integrator, &mut rows, &mut tally).map_err(RunError::Write)?;
    }
    let stats = [("stats", totals(&integrator.stats()))];
    rows.finish(None, &stats).map_err(RunError::Write)?;
    Ok(tally.summary)
}

/// Steps onto `t` (`None`: stays at the start) and solves the reactions there.
fn advance(integrator: &mut Integrator<Interpreted>, t: Option<f64>) -> Result<(), DynamicsError> {
    if let Some(t) = t {
        integrator.step_to(t)?;
    }
    // The force solve at the state written, so that its reactions are the inverse dynamics
    // of this motion (`constraint_forces` leaves them in the state).
    integrator.constraint_forces()?;
    Ok(())
}

/// Writes the integrator's state, energies and free coordinates as a row and counts it.
fn record(
    integrator: &Integrator<Interpreted>,
    rows: &mut Rows<'_>,
    tally: &mut Tally,
) -> std::io::Result<()> {
    let free: Vec<f64> = (0..Dynamic::free(integrator.solver().mechanism()).value())
        .flat_map(|k| {
            let [value, rate, _] = integrator.free_state(k);
            [value, rate]
        })
        .collect();
    let state = integrator.state();
    rows.row(state, &[&energies(integrator), &free])?;
    tally.record(integrator.solver().mechanism(), state);
    Ok(())
}

/// The [`ENERGIES`] at the integrator's state.
fn energies(integrator: &Integrator<Interpreted>) -> [f64; 7] {
    let energy = integrator.energy();
    [
        energy.kinetic,
        energy.gravity,
        energy.springs,
        energy.loads_work,
        energy.drivers_work,
        energy.dissipated,
        energy.total(),
    ]
}

/// The integrator's totals as the JSON document's `stats`.
fn totals(stats: &IntegratorStats) -> serde_json::Value {
    serde_json::json!({
        "steps": stats.steps,
        "rejected": stats.rejected,
        "iterations": stats.iterations,
        "factorizations": stats.factorizations,
    })
}

/// What the run took, for the summary line.
fn effort(stats: &IntegratorStats) -> String {
    format!(
        "{}, {} rejected, {}, {}",
        count(stats.steps, "integrator step"),
        stats.rejected,
        count(stats.iterations, "Newton iteration"),
        count(stats.factorizations, "factorization"),
    )
}

/// What to try when the integrator fails (`start`: building its initial state).
fn hint(error: &DynamicsError, start: bool) -> &'static str {
    match error {
        DynamicsError::Solve { error, .. } if start => assembly_hint(error),
        DynamicsError::Solve { error, .. } => motion_hint(error),
        DynamicsError::Toggle { .. } => {
            "the coordinates declared `free` pass a toggle here (a slider's travel at a crank's \
             dead centre): declare free one that carries the mechanism through it, such as the \
             crank's angle, or end the run before this time"
        }
        DynamicsError::StepTooSmall { .. } => {
            "the error-controlled steps shrank below the smallest the integrator takes: the \
             motion changes too fast to follow here (a near-singular position, a very stiff \
             spring at a very tight tolerance): loosen `--rtol`/`--atol`, or take fixed steps \
             with `--step H`"
        }
        DynamicsError::NoConvergence { .. } => {
            "Newton's iteration on the equations of motion did not converge in this step: give \
             a smaller `--step`, or leave it out for error-controlled steps, which shrink where \
             the motion needs them"
        }
        DynamicsError::SingularMass { .. } => {
            "the named free degree of freedom moves no mass or inertia here: give the bodies it \
             moves a `mass` and an `inertia`, or declare another coordinate free"
        }
        DynamicsError::NonFinite { .. } => {
            "a value became NaN or infinite: check the parameter values, the loads' \
             expressions and the free coordinates' `from` and `speed`"
        }
        _ => "check `--rtol`, `--atol`, `--step` and `--rho-inf`",
    }
}

/// What to try when the kinematic solve fails along a free motion, where the declared free
/// coordinates (not drivers) hold the mechanism.
fn motion_hint(error: &SolveError) -> &'static str {
    match error {
        SolveError::Singular { .. } => {
            "the free motion reaches a position where the free coordinates no longer determine \
             the mechanism (a dead centre of the coordinate declared `free`): declare as free a \
             coordinate that stays independent through the motion, such as a crank's angle \
             rather than a slider's travel, or end the run before this time"
        }
        SolveError::NoAssembly { .. } => {
            "the free motion carries a free coordinate beyond where the mechanism closes: \
             declare as free a coordinate that covers the whole motion, such as a crank's \
             angle, or end the run before this time"
        }
        SolveError::NoConvergence { .. } | SolveError::BranchFlip { .. } => {
            "the step is too large for the constraints to follow (or the motion passes a \
             singular position): tighten `--rtol`, or give a smaller `--step`"
        }
        _ => step_hint(error),
    }
}
