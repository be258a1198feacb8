//! The stiff and extreme cases of the stability work, each run against its closed form or its
//! exact expectation, and measured: Newton iterations per step, sub-steps, error, condition
//! estimate and time per step. `cargo run --release --example stability` prints the table; the
//! integration tests (`tests/tests/stability.rs`) hold every case to its expectation.

use std::time::Instant;

use mechgen_runtime::{
    Accelerations, Mechanism, Simulation, SolveError, Solver, SolverOptions, State, Structured,
    mechanism, nalgebra::Const,
};

use num_dual::DualNum;

use crate::accuracy::{ErrorTracker, RelativeErrors};
use crate::closed_form::{self, Kinematics};

mechanism! {
    /// The seed piston-crank with every length multiplied by `scale` and the crank driven by
    /// `θ = ω t + a sin(f t)`: the seed at another unit, speed, or oscillating.
    pub mechanism FlexiblePistonCrank {
        /// Length factor.
        param scale = 1.0;
        /// Steady crank speed (rad/s).
        param omega = 314.0;
        /// Oscillation amplitude (rad).
        param amplitude = 0.0;
        /// Oscillation frequency (rad/s).
        param frequency = 0.0;

        ground liner at (156.8 * scale, 0, 0);
        body piston near (130 * scale, 0, 0);
        body rod near (29 * scale, 72 * scale, -2.35);
        body crank near (0, 0, 0);
        ground bearing at (0, 0, 0);

        joint crank_pin: revolute(rod @ (41.3 * scale, 0), crank @ (0, 43 * scale));
        joint piston_pin: revolute(piston @ (-28 * scale, 0), rod @ (0, 102.6 * scale));
        joint main_bearing: revolute(crank, bearing);
        joint slide: prismatic(liner, piston, along (1, 0));

        driver crank_angle: angle(crank) = omega * t + amplitude * sin(frequency * t);

        /// The piston pin stays on the liner side of the crank pin.
        branch piston_outboard: dot(bearing -> liner, rod @ (41.3 * scale, 0) -> rod @ (0, 102.6 * scale)) > 0;
    }
}

mechanism! {
    /// An in-line slider-crank with a crank of radius `r` and a rod of length `l`
    /// (`closed_form::SliderCrank`): near or at a toggle position when `l` is close to `r`.
    pub mechanism SliderCrank {
        /// Crank radius.
        param r = 1.0;
        /// Rod length.
        param l = 2.0;
        /// Crank speed (rad/s).
        param omega = 1.0;

        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body rod near (r, 0, 0);
        body slider near (r + l, 0, 0);

        joint pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (r, 0), rod);
        joint wrist_pin: revolute(rod @ (l, 0), slider);
        joint slide: prismatic(frame, slider, along (1, 0));

        driver turn: angle(crank) = omega * t;

        /// The slider stays ahead of the crank pin.
        branch slider_ahead: dot(frame -> frame @ (1, 0), rod -> rod @ (l, 0)) > 0;
    }
}

mechanism! {
    /// A four-bar whose links cannot close: the frame is 100 long, the others 10, 20 and 20.
    pub mechanism Unclosable {
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body coupler near (10, 0, 0);
        body rocker near (100, 0, 3);

        joint pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (10, 0), coupler);
        joint rocker_pin: revolute(coupler @ (20, 0), rocker @ (20, 0));
        joint rocker_pivot: revolute(rocker, frame @ (100, 0));

        driver turn: angle(crank) = t;
    }
}

mechanism! {
    /// A parallelogram with a third, parallel crank: its six pins over-constrain the three
    /// cranks and the coupler by one equation that only the geometry makes consistent. Gruebler
    /// counts zero degrees of freedom (so no driver); the linkage actually moves.
    pub mechanism Parallelogram {
        ground frame at (0, 0, 0);
        body left near (0, 0, 1);
        body middle near (1, 0, 1);
        body right near (2, 0, 1);
        body coupler near (0.54, 0.84, 0);

        joint left_pivot: revolute(frame, left);
        joint middle_pivot: revolute(frame @ (1, 0), middle);
        joint right_pivot: revolute(frame @ (2, 0), right);
        joint left_pin: revolute(left @ (1, 0), coupler);
        joint middle_pin: revolute(middle @ (1, 0), coupler @ (1, 0));
        joint right_pin: revolute(right @ (1, 0), coupler @ (2, 0));
    }
}

/// What one case measured.
#[derive(Debug, Clone, Copy)]
pub struct Measured {
    /// Time steps requested.
    pub steps: usize,
    /// Newton iterations over all steps (sub-steps included), and the most in one step.
    pub iterations: usize,
    /// The most Newton iterations one step needed.
    pub max_iterations: usize,
    /// Sub-steps taken over all steps (= `steps` when none was split).
    pub substeps: usize,
    /// Errors against the closed form (relative to each quantity's largest magnitude).
    pub errors: RelativeErrors,
    /// Largest condition estimate of the scaled Φ_q along the motion.
    pub max_condition: f64,
    /// Wall time per step, µs (with the closed-form comparison excluded).
    pub micros_per_step: f64,
    /// The first failure, if the motion did not complete.
    pub failure: Option<SolveError>,
}

impl Measured {
    /// Mean Newton iterations per requested step.
    pub fn iterations_per_step(&self) -> f64 {
        self.iterations as f64 / self.steps.max(1) as f64
    }
}

/// Runs `mechanism` from `t = 0` to `t_end` in `steps` equal steps and compares every state with
/// `exact`; the comparison runs after the timed loop.
pub fn run<M, const N: usize>(
    mechanism: M,
    options: SolverOptions,
    t_end: f64,
    steps: usize,
    exact: impl Fn(f64) -> Kinematics<N>,
) -> Measured
where
    M: Structured<Dim = Const<N>> + Accelerations,
{
    let mut states: Vec<State<M>> = Vec::with_capacity(steps + 1);
    let started = Instant::now();
    let result = Simulation::new(Solver::with_options(mechanism, options), 0.0)
        .map_err(SolveError::from)
        .and_then(|mut s| s.run(t_end, steps, |state| states.push(state.clone())));
    let micros_per_step = started.elapsed().as_secs_f64() * 1e6 / (steps + 1) as f64;
    let mut tracker = ErrorTracker::new();
    let mut measured = Measured {
        steps,
        iterations: 0,
        max_iterations: 0,
        substeps: 0,
        errors: RelativeErrors::default(),
        max_condition: 0.0,
        micros_per_step,
        failure: result.err(),
    };
    for state in states.iter().skip(1) {
        measured.iterations += state.iterations;
        measured.max_iterations = measured.max_iterations.max(state.iterations);
        measured.substeps += state.substeps;
    }
    for state in &states {
        measured.max_condition = measured.max_condition.max(state.condition);
        tracker.add(
            state.q.as_slice(),
            state.qd().as_slice(),
            state.qdd().as_slice(),
            &exact(state.t),
        );
    }
    measured.errors = tracker.errors();
    measured
}

/// The seed at length factor `scale` and crank speed `omega`, one revolution in `steps` steps.
pub fn scaled_seed(scale: f64, omega: f64, steps: usize) -> Measured {
    let exact = closed_form::PistonCrank {
        scale,
        omega,
        ..closed_form::PistonCrank::default()
    };
    let scene = FlexiblePistonCrank {
        scale,
        omega,
        ..FlexiblePistonCrank::default()
    };
    run(
        scene,
        SolverOptions::default(),
        exact.period(),
        steps,
        |t| exact.kinematics(t),
    )
}

/// The seed's crank oscillating as `θ = a sin(f t)` over `periods` periods, `steps` per period.
pub fn oscillating_seed(amplitude: f64, frequency: f64, periods: usize, steps: usize) -> Measured {
    let exact = closed_form::PistonCrank::default();
    let scene = FlexiblePistonCrank {
        omega: 0.0,
        amplitude,
        frequency,
        ..FlexiblePistonCrank::default()
    };
    let period = core::f64::consts::TAU / frequency;
    run(
        scene,
        SolverOptions::default(),
        periods as f64 * period,
        periods * steps,
        |t| {
            closed_form::differentiate(
                |t| exact.positions_at_angle((t * frequency).sin() * amplitude),
                t,
            )
        },
    )
}

/// The slider-crank with rod `l` and crank `r`, one revolution at ω = 1 in `steps` steps.
pub fn slider_crank(r: f64, l: f64, steps: usize) -> Measured {
    let exact = closed_form::SliderCrank {
        crank: r,
        rod: l,
        omega: 1.0,
    };
    let scene = SliderCrank {
        r,
        l,
        ..SliderCrank::default()
    };
    run(
        scene,
        SolverOptions::default(),
        exact.period(),
        steps,
        |t| exact.kinematics(t),
    )
}

/// Solves the seed once at `t` from a guess with every moving body at the origin, unrotated.
pub fn seed_from_origin(t: f64) -> Result<State<crate::scenes::PistonCrank>, SolveError> {
    let scene = crate::scenes::PistonCrank::default();
    let mut guess = mechgen_runtime::Vector::<Const<15>>::zeros();
    scene.initial_guess(&mut guess);
    // Keep the ground bodies' poses (liner, bearing); move piston, rod and crank to the origin.
    for k in 3..12 {
        guess[k] = 0.0;
    }
    Solver::new(scene).solve(t, &guess)
}
