//! Why a block's solve failed: the iteration cap, a residual that stopped decreasing, one
//! the coordinates' rounding cannot resolve, and the rank-revealing diagnosis of a singular
//! block.

use nalgebra::DefaultAllocator;

use super::SINGULAR_RESIDUAL;
use super::marquardt::Marquardt;
use super::newton::Newton;
use super::norms::max_abs;

use crate::block::Factors;
use crate::error::SolveError;
use crate::mechanism::{Storage, Vector};
use crate::names::Names;
use crate::structure::Structured;

impl<'a, 'w, M: Structured> Newton<'a, 'w, M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Why a solve hit the iteration cap.
    pub(super) fn give_up(
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
    pub(super) fn no_assembly(&mut self, q: &Vector<M::Dim>, iterations: usize) -> SolveError {
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
    pub(super) fn unresolved(&self, iterations: usize) -> SolveError {
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
}
