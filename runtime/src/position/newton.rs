//! Newton–Raphson on one block: the iteration with its step clamp, deferred line search and
//! stopping rule, the evaluations and factorisations it makes, and the check at its solution.

use nalgebra::DefaultAllocator;

use super::closed;
use super::marquardt::Marquardt;
use super::norms::{max_abs, scaled_max, scaled_max_iter, scaled_norms};
use super::{
    CONTRACTION, CRAWL_LIMIT, CRAWL_RATIO, MIN_STEP_FRACTION, NEGLIGIBLE_STEP, SINGULAR_RESIDUAL,
    SUFFICIENT_DECREASE,
};

use crate::block::{BlockSolve, Factors};
use crate::error::{Quantity, SolveError};
use crate::finite::{all_finite, non_finite};
use crate::lu::LuError;
use crate::mechanism::{Storage, Vector};
use crate::names::Names;
use crate::options::SolverOptions;
use crate::structure::Structured;
use crate::workspace::Parts;

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
    /// Whether the iteration started from the block's closed-form solution.
    pub closed_form: bool,
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
            closed_form: false,
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
    ///
    /// A block with a closed form starts from its solution nearest `q` ([`closed::start`]).
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
        if options.closed_forms {
            self.closed_form = closed::start(&self.bs, self.parts, q, self.t);
        }
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
    pub(super) fn evaluate(&mut self, q: &Vector<M::Dim>) -> Result<Factors, LuError> {
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

    pub(super) fn check_phi(&self) -> Result<(), SolveError> {
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
    pub(super) fn non_finite_jacobian(&mut self, q: &Vector<M::Dim>) -> SolveError {
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
    pub(super) fn norms(&self) -> (f64, f64) {
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
    pub(super) fn save_base(&mut self, q: &Vector<M::Dim>) {
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
    pub(super) fn restore(&self, q: &mut Vector<M::Dim>) {
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
}
