//! A [`crate::Simulation`] step's prediction: the guess of the Newton blocks' coordinates at
//! the step's time (a Taylor expansion from the last solved states), and the jump test that
//! judges the solve against it.
//!
//! Both walk the blocks' coordinates only, the ones a solve starts Newton from and can move to
//! another branch: explicit stages assign theirs whatever the guess, and have one solution.
//! The predicted motion is measured while predicting, so that the test after the solve needs
//! only the correction Newton made.

use nalgebra::DefaultAllocator;

use crate::mechanism::{Outputs, Storage, Vector};
use crate::solver::{Solver, larger};
use crate::state::State;
use crate::structure::Structured;

/// A predicted step is suspect when Newton moved the solution further from the prediction than
/// this fraction of the predicted motion (both measured on the Newton blocks' coordinates, the
/// only ones a solve can move to another branch): a second-order prediction is O(h³) off while the
/// motion is O(h), so only a step far too coarse for the motion, or a landing on the mirror
/// branch, gets near it.
const JUMP_FRACTION: f64 = 0.5;
/// … plus this much (scaled: scene lengths, radians) and ten times the solver's tolerances, so
/// that a mechanism at rest, whose predicted motion is zero, is not suspect for the corrections
/// of round-off or of a loosely converged solve.
const JUMP_FLOOR: f64 = 1e-6;
/// A predicted step is also suspect when the prediction turns a block angle by more than this
/// (radians), however close Newton lands to it: over so long a step the Taylor prediction
/// says nothing about which turn of a lever or which side of a crank the motion reaches, so a
/// solution near it may be another winding of the same pose (a single step of 20 rad of crank
/// gave a lever four turns ahead). It is the solver's default step clamp: no single Newton
/// step moves further either. Lengths are not bounded: a tall linkage's upper bodies travel
/// many scene lengths in a step while each joint turns a little (the 1000-stage scissor
/// lift's platform), and bounding them sub-stepped its rise in proportion to its height.
const MAX_PREDICTED_MOTION: f64 = 1.0;

/// The last prediction: the guessed block coordinates, and how far they move from the state
/// predicted from.
pub(crate) struct Prediction<M: Structured>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// The predicted value of each block coordinate (the other entries are stale: nothing
    /// reads them).
    guess: Vector<M::Dim>,
    /// ‖D_c⁻¹ (guess − current)‖∞ over the block coordinates: the predicted motion, in scene
    /// lengths and radians.
    motion: f64,
    /// The largest predicted turn of a block angle (radians).
    turn: f64,
}

impl<M: Structured> Clone for Prediction<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn clone(&self) -> Self {
        Self {
            guess: self.guess.clone(),
            motion: self.motion,
            turn: self.turn,
        }
    }
}

impl<M: Structured> Prediction<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// No prediction yet, with room for `state`'s coordinates.
    pub(crate) fn new(state: &State<M>) -> Self {
        Self {
            guess: state.q.clone(),
            motion: 0.0,
            turn: 0.0,
        }
    }

    /// Writes the guess at `t` into `next.q` and says whether it predicted one (otherwise
    /// nothing is touched): the Newton blocks' coordinates by the Taylor expansion from
    /// `current` with the derivatives the scene computes, plus one more from the difference
    /// with the previous state, which `next` still holds when `history` (the secant slope for
    /// positions-only scenes, q̈ from two velocities, the jerk from two accelerations). A
    /// positions-only scene without history has nothing to predict with.
    ///
    /// The other coordinates belong to explicit stages, which assign them whatever their guess:
    /// they are left as `next` holds them when that is a solved state (`history`, finite as the
    /// solve checks), and are `current`'s otherwise.
    #[inline]
    pub(crate) fn predict(
        &mut self,
        solver: &Solver<M>,
        current: &State<M>,
        next: &mut State<M>,
        history: bool,
        t: f64,
    ) -> bool {
        let h = t - current.t;
        let h_prev = current.t - next.t;
        let differences = history && h_prev != 0.0 && h_prev.is_finite();
        // Coefficients hoisted out of the loop: one division per step, none per coordinate.
        // The scene's outputs (its states'), a constant of a generated scene's type.
        let formula = match solver.mechanism().outputs() {
            Outputs::Positions if !differences => return false,
            Outputs::Positions => Taylor::Secant(h / h_prev),
            Outputs::Velocities if differences => Taylor::Velocities(0.5 * h * h / h_prev),
            Outputs::Velocities => Taylor::Velocity,
            Outputs::Accelerations | Outputs::Forces if differences => {
                Taylor::Accelerations(h * h * h / (6.0 * h_prev))
            }
            Outputs::Accelerations | Outputs::Forces => Taylor::Acceleration,
        };
        if !history {
            // `next` may hold a failed solve's iterate.
            next.q.copy_from(&current.q);
        }
        let now = [&current.q, &current.velocities, &current.accelerations].map(|v| v.as_slice());
        let guess = self.guess.as_mut_slice();
        let (mut motion, mut turn) = (0.0, 0.0);
        // Each coordinate's earlier values are read before its guess overwrites them in `next`.
        solver.visit_block_coordinates(|j, inverse_scale, angle| {
            let before = [&next.q, &next.velocities, &next.accelerations].map(|v| v.as_slice());
            let (Some(value), Some(&from)) = (formula.at(j, h, now, before), now[0].get(j)) else {
                return;
            };
            let (Some(g), Some(q)) = (guess.get_mut(j), next.q.get_mut(j)) else {
                return;
            };
            (*g, *q) = (value, value);
            let moved = ((value - from) * inverse_scale).abs();
            motion = larger(motion, moved);
            if angle {
                turn = larger(turn, moved);
            }
        });
        (self.motion, self.turn) = (motion, turn);
        true
    }

    /// Whether the solve from the last prediction, which reached `solved`, is suspect: it
    /// landed further from the prediction than [`JUMP_FRACTION`] of the predicted motion (plus
    /// the floor), or the prediction turned a block angle by more than
    /// [`MAX_PREDICTED_MOTION`].
    #[inline]
    pub(crate) fn jumped(&self, solver: &Solver<M>, solved: &Vector<M::Dim>) -> bool {
        if self.turn > MAX_PREDICTED_MOTION {
            return true;
        }
        let (guess, solved) = (self.guess.as_slice(), solved.as_slice());
        let mut correction = 0.0;
        solver.visit_block_coordinates(|j, inverse_scale, _| {
            if let (Some(x), Some(s)) = (guess.get(j), solved.get(j)) {
                correction = larger(correction, ((x - s) * inverse_scale).abs());
            }
        });
        let options = solver.options();
        let floor = JUMP_FLOOR + 10.0 * (options.residual_tolerance + options.step_tolerance);
        correction > JUMP_FRACTION * self.motion + floor
    }
}

/// The Taylor formula of a prediction, by what the scene computes and whether the previous
/// state is known, with its coefficient of the difference with that state.
#[derive(Clone, Copy)]
enum Taylor {
    /// Positions only: the secant through the last two, `q + (q − q_prev) h / h_prev`.
    Secant(f64),
    /// `q + q̇ h`.
    Velocity,
    /// … `+ ½ q̈ h²`, q̈ from the last two velocities (the coefficient `h² / (2 h_prev)`).
    Velocities(f64),
    /// `q + q̇ h + ½ q̈ h²`.
    Acceleration,
    /// … `+ ⅙ q⃛ h³`, q⃛ from the last two accelerations (the coefficient `h³ / (6 h_prev)`).
    Accelerations(f64),
}

impl Taylor {
    /// The prediction of coordinate `j` over a step `h` from the (q, q̇, q̈) `now`, with the
    /// previous state's `before`; `None` past the end. A term is left out, not multiplied by
    /// zero, where the state has no such value (`before` may hold a failed solve's non-finite
    /// iterate).
    #[inline]
    fn at(self, j: usize, h: f64, now: [&[f64]; 3], before: [&[f64]; 3]) -> Option<f64> {
        let [q, qd, qdd] = now.map(|v| v.get(j).copied());
        let [q_prev, qd_prev, qdd_prev] = before.map(|v| v.get(j).copied());
        let q = q?;
        Some(match self {
            Taylor::Secant(ratio) => q + (q - q_prev?) * ratio,
            Taylor::Velocity => q + h * qd?,
            Taylor::Velocities(c) => {
                let v = qd?;
                q + h * v + c * (v - qd_prev?)
            }
            Taylor::Acceleration => q + h * qd? + 0.5 * h * h * qdd?,
            Taylor::Accelerations(c) => {
                let a = qdd?;
                q + h * qd? + 0.5 * h * h * a + c * (a - qdd_prev?)
            }
        })
    }
}
