//! The position solve: Newton–Raphson on the unit-scaled Φ(q, t) = 0, kept on track by a step
//! clamp, a backtracking line search and Levenberg–Marquardt steps where Newton's cannot be
//! used; and, when it fails, the diagnosis of why.
//!
//! The safeguards cost nothing on the usual path. A Newton step is applied without evaluating
//! the trial point first; the next iteration's evaluation, needed anyway, doubles as the line
//! search test, and only a step that failed to reduce the residual is taken back and shortened.

use nalgebra::DefaultAllocator;

use crate::error::{Quantity, SolveError};
use crate::lu::LuError;
use crate::mechanism::{Matrix, Mechanism, Outputs, Storage, Vector};
use crate::solver::{
    Convergence, Solver, check_finite, lu_error, max_abs, non_finite, scaled_max_abs,
};

/// Armijo constant: a step of length α must reduce the merit ‖D_r Φ‖₂ by at least this · α.
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

/// Levenberg–Marquardt state carried across the iterations of one solve.
#[derive(Default)]
struct Marquardt {
    /// Damping μ (0: not yet chosen).
    mu: f64,
    /// Consecutive accepted steps with little progress.
    stalls: usize,
    /// Whether any step was needed: a capped solve that needed them did not assemble.
    used: bool,
}

impl<M: Mechanism> Solver<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Newton–Raphson on Φ(q, t) = 0, starting from and overwriting `q`.
    ///
    /// Each iteration evaluates Φ and Φ_q at `q`, factors the unit-scaled Φ_q and steps.
    /// Converged once a step within `step_tolerance` has been taken from a point within
    /// `residual_tolerance` (both scaled); Φ_q is then evaluated and factored once more at the
    /// returned `q`, so the residual reported is the true one, the kept factors are exactly those
    /// of Φ_q(q) (for the derivative solves), and `q` is quadratically accurate.
    ///
    /// Safeguards: steps longer than `max_step` are shortened; a step that does not reduce
    /// ‖D_r Φ‖₂ is halved down to 1/64, then replaced by a Levenberg–Marquardt step, as is a
    /// step from an iterate where Φ_q is singular. At the solution the condition of the scaled
    /// Φ_q must be below `max_condition`, and every branch invariant of the scene positive.
    ///
    /// # Errors
    /// [`SolveError::NonFinite`] for a non-finite `t`, parameter, guess, Φ, Φ_q or step;
    /// [`SolveError::Singular`] at a solution where Φ_q is singular or too ill-conditioned (the
    /// solver then lists every dependent equation: [`Solver::dependent_equations`]);
    /// [`SolveError::NoAssembly`] when the residual stops decreasing above the tolerance;
    /// [`SolveError::BranchFlip`] for a solution on another branch;
    /// [`SolveError::NoConvergence`] after `max_iterations` updates. `q` holds the last iterate.
    pub fn solve_position(
        &mut self,
        q: &mut Vector<M::Dim>,
        t: f64,
    ) -> Result<Convergence, SolveError> {
        self.check_inputs(t, q, Quantity::Guess)?;
        self.check_parameters(t)?;
        self.update_scales();
        let options = self.options;
        let (mut iterations, mut converged) = (0, false);
        let mut marquardt = Marquardt::default();
        // The step last applied: merit at `base` and the fraction of the step taken.
        let mut pending: Option<(f64, f64)> = None;
        loop {
            let factored = self.evaluate(q, t);
            check_finite(&self.phi, t, Quantity::Phi)?;
            let (merit, residual) = scaled_norms(&self.phi, &self.rows);
            // Relative to the scaled coordinates' size as well: a crank that has turned for
            // hours has θ ~ 1e6 rad, which no absolute angle tolerance near ε could resolve.
            let magnitude = scaled_max(q, &self.cols).max(1.0);
            let small = residual <= options.residual_tolerance * magnitude;

            if let Some((base_merit, fraction)) = pending.take() {
                let enough = merit <= (1.0 - SUFFICIENT_DECREASE * fraction) * base_merit;
                if !small && (factored.is_err() || !enough) {
                    if fraction > MIN_STEP_FRACTION {
                        self.retreat(q, fraction * 0.5);
                        pending = Some((base_merit, fraction * 0.5));
                        continue;
                    }
                    q.copy_from(&self.base);
                    self.marquardt_step(q, t, &mut marquardt, &mut iterations)?;
                    converged = false;
                    continue;
                }
            }
            match factored {
                Ok(()) => {}
                Err(LuError::Singular { .. }) if residual <= SINGULAR_RESIDUAL => {
                    return Err(self.diagnose(q, t, f64::INFINITY));
                }
                Err(LuError::Singular { .. }) => {
                    self.marquardt_step(q, t, &mut marquardt, &mut iterations)?;
                    converged = false;
                    continue;
                }
                Err(error) => return Err(lu_error(error, t)),
            }
            if converged {
                return self.accept(q, t, iterations);
            }
            if iterations >= options.max_iterations {
                return Err(self.give_up(q, t, iterations, residual, &marquardt));
            }

            self.step.copy_from(&self.phi);
            self.lu
                .solve_in_place(&mut self.step)
                .map_err(|error| lu_error(error, t))?;
            // `step` now holds Φ_q⁻¹ Φ = −Δq.
            let length = scaled_max(&self.step, &self.cols);
            if !length.is_finite() {
                return Err(non_finite(t, Quantity::Step));
            }
            converged = small && length <= options.step_tolerance * magnitude;
            let fraction = if length > options.max_step {
                options.max_step / length
            } else {
                1.0
            };
            self.base.copy_from(q);
            self.retreat(q, fraction);
            pending = Some((merit, fraction));
            iterations += 1;
            // A positions-only scene needs no factors at the returned q (nothing solves with
            // them): stop without the confirming evaluation; the residual reported is then the
            // one before the last (tiny) step, an upper bound.
            if converged && self.mechanism.outputs() == Outputs::Positions {
                return self.accept(q, t, iterations);
            }
        }
    }

    /// Evaluates Φ into `phi` and factors the scaled Φ_q at `q`.
    fn evaluate(&mut self, q: &Vector<M::Dim>, t: f64) -> Result<(), LuError> {
        let Self {
            mechanism,
            phi,
            lu,
            rows,
            cols,
            ..
        } = self;
        lu.factor_scaled_with(rows, cols, |jacobian| {
            mechanism.phi_and_jacobian(q, t, phi, jacobian);
        })
    }

    /// `q = base − fraction · step`.
    fn retreat(&self, q: &mut Vector<M::Dim>, fraction: f64) {
        let (base, step) = (self.base.as_slice(), self.step.as_slice());
        for ((q, b), s) in q.as_mut_slice().iter_mut().zip(base).zip(step) {
            *q = b - fraction * s;
        }
    }

    /// The checks at a converged `q`: condition and branch invariants.
    fn accept(
        &mut self,
        q: &Vector<M::Dim>,
        t: f64,
        iterations: usize,
    ) -> Result<Convergence, SolveError> {
        let condition = if self.options.estimate_condition {
            let condition = self.lu.condition_estimate().unwrap_or(f64::INFINITY);
            if condition.is_nan() || condition > self.options.max_condition {
                return Err(self.diagnose(q, t, condition));
            }
            condition
        } else {
            f64::NAN
        };
        let m = &self.mechanism;
        for branch in 0..m.branch_count() {
            let value = m.branch_value(branch, q);
            if !value.is_finite() {
                return Err(non_finite(t, Quantity::Branch(branch)));
            }
            if value <= 0.0 {
                return Err(SolveError::BranchFlip {
                    time: t,
                    branch,
                    value,
                });
            }
        }
        Ok(Convergence {
            iterations,
            residual: max_abs(&self.phi),
            condition,
        })
    }

    /// Why a solve hit the iteration cap.
    fn give_up(
        &mut self,
        q: &Vector<M::Dim>,
        t: f64,
        iterations: usize,
        residual: f64,
        marquardt: &Marquardt,
    ) -> SolveError {
        // Newton crawls into a singular root (linearly, not quadratically): name the cause.
        if residual <= SINGULAR_RESIDUAL {
            let condition = self.lu.condition_estimate().unwrap_or(f64::INFINITY);
            if condition.is_nan() || condition > self.options.max_condition {
                return self.diagnose(q, t, condition);
            }
        }
        if marquardt.used {
            self.no_assembly(q, t, iterations)
        } else {
            SolveError::NoConvergence {
                time: t,
                iterations,
                residual: max_abs(&self.phi),
            }
        }
    }

    /// Why the residual stopped decreasing at `q` (whose Φ is in `phi`): above
    /// [`SINGULAR_RESIDUAL`] the constraints cannot be met ([`SolveError::NoAssembly`]); below
    /// it, `q` is (next to) a solution where Φ_q is singular, so Newton crawled instead of
    /// converging: redundant constraints or a toggle position ([`SolveError::Singular`]).
    fn no_assembly(&mut self, q: &Vector<M::Dim>, t: f64, iterations: usize) -> SolveError {
        if scaled_norms(&self.phi, &self.rows).1 <= SINGULAR_RESIDUAL {
            let condition = match self.evaluate(q, t) {
                Ok(()) => self.lu.condition_estimate().unwrap_or(f64::INFINITY),
                Err(_) => f64::INFINITY,
            };
            return self.diagnose(q, t, condition);
        }
        let (rows, phi) = (self.rows.as_slice(), self.phi.as_slice());
        let mut worst = (0, 0.0);
        for (i, (r, p)) in rows.iter().zip(phi).enumerate() {
            if (r * p).abs() > worst.1 {
                worst = (i, (r * p).abs());
            }
        }
        SolveError::NoAssembly {
            time: t,
            iterations,
            residual: max_abs(&self.phi),
            equation: worst.0,
        }
    }

    /// The rank-revealing diagnosis of a singular or ill-conditioned Φ_q at `q`: which
    /// equations depend on the others, which coordinates they leave free.
    fn diagnose(&mut self, q: &Vector<M::Dim>, t: f64, condition: f64) -> SolveError {
        let n = self.phi.nrows();
        let floor = self.options.pivot_tolerance * n as f64;
        let mut tolerance = (1.0 / self.options.max_condition).max(floor);
        let Self {
            mechanism,
            lu,
            rows,
            cols,
            ..
        } = self;
        // A condition above the limit but no pivot below the tolerance: widen until the
        // smallest pivots show (complete pivoting makes them track the small singular values).
        for _ in 0..8 {
            match lu.reveal_rank(rows, cols, tolerance, |j| mechanism.jacobian(q, t, j)) {
                Ok(rank) if rank < n => {
                    let first = |indices: &[usize]| indices.first().copied().unwrap_or(0);
                    return SolveError::Singular {
                        time: t,
                        equation: first(lu.dependent_rows()),
                        coordinate: first(lu.undetermined_columns()),
                        condition,
                        deficiency: n - rank,
                    };
                }
                Ok(_) => tolerance *= 10.0,
                Err(error) => return lu_error(error, t),
            }
        }
        SolveError::Singular {
            time: t,
            equation: 0,
            coordinate: 0,
            condition,
            deficiency: 0,
        }
    }

    /// One accepted Levenberg–Marquardt step from `q`: solves (J_sᵀJ_s + μI) δ = J_sᵀ Φ_s on
    /// the scaled system, raising μ until the step reduces ‖D_r Φ‖₂. Used where Newton's step
    /// fails: at a singular Φ_q, or when its direction does not reduce the residual (far from
    /// a solution, or where none exists, whose nonzero least-squares minimum it then finds).
    ///
    /// # Errors
    /// [`SolveError::NoAssembly`] when no μ reduces the residual, or progress stalls, above the
    /// tolerance; non-finite evaluations; the iteration cap.
    fn marquardt_step(
        &mut self,
        q: &mut Vector<M::Dim>,
        t: f64,
        marquardt: &mut Marquardt,
        iterations: &mut usize,
    ) -> Result<(), SolveError> {
        marquardt.used = true;
        if *iterations >= self.options.max_iterations {
            self.mechanism.phi(q, t, &mut self.phi);
            return Err(self.no_assembly(q, t, *iterations));
        }
        {
            let Self {
                mechanism,
                phi,
                jacobian,
                ..
            } = self;
            mechanism.phi_and_jacobian(q, t, phi, jacobian);
        }
        check_finite(&self.phi, t, Quantity::Phi)?;
        if !self.jacobian.as_slice().iter().all(|x| x.is_finite()) {
            return Err(non_finite(t, Quantity::Jacobian));
        }
        let (merit, residual) = scaled_norms(&self.phi, &self.rows);
        if residual <= self.options.residual_tolerance {
            return Ok(());
        }
        let largest = self.scale_jacobian_and_gradient();
        if largest == 0.0 {
            // Φ_q vanishes: no direction reduces the residual.
            return Err(self.no_assembly(q, t, *iterations));
        }
        if marquardt.mu == 0.0 {
            marquardt.mu = 1e-3 * largest;
        }
        // μ beyond this leaves a step of round-off size: the residual is at a minimum.
        let mu_limit = 1e14 * largest;
        while marquardt.mu <= mu_limit {
            let mu = marquardt.mu;
            let Self {
                lu,
                jacobian,
                step,
                gradient,
                ..
            } = self;
            let factored = lu.factor_with(|a| normal_matrix(jacobian, mu, a));
            if factored.is_ok() {
                step.copy_from(gradient);
                lu.solve_in_place(step)
                    .map_err(|error| lu_error(error, t))?;
            }
            // Trial point q − D_c δ (δ clamped) into `base`, its Φ into `trial`.
            let length = max_abs(&self.step);
            let fraction = if length > self.options.max_step {
                self.options.max_step / length
            } else {
                1.0
            };
            let trial_merit = if factored.is_ok() && length.is_finite() {
                for (((b, x), s), c) in self
                    .base
                    .as_mut_slice()
                    .iter_mut()
                    .zip(q.as_slice())
                    .zip(self.step.as_slice())
                    .zip(self.cols.as_slice())
                {
                    *b = x - fraction * s * c;
                }
                self.mechanism.phi(&self.base, t, &mut self.trial);
                scaled_norms(&self.trial, &self.rows).0
            } else {
                f64::INFINITY
            };
            if trial_merit < merit {
                q.copy_from(&self.base);
                self.phi.copy_from(&self.trial);
                *iterations += 1;
                marquardt.mu = (mu / 3.0).max(1e-12 * largest);
                let progress = 1.0 - trial_merit / merit;
                marquardt.stalls = if progress < STALL_DECREASE {
                    marquardt.stalls + 1
                } else {
                    0
                };
                if marquardt.stalls >= STALL_LIMIT {
                    return Err(self.no_assembly(q, t, *iterations));
                }
                return Ok(());
            }
            marquardt.mu = mu * 4.0;
        }
        Err(self.no_assembly(q, t, *iterations))
    }

    /// Scales `jacobian` in place to J_s = D_r J D_c, writes J_sᵀ (D_r Φ) into `gradient`, and
    /// returns the largest diagonal entry of J_sᵀ J_s (the largest squared column norm).
    fn scale_jacobian_and_gradient(&mut self) -> f64 {
        let n = self.phi.nrows();
        let (rows, cols, phi) = (
            self.rows.as_slice(),
            self.cols.as_slice(),
            self.phi.as_slice(),
        );
        let mut largest = 0.0_f64;
        let columns = self.jacobian.as_mut_slice().chunks_exact_mut(n.max(1));
        for ((column, c), g) in columns.zip(cols).zip(self.gradient.as_mut_slice()) {
            let (mut dot, mut norm) = (0.0, 0.0);
            for ((a, r), p) in column.iter_mut().zip(rows).zip(phi) {
                *a *= r * c;
                dot += *a * r * p;
                norm += *a * *a;
            }
            *g = dot;
            largest = largest.max(norm);
        }
        largest
    }
}

/// `a = jᵀ j + μ I` (column-major slices; `j` is small or this is the rare fallback path).
fn normal_matrix<D: nalgebra::Dim>(j: &Matrix<D>, mu: f64, a: &mut Matrix<D>)
where
    DefaultAllocator: Storage<D>,
{
    let n = j.nrows();
    let (j, a) = (j.as_slice(), a.as_mut_slice());
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
fn scaled_norms<D: nalgebra::Dim>(v: &Vector<D>, rows: &Vector<D>) -> (f64, f64)
where
    DefaultAllocator: Storage<D>,
{
    let (mut sum, mut max) = (0.0_f64, 0.0_f64);
    for (x, r) in v.as_slice().iter().zip(rows.as_slice()) {
        let y = x * r;
        sum += y * y;
        max = max.max(y.abs());
    }
    (libm::sqrt(sum), max)
}

/// ‖D_c⁻¹ v‖∞: a step or a position in scene lengths and radians.
fn scaled_max<D: nalgebra::Dim>(v: &Vector<D>, cols: &Vector<D>) -> f64
where
    DefaultAllocator: Storage<D>,
{
    scaled_max_abs(v.as_slice().iter().copied(), cols)
}
