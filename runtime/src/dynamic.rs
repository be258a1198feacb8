//! The contract between a scene's equations of motion (generated or interpreted) and the
//! integrator: a scene with free degrees of freedom, `M(q) q̈ + Φ_qᵀ λ = Q(q, q̇, t)`.
//!
//! A free degree of freedom is declared where a driver would go (`free swing: angle(arm);`),
//! and its equation holds the driven quantity at the integrator's state `u` (value, rate,
//! acceleration: [`Dynamic::set_free`]). So the scene's kinematic solve, planned at compile
//! time, gives `q`, `q̇`, `q̈` from `u`, `u̇`, `ü` with the constraints exact (coordinate
//! partitioning with the partition the user named); the integrator moves `u` under the
//! reduced equations `Vᵀ F(q, q̇, q̈, t) = 0`, `V = ∂q/∂u`, with [`Mechanism::generalized_forces`]
//! `F = Q − M q̈`, and builds its iteration matrix from `VᵀMV`, `VᵀCV` and `VᵀKV`.

use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim};

#[cfg(doc)]
use crate::mechanism::Mechanism;
use crate::mechanism::{Forces, Storage, Vector};

/// Storage bounds for a scene with `D` coordinates and `F` free degrees of freedom; repeat
/// this where-clause on generic code (it holds for every `Const` pair and, with `alloc`, `Dyn`).
///
/// It names [`Storage<F>`] (not its two allocators) so that generic code with both bounds
/// holds two `Storage` where-clauses and rustc infers which dimension a value has from the
/// value, not from the only where-clause in sight.
pub trait FreeStorage<D: Dim, F: Dim>: Storage<F> + Allocator<D, F> {}
impl<D: Dim, F: Dim, A: Storage<F> + Allocator<D, F>> FreeStorage<D, F> for A {}

/// The conservative energies and the powers at one state, from [`EquationsOfMotion::energy_terms`]
/// (the kinetic energy is `½ q̇ᵀ M q̇`, from [`EquationsOfMotion::mass_times`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EnergyTerms {
    /// Potential energy of gravity, `−Σ m g · c` over the bodies' centres of mass `c`.
    pub gravity: f64,
    /// Potential energy of the springs, `Σ ½ k (ℓ − L)²`.
    pub springs: f64,
    /// Power of the loads (forces and torques) on the motion, `Σ f · ṗ + τ θ̇`.
    pub loads: f64,
    /// Power the dampers dissipate, `Σ c ℓ̇²` (never negative).
    pub dampers: f64,
}

/// The equations of motion `M(q) q̈ = Q(q, q̇, t) + Φ_qᵀ λ` of a scene with masses, as the
/// integrator uses them: products with `M` and with the derivatives of `Q`, only their
/// non-zeros computed, and the energies ([`Mechanism::generalized_forces`] gives
/// `F = Q − M q̈`).
///
/// Generated with [`Dynamic`] (the integrator needs both), for a scene that declares free
/// degrees of freedom; the interpreter implements it too. Implementations are straight-line code: they must not
/// allocate or panic.
pub trait EquationsOfMotion: Forces
where
    DefaultAllocator: Storage<Self::Dim>,
{
    /// Writes `M(q) v`.
    fn mass_times(&self, q: &Vector<Self::Dim>, v: &Vector<Self::Dim>, out: &mut Vector<Self::Dim>);

    /// Writes `K v`, `K = −∂Q/∂q` at `(q, q̇, t)`, and returns `true`; a scene whose `Q` does not
    /// depend on `q` has no such kernel and returns `false` with `out` untouched.
    fn stiffness_times(
        &self,
        _q: &Vector<Self::Dim>,
        _qd: &Vector<Self::Dim>,
        _t: f64,
        _v: &Vector<Self::Dim>,
        _out: &mut Vector<Self::Dim>,
    ) -> bool {
        false
    }

    /// Writes `C v`, `C = −∂Q/∂q̇` at `(q, q̇, t)`, and returns `true`; a scene whose `Q` does not
    /// depend on `q̇` (no dampers, no offset centres of mass) returns `false`, `out` untouched.
    fn damping_times(
        &self,
        _q: &Vector<Self::Dim>,
        _qd: &Vector<Self::Dim>,
        _t: f64,
        _v: &Vector<Self::Dim>,
        _out: &mut Vector<Self::Dim>,
    ) -> bool {
        false
    }

    /// The potential energies and powers at `(q, q̇, t)`.
    fn energy_terms(&self, q: &Vector<Self::Dim>, qd: &Vector<Self::Dim>, t: f64) -> EnergyTerms;
}

/// A scene with free degrees of freedom that moves under its forces.
///
/// Generated for a scene that declares `free` degrees of freedom (and masses); the interpreter
/// implements it too. Implementations are straight-line code: they must not allocate or panic.
pub trait Dynamic: Forces
where
    DefaultAllocator: Storage<Self::Dim> + FreeStorage<Self::Dim, Self::Free>,
{
    /// Type-level number of free degrees of freedom.
    type Free: Dim;

    /// The number of free degrees of freedom, as a value of the type-level dimension.
    fn free(&self) -> Self::Free;

    /// Name of free degree of freedom `k` (its declaration's name); `None` past the end.
    fn free_name(&self, k: usize) -> Option<&str>;

    /// The equation that holds free degree of freedom `k` at its state (the row its
    /// declaration adds); `usize::MAX` past the end.
    fn free_equation(&self, k: usize) -> usize;

    /// The declared initial value of free degree of freedom `k` (`None`: the value at the
    /// scene's initial guess, assembled) and its declared initial rate (0 unless declared).
    fn free_initial(&self, k: usize) -> (Option<f64>, f64);

    /// The `[value, rate, acceleration]` the kinematic solve holds free degree of freedom `k`
    /// at; NaNs past the end.
    fn free_state(&self, k: usize) -> [f64; 3];

    /// Sets the `[value, rate, acceleration]` of free degree of freedom `k` (ignored past the
    /// end).
    fn set_free(&mut self, k: usize, state: [f64; 3]);
}
