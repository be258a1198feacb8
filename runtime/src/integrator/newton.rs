//! The step's Newton iteration on the free accelerations `ü_{n+1}`.
//!
//! The iteration matrix is `S = VᵀMV + γ' VᵀCV + β' VᵀKV` (`β' = ∂u/∂ü`, `γ' = ∂u̇/∂ü`), its
//! three reduced parts kept from the evaluation where they were last built: a new step size
//! only recombines and refactors them (f × f), and they are rebuilt at the current iterate
//! when the corrections stop contracting. `S` leaves out the derivatives of `V` itself (the
//! geometric stiffness, and the velocity terms of a configuration-dependent `V`), of the
//! order `h² ω²` and `h θ̇ |∂V/∂u| / |V|` of the motion's own frequencies and speeds: the
//! inverse is kept explicitly (f × f) and improved by Broyden's rank-one updates from the
//! residuals the iteration sees, so those terms slow it little. The scene's springs and
//! dampers are in `K` and `C` exactly, so a stiff spring does not slow it at all.
//!
//! Each step starts from a prediction (`predict`): in the stiff regime the linearly implicit
//! step of the reduced linear model `M_r Δü + C_r Δu̇ + K_r Δu = 0` about the current state,
//! which for a stiff spring is close to the answer where "ü unchanged" would stretch it by
//! `h² ü`; otherwise the accelerations extrapolated from the last two steps.

use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector, U1};

use super::Integrator;
use crate::dynamic::{Dynamic, EquationsOfMotion, FreeStorage};
use crate::error::SolveError;
use crate::lu::{Lu, LuError};
use crate::mechanism::Storage;
use crate::structure::Structured;

/// A reduced mass pivot below this fraction of the largest (both scaled to the scene's
/// length unit) counts as zero: a free degree of freedom that moves no mass.
const MASS_TOLERANCE: f64 = 1e-12;
/// The corrections must shrink at least this fast for the matrix to be kept.
const CONTRACTION: f64 = 0.5;
/// Accelerations below this many scene scales per step squared count as zero for the
/// relative Newton test (a state at rest).
pub(super) const ACCELERATION_FLOOR: f64 = 1e-6;
/// The share of the iteration matrix (largest scaled entries) above which stiffness and
/// damping make a step stiff.
const STIFF_SHARE: f64 = 0.5;
/// A correction that stalls within this factor of the tolerance (with a fresh matrix) is the
/// residual's round-off: the iterate is accepted.
const STALL: f64 = 100.0;
/// Broyden's update is skipped when the correction is within this factor of the tolerance:
/// there, the residual's change is mostly the kinematic solve's round-off.
const UPDATE_ABOVE: f64 = 100.0;

/// Why a step's iteration failed.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Failure {
    /// The kinematic solve at an iterate.
    Kinematics(SolveError),
    /// The reduced mass is not positive definite at this free degree of freedom.
    SingularMass(usize),
    /// The iteration matrix is singular (a negative stiffness cancelling the mass).
    SingularMatrix,
    /// A non-finite residual, correction or state (of this degree of freedom, if one).
    NonFinite(Option<usize>),
    /// No convergence in the iterations allowed.
    NoConvergence { iterations: u32, residual: f64 },
    /// Converged, but the error estimate is above the tolerance (error-controlled mode).
    Rejected,
    /// Converged across a singular configuration of the partition.
    Toggle,
}

/// The iteration matrix's reduced parts, its inverse and the step size it is for.
#[derive(Clone)]
pub(crate) struct IterationMatrix<F: Dim>
where
    DefaultAllocator: Storage<F>,
{
    /// `VᵀMV`, `VᵀCV`, `VᵀKV` at the evaluation where they were built.
    mass: OMatrix<f64, F, F>,
    damping: OMatrix<f64, F, F>,
    stiffness: OMatrix<f64, F, F>,
    /// Whether the scene has `C`, `K`; whether the parts exist at all.
    has: (bool, bool),
    /// Whether `γ' C_r + β' K_r` outweighs [`STIFF_SHARE`] of the mass in the last
    /// combination: the step is then in the stiff regime, where the linear model predicts.
    pub stiff: bool,
    built: bool,
    /// `S` (and the mass check's elimination).
    scratch: OMatrix<f64, F, F>,
    lu: Lu<F>,
    /// `B ≈ S⁻¹`, with Broyden's updates.
    inverse: OMatrix<f64, F, F>,
    /// The residual of the last correction, and Broyden's scratch.
    last: OVector<f64, F>,
    /// Scratch of Broyden's update and of the toggle check.
    pub change: OVector<f64, F>,
    pub row: OVector<f64, F>,
    /// The free coordinates' unit scales (lengths to the scene's length scale).
    pub scales: OVector<f64, F>,
    /// The step size the inverse is for; `None` without one.
    pub step: Option<f64>,
}

impl<F: Dim> IterationMatrix<F>
where
    DefaultAllocator: Storage<F>,
{
    /// Storage for `f` free degrees of freedom.
    pub fn new(f: F) -> Self {
        let square = || OMatrix::zeros_generic(f, f);
        let column = || OVector::zeros_generic(f, U1);
        Self {
            mass: square(),
            damping: square(),
            stiffness: square(),
            has: (false, false),
            stiff: false,
            built: false,
            scratch: square(),
            lu: Lu::new(f),
            inverse: square(),
            last: column(),
            change: column(),
            row: column(),
            scales: OVector::from_element_generic(f, U1, 1.0),
            step: None,
        }
    }

    /// Combines the parts for step size `h` (`∂u/∂ü = du`, `∂u̇/∂ü = dud`) and inverts.
    fn combine(&mut self, (du, dud): (f64, f64)) -> Result<(), Failure> {
        self.step = None;
        self.scratch.copy_from(&self.mass);
        if self.has.0 {
            self.scratch.zip_apply(&self.damping, |a, b| *a += dud * b);
        }
        if self.has.1 {
            self.scratch.zip_apply(&self.stiffness, |a, b| *a += du * b);
        }
        let (mut mass, mut rest) = (0.0_f64, 0.0_f64);
        for j in 0..self.mass.ncols() {
            for i in 0..self.mass.nrows() {
                let scale = self.scales[i] * self.scales[j];
                mass = mass.max((self.mass[(i, j)] * scale).abs());
                rest = rest.max(((self.scratch[(i, j)] - self.mass[(i, j)]) * scale).abs());
            }
        }
        self.stiff = rest > STIFF_SHARE * mass;
        let matrix = &self.scratch;
        self.lu
            .factor_scaled_with(&self.scales, &self.scales, |s| s.copy_from(matrix))
            .map_err(|e| match e {
                LuError::NonFinite => Failure::NonFinite(None),
                _ => Failure::SingularMatrix,
            })?;
        self.inverse.fill_with_identity();
        for k in 0..self.inverse.ncols() {
            self.change.copy_from(&self.inverse.column(k));
            self.lu
                .solve_in_place(&mut self.change)
                .map_err(|_| Failure::SingularMatrix)?;
            self.inverse.set_column(k, &self.change);
        }
        Ok(())
    }

    /// Broyden's ("good") update of `B ≈ S⁻¹` from the last correction `s` (applied to ü)
    /// and the residual now, `R`: with `y = R_before − R` (the change of `−R`, whose
    /// Jacobian `S` approximates), `B ← B + (s − B y) sᵀB / (sᵀ B y)`. Skipped when
    /// `sᵀ B y` is not safely away from zero.
    fn update(&mut self, s: &OVector<f64, F>, residual: &OVector<f64, F>) {
        self.change.copy_from(&self.last);
        self.change -= residual;
        self.row.gemv(1.0, &self.inverse, &self.change, 0.0);
        let denominator = s.dot(&self.row);
        // NaN counts as unusable.
        let usable = denominator.abs() > 1e-12 * s.norm() * self.row.norm();
        if !usable {
            return;
        }
        self.row.axpy(1.0, s, -1.0);
        self.change.gemv_tr(1.0, &self.inverse, s, 0.0);
        self.inverse
            .ger(1.0 / denominator, &self.row, &self.change, 1.0);
    }
}

/// Checks that the scaled reduced mass `D M_r D` (D the scales) is positive definite by
/// symmetric elimination without pivoting (Cholesky's pivots); otherwise names the first
/// degree of freedom whose pivot is not above [`MASS_TOLERANCE`] times the largest diagonal.
fn check_mass<F: Dim>(
    mass: &mut OMatrix<f64, F, F>,
    scales: &OVector<f64, F>,
) -> Result<(), Failure>
where
    DefaultAllocator: Storage<F>,
{
    let f = mass.nrows();
    for j in 0..f {
        for i in 0..f {
            mass[(i, j)] *= scales[i] * scales[j];
        }
    }
    if mass.iter().any(|x| !x.is_finite()) {
        return Err(Failure::NonFinite(None));
    }
    let largest = (0..f).map(|k| mass[(k, k)]).fold(0.0, f64::max);
    for k in 0..f {
        let pivot = mass[(k, k)];
        // NaN counts as zero.
        let positive = pivot > MASS_TOLERANCE * largest;
        if !positive {
            return Err(Failure::SingularMass(k));
        }
        for i in k + 1..f {
            let factor = mass[(i, k)] / pivot;
            for j in k + 1..f {
                mass[(i, j)] -= factor * mass[(k, j)];
            }
        }
    }
    Ok(())
}

impl<M: Dynamic + EquationsOfMotion + Structured> Integrator<M>
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    /// Solves the step of size `h` from `now` to `t`, leaving the converged iterate in `next`
    /// and its kinematic state in `trial`.
    ///
    /// The iterate returned is the last one evaluated (its state and `V`, `F` are consistent),
    /// accepted when the correction it still calls for is below the tolerance.
    pub(super) fn solve_step(&mut self, h: f64, t: f64) -> Result<(), Failure> {
        self.predict(h)?;
        let tolerance = self.options.newton_tolerance;
        // Whether the matrix was rebuilt in this step; the last correction, and the last one
        // a matrix made at the iterate where it was rebuilt.
        let mut fresh = false;
        let (mut previous, mut rebuilt_size) = (f64::INFINITY, f64::INFINITY);
        for iteration in 1..=self.options.max_iterations {
            self.stats.iterations += 1;
            self.next.advance(&self.now, &self.alpha, h);
            self.evaluate(t)?;
            // Whether the matrix (and V) is this iterate's.
            let mut rebuilt = false;
            if self.matrix.step != Some(h) || !self.matrix.built {
                self.refresh(h)?;
                rebuilt = true;
            } else if iteration > 1 && previous > UPDATE_ABOVE * tolerance {
                self.matrix.update(&self.correction, &self.reduced.residual);
            }
            let mut size = self.correct(h)?;
            if size > CONTRACTION * previous && !fresh && !rebuilt {
                // Slow: the kept matrix is too far from this iterate's; rebuild it here.
                self.refresh(h)?;
                rebuilt = true;
                size = self.correct(h)?;
            }
            fresh |= rebuilt;
            // Converged; or, with a fresh matrix, stalled at the residual's round-off (a stiff
            // spring amplifies the positions' rounding into forces) within reach of it.
            let stalled = fresh && size > CONTRACTION * previous && size <= STALL * tolerance;
            if size <= tolerance || stalled {
                return self.finish(rebuilt, h);
            }
            // Diverging: a rebuilt matrix's correction is measured against the last rebuilt
            // one's, not against the old matrix's (which may have overshot), so that it is
            // tried.
            let reference = if rebuilt { rebuilt_size } else { previous };
            if size >= reference && fresh {
                let failure = Failure::NoConvergence {
                    iterations: iteration,
                    residual: size,
                };
                return Err(self.diagnose(h, failure));
            }
            if rebuilt {
                rebuilt_size = size;
            }
            self.next.udd += &self.correction;
            previous = size;
        }
        let failure = Failure::NoConvergence {
            iterations: self.options.max_iterations,
            residual: previous,
        };
        Err(self.diagnose(h, failure))
    }

    /// Starts a step from a prediction of `ü_{n+1}`: in the stiff regime the linearly implicit
    /// one (see the module documentation); otherwise the accelerations extrapolated from the
    /// last steps (`history.rs`: up to a cubic, `O((ωh)⁴)` off on a resolved motion, where
    /// "ü unchanged" is `O(ωh)` off), so that the iteration usually ends at its first
    /// evaluation. The kinematic solve is warm-started from the positions the predicted state
    /// gives to first order, `q + V (u_{n+1} − u_n)` (`V` of the last evaluation).
    fn predict(&mut self, h: f64) -> Result<(), Failure> {
        let derivatives = self.alpha.derivatives(h);
        if self.matrix.built && self.matrix.step != Some(h) {
            self.matrix.combine(derivatives)?;
            self.matrix.step = Some(h);
            self.stats.factorizations += 1;
        }
        self.next.copy_from(&self.now);
        let linear = self.matrix.built && self.matrix.stiff;
        if !linear {
            self.history.extrapolate(h, &mut self.next.udd);
        }
        self.next.advance(&self.now, &self.alpha, h);
        if linear {
            self.linear_prediction(h);
        }
        // Only the positions: the solve writes the rest of the state.
        let (state, trial) = self.states.split();
        trial.q.copy_from(&state.q);
        self.correction.copy_from(&self.next.u);
        self.correction -= &self.now.u;
        trial.q.gemv(1.0, &self.reduced.v, &self.correction, 1.0);
        if trial.q.as_slice().iter().any(|x| !x.is_finite()) {
            // A V left by a failed restart elsewhere: start from the positions as they are.
            trial.q.copy_from(&state.q);
        }
        Ok(())
    }

    /// Corrects `next` (advanced with `ü_{n+1} = ü_n`) by the step of the reduced linear
    /// model: `S Δü = −C_r (u̇⁰ − u̇_n) − K_r (u⁰ − u_n)`.
    fn linear_prediction(&mut self, h: f64) {
        let it = &mut self.matrix;
        // The right-hand side, in `last` (scratch until the first correction).
        it.last.fill(0.0);
        if it.has.0 {
            self.correction.copy_from(&self.next.ud);
            self.correction -= &self.now.ud;
            it.last.gemv(-1.0, &it.damping, &self.correction, 1.0);
        }
        if it.has.1 {
            self.correction.copy_from(&self.next.u);
            self.correction -= &self.now.u;
            it.last.gemv(-1.0, &it.stiffness, &self.correction, 1.0);
        }
        self.correction.gemv(1.0, &it.inverse, &it.last, 0.0);
        self.next.udd += &self.correction;
        self.next.advance(&self.now, &self.alpha, h);
    }

    /// Completes the converged iterate in `trial`: its `V` (unless `solved_v`) and `F`, then
    /// the toggle checks.
    fn finish(&mut self, solved_v: bool, h: f64) -> Result<(), Failure> {
        if !solved_v {
            self.solve_v()?;
        }
        let m = self.solver.mechanism();
        self.reduced.measure_forces(m, self.states.trial());
        self.check_crossing(h)
    }

    /// `V` at the last evaluation (`next`, solved into `trial`).
    pub(super) fn solve_v(&mut self) -> Result<(), Failure> {
        let trial = self.states.trial();
        self.reduced
            .sensitivities(&mut self.solver, trial.t, &self.next, trial)
            .map_err(Failure::Kinematics)
    }

    /// Evaluates the residual at `next`, into `trial`.
    pub(super) fn evaluate(&mut self, t: f64) -> Result<(), Failure> {
        self.reduced
            .evaluate(&mut self.solver, t, &self.next, self.states.trial_mut())
            .map_err(Failure::Kinematics)?;
        if self.reduced.residual.iter().all(|r| r.is_finite()) {
            Ok(())
        } else {
            let k = self.reduced.residual.iter().position(|r| !r.is_finite());
            Err(Failure::NonFinite(k))
        }
    }

    /// Rebuilds the iteration matrix's parts at the last evaluation and inverts it for step
    /// `h` (`h = 0`: the reduced mass alone, for the accelerations of a state).
    pub(super) fn refresh(&mut self, h: f64) -> Result<(), Failure> {
        self.solve_v()?;
        let m = self.solver.mechanism();
        let it = &mut self.matrix;
        it.built = false;
        it.step = None;
        let trial = self.states.trial();
        self.reduced.mass(m, trial, &mut it.mass);
        it.scratch.copy_from(&it.mass);
        check_mass(&mut it.scratch, &it.scales)?;
        it.has = (
            self.reduced.damping(m, trial, &mut it.damping),
            self.reduced.stiffness(m, trial, &mut it.stiffness),
        );
        it.built = true;
        self.stats.factorizations += 1;
        it.combine(self.alpha.derivatives(h))?;
        it.step = Some(h);
        Ok(())
    }

    /// The Newton correction `B R` into `correction`, and its size: the largest change of a
    /// free acceleration it makes, relative to the largest free acceleration (each scaled to
    /// the scene's length unit; accelerations that would move the state by less than
    /// [`ACCELERATION_FLOOR`] scene scales over the step count as zero).
    pub(super) fn correct(&mut self, h: f64) -> Result<f64, Failure> {
        let it = &mut self.matrix;
        self.correction
            .gemv(1.0, &it.inverse, &self.reduced.residual, 0.0);
        it.last.copy_from(&self.reduced.residual);
        let scales = &it.scales;
        let scaled = |v: &OVector<f64, M::Free>, k: usize| (v[k] / scales[k]).abs();
        let f = self.correction.len();
        let floor = if h > 0.0 {
            ACCELERATION_FLOOR / (h * h)
        } else {
            0.0
        };
        let reference = (0..f)
            .map(|k| scaled(&self.next.udd, k))
            .fold(floor, f64::max);
        let largest = (0..f)
            .map(|k| scaled(&self.correction, k))
            .fold(0.0, |a: f64, b| if b.is_nan() { b } else { a.max(b) });
        if !largest.is_finite() {
            let k = (0..f).find(|&k| !self.correction[k].is_finite());
            return Err(Failure::NonFinite(k));
        }
        Ok(if largest == 0.0 {
            0.0
        } else {
            largest / reference
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Const, Matrix2, Vector2};

    #[test]
    fn the_mass_check_names_the_degree_of_freedom_that_moves_nothing() {
        let scales = Vector2::new(1.0, 1.0);
        let mut good = Matrix2::new(2.0, 1.0, 1.0, 3.0);
        assert!(check_mass::<Const<2>>(&mut good, &scales).is_ok());
        // The second degree of freedom moves only what the first does: pivot 0.
        let mut dependent = Matrix2::new(2.0, 2.0, 2.0, 2.0);
        let failure = check_mass::<Const<2>>(&mut dependent, &scales);
        assert!(matches!(failure, Err(Failure::SingularMass(1))));
        let mut massless = Matrix2::new(0.0, 0.0, 0.0, 3.0);
        let failure = check_mass::<Const<2>>(&mut massless, &scales);
        assert!(matches!(failure, Err(Failure::SingularMass(0))));
        let mut none = Matrix2::zeros();
        let failure = check_mass::<Const<2>>(&mut none, &scales);
        assert!(matches!(failure, Err(Failure::SingularMass(0))));
    }
}
