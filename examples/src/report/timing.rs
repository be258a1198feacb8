//! Micro-timing for the report: the cost of one call of the pieces a step is made of (Φ and Φ_q,
//! factorisation, a triangular solve, ν and γ), measured in batches, and the split of a step's
//! time among them.
//!
//! Batches rather than a clock read per call: `Instant::now` costs ~20 ns, as much as a
//! generated Φ. Each figure is the best of a few batches (the least disturbed by the rest of
//! the machine), like criterion's lower estimates rather than its means.

use std::hint::black_box;
use std::time::{Duration, Instant};

use mechgen_runtime::nalgebra::{DefaultAllocator, U1};
use mechgen_runtime::{Accelerations, Lu, Matrix, Storage, Vector};

/// Seconds per call of `f`: calibrates a batch size lasting about `batch`, then keeps the best
/// of `batches` batches.
pub fn seconds_per_call(batch: Duration, batches: usize, mut f: impl FnMut()) -> f64 {
    // Calibrate: double the count until one batch takes long enough to dwarf the clock reads.
    let mut count: u64 = 1;
    loop {
        let start = Instant::now();
        for _ in 0..count {
            f();
        }
        let elapsed = start.elapsed();
        if elapsed >= batch / 4 || count >= 1 << 30 {
            // Scale to the requested batch length from this measurement.
            let per_call = elapsed.as_secs_f64() / count as f64;
            if per_call > 0.0 {
                let wanted = (batch.as_secs_f64() / per_call).ceil();
                count = if wanted.is_finite() {
                    (wanted as u64).clamp(1, 1 << 32)
                } else {
                    count
                };
            }
            break;
        }
        count *= 2;
    }
    let mut best = f64::INFINITY;
    for _ in 0..batches.max(1) {
        let start = Instant::now();
        for _ in 0..count {
            f();
        }
        best = best.min(start.elapsed().as_secs_f64() / count as f64);
    }
    best
}

/// Cost of one call of each piece of a step, seconds.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Micro {
    /// Φ and Φ_q together (`phi_and_jacobian`, what each Newton iteration evaluates).
    pub phi_and_jacobian: f64,
    /// One LU factorisation of this method's Φ_q (copy into the LU's storage and factor, minus
    /// the copy alone).
    pub factorisation: f64,
    /// One forward/back substitution with the factors.
    pub solve: f64,
    /// ν and γ, one evaluation each.
    pub rates: f64,
}

impl Micro {
    /// The faster of two measurements, piece by piece.
    pub fn fastest(&self, other: &Micro) -> Micro {
        Micro {
            phi_and_jacobian: self.phi_and_jacobian.min(other.phi_and_jacobian),
            factorisation: self.factorisation.min(other.factorisation),
            solve: self.solve.min(other.solve),
            rates: self.rates.min(other.rates),
        }
    }
}

/// Times the pieces of a step for `mechanism` at the solved positions `q` at time `t`.
pub fn measure<M: Accelerations>(
    mechanism: &M,
    q: &Vector<M::Dim>,
    t: f64,
    batch: Duration,
    batches: usize,
) -> Micro
where
    DefaultAllocator: Storage<M::Dim>,
{
    let dim = mechanism.dim();
    let mut phi = Vector::zeros_generic(dim, U1);
    let mut jacobian = Matrix::zeros_generic(dim, dim);
    let evaluation = seconds_per_call(batch, batches, || {
        mechanism.phi_and_jacobian(black_box(q), black_box(t), &mut phi, &mut jacobian);
        black_box(&jacobian);
    });

    // Factor this method's own Φ_q (its zeros, which the LU skips, are this method's), copied
    // into the LU's storage each time; the copy is timed alone and taken off. (Subtracting the
    // evaluation from evaluation + factorisation instead would bury the factorisation in the
    // noise of slow evaluations.)
    let mut lu = Lu::new(dim);
    let copy_and_factorisation = seconds_per_call(batch, batches, || {
        let factored = lu.factor_with(|storage| storage.copy_from(black_box(&jacobian)));
        let _ = black_box(factored);
    });
    let mut scratch = jacobian.clone();
    let matrix_copy = seconds_per_call(batch, batches, || {
        scratch.copy_from(black_box(&jacobian));
        black_box(&scratch);
    });
    // Leave `lu` holding the factors at q for the solves below (a failure leaves it unfactored
    // and the solves then return at once: the figures are small, not wrong by a panic).
    let _ = lu.factor(&jacobian);

    let mut rhs = Vector::zeros_generic(dim, U1);
    rhs.fill(1.0);
    let mut x = rhs.clone();
    let solve = seconds_per_call(batch, batches, || {
        // Restore the right-hand side each time so repeated solves cannot drift to overflow.
        x.copy_from(&rhs);
        let _ = black_box(lu.solve_in_place(&mut x));
    });
    let copy = seconds_per_call(batch, batches, || {
        x.copy_from(black_box(&rhs));
        black_box(&x);
    });

    // ν at q, then γ at (q, q̇) with the q̇ those factors give: the inputs a step uses.
    let (mut nu, mut gamma) = (
        Vector::zeros_generic(dim, U1),
        Vector::zeros_generic(dim, U1),
    );
    mechanism.nu(q, t, &mut nu);
    let mut qd = nu.clone();
    let _ = lu.solve_in_place(&mut qd);
    let rates = seconds_per_call(batch, batches, || {
        mechanism.nu(black_box(q), black_box(t), &mut nu);
        mechanism.gamma(black_box(q), black_box(&qd), black_box(t), &mut gamma);
        black_box((&nu, &gamma));
    });

    Micro {
        phi_and_jacobian: evaluation,
        factorisation: (copy_and_factorisation - matrix_copy).max(0.0),
        solve: (solve - copy).max(0.0),
        rates,
    }
}

/// Where a step's time goes, seconds per step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Split {
    /// (iterations + 1) evaluations of Φ and Φ_q.
    pub evaluation: f64,
    /// (iterations + 1) factorisations.
    pub factorisation: f64,
    /// (iterations + 2) substitutions: one per Newton update, one each for q̇ and q̈.
    pub solves: f64,
    /// One evaluation each of ν and γ.
    pub rates: f64,
    /// The measured step time minus the above: predictor, norms, checks, copies (negative
    /// when the isolated figures overestimate the pieces in the loop).
    pub rest: f64,
}

impl Split {
    /// Splits a measured step of `seconds_per_step` with `iterations` Newton updates on average,
    /// following what `Solver::solve_into` does: each update evaluates and factors Φ_q and
    /// solves once; convergence is confirmed by one more evaluation and factorisation at the
    /// returned positions, whose factors then serve the velocity and acceleration solves.
    pub fn of_step(micro: &Micro, iterations: f64, seconds_per_step: f64) -> Self {
        let evaluation = (iterations + 1.0) * micro.phi_and_jacobian;
        let factorisation = (iterations + 1.0) * micro.factorisation;
        let solves = (iterations + 2.0) * micro.solve;
        let rates = micro.rates;
        Split {
            evaluation,
            factorisation,
            solves,
            rates,
            rest: seconds_per_step - evaluation - factorisation - solves - rates,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_follows_the_step_structure() {
        let micro = Micro {
            phi_and_jacobian: 1.0,
            factorisation: 2.0,
            solve: 0.5,
            rates: 0.25,
        };
        let split = Split::of_step(&micro, 2.0, 20.0);
        assert_eq!(split.evaluation, 3.0);
        assert_eq!(split.factorisation, 6.0);
        assert_eq!(split.solves, 2.0);
        assert_eq!(split.rates, 0.25);
        assert_eq!(split.rest, 20.0 - 11.25);
    }

    #[test]
    fn batch_timing_is_positive_and_finite() {
        let mut x = 0u64;
        let s = seconds_per_call(Duration::from_micros(200), 2, || {
            x = black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
        });
        assert!(s.is_finite() && s > 0.0 && s < 1e-3, "{s}");
    }
}
