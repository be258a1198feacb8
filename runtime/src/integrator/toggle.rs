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
//!   by less than a millionth of its scale over the step counting as zero (measured: 1.3–2.0
//!   across the pendulum's reflection; at most 0.013 on every resolved motion of the tests). The
//!   free motion explains the defect of `u` itself carried by `V` (large at ρ∞ < 1 for an
//!   unresolved stiff mode, whose `u̇` and `ü` alternate while the method's acceleration is
//!   smooth) and `V`'s change against the jump of `ü`. One more part, the jump of the
//!   velocity terms `V̇ u̇`, is the reflection's kink itself, but also follows a jump of `u̇`:
//!   so the test is made only on steps that resolve the free motion (their free
//!   accelerations change little over the step, below [`RESOLVED`] of the scale); a step
//!   that does not (an unresolved stiff mode at ρ∞ < 1 excited) is left to the other two
//!   checks. Only coordinates a branch decides are watched: those of the plan's blocks and
//!   of explicit stages downstream of one (the others are affine assignments from time and
//!   the free states, the same on either branch).
//!
//! The checks run cheapest first (the signs, `‖V‖²` against a bound set at the start, the
//! free accelerations' jump), and the kink's pass over the watched coordinates last, with
//! their floors found once ([`Watch`]).
//!
//! Fixed steps fail on a flagged step. The error-controlled mode retries it smaller, as any
//! failed step: the kink of a step that straddles the toggle persists as the step shrinks,
//! but the shorter retry no longer straddles it, so the steps close in on the toggle until the
//! growth of `‖V‖` (or the minimum step) stops them with the typed error, just before it.

use nalgebra::{DefaultAllocator, OVector, U1};

use super::Integrator;
use super::control::usable_length;
use super::newton::{ACCELERATION_FLOOR, Failure};
use crate::dynamic::{Dynamic, EquationsOfMotion, FreeStorage};
use crate::mechanism::{LengthScale, Mechanism, Storage, Vector};
use crate::structure::{Stage, Structured};

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

/// What the checks keep between steps: the bound on `‖V‖²` set at the last (re)start, and
/// the coordinates the kink test watches with their floors (found once).
pub(crate) struct Watch<M: Mechanism>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// `(TOGGLE_GROWTH ‖V‖)²` at the last (re)start (infinite before the first).
    limit: f64,
    /// The coordinates a reflection can kink, ascending, in the first `count` entries
    /// ([`watched_coordinates`]).
    watched: OVector<usize, M::Dim>,
    count: usize,
    /// Per watched coordinate, [`ACCELERATION_FLOOR`] of its unit in scene scales: over a
    /// step of size `h`, rates below this over `h` count as zero.
    floors: Vector<M::Dim>,
}

impl<M: Mechanism> Clone for Watch<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn clone(&self) -> Self {
        Self {
            limit: self.limit,
            watched: self.watched.clone(),
            count: self.count,
            floors: self.floors.clone(),
        }
    }
}

impl<M: Structured> Watch<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// The checks for `m`, before the first start.
    pub fn new(m: &M) -> Self {
        let n = m.dim();
        let mut watched = OVector::from_element_generic(n, U1, 0);
        let count = watched_coordinates(m.stage_count(), |s| m.stage(s), watched.as_mut_slice());
        let length = LengthScale::new(usable_length(m.length_scale()));
        let mut floors = Vector::zeros_generic(n, U1);
        for (floor, &i) in floors.iter_mut().zip(watched.iter().take(count)) {
            *floor = ACCELERATION_FLOOR * length.of(m.coordinate_unit(i));
        }
        Self {
            limit: f64::INFINITY,
            watched,
            count,
            floors,
        }
    }

    /// Measures the growth of `‖V‖` from `norm`, its value at a (re)start.
    pub fn restart(&mut self, norm: f64) {
        let limit = TOGGLE_GROWTH * norm;
        self.limit = limit * limit;
    }
}

/// Writes the coordinates a reflection can kink into the head of `out` (one entry per
/// coordinate) and returns how many, from the plan's `count` stages (`stage`): all but those
/// of explicit stages that read no block, directly or through other explicit stages. An
/// explicit stage assigns each coordinate from an equation affine in it, so those coordinates
/// are smooth functions of time and the free states, the same on either branch (the seed's
/// grounds, its piston's y and angle, its crank's pose: 11 of 15); the others come from a
/// block's solve, or from coordinates that do, and follow its branch.
fn watched_coordinates<'a>(
    count: usize,
    stage: impl Fn(usize) -> Option<Stage<'a>>,
    out: &mut [usize],
) -> usize {
    // First a flag per coordinate (1: watched), then the watched indices compacted in place.
    out.fill(1);
    for s in 0..count {
        let Some(Stage::Explicit {
            coordinates, reads, ..
        }) = stage(s)
        else {
            continue;
        };
        let smooth = |r: usize| {
            stage(r).is_some_and(|read| {
                let mut flags = read.coordinates().iter().map(|&c| out.get(c).copied());
                flags.all(|flag| flag == Some(0))
            })
        };
        if reads.iter().all(|&r| smooth(r)) {
            for &c in coordinates {
                if let Some(flag) = out.get_mut(c) {
                    *flag = 0;
                }
            }
        }
    }
    let mut watched = 0;
    for i in 0..out.len() {
        if out[i] == 1 {
            out[watched] = i;
            watched += 1;
        }
    }
    watched
}

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
    /// changed a sign, grew `‖V‖` or kinked `q` (the module documentation): the cheap checks
    /// first, the kink's pass over every coordinate last.
    fn at_toggle(&mut self, h: f64) -> bool {
        let (before, after) = (self.states.current(), self.states.trial());
        let same_side =
            before.orientation == after.orientation && before.block_signs == after.block_signs;
        !same_side
            || self.reduced.v.norm_squared() > self.watch.limit
            || (self.free_jump(h) <= RESOLVED && self.kinked(h))
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

    /// Whether, for some watched coordinate ([`watched_coordinates`]), the part of the
    /// trapezoid defect over the step of size `h` that the free coordinates do not explain
    /// exceeds [`KINK`] times its scale (the module documentation).
    ///
    /// With `q̇ = V u̇` (plus the drivers' terms, smooth in time), the defect is
    /// `d_q = V̄ d_u − (h/4) ΔV Δü + (ΔV ū̇ − (h/2)(V̇₀u̇₀ + V̇₁u̇₁))` (`V̄`, `ū̇` the ends'
    /// means, `Δ` their differences): the free coordinates' own defect `d_u` (large for an
    /// unresolved stiff mode, whose `u̇` and `ü` alternate) and the change of `V` against the
    /// jump of `ü` are the free motion's; the rest is `O(h³)` on a smooth `V` and the kink
    /// at a reflection. The explained part, `V₀ (½ d_u + ¼ h Δü) + V₁ (½ d_u − ¼ h Δü)`,
    /// counts in the scale, so a coordinate at rest whose free coordinates move gives no
    /// ratio out of round-off; and rates that would move a
    /// coordinate by less than [`ACCELERATION_FLOOR`] of its unit (in scene scales) over the
    /// step count as zero in the scale, as in [`Self::free_jump`], so that one the motion
    /// leaves still (the falling scissor lift's platform x, released from rest) gives none
    /// out of its rates' round-off (1e-18 m/s, 1e-15 m/s²: a ratio of 0.6 without the floor).
    fn kinked(&mut self, h: f64) -> bool {
        let (from, to) = (&self.now, &self.next);
        let (at_start, at_end) = (&mut self.matrix.row, &mut self.matrix.change);
        for k in 0..from.u.len() {
            let d_u = defect([from.ud[k], to.ud[k]], [from.udd[k], to.udd[k]], h);
            let jump = 0.25 * h * (to.udd[k] - from.udd[k]);
            at_start[k] = 0.5 * d_u + jump;
            at_end[k] = 0.5 * d_u - jump;
        }
        let (before, after) = (self.states.current(), self.states.trial());
        let (start, end) = (&self.reduced.accepted, &self.reduced.v);
        let watch = &self.watch;
        let watched = watch.watched.as_slice().iter().take(watch.count);
        let per_step = 1.0 / h;
        // Every watched coordinate, without an early exit (a kink is rare).
        let mut kinked = false;
        for (&i, &floor) in watched.zip(watch.floors.as_slice()) {
            let mut part = 0.0;
            for k in 0..at_start.len() {
                part += start[(i, k)] * at_start[k] + end[(i, k)] * at_end[k];
            }
            let v = [before.velocities[i], after.velocities[i]];
            let a = [before.accelerations[i], after.accelerations[i]];
            kinked |= exceeds(v, a, h, part, floor * per_step, KINK);
        }
        kinked
    }
}

/// Whether the unexplained part of a coordinate's trapezoid defect over a step of size `h`,
/// with rates `v` and accelerations `a` at its ends, `part` of it explained by the free motion
/// and rates below `floor` counting as zero, exceeds `threshold` times its scale (no
/// division: this runs for every coordinate at every step).
fn exceeds(v: [f64; 2], a: [f64; 2], h: f64, part: f64, floor: f64, threshold: f64) -> bool {
    let unexplained = defect(v, a, h) - part;
    // A NaN is no kink (the finiteness checks name it).
    unexplained.abs() > threshold * (scale(v, a, h) + part.abs() + floor)
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
    use crate::structure::{Block, Pattern};

    /// A reflection's kink counts whatever the floor; the round-off of a coordinate the motion
    /// leaves at rest (the falling scissor lift's platform x over its first step from rest,
    /// in m and s) does not, although against its own rates it looks like one.
    #[test]
    fn a_reflection_is_a_kink_and_round_off_at_rest_is_not() {
        let h = 1e-3;
        let floor = ACCELERATION_FLOOR / h;
        // θ̇ reversed within the step at a moderate θ̈: the defect is about 2|θ̇|, so it
        // exceeds the threshold with a margin.
        let reflection = ([0.8, -0.8], [-2.0, -2.0]);
        assert!(exceeds(
            reflection.0,
            reflection.1,
            h,
            0.0,
            floor,
            3.0 * KINK
        ));
        let (v, a) = ([0.0, 2.0e-18], [-5.6e-16, 1.9e-15]);
        assert!(exceeds(v, a, h, 0.0, 0.0, KINK));
        assert!(!exceeds(v, a, h, 0.0, floor, 1e-12));
        // A smooth motion at the floor's speed is no kink either.
        let smooth = ([1e-3, 1e-3 + 1e-6], [1e-3, 1e-3]);
        assert!(!exceeds(smooth.0, smooth.1, h, 0.0, floor, 1e-2));
        // The part the free motion explains is not counted: a defect all explained is none.
        let explained = defect(reflection.0, reflection.1, h);
        assert!(!exceeds(
            reflection.0,
            reflection.1,
            h,
            explained,
            floor,
            1e-12
        ));
        // NaN rates are no kink (the finiteness checks report them).
        assert!(!exceeds([f64::NAN, 0.0], [0.0, 0.0], h, 0.0, floor, KINK));
    }

    fn block<'a>(coordinates: &'a [usize], reads: &'a [usize]) -> Stage<'a> {
        Stage::Block(Block {
            equations: coordinates,
            coordinates,
            pattern: Pattern::Dense,
            slots: coordinates.len() * coordinates.len(),
            pivots: &[],
            reads,
        })
    }

    fn explicit<'a>(coordinates: &'a [usize], reads: &'a [usize]) -> Stage<'a> {
        Stage::Explicit {
            equations: coordinates,
            coordinates,
            reads,
        }
    }

    /// The watched coordinates of `n` (at most 16) under `stages`, and how many.
    fn watched(stages: &[Stage<'_>], n: usize) -> ([usize; 16], usize) {
        let mut out = [0; 16];
        let count = watched_coordinates(stages.len(), |s| stages.get(s).copied(), &mut out[..n]);
        (out, count)
    }

    /// The seed's plan (its snapshot): grounds, piston y and angle, crank x and y assigned from
    /// nothing, the crank angle from its free state, the rod's block, and the rod's x and the
    /// piston's x from the block: only the last four can follow a branch.
    #[test]
    fn the_kink_test_watches_what_a_block_decides() {
        let seed = [
            explicit(&[0, 1, 2, 4, 5, 9, 10, 12, 13, 14], &[]),
            explicit(&[11], &[]),
            block(&[7, 8], &[1]),
            explicit(&[6, 3], &[1, 2]),
        ];
        let (seed, count) = watched(&seed, 15);
        assert_eq!(seed[..count], [3, 6, 7, 8]);
        // Explicit stages reading only explicit ones stay smooth, through a chain; one
        // reading a block does not, nor one reading a stage downstream of a block.
        let chain = [
            explicit(&[0], &[]),
            explicit(&[1], &[0]),
            block(&[2], &[1]),
            explicit(&[3], &[1]),
            explicit(&[4], &[2]),
            explicit(&[5], &[0, 4]),
        ];
        let (all, count) = watched(&chain, 6);
        assert_eq!(all[..count], [2, 4, 5]);
        // A coordinate no stage assigns (a plan cut short) is watched.
        let (short, count) = watched(&chain[..2], 4);
        assert_eq!(short[..count], [2, 3]);
    }
}
