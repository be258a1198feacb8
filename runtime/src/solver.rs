//! The solver: unit scaling and the solve itself (its options are in `options`), which works through the scene's
//! stages in order. Each explicit stage is assigned in closed form; each block is solved by
//! Newton's method (`position.rs`) and, right after, its velocities and accelerations are
//! solved with the same factors: a block's derivatives depend only on earlier stages, so one
//! block's factors are all the storage a solve needs.

use nalgebra::{DefaultAllocator, Dim};

use crate::acceptance::{self, Rounding};
use crate::block::{BlockSolve, Factors};
use crate::error::{Described, Quantity, SolveError};
use crate::finite::{all_finite, check_finite, check_slice, non_finite};
use crate::forces;
use crate::mechanism::{Accelerations, LengthScale, Mechanism, Storage, Vector, Velocities};
use crate::names::Names;
use crate::options::{Rates, SolverOptions};
use crate::origin;
use crate::position::{Newton, Solved};
use crate::state::State;
use crate::structure::{Block, Stage, Structured};
use crate::workspace::{Parts, Workspace};

/// Outcome of a successful position solve, over all blocks.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Convergence {
    /// Updates applied by the block that needed the most (0 when every coordinate is explicit).
    pub iterations: usize,
    /// Largest ‖Φ_b‖∞ (unscaled) of the blocks at their last evaluation: at the returned
    /// positions, or, where the last correction was of round-off size, just before it.
    /// Explicit assignments satisfy their equations to the rounding of the coordinates they
    /// combine; where that rounding could reach `acceptance_tolerance` (coordinates beyond
    /// ~4e4 scene lengths or radians), their residuals at the returned positions are
    /// evaluated and included here.
    pub residual: f64,
    /// Largest condition estimate κ₁ of the scaled block Jacobians at the solution (1 without
    /// blocks; NaN if switched off).
    pub condition: f64,
    /// Block factorisations whose static pivots failed their test and were redone with partial
    /// pivoting.
    pub fallbacks: usize,
    /// Evaluations and factorisations of block Jacobians, summed over the blocks: one per
    /// Newton iteration, plus one at the returned positions unless the last correction was of
    /// round-off size (its factors then serve the rates).
    pub evaluations: usize,
    /// The sign of det Φ_q (unit-scaled, in the scene's solve order), +1 or −1: the product of
    /// the blocks' determinant signs (fixed and explicit coordinates have constant
    /// coefficients). It changes between two solutions only if Φ_q is singular somewhere
    /// between them; [`crate::Simulation`] watches it to catch toggle crossings.
    pub orientation: i8,
    /// Which blocks have a negative determinant: the XOR of a 64-bit code per such block
    /// (a splitmix64 code of the stage index, distinct and non-zero for every stage). Two states
    /// whose blocks' signs differ have a singular configuration between them even when an even
    /// number of blocks flipped and `orientation` did not change; the codes of two different
    /// blocks never cancel (three or more could, with a chance of order 2⁻⁶⁴).
    pub block_signs: u64,
    /// Whether a block's Newton iterates met both determinant signs: the iteration crossed
    /// a singular configuration between its start and the solution.
    pub swept: bool,
}

impl Convergence {
    fn start(estimate_condition: bool) -> Self {
        Convergence {
            iterations: 0,
            residual: 0.0,
            condition: if estimate_condition { 1.0 } else { f64::NAN },
            fallbacks: 0,
            evaluations: 0,
            orientation: 1,
            block_signs: 0,
            swept: false,
        }
    }

    fn add(&mut self, stage: usize, block: &Solved, newton: (usize, usize)) {
        let (fallbacks, evaluations) = newton;
        self.iterations = self.iterations.max(block.iterations);
        self.residual = self.residual.max(block.residual);
        // NaN (estimate off) stays NaN.
        self.condition = if block.condition > self.condition {
            block.condition
        } else {
            self.condition
        };
        self.fallbacks += fallbacks;
        self.evaluations += evaluations;
        if block.orientation < 0.0 {
            self.orientation = -self.orientation;
            self.block_signs ^= crate::block_signs::block_code(stage);
        }
        self.swept |= block.swept;
    }
}

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
    workspace: M::Workspace,
    /// The length scale of the last solve, rounded to a power of two.
    length: LengthScale,
    /// How many dependent equations and undetermined coordinates the last diagnosis found
    /// (heads of the workspace's diagnosis buffers).
    diagnosed: (usize, usize),
    /// Which side of a stationary guess Newton leaves it by first (+1 or −1; see the
    /// `position` module's escape): [`crate::Simulation::new`] tries the other side when the
    /// first leads off a declared branch.
    pub(crate) escape_side: f64,
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
        }
    }
}

/// What a full solve writes besides the motion: the reactions (for a scene that computes
/// forces) and the marker values.
pub(crate) struct Extras<'a, M: Mechanism>
where
    DefaultAllocator: Storage<M::Dim>,
{
    reactions: &'a mut Vector<M::Dim>,
    markers: &'a mut M::Markers,
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
        }
    }

    /// The mechanism.
    pub fn mechanism(&self) -> &M {
        &self.mechanism
    }

    /// The mechanism, for setting parameters between solves. Its `dim()` must not change.
    pub fn mechanism_mut(&mut self) -> &mut M {
        &mut self.mechanism
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
        self.solve_state(t, state).map_err(|e| self.named(e))
    }

    /// [`Solver::solve_into`], with unnamed errors.
    fn solve_state(&mut self, t: f64, state: &mut State<M>) -> Result<(), SolveError> {
        self.check_len(&state.velocities)?;
        self.check_len(&state.accelerations)?;
        self.check_len(&state.reactions)?;
        let rates = Rates::of(self.mechanism.outputs());
        let convergence = self.solve_stages(
            t,
            &mut state.q,
            &mut state.velocities,
            &mut state.accelerations,
            rates,
            Some(Extras {
                reactions: &mut state.reactions,
                markers: &mut state.markers,
            }),
        )?;
        state.t = t;
        state.iterations = convergence.iterations;
        state.condition = convergence.condition;
        state.evaluations = convergence.evaluations;
        state.fallbacks = convergence.fallbacks;
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
        self.solve_stages(t, q, &mut qd, &mut qdd, Rates::None, None)
            .map_err(|e| self.named(e))
    }

    /// The stage sweep of [`Solver::solve_into`] and [`Solver::solve_position`], with a
    /// non-finite value traced to where it began.
    fn solve_stages(
        &mut self,
        t: f64,
        q: &mut Vector<M::Dim>,
        qd: &mut Vector<M::Dim>,
        qdd: &mut Vector<M::Dim>,
        rates: Rates,
        extras: Option<Extras<'_, M>>,
    ) -> Result<Convergence, SolveError> {
        self.check_inputs(t, q, Quantity::Guess)?;
        self.check_parameters(t)?;
        let mut reached = 0;
        self.sweep(t, q, qd, qdd, rates, extras, &mut reached)
            .map_err(|e| origin::trace(&self.mechanism, reached, [q, qd, qdd], rates, e))
    }

    /// Solves the stages in order, recording in `reached` the stage being solved, then into
    /// `extras` (a full solve's) the force solve in reverse for [`Rates::Forces`] and the
    /// marker values.
    #[allow(clippy::too_many_arguments)]
    fn sweep(
        &mut self,
        t: f64,
        q: &mut Vector<M::Dim>,
        qd: &mut Vector<M::Dim>,
        qdd: &mut Vector<M::Dim>,
        rates: Rates,
        extras: Option<Extras<'_, M>>,
        reached: &mut usize,
    ) -> Result<Convergence, SolveError> {
        self.update_scale();
        self.diagnosed = (0, 0);
        let Self {
            mechanism: m,
            options,
            workspace,
            length,
            diagnosed,
            escape_side,
        } = self;
        let mut parts = workspace.parts();
        let mut total = Convergence::start(options.estimate_condition);
        // A looser residual tolerance asked for loosens acceptance with it (as in `position`).
        let acceptance = options.acceptance_tolerance.max(options.residual_tolerance);
        let mut rounding = Rounding::new(acceptance);
        // How much of the force solve's archive the blocks have filled.
        let mut archived = 0;
        for s in 0..m.stage_count() {
            *reached = s;
            match m.stage(s) {
                Some(Stage::Explicit { coordinates, .. }) => {
                    m.assign_positions(s, q, parts.trig, t);
                    rounding.explicit(m, coordinates, q, length);
                    m.fill_trig(s, q, parts.trig);
                    assign_rates(m, s, q, parts.trig, qd, qdd, t, rates);
                }
                Some(Stage::Block(block)) => {
                    let bs = BlockSolve { m, stage: s, block };
                    bs.set_scales(&mut parts.scales, length);
                    let mut newton = Newton::new(bs, &mut parts, options, t);
                    newton.escape_side = *escape_side;
                    let solved = newton
                        .solve(q, rates != Rates::None)
                        .map_err(|e| record(e, m, s, newton.parts, diagnosed))?;
                    total.add(s, &solved, (newton.fallbacks, newton.evaluations));
                    rounding.block::<M>(block.coordinates, newton.parts.scales.inverse_cols, q);
                    m.fill_trig(s, q, newton.parts.trig);
                    block_rates(
                        &newton.bs,
                        solved.factors,
                        newton.parts,
                        q,
                        qd,
                        qdd,
                        t,
                        rates,
                    )?;
                    if rates == Rates::Forces {
                        let n = q.len();
                        archived =
                            forces::archive(&newton.bs, solved.factors, newton.parts, n, archived);
                    }
                }
                None => break,
            }
        }
        // Blocks check what they solve; an explicit assignment's non-finite value shows here
        // (or earlier, as the non-finite Φ or rate of a block that reads it).
        *reached = m.stage_count();
        check_finite(q, t, Quantity::Phi)?;
        if rounding.pending() {
            let explicit = acceptance::check_explicit(m, q, t, length, acceptance)?;
            total.residual = total.residual.max(explicit);
        }
        check_rates(qd, qdd, t, rates)?;
        check_branches(m, q, parts.trig, t)?;
        if let Some(Extras { reactions, markers }) = extras {
            if rates == Rates::Forces {
                let motion = forces::Motion { t, q, qd, qdd };
                forces::solve(m, &mut parts, options, length, &motion, archived, reactions)?;
            }
            if !markers.as_ref().is_empty() {
                m.markers(q, parts.trig, qd, qdd, t, markers);
                let bad = markers.as_ref().iter().position(|v| !v.is_finite());
                if let Some(index) = bad {
                    return Err(non_finite(t, Quantity::Marker(index)));
                }
            }
        }
        Ok(total)
    }

    /// Evaluates and factors every block at the given positions and solves the rates asked for
    /// ([`Solver::solve_velocity`], [`Solver::solve_acceleration`]); `q̇` is an input when only
    /// accelerations are asked for.
    fn rate_stages(
        &mut self,
        t: f64,
        q: &Vector<M::Dim>,
        qd: &mut Vector<M::Dim>,
        qdd: &mut Vector<M::Dim>,
        rates: Rates,
    ) -> Result<(), SolveError> {
        self.check_parameters(t)?;
        let mut reached = 0;
        self.rate_sweep(t, q, qd, qdd, rates, &mut reached)
            .map_err(|e| origin::trace(&self.mechanism, reached, [q, qd, qdd], rates, e))
    }

    /// The stages of [`Solver::rate_stages`] in order, recording in `reached` the stage being
    /// solved.
    fn rate_sweep(
        &mut self,
        t: f64,
        q: &Vector<M::Dim>,
        qd: &mut Vector<M::Dim>,
        qdd: &mut Vector<M::Dim>,
        rates: Rates,
        reached: &mut usize,
    ) -> Result<(), SolveError> {
        self.update_scale();
        self.diagnosed = (0, 0);
        let Self {
            mechanism: m,
            options,
            workspace,
            length,
            diagnosed,
            ..
        } = self;
        let mut parts = workspace.parts();
        for s in 0..m.stage_count() {
            *reached = s;
            match m.stage(s) {
                Some(Stage::Explicit { .. }) => {
                    m.fill_trig(s, q, parts.trig);
                    assign_rates(m, s, q, parts.trig, qd, qdd, t, rates);
                }
                Some(Stage::Block(block)) => {
                    let bs = BlockSolve { m, stage: s, block };
                    bs.set_scales(&mut parts.scales, length);
                    let mut newton = Newton::new(bs, &mut parts, options, t);
                    let factors = newton
                        .factor_at(q)
                        .map_err(|e| record(e, m, s, newton.parts, diagnosed))?;
                    m.fill_trig(s, q, newton.parts.trig);
                    block_rates(&newton.bs, factors, newton.parts, q, qd, qdd, t, rates)?;
                }
                None => break,
            }
        }
        *reached = m.stage_count();
        check_rates(qd, qdd, t, rates)
    }

    /// The diagnosis of the configuration `q` at `t` (a solution next to a singular one): every
    /// block is factored there, and the one with the largest condition estimate gets the
    /// rank-revealing diagnosis ([`SolveError::Singular`], with the lists behind
    /// [`Solver::dependent_equations`]).
    pub(crate) fn diagnose_at(&mut self, t: f64, q: &Vector<M::Dim>) -> SolveError {
        self.update_scale();
        self.diagnosed = (0, 0);
        let Self {
            mechanism: m,
            options,
            workspace,
            length,
            diagnosed,
            ..
        } = self;
        let mut parts = workspace.parts();
        let mut worst: Option<(usize, Block<'_>, f64)> = None;
        for s in 0..m.stage_count() {
            let block = match m.stage(s) {
                Some(Stage::Explicit { .. }) => {
                    m.fill_trig(s, q, parts.trig);
                    continue;
                }
                Some(Stage::Block(block)) => block,
                None => break,
            };
            let bs = BlockSolve { m, stage: s, block };
            bs.set_scales(&mut parts.scales, length);
            let mut newton = Newton::new(bs, &mut parts, options, t);
            let condition = match newton.factor_at(q) {
                Ok(factors) => newton.condition(factors),
                Err(error) => return record(error, m, s, newton.parts, diagnosed),
            };
            // NaN (estimate off) counts as the worst.
            if worst.is_none_or(|(_, _, c)| condition > c || condition.is_nan()) {
                worst = Some((s, block, condition));
            }
            m.fill_trig(s, q, newton.parts.trig);
        }
        // The trig cache is complete: diagnose the worst block.
        let Some((s, block, condition)) = worst else {
            return SolveError::Singular {
                time: t,
                equation: 0,
                coordinate: 0,
                condition: f64::INFINITY,
                deficiency: 0,
                names: &Names::NONE,
            };
        };
        let bs = BlockSolve { m, stage: s, block };
        bs.set_scales(&mut parts.scales, length);
        let mut newton = Newton::new(bs, &mut parts, options, t);
        let error = newton.diagnose(q, condition);
        record(error, m, s, newton.parts, diagnosed)
    }

    /// ‖D_c⁻¹ (a − b)‖∞: how far apart two configurations are, in scene lengths and radians
    /// (with the length scale of the last solve).
    pub fn scaled_distance(&self, a: &Vector<M::Dim>, b: &Vector<M::Dim>) -> f64 {
        self.distance_over(a, b, 0..a.len().min(b.len()))
    }

    /// [`Solver::scaled_distance`] from `prediction` to `previous` and to `solved` (the
    /// motion predicted and the correction Newton made), over the coordinates of the Newton
    /// blocks only: those on which a solve can choose a branch (explicit assignments have one
    /// solution), so where a jump to another branch shows.
    pub(crate) fn block_distances(
        &self,
        previous: &Vector<M::Dim>,
        prediction: &Vector<M::Dim>,
        solved: &Vector<M::Dim>,
    ) -> (f64, f64) {
        let m = &self.mechanism;
        let coordinates = (0..m.stage_count())
            .filter_map(|s| match m.stage(s) {
                Some(Stage::Block(block)) => Some(block.coordinates),
                _ => None,
            })
            .flatten()
            .copied();
        let (previous, prediction, solved) = (
            previous.as_slice(),
            prediction.as_slice(),
            solved.as_slice(),
        );
        let (mut motion, mut correction) = (0.0, 0.0);
        for j in coordinates {
            let (Some(x), Some(p), Some(s)) = (prediction.get(j), previous.get(j), solved.get(j))
            else {
                continue;
            };
            let power = self.length.inverse_of(m.coordinate_unit(j));
            motion = larger(motion, ((x - p) * power).abs());
            correction = larger(correction, ((x - s) * power).abs());
        }
        (motion, correction)
    }

    fn distance_over(
        &self,
        a: &Vector<M::Dim>,
        b: &Vector<M::Dim>,
        coordinates: impl Iterator<Item = usize>,
    ) -> f64 {
        let m = &self.mechanism;
        let (a, b) = (a.as_slice(), b.as_slice());
        coordinates.fold(0.0, |largest, j| {
            let (Some(x), Some(y)) = (a.get(j), b.get(j)) else {
                return largest;
            };
            let power = self.length.inverse_of(m.coordinate_unit(j));
            larger(largest, ((x - y) * power).abs())
        })
    }

    /// Every parameter finite, and the geometry and physics written in them valid: a NaN set
    /// through a public field, a distance or a mass set negative, is reported as itself, not as
    /// the NaN Φ, the singular Jacobian or the wrong forces it would cause.
    pub(crate) fn check_parameters(&self, t: f64) -> Result<(), SolveError> {
        let m = &self.mechanism;
        match (0..m.parameter_count()).find(|&i| !m.parameter(i).is_some_and(f64::is_finite)) {
            Some(index) => Err(non_finite(t, Quantity::Parameter(index))),
            None => {
                m.check_geometry().map_err(|fault| fault.at(t))?;
                m.check_physics().map_err(|fault| fault.at(t))
            }
        }
    }

    /// The scene's length scale from the current parameters, rounded to a power of two so that
    /// scaling adds no rounding error (1 with unit scaling off).
    fn update_scale(&mut self) {
        self.length = LengthScale::new(if self.options.scale_units {
            power_of_two(self.mechanism.length_scale())
        } else {
            1.0
        });
    }

    /// Length and finiteness of an input, and finiteness of `t`.
    pub(crate) fn check_inputs(
        &self,
        t: f64,
        v: &Vector<M::Dim>,
        quantity: Quantity,
    ) -> Result<(), SolveError> {
        if !t.is_finite() {
            return Err(non_finite(t, Quantity::Time));
        }
        self.check_len(v)?;
        check_finite(v, t, quantity)
    }

    /// Only a `Dyn` vector can disagree with the mechanism; nalgebra would panic on it.
    pub(crate) fn check_len(&self, v: &Vector<M::Dim>) -> Result<(), SolveError> {
        let expected = self.mechanism.dim().value();
        if v.nrows() == expected {
            Ok(())
        } else {
            Err(SolveError::DimensionMismatch {
                expected,
                found: v.nrows(),
                names: &Names::NONE,
            })
        }
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

/// Completes the diagnosis of a singularity found in stage `stage` (for
/// [`Solver::dependent_equations`] and [`Solver::undetermined_coordinates`]): the block's own
/// undetermined coordinates, then every later stage that reads it, directly or not.
fn record<M: Structured>(
    error: SolveError,
    m: &M,
    stage: usize,
    parts: &mut Parts<'_>,
    diagnosed: &mut (usize, usize),
) -> SolveError
where
    DefaultAllocator: Storage<M::Dim>,
{
    let SolveError::Singular { deficiency, .. } = error else {
        return error;
    };
    let undetermined = &mut *parts.undetermined;
    let mut count = deficiency.min(undetermined.len());
    undetermined[..count].copy_from_slice(&parts.col_order[..count]);
    let downstream = &mut *parts.downstream;
    downstream.fill(false);
    for t in stage + 1..m.stage_count().min(downstream.len()) {
        let Some(later) = m.stage(t) else {
            break;
        };
        let reads = later.reads();
        if reads
            .iter()
            .any(|&r| r == stage || downstream.get(r) == Some(&true))
        {
            downstream[t] = true;
            for &c in later.coordinates() {
                if count < undetermined.len() {
                    undetermined[count] = c;
                    count += 1;
                }
            }
        }
    }
    crate::lu::sort_indices(&mut undetermined[..count]);
    *diagnosed = (deficiency, count);
    error
}

/// The rates of an explicit stage's coordinates (checked at the end of the sweep).
#[allow(clippy::too_many_arguments)]
fn assign_rates<M: Structured>(
    m: &M,
    stage: usize,
    q: &Vector<M::Dim>,
    trig: &[f64],
    qd: &mut Vector<M::Dim>,
    qdd: &mut Vector<M::Dim>,
    t: f64,
    rates: Rates,
) where
    DefaultAllocator: Storage<M::Dim>,
{
    if rates != Rates::None {
        m.assign_velocities(stage, q, trig, qd, t);
    }
    if rates >= Rates::Both {
        m.assign_accelerations(stage, q, trig, qd, qdd, t);
    }
}

/// The rates asked for are finite.
fn check_rates<D: Dim>(
    qd: &Vector<D>,
    qdd: &Vector<D>,
    t: f64,
    rates: Rates,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<D>,
{
    if rates != Rates::None {
        check_finite(qd, t, Quantity::Velocity)?;
    }
    if rates >= Rates::Both {
        check_finite(qdd, t, Quantity::Acceleration)?;
    }
    Ok(())
}

/// A block's velocities, then accelerations, with its factors at the solved `q`.
#[allow(clippy::too_many_arguments)]
fn block_rates<M: Structured>(
    bs: &BlockSolve<'_, M>,
    factors: Factors,
    parts: &mut Parts<'_>,
    q: &Vector<M::Dim>,
    qd: &mut Vector<M::Dim>,
    qdd: &mut Vector<M::Dim>,
    t: f64,
    rates: Rates,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    if rates == Rates::None {
        return Ok(());
    }
    let n = bs.n();
    let rhs = &mut parts.newton.trial[..n];
    bs.m.velocity_rhs(bs.stage, q, parts.trig, qd, t, rhs);
    check_rhs(bs, rhs, t, Quantity::Nu)?;
    bs.solve(factors, &parts.factors, &parts.scales, rhs);
    scatter(rhs, bs.block.coordinates, qd, t, Quantity::Velocity)?;
    if rates >= Rates::Both {
        bs.m.acceleration_rhs(bs.stage, q, parts.trig, qd, qdd, t, rhs);
        check_rhs(bs, rhs, t, Quantity::Gamma)?;
        bs.solve(factors, &parts.factors, &parts.scales, rhs);
        scatter(rhs, bs.block.coordinates, qdd, t, Quantity::Acceleration)?;
    }
    Ok(())
}

/// A block's right-hand side is finite; otherwise the error names its first non-finite row's
/// equation.
fn check_rhs<M: Structured>(
    bs: &BlockSolve<'_, M>,
    rhs: &[f64],
    t: f64,
    quantity: Quantity,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    if all_finite(rhs) {
        return Ok(());
    }
    let row = rhs.iter().position(|x| !x.is_finite());
    Err(SolveError::NonFinite {
        time: t,
        quantity,
        equation: row.and_then(|i| bs.block.equations.get(i).copied()),
        names: &Names::NONE,
    })
}

/// `v[coordinates[j]] ← x[j]`, finite.
fn scatter<D: Dim>(
    x: &[f64],
    coordinates: &[usize],
    v: &mut Vector<D>,
    t: f64,
    quantity: Quantity,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<D>,
{
    check_slice(x, t, quantity)?;
    let v = v.as_mut_slice();
    for (&x, &j) in x.iter().zip(coordinates) {
        v[j] = x;
    }
    Ok(())
}

/// Every branch invariant positive at `q`.
fn check_branches<M: Structured>(
    m: &M,
    q: &Vector<M::Dim>,
    trig: &[f64],
    t: f64,
) -> Result<(), SolveError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    for branch in 0..m.branch_count() {
        let value = m.branch(branch, q, trig);
        if !value.is_finite() {
            return Err(non_finite(t, Quantity::Branch(branch)));
        }
        if value <= 0.0 {
            return Err(SolveError::BranchFlip {
                time: t,
                branch,
                value,
                names: &Names::NONE,
            });
        }
    }
    Ok(())
}

/// The power of two nearest below `length` (1 for zero, subnormal or non-finite lengths, or
/// ones so extreme that their square would overflow the scaled equations).
fn power_of_two(length: f64) -> f64 {
    let length = length.abs();
    if !(1e-100..=1e100).contains(&length) {
        return 1.0;
    }
    // Clearing the mantissa of a normal positive float leaves its power of two.
    f64::from_bits(length.to_bits() & 0xfff0_0000_0000_0000)
}

/// The larger of two distances, NaN winning.
fn larger(largest: f64, d: f64) -> f64 {
    if d > largest || d.is_nan() {
        d
    } else {
        largest
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dense::Dense;
    use crate::mechanism::Mechanism;
    use crate::pendulum::Pendulum;
    use nalgebra::U1;

    type Reference = Dense<Pendulum>;

    fn dense(pendulum: Pendulum) -> Solver<Reference> {
        Solver::new(Dense::new(pendulum))
    }

    fn assert_exact(state: &State<Reference>, mechanism: &Pendulum) {
        let exact = mechanism.exact(state.t);
        for (computed, expected) in [&state.q, &state.velocities, &state.accelerations]
            .into_iter()
            .zip(exact)
        {
            for (c, e) in computed.iter().zip(expected) {
                assert!((c - e).abs() <= 1e-12 * e.abs().max(1.0), "{c} vs {e}");
            }
        }
    }

    #[test]
    fn newton_converges_quadratically_to_the_closed_form() {
        let mut solver = dense(Pendulum::default());
        let mut guess = Vector::zeros_generic(nalgebra::Const, U1);
        solver.mechanism().initial_guess(&mut guess);
        let state = solver.solve(0.7, &guess).unwrap();
        assert_exact(&state, solver.mechanism().inner());
        assert!((1..=6).contains(&state.iterations), "{}", state.iterations);

        // From the solution itself one (null) update confirms convergence.
        let mut q = state.q;
        let convergence = solver.solve_position(&mut q, 0.7).unwrap();
        assert_eq!(convergence.iterations, 1);
        assert!(convergence.residual <= 1e-15);
    }

    #[test]
    fn factors_are_reused_only_after_a_round_off_correction() {
        let mut solver = dense(Pendulum::default());
        let exact = Vector::from(solver.mechanism().inner().exact(0.7)[0]);
        // With the rates: the factors at the result are needed.
        let evaluations = |solver: &mut Solver<Reference>, nudge: f64| {
            let mut q = exact;
            q[2] += nudge;
            let (mut qd, mut qdd) = (q, q);
            let convergence = solver
                .solve_stages(0.7, &mut q, &mut qd, &mut qdd, Rates::Both, None)
                .unwrap();
            (convergence.iterations, convergence.evaluations)
        };
        // From the solution: one update of round-off size, its factors kept.
        assert_eq!(evaluations(&mut solver, 0.0), (1, 1));
        // 1e-9 off: the second correction is ~1e-18, negligible: two evaluations.
        assert_eq!(evaluations(&mut solver, 1e-9), (2, 2));
        // 1e-6 off: the second correction (~1e-13) ends the iteration but is not negligible:
        // the block is evaluated and factored once more at the result.
        assert_eq!(evaluations(&mut solver, 1e-6), (2, 3));
        // Positions alone need no factors at the result.
        let mut q = exact;
        q[2] += 1e-6;
        let convergence = solver.solve_position(&mut q, 0.7).unwrap();
        assert_eq!((convergence.iterations, convergence.evaluations), (2, 2));
    }

    #[test]
    fn newton_takes_the_same_steps_at_any_length_scale() {
        let solve = |a: f64| {
            let mut solver = dense(Pendulum {
                a,
                ..Pendulum::default()
            });
            let mut q = Vector::from([0.9 * a, 0.3 * a, 0.4]);
            let convergence = solver.solve_position(&mut q, 0.7).unwrap();
            (convergence.iterations, q[2], convergence.condition)
        };
        let reference = solve(2.0);
        // Scaled by a power of two, the scaled problem is the same to the bit.
        for a in [2.0 * 2f64.powi(-20), 2.0 * 2f64.powi(14)] {
            assert_eq!(solve(a), reference, "a = {a}");
        }
        // Otherwise the scale is rounded to a power of two, which leaves the scaled entries
        // within a factor of two of these: the same iterations and solution.
        for a in [2e-6, 2e4] {
            let (iterations, theta, _) = solve(a);
            assert_eq!(iterations, reference.0, "a = {a}");
            assert!((theta - reference.1).abs() < 1e-14, "a = {a}");
        }
    }

    #[test]
    fn a_guess_half_a_turn_away_still_converges() {
        let mut solver = dense(Pendulum::default());
        // The rod guessed pointing the other way, its angle 3 rad off: steps are clamped and
        // damped rather than thrown across the plane.
        let mut q = Vector::from([-2.0, 0.0, 0.7 + 3.0]);
        let convergence = solver.solve_position(&mut q, 0.7 / 1.5).unwrap();
        let exact = Pendulum::default().exact(0.7 / 1.5);
        assert!(
            (q[0] - exact[0][0]).abs() < 1e-12,
            "{q:?} after {convergence:?}"
        );
    }

    #[test]
    fn separate_velocity_and_acceleration_solves_agree() {
        let mut solver = dense(Pendulum::default());
        let q = Vector::from(solver.mechanism().inner().exact(2.0)[0]);
        let mut qd = Vector::<nalgebra::Const<3>>::zeros();
        let mut qdd = qd;
        solver.solve_velocity(&q, 2.0, &mut qd).unwrap();
        solver.solve_acceleration(&q, &qd, 2.0, &mut qdd).unwrap();
        let mut state = State::new(solver.mechanism());
        (state.t, state.q, state.velocities, state.accelerations) = (2.0, q, qd, qdd);
        assert_exact(&state, solver.mechanism().inner());
    }

    #[test]
    fn iteration_cap_reports_no_convergence() {
        let options = SolverOptions {
            max_iterations: 1,
            ..SolverOptions::default()
        };
        let mut solver = Solver::with_options(Dense::new(Pendulum::default()), options);
        let mut q = Vector::from([0.0, 0.0, 3.0]);
        let error = solver.solve_position(&mut q, 0.0).unwrap_err();
        assert!(matches!(
            error,
            SolveError::NoConvergence {
                time: 0.0,
                iterations: 1,
                ..
            }
        ));
    }

    #[test]
    fn singular_jacobian_names_the_duplicate_equation() {
        let pendulum = Pendulum {
            duplicate_pin: true,
            ..Pendulum::default()
        };
        let mut solver = dense(pendulum);
        let error = solver
            .solve(1.0, &Vector::from([2.0, 0.0, 0.0]))
            .unwrap_err();
        let SolveError::Singular {
            equation,
            coordinate,
            ..
        } = error
        else {
            panic!("expected a singular Jacobian, got {error:?}");
        };
        assert_eq!((equation, coordinate), (2, 2));
    }

    #[test]
    fn non_finite_inputs_and_evaluations_are_reported() {
        let mut solver = dense(Pendulum::default());
        let good = Vector::from([2.0, 0.0, 0.0]);
        let quantity = |result: Result<State<Reference>, SolveError>| match result {
            Err(SolveError::NonFinite { quantity, .. }) => quantity,
            other => panic!("expected NonFinite, got {other:?}"),
        };
        assert_eq!(quantity(solver.solve(f64::NAN, &good)), Quantity::Time);
        let bad = Vector::from([2.0, f64::INFINITY, 0.0]);
        assert_eq!(quantity(solver.solve(0.0, &bad)), Quantity::Guess);
        solver.mechanism_mut().inner_mut().a = f64::NAN;
        assert_eq!(quantity(solver.solve(0.0, &good)), Quantity::Phi);
        solver.mechanism_mut().inner_mut().a = 2.0;
        solver.mechanism_mut().inner_mut().omega = f64::INFINITY;
        assert_eq!(quantity(solver.solve(0.0, &good)), Quantity::Phi);
    }

    #[cfg(feature = "alloc")]
    #[test]
    fn dyn_mechanisms_solve_and_reject_wrong_lengths() {
        use crate::pendulum::DynPendulum;
        use nalgebra::DVector;

        let mut solver = Solver::new(Dense::new(DynPendulum(Pendulum::default())));
        let state = solver
            .solve(0.7, &DVector::from_row_slice(&[2.0, 0.1, 0.1]))
            .unwrap();
        let exact = Pendulum::default().exact(0.7);
        assert!((state.accelerations[1] - exact[2][1]).abs() < 1e-12);

        let mismatch = SolveError::DimensionMismatch {
            expected: 3,
            found: 2,
            names: &Names::NONE,
        };
        assert_eq!(solver.solve(0.7, &DVector::zeros(2)).err(), Some(mismatch));
        let mut short = state.clone();
        short.accelerations = DVector::zeros(2);
        assert_eq!(solver.solve_into(0.7, &mut short), Err(mismatch));
        let mut long = DVector::zeros(4);
        assert!(solver.solve_position(&mut long, 0.7).is_err());
    }
}
