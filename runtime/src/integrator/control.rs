//! Step control: the step loop (fixed steps, or error-controlled ones retried smaller when
//! rejected), the local error estimate of the free coordinates, the choice of the next step
//! size, and landing exactly on requested times.

use nalgebra::{DefaultAllocator, Dim, OVector};

use super::Integrator;
use super::alpha::{Alpha, FreeMotion};
use super::error::DynamicsError;
use super::newton::Failure;
use super::options::StepControl;
use crate::codegen::math::{pow, powi};
use crate::dynamic::{Dynamic, EquationsOfMotion, FreeStorage};
use crate::mechanism::Storage;
use crate::structure::Structured;

/// A step within this fraction of the time left lands on it (rather than leave a sliver).
const LANDING_SLACK: f64 = 1e-9;
/// The largest relative difference between a planned step and the step the clock takes (the
/// step the motion then takes too, so that the two never part).
const CLOCK_RESOLUTION: f64 = 0.01;
/// A failed iteration retries with the step times this (error-controlled mode).
const RETRY_SHRINK: f64 = 0.25;

impl<M: Dynamic + EquationsOfMotion + Structured> Integrator<M>
where
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    /// Takes one accepted step, landing exactly on `limit` when it is within reach: fixed
    /// steps fail with the iteration's error; error-controlled ones are retried smaller after
    /// an error estimate above the tolerance or a failed iteration, down to the minimum step.
    pub(super) fn advance(&mut self, limit: Option<f64>) -> Result<(), DynamicsError> {
        loop {
            let (h, t, clipped) = self.plan(limit)?;
            let outcome = self.solve_step(h, t).and_then(|()| self.check_iterate());
            let adaptive = match self.options.control {
                StepControl::Fixed { .. } => None,
                StepControl::Adaptive {
                    rtol, atol, min, ..
                } => Some((rtol, atol, min)),
            };
            match (outcome, adaptive) {
                (Ok(()), None) => {
                    self.accept(h);
                    return Ok(());
                }
                (Ok(()), Some((rtol, atol, min))) => {
                    let ratio = error_ratio(&self.alpha, h, &self.now, &self.next, (rtol, atol));
                    if ratio <= 1.0 {
                        self.accept(h);
                        let proposed = h * resize(ratio);
                        self.step = if clipped {
                            self.step.min(proposed.max(h))
                        } else {
                            proposed
                        };
                        return Ok(());
                    }
                    self.retry((h, t), h * resize(ratio), min, Failure::Rejected)?;
                }
                (Err(failure), None) => return Err(self.failure(failure, t, h)),
                (Err(Failure::SingularMass(k)), Some(_)) => {
                    return Err(self.failure(Failure::SingularMass(k), t, h));
                }
                (Err(failure), Some((_, _, min))) => {
                    self.retry((h, t), h * RETRY_SHRINK, min, failure)?;
                }
            }
        }
    }

    /// The next attempt's step `h`, its end `t`, and whether it was shortened to land on
    /// `limit` (a step that would leave less than itself before `limit` is halved, so that
    /// the last two steps are even). The step is the one the clock takes, `t − t0`;
    /// [`DynamicsError::StepBelowClock`] when that is not the step planned (to a hundredth).
    fn plan(&self, limit: Option<f64>) -> Result<(f64, f64, bool), DynamicsError> {
        let t0 = self.states.current().t;
        let (h, adaptive) = match self.options.control {
            StepControl::Fixed { step } => (step, false),
            StepControl::Adaptive { max, .. } => (self.step.min(max), true),
        };
        let (h, t, clipped) = match limit {
            Some(end) if end - t0 <= h * (1.0 + LANDING_SLACK) => (end - t0, end, true),
            Some(end) if adaptive && end - t0 < 2.0 * h => {
                let half = 0.5 * (end - t0);
                (half, t0 + half, true)
            }
            _ => (h, t0 + h, false),
        };
        // Far from t = 0, `t0 + h` rounds: the motion takes the step the clock takes, and a
        // step the clock cannot resolve (it would stand still: a hang) is refused.
        let taken = t - t0;
        if taken > 0.0 && (taken - h).abs() <= CLOCK_RESOLUTION * h {
            Ok((taken, t, clipped))
        } else {
            Err(DynamicsError::StepBelowClock { t: t0, step: h })
        }
    }

    /// Counts the rejection of the attempt `(h, t)` (its step and end) and sets the next
    /// try's step, unless it is below `min`: then the attempt's error if the kinematics failed
    /// or the partition met a toggle (a smaller step does not cure those), otherwise
    /// [`DynamicsError::StepTooSmall`] with the step refused.
    fn retry(
        &mut self,
        (h, t): (f64, f64),
        next: f64,
        min: f64,
        failure: Failure,
    ) -> Result<(), DynamicsError> {
        self.stats.rejected += 1;
        if next >= min {
            self.step = next;
            return Ok(());
        }
        Err(match failure {
            Failure::Kinematics(_) | Failure::Toggle => self.failure(failure, t, h),
            _ => DynamicsError::StepTooSmall {
                t: self.states.current().t,
                step: next,
                min,
            },
        })
    }

    /// The converged iterate is finite.
    fn check_iterate(&self) -> Result<(), Failure> {
        match self.next.first_non_finite() {
            Some(k) => Err(Failure::NonFinite(Some(k))),
            None => Ok(()),
        }
    }

    /// Makes the step's iterate the current state and books its energy.
    fn accept(&mut self, h: f64) {
        self.history.accept(&self.next.udd, &self.correction, h);
        self.states.accept();
        core::mem::swap(&mut self.now, &mut self.next);
        self.reduced.accepted.copy_from(&self.reduced.v);
        let m = self.solver.mechanism();
        self.book
            .advance(m, self.states.current(), &self.reduced.forces, h);
        self.stats.steps += 1;
    }
}

/// The largest ratio, over the free coordinates, of the estimated local error of a step of
/// size `h` from `from` to `to` to what the step may add, `(atol + rtol·max(|u_n|, |u_{n+1}|))
/// · h / (1 s)`: the step is accepted when it is at most 1.
///
/// The tolerance is per second of simulated time (error per unit step): an oscillation's
/// phase errors accumulate step after step, so a tolerance per step would let the global
/// error grow with the number of steps (some 3,700 × the tolerance over two periods of a
/// pendulum at 1e-9); per unit time, the error after T seconds stays about T × the tolerance,
/// and halves with it (tolerance proportionality), at the price of steps ∝ tol^(−1/2).
///
/// The estimate is `|C| h² |ü_{n+1} − ü_n|` ([`Alpha::error_constant`]), with the
/// accelerations that satisfy the equations of motion (not the method's `a`, whose start-up
/// offset for ρ∞ < 1 would pollute the difference). The velocities' local error is of the same
/// order, h³, but its constant involves the fourth derivative and no two-point difference
/// estimates it; it is controlled through the positions'.
pub(crate) fn error_ratio<F: Dim>(
    alpha: &Alpha,
    h: f64,
    from: &FreeMotion<F>,
    to: &FreeMotion<F>,
    (rtol, atol): (f64, f64),
) -> f64
where
    DefaultAllocator: Storage<F>,
{
    let c = alpha.error_constant().abs() * h;
    let ratio = |k: usize| {
        let error = c * (to.udd[k] - from.udd[k]).abs();
        let scale = atol + rtol * from.u[k].abs().max(to.u[k].abs());
        error / scale
    };
    (0..from.u.len()).map(ratio).fold(0.0, f64::max)
}

/// Safety factor on the step the error estimate allows.
const SAFETY: f64 = 0.9;
/// The step never grows by more than this in one step…
const MAX_GROWTH: f64 = 4.0;
/// … nor shrinks by more than this.
const MAX_SHRINK: f64 = 0.2;
/// A proposed growth below this keeps the step (and the iteration matrix's factors).
const KEEP_BELOW: f64 = 1.2;

/// The factor to multiply the step by after an error ratio `ratio` (local error O(h³) against
/// a tolerance ∝ h: the ratio is O(h²)).
pub(crate) fn resize(ratio: f64) -> f64 {
    if !ratio.is_finite() {
        return MAX_SHRINK;
    }
    let factor = if ratio == 0.0 {
        MAX_GROWTH
    } else {
        (SAFETY * pow(ratio, -0.5)).clamp(MAX_SHRINK, MAX_GROWTH)
    };
    if (1.0..KEEP_BELOW).contains(&factor) {
        1.0
    } else {
        factor
    }
}

/// Scales of the free coordinates for the Newton test: the scene's length scale to the power
/// of each free equation's unit.
pub(crate) fn scales<F: Dim>(length: f64, units: impl Fn(usize) -> i32, out: &mut OVector<f64, F>)
where
    DefaultAllocator: Storage<F>,
{
    let length = usable_length(length);
    for k in 0..out.len() {
        out[k] = powi(length, units(k));
    }
}

/// The scene's length scale where it is usable (finite and positive), 1 otherwise.
pub(crate) fn usable_length(length: f64) -> f64 {
    if length.is_finite() && length > 0.0 {
        length
    } else {
        1.0
    }
}
