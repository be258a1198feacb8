//! Forward dynamics: the integrator that moves a scene's free degrees of freedom under its
//! forces, with the constraints exact by construction.
//!
//! Coordinate partitioning with the partition the user named (Wehage & Haug): each free degree
//! of freedom holds one driven quantity at the integrator's state `u` ([`Dynamic`]), so the
//! scene's structured kinematic solve gives `q`, `q̇`, `q̈` from `u`, `u̇`, `ü` with every
//! constraint satisfied to the solver's tolerance (positions) and round-off (velocities,
//! accelerations). The integrator moves `u` under the reduced equations of motion
//! `Vᵀ F(q, q̇, q̈, t) = 0` (`V = ∂q/∂u`, `F = Q − M q̈`) by generalized-α (Chung & Hulbert 1993;
//! Arnold & Brüls 2007), second order, with numerical damping set by ρ∞, implicit (a stiff
//! spring neither blows up nor needs a small step).
//!
//! One concept per file: the [`Integrator`] and its API (here), the method's coefficients and
//! update (`alpha.rs`), one evaluation of the reduced equations (`reduced.rs`), the step's
//! modified Newton iteration (`newton.rs`), step control and landing on requested times
//! (`control.rs`), the current state and the step's iterate (`states.rs`), the predictor's
//! history of accelerations (`history.rs`), the checks for toggles of the partition
//! (`toggle.rs`), the [`IntegratorOptions`] (`options.rs`), the [`Energy`] book (`energy.rs`)
//! and the [`DynamicsError`] (`error.rs`).

mod alpha;
mod control;
mod energy;
mod error;
mod history;
mod newton;
mod options;
mod reduced;
mod states;
mod toggle;

pub use energy::Energy;
pub use error::{DescribedDynamics, DynamicsError};
pub use options::{IntegratorOptions, StepControl};

use nalgebra::{DefaultAllocator, Dim, OVector, U1};

use self::alpha::{Alpha, FreeMotion};
use self::energy::Book;
use self::history::History;
use self::newton::{Failure, IterationMatrix};
use self::reduced::{Reduced, set_free};
use self::states::States;
use self::toggle::Watch;
use crate::assembly::GUESS_TIME;
use crate::dynamic::{Dynamic, EquationsOfMotion, FreeStorage};
#[cfg(doc)]
use crate::mechanism::Mechanism;
use crate::mechanism::{Storage, Vector};
use crate::simulate::Simulation;
use crate::solver::Solver;
use crate::state::State;
use crate::structure::Structured;

/// The integrator's work so far.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct IntegratorStats {
    /// Accepted steps.
    pub steps: usize,
    /// Rejected step attempts (error too large, or an iteration that failed).
    pub rejected: usize,
    /// Newton iterations, each one evaluation of the reduced equations: a structured solve
    /// (positions, rates and the force solve). Each accepted step, and each rebuild of the
    /// iteration matrix, adds one velocity solve per free degree of freedom (for `∂q/∂u`).
    pub iterations: usize,
    /// Factorisations of the iteration matrix.
    pub factorizations: usize,
}

/// Steps a scene with free degrees of freedom through time under its forces (see the module
/// documentation for the method).
///
/// Holds the solver, the state at the current time and a scratch state, and the free
/// coordinates' state: stepping never allocates (for `Dyn` scenes, everything is allocated by
/// [`Integrator::new`]), and a failed step leaves the current state untouched.
pub struct Integrator<M: Dynamic + EquationsOfMotion + Structured>
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    solver: Solver<M>,
    /// The state at the current time, and the iterate of the step being solved.
    states: States<M>,
    /// The free coordinates at the current time, and the step's iterate.
    now: FreeMotion<M::Free>,
    next: FreeMotion<M::Free>,
    reduced: Reduced<M>,
    matrix: IterationMatrix<M::Free>,
    /// The last Newton correction.
    correction: OVector<f64, M::Free>,
    /// The free accelerations of the last steps, for the predictor's extrapolation.
    history: History<M::Free>,
    alpha: Alpha,
    options: IntegratorOptions,
    /// The next step's size.
    step: f64,
    /// The toggle checks' bound on `‖V‖` and per-coordinate floors.
    watch: Watch<M>,
    book: Book<M>,
    stats: IntegratorStats,
}

/// A checkpoint: the copy continues from the same state, with the same history (its iteration
/// matrix, step size, energy book and statistics).
impl<M: Dynamic + EquationsOfMotion + Structured + Clone> Clone for Integrator<M>
where
    M::Workspace: Clone,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    fn clone(&self) -> Self {
        Self {
            solver: self.solver.clone(),
            states: self.states.clone(),
            now: self.now.clone(),
            next: self.next.clone(),
            reduced: self.reduced.clone(),
            matrix: self.matrix.clone(),
            correction: self.correction.clone(),
            history: self.history.clone(),
            alpha: self.alpha,
            options: self.options,
            step: self.step,
            watch: self.watch.clone(),
            book: self.book.clone(),
            stats: self.stats,
        }
    }
}

impl<M: Dynamic + EquationsOfMotion + Structured> Integrator<M>
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    /// Assembles the scene at `t0` with its free degrees of freedom at their declared values
    /// and rates ([`Dynamic::free_initial`]; a value not declared is the driven quantity's at
    /// the scene's `near` guesses), then solves the initial accelerations from the equations of
    /// motion.
    ///
    /// # Errors
    /// [`DynamicsError::BadOptions`] for an option out of range or a non-finite `t0`;
    /// [`DynamicsError::Solve`] when the scene cannot be assembled there;
    /// [`DynamicsError::SingularMass`] when a free degree of freedom moves no mass;
    /// [`DynamicsError::NonFinite`] for a non-finite initial state.
    pub fn new(
        mut solver: Solver<M>,
        t0: f64,
        options: IntegratorOptions,
    ) -> Result<Self, DynamicsError> {
        options.check()?;
        if !t0.is_finite() {
            return Err(DynamicsError::BadOptions {
                option: "t",
                value: t0,
            });
        }
        let (initial, slopes) = initial_motion(&mut solver);
        if let Some(k) = initial.first_non_finite() {
            return Err(DynamicsError::NonFinite {
                t: t0,
                step: 0.0,
                free: Some(k),
            });
        }
        let (state, solver) = assemble(solver, &initial, t0)?;
        let mut integrator = Self::with_state(solver, state, (initial, &slopes), options);
        integrator.restart()?;
        Ok(integrator)
    }

    /// The integrator's storage around an assembled `state` with free coordinates `initial`
    /// (accelerations not yet solved) and free equations of slopes `slopes`.
    fn with_state(
        solver: Solver<M>,
        state: State<M>,
        (initial, slopes): (FreeMotion<M::Free>, &OVector<f64, M::Free>),
        options: IntegratorOptions,
    ) -> Self {
        let m = solver.mechanism();
        let f = m.free();
        let mut matrix = IterationMatrix::new(f);
        control::scales(
            m.length_scale(),
            |k| m.equation_unit(m.free_equation(k)).length_power(),
            &mut matrix.scales,
        );
        let step = match options.control {
            StepControl::Fixed { step } => step,
            StepControl::Adaptive { initial, .. } => initial,
        };
        Self {
            states: States::new(state),
            now: initial.clone(),
            next: initial,
            reduced: Reduced::new(m, slopes),
            matrix,
            correction: OVector::zeros_generic(f, U1),
            history: History::new(f),
            alpha: Alpha::new(options.rho_inf),
            options,
            step,
            watch: Watch::new(m),
            book: Book::new(m),
            stats: IntegratorStats::default(),
            solver,
        }
    }

    /// Starts the motion from the free values and rates in `next` at the current time: the
    /// accelerations from the equations of motion (linear in `ü`: one solve with the reduced
    /// mass), the state solved there. On failure the current state is untouched.
    fn restart(&mut self) -> Result<(), DynamicsError> {
        let t = self.states.current().t;
        self.next.udd.fill(0.0);
        let (state, trial) = self.states.split();
        trial.copy_from(state);
        self.matrix.step = None;
        let solved = self
            .evaluate(t)
            .and_then(|()| self.refresh(0.0))
            .and_then(|()| self.correct(0.0))
            .and_then(|_| {
                self.next.udd += &self.correction;
                self.evaluate(t)
            })
            .and_then(|()| self.solve_v());
        self.matrix.step = None;
        solved.map_err(|failure| self.failure(failure, t, 0.0))?;
        self.next.a.copy_from(&self.next.udd);
        self.watch.restart(self.reduced.v.norm());
        self.reduced.accepted.copy_from(&self.reduced.v);
        self.history.restart(&self.next.udd);
        self.states.accept();
        core::mem::swap(&mut self.now, &mut self.next);
        let m = self.solver.mechanism();
        self.reduced.measure_forces(m, self.states.current());
        self.book
            .restart(m, self.states.current(), &self.reduced.forces);
        Ok(())
    }

    /// The error a failed iteration at `t` with step `h` reports.
    fn failure(&self, failure: Failure, t: f64, h: f64) -> DynamicsError {
        let m = self.solver.mechanism();
        match failure {
            Failure::Kinematics(error) => DynamicsError::Solve { t, step: h, error },
            Failure::SingularMass(k) => DynamicsError::SingularMass {
                t,
                free: k,
                equation: m.free_equation(k),
                names: m.names(),
            },
            Failure::NonFinite(free) => DynamicsError::NonFinite { t, step: h, free },
            Failure::Toggle => DynamicsError::Toggle { t, step: h },
            // A singular iteration matrix (a negative stiffness as large as the mass) is an
            // iteration that cannot go on; `Rejected` never gets here (the step control
            // reports it as `StepTooSmall`).
            Failure::SingularMatrix | Failure::Rejected => DynamicsError::NoConvergence {
                t,
                step: h,
                iterations: 0,
                residual: f64::INFINITY,
            },
            Failure::NoConvergence {
                iterations,
                residual,
            } => DynamicsError::NoConvergence {
                t,
                step: h,
                iterations,
                residual,
            },
        }
    }

    /// The current time.
    pub fn t(&self) -> f64 {
        self.states.current().t
    }

    /// The state at the current time: `q`, `q̇`, `q̈` (and the reactions) as a kinematic
    /// solve gives them at the free coordinates' state.
    pub fn state(&self) -> &State<M> {
        self.states.current()
    }

    /// `[u, u̇, ü]` of free degree of freedom `k` (declaration order); NaNs past the end.
    pub fn free_state(&self, k: usize) -> [f64; 3] {
        if k < self.now.u.len() {
            self.now.of(k)
        } else {
            [f64::NAN; 3]
        }
    }

    /// Restarts the motion at the current time with free degree of freedom `k` at `value`
    /// moving at `rate` (the others keep theirs); the accelerations are solved again. The
    /// energy book keeps its works, so [`Energy::total`] changes by the energy the new state
    /// adds.
    ///
    /// # Errors
    /// [`DynamicsError::BadOptions`] for a `k` past the end or a non-finite value or rate;
    /// otherwise as [`Integrator::new`] (the state is then unchanged).
    pub fn set_free(&mut self, k: usize, value: f64, rate: f64) -> Result<(), DynamicsError> {
        let checks = [
            ("free", k as f64, k < self.now.u.len()),
            ("value", value, value.is_finite()),
            ("rate", rate, rate.is_finite()),
        ];
        if let Some(&(option, value, _)) = checks.iter().find(|(_, _, ok)| !ok) {
            return Err(DynamicsError::BadOptions { option, value });
        }
        self.next.copy_from(&self.now);
        self.next.u[k] = value;
        self.next.ud[k] = rate;
        self.restart()
    }

    /// The energies at the current time and the works since the start.
    pub fn energy(&self) -> Energy {
        self.book.energy
    }

    /// Steps, rejections, Newton iterations and factorisations so far.
    pub fn stats(&self) -> IntegratorStats {
        self.stats
    }

    /// The solver (and through it the mechanism).
    pub fn solver(&self) -> &Solver<M> {
        &self.solver
    }

    /// Gives the solver back.
    pub fn into_solver(self) -> Solver<M> {
        self.solver
    }

    /// The options.
    pub fn options(&self) -> &IntegratorOptions {
        &self.options
    }

    /// The size of the next step (fixed, or as the error control chose it).
    pub fn step_size(&self) -> f64 {
        self.step
    }

    /// The reaction of every equation at the current state ([`Mechanism::reactions`] says
    /// what each is): the force solve `Φ_qᵀ λ = F(q, q̇, q̈, t)` of the state's motion, which
    /// the step's last evaluation ran. The efforts of the free degrees of freedom are zero up
    /// to the Newton tolerance: that is the equation of motion.
    ///
    /// # Errors
    /// None at present: every accepted state carries its force solve (the signature leaves
    /// room for solving it on demand).
    pub fn constraint_forces(&mut self) -> Result<&Vector<M::Dim>, DynamicsError> {
        Ok(self.states.current().constraint_forces())
    }

    /// Takes one accepted step (the fixed step, or the size the error control chose, retried
    /// smaller when rejected).
    ///
    /// # Errors
    /// [`DynamicsError::Solve`] when the kinematics fail (in the error-controlled mode, once
    /// the step is below its minimum), [`DynamicsError::NoConvergence`] (fixed steps),
    /// [`DynamicsError::StepTooSmall`] (error-controlled), [`DynamicsError::SingularMass`],
    /// [`DynamicsError::NonFinite`]; the state is then unchanged.
    pub fn step(&mut self) -> Result<&State<M>, DynamicsError> {
        self.advance(None)?;
        Ok(self.states.current())
    }

    /// Steps until the time is exactly `t` (the last step shortened to land on it).
    ///
    /// # Errors
    /// [`DynamicsError::BadOptions`] for a non-finite `t` or one before the current time;
    /// otherwise as [`Integrator::step`] (the state is that of the last accepted step).
    pub fn step_to(&mut self, t: f64) -> Result<&State<M>, DynamicsError> {
        self.check_target(t)?;
        let mut steps = 0;
        while self.states.current().t < t {
            self.budget(&mut steps)?;
            self.advance(Some(t))?;
        }
        Ok(self.states.current())
    }

    /// Steps until `t_end` (landing on it exactly), calling `each` with the state and the
    /// energies after every accepted step.
    ///
    /// # Errors
    /// As [`Integrator::step_to`].
    pub fn run(
        &mut self,
        t_end: f64,
        mut each: impl FnMut(&State<M>, &Energy),
    ) -> Result<(), DynamicsError> {
        self.check_target(t_end)?;
        let mut steps = 0;
        while self.states.current().t < t_end {
            self.budget(&mut steps)?;
            self.advance(Some(t_end))?;
            each(self.states.current(), &self.book.energy);
        }
        Ok(())
    }

    /// Displays `error` with the scene's names ([`DynamicsError::describe`]).
    pub fn describe<'a>(&'a self, error: &'a DynamicsError) -> DescribedDynamics<'a, M> {
        error.describe(self.solver.mechanism())
    }

    /// Counts a step of one call against [`IntegratorOptions::max_steps`].
    fn budget(&self, steps: &mut u64) -> Result<(), DynamicsError> {
        if *steps >= self.options.max_steps {
            return Err(DynamicsError::StepBudget {
                t: self.states.current().t,
                steps: *steps,
            });
        }
        *steps += 1;
        Ok(())
    }

    /// A target time must be finite and not behind.
    fn check_target(&self, t: f64) -> Result<(), DynamicsError> {
        if t.is_finite() && t >= self.states.current().t {
            Ok(())
        } else {
            Err(DynamicsError::BadOptions {
                option: "t",
                value: t,
            })
        }
    }
}

/// Assembles the scene at `t0` with the free coordinates at `initial` (as
/// [`Simulation::new`] does for a driven scene: from the `near` guesses at t = 0, the motion
/// followed to `t0`), and gives the solved state and the solver back.
fn assemble<M: Dynamic + Structured>(
    mut solver: Solver<M>,
    initial: &FreeMotion<M::Free>,
    t0: f64,
) -> Result<(State<M>, Solver<M>), DynamicsError>
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    set_free(&mut solver, initial);
    let simulation = Simulation::new(solver, t0).map_err(|f| DynamicsError::Solve {
        t: t0,
        step: 0.0,
        error: f.error,
    })?;
    let state = simulation.state().clone();
    Ok((state, simulation.into_solver()))
}

/// The declared initial values and rates of the free degrees of freedom, and each free
/// equation's slope `∂Φ_e/∂u`; a value not declared is the driven quantity at the scene's
/// `near` guesses: the free equation `g(q) − u` is affine in `u`, so two evaluations of Φ at
/// the guess (u = 0 and u = 1) give the slope and the `u` that zeroes it, whatever the
/// equation's sign convention.
fn initial_motion<M: Dynamic + Structured>(
    solver: &mut Solver<M>,
) -> (FreeMotion<M::Free>, OVector<f64, M::Free>)
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    let m = solver.mechanism_mut();
    let (n, f) = (m.dim(), m.free());
    let mut motion = FreeMotion::new(f);
    let mut slopes = OVector::zeros_generic(f, U1);
    let mut guess = Vector::zeros_generic(n, U1);
    m.initial_guess(&mut guess);
    let mut phi = [Vector::zeros_generic(n, U1), Vector::zeros_generic(n, U1)];
    for (value, phi) in phi.iter_mut().enumerate() {
        for k in 0..f.value() {
            m.set_free(k, [value as f64, 0.0, 0.0]);
        }
        m.phi(&guess, GUESS_TIME, phi);
    }
    for k in 0..f.value() {
        let (declared, rate) = m.free_initial(k);
        let e = m.free_equation(k);
        let at = |v: &Vector<M::Dim>| v.get(e).copied().unwrap_or(f64::NAN);
        let (p0, p1) = (at(&phi[0]), at(&phi[1]));
        slopes[k] = p1 - p0;
        motion.u[k] = declared.unwrap_or(-p0 / (p1 - p0));
        motion.ud[k] = rate;
    }
    (motion, slopes)
}
