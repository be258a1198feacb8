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
    let mut candidates = [[f64::NAN; N]; 2];
    bs.m.closed_form(bs.stage, q, parts.trig, t, candidates.as_flattened_mut());
    let coordinates = bs.block.coordinates;
    let (mut guess, mut angles, mut scales) = ([0.0; N], [false; N], [0.0; N]);
    for (j, &c) in coordinates.iter().enumerate().take(N) {
        (guess[j], angles[j]) = (q[c], bs.m.coordinate_unit(c) == Unit::Angle);
    }
    for (s, &c) in scales.iter_mut().zip(&*parts.scales.inverse_cols) {
        *s = c;
    }
    let Some(nearest) = nearest(&guess, &mut candidates, &angles, &scales) else {
        return false;
    };
    for (&value, &c) in candidates[nearest].iter().zip(coordinates) {
        q[c] = value;
    }
    true
}

/// The rule of [`start`], shared with the straight step (its `choose`): of the two
/// `candidates` of a block at `guess`, the one (0 or 1) the guess takes, after moving each
/// candidate angle (`angles[j]`) by whole turns to the guess's; `None` near a toggle, away
/// from both solutions, or where the loop cannot close (NaN). `inverse_cols` scales each
/// coordinate to scene lengths and radians.
#[inline]
pub(crate) fn nearest<const N: usize>(
    guess: &[f64; N],
    candidates: &mut [[f64; N]; 2],
    angles: &[bool; N],
    inverse_cols: &[f64; N],
) -> Option<usize> {
    // Per coordinate: each candidate moved to the guess's turn; then the squared scaled
    // distances from the guess to each candidate and between them.
    let (mut to_first, mut to_second, mut apart) = (0.0, 0.0, 0.0);
    for j in 0..N {
        let (guess, scale) = (guess[j], inverse_cols[j]);
        if angles[j] {
            to_turn(&mut candidates[0][j], guess);
            to_turn(&mut candidates[1][j], guess);
        }
        let (first, second) = (candidates[0][j], candidates[1][j]);
        let [d1, d2, d12] = [first - guess, second - guess, first - second].map(|d| d * scale);
        (to_first, to_second, apart) = (to_first + d1 * d1, to_second + d2 * d2, apart + d12 * d12);
    }
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
