//! `Scene<S>`: a hand-written mechanism with free degrees of freedom, solved as one dense
//! block ([`Dense`]), presented with every trait the integrator needs (the orphan rule keeps
//! the tests from implementing the runtime's `Dynamic` for the runtime's `Dense`).

use mechgen_runtime::codegen::{DenseBuffers, Stage};
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{
    Accelerations, Dense, Dynamic, EnergyTerms, EquationsOfMotion, Forces, FreeStorage, Matrix,
    Mechanism, Names, Outputs, ParameterError, Storage, Structured, Unit, Vector, Velocities,
};

/// `S` behind [`Dense`], with `S`'s equations of motion and free degrees of freedom.
pub struct Scene<S: Mechanism>(pub Dense<S>)
where
    DefaultAllocator: Storage<S::Dim>;

impl<S: Mechanism> Scene<S>
where
    DefaultAllocator: Storage<S::Dim>,
{
    pub fn new(inner: S) -> Self {
        Self(Dense::new(inner))
    }

    pub fn inner(&self) -> &S {
        self.0.inner()
    }
}

impl<S: Mechanism + Clone> Clone for Scene<S>
where
    DefaultAllocator: Storage<S::Dim>,
{
    fn clone(&self) -> Self {
        Self(self.0.clone())
    }
}

impl<S: Mechanism> Mechanism for Scene<S>
where
    DefaultAllocator: Storage<S::Dim>,
{
    type Dim = S::Dim;
    type Markers = S::Markers;

    fn dim(&self) -> S::Dim {
        self.0.dim()
    }
    fn marker_storage(&self) -> S::Markers {
        self.0.marker_storage()
    }
    fn names(&self) -> &'static Names {
        self.0.names()
    }
    fn coordinate_name(&self, index: usize) -> Option<&str> {
        self.0.coordinate_name(index)
    }
    fn equation_name(&self, index: usize) -> Option<&str> {
        self.0.equation_name(index)
    }
    fn parameter_count(&self) -> usize {
        self.0.parameter_count()
    }
    fn parameter_name(&self, index: usize) -> Option<&str> {
        self.0.parameter_name(index)
    }
    fn parameter(&self, index: usize) -> Option<f64> {
        self.0.parameter(index)
    }
    fn set_parameter<'a>(
        &'a mut self,
        name: &'a str,
        value: f64,
    ) -> Result<(), ParameterError<'a>> {
        self.0.set_parameter(name, value)
    }
    fn coordinate_unit(&self, index: usize) -> Unit {
        self.0.coordinate_unit(index)
    }
    fn equation_unit(&self, index: usize) -> Unit {
        self.0.equation_unit(index)
    }
    fn length_scale(&self) -> f64 {
        self.0.length_scale()
    }
    fn initial_guess(&self, q: &mut Vector<S::Dim>) {
        self.0.initial_guess(q);
    }
    fn phi(&self, q: &Vector<S::Dim>, t: f64, out: &mut Vector<S::Dim>) {
        self.0.phi(q, t, out);
    }
    fn jacobian(&self, q: &Vector<S::Dim>, t: f64, out: &mut Matrix<S::Dim>) {
        self.0.jacobian(q, t, out);
    }
    fn outputs(&self) -> Outputs {
        self.0.outputs()
    }
    fn nu(&self, q: &Vector<S::Dim>, t: f64, out: &mut Vector<S::Dim>) {
        self.0.nu(q, t, out);
    }
    fn gamma(&self, q: &Vector<S::Dim>, qd: &Vector<S::Dim>, t: f64, out: &mut Vector<S::Dim>) {
        self.0.gamma(q, qd, t, out);
    }
    fn generalized_forces(
        &self,
        q: &Vector<S::Dim>,
        qd: &Vector<S::Dim>,
        qdd: &Vector<S::Dim>,
        t: f64,
        out: &mut Vector<S::Dim>,
    ) {
        self.0.generalized_forces(q, qd, qdd, t, out);
    }
    fn reactions(
        &self,
        q: &Vector<S::Dim>,
        qd: &Vector<S::Dim>,
        lambda: &[f64],
        out: &mut Vector<S::Dim>,
    ) {
        self.0.reactions(q, qd, lambda, out);
    }
    fn reaction_name(&self, index: usize) -> Option<&str> {
        self.0.reaction_name(index)
    }
}

impl<S: Velocities> Velocities for Scene<S> where DefaultAllocator: Storage<S::Dim> {}
impl<S: Accelerations> Accelerations for Scene<S> where DefaultAllocator: Storage<S::Dim> {}
impl<S: Forces> Forces for Scene<S> where DefaultAllocator: Storage<S::Dim> {}

impl<S: Mechanism> Structured for Scene<S>
where
    DefaultAllocator: Storage<S::Dim>,
{
    type Workspace = DenseBuffers<S::Dim>;

    fn workspace(&self) -> Self::Workspace {
        self.0.workspace()
    }
    fn stage_count(&self) -> usize {
        self.0.stage_count()
    }
    fn stage(&self, index: usize) -> Option<Stage<'_>> {
        self.0.stage(index)
    }
    fn assign_positions(&self, stage: usize, q: &mut Vector<S::Dim>, trig: &[f64], t: f64) {
        self.0.assign_positions(stage, q, trig, t);
    }
    fn block_jacobian(
        &self,
        stage: usize,
        q: &Vector<S::Dim>,
        trig: &[f64],
        t: f64,
        phi: &mut [f64],
        values: &mut [f64],
    ) {
        self.0.block_jacobian(stage, q, trig, t, phi, values);
    }
    fn velocity_rhs(
        &self,
        stage: usize,
        q: &Vector<S::Dim>,
        trig: &[f64],
        qd: &Vector<S::Dim>,
        t: f64,
        out: &mut [f64],
    ) {
        self.0.velocity_rhs(stage, q, trig, qd, t, out);
    }
    fn acceleration_rhs(
        &self,
        stage: usize,
        q: &Vector<S::Dim>,
        trig: &[f64],
        qd: &Vector<S::Dim>,
        qdd: &Vector<S::Dim>,
        t: f64,
        out: &mut [f64],
    ) {
        self.0.acceleration_rhs(stage, q, trig, qd, qdd, t, out);
    }
    fn force_rhs(
        &self,
        stage: usize,
        q: &Vector<S::Dim>,
        trig: &[f64],
        qd: &Vector<S::Dim>,
        qdd: &Vector<S::Dim>,
        lambda: &[f64],
        t: f64,
        out: &mut [f64],
    ) {
        self.0.force_rhs(stage, q, trig, qd, qdd, lambda, t, out);
    }
}

impl<S: EquationsOfMotion> EquationsOfMotion for Scene<S>
where
    DefaultAllocator: Storage<S::Dim>,
{
    fn mass_times(&self, q: &Vector<S::Dim>, v: &Vector<S::Dim>, out: &mut Vector<S::Dim>) {
        self.inner().mass_times(q, v, out);
    }
    fn stiffness_times(
        &self,
        q: &Vector<S::Dim>,
        qd: &Vector<S::Dim>,
        t: f64,
        v: &Vector<S::Dim>,
        out: &mut Vector<S::Dim>,
    ) -> bool {
        self.inner().stiffness_times(q, qd, t, v, out)
    }
    fn damping_times(
        &self,
        q: &Vector<S::Dim>,
        qd: &Vector<S::Dim>,
        t: f64,
        v: &Vector<S::Dim>,
        out: &mut Vector<S::Dim>,
    ) -> bool {
        self.inner().damping_times(q, qd, t, v, out)
    }
    fn energy_terms(&self, q: &Vector<S::Dim>, qd: &Vector<S::Dim>, t: f64) -> EnergyTerms {
        self.inner().energy_terms(q, qd, t)
    }
}

impl<S: Dynamic> Dynamic for Scene<S>
where
    DefaultAllocator: Storage<S::Dim> + FreeStorage<S::Dim, S::Free>,
{
    type Free = S::Free;

    fn free(&self) -> S::Free {
        self.inner().free()
    }
    fn free_name(&self, k: usize) -> Option<&str> {
        self.inner().free_name(k)
    }
    fn free_equation(&self, k: usize) -> usize {
        self.inner().free_equation(k)
    }
    fn free_initial(&self, k: usize) -> (Option<f64>, f64) {
        self.inner().free_initial(k)
    }
    fn free_state(&self, k: usize) -> [f64; 3] {
        self.inner().free_state(k)
    }
    fn set_free(&mut self, k: usize, state: [f64; 3]) {
        self.0.inner_mut().set_free(k, state);
    }
}
