//! The position solve of one block: Newton–Raphson on the block's unit-scaled equations, kept on
//! track by a step clamp, a backtracking line search and Levenberg–Marquardt steps where
//! Newton's cannot be used; and, when it fails, the diagnosis of why.
//!
//! The safeguards cost nothing on the usual path. A Newton step is applied without evaluating
//! the trial point first; the next iteration's evaluation, needed anyway, doubles as the line
//! search test, and only a step that failed to reduce the residual is taken back and shortened.
//!
//! A Newton iteration that crawls into its root (corrections shrinking linearly from a small
//! residual) has found a singular one: a toggle position or redundant constraints
//! ([`CRAWL_LIMIT`]).
//!
//! Stopping rule. A correction within `step_tolerance` ends the iteration when convergence is
//! evident: the correction shrank to at most a quarter of the previous one (Newton's quadratic
//! phase; a linearly converging iteration, as at a singular root, halves it at best), or, for
//! the first correction, it was taken from a point whose residual was already within
//! `residual_tolerance`. The correction is applied; its size bounds the error before it, so the
//! error after it is of the order of its square. No confirming update follows. The factors the
//! derivative solves need are those at the returned positions: when the last correction was of
//! round-off size (≤ [`NEGLIGIBLE_STEP`]), the factors it was computed with are kept (the
//! Jacobian moved by less than its own rounding); otherwise the block is evaluated and factored
//! once more at the returned positions.

use nalgebra::DefaultAllocator;

use crate::block::{BlockSolve, Factors};
use crate::error::{Quantity, SolveError};
use crate::finite::{all_finite, non_finite};
use crate::lu::{self, LuError};
use crate::mechanism::{Storage, Vector};
use crate::names::Names;
use crate::options::SolverOptions;
use crate::structure::Structured;
use crate::workspace::Parts;

/// Armijo constant: a step of length α must reduce the merit ‖D_r Φ_b‖₂ by at least this · α.
const SUFFICIENT_DECREASE: f64 = 1e-4;
/// Shortest fraction of a Newton step tried before switching to Levenberg–Marquardt.
const MIN_STEP_FRACTION: f64 = 1.0 / 64.0;
/// A singular Φ_q at an iterate whose scaled residual is below this is a singular solution
/// (toggle position, redundant constraints); above it, only a bad iterate to step away from.
const SINGULAR_RESIDUAL: f64 = 1e-6;
/// Levenberg–Marquardt steps in a row that reduce the merit by less than [`STALL_DECREASE`]
/// before the residual is declared a nonzero minimum ([`SolveError::NoAssembly`]).
const STALL_LIMIT: usize = 4;
const STALL_DECREASE: f64 = 1e-3;
/// A correction at most this fraction of the previous one shows quadratic convergence.
const CONTRACTION: f64 = 0.25;
/// A full Newton correction at least this fraction of the previous one, taken where the scaled
/// residual is already below [`SINGULAR_RESIDUAL`], is crawling: at a double root (a toggle
/// position) Newton halves the error at every step instead of squaring it, and rounding then
/// stops it about √ε away, where the Jacobian's condition is only ~1/√ε.
const CRAWL_RATIO: f64 = 0.4;
/// This many crawling corrections in a row identify a singular root ([`SolveError::Singular`]).
/// A regular root crawls at most while its error exceeds four times its Jacobian's smallest
/// singular value, so three in a row from a residual below [`SINGULAR_RESIDUAL`] need a
/// condition above ~1e4 as well.
const CRAWL_LIMIT: usize = 3;
/// A last correction this small (scaled) moved the Jacobian by less than its own rounding: its
/// factors serve the derivative solves at the returned positions.
pub(crate) const NEGLIGIBLE_STEP: f64 = 8.0 * f64::EPSILON;
/// Levenberg–Marquardt damping values tried for one step before the residual counts as a
/// minimum: μ grows fourfold per trial from at least 1e-12 of the largest column norm to at
/// most 1e14 of it, which takes at most 43 trials; the cap only guards that arithmetic.
const MAX_DAMPING_TRIALS: usize = 64;

/// Levenberg–Marquardt state carried across the iterations of one block's solve.
#[derive(Default)]
struct Marquardt {
    /// Damping μ (0: not yet chosen).
    mu: f64,
    /// Consecutive accepted steps with little progress.
    stalls: usize,
    /// Whether any step was needed: a capped solve that needed them did not assemble.
    used: bool,
    /// Whether a step along the Jacobian's null direction was tried ([`Newton::escape`]).
    escaped: bool,
}

/// A block solved at one time.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Solved {
    /// Updates applied.
    pub iterations: usize,
    /// ‖Φ_b‖∞ at the last evaluation (unscaled): at the returned positions, or just before the
    /// last (negligible) correction.
    pub residual: f64,
    /// Condition estimate κ₁ of the scaled block Jacobian (NaN if switched off).
    pub condition: f64,
    /// The sign of the block Jacobian's determinant (local order) at the returned positions.
    pub orientation: f64,
    /// Whether the iterates' Jacobians had both determinant signs: Newton crossed a singular
    /// configuration on its way (from a prediction past a toggle onto the branch that meets
    /// the starting one there, say), so the solution may not continue the starting branch.
    pub swept: bool,
    /// The factors at the returned positions.
    pub factors: Factors,
}

/// One block's solve: the block, the workspace it runs in, and the solver's settings.
pub(crate) struct Newton<'a, 'w, M> {
    pub bs: BlockSolve<'a, M>,
    pub parts: &'a mut Parts<'w>,
    pub options: &'a SolverOptions,
    pub t: f64,
    /// Factorisations whose static pivots failed and were redone with partial pivoting.
    pub fallbacks: usize,
    /// Evaluations (and factorisations) of the block's Jacobian.
    pub evaluations: usize,
    /// Determinant signs of the factorisations so far: (a positive one, a negative one), and
    /// the last one's.
    signs: (bool, bool),
    orientation: f64,
    /// The side a stationary point is left by first ([`Newton::escape`]): +1 or −1.
    pub escape_side: f64,
}

impl<'a, 'w, M: Structured> Newton<'a, 'w, M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// The solve of one block at time `t`.
    pub fn new(
        bs: BlockSolve<'a, M>,
        parts: &'a mut Parts<'w>,
        options: &'a SolverOptions,
        t: f64,
    ) -> Self {
        Self {
            bs,
            parts,
            options,
            t,
            fallbacks: 0,
            evaluations: 0,
            signs: (false, false),
            orientation: 1.0,
            escape_side: 1.0,
        }
    }

    /// Newton–Raphson on the block's equations, from and into the block's coordinates of `q`
    /// (earlier stages' coordinates are inputs), ending with the block's factors at the
    /// returned positions when `factors_needed` (derivative solves follow).
    ///
    /// # Errors
    /// [`SolveError::NonFinite`] for a non-finite Φ, Φ_q or step; [`SolveError::Singular`] at a
    /// solution where the block Jacobian is singular or too ill-conditioned (the diagnosis is
    /// in the workspace's orders); [`SolveError::NoAssembly`] when the residual stops
    /// decreasing above the tolerance; [`SolveError::Unresolved`] when the corrections reached
    /// the rounding of the coordinates but the residual stayed above `acceptance_tolerance`;
    /// [`SolveError::NoConvergence`] after `max_iterations`.
    pub fn solve(
        &mut self,
        q: &mut Vector<M::Dim>,
        factors_needed: bool,
    ) -> Result<Solved, SolveError> {
        // Kept whole: one Newton loop; its phases share the pending step and the last correction.
        let options = *self.options;
        // A looser residual tolerance asked for loosens acceptance with it.
        let acceptance = options.acceptance_tolerance.max(options.residual_tolerance);
        let (mut iterations, mut finishing) = (0, false);
        // Length of the last full Newton correction, for the contraction test, and how many
        // corrections in a row crawled.
        let mut previous: Option<f64> = None;
        let mut crawls = 0;
        let mut marquardt = Marquardt::default();
        // The step last applied: merit at `base` and the fraction of the step taken.
        let mut pending: Option<(f64, f64)> = None;
        loop {
            let factored = self.evaluate(q);
            self.check_phi()?;
            let (merit, residual) = self.norms();
            let magnitude = self.magnitude(q);
            let small = residual <= options.residual_tolerance * magnitude;
            if finishing {
                return self.finish_evaluated(q, factored, residual, acceptance, iterations);
            }
            if let Some((base_merit, fraction)) = pending.take() {
                let enough = merit <= (1.0 - SUFFICIENT_DECREASE * fraction) * base_merit;
                if !small && (factored.is_err() || !enough) {
                    previous = None;
                    if fraction > MIN_STEP_FRACTION {
                        self.retreat(q, fraction * 0.5);
                        pending = Some((base_merit, fraction * 0.5));
                        continue;
                    }
                    self.restore(q);
                    self.marquardt_step(q, &mut marquardt, &mut iterations)?;
                    continue;
                }
            }
            let factors = match factored {
                Ok(factors) => factors,
                Err(LuError::Singular { .. }) if residual <= SINGULAR_RESIDUAL => {
                    return Err(self.diagnose(q, f64::INFINITY));
                }
                Err(LuError::Singular { .. }) => {
                    previous = None;
                    self.marquardt_step(q, &mut marquardt, &mut iterations)?;
                    continue;
                }
                Err(error) => return Err(self.factor_error(q, error)),
            };
            if iterations >= options.max_iterations {
                return Err(self.give_up(q, factors, iterations, residual, &marquardt));
            }

            let length = self.newton_step(factors)?;
            let fraction = if length > options.max_step {
                options.max_step / length
            } else {
                1.0
            };
            let crawling = fraction == 1.0
                && residual <= SINGULAR_RESIDUAL
                && previous.is_some_and(|p| length >= CRAWL_RATIO * p);
            crawls = if crawling { crawls + 1 } else { 0 };
            if crawls >= CRAWL_LIMIT {
                return Err(self.diagnose(q, f64::INFINITY));
            }
            let converged = length <= options.step_tolerance * magnitude
                && previous.map_or(small, |p| length <= CONTRACTION * p);
            previous = Some(length);
            self.save_base(q);
            self.retreat(q, fraction);
            pending = Some((merit, fraction));
            iterations += 1;
            if converged {
                // The residual before the correction bounds the one after it; only when it is
                // above the acceptance tolerance must the returned positions be evaluated.
                let accepted = residual <= acceptance;
                if accepted && (!factors_needed || length <= NEGLIGIBLE_STEP) {
                    return self.finish(q, factors, iterations);
                }
                finishing = true;
            }
        }
    }

    /// The end of a solve whose last correction was not negligible: the positions it returned
    /// were evaluated (`factored`, with ‖D_r Φ_b‖∞ = `residual`), and are accepted with these
    /// factors if the residual is within `acceptance`.
    fn finish_evaluated(
        &mut self,
        q: &Vector<M::Dim>,
        factored: Result<Factors, LuError>,
        residual: f64,
        acceptance: f64,
        iterations: usize,
    ) -> Result<Solved, SolveError> {
        // Acceptance is absolute: a step test relative to large coordinates (an angle
        // of 1e12 rad) must not accept a residual of their rounding.
        if residual > acceptance {
            return Err(self.unresolved(iterations));
        }
        match factored {
            Ok(factors) => self.finish(q, factors, iterations),
            Err(error) => Err(self.factor_error(q, error)),
        }
    }

    /// The Newton step `step ← J⁻¹ Φ = −Δq` with `factors`, and its length ‖D_c⁻¹ step‖∞ in
    /// scene lengths and radians.
    ///
    /// # Errors
    /// [`SolveError::NonFinite`] for a non-finite step.
    fn newton_step(&mut self, factors: Factors) -> Result<f64, SolveError> {
        let n = self.bs.n();
        let newton = &mut self.parts.newton;
        newton.step[..n].copy_from_slice(&newton.phi[..n]);
        self.bs.solve(
            factors,
            &self.parts.factors,
            &self.parts.scales,
            self.parts.newton.step,
        );
        let length = scaled_max(&self.parts.newton.step[..n], self.parts.scales.inverse_cols);
        if !length.is_finite() {
            return Err(non_finite(self.t, Quantity::Step));
        }
        Ok(length)
    }

    /// Evaluates Φ_b into `phi` and factors the scaled block Jacobian at `q`.
    fn evaluate(&mut self, q: &Vector<M::Dim>) -> Result<Factors, LuError> {
        let parts = &mut *self.parts;
        let factored = self.bs.factor(
            q,
            parts.trig,
            self.t,
            parts.newton.phi,
            &mut parts.factors,
            &parts.scales,
            parts.estimator.x,
            self.options,
        );
        self.evaluations += 1;
        if let Ok(factors) = factored {
            self.fallbacks += usize::from(factors.fell_back());
            self.orientation = self.bs.orientation(factors, &self.parts.factors);
            if self.orientation > 0.0 {
                self.signs.0 = true;
            } else {
                self.signs.1 = true;
            }
        }
        factored
    }

    /// The block's factors at given positions (for separate derivative solves).
    ///
    /// # Errors
    /// [`SolveError::Singular`] with the diagnosis, or [`SolveError::NonFinite`] for the
    /// Jacobian.
    pub fn factor_at(&mut self, q: &Vector<M::Dim>) -> Result<Factors, SolveError> {
        self.evaluate(q)
            .map_err(|error| self.factor_error(q, error))
    }

    fn check_phi(&self) -> Result<(), SolveError> {
        let phi = &self.parts.newton.phi[..self.bs.n()];
        if all_finite(phi) {
            return Ok(());
        }
        let row = phi.iter().position(|x| !x.is_finite());
        Err(SolveError::NonFinite {
            time: self.t,
            quantity: Quantity::Phi,
            equation: row.and_then(|i| self.bs.block.equations.get(i).copied()),
            names: &Names::NONE,
        })
    }

    /// A non-finite Jacobian at `q`, naming the first equation with a non-finite entry.
    fn non_finite_jacobian(&mut self, q: &Vector<M::Dim>) -> SolveError {
        let parts = &mut *self.parts;
        SolveError::NonFinite {
            time: self.t,
            quantity: Quantity::Jacobian,
            equation: self.bs.non_finite_equation(
                q,
                parts.trig,
                self.t,
                parts.newton.trial,
                parts.factors.values,
            ),
            names: &Names::NONE,
        }
    }

    /// (‖D_r Φ_b‖₂, ‖D_r Φ_b‖∞) of `phi`.
    fn norms(&self) -> (f64, f64) {
        let n = self.bs.n();
        scaled_norms(&self.parts.newton.phi[..n], self.parts.scales.rows)
    }

    /// max(1, ‖D_c⁻¹ q_b‖∞): tolerances are relative to the size of the block's own
    /// coordinates (a coupler that has turned for hours has θ ~ 1e6 rad, which no absolute
    /// angle tolerance near ε could resolve; a huge angle elsewhere does not loosen this block).
    fn magnitude(&self, q: &Vector<M::Dim>) -> f64 {
        let q = q.as_slice();
        let values = self.bs.block.coordinates.iter().map(|&j| q[j]);
        scaled_max_iter(values, self.parts.scales.inverse_cols).max(1.0)
    }

    /// `base ← q_b`.
    fn save_base(&mut self, q: &Vector<M::Dim>) {
        let q = q.as_slice();
        for (b, &j) in self
            .parts
            .newton
            .base
            .iter_mut()
            .zip(self.bs.block.coordinates)
        {
            *b = q[j];
        }
    }

    /// `q_b ← base`.
    fn restore(&self, q: &mut Vector<M::Dim>) {
        let q = q.as_mut_slice();
        for (&b, &j) in self.parts.newton.base.iter().zip(self.bs.block.coordinates) {
            q[j] = b;
        }
    }

    /// `q_b = base − fraction · step`.
    fn retreat(&self, q: &mut Vector<M::Dim>, fraction: f64) {
        let q = q.as_mut_slice();
        let newton = &self.parts.newton;
        for ((&b, &s), &j) in newton
            .base
            .iter()
            .zip(newton.step.iter())
            .zip(self.bs.block.coordinates)
        {
            q[j] = b - fraction * s;
        }
    }

    /// The check at a converged `q`: the condition of the factors kept.
    fn finish(
        &mut self,
        q: &Vector<M::Dim>,
        factors: Factors,
        iterations: usize,
    ) -> Result<Solved, SolveError> {
        let condition = if self.options.estimate_condition {
            let condition = self.condition(factors);
            if condition.is_nan() || condition > self.options.max_condition {
                return Err(self.diagnose(q, condition));
            }
            condition
        } else {
            f64::NAN
        };
        Ok(Solved {
            iterations,
            residual: max_abs(&self.parts.newton.phi[..self.bs.n()]),
            condition,
            // `factors` are the last ones evaluated.
            orientation: self.orientation,
            swept: self.signs.0 && self.signs.1,
            factors,
        })
    }

    /// Condition estimate of the current factors, warm-started from the block's last one.
    pub fn condition(&mut self, factors: Factors) -> f64 {
        let parts = &mut *self.parts;
        let hint = &mut parts.hints[self.bs.stage];
        self.bs
            .condition(factors, &parts.factors, &mut parts.estimator, hint)
    }

    /// A failed factorisation at a (converged or given) `q`, as a solve error.
    pub fn factor_error(&mut self, q: &Vector<M::Dim>, error: LuError) -> SolveError {
        match error {
            LuError::Singular { .. } => self.diagnose(q, f64::INFINITY),
            _ => self.non_finite_jacobian(q),
        }
    }

    /// Why a solve hit the iteration cap.
    fn give_up(
        &mut self,
        q: &Vector<M::Dim>,
        factors: Factors,
        iterations: usize,
        residual: f64,
        marquardt: &Marquardt,
    ) -> SolveError {
        // Newton crawls into a singular root (linearly, not quadratically): name the cause.
        if residual <= SINGULAR_RESIDUAL {
            let condition = self.condition(factors);
            if condition.is_nan() || condition > self.options.max_condition {
                return self.diagnose(q, condition);
            }
        }
        if marquardt.used {
            self.no_assembly(q, iterations)
        } else {
            let (equation, residual) = self.worst_equation();
            SolveError::NoConvergence {
                time: self.t,
                iterations,
                residual,
                equation,
                names: &Names::NONE,
            }
        }
    }

    /// Why the residual stopped decreasing at `q` (whose Φ_b is in `phi`): above
    /// [`SINGULAR_RESIDUAL`] the constraints cannot be met ([`SolveError::NoAssembly`]); below
    /// it, `q` is (next to) a solution where the Jacobian is singular, so Newton crawled
    /// instead of converging: redundant constraints or a toggle position
    /// ([`SolveError::Singular`]).
    fn no_assembly(&mut self, q: &Vector<M::Dim>, iterations: usize) -> SolveError {
        if self.norms().1 <= SINGULAR_RESIDUAL {
            let condition = match self.evaluate(q) {
                Ok(factors) => self.condition(factors),
                Err(_) => f64::INFINITY,
            };
            return self.diagnose(q, condition);
        }
        let (equation, residual) = self.worst_equation();
        SolveError::NoAssembly {
            time: self.t,
            iterations,
            residual,
            equation,
            names: &Names::NONE,
        }
    }

    /// Converged as finely as the coordinates' rounding allows, with the residual in `phi`
    /// still above the acceptance tolerance.
    fn unresolved(&self, iterations: usize) -> SolveError {
        let (equation, residual) = self.worst_equation();
        SolveError::Unresolved {
            time: self.t,
            iterations,
            residual,
            equation,
            names: &Names::NONE,
        }
    }

    /// The global index of the equation with the largest scaled residual in `phi`, and ‖Φ_b‖∞.
    fn worst_equation(&self) -> (usize, f64) {
        let n = self.bs.n();
        let (rows, phi) = (&self.parts.scales.rows[..n], &self.parts.newton.phi[..n]);
        let mut worst = (0, 0.0);
        for (i, (r, p)) in rows.iter().zip(phi).enumerate() {
            if (r * p).abs() > worst.1 {
                worst = (i, (r * p).abs());
            }
        }
        let equation = self.bs.block.equations.get(worst.0).copied().unwrap_or(0);
        (equation, max_abs(phi))
    }

    /// The rank-revealing diagnosis of a singular or ill-conditioned block Jacobian at `q`:
    /// which equations depend on the others, which coordinates they leave free (global indices
    /// in the workspace's order buffers).
    pub fn diagnose(&mut self, q: &Vector<M::Dim>, condition: f64) -> SolveError {
        let n = self.bs.n();
        let floor = self.options.pivot_tolerance * n as f64;
        let mut tolerance = (1.0 / self.options.max_condition).max(floor);
        let parts = &mut *self.parts;
        // A condition above the limit but no pivot below the tolerance: widen until the
        // smallest pivots show (complete pivoting makes them track the small singular values).
        for _ in 0..8 {
            let revealed = self.bs.diagnose(
                q,
                parts.trig,
                self.t,
                parts.newton.phi,
                parts.factors.values,
                &parts.scales,
                parts.estimator.x,
                parts.dense,
                parts.row_order,
                parts.col_order,
                tolerance,
            );
            match revealed {
                Ok(0) => tolerance *= 10.0,
                Ok(deficiency) => {
                    return SolveError::Singular {
                        time: self.t,
                        equation: parts.row_order[0],
                        coordinate: parts.col_order[0],
                        condition,
                        deficiency,
                        names: &Names::NONE,
                    };
                }
                Err(_) => return self.non_finite_jacobian(q),
            }
        }
        SolveError::Singular {
            time: self.t,
            equation: self.bs.block.equations.first().copied().unwrap_or(0),
            coordinate: self.bs.block.coordinates.first().copied().unwrap_or(0),
            condition,
            deficiency: 0,
            names: &Names::NONE,
        }
    }

    /// One accepted Levenberg–Marquardt step from `q`: solves (J_sᵀJ_s + μI) δ = J_sᵀ Φ_s on
    /// the scaled block, raising μ until the step reduces ‖D_r Φ_b‖₂. Used where Newton's step
    /// fails: at a singular Jacobian, or when its direction does not reduce the residual (far
    /// from a solution, or where none exists, whose nonzero least-squares minimum it then
    /// finds).
    ///
    /// # Errors
    /// [`SolveError::NoAssembly`] when no μ reduces the residual, or progress stalls, above the
    /// tolerance; non-finite evaluations; the iteration cap.
    fn marquardt_step(
        &mut self,
        q: &mut Vector<M::Dim>,
        marquardt: &mut Marquardt,
        iterations: &mut usize,
    ) -> Result<(), SolveError> {
        marquardt.used = true;
        if *iterations >= self.options.max_iterations {
            self.residual_at(q)?;
            return Err(self.no_assembly(q, *iterations));
        }
        self.evaluate_dense(q)?;
        let (merit, residual) = self.norms();
        if residual <= self.options.residual_tolerance {
            return Ok(());
        }
        let largest = self.gradient();
        if !largest.is_finite() {
            return Err(self.non_finite_jacobian(q));
        }
        if largest == 0.0 {
            // The Jacobian vanishes: no direction reduces the residual.
            return Err(self.no_assembly(q, *iterations));
        }
        if marquardt.mu == 0.0 {
            marquardt.mu = 1e-3 * largest;
        }
        self.save_base(q);
        // μ beyond this leaves a step of round-off size: the residual is at a minimum.
        let mu_limit = 1e14 * largest;
        let mut trials = 0;
        while marquardt.mu <= mu_limit && trials < MAX_DAMPING_TRIALS {
            trials += 1;
            let mu = marquardt.mu;
            let trial_merit = self.damped_trial(q, mu);
            if trial_merit < merit {
                let progress = 1.0 - trial_merit / merit;
                return self.accept_damped(q, marquardt, iterations, mu, largest, progress);
            }
            self.restore(q);
            marquardt.mu = mu * 4.0;
        }
        // No damped step reduces the residual: a stationary point. At a singular start (links
        // guessed in line) that is a saddle, left along the Jacobian's null direction; at a
        // minimum of the residual no direction reduces it, and the loop cannot close.
        if !marquardt.escaped {
            marquardt.escaped = true;
            if self.escape(q, merit, largest)? {
                *iterations += 1;
                return Ok(());
            }
        }
        Err(self.no_assembly(q, *iterations))
    }

    /// Takes the damped step (with damping `mu`) whose trial point is in `q` and its Φ_b in
    /// `trial`: that Φ_b becomes `phi`, μ shrinks (to no less than 1e-12 of the largest
    /// squared column norm `largest`), and a step whose relative `progress` is below
    /// [`STALL_DECREASE`] counts towards a stall.
    ///
    /// # Errors
    /// [`SolveError::NoAssembly`] after [`STALL_LIMIT`] stalled steps in a row.
    fn accept_damped(
        &mut self,
        q: &Vector<M::Dim>,
        marquardt: &mut Marquardt,
        iterations: &mut usize,
        mu: f64,
        largest: f64,
        progress: f64,
    ) -> Result<(), SolveError> {
        let n = self.bs.n();
        let newton = &mut self.parts.newton;
        newton.phi[..n].copy_from_slice(&newton.trial[..n]);
        *iterations += 1;
        marquardt.mu = (mu / 3.0).max(1e-12 * largest);
        marquardt.stalls = if progress < STALL_DECREASE {
            marquardt.stalls + 1
        } else {
            0
        };
        if marquardt.stalls >= STALL_LIMIT {
            return Err(self.no_assembly(q, *iterations));
        }
        Ok(())
    }

    /// Φ_b at `q` into `phi` and the scaled Jacobian S = D_r J D_c into `dense`, for a
    /// Levenberg–Marquardt step.
    fn evaluate_dense(&mut self, q: &Vector<M::Dim>) -> Result<(), SolveError> {
        let n = self.bs.n();
        let parts = &mut *self.parts;
        let evaluated = self.bs.evaluate(
            q,
            parts.trig,
            self.t,
            parts.newton.phi,
            parts.factors.values,
            &parts.scales,
            parts.estimator.x,
        );
        self.check_phi()?;
        if evaluated.is_err() {
            return Err(self.non_finite_jacobian(q));
        }
        let parts = &mut *self.parts;
        self.bs
            .scatter(parts.factors.values, &mut parts.dense[..n * n]);
        Ok(())
    }

    /// The merit ‖D_r Φ_b‖₂ at the trial point of a Levenberg–Marquardt step with damping
    /// `mu` from `base` (S in `dense`, J_sᵀ Φ_s in `gradient`): q_b = base − D_c δ, δ clamped
    /// to `max_step`, its Φ_b into `trial`. Infinite (and `q` untouched) when the damped system
    /// cannot be factored or its step is not finite.
    fn damped_trial(&mut self, q: &mut Vector<M::Dim>, mu: f64) -> f64 {
        let n = self.bs.n();
        let parts = &mut *self.parts;
        let (lu, swaps) = (
            &mut parts.factors.lu[..n * n],
            &mut parts.factors.swaps[..n],
        );
        normal_matrix(&parts.dense[..n * n], n, mu, lu);
        let factored = lu::factor_in_place(lu, swaps, self.options.pivot_tolerance, 0.0).is_ok();
        let step = &mut parts.newton.step[..n];
        if factored {
            step.copy_from_slice(&parts.newton.gradient[..n]);
            lu::solve_factors(lu, swaps, step);
        }
        // Trial point q_b = base − D_c δ (δ clamped), its Φ_b into `trial`.
        let length = max_abs(step);
        let fraction = if length > self.options.max_step {
            self.options.max_step / length
        } else {
            1.0
        };
        if factored && length.is_finite() {
            let qs = q.as_mut_slice();
            for (((&b, &s), &c), &j) in parts
                .newton
                .base
                .iter()
                .zip(step.iter())
                .zip(parts.scales.cols.iter())
                .zip(self.bs.block.coordinates)
            {
                qs[j] = b - fraction * s * c;
            }
            self.bs.m.block_jacobian(
                self.bs.stage,
                q,
                parts.trig,
                self.t,
                &mut parts.newton.trial[..n],
                &mut parts.factors.values[..self.bs.block.slots],
            );
            scaled_norms(&parts.newton.trial[..n], parts.scales.rows).0
        } else {
            f64::INFINITY
        }
    }

    /// The direction v that the scaled Jacobian S (in `dense`) maps closest to zero, into
    /// `step`: inverse iteration on SᵀS + μI, μ tiny against the largest squared column norm
    /// `largest`, v signed so that its largest component is positive. `false` when SᵀS + μI
    /// cannot be factored or the iteration degenerates.
    fn null_direction(&mut self, largest: f64) -> bool {
        let n = self.bs.n();
        let parts = &mut *self.parts;
        let (lu, swaps) = (
            &mut parts.factors.lu[..n * n],
            &mut parts.factors.swaps[..n],
        );
        normal_matrix(&parts.dense[..n * n], n, 1e-10 * largest, lu);
        if lu::factor_in_place(lu, swaps, 0.0, 0.0).is_err() {
            return false;
        }
        let v = &mut parts.newton.step[..n];
        v.fill(1.0);
        for _ in 0..3 {
            lu::solve_factors(lu, swaps, v);
            let size = max_abs(v);
            if !(size.is_finite() && size > 0.0) {
                return false;
            }
            let sign = v
                .iter()
                .fold(0.0_f64, |m, x| if x.abs() > m.abs() { *x } else { m });
            let norm = size.copysign(sign);
            v.iter_mut().for_each(|x| *x /= norm);
        }
        true
    }

    /// From a stationary point `q` (Φ_b in `phi`, scaled Jacobian S in `dense`) where the merit
    /// is `merit`: the direction v that S maps closest to zero (inverse iteration on
    /// SᵀS + μI, μ tiny against the largest squared column norm `largest`), signed so that its
    /// largest component is positive, and steps of ±1/2ᵏ scene lengths or radians along it
    /// (the [`Newton::escape_side`] first, longest first). Along v the residual changes only at second order, so a saddle
    /// (a flat guess: every link on one line) is left by one of them; the first that reduces
    /// the merit is taken (its Φ_b in `phi`) and `true` returned. `false` (and `q` unchanged)
    /// when none does: a minimum, where the loop cannot close.
    fn escape(
        &mut self,
        q: &mut Vector<M::Dim>,
        merit: f64,
        largest: f64,
    ) -> Result<bool, SolveError> {
        if !self.null_direction(largest) {
            return Ok(false);
        }
        let n = self.bs.n();
        self.save_base(q);
        for sign in [self.escape_side, -self.escape_side] {
            let mut length = self.options.max_step;
            for _ in 0..6 {
                let parts = &mut *self.parts;
                let qs = q.as_mut_slice();
                for (((&b, &v), &c), &j) in parts
                    .newton
                    .base
                    .iter()
                    .zip(parts.newton.step.iter())
                    .zip(parts.scales.cols.iter())
                    .zip(self.bs.block.coordinates)
                {
                    qs[j] = b + sign * length * v * c;
                }
                self.bs.m.block_jacobian(
                    self.bs.stage,
                    q,
                    parts.trig,
                    self.t,
                    &mut parts.newton.trial[..n],
                    &mut parts.factors.values[..self.bs.block.slots],
                );
                let trial = scaled_norms(&parts.newton.trial[..n], parts.scales.rows).0;
                if trial < (1.0 - SUFFICIENT_DECREASE) * merit {
                    let newton = &mut self.parts.newton;
                    newton.phi[..n].copy_from_slice(&newton.trial[..n]);
                    return Ok(true);
                }
                length *= 0.5;
            }
        }
        self.restore(q);
        Ok(false)
    }

    /// Φ_b at `q` into `phi` (the Jacobian values are overwritten and not used).
    fn residual_at(&mut self, q: &Vector<M::Dim>) -> Result<(), SolveError> {
        let n = self.bs.n();
        let parts = &mut *self.parts;
        self.bs.m.block_jacobian(
            self.bs.stage,
            q,
            parts.trig,
            self.t,
            &mut parts.newton.phi[..n],
            &mut parts.factors.values[..self.bs.block.slots],
        );
        self.check_phi()
    }

    /// Writes J_sᵀ (D_r Φ_b) into `gradient` from the scaled dense Jacobian in `dense`, and
    /// returns the largest diagonal entry of J_sᵀ J_s (the largest squared column norm).
    fn gradient(&mut self) -> f64 {
        let n = self.bs.n();
        let parts = &mut *self.parts;
        let (rows, phi) = (&parts.scales.rows[..n], &parts.newton.phi[..n]);
        let mut largest = 0.0_f64;
        let columns = parts.dense[..n * n].chunks_exact(n.max(1));
        for (column, g) in columns.zip(parts.newton.gradient.iter_mut()) {
            let (mut dot, mut norm) = (0.0, 0.0);
            for ((a, r), p) in column.iter().zip(rows).zip(phi) {
                dot += a * r * p;
                norm += a * a;
            }
            *g = dot;
            largest = largest.max(norm);
        }
        largest
    }
}

/// `a = jᵀ j + μ I` for the column-major n × n `j` (small, and the rare fallback path).
fn normal_matrix(j: &[f64], n: usize, mu: f64, a: &mut [f64]) {
    for col in 0..n {
        let jc = &j[col * n..(col + 1) * n];
        for row in 0..n {
            let jr = &j[row * n..(row + 1) * n];
            let dot: f64 = jr.iter().zip(jc).map(|(x, y)| x * y).sum();
            a[col * n + row] = if row == col { dot + mu } else { dot };
        }
    }
}

/// (‖D_r v‖₂, ‖D_r v‖∞).
#[inline]
pub(crate) fn scaled_norms(v: &[f64], rows: &[f64]) -> (f64, f64) {
    let (mut sum, mut max) = (0.0_f64, 0.0_f64);
    for (x, r) in v.iter().zip(rows) {
        let y = x * r;
        sum += y * y;
        max = max.max(y.abs());
    }
    (libm::sqrt(sum), max)
}

/// ‖D_c⁻¹ v‖∞: a step or a position in scene lengths and radians; a NaN entry makes it NaN, so
/// that callers see a non-finite step rather than a small one.
#[inline]
pub(crate) fn scaled_max(v: &[f64], inverse_cols: &[f64]) -> f64 {
    scaled_max_iter(v.iter().copied(), inverse_cols)
}

fn scaled_max_iter(v: impl Iterator<Item = f64>, inverse_cols: &[f64]) -> f64 {
    v.zip(inverse_cols).fold(0.0, |m, (x, c)| {
        let y = (x * c).abs();
        if y > m || y.is_nan() { y } else { m }
    })
}

/// ‖v‖∞.
#[inline]
pub(crate) fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}
