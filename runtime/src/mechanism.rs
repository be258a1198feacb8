//! The contract between a mechanism's kinematic equations (generated or interpreted) and the solver.

use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OMatrix, OVector};

use crate::geometry::GeometryFault;
use crate::names::Names;

/// A column of coordinates or equation values (`Const<N>` for generated scenes: on the stack).
pub type Vector<D> = OVector<f64, D>;
/// A square matrix over coordinates × equations, such as the Jacobian Φ_q.
pub type Matrix<D> = OMatrix<f64, D, D>;

/// Storage bounds every mechanism dimension satisfies; repeat this where-clause on generic code.
///
/// `DefaultAllocator: Allocator<D> + Allocator<D, D>` holds for every `Const<N>` and, with the
/// `alloc` feature, for `Dyn`.
pub trait Storage<D: Dim>: Allocator<D> + Allocator<D, D> {}
impl<D: Dim, A: Allocator<D> + Allocator<D, D>> Storage<D> for A {}

/// Storage for a scene's marker values ([`Mechanism::Markers`]): `[f64; K]` for a generated
/// scene with K values (`[f64; 0]` without markers), a `Vec` for an interpreted one.
pub trait MarkerStorage:
    AsRef<[f64]> + AsMut<[f64]> + Clone + core::fmt::Debug + Send + Sync
{
}
impl<T: AsRef<[f64]> + AsMut<[f64]> + Clone + core::fmt::Debug + Send + Sync> MarkerStorage for T {}

/// The names of a scene's parameters, in declaration order, as a [`ParameterError`] lists them:
/// a generated scene's `&'static [&'static str]`, or an interpreted scene's strings.
pub trait ParameterNames {
    /// Name `index`; `None` past the end.
    fn parameter_name(&self, index: usize) -> Option<&str>;
}

impl<const N: usize> ParameterNames for [&str; N] {
    fn parameter_name(&self, index: usize) -> Option<&str> {
        self.get(index).copied()
    }
}

#[cfg(feature = "alloc")]
impl ParameterNames for alloc::vec::Vec<alloc::string::String> {
    fn parameter_name(&self, index: usize) -> Option<&str> {
        self.get(index).map(alloc::string::String::as_str)
    }
}

/// Error from setting a parameter by name: it names the parameter, and for an unknown one lists
/// the parameters the scene declares, so that its `Display` says how to fix the call.
#[derive(Clone, Copy)]
pub enum ParameterError<'a> {
    /// No parameter of that name was declared in the scene.
    Unknown {
        /// The name asked for.
        name: &'a str,
        /// The parameters the scene declares.
        declared: &'a dyn ParameterNames,
    },
    /// The value is NaN or infinite (the mechanism is left unchanged).
    NonFinite {
        /// The parameter.
        name: &'a str,
        /// The value refused.
        value: f64,
    },
}

impl ParameterError<'_> {
    /// Whether the name was unknown (as opposed to the value refused).
    pub fn is_unknown(&self) -> bool {
        matches!(self, Self::Unknown { .. })
    }
}

impl core::fmt::Display for ParameterError<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::Unknown { name, declared } => {
                write!(f, "the scene declares no parameter `{name}`")?;
                let names = (0..).map_while(|i| declared.parameter_name(i));
                for (i, declared) in names.enumerate() {
                    let lead = if i == 0 { "; declared: " } else { ", " };
                    write!(f, "{lead}`{declared}`")?;
                }
                if declared.parameter_name(0).is_none() {
                    f.write_str(" (it declares none)")?;
                }
                Ok(())
            }
            Self::NonFinite { name, value } => {
                write!(f, "parameter `{name}` must be a finite number, not {value}")
            }
        }
    }
}

impl core::fmt::Debug for ParameterError<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "ParameterError({self})")
    }
}

impl core::error::Error for ParameterError<'_> {}

/// Which kinematic outputs a scene computes: the spec's `outputs` line (default: all three).
///
/// Ordered: each level includes the ones before it.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[non_exhaustive]
pub enum Outputs {
    /// Positions q only.
    Positions,
    /// Positions and velocities q̇.
    Velocities,
    /// Positions, velocities and accelerations q̈.
    Accelerations,
    /// All three, and the forces that produce the motion: the reaction of every constraint
    /// and the effort of every driver (inverse dynamics).
    Forces,
}

/// Physical dimension of a coordinate or of an equation's value.
///
/// The solver scales by it so that convergence, pivoting and the condition estimate do not depend
/// on the length unit: lengths are divided by the scene's [`Mechanism::length_scale`], areas by
/// its square, angles are left alone. A scene in metres and the same scene in millimetres then
/// take the same Newton steps and report the same condition number. The discriminant is the
/// power of length.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Unit {
    /// Radians (θ coordinates, angle drivers, a prismatic joint's relative angle).
    Angle = 0,
    /// A length (x, y coordinates, point-coincidence equations, position drivers).
    Length = 1,
    /// A length squared (a distance joint's `|d|² − L²`).
    Area = 2,
}

impl Unit {
    /// The power of length this unit carries (0, 1 or 2).
    pub fn length_power(self) -> i32 {
        self as i32
    }
}

/// The scene's length scale L, a power of two (so scaling by it is exact), to the power of each
/// [`Unit`] and its inverse: looked up per coordinate and equation on every solve, so computed
/// once per solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LengthScale {
    powers: [f64; 3],
    inverses: [f64; 3],
}

impl LengthScale {
    /// The scale for a length `length` (a power of two).
    pub fn new(length: f64) -> Self {
        let inverse = 1.0 / length;
        Self {
            powers: [1.0, length, length * length],
            inverses: [1.0, inverse, inverse * inverse],
        }
    }

    /// Lᵖ for a unit of length power p: a value of this unit in scene units times this is
    /// the value in the scene's unit.
    pub fn of(&self, unit: Unit) -> f64 {
        self.powers[unit as usize]
    }

    /// L⁻ᵖ: a value of this unit, in scene units.
    pub fn inverse_of(&self, unit: Unit) -> f64 {
        self.inverses[unit as usize]
    }

    /// The largest L⁻ᵖ of any unit: no value grows more when measured in scene units.
    pub fn largest_inverse(&self) -> f64 {
        self.inverses.iter().fold(1.0, |m, &x| m.max(x))
    }
}

/// The kinematic equations of a planar mechanism in Cartesian body coordinates.
///
/// `q` holds `(x, y, θ)` for every body in declaration order; equations follow the scene's
/// declaration order (ground bodies, joints, drivers). The system is square: `dim()` coordinates and
/// `dim()` equations. Implementations are straight-line code: they must not allocate or panic.
///
/// These are the textbook functions over all coordinates: the reviewable contract, and what the
/// dense reference solve ([`crate::Dense`]) uses. The solver itself follows the scene's solve
/// structure ([`crate::Structured`]). A scene that asked for velocities also implements the
/// marker [`Velocities`] (and [`Mechanism::nu`]), one that asked for accelerations
/// [`Accelerations`] (and [`Mechanism::gamma`]), so asking for an output a scene left out is a
/// compile error, not a run-time one.
pub trait Mechanism
where
    DefaultAllocator: Storage<Self::Dim>,
{
    /// Type-level number of coordinates (= number of equations).
    type Dim: Dim;

    /// Where a solved state keeps the scene's marker values ([`Mechanism::marker_values`]).
    type Markers: MarkerStorage;

    /// The number of coordinates (= number of equations), as a value of the type-level dimension.
    fn dim(&self) -> Self::Dim;

    /// The scene's name tables, which the solver attaches to every [`crate::SolveError`] it
    /// returns so that the error names what failed. The default, [`Names::NONE`], leaves
    /// errors with indices (the names methods below still serve
    /// [`crate::SolveError::describe`]).
    fn names(&self) -> &'static Names {
        &Names::NONE
    }

    /// Name of coordinate `index`, such as `"piston.x"`; `None` past the end.
    fn coordinate_name(&self, index: usize) -> Option<&str>;

    /// Name of equation `index`, such as `"crank_pin.x"`; `None` past the end.
    fn equation_name(&self, index: usize) -> Option<&str>;

    /// Number of run-time parameters the scene declared.
    fn parameter_count(&self) -> usize;

    /// Name of parameter `index`; `None` past the end.
    fn parameter_name(&self, index: usize) -> Option<&str>;

    /// Current value of parameter `index`; `None` past the end.
    fn parameter(&self, index: usize) -> Option<f64>;

    /// Sets a parameter by name.
    ///
    /// # Errors
    /// [`ParameterError::Unknown`] if no parameter has that name (listing the declared ones),
    /// [`ParameterError::NonFinite`] for NaN or infinite values (the mechanism is left
    /// unchanged).
    fn set_parameter<'a>(&'a mut self, name: &'a str, value: f64)
    -> Result<(), ParameterError<'a>>;

    /// Physical dimension of coordinate `index` (past the end: [`Unit::Angle`], unscaled).
    fn coordinate_unit(&self, index: usize) -> Unit;

    /// Physical dimension of equation `index` (past the end: [`Unit::Angle`], unscaled).
    fn equation_unit(&self, index: usize) -> Unit;

    /// The scene's characteristic length with the current parameters: the largest magnitude
    /// among its geometric lengths (body-fixed points, distances, ground positions). The solver
    /// measures lengths relative to it; it is only a scale, so any value within a few orders of
    /// magnitude of the mechanism's size works. Zero or non-finite values make the solver fall
    /// back to 1.
    fn length_scale(&self) -> f64;

    /// Checks the geometry written in parameters (body-fixed points, distances, ground poses,
    /// prismatic axes) against its rules with the current parameter values; the solver calls
    /// it before every solve. Scenes whose geometry is constant have nothing to check (the
    /// default), having been checked at compile time.
    ///
    /// # Errors
    /// A [`GeometryFault`] for the first value that breaks its rule.
    fn check_geometry(&self) -> Result<(), GeometryFault> {
        Ok(())
    }

    /// Checks the mass properties and load constants written in parameters (masses,
    /// inertias, centres of mass, spring constants, load points) against the compile-time
    /// rules for constants, with the current parameter values; the solver calls it before
    /// every solve, after [`Mechanism::check_geometry`]. Scenes whose physics is constant have
    /// nothing to check (the default).
    ///
    /// # Errors
    /// A [`crate::PhysicsFault`] for the first value that breaks its rule.
    fn check_physics(&self) -> Result<(), crate::PhysicsFault> {
        Ok(())
    }

    /// Number of branch invariants the scene declares (`branch NAME: …;` in the spec).
    ///
    /// A branch invariant is a quantity whose sign tells two assembly branches apart (e.g. the
    /// cross product of two links of a loop); the solver refuses a solution where one has the
    /// wrong sign rather than stepping silently onto the mirror branch.
    fn branch_count(&self) -> usize {
        0
    }

    /// Name of branch invariant `index`; `None` past the end.
    fn branch_name(&self, _index: usize) -> Option<&str> {
        None
    }

    /// Value of branch invariant `index` at `q`, signed so that it is positive on the declared
    /// branch; NaN past the end.
    fn branch_value(&self, _index: usize, _q: &Vector<Self::Dim>) -> f64 {
        f64::NAN
    }

    /// Writes the scene's initial guess (ground poses and the moving bodies' declared guesses).
    fn initial_guess(&self, q: &mut Vector<Self::Dim>);

    /// Writes the constraint vector Φ(q, t).
    fn phi(&self, q: &Vector<Self::Dim>, t: f64, out: &mut Vector<Self::Dim>);

    /// Writes the Jacobian Φ_q(q, t); every entry is overwritten (structural zeros included).
    fn jacobian(&self, q: &Vector<Self::Dim>, t: f64, out: &mut Matrix<Self::Dim>);

    /// Writes Φ and Φ_q together; generated code overrides this to share sub-expressions.
    fn phi_and_jacobian(
        &self,
        q: &Vector<Self::Dim>,
        t: f64,
        phi: &mut Vector<Self::Dim>,
        jacobian: &mut Matrix<Self::Dim>,
    ) {
        self.phi(q, t, phi);
        self.jacobian(q, t, jacobian);
    }

    /// The outputs this scene computes.
    fn outputs(&self) -> Outputs;

    /// Writes the velocity right-hand side ν = −Φ_t, so that Φ_q q̇ = ν.
    ///
    /// Scenes that compute velocities ([`Outputs::Velocities`] or more) implement it; the
    /// default writes NaN, and the solver never asks a scene for an output it did not declare.
    fn nu(&self, _q: &Vector<Self::Dim>, _t: f64, out: &mut Vector<Self::Dim>) {
        out.as_mut_slice().fill(f64::NAN);
    }

    /// Writes the acceleration right-hand side γ = −(Φ_q q̇)_q q̇ − 2 Φ_qt q̇ − Φ_tt, so that
    /// Φ_q q̈ = γ.
    ///
    /// Scenes that compute accelerations implement it; the default writes NaN.
    fn gamma(
        &self,
        _q: &Vector<Self::Dim>,
        _qd: &Vector<Self::Dim>,
        _t: f64,
        out: &mut Vector<Self::Dim>,
    ) {
        out.as_mut_slice().fill(f64::NAN);
    }

    /// Writes the generalised applied and inertial forces `F = Q(q, q̇, t) − M q̈ − (velocity
    /// terms)`, per coordinate: gravity, the scene's loads and springs, and the inertia of its
    /// masses. The constraint forces balance them: `Φ_qᵀ λ = F` ([`Forces`]).
    ///
    /// Scenes that compute forces implement it; the default writes NaN.
    fn generalized_forces(
        &self,
        _q: &Vector<Self::Dim>,
        _qd: &Vector<Self::Dim>,
        _qdd: &Vector<Self::Dim>,
        _t: f64,
        out: &mut Vector<Self::Dim>,
    ) {
        out.as_mut_slice().fill(f64::NAN);
    }

    /// Writes the reported reaction of every equation from the Lagrange multipliers `lambda`
    /// (`Φ_qᵀ λ = F`) at positions `q` and velocities `qd`: for a revolute joint the force in world axes that its
    /// second body exerts on its first, for a prismatic joint the normal force and the torque
    /// on its first body, for a distance joint the tension, for a driver its effort, and for a
    /// ground body the force (world axes) and torque (about its reference point) the mechanism
    /// exerts on it through its joints, drivers and springs. [`Mechanism::reaction_name`] names
    /// each.
    ///
    /// Scenes that compute forces implement it; the default writes NaN.
    fn reactions(
        &self,
        _q: &Vector<Self::Dim>,
        _qd: &Vector<Self::Dim>,
        _lambda: &[f64],
        out: &mut Vector<Self::Dim>,
    ) {
        out.as_mut_slice().fill(f64::NAN);
    }

    /// Fresh storage for the marker values (zeros).
    fn marker_storage(&self) -> Self::Markers;

    /// Writes the values of the scene's markers (`marker NAME: body @ (x, y);`: a point's world
    /// position, `marker NAME: angle(a, b);`: `θ_b − θ_a`) and of their rates, as far as the
    /// scene computes rates, at the state `(q, q̇, q̈)`; [`Mechanism::marker_name`] names each.
    /// The default writes nothing (a scene without markers).
    fn marker_values(
        &self,
        _q: &Vector<Self::Dim>,
        _qd: &Vector<Self::Dim>,
        _qdd: &Vector<Self::Dim>,
        _t: f64,
        _out: &mut Self::Markers,
    ) {
    }

    /// Name of marker value `index` (`tip.x`, `tip.y`, `tip.x_dot`, …, `swing.angle`, …); `None`
    /// past the end.
    fn marker_name(&self, _index: usize) -> Option<&str> {
        None
    }

    /// On the force solve's failure path, with F not finite: the first load whose force or
    /// moment is not, at the state `(q, q̇)` and `t` ([`crate::Quantity::LoadValue`], or
    /// [`crate::Quantity::SpringEnds`] for a spring whose ends meet), so that the error names
    /// it. The default finds none (F is then blamed as a whole: the masses' inertia).
    fn load_fault(
        &self,
        _q: &Vector<Self::Dim>,
        _qd: &Vector<Self::Dim>,
        _t: f64,
    ) -> Option<crate::Quantity> {
        None
    }

    /// Name of the reaction [`Mechanism::reactions`] writes for equation `index`, such as
    /// `"crank_pin.fx"` or `"crank_angle.effort"`; `None` past the end or for a scene that does
    /// not compute forces.
    fn reaction_name(&self, _index: usize) -> Option<&str> {
        None
    }
}

/// Marks a scene that computes velocities (implements [`Mechanism::nu`]): [`crate::State::qd`]
/// and the velocity accessors exist only for such scenes, so asking a positions-only scene for
/// velocities is a compile error.
pub trait Velocities: Mechanism
where
    DefaultAllocator: Storage<Self::Dim>,
{
}

/// Marks a scene that computes accelerations (implements [`Mechanism::gamma`]).
pub trait Accelerations: Velocities
where
    DefaultAllocator: Storage<Self::Dim>,
{
}

/// Marks a scene that computes forces (implements [`Mechanism::generalized_forces`],
/// [`Mechanism::reactions`] and [`Mechanism::reaction_name`]): its mass properties, gravity and
/// loads, with the solved motion, give the reaction of every constraint and the effort of
/// every driver from one more linear solve with the transposed Jacobian, `Φ_qᵀ λ = F`.
/// [`crate::State::constraint_forces`] exists only for such scenes.
pub trait Forces: Accelerations
where
    DefaultAllocator: Storage<Self::Dim>,
{
}
