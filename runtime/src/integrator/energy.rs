//! The energy book: kinetic energy `½ q̇ᵀ M q̇`, the potentials of gravity and springs from the
//! scene's energy terms, and the work of loads, of drivers and of dampers integrated over the
//! accepted steps by the trapezoidal rule on their powers.
//!
//! The drivers' power is `−q̇ᵀ F(q, q̇, q̈, t)`, exact: `F = Φ_qᵀ λ`, so `q̇ᵀ F = λᵀ Φ_q q̇ = λᵀ ν`,
//! and only rheonomic rows (drivers of time; a free degree of freedom's effort is zero on the
//! motion) carry power. The balance
//! `kinetic + gravity + springs − loads_work − drivers_work + dissipated` ([`Energy::total`])
//! then stays constant up to the method's error.

use nalgebra::{DefaultAllocator, Dim, U1};

use crate::dynamic::EquationsOfMotion;
use crate::mechanism::{Mechanism, Storage, Vector};
use crate::state::State;

/// The energies at the integrator's state and the works done since its start (scene units:
/// with kg, mm and s, energies are in kg·mm²/s² = µJ).
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Energy {
    /// Kinetic energy `½ q̇ᵀ M q̇`.
    pub kinetic: f64,
    /// Potential energy of gravity.
    pub gravity: f64,
    /// Potential energy of the springs.
    pub springs: f64,
    /// Work the loads (forces, torques) did since the start.
    pub loads_work: f64,
    /// Work the drivers (prescribed motions) did since the start.
    pub drivers_work: f64,
    /// Energy the dampers dissipated since the start (never negative).
    pub dissipated: f64,
}

impl Energy {
    /// `kinetic + gravity + springs − loads_work − drivers_work + dissipated`: constant on an
    /// exact motion; its drift measures the integration's energy error.
    pub fn total(&self) -> f64 {
        self.kinetic + self.gravity + self.springs - self.loads_work - self.drivers_work
            + self.dissipated
    }
}

/// The book: the energies, and the powers at the last accepted state (the left end of the
/// next step's trapezoid).
pub(crate) struct Book<M: Mechanism>
where
    DefaultAllocator: Storage<M::Dim>,
{
    pub energy: Energy,
    powers: Powers,
    scratch: Vector<M::Dim>,
}

impl<M: Mechanism> Clone for Book<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn clone(&self) -> Self {
        Self {
            energy: self.energy,
            powers: self.powers,
            scratch: self.scratch.clone(),
        }
    }
}

/// Powers of the loads, of the dampers (dissipated) and of the drivers.
#[derive(Debug, Clone, Copy, Default)]
struct Powers {
    loads: f64,
    dampers: f64,
    drivers: f64,
}

impl<M: EquationsOfMotion> Book<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// An empty book for `m`.
    pub fn new(m: &M) -> Self {
        Self {
            energy: Energy::default(),
            powers: Powers::default(),
            scratch: Vector::zeros_generic(m.dim(), U1),
        }
    }

    /// Measures the energies and powers at `state` (`forces` = F there) without adding work:
    /// the start, or a restart from a new free state.
    pub fn restart(&mut self, m: &M, state: &State<M>, forces: &Vector<M::Dim>) {
        self.powers = self.measure(m, state, forces);
    }

    /// Adds the works of a step of size `h` ending at `state`, and measures there.
    pub fn advance(&mut self, m: &M, state: &State<M>, forces: &Vector<M::Dim>, h: f64) {
        let before = self.powers;
        let after = self.measure(m, state, forces);
        let e = &mut self.energy;
        e.loads_work += 0.5 * h * (before.loads + after.loads);
        e.dissipated += 0.5 * h * (before.dampers + after.dampers);
        e.drivers_work += 0.5 * h * (before.drivers + after.drivers);
        self.powers = after;
    }

    /// Sets the energies at `state` and returns its powers.
    fn measure(&mut self, m: &M, state: &State<M>, forces: &Vector<M::Dim>) -> Powers {
        let (q, qd) = (&state.q, &state.velocities);
        m.mass_times(q, qd, &mut self.scratch);
        self.energy.kinetic = 0.5 * dot(qd, &self.scratch);
        let terms = m.energy_terms(q, qd, state.t);
        self.energy.gravity = terms.gravity;
        self.energy.springs = terms.springs;
        Powers {
            loads: terms.loads,
            dampers: terms.dampers,
            drivers: -dot(qd, forces),
        }
    }
}

/// `aᵀb` over the vectors' slices (nalgebra's `dot` costs several times the products here,
/// at every step).
fn dot<D: Dim>(a: &Vector<D>, b: &Vector<D>) -> f64
where
    DefaultAllocator: Storage<D>,
{
    a.as_slice()
        .iter()
        .zip(b.as_slice())
        .map(|(x, y)| x * y)
        .sum()
}
