//! Micro-timing for the report: the cost of one call of the pieces a step is made of (a block's
//! evaluation, its factorisation, a triangular solve, the rate kernels; for a dense method Φ
//! and Φ_q, the dense LU, ν and γ), measured in batches, and the split of a step's time among
//! them.
//!
//! Batches rather than a clock read per call: `Instant::now` costs ~20 ns, as much as a
//! generated Φ. Each figure is the best of a few batches (the least disturbed by the rest of
//! the machine), like criterion's lower estimates rather than its means.

use std::hint::black_box;
use std::time::{Duration, Instant};

use mechgen_runtime::codegen::{Block, Stage};
use mechgen_runtime::nalgebra::{DefaultAllocator, U1};
use mechgen_runtime::{Accelerations, Lu, Matrix, Storage, Structured, Vector};

use super::sweep::Work;

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
    /// Φ and Φ_q together through the textbook function (`phi_and_jacobian`), as the criterion
    /// benchmarks time it.
    pub phi_and_jacobian: f64,
    /// One evaluation as the solver makes it: one block's Φ_b and Jacobian values (averaged
    /// over the scene's blocks, explicit assignments included); for a dense method, Φ and Φ_q.
    pub evaluation: f64,
    /// One factorisation of a block's Jacobian (averaged over the blocks; for a dense method,
    /// copying its Φ_q into the LU's storage and factoring it, minus the copy alone).
    pub factorisation: f64,
    /// One forward/back substitution with a block's factors (averaged over the blocks).
    pub solve: f64,
    /// The rate kernels of one step: ν and γ for a dense method; every stage's velocity and
    /// acceleration kernels for a structured one.
    pub rates: f64,
    /// Newton blocks of the method's solve.
    pub blocks: usize,
}

impl Micro {
    /// The faster of two measurements, piece by piece.
    pub fn fastest(&self, other: &Micro) -> Micro {
        Micro {
            phi_and_jacobian: self.phi_and_jacobian.min(other.phi_and_jacobian),
            evaluation: self.evaluation.min(other.evaluation),
            factorisation: self.factorisation.min(other.factorisation),
            solve: self.solve.min(other.solve),
            rates: self.rates.min(other.rates),
            blocks: self.blocks,
        }
    }
}

/// Times the pieces of a step for `mechanism` at the solved state (`q`, `qd`) at time `t`.
pub fn measure<M: Structured + Accelerations>(
    mechanism: &M,
    q: &Vector<M::Dim>,
    qd: &Vector<M::Dim>,
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
    let phi_and_jacobian = seconds_per_call(batch, batches, || {
        mechanism.phi_and_jacobian(black_box(q), black_box(t), &mut phi, &mut jacobian);
        black_box(&jacobian);
    });
    let blocks: Vec<(usize, Block<'_>)> = (0..mechanism.stage_count())
        .filter_map(|s| match mechanism.stage(s)? {
            Stage::Block(block) => Some((s, block)),
            Stage::Explicit { .. } => None,
        })
        .collect();
    let pieces = if blocks.iter().all(|(_, b)| !b.pivots.is_empty()) {
        structured(mechanism, &blocks, q, qd, t, batch, batches)
    } else {
        dense(mechanism, &jacobian, q, t, batch, batches)
    };
    Micro {
        phi_and_jacobian,
        blocks: blocks.len().max(1),
        ..pieces
    }
}

/// The pieces of a scene solved through its structure: every block's kernels at the solved
/// state, summed, then averaged per block.
fn structured<M: Structured + Accelerations>(
    m: &M,
    blocks: &[(usize, Block<'_>)],
    q: &Vector<M::Dim>,
    qd: &Vector<M::Dim>,
    t: f64,
    batch: Duration,
    batches: usize,
) -> Micro
where
    DefaultAllocator: Storage<M::Dim>,
{
    let stages = m.stage_count();
    // Each cached angle takes two slots: twice the coordinates is always enough.
    let mut trig = vec![0.0; 2 * q.len()];
    for s in 0..stages {
        m.fill_trig(s, q, &mut trig);
    }
    let slots = blocks.iter().map(|(_, b)| b.slots).max().unwrap_or(0);
    let size = blocks.iter().map(|(_, b)| b.len()).max().unwrap_or(0);
    let (mut values, mut phi) = (vec![0.0; slots], vec![0.0; size]);
    let mut q_assigned = q.clone();
    let evaluation = seconds_per_call(batch, batches, || {
        for s in 0..stages {
            m.assign_positions(s, &mut q_assigned, &trig, t);
        }
        for &(s, b) in blocks {
            m.block_jacobian(s, black_box(q), &trig, t, &mut phi[..b.len()], &mut values);
        }
        black_box((&q_assigned, &values));
    });
    // Every block's Jacobian values, kept, and the factors of each (a block that fails its
    // static pivots here is factored as far as it goes: the figure is then small, not wrong
    // by a panic).
    let jacobians: Vec<Vec<f64>> = blocks
        .iter()
        .map(|&(s, b)| {
            m.block_jacobian(s, q, &trig, t, &mut phi[..b.len()], &mut values);
            values[..b.slots].to_vec()
        })
        .collect();
    let mut factors = jacobians.clone();
    let copy_and_factor = |factors: &mut [Vec<f64>]| {
        for (&(s, b), (f, j)) in blocks.iter().zip(factors.iter_mut().zip(&jacobians)) {
            f.copy_from_slice(j);
            let _ = black_box(m.factor(s, &mut f[..b.slots], 0.0, f64::INFINITY));
        }
    };
    let copy_and_factorisation = seconds_per_call(batch, batches, || copy_and_factor(&mut factors));
    let copy = seconds_per_call(batch, batches, || {
        for (f, j) in factors.iter_mut().zip(&jacobians) {
            f.copy_from_slice(black_box(j));
        }
        black_box(&factors);
    });
    copy_and_factor(&mut factors);
    let mut x = vec![1.0; size];
    let solve = seconds_per_call(batch, batches, || {
        for (&(s, b), f) in blocks.iter().zip(&factors) {
            x.fill(1.0);
            m.solve(s, f, &mut x[..b.len()]);
        }
        black_box(&x);
    });
    let (mut qd_assigned, mut qdd) = (qd.clone(), qd.clone());
    let rates = seconds_per_call(batch, batches, || {
        for s in 0..stages {
            m.assign_velocities(s, q, &trig, &mut qd_assigned, t);
            m.assign_accelerations(s, q, &trig, qd, &mut qdd, t);
        }
        for &(s, b) in blocks {
            m.velocity_rhs(s, q, &trig, qd, t, &mut phi[..b.len()]);
            m.acceleration_rhs(s, q, &trig, qd, &qdd, t, &mut phi[..b.len()]);
        }
        black_box((&qd_assigned, &qdd, &phi));
    });
    let per_block = 1.0 / blocks.len().max(1) as f64;
    Micro {
        phi_and_jacobian: 0.0,
        evaluation: evaluation * per_block,
        factorisation: (copy_and_factorisation - copy).max(0.0) * per_block,
        solve: solve * per_block,
        rates,
        blocks: blocks.len(),
    }
}

/// The pieces of a dense solve: Φ and Φ_q from the textbook function, factored and solved
/// with partial pivoting.
fn dense<M: Accelerations>(
    mechanism: &M,
    jacobian: &Matrix<M::Dim>,
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
    let mut scratch = jacobian.clone();
    let evaluation = seconds_per_call(batch, batches, || {
        mechanism.phi_and_jacobian(black_box(q), black_box(t), &mut phi, &mut scratch);
        black_box(&scratch);
    });

    // Factor this method's own Φ_q (its zeros, which the LU skips, are this method's), copied
    // into the LU's storage each time; the copy is timed alone and taken off. (Subtracting the
    // evaluation from evaluation + factorisation instead would bury the factorisation in the
    // noise of slow evaluations.)
    let mut lu = Lu::new(dim);
    let copy_and_factorisation = seconds_per_call(batch, batches, || {
        let factored = lu.factor_with(|storage| storage.copy_from(black_box(jacobian)));
        let _ = black_box(factored);
    });
    let matrix_copy = seconds_per_call(batch, batches, || {
        scratch.copy_from(black_box(jacobian));
        black_box(&scratch);
    });
    // Leave `lu` holding the factors at q for the solves below (a failure leaves it unfactored
    // and the solves then return at once: the figures are small, not wrong by a panic).
    let _ = lu.factor(jacobian);

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
        evaluation,
        factorisation: (copy_and_factorisation - matrix_copy).max(0.0),
        solve: (solve - copy).max(0.0),
        rates,
        blocks: 1,
    }
}

/// Where a step's time goes, seconds per step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Split {
    /// The step's block evaluations.
    pub evaluation: f64,
    /// As many factorisations.
    pub factorisation: f64,
    /// Substitutions: about one per evaluation (Newton updates), and two per block (q̇, q̈).
    pub solves: f64,
    /// One pass of the rate kernels.
    pub rates: f64,
    /// The measured step time minus the above: predictor, norms, condition estimate, checks,
    /// copies (negative when the isolated figures overestimate the pieces in the loop).
    pub rest: f64,
}

impl Split {
    /// Splits a measured step of `seconds_per_step` that did `work` on average, following what
    /// `Solver::solve_into` does: each evaluation of a block is factored, each Newton update
    /// solves once, and each block's velocities and accelerations are one solve each with the
    /// factors it ends with.
    pub fn of_step(micro: &Micro, work: Work, seconds_per_step: f64) -> Self {
        let evaluation = work.evaluations * micro.evaluation;
        let factorisation = work.evaluations * micro.factorisation;
        let solves = (work.evaluations + 2.0 * micro.blocks as f64) * micro.solve;
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
            evaluation: 1.0,
            factorisation: 2.0,
            solve: 0.5,
            rates: 0.25,
            blocks: 1,
        };
        let work = Work {
            iterations: 2.0,
            evaluations: 2.0,
        };
        let split = Split::of_step(&micro, work, 20.0);
        assert_eq!(split.evaluation, 2.0);
        assert_eq!(split.factorisation, 4.0);
        assert_eq!(split.solves, 2.0);
        assert_eq!(split.rates, 0.25);
        assert_eq!(split.rest, 20.0 - 8.25);
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
