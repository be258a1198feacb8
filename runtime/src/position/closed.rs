//! A block's closed-form start: of the two solutions the generated code gives for a block whose
//! loop closes by an intersection ([`Structured::closed_form`]), the one nearest the guess
//! replaces the guess, and Newton's iteration verifies it.
//!
//! Nearest is measured like Newton's steps, in scene lengths and radians, with each candidate
//! angle first moved by whole turns to the guess's. The guess (the predicted state while
//! stepping, the `near` guesses at assembly) takes the nearest solution only when it lies well
//! inside that solution's neighbourhood, a quarter of the way to the other at most: there the
//! choice is the one Newton would make from the same guess, and the crossing and jump checks
//! that watch Newton's solutions watch these the same way. Near a toggle or a change point,
//! where the two solutions merge (closer than [`SEPARATION`]), and where the loop cannot close
//! (NaN candidates), Newton starts from the guess as it did without a closed form, so its
//! answers and its errors there are unchanged: at a toggle Newton crawls into the singular root
//! and reports it, where a start on the exact root would converge at once and hide it.

use core::f64::consts::{PI, TAU};

use nalgebra::DefaultAllocator;

use crate::block::BlockSolve;
use crate::mechanism::{Storage, Unit, Vector};
use crate::structure::Structured;
use crate::workspace::Parts;

/// The most coordinates a closed-form block has (a dyad: two).
const MAX_SIZE: usize = 2;
/// The guess takes the nearest solution only when it is within this fraction of the distance
/// between the two solutions (scaled).
const CLEAR_FRACTION: f64 = 0.25;
/// … and when the two solutions are at least this far apart (scaled: scene lengths, radians).
/// Closer, the block is near a toggle, where Newton from the guess crawls into a singular root
/// and reports it; a closed-form start would land on the root and hide the toggle.
const SEPARATION: f64 = 1e-3;

/// Moves the block's coordinates in `q` to its closed-form solution nearest them, if it has
/// one; returns whether it did.
pub(crate) fn start<M: Structured>(
    bs: &BlockSolve<'_, M>,
    parts: &Parts<'_>,
    q: &mut Vector<M::Dim>,
    t: f64,
) -> bool
where
    DefaultAllocator: Storage<M::Dim>,
{
    match bs.n() {
        1 => start_sized::<M, 1>(bs, parts, q, t),
        MAX_SIZE => start_sized::<M, MAX_SIZE>(bs, parts, q, t),
        _ => false,
    }
}

/// [`start`] for a block of `N` coordinates.
fn start_sized<M: Structured, const N: usize>(
    bs: &BlockSolve<'_, M>,
    parts: &Parts<'_>,
    q: &mut Vector<M::Dim>,
    t: f64,
) -> bool
where
    DefaultAllocator: Storage<M::Dim>,
{
    let mut candidates = [[[f64::NAN; 2]; N]; 2];
    bs.m.closed_form(
        bs.stage,
        q,
        parts.trig,
        t,
        candidates.as_flattened_mut().as_flattened_mut(),
    );
    let coordinates = bs.block.coordinates;
    let (mut guess, mut angles, mut scales) = ([0.0; N], [false; N], [0.0; N]);
    for (j, &c) in coordinates.iter().enumerate().take(N) {
        (guess[j], angles[j]) = (q[c], bs.m.coordinate_unit(c) == Unit::Angle);
    }
    for (s, &c) in scales.iter_mut().zip(&*parts.scales.inverse_cols) {
        *s = c;
    }
    let Some((_, solution)) = nearest(&guess, &candidates, &angles, &scales, 0) else {
        return false;
    };
    for (&value, &c) in solution.iter().zip(coordinates) {
        q[c] = value;
    }
    true
}

/// The rule of [`start`], shared with the straight step (its `choose`): of the two
/// `candidates` of a block at `guess` (per coordinate its value, or an angle's cosine and
/// sine; see [`Structured::closed_form`]), the one (0 or 1) the guess takes and its
/// coordinates, each angle moved by whole turns to the guess's; `None` near a toggle, away
/// from both solutions, or where the loop cannot close (NaN). `inverse_cols` scales each
/// coordinate to scene lengths and radians.
///
/// The rule measures angles, but one `atan2` decides it where the guess is clearly nearest
/// the candidate `first` (the one tried first: 0, or the last step's choice), as while
/// stepping; anywhere else both angles are computed and the exact rule ([`nearest_of`])
/// decides. The answer does not depend on `first`.
#[inline(always)]
pub(crate) fn nearest<const N: usize>(
    guess: &[f64; N],
    candidates: &[Units<N>; 2],
    angles: &[bool; N],
    inverse_cols: &[f64; N],
    first: usize,
) -> Option<(usize, [f64; N])> {
    let (first, other) = if first == 1 { (1, 0) } else { (0, 1) };
    let exact = |k: usize| coordinates(&candidates[k], angles, guess);
    let tried = exact(first);
    let near = squared_distance(guess, &tried, inverse_cols);
    if angles.contains(&true)
        && clearly_nearest(near, &candidates[first], &candidates[other], inverse_cols)
    {
        return Some((first, tried));
    }
    let mut both = [tried, tried];
    both[other] = exact(other);
    let chosen = nearest_of(guess, &both, inverse_cols)?;
    Some((chosen, both[chosen]))
}

/// Whether the exact rule takes the candidate `tried`, at squared distance `near` from the
/// guess, over `other`, decided without the other's angles: `near` is within the rule's
/// fraction of a lower bound on the candidates' distance (an angle's chord is at most its
/// arc, whatever turns the rule moves the angles by), by a margin that rounding in the bound
/// cannot cross. The other candidate is then at least three times as far from the guess (the
/// triangle inequality).
#[inline(always)]
fn clearly_nearest<const N: usize>(
    near: f64,
    tried: &Units<N>,
    other: &Units<N>,
    inverse_cols: &[f64; N],
) -> bool {
    let apart = chord_distance(tried, other, inverse_cols);
    apart >= SEPARATION * SEPARATION * (1.0 + MARGIN)
        && near <= CLEAR_FRACTION * CLEAR_FRACTION * apart * (1.0 - MARGIN)
}

/// A closed-form candidate's coordinates as the generated code writes them: per coordinate
/// its value (then 0), or an angle's cosine and sine.
pub(crate) type Units<const N: usize> = [[f64; 2]; N];

/// How much clearer than the exact rule's thresholds the one-`atan2` test must be, so that
/// rounding in the bound cannot decide differently from the exact rule.
const MARGIN: f64 = 1e-9;

/// A candidate's coordinates, each angle taken by `atan2` from its cosine and sine and moved
/// to the guess's turn.
#[inline(always)]
fn coordinates<const N: usize>(units: &Units<N>, angles: &[bool; N], guess: &[f64; N]) -> [f64; N] {
    let mut values = [0.0; N];
    for j in 0..N {
        let [value, sin] = units[j];
        values[j] = if angles[j] {
            let mut angle = libm::atan2(sin, value);
            to_turn(&mut angle, guess[j]);
            angle
        } else {
            value
        };
    }
    values
}

/// `Σ ((a_j − b_j) c_j)²`.
#[inline(always)]
fn squared_distance<const N: usize>(a: &[f64; N], b: &[f64; N], inverse_cols: &[f64; N]) -> f64 {
    let mut sum = 0.0;
    for j in 0..N {
        let d = (a[j] - b[j]) * inverse_cols[j];
        sum += d * d;
    }
    sum
}

/// A lower bound on the squared scaled distance between two candidates however their angles
/// are turned: angles by their chord.
#[inline(always)]
fn chord_distance<const N: usize>(a: &Units<N>, b: &Units<N>, inverse_cols: &[f64; N]) -> f64 {
    let mut sum = 0.0;
    for j in 0..N {
        let (dx, dy) = (
            (a[j][0] - b[j][0]) * inverse_cols[j],
            (a[j][1] - b[j][1]) * inverse_cols[j],
        );
        sum += dx * dx + dy * dy;
    }
    sum
}

/// The exact rule: of the two `candidates` (coordinates, angles already moved to the
/// guess's turn), the one the guess takes.
#[inline]
fn nearest_of<const N: usize>(
    guess: &[f64; N],
    [first, second]: &[[f64; N]; 2],
    inverse_cols: &[f64; N],
) -> Option<usize> {
    let (to_first, to_second, apart) = (
        squared_distance(guess, first, inverse_cols),
        squared_distance(guess, second, inverse_cols),
        squared_distance(first, second, inverse_cols),
    );
    let (nearest, near, far) = if to_first <= to_second {
        (0, to_first, to_second)
    } else {
        (1, to_second, to_first)
    };
    // Only a guess well inside the nearest solution's neighbourhood takes it, and only away
    // from a toggle: where the solutions merge, Newton's own choice from the guess stands, as
    // do its crossing reports. One solution listed twice is always taken. NaN (a loop that
    // cannot close) fails every comparison.
    let unique = apart == 0.0 && near.is_finite();
    let clear = far.is_finite()
        && apart >= SEPARATION * SEPARATION
        && near <= CLEAR_FRACTION * CLEAR_FRACTION * apart;
    (unique || clear).then_some(nearest)
}

/// Moves the angle `value` by whole turns to the turn of `guess`.
#[inline]
fn to_turn(value: &mut f64, guess: f64) {
    // atan2 answers within a turn and a half of 0: most guesses need no rounding.
    if (guess - *value).abs() > PI {
        *value += TAU * libm::round((guess - *value) / TAU);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (xorshift), so the sample is the same on every run.
    struct Sample(u64);

    impl Sample {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1_u64 << 53) as f64
        }

        fn between(&mut self, low: f64, high: f64) -> f64 {
            low + (high - low) * self.next()
        }
    }

    /// The rule as the sweep applied it before the one-`atan2` test: both angles, then the
    /// exact comparison.
    fn reference(
        guess: &[f64; 2],
        candidates: &[Units<2>; 2],
        angles: &[bool; 2],
        scales: &[f64; 2],
    ) -> Option<(usize, [f64; 2])> {
        let both = [0, 1].map(|k| coordinates(&candidates[k], angles, guess));
        nearest_of(guess, &both, scales).map(|k| (k, both[k]))
    }

    /// A candidate's entries from its coordinates.
    fn units(values: [f64; 2], angles: &[bool; 2]) -> Units<2> {
        let mut units = [[0.0; 2]; 2];
        for ((unit, value), &angle) in units.iter_mut().zip(values).zip(angles) {
            *unit = if angle {
                [value.cos(), value.sin()]
            } else {
                [value, 0.0]
            };
        }
        units
    }

    #[test]
    fn trying_either_candidate_first_decides_as_the_exact_rule() {
        let mut sample = Sample(0x9E37_79B9_7F4A_7C15);
        let (mut chosen, mut declined) = (0, 0);
        for case in 0..20_000 {
            // A length and an angle (the seed's rod), or two angles (a four-bar's dyad).
            let angles = [case % 3 == 0, true];
            let scales = [
                if angles[0] {
                    1.0
                } else {
                    sample.between(0.01, 10.0)
                },
                1.0,
            ];
            let first = [sample.between(-5.0, 5.0), sample.between(-PI, PI)];
            // The second solution from far away down to merging with the first (a toggle).
            let spread = 10_f64.powf(sample.between(-5.0, 0.5));
            let second = first.map(|x| x + spread * sample.between(-3.0, 3.0));
            let candidates = [units(first, &angles), units(second, &angles)];
            // Guesses around the first, a turn or two away, out to beyond the rule's threshold.
            let mut guess = first.map(|x| x + spread * sample.between(-1.0, 1.0));
            guess[1] += TAU * sample.between(-2.0, 2.0).round();
            let expected = reference(&guess, &candidates, &angles, &scales);
            for tried in [0, 1] {
                let got = nearest(&guess, &candidates, &angles, &scales, tried);
                assert_eq!(got, expected, "case {case}, trying {tried} first");
            }
            match expected {
                Some(_) => chosen += 1,
                None => declined += 1,
            }
        }
        // Both outcomes were exercised.
        assert!(
            chosen > 1000 && declined > 1000,
            "{chosen} chosen, {declined} declined"
        );
    }

    #[test]
    fn a_loop_that_cannot_close_is_declined_whichever_is_tried_first() {
        let nan = [[f64::NAN; 2]; 2];
        for tried in [0, 1] {
            let got = nearest(&[0.1, 0.2], &[nan, nan], &[false, true], &[1.0, 1.0], tried);
            assert_eq!(got, None);
        }
    }
}
