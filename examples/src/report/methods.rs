//! The ways of solving the report compares, as mechanisms behind the runtime's traits: the same
//! Newton loop and stepping run all of them.
//!
//! - [`Method::Generated`]: the scene's generated code, solved with its structure (explicit
//!   assignments, small Newton blocks, static sparse LU): the product.
//! - [`Method::Dense`]: the same generated Φ, Φ_q, ν, γ solved as one dense block with partial
//!   pivoting ([`mechgen_runtime::Dense`]): what the structure saves.
//! - [`ForwardDifference`] / [`CentralDifference`]: Φ_q by finite differences of the generated Φ,
//!   solved densely.
//! - [`AutoDiff`]: Φ_q by forward-mode automatic differentiation (num-dual's `Dual64`) of the
//!   scene's Φ, evaluated from its IR by the interpreter's tape over dual numbers, solved densely.
//! - [`Method::Interpreted`]: `mechgen_interp::Interpreted`, the same plan as the generated code
//!   with everything evaluated from the IR, as a run-time (non-generated) library would do.
//!
//! The wrappers take ν and γ (and the initial guess, names and parameters) from the generated
//! scene they wrap, and run through the dense reference, which only needs textbook functions:
//! against [`Method::Dense`] the comparison isolates the Jacobian.

use std::cell::RefCell;
use std::ops::{Add, Div, Mul, Neg, Sub};

use mechgen::expr::tape::{Inputs, Scalar, Tape};
use mechgen::expr::{Func, Func2};
use mechgen_runtime::nalgebra::{DefaultAllocator, Dim, U1};
use mechgen_runtime::{
    Accelerations, Matrix, Mechanism, Outputs, ParameterError, Storage, Unit, Vector, Velocities,
};
use num_dual::{Dual64, DualNum};

/// One way of computing Φ_q (and, for the interpreter, everything else).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Method {
    /// Generated code: the analytic Jacobian, emitted as straight-line Rust, solved with the
    /// scene's structure.
    Generated,
    /// The same generated functions, solved as one dense block.
    Dense,
    /// Forward differences of the generated Φ.
    ForwardDifference,
    /// Central differences of the generated Φ.
    CentralDifference,
    /// Forward-mode automatic differentiation of the same Φ (interpreted over dual numbers).
    AutoDiff,
    /// The interpreter over the IR, for Φ, Φ_q, ν and γ.
    Interpreted,
}

impl Method {
    /// Every method, in the order of the report's tables (generated first: the reference).
    pub const ALL: [Method; 6] = [
        Method::Generated,
        Method::Dense,
        Method::ForwardDifference,
        Method::CentralDifference,
        Method::AutoDiff,
        Method::Interpreted,
    ];

    /// Short name for tables and legends.
    pub fn label(self) -> &'static str {
        match self {
            Method::Generated => "generated (analytic)",
            Method::Dense => "generated, dense LU",
            Method::ForwardDifference => "forward difference",
            Method::CentralDifference => "central difference",
            Method::AutoDiff => "forward-mode AD",
            Method::Interpreted => "interpreter",
        }
    }

    /// Identifier for CSV files and criterion benchmark names.
    pub fn slug(self) -> &'static str {
        match self {
            Method::Generated => "generated",
            Method::Dense => "dense",
            Method::ForwardDifference => "forward_difference",
            Method::CentralDifference => "central_difference",
            Method::AutoDiff => "autodiff",
            Method::Interpreted => "interpreted",
        }
    }

    /// One sentence on what the method computes and how.
    pub fn description(self) -> &'static str {
        match self {
            Method::Generated => {
                "the generated solve structure: explicit assignments, Newton on the coupled \
                 blocks with their analytic Jacobians and static sparse LU, each block's \
                 velocities and accelerations with the same factors."
            }
            Method::Dense => {
                "Φ and the analytic Φ_q from the generated code, in one pass sharing every sin/cos \
                 (`phi_and_jacobian`), solved as one dense block with partial pivoting; ν and γ \
                 generated."
            }
            Method::ForwardDifference => {
                "generated Φ; Φ_q column k = (Φ(q + h e_k) − Φ(q)) / h with \
                 h = √ε·max(1, |q_k|) (n + 1 evaluations of Φ); ν and γ generated."
            }
            Method::CentralDifference => {
                "generated Φ; Φ_q column k = (Φ(q + h e_k) − Φ(q − h e_k)) / 2h with \
                 h = ∛ε·max(1, |q_k|) (2n + 1 evaluations of Φ); ν and γ generated."
            }
            Method::AutoDiff => {
                "Φ from the scene's IR evaluated over num-dual's `Dual64` by the interpreter's \
                 tape, one pass per column seeded with that coordinate's unit derivative \
                 (n passes; no heap use per call); ν and γ generated."
            }
            Method::Interpreted => {
                "`mechgen_interp::Interpreted`: the generated code's plan, with every expression \
                 evaluated from the IR at run time, as a non-generated library would \
                 (dynamically sized: heap vectors)."
            }
        }
    }
}

impl core::fmt::Display for Method {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.label())
    }
}

/// Why a method could not be built for a scene.
#[derive(Debug, Clone, PartialEq)]
pub enum MethodError {
    /// The IR scene and the generated scene disagree (size, coordinate names or parameters).
    Mismatch(String),
}

impl core::fmt::Display for MethodError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            MethodError::Mismatch(what) => {
                write!(
                    f,
                    "the .mech scene does not match the generated one: {what}"
                )
            }
        }
    }
}

impl std::error::Error for MethodError {}

/// Everything but Φ and Φ_q is the wrapped scene's: names, parameters, guess, ν and γ. (One macro so that the three wrappers cannot drift apart.)
macro_rules! delegate_to_inner {
    () => {
        type Dim = M::Dim;
        type Markers = M::Markers;

        fn dim(&self) -> M::Dim {
            self.inner.dim()
        }

        fn marker_storage(&self) -> M::Markers {
            self.inner.marker_storage()
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

        fn coordinate_unit(&self, index: usize) -> Unit {
            self.inner.coordinate_unit(index)
        }

        fn equation_unit(&self, index: usize) -> Unit {
            self.inner.equation_unit(index)
        }

        fn length_scale(&self) -> f64 {
            self.inner.length_scale()
        }

        fn check_geometry(&self) -> Result<(), mechgen_runtime::GeometryFault> {
            self.inner.check_geometry()
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

        fn outputs(&self) -> Outputs {
            self.inner.outputs()
        }

        fn nu(&self, q: &Vector<M::Dim>, t: f64, out: &mut Vector<M::Dim>) {
            self.inner.nu(q, t, out);
        }

        fn gamma(&self, q: &Vector<M::Dim>, qd: &Vector<M::Dim>, t: f64, out: &mut Vector<M::Dim>) {
            self.inner.gamma(q, qd, t, out);
        }
    };
}

/// The wrapped scene's output level, for each wrapper (ν and γ are delegated above).
macro_rules! delegate_derivatives {
    ($wrapper:ident) => {
        impl<M: Velocities> Velocities for $wrapper<M> where DefaultAllocator: Storage<M::Dim> {}
        impl<M: Accelerations> Accelerations for $wrapper<M> where
            DefaultAllocator: Storage<M::Dim>
        {
        }
    };
}

/// Unit round-off of f64 (2⁻⁵²).
const EPSILON: f64 = f64::EPSILON;

/// A mechanism whose Jacobian is forward differences of the wrapped scene's Φ.
///
/// Column k is `(Φ(q + h e_k) − Φ(q)) / h` with `h = √ε · max(1, |q_k|)`, rounded so that
/// `q_k + h` is exact: the step balancing truncation (∝ h) against round-off (∝ ε/h) for a
/// well-scaled Φ, which leaves about half the digits. The analytic Jacobian is never called.
#[derive(Debug, Clone)]
pub struct ForwardDifference<M> {
    inner: M,
}

impl<M> ForwardDifference<M> {
    /// Wraps a (generated) scene.
    pub fn new(inner: M) -> Self {
        Self { inner }
    }

    /// The wrapped scene.
    pub fn inner(&self) -> &M {
        &self.inner
    }
}

impl<M: Mechanism> Mechanism for ForwardDifference<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    delegate_to_inner!();

    fn set_parameter<'a>(
        &'a mut self,
        name: &'a str,
        value: f64,
    ) -> Result<(), ParameterError<'a>> {
        self.inner.set_parameter(name, value)
    }

    fn phi(&self, q: &Vector<M::Dim>, t: f64, out: &mut Vector<M::Dim>) {
        self.inner.phi(q, t, out);
    }

    fn jacobian(&self, q: &Vector<M::Dim>, t: f64, out: &mut Matrix<M::Dim>) {
        let mut phi = Vector::zeros_generic(self.inner.dim(), U1);
        self.phi_and_jacobian(q, t, &mut phi, out);
    }

    fn phi_and_jacobian(
        &self,
        q: &Vector<M::Dim>,
        t: f64,
        phi: &mut Vector<M::Dim>,
        jacobian: &mut Matrix<M::Dim>,
    ) {
        self.inner.phi(q, t, phi);
        let (dim, base) = (self.inner.dim(), &*phi);
        // Stack vectors for `Const` scenes: no allocation per call.
        let mut shifted = q.clone();
        let mut plus = Vector::zeros_generic(dim, U1);
        for_each_column(jacobian, dim, |k, column| {
            let qk = q[k];
            // Rounding `q_k + h` and taking the difference back makes h exactly representable
            // as the step actually taken.
            let h = (qk + EPSILON.sqrt() * qk.abs().max(1.0)) - qk;
            shifted[k] = qk + h;
            self.inner.phi(&shifted, t, &mut plus);
            shifted[k] = qk;
            let (plus, base) = (plus.as_slice(), base.as_slice());
            for ((c, p), b) in column.iter_mut().zip(plus).zip(base) {
                *c = (p - b) / h;
            }
        });
    }
}

delegate_derivatives!(ForwardDifference);

/// A mechanism whose Jacobian is central differences of the wrapped scene's Φ.
///
/// Column k is `(Φ(q + h e_k) − Φ(q − h e_k)) / (2h)` with `h = ∛ε · max(1, |q_k|)`: truncation
/// ∝ h², round-off ∝ ε/h, leaving about two thirds of the digits for twice the evaluations.
#[derive(Debug, Clone)]
pub struct CentralDifference<M> {
    inner: M,
}

impl<M> CentralDifference<M> {
    /// Wraps a (generated) scene.
    pub fn new(inner: M) -> Self {
        Self { inner }
    }

    /// The wrapped scene.
    pub fn inner(&self) -> &M {
        &self.inner
    }
}

impl<M: Mechanism> Mechanism for CentralDifference<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    delegate_to_inner!();

    fn set_parameter<'a>(
        &'a mut self,
        name: &'a str,
        value: f64,
    ) -> Result<(), ParameterError<'a>> {
        self.inner.set_parameter(name, value)
    }

    fn phi(&self, q: &Vector<M::Dim>, t: f64, out: &mut Vector<M::Dim>) {
        self.inner.phi(q, t, out);
    }

    fn jacobian(&self, q: &Vector<M::Dim>, t: f64, out: &mut Matrix<M::Dim>) {
        let dim = self.inner.dim();
        let mut shifted = q.clone();
        let (mut plus, mut minus) = (
            Vector::zeros_generic(dim, U1),
            Vector::zeros_generic(dim, U1),
        );
        for_each_column(out, dim, |k, column| {
            let qk = q[k];
            let step = EPSILON.cbrt() * qk.abs().max(1.0);
            let (up, down) = (qk + step, qk - step);
            shifted[k] = up;
            self.inner.phi(&shifted, t, &mut plus);
            shifted[k] = down;
            self.inner.phi(&shifted, t, &mut minus);
            shifted[k] = qk;
            // The width actually spanned after rounding.
            let width = up - down;
            let (plus, minus) = (plus.as_slice(), minus.as_slice());
            for ((c, p), m) in column.iter_mut().zip(plus).zip(minus) {
                *c = (p - m) / width;
            }
        });
    }

    fn phi_and_jacobian(
        &self,
        q: &Vector<M::Dim>,
        t: f64,
        phi: &mut Vector<M::Dim>,
        jacobian: &mut Matrix<M::Dim>,
    ) {
        // Central differences do not use Φ(q) itself: one more evaluation for the residual.
        self.inner.phi(q, t, phi);
        self.jacobian(q, t, jacobian);
    }
}

delegate_derivatives!(CentralDifference);

/// Calls `fill(k, column_k)` for every column of the square `matrix` (column-major storage:
/// each column is one contiguous slice, so no per-entry index arithmetic or bounds checks).
fn for_each_column<D: Dim>(matrix: &mut Matrix<D>, dim: D, mut fill: impl FnMut(usize, &mut [f64]))
where
    DefaultAllocator: Storage<D>,
{
    let n = dim.value();
    if n == 0 {
        return;
    }
    for (k, column) in matrix.as_mut_slice().chunks_exact_mut(n).enumerate() {
        fill(k, column);
    }
}

/// A `Dual64` the interpreter's tape can evaluate over.
///
/// A newtype because neither the [`Scalar`] trait (mechgen) nor `Dual64` (num-dual) belongs to
/// this crate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ad(pub Dual64);

impl Add for Ad {
    type Output = Ad;
    #[inline]
    fn add(self, other: Ad) -> Ad {
        Ad(self.0 + other.0)
    }
}

impl Sub for Ad {
    type Output = Ad;
    #[inline]
    fn sub(self, other: Ad) -> Ad {
        Ad(self.0 - other.0)
    }
}

impl Mul for Ad {
    type Output = Ad;
    #[inline]
    fn mul(self, other: Ad) -> Ad {
        Ad(self.0 * other.0)
    }
}

impl Div for Ad {
    type Output = Ad;
    #[inline]
    fn div(self, other: Ad) -> Ad {
        Ad(self.0 / other.0)
    }
}

impl Neg for Ad {
    type Output = Ad;
    #[inline]
    fn neg(self) -> Ad {
        Ad(-self.0)
    }
}

impl Scalar for Ad {
    #[inline]
    fn from_f64(value: f64) -> Self {
        Ad(Dual64::from_re(value))
    }

    #[inline]
    fn powi(self, n: i32) -> Self {
        Ad(self.0.powi(n))
    }

    #[inline]
    fn apply(self, function: Func) -> Self {
        let x = self.0;
        Ad(match function {
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Tan => x.tan(),
            Func::Exp => x.exp(),
            Func::Ln => x.ln(),
            Func::Sqrt => x.sqrt(),
            Func::Asin => x.asin(),
            Func::Acos => x.acos(),
        })
    }

    #[inline]
    fn apply2(self, function: Func2, other: Self) -> Self {
        let (a, b) = (self.0, other.0);
        Ad(match function {
            // atan2(y, x)' = (x dy − y dx) / (x² + y²).
            Func2::Atan2 => {
                let value = a.re.atan2(b.re);
                let slope = (b.re * a.eps - a.re * b.eps) / (a.re * a.re + b.re * b.re);
                Dual64::new(value, slope)
            }
            Func2::Pow => a.powd(b),
        })
    }

    #[inline]
    fn primal(self) -> f64 {
        self.0.re
    }
}

/// A mechanism whose Φ and Φ_q come from forward-mode automatic differentiation of the scene's
/// Φ, evaluated from its IR; everything else is the wrapped (generated) scene's.
///
/// Φ_q takes n passes of the Φ tape over `Dual64`, the k-th seeded with q̇_k = 1 (one
/// directional derivative, i.e. one column, per pass); the real parts of the first pass are Φ.
/// Exact to round-off, like the analytic Jacobian, but paid for at run time. The buffers are
/// allocated once by [`AutoDiff::new`].
#[derive(Debug, Clone)]
pub struct AutoDiff<M> {
    inner: M,
    phi: Tape,
    /// Parameter values by declaration index, kept equal to the wrapped scene's.
    params: Vec<f64>,
    work: RefCell<Work>,
}

/// Reusable buffers of [`AutoDiff`] (evaluation is `&self`).
#[derive(Debug, Clone)]
struct Work {
    q: Vec<Ad>,
    slots: Vec<Ad>,
    out: Vec<Ad>,
    plain_slots: Vec<f64>,
    plain_out: Vec<f64>,
}

impl<M: Mechanism> AutoDiff<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Wraps the generated scene `inner`, differentiating the Φ of `scene` (its IR twin).
    ///
    /// # Errors
    /// [`MethodError::Mismatch`] if the two disagree on coordinates or parameters.
    pub fn new(inner: M, scene: &mechgen::Scene) -> Result<Self, MethodError> {
        let model = &scene.model;
        let n = inner.dim().value();
        if model.dim() != n || scene.kinematics.phi.len() != n {
            return Err(MethodError::Mismatch(format!(
                "{} coordinates in the IR, {n} generated",
                model.dim()
            )));
        }
        for (k, name) in model.coordinate_names().iter().enumerate() {
            if inner.coordinate_name(k) != Some(name.as_str()) {
                return Err(MethodError::Mismatch(format!("coordinate {k} is `{name}`")));
            }
        }
        if model.params.len() != inner.parameter_count() {
            return Err(MethodError::Mismatch("parameter count".into()));
        }
        let mut params = Vec::with_capacity(model.params.len());
        for (k, param) in model.params.iter().enumerate() {
            let name = param.name.to_string();
            match (inner.parameter_name(k), inner.parameter(k)) {
                (Some(generated), Some(value)) if generated == name => params.push(value),
                _ => return Err(MethodError::Mismatch(format!("parameter {k} is `{name}`"))),
            }
        }
        let phi = Tape::new(&model.arena, &scene.kinematics.phi);
        let zero = Ad::from_f64(0.0);
        let work = Work {
            q: vec![zero; n],
            slots: phi.scratch_of(),
            out: vec![zero; n],
            plain_slots: phi.scratch(),
            plain_out: vec![0.0; n],
        };
        Ok(Self {
            inner,
            phi,
            params,
            work: RefCell::new(work),
        })
    }

    /// The wrapped scene.
    pub fn inner(&self) -> &M {
        &self.inner
    }

    /// Φ (real parts) and Φ_q (one dual pass per column) at `q`.
    fn differentiate(
        &self,
        q: &Vector<M::Dim>,
        t: f64,
        mut phi: Option<&mut Vector<M::Dim>>,
        jacobian: &mut Matrix<M::Dim>,
    ) {
        let n = self.inner.dim().value();
        // Re-entrancy is impossible here; should it ever happen, fail as non-finite values
        // (which the solver reports) rather than panic.
        let Ok(mut work) = self.work.try_borrow_mut() else {
            jacobian.as_mut_slice().fill(f64::NAN);
            if let Some(phi) = phi {
                phi.as_mut_slice().fill(f64::NAN);
            }
            return;
        };
        let Work {
            q: dual_q,
            slots,
            out,
            ..
        } = &mut *work;
        for (d, &x) in dual_q.iter_mut().zip(q.as_slice()) {
            *d = Ad::from_f64(x);
        }
        let params = &self.params;
        for_each_column(jacobian, self.inner.dim(), |k, column| {
            // Seed coordinate k only: the pass yields ∂Φ/∂q_k.
            if let Some(d) = dual_q.get_mut(k) {
                d.0.eps = 1.0;
            }
            let inputs = Inputs {
                q: dual_q.as_slice(),
                qd: &[],
                qdd: &[],
                trig: &[],
                lambda: &[],
                t,
                params,
                free: &[],
            };
            self.phi.eval_generic(inputs, slots, out);
            if let Some(d) = dual_q.get_mut(k) {
                d.0.eps = 0.0;
            }
            for (c, o) in column.iter_mut().zip(out.iter()) {
                *c = o.0.eps;
            }
            if k == 0
                && let Some(phi) = phi.as_deref_mut()
            {
                for (p, o) in phi.as_mut_slice().iter_mut().zip(out.iter()) {
                    *p = o.0.re;
                }
            }
        });
        if n == 0
            && let Some(phi) = phi
        {
            phi.as_mut_slice().fill(0.0);
        }
    }
}

impl<M: Mechanism> Mechanism for AutoDiff<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    delegate_to_inner!();

    fn set_parameter<'a>(
        &'a mut self,
        name: &'a str,
        value: f64,
    ) -> Result<(), ParameterError<'a>> {
        // The copy first: the inner error borrows the inner mechanism for as long as it lives.
        let index =
            (0..self.inner.parameter_count()).find(|&k| self.inner.parameter_name(k) == Some(name));
        if let (Some(slot), true) = (
            index.and_then(|k| self.params.get_mut(k)),
            value.is_finite(),
        ) {
            *slot = value;
        }
        self.inner.set_parameter(name, value)
    }

    fn phi(&self, q: &Vector<M::Dim>, t: f64, out: &mut Vector<M::Dim>) {
        // The same tape in plain f64: Φ is the differentiated function, not the generated one.
        let Ok(mut work) = self.work.try_borrow_mut() else {
            out.as_mut_slice().fill(f64::NAN);
            return;
        };
        let Work {
            plain_slots,
            plain_out,
            ..
        } = &mut *work;
        let inputs = Inputs {
            q: q.as_slice(),
            qd: &[],
            qdd: &[],
            trig: &[],
            lambda: &[],
            t,
            params: &self.params,
            free: &[],
        };
        self.phi.eval(inputs, plain_slots, plain_out);
        for (o, v) in out.as_mut_slice().iter_mut().zip(plain_out.iter()) {
            *o = *v;
        }
    }

    fn jacobian(&self, q: &Vector<M::Dim>, t: f64, out: &mut Matrix<M::Dim>) {
        self.differentiate(q, t, None, out);
    }

    fn phi_and_jacobian(
        &self,
        q: &Vector<M::Dim>,
        t: f64,
        phi: &mut Vector<M::Dim>,
        jacobian: &mut Matrix<M::Dim>,
    ) {
        self.differentiate(q, t, Some(phi), jacobian);
    }
}

delegate_derivatives!(AutoDiff);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::{FourBar, PistonCrank};
    use mechgen_runtime::nalgebra::Const;

    fn seed_scene() -> mechgen::Scene {
        mechgen::compile(
            mechgen::Input::Text(include_str!("../../scenes/piston_crank.mech")),
            &mechgen::Options::default(),
        )
        .expect("compiles")
    }

    /// Largest |a − b| relative to max(1, |b|) over all entries.
    fn max_difference<const N: usize>(a: &Matrix<Const<N>>, b: &Matrix<Const<N>>) -> f64 {
        a.iter()
            .zip(b.iter())
            .map(|(x, y)| (x - y).abs() / y.abs().max(1.0))
            .fold(0.0, f64::max)
    }

    fn seed_state() -> (Vector<Const<15>>, f64) {
        let exact = crate::closed_form::PistonCrank::default();
        let t = 0.3 * exact.period();
        (Vector::from(exact.q(t)), t)
    }

    #[test]
    fn jacobians_agree_with_the_analytic_one_to_their_order() {
        let (q, t) = seed_state();
        let scene = PistonCrank::default();
        let mut analytic = Matrix::<Const<15>>::zeros();
        let mut phi = Vector::<Const<15>>::zeros();
        scene.phi_and_jacobian(&q, t, &mut phi, &mut analytic);

        let mut other = Matrix::<Const<15>>::zeros();
        let mut other_phi = Vector::<Const<15>>::zeros();
        ForwardDifference::new(scene).phi_and_jacobian(&q, t, &mut other_phi, &mut other);
        assert_eq!(other_phi, phi);
        let forward = max_difference(&other, &analytic);
        assert!(forward < 1e-5 && forward > 0.0, "forward {forward:e}");

        CentralDifference::new(scene).phi_and_jacobian(&q, t, &mut other_phi, &mut other);
        let central = max_difference(&other, &analytic);
        assert!(central < 1e-8 && central < forward, "central {central:e}");

        let ad = AutoDiff::new(scene, &seed_scene()).expect("matches");
        ad.phi_and_jacobian(&q, t, &mut other_phi, &mut other);
        assert!(max_difference(&other, &analytic) < 1e-14);
        assert!((other_phi - phi).amax() < 1e-12);
        let mut plain = Vector::<Const<15>>::zeros();
        ad.phi(&q, t, &mut plain);
        assert_eq!(plain, other_phi);
    }

    #[test]
    fn autodiff_rejects_a_different_scene_and_tracks_parameters() {
        let four_bar = mechgen::compile(
            mechgen::Input::Text(include_str!("../../scenes/four_bar.mech")),
            &mechgen::Options::default(),
        )
        .expect("compiles");
        assert!(matches!(
            AutoDiff::new(PistonCrank::default(), &four_bar),
            Err(MethodError::Mismatch(_))
        ));
        assert!(AutoDiff::new(FourBar::default(), &four_bar).is_ok());

        let mut ad = AutoDiff::new(PistonCrank::default(), &seed_scene()).expect("matches");
        ad.set_parameter("omega", 100.0).expect("known");
        assert_eq!(ad.params, vec![100.0]);
        assert_eq!(ad.parameter(0), Some(100.0));
        assert!(ad.set_parameter("nope", 1.0).is_err());
        assert!(ad.set_parameter("omega", f64::NAN).is_err());
        assert_eq!(ad.params, vec![100.0]);
    }
}
