//! Where a NaN began. A block that finds its Φ, Jacobian or right-hand side non-finite may only
//! be reading a non-finite value assigned in closed form upstream (a driver's `sqrt` of a
//! negative number feeds every loop after it), and an explicit stage's own value is only
//! checked at the end of the sweep. So a `NonFinite` error from a sweep is traced back to the
//! first explicit stage, in solve order, whose assigned value is not finite, and names its
//! equation: the joint or driver whose expression failed. Only the failure path pays for this.

use nalgebra::DefaultAllocator;

use crate::error::{Quantity, SolveError};
use crate::mechanism::{Storage, Vector};
use crate::names::Names;
use crate::options::Rates;
use crate::structure::{Stage, Structured};

/// `error`, re-attributed to the first explicit stage before `reached` (the stage being solved
/// when it occurred) whose assigned position, or velocity or acceleration when `rates` asks for
/// them, is not finite. Other errors, and non-finite values no assignment explains, are
/// returned unchanged.
pub(crate) fn trace<M: Structured>(
    m: &M,
    reached: usize,
    [q, qd, qdd]: [&Vector<M::Dim>; 3],
    rates: Rates,
    error: SolveError,
) -> SolveError
where
    DefaultAllocator: Storage<M::Dim>,
{
    let SolveError::NonFinite { time, .. } = error else {
        return error;
    };
    let vectors = [
        (Some(q), Quantity::Phi),
        ((rates != Rates::None).then_some(qd), Quantity::Velocity),
        (
            (rates >= Rates::Both).then_some(qdd),
            Quantity::Acceleration,
        ),
    ];
    for stage in 0..reached.min(m.stage_count()) {
        let Some(Stage::Explicit {
            equations,
            coordinates,
            ..
        }) = m.stage(stage)
        else {
            continue;
        };
        for (vector, quantity) in vectors {
            let Some(v) = vector else { continue };
            let bad = coordinates
                .iter()
                .position(|&j| v.get(j).is_some_and(|x| !x.is_finite()));
            if let Some(k) = bad {
                return SolveError::NonFinite {
                    time,
                    quantity,
                    equation: equations.get(k).copied(),
                    names: &Names::NONE,
                };
            }
        }
    }
    error
}
