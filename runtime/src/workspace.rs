//! The solver's scratch storage, sized by the scene: vectors of the largest block's size, the
//! largest block's factor values, two dense matrices of the largest block's size (the partial
//! pivoting fallback and Levenberg–Marquardt), a word per stage, the trig cache, one index per
//! coordinate for a diagnosis, and, for a scene that computes forces, the force solve's
//! multipliers and the archive of its blocks' factors (see `forces.rs`).
//!
//! Nothing here grows with the square of the scene: the 1000-stage scissor lift (6,012
//! coordinates, largest block 6) needs 90 kB, where one dense Jacobian would need 289 MB.

/// Storage the solver borrows for one solve. Implemented by [`Buffers`] (inline arrays, for
/// generated scenes), [`crate::codegen::DenseBuffers`] (the dense reference) and, with the `alloc`
/// feature, `VecBuffers` (the interpreter); the solver is its only user.
pub trait Workspace {
    /// Every buffer at once, as disjoint slices.
    fn parts(&mut self) -> Parts<'_>;

    /// The diagnosis of the last [`crate::SolveError::Singular`]: the row order buffer, whose
    /// head the solver fills with the dependent equations, and the undetermined coordinates'
    /// buffer.
    fn diagnosis(&self) -> (&[usize], &[usize]);

    /// What the straight step borrows (the trig cache and the force storage of [`Parts`]),
    /// without building the rest.
    fn step_parts(&mut self) -> StepParts<'_> {
        let parts = self.parts();
        StepParts {
            trig: parts.trig,
            forces: parts.forces,
            archived: parts.archived,
        }
    }
}

/// The buffers the straight step borrows: the trig cache, and, for a scene that computes
/// forces, the force solve's storage and which blocks' factors it holds.
pub struct StepParts<'a> {
    pub(crate) trig: &'a mut [f64],
    pub(crate) forces: &'a mut [f64],
    pub(crate) archived: &'a mut [bool],
}

/// The buffers of a [`Workspace`], each at least as long as the scene's largest block needs
/// (B its size, S its factor values, K the number of stages), grouped so that the solver can
/// borrow the groups separately.
pub struct Parts<'a> {
    pub(crate) newton: NewtonVectors<'a>,
    pub(crate) scales: Scales<'a>,
    pub(crate) factors: FactorStorage<'a>,
    pub(crate) estimator: Estimator<'a>,
    /// Scaled dense Jacobian for Levenberg–Marquardt and the rank reveal (B²).
    pub(crate) dense: &'a mut [f64],
    /// Row and column orders of the rank reveal; after a diagnosis, global indices (B each).
    pub(crate) row_order: &'a mut [usize],
    pub(crate) col_order: &'a mut [usize],
    /// Per stage: the condition estimator's warm-start column (K).
    pub(crate) hints: &'a mut [usize],
    /// After a diagnosis: every undetermined coordinate (at most the scene's n), and per
    /// stage whether it is downstream of the singular one (K).
    pub(crate) undetermined: &'a mut [usize],
    pub(crate) downstream: &'a mut [bool],
    /// The trig cache ([`crate::Structured::fill_trig`]).
    pub(crate) trig: &'a mut [f64],
    /// The force solve's storage (empty unless the scene computes forces): one multiplier per
    /// equation, then the static factors of the blocks the forward sweep archived.
    pub(crate) forces: &'a mut [f64],
    /// Per stage: whether its block's static factors are in the archive (K).
    pub(crate) archived: &'a mut [bool],
}

/// The Newton iteration's vectors (B each).
pub(crate) struct NewtonVectors<'a> {
    /// Block residual Φ_b.
    pub phi: &'a mut [f64],
    /// Newton or Levenberg–Marquardt step.
    pub step: &'a mut [f64],
    /// The block's coordinates where the last step started.
    pub base: &'a mut [f64],
    /// Residual at a trial point; right-hand sides of derivative solves.
    pub trial: &'a mut [f64],
    /// Levenberg–Marquardt gradient.
    pub gradient: &'a mut [f64],
}

/// Unit scales of a block's equations (D_r) and coordinates (D_c, and D_c⁻¹ so that measuring
/// a step in scene units needs no division) (B each).
pub(crate) struct Scales<'a> {
    pub rows: &'a mut [f64],
    pub cols: &'a mut [f64],
    pub inverse_cols: &'a mut [f64],
    /// Whose scales these are: see [`ScalesOf`].
    pub of: &'a mut ScalesOf,
}

/// The block (stage index) and the length scale whose unit scales [`Scales`] hold, if any:
/// `BlockSolve::set_scales`, their only writer, skips rewriting the same ones, so a scene
/// with one block computes them once per length scale rather than on every solve.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct ScalesOf(pub Option<(usize, f64)>);

/// A block's factors: its Jacobian values and static factors (S), dense partial-pivoting
/// factors (B²) and their row swaps (B).
pub(crate) struct FactorStorage<'a> {
    pub values: &'a mut [f64],
    pub lu: &'a mut [f64],
    pub swaps: &'a mut [usize],
}

/// The condition estimator's scratch (B each).
pub(crate) struct Estimator<'a> {
    pub x: &'a mut [f64],
    pub signs: &'a mut [f64],
}

impl<'a> Parts<'a> {
    /// Groups the buffers.
    pub(crate) fn new(
        [
            phi,
            step,
            base,
            trial,
            gradient,
            rows,
            cols,
            inverse_cols,
            x,
            signs,
        ]: [&'a mut [f64]; 10],
        [swaps, row_order, col_order]: [&'a mut [usize]; 3],
        values: &'a mut [f64],
        [lu, dense]: [&'a mut [f64]; 2],
        (hints, undetermined, downstream): (&'a mut [usize], &'a mut [usize], &'a mut [bool]),
        (trig, scales_of): (&'a mut [f64], &'a mut ScalesOf),
        (forces, archived): (&'a mut [f64], &'a mut [bool]),
    ) -> Self {
        Parts {
            newton: NewtonVectors {
                phi,
                step,
                base,
                trial,
                gradient,
            },
            scales: Scales {
                rows,
                cols,
                inverse_cols,
                of: scales_of,
            },
            factors: FactorStorage { values, lu, swaps },
            estimator: Estimator { x, signs },
            dense,
            row_order,
            col_order,
            hints,
            undetermined,
            downstream,
            trig,
            forces,
            archived,
        }
    }
}

/// Inline storage for a scene of `N` coordinates whose largest block has `B` coordinates and
/// `S` factor values, solved in `K` stages with `T` cached sines and cosines, and `R` values
/// for the force solve (0 unless the scene computes forces: `N` multipliers, then the static
/// factor values of every block): what generated code names as its
/// [`crate::Structured::Workspace`].
#[derive(Debug, Clone)]
pub struct Buffers<
    const B: usize,
    const S: usize,
    const K: usize,
    const N: usize,
    const T: usize,
    const R: usize = 0,
> {
    vectors: [[f64; B]; 10],
    indices: [[usize; B]; 3],
    values: [f64; S],
    matrices: [[[f64; B]; B]; 2],
    hints: [usize; K],
    undetermined: [usize; N],
    downstream: [bool; K],
    trig: [f64; T],
    scales_of: ScalesOf,
    forces: [f64; R],
    archived: [bool; K],
}

impl<const B: usize, const S: usize, const K: usize, const N: usize, const T: usize, const R: usize>
    Buffers<B, S, K, N, T, R>
{
    /// Zeroed buffers.
    pub const fn new() -> Self {
        Self {
            vectors: [[0.0; B]; 10],
            indices: [[0; B]; 3],
            values: [0.0; S],
            matrices: [[[0.0; B]; B]; 2],
            hints: [usize::MAX; K],
            undetermined: [0; N],
            downstream: [false; K],
            trig: [0.0; T],
            scales_of: ScalesOf(None),
            forces: [0.0; R],
            archived: [false; K],
        }
    }
}

impl<const B: usize, const S: usize, const K: usize, const N: usize, const T: usize, const R: usize>
    Default for Buffers<B, S, K, N, T, R>
{
    fn default() -> Self {
        Self::new()
    }
}

impl<const B: usize, const S: usize, const K: usize, const N: usize, const T: usize, const R: usize>
    Workspace for Buffers<B, S, K, N, T, R>
{
    fn parts(&mut self) -> Parts<'_> {
        let [lu, dense] = &mut self.matrices;
        // Spelled out rather than `each_mut().map(..)`: the compiler does not always inline
        // an array map, and this runs on every solve.
        let [v0, v1, v2, v3, v4, v5, v6, v7, v8, v9] = &mut self.vectors;
        let [i0, i1, i2] = &mut self.indices;
        Parts::new(
            [v0, v1, v2, v3, v4, v5, v6, v7, v8, v9],
            [i0, i1, i2],
            &mut self.values,
            [lu.as_flattened_mut(), dense.as_flattened_mut()],
            (
                &mut self.hints,
                &mut self.undetermined,
                &mut self.downstream,
            ),
            (&mut self.trig, &mut self.scales_of),
            (&mut self.forces, &mut self.archived),
        )
    }

    fn diagnosis(&self) -> (&[usize], &[usize]) {
        (&self.indices[1], &self.undetermined)
    }

    fn step_parts(&mut self) -> StepParts<'_> {
        StepParts {
            trig: &mut self.trig,
            forces: &mut self.forces,
            archived: &mut self.archived,
        }
    }
}

/// Heap storage for scenes whose sizes are known only at run time (the interpreter).
#[cfg(feature = "alloc")]
#[derive(Debug, Clone)]
pub struct VecBuffers {
    vectors: [alloc::vec::Vec<f64>; 10],
    indices: [alloc::vec::Vec<usize>; 3],
    values: alloc::vec::Vec<f64>,
    matrices: [alloc::vec::Vec<f64>; 2],
    hints: alloc::vec::Vec<usize>,
    undetermined: alloc::vec::Vec<usize>,
    downstream: alloc::vec::Vec<bool>,
    trig: alloc::vec::Vec<f64>,
    scales_of: ScalesOf,
    forces: alloc::vec::Vec<f64>,
    archived: alloc::vec::Vec<bool>,
}

#[cfg(feature = "alloc")]
impl VecBuffers {
    /// Buffers for a scene of `n` coordinates whose blocks have up to `block` coordinates and
    /// `slots` factor values, in `stages` stages, with `trig` cached sines and cosines and
    /// `forces` values for the force solve (0 unless the scene computes forces).
    pub fn new(
        block: usize,
        slots: usize,
        stages: usize,
        n: usize,
        trig: usize,
        forces: usize,
    ) -> Self {
        use alloc::vec;
        Self {
            vectors: core::array::from_fn(|_| vec![0.0; block]),
            indices: core::array::from_fn(|_| vec![0; block]),
            values: vec![0.0; slots],
            matrices: core::array::from_fn(|_| vec![0.0; block * block]),
            hints: vec![usize::MAX; stages],
            undetermined: vec![0; n],
            downstream: vec![false; stages],
            trig: vec![0.0; trig],
            scales_of: ScalesOf(None),
            forces: vec![0.0; forces],
            archived: vec![false; stages],
        }
    }
}

#[cfg(feature = "alloc")]
impl Workspace for VecBuffers {
    fn parts(&mut self) -> Parts<'_> {
        Parts::new(
            self.vectors.each_mut().map(|v| &mut v[..]),
            self.indices.each_mut().map(|v| &mut v[..]),
            &mut self.values,
            self.matrices.each_mut().map(|v| &mut v[..]),
            (
                &mut self.hints,
                &mut self.undetermined,
                &mut self.downstream,
            ),
            (&mut self.trig, &mut self.scales_of),
            (&mut self.forces, &mut self.archived),
        )
    }

    fn diagnosis(&self) -> (&[usize], &[usize]) {
        (&self.indices[1], &self.undetermined)
    }

    fn step_parts(&mut self) -> StepParts<'_> {
        StepParts {
            trig: &mut self.trig,
            forces: &mut self.forces,
            archived: &mut self.archived,
        }
    }
}

#[cfg(test)]
impl Parts<'_> {
    /// The length of every part, in declaration order (the Newton vectors, the scales, the
    /// factor storage, the estimator, then the rest).
    pub(crate) fn lengths(&self) -> [usize; 22] {
        let (n, s, f, e) = (&self.newton, &self.scales, &self.factors, &self.estimator);
        [
            n.phi.len(),
            n.step.len(),
            n.base.len(),
            n.trial.len(),
            n.gradient.len(),
            s.rows.len(),
            s.cols.len(),
            s.inverse_cols.len(),
            f.values.len(),
            f.lu.len(),
            f.swaps.len(),
            e.x.len(),
            e.signs.len(),
            self.dense.len(),
            self.row_order.len(),
            self.col_order.len(),
            self.hints.len(),
            self.undetermined.len(),
            self.downstream.len(),
            self.trig.len(),
            self.forces.len(),
            self.archived.len(),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Block size 3, 7 factor values, 4 stages, 9 coordinates, 5 trig slots, 11 force values.
    type Small = Buffers<3, 7, 4, 9, 5, 11>;

    /// [`Parts::lengths`] for `Small`: B-long vectors, S values, B² matrices, K per-stage
    /// words, N undetermined coordinates, T trig slots, R force values.
    const SMALL: [usize; 22] = [
        3, 3, 3, 3, 3, 3, 3, 3, 7, 9, 3, 3, 3, 9, 3, 3, 4, 9, 4, 5, 11, 4,
    ];

    #[test]
    fn buffers_lend_every_part_at_its_declared_size() {
        let mut buffers = Small::new();
        assert_eq!(buffers.parts().lengths(), SMALL);
        // No warm-start column yet: the estimator starts cold in every stage.
        assert!(buffers.parts().hints.iter().all(|&h| h == usize::MAX));
        // Without forces the force storage is empty.
        let mut kinematic = Buffers::<3, 7, 4, 9, 5>::new();
        assert_eq!(kinematic.parts().forces.len(), 0);
    }

    #[cfg(feature = "alloc")]
    #[test]
    fn vec_buffers_have_the_inline_buffers_sizes() {
        let mut buffers = VecBuffers::new(3, 7, 4, 9, 5, 11);
        assert_eq!(buffers.parts().lengths(), SMALL);
        assert!(buffers.parts().hints.iter().all(|&h| h == usize::MAX));
    }

    /// Writes a different value into every element of every part, reads them all back from a
    /// second borrow, and returns the diagnosis lists.
    fn round_trip<W: Workspace>(workspace: &mut W) -> (std::vec::Vec<usize>, std::vec::Vec<usize>) {
        let mut parts = workspace.parts();
        let mut next = 0.0;
        for part in floats(&mut parts) {
            for x in part.iter_mut() {
                next += 1.0;
                *x = next;
            }
        }
        let mut next = 0;
        for part in [
            &mut *parts.factors.swaps,
            &mut *parts.row_order,
            &mut *parts.col_order,
            &mut *parts.hints,
            &mut *parts.undetermined,
        ] {
            for x in part.iter_mut() {
                next += 1;
                *x = next;
            }
        }
        parts.downstream.fill(true);
        parts.archived.fill(true);
        // A fresh borrow sees every value where it was written: no part shares storage with
        // another, and nothing is lost between solves (the warm-start hints must persist).
        let mut parts = workspace.parts();
        let mut expected = 0.0;
        for part in floats(&mut parts) {
            for &x in part.iter() {
                expected += 1.0;
                assert_eq!(x, expected);
            }
        }
        let mut expected = 0;
        for part in [
            &*parts.factors.swaps,
            &*parts.row_order,
            &*parts.col_order,
            &*parts.hints,
            &*parts.undetermined,
        ] {
            for &x in part {
                expected += 1;
                assert_eq!(x, expected);
            }
        }
        assert!(
            parts
                .downstream
                .iter()
                .chain(parts.archived.iter())
                .all(|&b| b)
        );
        let (rows, columns) = workspace.diagnosis();
        (rows.to_vec(), columns.to_vec())
    }

    /// Every `f64` part.
    fn floats<'p>(parts: &'p mut Parts<'_>) -> [&'p mut [f64]; 15] {
        let (n, s, f, e) = (
            &mut parts.newton,
            &mut parts.scales,
            &mut parts.factors,
            &mut parts.estimator,
        );
        [
            &mut *n.phi,
            &mut *n.step,
            &mut *n.base,
            &mut *n.trial,
            &mut *n.gradient,
            &mut *s.rows,
            &mut *s.cols,
            &mut *s.inverse_cols,
            &mut *f.values,
            &mut *f.lu,
            &mut *e.x,
            &mut *e.signs,
            &mut *parts.dense,
            &mut *parts.trig,
            &mut *parts.forces,
        ]
    }

    #[test]
    fn parts_are_disjoint_persist_and_the_diagnosis_reads_the_solvers_lists() {
        let (rows, columns) = round_trip(&mut Small::new());
        // The row order (after swaps: 4, 5, 6) and the undetermined coordinates (after swaps,
        // row and column orders and hints: 14, …, 22).
        assert_eq!(rows, [4, 5, 6]);
        assert_eq!(columns, (14..=22).collect::<std::vec::Vec<_>>());
        #[cfg(feature = "alloc")]
        {
            let (rows, columns) = round_trip(&mut VecBuffers::new(3, 7, 4, 9, 5, 11));
            assert_eq!(rows, [4, 5, 6]);
            assert_eq!(columns, (14..=22).collect::<std::vec::Vec<_>>());
        }
    }
}
