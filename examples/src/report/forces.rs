//! The force solve in the report: the seed with its mass properties (`PistonCrankDynamics`)
//! solved for its reactions and driving torque at the reference setting, against the
//! closed-form inverse dynamics (`inverse_dynamics`), and what a step with forces costs next to
//! the kinematic seed step, both timed in the same interleaved passes.

use mechgen_interp::Interpreted;
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{Dense, Forces, SolveError, Storage, Structured};

use super::ReportError;
use super::methods::Method;
use super::sweep::{Plan, Setting, Timing, start};
use crate::closed_form::PistonCrank as SeedMotion;
use crate::inverse_dynamics::{MassProperties, seed_reactions};
use crate::scenes::{PistonCrank, PistonCrankDynamics};

/// The methods the force solve is reported for: the scene's structure (generated and
/// interpreted) and the dense reference.
pub const METHODS: [Method; 3] = [Method::Generated, Method::Dense, Method::Interpreted];

/// One method's force solve.
#[derive(Debug, Clone)]
pub struct ForceRow {
    /// How the equations were solved.
    pub method: Method,
    /// The largest error of any reaction or the driving torque over the revolution, relative
    /// to that quantity's largest magnitude, against the closed form; or why the run failed.
    pub error: Result<f64, String>,
    /// Time per step with the force solve (fastest stretches, as the sweep times).
    pub seconds_per_step: f64,
}

/// The force solve's section of the report.
#[derive(Debug, Clone)]
pub struct ForceReport {
    /// Where it was measured (the report's reference setting).
    pub setting: Setting,
    /// Per method.
    pub rows: Vec<ForceRow>,
    /// The kinematic seed's generated step, timed in the same passes.
    pub kinematic: f64,
}

impl ForceReport {
    /// Time per step of `method` with forces, if it ran.
    pub fn seconds(&self, method: Method) -> Option<f64> {
        self.rows
            .iter()
            .find(|r| r.method == method && r.error.is_ok())
            .map(|r| r.seconds_per_step)
    }
}

/// Measures the force solve at `plan`'s reference setting.
///
/// # Errors
/// The dynamics scene's `.mech` twin not compiling.
pub fn run(plan: &Plan) -> Result<ForceReport, ReportError> {
    let setting = plan.reference;
    let source = include_str!("../../scenes/piston_crank_dynamics.mech");
    let scene = mechgen::compile(mechgen::Input::Text(source), &mechgen::Options::default())
        .map_err(|e| ReportError::Scene(e.to_string()))?;
    let scenes = (
        PistonCrankDynamics::default(),
        Dense::new(PistonCrankDynamics::default()),
        Interpreted::new(&scene),
    );
    let period = SeedMotion::default().period();
    let errors = [
        reaction_error(&scenes.0, setting, period),
        reaction_error(&scenes.1, setting, period),
        reaction_error(&scenes.2, setting, period),
    ];
    // The three force solves and the kinematic seed, timed in passes over all four so that a
    // slow spell of the machine hits each alike.
    let mut timings: [Timing; 4] = core::array::from_fn(|_| Timing::new(setting.steps));
    // A method whose accuracy run failed is not timed (nor one whose timed run fails).
    let mut failed: [bool; 4] = core::array::from_fn(|k| errors.get(k).is_some_and(Result::is_err));
    let kinematic_seed = PistonCrank::default();
    let pending = |timings: &[Timing; 4], failed: &[bool; 4]| {
        (0..4).any(|k| !failed[k] && timings[k].wants_more(plan))
    };
    while pending(&timings, &failed) {
        for (k, timing) in timings.iter_mut().enumerate() {
            if failed[k] || !timing.wants_more(plan) {
                continue;
            }
            let timed = match k {
                0 => timing.run(&scenes.0, setting, period),
                1 => timing.run(&scenes.1, setting, period),
                2 => timing.run(&scenes.2, setting, period),
                _ => timing.run(&kinematic_seed, setting, period),
            };
            failed[k] = timed.is_err();
        }
    }
    let rows = METHODS
        .into_iter()
        .zip(errors)
        .zip(&timings)
        .map(|((method, error), timing)| ForceRow {
            method,
            error,
            seconds_per_step: timing.seconds_per_step(),
        })
        .collect();
    Ok(ForceReport {
        setting,
        rows,
        kinematic: timings[3].seconds_per_step(),
    })
}

/// The largest relative error of the reactions over one revolution at `setting`.
fn reaction_error<M>(mechanism: &M, setting: Setting, period: f64) -> Result<f64, String>
where
    M: Structured + Forces + Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    let (exact, mass) = (SeedMotion::default(), MassProperties::default());
    let describe = |e: SolveError| e.describe(mechanism).to_string();
    let mut simulation = start(mechanism, setting).map_err(describe)?;
    let mut solved: Vec<(f64, Vec<f64>)> = Vec::new();
    simulation
        .run(period, setting.steps, |state| {
            solved.push((state.t, state.constraint_forces().as_slice().to_vec()));
        })
        .map_err(describe)?;
    let reference: Vec<[f64; 15]> = solved
        .iter()
        .map(|(t, _)| seed_reactions(&exact, &mass, &exact.kinematics(*t)).in_equation_order())
        .collect();
    let worst = (0..15)
        .map(|k| {
            let scale = reference.iter().fold(1.0f64, |m, r| m.max(r[k].abs()));
            let error = solved
                .iter()
                .zip(&reference)
                .fold(0.0f64, |m, ((_, s), r)| m.max((s[k] - r[k]).abs()));
            error / scale
        })
        .fold(0.0, f64::max);
    Ok(worst)
}
