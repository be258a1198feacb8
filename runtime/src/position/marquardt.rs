//! The Levenberg–Marquardt fallback of a block's solve: damped steps where Newton's cannot
//! be used, and the escape from a stationary point along the Jacobian's null direction.

use nalgebra::DefaultAllocator;

use super::newton::Newton;
use super::norms::{max_abs, scaled_norms};
use super::{MAX_DAMPING_TRIALS, STALL_DECREASE, STALL_LIMIT, SUFFICIENT_DECREASE};

use crate::error::SolveError;
use crate::lu;
use crate::mechanism::{Storage, Vector};
use crate::structure::Structured;

/// Levenberg–Marquardt state carried across the iterations of one block's solve.
#[derive(Default)]
pub(super) struct Marquardt {
    /// Damping μ (0: not yet chosen).
    mu: f64,
    /// Consecutive accepted steps with little progress.
    stalls: usize,
    /// Whether any step was needed: a capped solve that needed them did not assemble.
    pub(super) used: bool,
    /// Whether a step along the Jacobian's null direction was tried ([`Newton::escape`]).
    escaped: bool,
}

impl<'a, 'w, M: Structured> Newton<'a, 'w, M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// One accepted Levenberg–Marquardt step from `q`: solves (J_sᵀJ_s + μI) δ = J_sᵀ Φ_s on
    /// the scaled block, raising μ until the step reduces ‖D_r Φ_b‖₂. Used where Newton's step
    /// fails: at a singular Jacobian, or when its direction does not reduce the residual (far
    /// from a solution, or where none exists, whose nonzero least-squares minimum it then
    /// finds).
    ///
    /// # Errors
    /// [`SolveError::NoAssembly`] when no μ reduces the residual, or progress stalls, above the
    /// tolerance; non-finite evaluations; the iteration cap.
    pub(super) fn marquardt_step(
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
