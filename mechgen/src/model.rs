//! The model: a checked spec with names resolved to indices and every value lowered to the IR.
//!
//! Built only by `check`, so everything here is known to be consistent: bodies exist, the
//! system is square (drivers match the degrees of freedom), geometry does not depend on time.

use syn::{Attribute, Ident, Visibility};

use crate::expr::{Arena, Id};

/// The checked mechanism.
#[derive(Clone)]
pub struct Model {
    /// Doc comments for the generated struct.
    pub docs: Vec<Attribute>,
    /// Visibility of the generated items.
    pub vis: Visibility,
    /// Name of the generated struct.
    pub name: Ident,
    /// The IR holding every expression of the model (and, after `kinematics`, its derivatives).
    pub arena: Arena,
    /// Run-time parameters, by index.
    pub params: Vec<Param>,
    /// Bodies in q order: body i owns coordinates 3i, 3i+1, 3i+2.
    pub bodies: Vec<Body>,
    /// Constraints in equation order: ground bodies, then joints, then drivers.
    pub constraints: Vec<Constraint>,
    /// What the scene asked to compute.
    pub outputs: Outputs,
}

/// Which kinematic outputs a scene computes (the spec's `outputs` line; default all three).
/// Ordered: each level includes the ones before it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Outputs {
    /// Positions only.
    Positions,
    /// Positions and velocities.
    Velocities,
    /// Positions, velocities and accelerations.
    Accelerations,
}

impl Outputs {
    /// Every level, in order; `ALL[k]` is named `NAMES[k]` in specs.
    pub const ALL: [Outputs; 3] = [
        Outputs::Positions,
        Outputs::Velocities,
        Outputs::Accelerations,
    ];
    /// The names used in the `outputs` statement.
    pub const NAMES: [&'static str; 3] = ["positions", "velocities", "accelerations"];
}

/// A run-time parameter.
#[derive(Clone)]
pub struct Param {
    /// Name (also the generated field).
    pub name: Ident,
    /// Doc comments.
    pub docs: Vec<Attribute>,
    /// Default value.
    pub default: f64,
}

/// A body.
#[derive(Clone)]
pub struct Body {
    /// Name (also the generated accessor).
    pub name: Ident,
    /// Doc comments.
    pub docs: Vec<Attribute>,
    /// Fixed by three ground equations.
    pub ground: bool,
    /// Ground pose or initial guess, as expressions in parameters.
    pub pose: [Id; 3],
}

/// A point fixed to a body: body-frame coordinates as expressions in parameters.
#[derive(Clone, Copy)]
pub struct Point {
    /// Body index.
    pub body: usize,
    /// Body-frame coordinates.
    pub local: [Id; 2],
}

/// One named constraint, contributing one or more equations.
#[derive(Clone)]
pub struct Constraint {
    /// Name as declared (the body's name for ground equations).
    pub name: String,
    /// What it constrains.
    pub kind: ConstraintKind,
}

/// The constraint library; each is only its Φ (see `kinematics`).
#[derive(Clone, Copy)]
pub enum ConstraintKind {
    /// Body fixed at a pose: x − x0, y − y0, θ − θ0.
    Ground {
        /// Body index.
        body: usize,
        /// Pose (x0, y0, θ0).
        pose: [Id; 3],
    },
    /// Two points coincide.
    Revolute {
        /// Point on the first body.
        a: Point,
        /// Point on the second body.
        b: Point,
    },
    /// `b`'s point on the line through `a`'s point along `a`-fixed unit `axis`; no rotation.
    Prismatic {
        /// Point on the guiding body.
        a: Point,
        /// Point on the sliding body.
        b: Point,
        /// Unit axis in the guiding body's frame.
        axis: [Id; 2],
    },
    /// Two points stay `length` apart.
    Distance {
        /// Point on the first body.
        a: Point,
        /// Point on the second body.
        b: Point,
        /// The distance.
        length: Id,
    },
    /// A driven quantity equals `value(t)`.
    Driver {
        /// The driven quantity.
        driven: Driven,
        /// The prescribed value, an expression in t and parameters.
        value: Id,
    },
}

/// The quantity a driver prescribes.
#[derive(Clone, Copy)]
pub enum Driven {
    /// θ of a body.
    Angle(usize),
    /// θ_b − θ_a.
    RelativeAngle(usize, usize),
    /// Global x of a point.
    X(Point),
    /// Global y of a point.
    Y(Point),
    /// Travel of a prismatic joint's slider along its unit axis.
    Travel {
        /// Point on the guiding body.
        a: Point,
        /// Point on the sliding body.
        b: Point,
        /// Unit axis in the guiding body's frame.
        axis: [Id; 2],
    },
}

impl ConstraintKind {
    /// Suffixes naming this constraint's equations (`pin.x`, `pin.y`, …); empty for one equation.
    pub fn equation_suffixes(&self) -> &'static [&'static str] {
        match self {
            ConstraintKind::Ground { .. } => &["x", "y", "theta"],
            ConstraintKind::Revolute { .. } => &["x", "y"],
            ConstraintKind::Prismatic { .. } => &["normal", "angle"],
            ConstraintKind::Distance { .. } | ConstraintKind::Driver { .. } => &[""],
        }
    }
}

/// Names of a body's coordinates, in q order.
pub const COORDINATE_SUFFIXES: [&str; 3] = ["x", "y", "theta"];

impl Model {
    /// Number of coordinates (= number of equations, checked).
    pub fn dim(&self) -> usize {
        3 * self.bodies.len()
    }

    /// Coordinate names in q order: `piston.x`, `piston.y`, `piston.theta`, …
    pub fn coordinate_names(&self) -> Vec<String> {
        self.bodies
            .iter()
            .flat_map(|b| COORDINATE_SUFFIXES.map(|s| format!("{}.{s}", b.name)))
            .collect()
    }

    /// Equation names in Φ order: `liner.x`, …, `crank_pin.x`, …, `crank`.
    pub fn equation_names(&self) -> Vec<String> {
        self.constraints
            .iter()
            .flat_map(|c| {
                c.kind.equation_suffixes().iter().map(move |s| {
                    if s.is_empty() {
                        c.name.clone()
                    } else {
                        format!("{}.{s}", c.name)
                    }
                })
            })
            .collect()
    }

    /// Number of drivers (the mechanism's degrees of freedom, checked).
    pub fn driver_count(&self) -> usize {
        self.constraints
            .iter()
            .filter(|c| matches!(c.kind, ConstraintKind::Driver { .. }))
            .count()
    }
}
