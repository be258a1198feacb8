//! A solved kinematic state, per-body views of it, and heap-free CSV output.

use core::fmt::{self, Write};
use core::marker::PhantomData;

use nalgebra::{DefaultAllocator, Dim};

use crate::mechanism::{Accelerations, Forces, Mechanism, Outputs, Storage, Vector, Velocities};

/// Positions (and the derivatives the scene provides) of a mechanism at time `t`.
///
/// Typed by the mechanism (not just its dimension) so generated code can add named accessors
/// such as `state.piston()` for its own scene only, and so that [`State::qd`] and
/// [`State::qdd`] exist only for scenes that compute velocities and accelerations: reading an
/// output the scene left out is a compile error.
///
/// ```
/// # use mechgen_runtime::mechanism;
/// # mechanism! {
/// #     /// A slider-crank (mm, rad, s).
/// #     pub mechanism SliderCrank {
/// #         param omega = 10.0;
/// #         ground frame at (0, 0, 0);
/// #         body crank near (0, 0, 0.5);
/// #         body rod near (35, 19, -0.19);
/// #         body slider near (133, 0, 0);
/// #         joint pivot: revolute(frame, crank);
/// #         joint crank_pin: revolute(crank @ (40, 0), rod);
/// #         joint wrist: revolute(rod @ (100, 0), slider);
/// #         joint guide: prismatic(frame, slider, along (1, 0));
/// #         driver turn: angle(crank) = 0.5 + omega * t;
/// #     }
/// # }
/// use mechgen_runtime::{Simulation, Solver, write_csv_header};
///
/// let simulation = Simulation::new(Solver::new(SliderCrank::default()), 0.0)?;
/// let state = simulation.state();
/// // Named access through the scene's generated trait, or by index.
/// let rod = state.rod();
/// assert_eq!(rod.theta, state.q[SliderCrank::ROD_THETA]);
/// assert_eq!(rod.theta_dot, state.qd()[SliderCrank::ROD_THETA]);
/// // One CSV row without a heap (any `core::fmt::Write`).
/// let mut csv = String::new();
/// write_csv_header(simulation.solver().mechanism(), &mut csv).unwrap();
/// state.write_csv_row(&mut csv).unwrap();
/// assert!(csv.starts_with("t,frame.x,"));
/// # Ok::<(), mechgen_runtime::SolveError>(())
/// ```
pub struct State<M: Mechanism>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Time.
    pub t: f64,
    /// Positions q.
    pub q: Vector<M::Dim>,
    /// Velocities q̇ (zero unless the scene computes them).
    pub(crate) velocities: Vector<M::Dim>,
    /// Accelerations q̈ (zero unless the scene computes them).
    pub(crate) accelerations: Vector<M::Dim>,
    /// The reaction of every equation (zero unless the scene computes forces).
    pub(crate) reactions: Vector<M::Dim>,
    /// The marker values (empty for a scene without markers).
    pub(crate) markers: M::Markers,
    /// Newton updates the position solve needed: the most any block needed (summed over
    /// sub-steps, if any).
    pub iterations: usize,
    /// Evaluations and factorisations of block Jacobians, summed over the blocks (and
    /// sub-steps): one per Newton update, plus one at the solution for a block whose last
    /// correction was not of round-off size (see [`crate::Convergence::evaluations`]).
    pub evaluations: usize,
    /// Time steps this state took: 1, or more when [`crate::Simulation`] had to sub-step the
    /// drivers to get here (0 for a state not reached by stepping).
    pub substeps: usize,
    /// Largest condition estimate κ₁ of the unit-scaled block Jacobians at `q` (see
    /// [`crate::Lu::condition_estimate`]);
    /// large near toggle positions. NaN when the solver's estimate is switched off.
    pub condition: f64,
    /// Block factorisations whose static pivots were too small and were redone with partial
    /// pivoting (see [`crate::SolverOptions::static_pivot_threshold`]), summed over sub-steps.
    pub fallbacks: usize,
    /// Blocks the last position solve started from their closed-form solution
    /// ([`crate::Convergence::closed_forms`]).
    pub closed_forms: usize,
    /// The sign of det Φ_q at `q` (unit-scaled, in the scene's solve order): +1 or −1. Two
    /// states of one motion with different signs have a singular configuration (a toggle or
    /// change point) between them ([`crate::Convergence::orientation`]).
    pub orientation: i8,
    /// Which blocks have a negative determinant, as a signature
    /// ([`crate::Convergence::block_signs`]): a step that flips two blocks keeps
    /// `orientation` but changes this.
    pub(crate) block_signs: u64,
    /// Whether the solve's Newton iterates crossed a singular configuration
    /// ([`crate::Convergence::swept`]).
    pub(crate) swept: bool,
    /// What the scene computes, which decides the CSV columns.
    outputs: Outputs,
    // `fn() -> M` keeps `State` Send/Sync/Clone regardless of `M`.
    mechanism: PhantomData<fn() -> M>,
}

/// One body's pose.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Reference point x.
    pub x: f64,
    /// Reference point y.
    pub y: f64,
    /// Orientation θ (radians).
    pub theta: f64,
}

/// One body's pose and velocity.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseVelocity {
    /// Reference point x.
    pub x: f64,
    /// Reference point y.
    pub y: f64,
    /// Orientation θ (radians).
    pub theta: f64,
    /// ẋ.
    pub x_dot: f64,
    /// ẏ.
    pub y_dot: f64,
    /// θ̇.
    pub theta_dot: f64,
}

/// One body's pose and its first two time derivatives.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyState {
    /// Reference point x.
    pub x: f64,
    /// Reference point y.
    pub y: f64,
    /// Orientation θ (radians).
    pub theta: f64,
    /// ẋ.
    pub x_dot: f64,
    /// ẏ.
    pub y_dot: f64,
    /// θ̇.
    pub theta_dot: f64,
    /// ẍ.
    pub x_ddot: f64,
    /// ÿ.
    pub y_ddot: f64,
    /// θ̈.
    pub theta_ddot: f64,
}

/// Coordinates `3·index .. 3·index + 2` of `v`; `None` past the end.
fn read3<D: Dim>(v: &Vector<D>, index: usize) -> Option<[f64; 3]>
where
    DefaultAllocator: Storage<D>,
{
    let first = index.checked_mul(3)?;
    let slice = v.as_slice().get(first..first.checked_add(3)?)?;
    Some([slice[0], slice[1], slice[2]])
}

impl<M: Mechanism> State<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// An all-zero state at `t = 0` for `mechanism` (allocates for `Dyn`, lives on the stack
    /// for `Const`).
    pub fn new(mechanism: &M) -> Self {
        let dim = mechanism.dim();
        Self {
            t: 0.0,
            q: Vector::zeros_generic(dim, nalgebra::U1),
            velocities: Vector::zeros_generic(dim, nalgebra::U1),
            accelerations: Vector::zeros_generic(dim, nalgebra::U1),
            // NaN until a force solve writes them: a scene without forces has none.
            reactions: Vector::from_element_generic(dim, nalgebra::U1, f64::NAN),
            markers: mechanism.marker_storage(),
            iterations: 0,
            substeps: 0,
            condition: f64::NAN,
            evaluations: 0,
            fallbacks: 0,
            closed_forms: 0,
            orientation: 1,
            block_signs: 0,
            swept: false,
            outputs: mechanism.outputs(),
            mechanism: PhantomData,
        }
    }

    /// Copies `other` into `self` without allocating (both hold vectors of the same length).
    pub(crate) fn copy_from(&mut self, other: &Self) {
        self.t = other.t;
        self.q.copy_from(&other.q);
        self.velocities.copy_from(&other.velocities);
        self.accelerations.copy_from(&other.accelerations);
        self.reactions.copy_from(&other.reactions);
        let (ours, theirs) = (self.markers.as_mut(), other.markers.as_ref());
        if ours.len() == theirs.len() {
            ours.copy_from_slice(theirs);
        }
        self.iterations = other.iterations;
        self.substeps = other.substeps;
        self.condition = other.condition;
        self.evaluations = other.evaluations;
        self.fallbacks = other.fallbacks;
        self.closed_forms = other.closed_forms;
        self.orientation = other.orientation;
        self.block_signs = other.block_signs;
        self.swept = other.swept;
    }

    /// The outputs this state holds (its scene's).
    pub fn outputs(&self) -> Outputs {
        self.outputs
    }

    /// The values of the scene's markers ([`Mechanism::marker_values`], named by
    /// [`Mechanism::marker_name`]); the scene's generated accessors read them by name
    /// (`state.tip().x`). Empty for a scene without markers.
    pub fn marker_values(&self) -> &[f64] {
        self.markers.as_ref()
    }

    /// Pose of body `index` (declaration order); `None` past the end.
    pub fn pose(&self, index: usize) -> Option<Pose> {
        let [x, y, theta] = read3(&self.q, index)?;
        Some(Pose { x, y, theta })
    }

    /// Writes `t`, then q (and q̇, q̈ when the scene computes them), the marker values, and the
    /// reaction of every equation when the scene computes forces, as one CSV line ending in
    /// `\n`, matching [`write_csv_header`].
    ///
    /// Numbers are the shortest strings that parse back to the same value, with an exponent
    /// for tiny and huge magnitudes (`5.2e-30`), and −0 written as `0.0` (a sign where there is
    /// none only confuses a reader). A NaN or infinity (which a successful solve never
    /// produces) is written as `NaN`/`inf`/`-inf`, which float parsers accept.
    ///
    /// # Errors
    /// Whatever `out` returns.
    pub fn write_csv_row<W: Write>(&self, out: &mut W) -> fmt::Result {
        // `x + 0.0` is `x`, except that −0 becomes +0.
        write!(out, "{:?}", self.t + 0.0)?;
        let groups = column_groups(self.outputs);
        let kinematics = [&self.q, &self.velocities, &self.accelerations];
        let forces = (groups > kinematics.len()).then_some(self.reactions.as_slice());
        let columns = kinematics
            .iter()
            .take(groups)
            .map(|v| v.as_slice())
            .chain([self.markers.as_ref()])
            .chain(forces);
        for column in columns {
            for value in column {
                write!(out, ",{:?}", value + 0.0)?;
            }
        }
        out.write_char('\n')
    }
}

impl<M: Velocities> State<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Velocities q̇.
    pub fn qd(&self) -> &Vector<M::Dim> {
        &self.velocities
    }

    /// Pose and velocity of body `index`; `None` past the end.
    pub fn pose_velocity(&self, index: usize) -> Option<PoseVelocity> {
        let [x, y, theta] = read3(&self.q, index)?;
        let [x_dot, y_dot, theta_dot] = read3(&self.velocities, index)?;
        Some(PoseVelocity {
            x,
            y,
            theta,
            x_dot,
            y_dot,
            theta_dot,
        })
    }
}

impl<M: Accelerations> State<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// Accelerations q̈.
    pub fn qdd(&self) -> &Vector<M::Dim> {
        &self.accelerations
    }

    /// Pose, velocity and acceleration of body `index`; `None` past the end.
    pub fn body(&self, index: usize) -> Option<BodyState> {
        let [x, y, theta] = read3(&self.q, index)?;
        let [x_dot, y_dot, theta_dot] = read3(&self.velocities, index)?;
        let [x_ddot, y_ddot, theta_ddot] = read3(&self.accelerations, index)?;
        Some(BodyState {
            x,
            y,
            theta,
            x_dot,
            y_dot,
            theta_dot,
            x_ddot,
            y_ddot,
            theta_ddot,
        })
    }
}

impl<M: Forces> State<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    /// The reaction of every equation, in Φ order ([`Mechanism::reactions`] says what each is
    /// and [`Mechanism::reaction_name`] names it): the scene's generated `reactions()` and
    /// `efforts()` read them by name.
    pub fn constraint_forces(&self) -> &Vector<M::Dim> {
        &self.reactions
    }
}

/// Number of CSV column groups (q; q, q̇; q, q̇, q̈; and the reactions) for a scene's outputs.
fn column_groups(outputs: Outputs) -> usize {
    match outputs {
        Outputs::Positions => 1,
        Outputs::Velocities => 2,
        Outputs::Accelerations => 3,
        Outputs::Forces => 4,
    }
}

/// Writes the CSV header line: `t`, every coordinate name, then (when the scene computes them)
/// the names with `_dot`, then with `_ddot` (`t,piston.x,…,piston.x_dot,…,piston.x_ddot,…\n`),
/// then every marker value by its [`Mechanism::marker_name`] (`tip.x`, `tip.y`, `tip.x_dot`,
/// …), then, when it computes forces, every equation's reaction by its
/// [`Mechanism::reaction_name`] (`crank_pin.fx`, …, `crank_angle.effort`).
///
/// A coordinate without a name is written as `q<index>`, a reaction as `reaction<index>`.
///
/// # Errors
/// Whatever `out` returns.
pub fn write_csv_header<M: Mechanism, W: Write>(mechanism: &M, out: &mut W) -> fmt::Result
where
    DefaultAllocator: Storage<M::Dim>,
{
    out.write_char('t')?;
    let n = mechanism.dim().value();
    let groups = column_groups(mechanism.outputs());
    let suffixes = ["", "_dot", "_ddot"];
    for suffix in suffixes.iter().take(groups) {
        for index in 0..n {
            match mechanism.coordinate_name(index) {
                Some(name) => write!(out, ",{name}{suffix}")?,
                None => write!(out, ",q{index}{suffix}")?,
            }
        }
    }
    for name in (0..).map_while(|index| mechanism.marker_name(index)) {
        write!(out, ",{name}")?;
    }
    if groups > suffixes.len() {
        for index in 0..n {
            match mechanism.reaction_name(index) {
                Some(name) => write!(out, ",{name}")?,
                None => write!(out, ",reaction{index}")?,
            }
        }
    }
    out.write_char('\n')
}

impl<M: Mechanism> Clone for State<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn clone(&self) -> Self {
        Self {
            t: self.t,
            q: self.q.clone(),
            velocities: self.velocities.clone(),
            accelerations: self.accelerations.clone(),
            reactions: self.reactions.clone(),
            markers: self.markers.clone(),
            iterations: self.iterations,
            substeps: self.substeps,
            condition: self.condition,
            evaluations: self.evaluations,
            fallbacks: self.fallbacks,
            closed_forms: self.closed_forms,
            orientation: self.orientation,
            block_signs: self.block_signs,
            swept: self.swept,
            outputs: self.outputs,
            mechanism: PhantomData,
        }
    }
}

impl<M: Mechanism> fmt::Debug for State<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("State")
            .field("t", &self.t)
            .field("q", &self.q.as_slice())
            .field("qd", &self.velocities.as_slice())
            .field("qdd", &self.accelerations.as_slice())
            .field("reactions", &self.reactions.as_slice())
            .field("markers", &self.markers.as_ref())
            .field("iterations", &self.iterations)
            .field("substeps", &self.substeps)
            .field("condition", &self.condition)
            .field("evaluations", &self.evaluations)
            .field("fallbacks", &self.fallbacks)
            .field("closed_forms", &self.closed_forms)
            .field("orientation", &self.orientation)
            .field("outputs", &self.outputs)
            .finish()
    }
}

/// `{"t", "q", "q_dot", "q_ddot", "markers", "reactions", "iterations", "evaluations",
/// "substeps", "condition", "fallbacks", "det_sign"}`, with `q_dot`, `q_ddot`, `markers` and
/// `reactions` only for scenes that compute them (as the CSV columns) and `condition` `null`
/// when not estimated (serde_json writes NaN as `null`).
#[cfg(feature = "serde")]
impl<M: Mechanism> serde::Serialize for State<M>
where
    DefaultAllocator: Storage<M::Dim>,
{
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let groups = column_groups(self.outputs);
        let mut s = serializer.serialize_struct("State", 8 + groups)?;
        s.serialize_field("t", &self.t)?;
        s.serialize_field("q", self.q.as_slice())?;
        if groups >= 2 {
            s.serialize_field("q_dot", self.velocities.as_slice())?;
        } else {
            s.skip_field("q_dot")?;
        }
        if groups >= 3 {
            s.serialize_field("q_ddot", self.accelerations.as_slice())?;
        } else {
            s.skip_field("q_ddot")?;
        }
        let markers = self.markers.as_ref();
        if markers.is_empty() {
            s.skip_field("markers")?;
        } else {
            s.serialize_field("markers", markers)?;
        }
        if groups >= 4 {
            s.serialize_field("reactions", self.reactions.as_slice())?;
        } else {
            s.skip_field("reactions")?;
        }
        s.serialize_field("iterations", &self.iterations)?;
        s.serialize_field("evaluations", &self.evaluations)?;
        s.serialize_field("substeps", &self.substeps)?;
        s.serialize_field("condition", &self.condition)?;
        s.serialize_field("fallbacks", &self.fallbacks)?;
        s.serialize_field("det_sign", &self.orientation)?;
        s.end()
    }
}
