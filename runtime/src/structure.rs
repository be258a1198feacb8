//! The solve structure a scene hands the solver: its equations split into stages solved in
//! order, each stage's coordinates depending only on earlier stages.
//!
//! Generated scenes implement [`Structured`] with the plan `mechgen` derived at compile time
//! (explicit assignments, small Newton blocks in block-triangular order, each block's sparse LU
//! with its pivot order fixed in advance); the interpreter implements it with the same plan as
//! data, and [`crate::Dense`] with one block holding every equation (the dense reference).

use nalgebra::DefaultAllocator;

use crate::mechanism::{Mechanism, Storage, Vector};
use crate::step::{StepContext, StepReport};
use crate::workspace::Workspace;

/// One stage of a solve, in solve order. Every coordinate belongs to exactly one stage.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage<'a> {
    /// Coordinates assigned in closed form: equation `equations[k]` is affine in coordinate
    /// `coordinates[k]` with a constant non-zero coefficient, every other coordinate it reads
    /// being known from earlier stages (a ground pose, a driven angle, a pin on a point already
    /// placed). No Newton iteration, no factorisation.
    Explicit {
        /// Equation indices, in assignment order.
        equations: &'a [usize],
        /// The coordinate each equation assigns.
        coordinates: &'a [usize],
        /// The earlier stages whose coordinates these equations read, ascending.
        reads: &'a [usize],
    },
    /// Equations coupled so that they must be solved together, by Newton's method on the
    /// block's own Jacobian.
    Block(Block<'a>),
}

/// A square block of equations and the coordinates they determine together.
///
/// Local row `i` is equation `equations[i]`, local column `j` coordinate `coordinates[j]`,
/// both in pivot order: the block's static factorisation pivots on `(k, k)` at step `k`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Block<'a> {
    /// Global equation indices, in the block's row order.
    pub equations: &'a [usize],
    /// Global coordinate indices, in the block's column order.
    pub coordinates: &'a [usize],
    /// Where the Jacobian values written by [`Structured::block_jacobian`] sit.
    pub pattern: Pattern<'a>,
    /// Length of the value array the block's kernels work in: the Jacobian's entries, then the
    /// fill-in of its static factorisation.
    pub slots: usize,
    /// The value slot of each pivot of the block's static factorisation ([`Structured::factor`]
    /// stores each pivot's reciprocal there), in pivot order; the signs of these give the sign
    /// of the block's determinant. Empty without a static factorisation (the dense reference):
    /// the solver then always factors with partial pivoting.
    pub pivots: &'a [usize],
    /// The earlier stages whose coordinates the block's equations read, ascending.
    pub reads: &'a [usize],
}

/// The layout of a block's Jacobian values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pattern<'a> {
    /// Value `k` is the entry at local `(row, column) = entries[k]`; all others are zero.
    Sparse(&'a [(usize, usize)]),
    /// Every entry, column-major (`values[i + j·n]` is row `i`, column `j`).
    Dense,
}

impl<'a> Stage<'a> {
    /// The coordinates the stage determines.
    pub fn coordinates(&self) -> &'a [usize] {
        match *self {
            Stage::Explicit { coordinates, .. } => coordinates,
            Stage::Block(block) => block.coordinates,
        }
    }

    /// The earlier stages it reads.
    pub fn reads(&self) -> &'a [usize] {
        match *self {
            Stage::Explicit { reads, .. } => reads,
            Stage::Block(block) => block.reads,
        }
    }
}

impl Block<'_> {
    /// Number of equations (= coordinates).
    pub fn len(&self) -> usize {
        self.equations.len()
    }

    /// True for an empty block (never produced by `mechgen`).
    pub fn is_empty(&self) -> bool {
        self.equations.is_empty()
    }
}

/// A mechanism with a solve structure: the stages the solver works through, and the kernels it
/// calls for each of them.
///
/// Kernels take the stage index; called with the index of a stage of another kind, or past the
/// end, they do nothing. Slices passed in have the lengths the stage describes (the block size,
/// or [`Block::slots`] for values); kernels must not panic or allocate.
///
/// `trig` is the solve's trig cache: the sines and cosines of solved angles, which a stage
/// writes with [`Structured::fill_trig`] once its positions are known, and which later kernels
/// (and the stage's own rates) read instead of computing them again. Its length is the
/// workspace's; scenes without cached angles ignore it.
pub trait Structured: Mechanism
where
    DefaultAllocator: Storage<Self::Dim>,
{
    /// The solver's scratch storage, sized for this scene's largest block.
    type Workspace: Workspace;

    /// A fresh workspace (inline arrays for generated scenes; allocated once for interpreted
    /// ones).
    fn workspace(&self) -> Self::Workspace;

    /// Number of stages.
    fn stage_count(&self) -> usize;

    /// Stage `index` in solve order; `None` past the end.
    fn stage(&self, index: usize) -> Option<Stage<'_>>;

    /// Writes the coordinates an explicit stage assigns, from the earlier ones in `q`.
    fn assign_positions(&self, stage: usize, q: &mut Vector<Self::Dim>, trig: &[f64], t: f64);

    /// Writes the velocities of an explicit stage's coordinates.
    fn assign_velocities(
        &self,
        _stage: usize,
        _q: &Vector<Self::Dim>,
        _trig: &[f64],
        _qd: &mut Vector<Self::Dim>,
        _t: f64,
    ) {
    }

    /// Writes the accelerations of an explicit stage's coordinates.
    fn assign_accelerations(
        &self,
        _stage: usize,
        _q: &Vector<Self::Dim>,
        _trig: &[f64],
        _qd: &Vector<Self::Dim>,
        _qdd: &mut Vector<Self::Dim>,
        _t: f64,
    ) {
    }

    /// Writes a block's residual (its equations' values, local row order) into `phi` and its
    /// Jacobian values into `values` (layout [`Block::pattern`]).
    fn block_jacobian(
        &self,
        stage: usize,
        q: &Vector<Self::Dim>,
        trig: &[f64],
        t: f64,
        phi: &mut [f64],
        values: &mut [f64],
    );

    /// Writes a block's two solutions in closed form, where the generator found them (a loop
    /// that closes by a circle–line or circle–circle intersection), from the earlier stages'
    /// positions in `q`, into `out` (four times the block's length): candidate-major, and per
    /// coordinate of the block (local column order) two numbers, a length's value and 0, or an
    /// angle's cosine and sine (the intersection's unit vector: the solver takes the angle by
    /// `atan2`, and the straight step fills the trig cache with them). NaN where the loop
    /// cannot close. Blocks without a closed form leave `out` as it is (the solver fills it
    /// with NaN first): the default, for scenes without any.
    fn closed_form(
        &self,
        _stage: usize,
        _q: &Vector<Self::Dim>,
        _trig: &[f64],
        _t: f64,
        _out: &mut [f64],
    ) {
    }

    /// The straight kinematic step: every stage in order, positions, velocities and
    /// accelerations at `t`, each block taking its closed-form solution nearest the guess in
    /// `q` after the checks of [`crate::codegen::StepContext`], and the trig cache filled as
    /// the stage sweep fills it. Generated for a scene whose every block has a closed form
    /// and whose outputs are the accelerations or the forces. A scene that computes forces
    /// ends with the force solve, into `forces` (the workspace's force storage, empty for a
    /// kinematic scene): the multipliers, then each block's static factors, archived in stage
    /// order as the stage sweep archives them. `Err(stage)` where a check fails (or, by
    /// default, for a scene without one), with `q` as it was: the solver then runs the stage
    /// sweep.
    #[allow(clippy::too_many_arguments)]
    fn straight_step(
        &self,
        _t: f64,
        _q: &mut Vector<Self::Dim>,
        _qd: &mut Vector<Self::Dim>,
        _qdd: &mut Vector<Self::Dim>,
        _trig: &mut [f64],
        _forces: &mut [f64],
        _context: &StepContext,
        _report: &mut StepReport,
    ) -> Result<(), usize> {
        Err(0)
    }

    /// The velocities at the positions `q` of the last full solve of a scene that computes
    /// forces, with every block's static factors archived in `forces` (the workspace's force
    /// storage) by that solve: every stage in order, explicit ones assigned, each block's
    /// right-hand side solved with its archived factors (the integrator's columns of
    /// `∂q̇/∂u̇`). Generated with the straight step. `Err(stage)` for a non-finite block rate
    /// (or, by default, for a scene without a straight step): the solver then solves them
    /// the generic way.
    fn straight_velocities(
        &self,
        _t: f64,
        _q: &Vector<Self::Dim>,
        _trig: &[f64],
        _qd: &mut Vector<Self::Dim>,
        _forces: &[f64],
        _context: &StepContext,
    ) -> Result<(), usize> {
        Err(0)
    }

    /// Writes the sines and cosines of the angles stage `stage` solved into the trig cache, once
    /// its positions in `q` are final.
    fn fill_trig(&self, _stage: usize, _q: &Vector<Self::Dim>, _trig: &mut [f64]) {}

    /// Value of branch invariant `index` at the solved positions `q`, with every stage's trig
    /// cached: [`Mechanism::branch_value`], which generated scenes evaluate from the cache.
    fn branch(&self, index: usize, q: &Vector<Self::Dim>, _trig: &[f64]) -> f64 {
        self.branch_value(index, q)
    }

    /// The marker values at the solved state, with every stage's trig cached:
    /// [`Mechanism::marker_values`], which generated scenes evaluate from the cache.
    fn markers(
        &self,
        q: &Vector<Self::Dim>,
        _trig: &[f64],
        qd: &Vector<Self::Dim>,
        qdd: &Vector<Self::Dim>,
        t: f64,
        out: &mut Self::Markers,
    ) {
        self.marker_values(q, qd, qdd, t, out);
    }

    /// Factors a block's (scaled) Jacobian values in place with its static pivot order.
    ///
    /// # Errors
    /// The first pivot step `k` at which the pivot is not above `tiny` in magnitude or a
    /// multiplier exceeds `limit` in magnitude (NaN fails both tests): the solver then
    /// refactors the block with partial pivoting.
    fn factor(
        &self,
        _stage: usize,
        _values: &mut [f64],
        _tiny: f64,
        _limit: f64,
    ) -> Result<(), usize> {
        Err(0)
    }

    /// Solves `A x = b` in place with the factors from [`Structured::factor`] (`b` in local row
    /// order, `x` in local column order).
    fn solve(&self, _stage: usize, _values: &[f64], _x: &mut [f64]) {}

    /// Solves `Aᵀ x = b` in place with the factors from [`Structured::factor`] (`b` in local
    /// column order, `x` in local row order).
    fn solve_transpose(&self, _stage: usize, _values: &[f64], _x: &mut [f64]) {}

    /// Writes a block's velocity right-hand side, `ν_b − Φ_q[b, earlier] q̇_earlier`, from the
    /// velocities of earlier stages in `qd` (local row order).
    fn velocity_rhs(
        &self,
        _stage: usize,
        _q: &Vector<Self::Dim>,
        _trig: &[f64],
        _qd: &Vector<Self::Dim>,
        _t: f64,
        out: &mut [f64],
    ) {
        out.fill(f64::NAN);
    }

    /// Writes a block's acceleration right-hand side, `γ_b − Φ_q[b, earlier] q̈_earlier`, from
    /// the block's and earlier velocities and earlier accelerations.
    // Each argument is one input the kernel may read; bundling them would only rename them.
    #[allow(clippy::too_many_arguments)]
    fn acceleration_rhs(
        &self,
        _stage: usize,
        _q: &Vector<Self::Dim>,
        _trig: &[f64],
        _qd: &Vector<Self::Dim>,
        _qdd: &Vector<Self::Dim>,
        _t: f64,
        out: &mut [f64],
    ) {
        out.fill(f64::NAN);
    }

    /// Writes the Lagrange multipliers of an explicit stage's equations into `lambda` (indexed
    /// by equation), from the multipliers of later stages already there: each assignment's
    /// equation balances the generalised force on its coordinate,
    /// `λ_e = (F_c − Σ_{later} Φ_q[i, c] λ_i) / Φ_q[e, c]` ([`crate::Forces`]).
    ///
    /// Scenes that compute forces implement it; the default writes NaN.
    #[allow(clippy::too_many_arguments)]
    fn assign_multipliers(
        &self,
        stage: usize,
        _q: &Vector<Self::Dim>,
        _trig: &[f64],
        _qd: &Vector<Self::Dim>,
        _qdd: &Vector<Self::Dim>,
        lambda: &mut [f64],
        _t: f64,
    ) {
        if let Some(Stage::Explicit { equations, .. }) = self.stage(stage) {
            for &e in equations {
                if let Some(l) = lambda.get_mut(e) {
                    *l = f64::NAN;
                }
            }
        }
    }

    /// Writes a block's force right-hand side, in local column order: the generalised force
    /// on each of its coordinates less what the constraints of later stages take up,
    /// `F_c − Σ_{later} Φ_q[i, c] λ_i`, from the multipliers of later stages in `lambda`. The
    /// block's multipliers solve `Φ_q[b, b]ᵀ λ_b = out` ([`Structured::solve_transpose`]).
    ///
    /// Scenes that compute forces implement it; the default writes NaN.
    #[allow(clippy::too_many_arguments)]
    fn force_rhs(
        &self,
        _stage: usize,
        _q: &Vector<Self::Dim>,
        _trig: &[f64],
        _qd: &Vector<Self::Dim>,
        _qdd: &Vector<Self::Dim>,
        _lambda: &[f64],
        _t: f64,
        out: &mut [f64],
    ) {
        out.fill(f64::NAN);
    }
}
