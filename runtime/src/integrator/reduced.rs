//! One evaluation of the reduced equations of motion at a free state `(t, u, u̇, ü)`: the
//! free degrees of freedom set, the structured kinematic solve (`q`, `q̇`, `q̈` with the
//! constraints exact, and the force solve's multipliers λ), and the residual `R = Vᵀ F`,
//! `V = ∂q/∂u`, `F = Q − M q̈`; and, on demand, `V` itself (one velocity solve per free degree
//! of freedom), `F`, and the reduced matrices `VᵀMV`, `VᵀCV`, `VᵀKV` of the iteration matrix.
//!
//! `R` is the effort the free degrees of freedom's equations carry, read from the force
//! solve: `F = Φ_qᵀ λ` (Φ_q is square), and the free rows `g(q) − u` give `Φ_q V = e_k`
//! (differentiating `Φ(q(u), u) = 0`), so `R_k = V_kᵀ Φ_qᵀ λ = λ_{e_k}` — times the sign of
//! `−∂Φ_{e_k}/∂u_k` for a scene that writes the row the other way round. An evaluation
//! therefore costs one structured solve; `V` is solved for only where it is needed (the
//! iteration matrix, the accepted state).

use nalgebra::{DefaultAllocator, OMatrix, OVector, U1};

use super::alpha::FreeMotion;
use crate::dynamic::{Dynamic, EquationsOfMotion, FreeStorage};
use crate::error::SolveError;
use crate::mechanism::{Storage, Vector};
use crate::solver::Solver;
use crate::state::State;
use crate::structure::Structured;

/// The smallest free rate `|u̇|` from which `V = q̇ / u̇` is taken: far above the range where
/// the rates `V u̇` would lose digits to underflow (`V`'s entries are the scene's lengths per
/// unit of `u`, and a rate this small is a state at rest).
const SMALLEST_RATE: f64 = 1e-150;

/// The evaluation's storage: `V`, `F`, the residual and scratch columns.
pub(crate) struct Reduced<M: Dynamic>
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    /// `V = ∂q/∂u`, one column per free degree of freedom, where last solved for.
    pub v: OMatrix<f64, M::Dim, M::Free>,
    /// `V` at the current (accepted) state.
    pub accepted: OMatrix<f64, M::Dim, M::Free>,
    /// `F = Q − M q̈`, where last computed.
    pub forces: Vector<M::Dim>,
    /// `R = Vᵀ F` at the last evaluation.
    pub residual: OVector<f64, M::Free>,
    /// Each free degree of freedom's equation and the sign of `−∂Φ_e/∂u` there.
    rows: OVector<usize, M::Free>,
    signs: OVector<f64, M::Free>,
    /// Scratch: a column of `V`, its product with `M`, `K` or `C`, a velocity solve.
    column: Vector<M::Dim>,
    product: Vector<M::Dim>,
    velocity: Vector<M::Dim>,
}

impl<M: Dynamic> Clone for Reduced<M>
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    fn clone(&self) -> Self {
        Self {
            v: self.v.clone(),
            accepted: self.accepted.clone(),
            forces: self.forces.clone(),
            residual: self.residual.clone(),
            rows: self.rows.clone(),
            signs: self.signs.clone(),
            column: self.column.clone(),
            product: self.product.clone(),
            velocity: self.velocity.clone(),
        }
    }
}

/// Writes `[u, u̇, ü]` of every free degree of freedom into the mechanism.
pub(crate) fn set_free<M: Dynamic + Structured>(solver: &mut Solver<M>, x: &FreeMotion<M::Free>)
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    for k in 0..x.u.len() {
        solver.set_free(k, x.of(k));
    }
}

impl<M: Dynamic + EquationsOfMotion + Structured> Reduced<M>
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    /// Storage for `m`, whose free rows have `∂Φ_e/∂u = slopes` (−1 for `g(q) − u`).
    pub fn new(m: &M, slopes: &OVector<f64, M::Free>) -> Self {
        let (n, f) = (m.dim(), m.free());
        Self {
            v: OMatrix::zeros_generic(n, f),
            accepted: OMatrix::zeros_generic(n, f),
            forces: Vector::zeros_generic(n, U1),
            residual: OVector::zeros_generic(f, U1),
            rows: OVector::from_fn_generic(f, U1, |k, _| m.free_equation(k)),
            signs: slopes.map(|slope| if slope > 0.0 { -1.0 } else { 1.0 }),
            column: Vector::zeros_generic(n, U1),
            product: Vector::zeros_generic(n, U1),
            velocity: Vector::zeros_generic(n, U1),
        }
    }

    /// Evaluates `R` at `(t, x)`, solving the kinematics into `state` from the positions it
    /// holds (the warm start).
    ///
    /// # Errors
    /// The kinematic solve's error.
    pub fn evaluate(
        &mut self,
        solver: &mut Solver<M>,
        t: f64,
        x: &FreeMotion<M::Free>,
        state: &mut State<M>,
    ) -> Result<(), SolveError> {
        set_free(solver, x);
        // The state holds the positions of a solve (the last evaluation's or an accepted
        // state's): a prediction the straight step need not check first.
        solver.solve_predicted(t, state)?;
        let lambda = solver.multipliers();
        for k in 0..self.residual.len() {
            let row = lambda.get(self.rows[k]).copied().unwrap_or(f64::NAN);
            self.residual[k] = self.signs[k] * row;
        }
        Ok(())
    }

    /// `F` at the evaluated `state`.
    pub fn measure_forces(&mut self, m: &M, state: &State<M>) {
        m.generalized_forces(
            &state.q,
            &state.velocities,
            &state.accelerations,
            state.t,
            &mut self.forces,
        );
    }

    /// `V`, column by column: q̇ is affine in u̇ at fixed positions, so column k is the change
    /// of q̇ when u̇_k alone changes, divided by the change (one velocity solve each, over the
    /// factors the solve of `state` archived). The change is `1 + |u̇_k|`, so that the
    /// difference keeps the digits of a fast motion. `state` must be the solver's last solve.
    /// A single free degree of freedom at a state without rheonomic terms needs no solve
    /// ([`Self::sensitivities_from_rates`]).
    ///
    /// # Errors
    /// A velocity solve's error.
    pub fn sensitivities(
        &mut self,
        solver: &mut Solver<M>,
        t: f64,
        x: &FreeMotion<M::Free>,
        state: &State<M>,
    ) -> Result<(), SolveError> {
        if self.sensitivities_from_rates(solver.mechanism(), x, state) {
            return Ok(());
        }
        for k in 0..x.u.len() {
            let [u, ud, udd] = x.of(k);
            let change = 1.0 + ud.abs();
            solver.set_free(k, [u, ud + change, udd]);
            let solved = solver.solve_velocity_again(&state.q, t, &mut self.velocity);
            solver.set_free(k, [u, ud, udd]);
            solved?;
            let mut column = self.v.column_mut(k);
            for i in 0..column.len() {
                column[i] = (self.velocity[i] - state.velocities[i]) / change;
            }
        }
        Ok(())
    }

    /// `V = q̇ / u̇` where that is exact, and whether it was: with one free degree of freedom
    /// and `ν = −Φ_t` zero on every other row at `state` (no driver of time moving there),
    /// `q̇ = Φ_q⁻¹ ν` is `V u̇` exactly, and in floating point too, each rate being a sum of
    /// products with `u̇` (so the quotient keeps the solve's relative precision). Declines
    /// (leaving `V` to the velocity solve) for a rate at or near zero (from rest), a
    /// rheonomic row, or a quotient that is not finite.
    fn sensitivities_from_rates(
        &mut self,
        m: &M,
        x: &FreeMotion<M::Free>,
        state: &State<M>,
    ) -> bool {
        let (Some(&rate), Some(&row)) = (x.ud.get(0), self.rows.get(0)) else {
            return false;
        };
        // NaN fails too.
        let usable = x.ud.len() == 1 && rate.abs() >= SMALLEST_RATE;
        if !usable {
            return false;
        }
        m.nu(&state.q, state.t, &mut self.velocity);
        // The free row's entry cleared (ν is scratch here), every entry must be zero.
        let Some(free) = self.velocity.get_mut(row) else {
            return false;
        };
        *free = 0.0;
        let nu = self.velocity.as_slice();
        if !nu.iter().all(|&nu| nu == 0.0) {
            return false;
        }
        let Some(column) = self.v.as_mut_slice().get_mut(..nu.len()) else {
            return false;
        };
        let inverse = 1.0 / rate;
        for (v, &qd) in column.iter_mut().zip(state.velocities.as_slice()) {
            *v = qd * inverse;
        }
        // Otherwise the velocity solve overwrites the column.
        column.iter().all(|v| v.is_finite())
    }

    /// Writes `VᵀMV` into `out`.
    pub fn mass(&mut self, m: &M, state: &State<M>, out: &mut OMatrix<f64, M::Free, M::Free>) {
        out.fill(0.0);
        self.add_projected(out, 1.0, |column, product| {
            m.mass_times(&state.q, column, product);
            true
        });
    }

    /// Writes `VᵀKV` into `out` (`K = −∂Q/∂q`) and returns whether the scene has `K`.
    pub fn stiffness(
        &mut self,
        m: &M,
        state: &State<M>,
        out: &mut OMatrix<f64, M::Free, M::Free>,
    ) -> bool {
        let (q, qd, t) = (&state.q, &state.velocities, state.t);
        out.fill(0.0);
        self.add_projected(out, 1.0, |v, product| {
            m.stiffness_times(q, qd, t, v, product)
        })
    }

    /// Writes `VᵀCV` into `out` (`C = −∂Q/∂q̇`) and returns whether the scene has `C`.
    pub fn damping(
        &mut self,
        m: &M,
        state: &State<M>,
        out: &mut OMatrix<f64, M::Free, M::Free>,
    ) -> bool {
        let (q, qd, t) = (&state.q, &state.velocities, state.t);
        out.fill(0.0);
        self.add_projected(out, 1.0, |v, product| m.damping_times(q, qd, t, v, product))
    }

    /// Adds `c Vᵀ A V` to `out`, with `apply` writing `A v` and returning whether the scene
    /// has `A` (returned; `out` is untouched without it).
    fn add_projected(
        &mut self,
        out: &mut OMatrix<f64, M::Free, M::Free>,
        c: f64,
        mut apply: impl FnMut(&Vector<M::Dim>, &mut Vector<M::Dim>) -> bool,
    ) -> bool {
        for k in 0..self.v.ncols() {
            self.column.copy_from(&self.v.column(k));
            if !apply(&self.column, &mut self.product) {
                return false;
            }
            for i in 0..self.v.ncols() {
                out[(i, k)] += c * self.v.column(i).dot(&self.product);
            }
        }
        true
    }
}
