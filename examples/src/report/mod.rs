//! The accuracy-against-run-time report: for every example scene with a closed form, how
//! accurate each way of solving is and what it costs, from real runs of the one runtime solver.
//!
//! [`run`] sweeps every [`Method`] over Newton tolerances, steps per revolution and the
//! predictor ([`Plan`]), measures errors against the closed form and time per step, times the
//! pieces of a step, measures the seed's force solve against its closed-form inverse dynamics
//! ([`forces`]), and writes `README.md`, one SVG work-precision diagram per scene and
//! `points.csv` into the output directory. `cargo run --release --example report` is the
//! command; the test `tests/tests/report.rs` runs it with [`Plan::quick`].
//!
//! Everything reported is measured when the report runs: rerunning changes the timings (and
//! the date), never the errors or iteration counts, which are deterministic.

pub mod chart;
pub mod criterion;
pub mod forces;
pub mod markdown;
pub mod methods;
pub mod sweep;
pub mod timing;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use mechgen_interp::Interpreted;
use mechgen_runtime::nalgebra::{Const, DefaultAllocator};
use mechgen_runtime::{Accelerations, Dense, Mechanism, SolveError, Storage, Structured};

use crate::accuracy::RelativeErrors;
use crate::closed_form::{self, Kinematics};
use crate::scenes::{FourBar, PistonCrank};

pub use methods::{AutoDiff, CentralDifference, ForwardDifference, Method, MethodError};
pub use sweep::{Measured, Plan, Point, Setting, Timing, Work};
pub use timing::{Micro, Split};

/// Command-line options of the report.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Output directory (created if missing).
    pub out: PathBuf,
    /// Few points, timed once ([`Plan::quick`]) instead of the full sweep.
    pub quick: bool,
    /// Scenes to run, by slug (`seed`, `four_bar`); empty means all.
    pub scenes: Vec<String>,
}

/// Usage line of the report binary.
pub const USAGE: &str = "usage: report [--out DIR] [--quick] [--scene seed|four_bar]...";

/// Every scene the report knows, by slug, in report order (the seed first).
pub const SCENES: [&str; 2] = ["seed", "four_bar"];

impl Options {
    /// The defaults: `report/` at the workspace root, full sweep, every scene.
    pub fn new() -> Self {
        Options {
            out: default_out(),
            quick: false,
            scenes: Vec::new(),
        }
    }

    /// Parses `--out DIR`, `--quick`, `--scene NAME` (repeatable).
    ///
    /// # Errors
    /// A message naming the unknown flag, missing value or unknown scene.
    pub fn from_args(args: impl IntoIterator<Item = String>) -> Result<Self, String> {
        let mut options = Options::new();
        let mut args = args.into_iter();
        while let Some(flag) = args.next() {
            match flag.as_str() {
                "--out" => {
                    options.out = args.next().map(PathBuf::from).ok_or("--out needs a path")?;
                }
                "--quick" => options.quick = true,
                "--scene" => {
                    let scene = args.next().ok_or("--scene needs a name")?;
                    if !SCENES.contains(&scene.as_str()) {
                        return Err(format!(
                            "unknown scene `{scene}`; scenes are {}",
                            SCENES.join(", ")
                        ));
                    }
                    options.scenes.push(scene);
                }
                other => return Err(format!("unknown argument `{other}`; {USAGE}")),
            }
        }
        Ok(options)
    }

    fn wants(&self, slug: &str) -> bool {
        self.scenes.is_empty() || self.scenes.iter().any(|s| s == slug)
    }
}

impl Default for Options {
    fn default() -> Self {
        Self::new()
    }
}

/// `report/` at the workspace root.
pub fn default_out() -> PathBuf {
    workspace_root().join("report")
}

/// The workspace root (the parent of this crate's manifest directory).
pub fn workspace_root() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    root.canonicalize().unwrap_or(root)
}

/// Where the report is, for a progress display.
#[derive(Debug, Clone)]
pub struct Progress<'a> {
    /// Units of work finished (a point's accuracy run, a point's timed runs, a method's
    /// micro-timings).
    pub done: usize,
    /// Units of work in all.
    pub total: usize,
    /// The scene being run.
    pub scene: &'a str,
    /// What is starting now (empty once `done == total`).
    pub task: String,
}

/// Why the report could not be written (a failing solve is not one: it is reported as such).
#[derive(Debug)]
pub enum ReportError {
    /// A scene's `.mech` source did not compile.
    Scene(String),
    /// A method could not be built for a scene.
    Method(MethodError),
    /// Drawing a chart failed.
    Plot(crate::plot::PlotError),
    /// Writing a file failed.
    Io(PathBuf, std::io::Error),
}

impl core::fmt::Display for ReportError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ReportError::Scene(message) => write!(f, "scene does not compile: {message}"),
            ReportError::Method(error) => error.fmt(f),
            ReportError::Plot(error) => error.fmt(f),
            ReportError::Io(path, error) => write!(f, "writing {}: {error}", path.display()),
        }
    }
}

impl std::error::Error for ReportError {}

/// A scene's sweep: every point, and the micro-timings of every method.
#[derive(Debug, Clone)]
pub struct SceneReport {
    /// Identifier (`seed`, `four_bar`), also the chart's file name.
    pub slug: &'static str,
    /// Title for headings and the chart.
    pub title: &'static str,
    /// Number of coordinates (= equations).
    pub coordinates: usize,
    /// The setting of the tables.
    pub reference: Setting,
    /// Every point, in sweep order (settings outer, methods inner).
    pub points: Vec<Point>,
    /// Per-call cost of the pieces of a step, per method, at the reference setting.
    pub micro: Vec<(Method, Result<Micro, String>)>,
}

impl SceneReport {
    /// The measurements of `method` at `setting`, if it ran and succeeded.
    pub fn measured(&self, method: Method, setting: &Setting) -> Option<&Measured> {
        self.points
            .iter()
            .find(|p| p.method == method && p.setting == *setting)
            .and_then(|p| p.outcome.as_ref().ok())
    }

    /// [`SceneReport::measured`] at the reference setting.
    pub fn at_reference(&self, method: Method) -> Option<&Measured> {
        self.measured(method, &self.reference)
    }

    /// The micro-timings of `method`, if measured.
    pub fn micro(&self, method: Method) -> Option<&Micro> {
        self.micro
            .iter()
            .find(|(m, _)| *m == method)
            .and_then(|(_, micro)| micro.as_ref().ok())
    }

    /// Where a reference step of `method` spends its time.
    pub fn split(&self, method: Method) -> Option<Split> {
        let measured = self.at_reference(method)?;
        let micro = self.micro(method)?;
        Some(Split::of_step(
            micro,
            measured.work,
            measured.seconds_per_step,
        ))
    }
}

/// The finished report.
#[derive(Debug, Clone)]
pub struct Report {
    /// The plan that was run.
    pub plan: Plan,
    /// One entry per scene run, in report order.
    pub scenes: Vec<SceneReport>,
    /// The seed's force solve (run with the seed).
    pub forces: Option<forces::ForceReport>,
    /// The output directory.
    pub out: PathBuf,
    /// Every file written.
    pub files: Vec<PathBuf>,
    /// Wall time of the whole run.
    pub elapsed: Duration,
}

impl Report {
    /// The summary table printed at the end of a run: per scene and method, the error and
    /// time per step at the reference setting and the time relative to generated code.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        for scene in &self.scenes {
            let _ = writeln!(
                s,
                "{} — {}\n{:<22} {:>10} {:>10} {:>14} {:>10}",
                scene.title,
                scene.reference,
                "method",
                "error",
                "µs/step",
                "× generated",
                "it./step"
            );
            let base = scene
                .at_reference(Method::Generated)
                .map(|m| m.seconds_per_step);
            for method in Method::ALL {
                match scene.at_reference(method) {
                    Some(m) => {
                        let ratio = base.map_or(f64::NAN, |b| m.seconds_per_step / b);
                        let _ = writeln!(
                            s,
                            "{:<22} {:>10.1e} {:>10.2} {:>14.2} {:>10.2}",
                            method.label(),
                            m.errors.max(),
                            m.seconds_per_step * 1e6,
                            ratio,
                            m.work.iterations
                        );
                    }
                    None => {
                        let _ = writeln!(s, "{:<22} {:>10}", method.label(), "failed");
                    }
                }
            }
            s.push('\n');
        }
        if let Some(forces) = &self.forces {
            let _ = writeln!(
                s,
                "Seed with masses: the force solve — {}\n{:<22} {:>10} {:>10} {:>16}",
                forces.setting, "method", "error", "µs/step", "× kinematic step"
            );
            for row in &forces.rows {
                match &row.error {
                    Ok(error) => {
                        let _ = writeln!(
                            s,
                            "{:<22} {:>10.1e} {:>10.2} {:>16.2}",
                            row.method.label(),
                            error,
                            row.seconds_per_step * 1e6,
                            row.seconds_per_step / forces.kinematic
                        );
                    }
                    Err(_) => {
                        let _ = writeln!(s, "{:<22} {:>10}", row.method.label(), "failed");
                    }
                }
            }
            s.push('\n');
        }
        let _ = writeln!(
            s,
            "report written to {} in {:.0} s",
            self.out.display(),
            self.elapsed.as_secs_f64()
        );
        s
    }
}

/// Runs the report and writes it to `options.out`, calling `progress` before each unit of work
/// and once at the end.
///
/// # Errors
/// A scene that does not compile, a chart that cannot be drawn or a file that cannot be
/// written. Failed solves are not errors: they are reported as failed points.
pub fn run(
    options: &Options,
    progress: &mut dyn FnMut(&Progress<'_>),
) -> Result<Report, ReportError> {
    let plan = if options.quick {
        Plan::quick()
    } else {
        Plan::full()
    };
    let clock = Instant::now();
    let slugs: Vec<&'static str> = SCENES.into_iter().filter(|s| options.wants(s)).collect();
    // Per point an accuracy run and its timing; per method the micro-timings.
    let units_per_scene = Method::ALL.len() * (2 * plan.settings().len() + 1);
    let with_forces = slugs.contains(&"seed");
    let mut counter = Counter {
        done: 0,
        total: slugs.len() * units_per_scene + usize::from(with_forces),
        progress,
    };

    let mut scenes = Vec::new();
    for slug in slugs {
        let report = match slug {
            "seed" => {
                let exact = closed_form::PistonCrank::default();
                run_case(
                    &Case {
                        slug,
                        title: "Seed piston-crank",
                        mechanism: PistonCrank::default(),
                        source: include_str!("../../scenes/piston_crank.mech"),
                        period: exact.period(),
                        exact: &|t| exact.kinematics(t),
                    },
                    &plan,
                    &mut counter,
                )?
            }
            _ => {
                let exact = closed_form::FourBar::default();
                run_case(
                    &Case {
                        slug,
                        title: "Crank-rocker four-bar",
                        mechanism: FourBar::default(),
                        source: include_str!("../../scenes/four_bar.mech"),
                        period: exact.period(),
                        exact: &|t| exact.kinematics(t),
                    },
                    &plan,
                    &mut counter,
                )?
            }
        };
        scenes.push(report);
    }
    let forces = if with_forces {
        counter.start("seed", "the force solve".to_owned());
        Some(forces::run(&plan)?)
    } else {
        None
    };
    (counter.progress)(&Progress {
        done: counter.total,
        total: counter.total,
        scene: "",
        task: String::new(),
    });

    let mut report = Report {
        plan,
        scenes,
        forces,
        out: options.out.clone(),
        files: Vec::new(),
        elapsed: Duration::ZERO,
    };
    report.elapsed = clock.elapsed();
    report.files = markdown::write_all(&report)?;
    Ok(report)
}

/// Counts units of work and reports them.
struct Counter<'p, 'q> {
    done: usize,
    total: usize,
    progress: &'p mut dyn FnMut(&Progress<'q>),
}

impl<'q> Counter<'_, 'q> {
    fn start(&mut self, scene: &'q str, task: String) {
        (self.progress)(&Progress {
            done: self.done,
            total: self.total,
            scene,
            task,
        });
        self.done += 1;
    }
}

/// One scene: its generated code, its `.mech` twin and its closed form.
struct Case<'a, M, const N: usize> {
    slug: &'static str,
    title: &'static str,
    mechanism: M,
    source: &'static str,
    period: f64,
    exact: &'a dyn Fn(f64) -> Kinematics<N>,
}

/// The methods for one scene, built once.
struct Methods<M: Mechanism>
where
    DefaultAllocator: Storage<M::Dim>,
{
    generated: M,
    dense: Dense<M>,
    forward: Dense<ForwardDifference<M>>,
    central: Dense<CentralDifference<M>>,
    autodiff: Dense<AutoDiff<M>>,
    interpreted: Interpreted,
}

fn run_case<M, const N: usize>(
    case: &Case<'_, M, N>,
    plan: &Plan,
    counter: &mut Counter<'_, '_>,
) -> Result<SceneReport, ReportError>
where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    let scene = mechgen::compile(
        mechgen::Input::Text(case.source),
        &mechgen::Options::default(),
    )
    .map_err(|e| ReportError::Scene(e.to_string()))?;
    let methods = Methods {
        generated: case.mechanism.clone(),
        dense: Dense::new(case.mechanism.clone()),
        forward: Dense::new(ForwardDifference::new(case.mechanism.clone())),
        central: Dense::new(CentralDifference::new(case.mechanism.clone())),
        autodiff: Dense::new(
            AutoDiff::new(case.mechanism.clone(), &scene).map_err(ReportError::Method)?,
        ),
        interpreted: Interpreted::new(&scene),
    };
    let describe = |error: SolveError| error.describe(&case.mechanism).to_string();

    // Accuracy first: one run per point, setting by setting, method by method …
    struct Run {
        method: Method,
        setting: Setting,
        accuracy: Result<(RelativeErrors, Work), SolveError>,
        timing: Timing,
        failure: Option<SolveError>,
    }
    let mut runs = Vec::new();
    for setting in plan.settings() {
        for method in Method::ALL {
            counter.start(case.slug, format!("{method}, {setting}"));
            let accuracy = methods.with(method, |m: &dyn RunSetting<N>| {
                m.accuracy(setting, case.period, case.exact)
            });
            runs.push(Run {
                method,
                setting,
                accuracy,
                timing: Timing::new(setting.steps),
                failure: None,
            });
        }
    }
    // … then the timed runs, in passes over every point of the scene: a point's runs are
    // spread over the whole sweep, so a slow spell of the machine (they last seconds on a
    // shared host) cannot spoil all of them, and it hits every method alike. Each pass also
    // times the pieces of a step once per method (the fastest pass kept), so that those
    // figures come from the same stretch of time as the steps they split.
    let mut micro: Vec<(Method, Result<Micro, String>)> = Vec::new();
    let rounds = plan.micro_batches.max(1);
    for pass in 1.. {
        let mut ran = false;
        for run in runs.iter_mut() {
            if run.accuracy.is_err() || run.failure.is_some() || !run.timing.wants_more(plan) {
                continue;
            }
            ran = true;
            let result = methods.with(run.method, |m: &dyn RunSetting<N>| {
                m.time_once(&mut run.timing, run.setting, case.period)
            });
            run.failure = result.err();
            if run.failure.is_some() || !run.timing.wants_more(plan) {
                let task = format!("timed {}, {} (pass {pass})", run.method, run.setting);
                counter.start(case.slug, task);
            }
        }
        if pass <= rounds {
            ran = true;
            for (index, method) in Method::ALL.into_iter().enumerate() {
                let timed =
                    methods.with(method, |m: &dyn RunSetting<N>| m.micro(case.period, plan));
                match micro.get_mut(index) {
                    None => micro.push((method, timed.map_err(describe))),
                    // The same solve succeeded in the first pass; should it not, keep that.
                    Some((_, Ok(best))) => {
                        if let Ok(timed) = timed {
                            *best = best.fastest(&timed);
                        }
                    }
                    Some((_, Err(_))) => {}
                }
                if pass == rounds {
                    counter.start(case.slug, format!("{method}, pieces of a step timed"));
                }
            }
        }
        if !ran {
            break;
        }
    }
    // Points that failed their accuracy run count as timed too.
    for run in runs.iter().filter(|r| r.accuracy.is_err()) {
        counter.start(case.slug, format!("{}, {} failed", run.method, run.setting));
    }
    let points = runs
        .into_iter()
        .map(|run| {
            let outcome = run
                .accuracy
                .and_then(|(errors, work)| match run.failure {
                    Some(error) => Err(error),
                    None => Ok(Measured {
                        errors,
                        seconds_per_step: run.timing.seconds_per_step(),
                        work,
                        repetitions: run.timing.repetitions,
                    }),
                })
                .map_err(describe);
            Point {
                method: run.method,
                setting: run.setting,
                outcome,
            }
        })
        .collect();

    Ok(SceneReport {
        slug: case.slug,
        title: case.title,
        coordinates: N,
        reference: plan.reference,
        points,
        micro,
    })
}

/// What the sweep does with a method, object-safe so the five mechanism types can share one
/// loop.
trait RunSetting<const N: usize> {
    fn accuracy(
        &self,
        setting: Setting,
        period: f64,
        exact: &dyn Fn(f64) -> Kinematics<N>,
    ) -> Result<(RelativeErrors, Work), SolveError>;

    fn time_once(
        &self,
        timing: &mut Timing,
        setting: Setting,
        period: f64,
    ) -> Result<(), SolveError>;

    fn micro(&self, period: f64, plan: &Plan) -> Result<Micro, SolveError>;
}

impl<M, const N: usize> RunSetting<N> for M
where
    M: Structured + Accelerations + Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    fn accuracy(
        &self,
        setting: Setting,
        period: f64,
        exact: &dyn Fn(f64) -> Kinematics<N>,
    ) -> Result<(RelativeErrors, Work), SolveError> {
        sweep::accuracy(self, setting, period, exact)
    }

    fn time_once(
        &self,
        timing: &mut Timing,
        setting: Setting,
        period: f64,
    ) -> Result<(), SolveError> {
        timing.run(self, setting, period)
    }

    fn micro(&self, period: f64, plan: &Plan) -> Result<Micro, SolveError> {
        sweep::micro(self, period, plan)
    }
}

impl<M, const N: usize> Methods<M>
where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    /// Calls `f` with the mechanism of `method`.
    fn with<R>(&self, method: Method, f: impl FnOnce(&dyn RunSetting<N>) -> R) -> R {
        match method {
            Method::Generated => f(&self.generated),
            Method::Dense => f(&self.dense),
            Method::ForwardDifference => f(&self.forward),
            Method::CentralDifference => f(&self.central),
            Method::AutoDiff => f(&self.autodiff),
            Method::Interpreted => f(&self.interpreted),
        }
    }
}
