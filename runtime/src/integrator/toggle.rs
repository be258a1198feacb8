//! Toggles of the partition: configurations where the coordinates the free degrees of freedom
//! name stop determining the mechanism (a slider's position at a crank's dead centre, a
//! pendulum's x where its rod is horizontal). There `V = ∂q/∂u` is infinite, and past one the
//! kinematic solve lands on the mirror branch (the sign of det Φ_q or of a block's determinant
//! changes) or, worse, stays on the same one: the reflected motion `θ → −θ` of the pendulum
//! whose free coordinate is `x = L cos θ` gives the same smooth `x(t)`, so nothing in `u`
//! shows it, and no sign changes. Three checks on every converged step, each of which fails it
//! with [`Failure::Toggle`]:
//!
//! - **a sign change**: the step crossed a singular configuration of Φ_q;
//! - **growth of `‖V‖`** past [`TOGGLE_GROWTH`] times its value at the start: the step came
//!   close to one (the reduced mass grew a millionfold);
//! - **a kink in `q`**: the reflection reverses the velocity of the coordinates the free ones
//!   no longer determine (`θ̇ → −θ̇`, at a moderate `θ̈`), which no smooth motion does within a
//!   step. Over a step the trapezoid defect of a coordinate, `d = q̇_{n+1} − q̇_n −
//!   (h/2)(q̈_n + q̈_{n+1})`, is `O(h³)` on a resolved motion and about `2|q̇|` across a
//!   reflection, whatever the step. The step fails when the part of `d` that the free
//!   coordinates' own motion does not explain exceeds [`KINK`] times the scale
//!   `½(|q̇_n| + |q̇_{n+1}|) + ½h(|q̈_n| + |q̈_{n+1}|)`, rates that would move the coordinate
//!   by less than a millionth of its scale over the step counting as zero (measured: 1.3–2.0 across the
//!   pendulum's reflection; at most 0.013 on every resolved motion of the tests). The
//!   free motion explains the defect of `u` itself carried by `V` (large at ρ∞ < 1 for an
//!   unresolved stiff mode, whose `u̇` and `ü` alternate while the method's acceleration is
//!   smooth) and `V`'s change against the jump of `ü`. One more part, the jump of the
//!   velocity terms `V̇ u̇`, is the reflection's kink itself, but also follows a jump of `u̇`:
//!   so the test is made only on steps that resolve the free motion (their free
//!   accelerations change little over the step, below [`RESOLVED`] of the scale); a step
//!   that does not (an unresolved stiff mode at ρ∞ < 1 excited) is left to the other two
//!   checks.
//!
//! Fixed steps fail on a flagged step. The error-controlled mode retries it smaller, as any
//! failed step: the kink of a step that straddles the toggle persists as the step shrinks,
//! but the shorter retry no longer straddles it, so the steps close in on the toggle until the
//! growth of `‖V‖` (or the minimum step) stops them with the typed error, just before it.

use nalgebra::DefaultAllocator;

use super::Integrator;
use super::control::usable_length;
use super::newton::{ACCELERATION_FLOOR, Failure};
use crate::dynamic::{Dynamic, EquationsOfMotion, FreeStorage};
use crate::mechanism::{LengthScale, Storage};
use crate::structure::Structured;

/// How far `‖V‖` may grow past its value at the start before the state counts as at a
/// toggle of the partition: the reduced mass then grew about a million times.
const TOGGLE_GROWTH: f64 = 1e3;
/// A coordinate's trapezoid defect above this fraction of its scale is a kink (a reflection
/// gives about twice the scale; a resolved motion `O(h²ω²)` of it).
const KINK: f64 = 0.5;
/// The free accelerations' jump ratio (`free_jump`) up to which a step resolves
/// the free motion: `O(h²ω²)` on a resolved one (a step across a reflection: 0.008 at
/// h = 0.01, 0.05 at the failed iterate of h = 0.001); an unresolved stiff mode's, whose `ü`
/// jumps, above 1 (1.3–1.6 on the stiff slider-crank at ρ∞ = 0).
const RESOLVED: f64 = 0.25;

impl<M: Dynamic + EquationsOfMotion + Structured> Integrator<M>
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    /// The converged step of size `h` (the current state to `trial`, `now` to `next`) neither
    /// crossed nor reached a toggle of the partition (see the module documentation).
    pub(super) fn check_crossing(&mut self, h: f64) -> Result<(), Failure> {
        if self.at_toggle(h) {
            Err(Failure::Toggle)
        } else {
            Ok(())
        }
    }

    /// A step of size `h` whose iteration failed is a toggle when its last iterate (`next`,
    /// solved into `trial`) shows one: near a toggle the reduced equations are singular, and
    /// the iteration may fail before it converges on the reflected motion.
    pub(super) fn diagnose(&mut self, h: f64, failure: Failure) -> Failure {
        if self.at_toggle(h) {
            Failure::Toggle
        } else {
            failure
        }
    }

    /// Whether the step of size `h` from the current state to `trial` (`now` to `next`)
    /// changed a sign, grew `‖V‖` or kinked `q` (the module documentation).
    fn at_toggle(&mut self, h: f64) -> bool {
        let (before, after) = (self.states.current(), self.states.trial());
        let same_side =
            before.orientation == after.orientation && before.block_signs == after.block_signs;
        let near = self.reduced.v.norm() > TOGGLE_GROWTH * self.sensitivity;
        let kink = self.free_jump(h) <= RESOLVED && self.unexplained_kink(h) > KINK;
        !same_side || near || kink
    }

    /// The largest ratio, over the free coordinates, of the change of the accelerations over
    /// the step of size `h`, `h |ü₁ − ü₀|`, to the trapezoid scale: `O(h²ω²)` on a resolved
    /// motion (it is the error estimate's `h² Δü` against the motion over the step). Rates
    /// that would move the state by less than [`ACCELERATION_FLOOR`] scene scales over the
    /// step count as zero in the scale, so that a stiff spring's force noise (a free
    /// coordinate at rest whose `ü` is `k` times the positions' rounding) counts as resolved.
    fn free_jump(&self, h: f64) -> f64 {
        let (from, to) = (&self.now, &self.next);
        (0..from.u.len())
            .map(|k| {
                let (v, a) = ([from.ud[k], to.ud[k]], [from.udd[k], to.udd[k]]);
                let floor = ACCELERATION_FLOOR * self.matrix.scales[k] / h;
                ratio(h * (a[1] - a[0]), scale(v, a, h) + floor)
            })
            .fold(0.0, f64::max)
    }

    /// The largest ratio, over the coordinates, of the part of the trapezoid defect over the
    /// step of size `h` that the free coordinates do not explain, to its scale (the module
    /// documentation).
    ///
    /// With `q̇ = V u̇` (plus the drivers' terms, smooth in time), the defect is
    /// `d_q = V̄ d_u − (h/4) ΔV Δü + (ΔV ū̇ − (h/2)(V̇₀u̇₀ + V̇₁u̇₁))` (`V̄`, `ū̇` the ends'
    /// means, `Δ` their differences): the free coordinates' own defect `d_u` (large for an
    /// unresolved stiff mode, whose `u̇` and `ü` alternate) and the change of `V` against the
    /// jump of `ü` are the free motion's; the rest is `O(h³)` on a smooth `V` and the kink
    /// at a reflection. The explained part counts in the scale, so a coordinate at rest whose
    /// free coordinates move gives no ratio out of round-off; and rates that would move a
    /// coordinate by less than [`ACCELERATION_FLOOR`] of its unit (in scene scales) over the
    /// step count as zero in the scale, as in [`Self::free_jump`], so that one the motion
    /// leaves still (the falling scissor lift's platform x, released from rest) gives none
    /// out of its rates' round-off (1e-18 m/s, 1e-15 m/s²: a ratio of 0.6 without the floor).
    fn unexplained_kink(&mut self, h: f64) -> f64 {
        let (from, to) = (&self.now, &self.next);
        let (d_u, jump) = (&mut self.matrix.row, &mut self.matrix.change);
        for k in 0..from.u.len() {
            d_u[k] = defect([from.ud[k], to.ud[k]], [from.udd[k], to.udd[k]], h);
            jump[k] = to.udd[k] - from.udd[k];
        }
        let (before, after) = (self.states.current(), self.states.trial());
        let (v0, v1) = (&before.velocities, &after.velocities);
        let (a0, a1) = (&before.accelerations, &after.accelerations);
        let (start, end) = (&self.reduced.accepted, &self.reduced.v);
        let m = self.solver.mechanism();
        let length = LengthScale::new(usable_length(m.length_scale()));
        (0..v0.len())
            .map(|i| {
                let (s, e) = (start.row(i).transpose(), end.row(i).transpose());
                let part = 0.5 * (s.dot(d_u) + e.dot(d_u)) - 0.25 * h * (e.dot(jump) - s.dot(jump));
                let (v, a) = ([v0[i], v1[i]], [a0[i], a1[i]]);
                let floor = ACCELERATION_FLOOR * length.of(m.coordinate_unit(i)) / h;
                kink_ratio(v, a, h, part, floor)
            })
            .fold(0.0, f64::max)
    }
}

/// The unexplained part of a coordinate's trapezoid defect over a step of size `h`, with
/// rates `v` and accelerations `a` at its ends, `part` of it explained by the free motion and
/// rates below `floor` counting as zero, against its scale.
fn kink_ratio(v: [f64; 2], a: [f64; 2], h: f64, part: f64, floor: f64) -> f64 {
    ratio(defect(v, a, h) - part, scale(v, a, h) + part.abs() + floor)
}

/// The trapezoid defect `v₁ − v₀ − (h/2)(a₀ + a₁)` of rates `v` with accelerations `a` at a
/// step's ends.
fn defect(v: [f64; 2], a: [f64; 2], h: f64) -> f64 {
    v[1] - v[0] - 0.5 * h * (a[0] + a[1])
}

/// The scale of a trapezoid defect: `½(|v₀| + |v₁|) + ½h(|a₀| + |a₁|)`.
fn scale(v: [f64; 2], a: [f64; 2], h: f64) -> f64 {
    0.5 * (v[0].abs() + v[1].abs()) + 0.5 * h * (a[0].abs() + a[1].abs())
}

/// `|defect| / scale`, 0 for no defect (a coordinate at rest).
fn ratio(defect: f64, scale: f64) -> f64 {
    if defect == 0.0 {
        0.0
    } else {
        (defect / scale).abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reflection's kink counts whatever the floor; the round-off of a coordinate the motion
    /// leaves at rest (the falling scissor lift's platform x over its first step from rest,
    /// in m and s) does not, although against its own rates it looks like one.
    #[test]
    fn a_reflection_is_a_kink_and_round_off_at_rest_is_not() {
        let h = 1e-3;
        let floor = ACCELERATION_FLOOR / h;
        // θ̇ reversed within the step at a moderate θ̈: the defect is about 2|θ̇|.
        let reflection = kink_ratio([0.8, -0.8], [-2.0, -2.0], h, 0.0, floor);
        assert!(reflection > 1.5 * KINK, "{reflection}");
        let (v, a) = ([0.0, 2.0e-18], [-5.6e-16, 1.9e-15]);
        assert!(kink_ratio(v, a, h, 0.0, 0.0) > KINK);
        let at_rest = kink_ratio(v, a, h, 0.0, floor);
        assert!(at_rest < 1e-12, "{at_rest}");
        // A smooth motion at the floor's speed is no kink either.
        let smooth = kink_ratio([1e-3, 1e-3 + 1e-6], [1e-3, 1e-3], h, 0.0, floor);
        assert!(smooth < 1e-2, "{smooth}");
    }
}
