//! The [`Solver`] type and its public methods: one instant's positions, rates and forces,
//! and the lists behind a [`SolveError::Singular`].

use nalgebra::DefaultAllocator;

use super::convergence::Convergence;
use super::sweep::Extras;

use crate::dynamic::{Dynamic, FreeStorage};
use crate::error::{Described, Quantity, SolveError};
use crate::mechanism::{Accelerations, LengthScale, Storage, Vector, Velocities};
use crate::options::{Rates, SolverOptions};
use crate::state::State;
use crate::step::StepContext;
use crate::structure::Structured;
use crate::workspace::Workspace;

/// Kinematic solver owning a mechanism and every buffer it needs.
///
/// All storage is created by [`Solver::new`]: the scene's [`Structured::Workspace`], sized by
/// its largest block. Solves never allocate, error paths included.
///
/// One instant, from the scene's guess:
///
/// ```
/// # use mechgen_runtime::mechanism;
/// # mechanism! {
/// #     /// A slider-crank (mm, rad, s).
/// #     pub mechanism SliderCrank {
/// #         param omega = 10.0;
/// #         ground frame at (0, 0, 0);
/// #         body crank near (0, 0, 0.5);
/// #         body rod near (35, 19, -0.19);
/// #         body slider near (133, 0, 0);
/// #         joint pivot: revolute(frame, crank);
/// #         joint crank_pin: revolute(crank @ (40, 0), rod);
/// #         joint wrist: revolute(rod @ (100, 0), slider);
/// #         joint guide: prismatic(frame, slider, along (1, 0));
/// #         driver turn: angle(crank) = 0.5 + omega * t;
/// #     }
/// # }
/// use mechgen_runtime::{Mechanism, Solver, Vector, nalgebra::Const};
///
/// let mut solver = Solver::new(SliderCrank::default());
/// let mut guess = Vector::<Const<12>>::zeros();
/// solver.mechanism().initial_guess(&mut guess);
/// let state = solver.solve(0.05, &guess)?;
/// // q is in declaration order: frame, crank, rod, slider (x, y, θ each).
/// assert!((state.q[SliderCrank::CRANK_THETA] - 1.0).abs() < 1e-12);
/// let slider_speed = state.qd()[SliderCrank::SLIDER_X];
/// assert!(slider_speed < 0.0);
/// # Ok::<(), mechgen_runtime::SolveError>(())
/// ```
pub struct Solver<M: Structured>
where
    DefaultAllocator: Storage<M::Dim>,
{
    pub(crate) mechanism: M,
    pub(crate) options: SolverOptions,
    pub(super) workspace: M::Workspace,
    /// The length scale of the last solve, rounded to a power of two.
    pub(super) length: LengthScale,
    /// How many dependent equations and undetermined coordinates the last diagnosis found
    /// (heads of the workspace's diagnosis buffers).
    pub(super) diagnosed: (usize, usize),
    /// Which side of a stationary guess Newton leaves it by first (+1 or −1; see the
    /// `position` module's escape): [`crate::Simulation::new`] tries the other side when the
    /// first leads off a declared branch.
    pub(crate) escape_side: f64,
    /// Whether the parameters passed their checks and gave the length scale since the
    /// mechanism or the options last changed ([`Solver::check_mechanism`]).
    pub(super) checked: bool,
    /// The straight step's settings at the length scale, made with the check, and the
    /// closed-form candidates the last straight step took (its
    /// [`crate::step::StepReport`]'s `choices`), which the next one tries first.
    pub(super) context: StepContext,
    /// Whether the force solve's archive holds the block factors, and the trig cache the
    /// sines and cosines, at the positions of the last solve (a full solve of a scene that
    /// computes forces, through the stage sweep, and no rate solve since): what
    /// [`Solver::solve_velocity_again`] solves with.
    pub(super) factors_archived: bool,
}

/// Where a full solve's guess comes from: the caller (checked, as documented), or
/// `Simulation`'s prediction from its own solved states (see [`Solver::solve_predicted`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Guess {
    Given,
    Predicted,
}

/// A copy with its own workspace (to run the same scene on another thread, or to restart
/// from a checkpoint).
impl<M: Structured + Clone> Clone for Solver<M>
where
    M::Workspace: Clone,
    DefaultAllocator: Storage<M::Dim>,
{
    fn clone(&self) -> Self {
        Self {
            mechanism: self.mechanism.clone(),
            options: self.options,
            workspace: self.workspace.clone(),
            length: self.length,
            diagnosed: self.diagnosed,
            escape_side: self.escape_side,
            checked: self.checked,
            context: self.context,
            factors_archived: self.factors_archived,
        }
    }
}

impl<M: Structured> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// A solver with [`SolverOptions::default`].
    pub fn new(mechanism: M) -> Self {
        Self::with_options(mechanism, SolverOptions::default())
    }

    /// A solver with the given options.
    pub fn with_options(mechanism: M, options: SolverOptions) -> Self {
        Self {
            workspace: mechanism.workspace(),
            mechanism,
            options,
            length: LengthScale::new(1.0),
            diagnosed: (0, 0),
            escape_side: 1.0,
            checked: false,
            context: StepContext::new(&options, LengthScale::new(1.0), 0),
            factors_archived: false,
        }
    }

    /// The mechanism.
    pub fn mechanism(&self) -> &M {
        &self.mechanism
    }

    /// The mechanism, for setting parameters between solves (the next solve checks them and
    /// their length scale again). Its `dim()` must not change.
    pub fn mechanism_mut(&mut self) -> &mut M {
        self.checked = false;
        &mut self.mechanism
    }

    /// Sets free degree of freedom `k`'s state `[u, u̇, ü]` (the integrator's, between its
    /// solves): it is not a parameter, so the parameters' checks and length scale stand (a
    /// non-finite state shows as the solve's non-finite coordinate or rate).
    pub(crate) fn set_free(&mut self, k: usize, state: [f64; 3])
    where
        M: Dynamic,
        DefaultAllocator: FreeStorage<M::Dim, M::Free>,
    {
        self.mechanism.set_free(k, state);
    }

    /// Gives the mechanism back.
    pub fn into_mechanism(self) -> M {
        self.mechanism
    }

    /// The current options.
    pub fn options(&self) -> &SolverOptions {
        &self.options
    }

    /// Replaces the options.
    pub fn set_options(&mut self, options: SolverOptions) {
        self.checked = false;
        self.options = options;
    }

    /// After a [`SolveError::Singular`]: every dependent (redundant) equation of the block that
    /// failed, ascending. Empty otherwise.
    pub fn dependent_equations(&self) -> &[usize] {
        let (rows, _) = self.workspace.diagnosis();
        rows.get(..self.diagnosed.0).unwrap_or(&[])
    }

    /// After a [`SolveError::Singular`]: every coordinate left undetermined, ascending: those of
    /// the failed block the dependent equations leave free, and those of every later stage
    /// computed from them.
    pub fn undetermined_coordinates(&self) -> &[usize] {
        let (_, columns) = self.workspace.diagnosis();
        columns.get(..self.diagnosed.1).unwrap_or(&[])
    }

    /// After a solve of a scene that computes forces: the Lagrange multipliers λ of its force
    /// solve (`Φ_qᵀ λ = F`), one per equation, as the workspace keeps them; empty for a scene
    /// without forces.
    pub(crate) fn multipliers(&mut self) -> &[f64] {
        let n = nalgebra::Dim::value(&self.mechanism.dim());
        let forces = self.workspace.step_parts().forces;
        forces.get(..n).unwrap_or(&[])
    }

    /// Displays `error` with the scene's names and, for the [`SolveError::Singular`] this
    /// solver just returned, every dependent equation and undetermined coordinate.
    pub fn describe<'a>(&'a self, error: &'a SolveError) -> Described<'a, M> {
        let (dependent, undetermined) = match error {
            SolveError::Singular { .. } => {
                (self.dependent_equations(), self.undetermined_coordinates())
            }
            _ => (&[][..], &[][..]),
        };
        Described {
            error,
            mechanism: &self.mechanism,
            dependent,
            undetermined,
        }
    }

    /// Positions (from `q_guess`) at `t`, and the derivatives the scene provides.
    ///
    /// Allocates the returned state for `Dyn` mechanisms; use [`Solver::solve_into`] to reuse one.
    ///
    /// # Errors
    /// As [`Solver::solve_into`].
    pub fn solve(&mut self, t: f64, q_guess: &Vector<M::Dim>) -> Result<State<M>, SolveError> {
        self.check_len(q_guess).map_err(|e| self.named(e))?;
        let mut state = State::new(&self.mechanism);
        state.q.copy_from(q_guess);
        self.solve_into(t, &mut state)?;
        Ok(state)
    }

    /// `error` with the scene's names: every error a public method returns goes through here.
    fn named(&self, error: SolveError) -> SolveError {
        error.named(self.mechanism.names())
    }

    /// Solves positions starting from `state.q`, and the derivatives the scene provides, into
    /// `state`, stage by stage: each block's velocities and accelerations are solved with the
    /// factors its Newton iteration ends with. A scene that computes forces then solves
    /// `Φ_qᵀ λ = F` with the same factors, stage by stage in reverse, into the state's
    /// reactions ([`crate::Forces`]). On error `state` is partly updated.
    ///
    /// # Errors
    /// Any [`SolveError`] of the position, velocity, acceleration or force solve.
    pub fn solve_into(&mut self, t: f64, state: &mut State<M>) -> Result<(), SolveError> {
        self.solve_state(t, state, Guess::Given)
            .map_err(|e| self.named(e))
    }

    /// [`Solver::solve_into`] from a guess `Simulation` predicted from its own solved states:
    /// the straight step does not check it first (a non-finite prediction of a block's
    /// coordinate makes it decline, and the stage sweep then checks and reports it; the
    /// others are assigned, not read).
    pub(crate) fn solve_predicted(
        &mut self,
        t: f64,
        state: &mut State<M>,
    ) -> Result<(), SolveError> {
        self.solve_state(t, state, Guess::Predicted)
            .map_err(|e| self.named(e))
    }

    /// [`Solver::solve_into`], with unnamed errors.
    fn solve_state(
        &mut self,
        t: f64,
        state: &mut State<M>,
        guess: Guess,
    ) -> Result<(), SolveError> {
        self.check_len(&state.velocities)?;
        self.check_len(&state.accelerations)?;
        self.check_len(&state.reactions)?;
        let rates = Rates::of(self.mechanism.outputs());
        self.factors_archived = false;
        let straight = self.straight_solve(t, state, rates, guess)?;
        let convergence = match straight {
            Some(convergence) => convergence,
            None => self.solve_stages(
                t,
                &mut state.q,
                &mut state.velocities,
                &mut state.accelerations,
                rates,
                Some(Extras {
                    reactions: &mut state.reactions,
                    markers: &mut state.markers,
                }),
            )?,
        };
        // Both paths archive the blocks' factors for the force solve.
        self.factors_archived = rates == Rates::Forces;
        state.t = t;
        state.iterations = convergence.iterations;
        state.condition = convergence.condition;
        state.evaluations = convergence.evaluations;
        state.fallbacks = convergence.fallbacks;
        state.closed_forms = convergence.closed_forms;
        state.orientation = convergence.orientation;
        state.block_signs = convergence.block_signs;
        state.swept = convergence.swept;
        Ok(())
    }

    /// Newton–Raphson on Φ(q, t) = 0, starting from and overwriting `q`: explicit stages are
    /// assigned, each block is solved by Newton's method on its own equations (see the
    /// `position` module for the stopping rule and the safeguards). At each block's solution the
    /// condition of its scaled Jacobian must be below `max_condition`, and at the end every
    /// branch invariant of the scene positive.
    ///
    /// # Errors
    /// [`SolveError::NonFinite`] for a non-finite `t`, parameter, guess, Φ, Φ_q or step;
    /// [`SolveError::Singular`] at a solution where a block is singular or too
    /// ill-conditioned (the solver then lists every dependent equation:
    /// [`Solver::dependent_equations`]); [`SolveError::NoAssembly`] when a block's residual
    /// stops decreasing above the tolerance; [`SolveError::BranchFlip`] for a solution on
    /// another branch; [`SolveError::NoConvergence`] after `max_iterations` updates of a block.
    /// `q` holds the last iterate.
    pub fn solve_position(
        &mut self,
        q: &mut Vector<M::Dim>,
        t: f64,
    ) -> Result<Convergence, SolveError> {
        let (mut qd, mut qdd) = (q.clone(), q.clone());
        self.factors_archived = false;
        self.solve_stages(t, q, &mut qd, &mut qdd, Rates::None, None)
            .map_err(|e| self.named(e))
    }
}

impl<M: Structured + Velocities> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Solves Φ_q q̇ = ν at positions `q` (assumed to satisfy Φ = 0) into `qd`.
    ///
    /// # Errors
    /// [`SolveError::NonFinite`] or [`SolveError::Singular`] as for positions.
    pub fn solve_velocity(
        &mut self,
        q: &Vector<M::Dim>,
        t: f64,
        qd: &mut Vector<M::Dim>,
    ) -> Result<(), SolveError> {
        let mut qdd = q.clone();
        self.check_inputs(t, q, Quantity::Guess)
            .and_then(|()| self.check_len(qd))
            .and_then(|()| self.rate_stages(t, q, qd, &mut qdd, Rates::Velocities))
            .map_err(|e| self.named(e))
    }
}

impl<M: Structured + Accelerations> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Solves Φ_q q̈ = γ(q, q̇, t) into `qdd`.
    ///
    /// # Errors
    /// [`SolveError::NonFinite`] or [`SolveError::Singular`] as for positions.
    pub fn solve_acceleration(
        &mut self,
        q: &Vector<M::Dim>,
        qd: &Vector<M::Dim>,
        t: f64,
        qdd: &mut Vector<M::Dim>,
    ) -> Result<(), SolveError> {
        let mut velocities = qd.clone();
        self.check_inputs(t, q, Quantity::Guess)
            .and_then(|()| self.check_inputs(t, qd, Quantity::Velocity))
            .and_then(|()| self.check_len(qdd))
            .and_then(|()| self.rate_stages(t, q, &mut velocities, qdd, Rates::Both))
            .map_err(|e| self.named(e))
    }
}
