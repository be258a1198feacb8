//! The dense reference solve: any [`Mechanism`] solved as one block holding all its equations,
//! factored with partial pivoting at every iteration from its textbook Φ_q, ν and γ.
//!
//! This is how the runtime solved every scene before scenes carried their solve structure. It
//! stays as the reference the structured solve is tested against, and as the way to solve a
//! hand-written mechanism that only provides the textbook functions:
//! `Solver::new(Dense::new(scene))`.

use core::cell::RefCell;

use nalgebra::{DefaultAllocator, OVector, U1};

use crate::mechanism::{
    Accelerations, Forces, Matrix, Mechanism, Outputs, ParameterError, Storage, Unit, Vector,
    Velocities,
};
use crate::structure::{Block, Pattern, Stage, Structured};
use crate::workspace::{Parts, ScalesOf, Workspace};

/// A mechanism solved densely, as one block: see the module documentation.
pub struct Dense<M: Mechanism>
where
    DefaultAllocator: Storage<M::Dim>,
{
    inner: M,
    /// `0, 1, …, n − 1`: the block's equations and coordinates.
    indices: OVector<usize, M::Dim>,
    /// Where the textbook functions write before their values are copied into the block's.
    scratch: RefCell<Scratch<M>>,
}

struct Scratch<M: Mechanism>
where
    DefaultAllocator: Storage<M::Dim>,
{
    phi: Vector<M::Dim>,
    jacobian: Matrix<M::Dim>,
    rhs: Vector<M::Dim>,
}

impl<M: Mechanism> Dense<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Wraps `inner`.
    pub fn new(inner: M) -> Self {
        let dim = inner.dim();
        Self {
            indices: OVector::from_fn_generic(dim, U1, |i, _| i),
            scratch: RefCell::new(Scratch {
                phi: Vector::zeros_generic(dim, U1),
                jacobian: Matrix::zeros_generic(dim, dim),
                rhs: Vector::zeros_generic(dim, U1),
            }),
            inner,
        }
    }

    /// The wrapped mechanism.
    pub fn inner(&self) -> &M {
        &self.inner
    }

    /// The wrapped mechanism, for setting parameters. Its `dim()` must not change.
    pub fn inner_mut(&mut self) -> &mut M {
        &mut self.inner
    }

    /// Gives the wrapped mechanism back.
    pub fn into_inner(self) -> M {
        self.inner
    }

    /// Runs `f` on the scratch buffers, or writes NaN to `out` if they are in use (never: the
    /// kernels do not call each other).
    fn with_scratch(&self, out: &mut [f64], f: impl FnOnce(&mut Scratch<M>, &mut [f64])) {
        match self.scratch.try_borrow_mut() {
            Ok(mut scratch) => f(&mut scratch, out),
            Err(_) => out.fill(f64::NAN),
        }
    }
}

impl<M: Mechanism + Clone> Clone for Dense<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn clone(&self) -> Self {
        Self::new(self.inner.clone())
    }
}

impl<M: Mechanism> Mechanism for Dense<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    type Dim = M::Dim;
    type Markers = M::Markers;

    fn dim(&self) -> M::Dim {
        self.inner.dim()
    }
    fn marker_storage(&self) -> M::Markers {
        self.inner.marker_storage()
    }
    fn marker_values(
        &self,
        q: &Vector<M::Dim>,
        qd: &Vector<M::Dim>,
        qdd: &Vector<M::Dim>,
        t: f64,
        out: &mut M::Markers,
    ) {
        self.inner.marker_values(q, qd, qdd, t, out);
    }
    fn marker_name(&self, index: usize) -> Option<&str> {
        self.inner.marker_name(index)
    }
    fn names(&self) -> &'static crate::Names {
        self.inner.names()
    }
    fn coordinate_name(&self, index: usize) -> Option<&str> {
        self.inner.coordinate_name(index)
    }
    fn equation_name(&self, index: usize) -> Option<&str> {
        self.inner.equation_name(index)
    }
    fn parameter_count(&self) -> usize {
        self.inner.parameter_count()
    }
    fn parameter_name(&self, index: usize) -> Option<&str> {
        self.inner.parameter_name(index)
    }
    fn parameter(&self, index: usize) -> Option<f64> {
        self.inner.parameter(index)
    }
    fn set_parameter<'a>(
        &'a mut self,
        name: &'a str,
        value: f64,
    ) -> Result<(), ParameterError<'a>> {
        self.inner.set_parameter(name, value)
    }
    fn coordinate_unit(&self, index: usize) -> Unit {
        self.inner.coordinate_unit(index)
    }
    fn equation_unit(&self, index: usize) -> Unit {
        self.inner.equation_unit(index)
    }
    fn length_scale(&self) -> f64 {
        self.inner.length_scale()
    }
    fn check_geometry(&self) -> Result<(), crate::GeometryFault> {
        self.inner.check_geometry()
    }
    fn check_physics(&self) -> Result<(), crate::PhysicsFault> {
        self.inner.check_physics()
    }
    fn branch_count(&self) -> usize {
        self.inner.branch_count()
    }
    fn branch_name(&self, index: usize) -> Option<&str> {
        self.inner.branch_name(index)
    }
    fn branch_value(&self, index: usize, q: &Vector<M::Dim>) -> f64 {
        self.inner.branch_value(index, q)
    }
    fn initial_guess(&self, q: &mut Vector<M::Dim>) {
        self.inner.initial_guess(q);
    }
    fn phi(&self, q: &Vector<M::Dim>, t: f64, out: &mut Vector<M::Dim>) {
        self.inner.phi(q, t, out);
    }
    fn jacobian(&self, q: &Vector<M::Dim>, t: f64, out: &mut Matrix<M::Dim>) {
        self.inner.jacobian(q, t, out);
    }
    fn phi_and_jacobian(
        &self,
        q: &Vector<M::Dim>,
        t: f64,
        phi: &mut Vector<M::Dim>,
        jacobian: &mut Matrix<M::Dim>,
    ) {
        self.inner.phi_and_jacobian(q, t, phi, jacobian);
    }
    fn outputs(&self) -> Outputs {
        self.inner.outputs()
    }
    fn nu(&self, q: &Vector<M::Dim>, t: f64, out: &mut Vector<M::Dim>) {
        self.inner.nu(q, t, out);
    }
    fn gamma(&self, q: &Vector<M::Dim>, qd: &Vector<M::Dim>, t: f64, out: &mut Vector<M::Dim>) {
        self.inner.gamma(q, qd, t, out);
    }
    fn generalized_forces(
        &self,
        q: &Vector<M::Dim>,
        qd: &Vector<M::Dim>,
        qdd: &Vector<M::Dim>,
        t: f64,
        out: &mut Vector<M::Dim>,
    ) {
        self.inner.generalized_forces(q, qd, qdd, t, out);
    }
    fn reactions(
        &self,
        q: &Vector<M::Dim>,
        qd: &Vector<M::Dim>,
        lambda: &[f64],
        out: &mut Vector<M::Dim>,
    ) {
        self.inner.reactions(q, qd, lambda, out);
    }
    fn reaction_name(&self, index: usize) -> Option<&str> {
        self.inner.reaction_name(index)
    }
    fn load_fault(
        &self,
        q: &Vector<M::Dim>,
        qd: &Vector<M::Dim>,
        t: f64,
    ) -> Option<crate::Quantity> {
        self.inner.load_fault(q, qd, t)
    }
}

impl<M: Velocities> Velocities for Dense<M> where DefaultAllocator: Storage<M::Dim> {}
impl<M: Accelerations> Accelerations for Dense<M> where DefaultAllocator: Storage<M::Dim> {}
impl<M: Forces> Forces for Dense<M> where DefaultAllocator: Storage<M::Dim> {}

impl<M: Mechanism> Structured for Dense<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    type Workspace = DenseBuffers<M::Dim>;

    fn workspace(&self) -> DenseBuffers<M::Dim> {
        DenseBuffers::new(self.inner.dim())
    }

    fn stage_count(&self) -> usize {
        1
    }

    fn stage(&self, index: usize) -> Option<Stage<'_>> {
        let n = self.indices.len();
        (index == 0).then(|| {
            Stage::Block(Block {
                equations: self.indices.as_slice(),
                coordinates: self.indices.as_slice(),
                pattern: Pattern::Dense,
                slots: n * n,
                pivots: &[],
                reads: &[],
            })
        })
    }

    fn assign_positions(&self, _stage: usize, _q: &mut Vector<M::Dim>, _trig: &[f64], _t: f64) {}

    fn block_jacobian(
        &self,
        _stage: usize,
        q: &Vector<M::Dim>,
        _trig: &[f64],
        t: f64,
        phi: &mut [f64],
        values: &mut [f64],
    ) {
        self.with_scratch(values, |scratch, values| {
            self.inner
                .phi_and_jacobian(q, t, &mut scratch.phi, &mut scratch.jacobian);
            copy(scratch.jacobian.as_slice(), values);
            copy(scratch.phi.as_slice(), phi);
        });
    }

    fn velocity_rhs(
        &self,
        _stage: usize,
        q: &Vector<M::Dim>,
        _trig: &[f64],
        _qd: &Vector<M::Dim>,
        t: f64,
        out: &mut [f64],
    ) {
        self.with_scratch(out, |scratch, out| {
            self.inner.nu(q, t, &mut scratch.rhs);
            copy(scratch.rhs.as_slice(), out);
        });
    }

    fn acceleration_rhs(
        &self,
        _stage: usize,
        q: &Vector<M::Dim>,
        _trig: &[f64],
        qd: &Vector<M::Dim>,
        _qdd: &Vector<M::Dim>,
        t: f64,
        out: &mut [f64],
    ) {
        self.with_scratch(out, |scratch, out| {
            self.inner.gamma(q, qd, t, &mut scratch.rhs);
            copy(scratch.rhs.as_slice(), out);
        });
    }

    /// The one block's force right-hand side is the whole of F: no later stage takes any up.
    fn force_rhs(
        &self,
        _stage: usize,
        q: &Vector<M::Dim>,
        _trig: &[f64],
        qd: &Vector<M::Dim>,
        qdd: &Vector<M::Dim>,
        _lambda: &[f64],
        t: f64,
        out: &mut [f64],
    ) {
        self.with_scratch(out, |scratch, out| {
            self.inner
                .generalized_forces(q, qd, qdd, t, &mut scratch.rhs);
            copy(scratch.rhs.as_slice(), out);
        });
    }
}

/// `to ← from` over their common length.
fn copy(from: &[f64], to: &mut [f64]) {
    for (t, f) in to.iter_mut().zip(from) {
        *t = *f;
    }
}

/// The workspace of a [`Dense`] mechanism: n × n matrices on the stack for `Const`
/// dimensions (allocated once for `Dyn`).
#[derive(Clone)]
pub struct DenseBuffers<D: nalgebra::Dim>
where
    DefaultAllocator: Storage<D>,
{
    vectors: [Vector<D>; 10],
    indices: [OVector<usize, D>; 3],
    values: Matrix<D>,
    matrices: [Matrix<D>; 2],
    hints: [usize; 1],
    undetermined: OVector<usize, D>,
    downstream: [bool; 1],
    /// The force solve's multipliers (the one block has no static factors to archive).
    multipliers: Vector<D>,
    archived: [bool; 1],
    scales_of: ScalesOf,
}

impl<D: nalgebra::Dim> DenseBuffers<D>
where
    DefaultAllocator: Storage<D>,
{
    /// Zeroed buffers for n × n blocks.
    pub fn new(dim: D) -> Self {
        Self {
            vectors: core::array::from_fn(|_| Vector::zeros_generic(dim, U1)),
            indices: core::array::from_fn(|_| OVector::from_element_generic(dim, U1, 0)),
            values: Matrix::zeros_generic(dim, dim),
            matrices: core::array::from_fn(|_| Matrix::zeros_generic(dim, dim)),
            hints: [usize::MAX],
            undetermined: OVector::from_element_generic(dim, U1, 0),
            downstream: [false],
            multipliers: Vector::zeros_generic(dim, U1),
            archived: [false],
            scales_of: ScalesOf(None),
        }
    }
}

impl<D: nalgebra::Dim> Workspace for DenseBuffers<D>
where
    DefaultAllocator: Storage<D>,
{
    fn parts(&mut self) -> Parts<'_> {
        Parts::new(
            self.vectors.each_mut().map(|v| v.as_mut_slice()),
            self.indices.each_mut().map(|v| v.as_mut_slice()),
            self.values.as_mut_slice(),
            self.matrices.each_mut().map(|m| m.as_mut_slice()),
            (
                &mut self.hints,
                self.undetermined.as_mut_slice(),
                &mut self.downstream,
            ),
            (&mut [], &mut self.scales_of),
            (self.multipliers.as_mut_slice(), &mut self.archived),
        )
    }

    fn diagnosis(&self) -> (&[usize], &[usize]) {
        (self.indices[1].as_slice(), self.undetermined.as_slice())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Const;

    #[test]
    fn dense_buffers_hold_one_block_of_every_coordinate() {
        let mut buffers = DenseBuffers::new(Const::<3>);
        // Every block-sized part is n long, matrices n², one stage, no trig cache, and the
        // force storage holds the n multipliers (no static factors to archive).
        let expected = [
            3, 3, 3, 3, 3, 3, 3, 3, 9, 9, 3, 3, 3, 9, 3, 3, 1, 3, 1, 0, 3, 1,
        ];
        assert_eq!(buffers.parts().lengths(), expected);
        assert_eq!(buffers.parts().hints, &[usize::MAX]);
    }
}
