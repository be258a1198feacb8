//! The sweep: every method over the solver settings, each point one real run over a revolution
//! (errors against the closed form, Newton iterations) and repeated timed runs (cost per step).

use std::hint::black_box;
use std::time::{Duration, Instant};

use mechgen_runtime::{
    Accelerations, Simulation, SolveError, Solver, SolverOptions, State, Structured, sample_time,
};

use crate::accuracy::{ErrorTracker, RelativeErrors};
use crate::closed_form::Kinematics;

use super::methods::Method;
use super::timing::{self, Micro};

/// Steps per timed stretch (see [`Timing`]): a few hundred microseconds, so the clock reads
/// (~20 ns each) are lost in the noise.
pub const CHUNK: usize = 100;

/// One solver setting.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setting {
    /// Newton tolerance, used for both the residual and the step test.
    pub tolerance: f64,
    /// Equal steps per revolution.
    pub steps: usize,
    /// Second-order predictor on (otherwise each solve starts from the last positions).
    pub predictor: bool,
}

impl Setting {
    /// The solver options of this setting (default iteration cap and pivot tolerance).
    pub fn options(&self) -> SolverOptions {
        SolverOptions {
            residual_tolerance: self.tolerance,
            step_tolerance: self.tolerance,
            ..SolverOptions::default()
        }
    }
}

impl core::fmt::Display for Setting {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "tol {:.0e}, {} steps/rev, predictor {}",
            self.tolerance,
            self.steps,
            if self.predictor { "on" } else { "off" }
        )
    }
}

/// Which settings a report sweeps, and how hard it times them.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Whether this is [`Plan::quick`] (said so in the report).
    pub quick: bool,
    /// Newton tolerances swept at the reference steps with the predictor on.
    pub tolerances: Vec<f64>,
    /// Steps per revolution swept at the reference tolerance, predictor on and off.
    pub steps: Vec<usize>,
    /// The setting of the tables: tolerance, steps and predictor.
    pub reference: Setting,
    /// Timed runs per point: at least this many …
    pub min_repetitions: usize,
    /// … and more, up to this many, while the point's timed runs total less than `budget`.
    pub max_repetitions: usize,
    /// Timing budget per point.
    pub budget: Duration,
    /// Batch length of the micro-timings.
    pub micro_batch: Duration,
    /// Rounds of micro-timings over the methods, one per pass of the timed runs (the fastest
    /// is kept).
    pub micro_batches: usize,
}

impl Plan {
    /// The full report: tolerances 1e-4 … 1e-14, 36 … 36,000 steps per revolution.
    pub fn full() -> Self {
        Plan {
            quick: false,
            tolerances: vec![1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14],
            steps: vec![36, 360, 3600, 36_000],
            reference: Setting {
                tolerance: 1e-12,
                steps: 360,
                predictor: true,
            },
            min_repetitions: 3,
            max_repetitions: 30,
            budget: Duration::from_millis(150),
            micro_batch: Duration::from_millis(1),
            micro_batches: 20,
        }
    }

    /// A few points, timed once: for tests and a smoke run (seconds even in a debug build).
    pub fn quick() -> Self {
        Plan {
            quick: true,
            tolerances: vec![1e-4, 1e-8, 1e-12],
            steps: vec![36, 72],
            reference: Setting {
                tolerance: 1e-12,
                steps: 36,
                predictor: true,
            },
            min_repetitions: 1,
            max_repetitions: 1,
            budget: Duration::ZERO,
            micro_batch: Duration::from_micros(200),
            micro_batches: 1,
        }
    }

    /// Every setting in sweep order: the tolerance sweep, then the steps sweep (predictor on,
    /// then off), without repeating the reference.
    pub fn settings(&self) -> Vec<Setting> {
        let reference = self.reference;
        let mut settings: Vec<Setting> = self
            .tolerances
            .iter()
            .map(|&tolerance| Setting {
                tolerance,
                ..reference
            })
            .collect();
        for predictor in [true, false] {
            for &steps in &self.steps {
                let setting = Setting {
                    steps,
                    predictor,
                    ..reference
                };
                if !settings.contains(&setting) {
                    settings.push(setting);
                }
            }
        }
        if !settings.contains(&reference) {
            settings.push(reference);
        }
        settings
    }
}

/// What one run measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Max errors of q, q̇, q̈ over the revolution, relative to their largest magnitudes.
    pub errors: RelativeErrors,
    /// Wall time per step, seconds ([`Timing::seconds_per_step`]).
    pub seconds_per_step: f64,
    /// Mean work per step.
    pub work: Work,
    /// Timed runs.
    pub repetitions: usize,
}

/// Mean solver work per step of a run (assembly excluded).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Work {
    /// Newton updates ([`mechgen_runtime::State::iterations`]).
    pub iterations: f64,
    /// Block Jacobian evaluations and factorisations, summed over the blocks
    /// ([`mechgen_runtime::State::evaluations`]).
    pub evaluations: f64,
}

/// One point of the sweep: a method at a setting, and what happened.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// The method.
    pub method: Method,
    /// The setting.
    pub setting: Setting,
    /// The measurements, or the solver's failure described.
    pub outcome: Result<Measured, String>,
}

/// The accuracy half of a point: one run over the revolution, every state compared with the
/// closed form. Returns the errors and the mean work per step (assembly excluded).
///
/// # Errors
/// The first [`SolveError`] (with its time).
pub fn accuracy<M, const N: usize>(
    mechanism: &M,
    setting: Setting,
    period: f64,
    exact: &dyn Fn(f64) -> Kinematics<N>,
) -> Result<(RelativeErrors, Work), SolveError>
where
    M: Structured + Accelerations + Clone,
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    let mut simulation = start(mechanism, setting)?;
    let mut tracker = ErrorTracker::new();
    let (mut iterations, mut evaluations, mut first) = (0usize, 0usize, true);
    simulation.run(period, setting.steps, |state| {
        tracker.add(
            state.q.as_slice(),
            state.qd().as_slice(),
            state.qdd().as_slice(),
            &exact(state.t),
        );
        // The first visit is the assembly from the declared guess, not a step.
        if !first {
            iterations += state.iterations;
            evaluations += state.evaluations;
        }
        first = false;
    })?;
    let steps = setting.steps.max(1) as f64;
    Ok((
        tracker.errors(),
        Work {
            iterations: iterations as f64 / steps,
            evaluations: evaluations as f64 / steps,
        },
    ))
}

/// Fastest time seen so far for each stretch of [`CHUNK`] steps of a revolution.
///
/// Each timed run is read every [`CHUNK`] steps; per stretch the fastest run counts, and the
/// stretches are summed. Like best-of-runs this drops interruptions by the rest of the machine,
/// but per stretch, so one busy moment does not spoil a whole long run; and since a stretch is
/// always the same part of the motion, its Newton iterations are the same in every run (no bias
/// towards easy stretches).
#[derive(Debug, Clone, PartialEq)]
pub struct Timing {
    fastest: Vec<f64>,
    steps: usize,
    /// Timed runs so far.
    pub repetitions: usize,
    /// Their total wall time.
    pub total: Duration,
}

impl Timing {
    /// No runs yet, for `steps` steps per run.
    pub fn new(steps: usize) -> Self {
        Timing {
            fastest: vec![f64::INFINITY; steps.div_ceil(CHUNK).max(1)],
            steps,
            repetitions: 0,
            total: Duration::ZERO,
        }
    }

    /// Whether `plan` wants another run: below its minimum, or below its maximum and budget.
    pub fn wants_more(&self, plan: &Plan) -> bool {
        self.repetitions < plan.min_repetitions.max(1)
            || (self.total < plan.budget && self.repetitions < plan.max_repetitions)
    }

    /// Seconds per step: the fastest stretches summed, over the steps (infinite before any run).
    pub fn seconds_per_step(&self) -> f64 {
        self.fastest.iter().sum::<f64>() / self.steps.max(1) as f64
    }

    /// One timed run of `mechanism` over the revolution (assembly excluded), stepping exactly
    /// as `Simulation::run` does (the same [`sample_time`]s).
    ///
    /// # Errors
    /// A [`SolveError`] of the run (the accuracy run would have met it first).
    pub fn run<M>(&mut self, mechanism: &M, setting: Setting, period: f64) -> Result<(), SolveError>
    where
        M: Structured + Accelerations + Clone,
        mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
    {
        let mut simulation = start(mechanism, setting)?;
        let steps = setting.steps;
        let run = Instant::now();
        let mut chunk = Instant::now();
        for k in 1..=steps {
            black_box(simulation.step_to(sample_time(0.0, period, steps, k))?);
            if k % CHUNK == 0 || k == steps {
                let seconds = chunk.elapsed().as_secs_f64();
                if let Some(best) = self.fastest.get_mut((k - 1) / CHUNK) {
                    *best = best.min(seconds);
                }
                chunk = Instant::now();
            }
        }
        self.total += run.elapsed();
        self.repetitions += 1;
        Ok(())
    }
}

/// A simulation of `mechanism` at `setting`, assembled at t = 0.
pub(super) fn start<M>(mechanism: &M, setting: Setting) -> Result<Simulation<M>, SolveError>
where
    M: Structured + Accelerations + Clone,
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    let solver = Solver::with_options(mechanism.clone(), setting.options());
    let mut simulation = Simulation::new(solver, 0.0)?;
    simulation.set_predictor(setting.predictor);
    Ok(simulation)
}

/// One point on its own: [`accuracy`], then timed runs until the plan is satisfied. (The
/// report interleaves the timed runs of all methods instead, see `report::run`.)
///
/// # Errors
/// The first [`SolveError`].
pub fn run_setting<M, const N: usize>(
    mechanism: &M,
    setting: Setting,
    period: f64,
    exact: &dyn Fn(f64) -> Kinematics<N>,
    plan: &Plan,
) -> Result<Measured, SolveError>
where
    M: Structured + Accelerations + Clone,
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    let (errors, work) = accuracy(mechanism, setting, period, exact)?;
    let mut timing = Timing::new(setting.steps);
    while timing.wants_more(plan) {
        timing.run(mechanism, setting, period)?;
    }
    Ok(Measured {
        errors,
        seconds_per_step: timing.seconds_per_step(),
        work,
        repetitions: timing.repetitions,
    })
}

/// The micro-timings of `mechanism` at a solved state a tenth of a revolution in (where the
/// criterion benchmarks evaluate too), at the reference setting: one batch per piece (the
/// report keeps the fastest of [`Plan::micro_batches`] rounds).
///
/// # Errors
/// A [`SolveError`] reaching that state.
pub fn micro<M>(mechanism: &M, period: f64, plan: &Plan) -> Result<Micro, SolveError>
where
    M: Structured + Accelerations + Clone,
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    let state = state_at(mechanism, 0.1 * period, plan.reference.options())?;
    Ok(timing::measure(
        mechanism,
        &state.q,
        state.qd(),
        state.t,
        plan.micro_batch,
        1,
    ))
}

/// Assembles `mechanism` and solves it at `t`.
fn state_at<M>(mechanism: &M, t: f64, options: SolverOptions) -> Result<State<M>, SolveError>
where
    M: Structured + Accelerations + Clone,
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    let solver = Solver::with_options(mechanism.clone(), options);
    let mut simulation = Simulation::new(solver, 0.0)?;
    let state = simulation.step_to(t)?;
    Ok(state.clone())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_cover_both_sweeps_once() {
        let plan = Plan::full();
        let settings = plan.settings();
        assert_eq!(settings.len(), 6 + 2 * 4 - 1);
        assert_eq!(settings[4], plan.reference);
        assert!(settings.iter().any(|s| s.steps == 36_000 && !s.predictor));
        let quick = Plan::quick().settings();
        assert!(quick.contains(&Plan::quick().reference));
    }
}
