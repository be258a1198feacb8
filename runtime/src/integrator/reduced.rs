//! One evaluation of the reduced equations of motion at a free state `(t, u, u̇, ü)`: the
//! free degrees of freedom set, the structured kinematic solve (`q`, `q̇`, `q̈` with the
//! constraints exact), the sensitivities `V = ∂q/∂u`, the generalised forces
//! `F = Q − M q̈` and the residual `R = Vᵀ F`; and, on demand, the reduced matrices `VᵀMV`,
//! `VᵀCV`, `VᵀKV` the iteration matrix is built from.
//!
//! `R` is the effort the free degrees of freedom's equations carry (`Φ_q V = I` on their rows,
//! so `Vᵀ Φ_qᵀ λ = λ_free`): zero on a solved motion, which is the equation of motion.

use nalgebra::{DefaultAllocator, OMatrix, OVector, U1};

use super::alpha::FreeMotion;
use crate::dynamic::{Dynamic, EquationsOfMotion, FreeStorage};
use crate::error::SolveError;
use crate::mechanism::{Storage, Vector};
use crate::solver::Solver;
use crate::state::State;
use crate::structure::Structured;

/// The evaluation's storage: `V`, `F`, the residual and scratch columns.
pub(crate) struct Reduced<M: Dynamic>
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    /// `V = ∂q/∂u`, one column per free degree of freedom.
    pub v: OMatrix<f64, M::Dim, M::Free>,
    /// `F = Q − M q̈` at the evaluated state.
    pub forces: Vector<M::Dim>,
    /// `R = Vᵀ F`.
    pub residual: OVector<f64, M::Free>,
    /// Scratch: a column of `V`, its product with `M`, `K` or `C`, a velocity solve.
    column: Vector<M::Dim>,
    product: Vector<M::Dim>,
    velocity: Vector<M::Dim>,
}

/// Writes `[u, u̇, ü]` of every free degree of freedom into the mechanism.
pub(crate) fn set_free<M: Dynamic + Structured>(solver: &mut Solver<M>, x: &FreeMotion<M::Free>)
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    let m = solver.mechanism_mut();
    for k in 0..x.u.len() {
        m.set_free(k, x.of(k));
    }
}

impl<M: Dynamic + EquationsOfMotion + Structured> Reduced<M>
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    /// Storage for `m`.
    pub fn new(m: &M) -> Self {
        let (n, f) = (m.dim(), m.free());
        Self {
            v: OMatrix::zeros_generic(n, f),
            forces: Vector::zeros_generic(n, U1),
            residual: OVector::zeros_generic(f, U1),
            column: Vector::zeros_generic(n, U1),
            product: Vector::zeros_generic(n, U1),
            velocity: Vector::zeros_generic(n, U1),
        }
    }

    /// Evaluates at `(t, x)`, solving the kinematics into `state` from the positions it holds
    /// (the warm start).
    ///
    /// # Errors
    /// The kinematic solve's error, of the positions or of a sensitivity's velocity solve.
    pub fn evaluate(
        &mut self,
        solver: &mut Solver<M>,
        t: f64,
        x: &FreeMotion<M::Free>,
        state: &mut State<M>,
    ) -> Result<(), SolveError> {
        set_free(solver, x);
        solver.solve_into(t, state)?;
        self.sensitivities(solver, t, x, state)?;
        solver.mechanism().generalized_forces(
            &state.q,
            &state.velocities,
            &state.accelerations,
            t,
            &mut self.forces,
        );
        self.residual.gemv_tr(1.0, &self.v, &self.forces, 0.0);
        Ok(())
    }

    /// `V`, column by column: q̇ is affine in u̇ at fixed positions, so column k is the change
    /// of q̇ when u̇_k alone changes, divided by the change (one velocity solve each). The
    /// change is `1 + |u̇_k|`, so that the difference keeps the digits of a fast motion.
    fn sensitivities(
        &mut self,
        solver: &mut Solver<M>,
        t: f64,
        x: &FreeMotion<M::Free>,
        state: &State<M>,
    ) -> Result<(), SolveError> {
        for k in 0..x.u.len() {
            let [u, ud, udd] = x.of(k);
            let change = 1.0 + ud.abs();
            solver.mechanism_mut().set_free(k, [u, ud + change, udd]);
            let solved = solver.solve_velocity(&state.q, t, &mut self.velocity);
            solver.mechanism_mut().set_free(k, [u, ud, udd]);
            solved?;
            let mut column = self.v.column_mut(k);
            for i in 0..column.len() {
                column[i] = (self.velocity[i] - state.velocities[i]) / change;
            }
        }
        Ok(())
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
