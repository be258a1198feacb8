//! The model: a checked spec with names resolved to indices and every value lowered to the IR.
//!
//! Built only by `check`, so everything here is known to be consistent: bodies exist, the
//! system is square (drivers match the degrees of freedom), geometry does not depend on time.
//!
//! What is derived from it: body frames as every stage writes through them (`frames`), the
//! constraint equations and their derivatives ([`kinematics`]), marker values ([`markers`]),
//! the generalised forces ([`dynamics`]), the equations of motion and the energies
//! ([`motion`], [`energy`]), and the run-time rules on geometry and mass properties written in
//! parameters ([`geometry`], [`physics`]).

pub mod dynamics;
pub mod energy;
mod frames;
pub mod geometry;
pub mod kinematics;
pub mod markers;
pub mod motion;
pub mod physics;

use syn::{Attribute, Ident, Visibility};

use crate::expr::{Arena, Id};
pub use crate::syntax::spec::{Product, Sign};

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
    /// Derived parameters (`param c = sqrt(a^2 + b^2);`), in declaration order: expressions of
    /// the run-time parameters, substituted wherever they are used (so they follow any change
    /// of those), and not settable themselves.
    pub derived: Vec<Derived>,
    /// Bodies in q order: body i owns coordinates 3i, 3i+1, 3i+2.
    pub bodies: Vec<Body>,
    /// Constraints in equation order: ground bodies, then joints, then drivers.
    pub constraints: Vec<Constraint>,
    /// Branch invariants in declaration order (their values are derived by `kinematics`).
    pub branches: Vec<Branch>,
    /// The acceleration of gravity in world axes (zero unless declared).
    pub gravity: [Id; 2],
    /// Applied loads in declaration order.
    pub loads: Vec<Load>,
    /// Markers in declaration order.
    pub markers: Vec<Marker>,
    /// What the scene asked to compute.
    pub outputs: Outputs,
    /// Free degrees of freedom in declaration order (each a [`ConstraintKind::Driver`] whose
    /// value is its [`Node::Free`](crate::expr::Node::Free) state).
    pub frees: Vec<Free>,
}

/// A free degree of freedom: a driver whose value `u` is the integrator's state.
#[derive(Clone)]
pub struct Free {
    /// Name as declared (its equation's name; its reaction is `NAME.effort`).
    pub name: Ident,
    /// Its driver's index in [`Model::constraints`].
    pub constraint: usize,
    /// The declared initial value, in parameters (`None`: the assembled guess's).
    pub from: Option<Id>,
    /// The declared initial rate, in parameters (0 unless declared).
    pub speed: Id,
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
    /// All three, and the reactions and driver efforts that produce the motion.
    Forces,
}

impl Outputs {
    /// Every level, in order; `ALL[k]` is named `NAMES[k]` in specs.
    pub const ALL: [Outputs; 4] = [
        Outputs::Positions,
        Outputs::Velocities,
        Outputs::Accelerations,
        Outputs::Forces,
    ];
    /// The names used in the `outputs` statement.
    pub const NAMES: [&'static str; 4] = ["positions", "velocities", "accelerations", "forces"];

    /// The variant's name (`Positions`, …), as in `mechgen_runtime::Outputs`.
    pub fn name(self) -> &'static str {
        match self {
            Outputs::Positions => "Positions",
            Outputs::Velocities => "Velocities",
            Outputs::Accelerations => "Accelerations",
            Outputs::Forces => "Forces",
        }
    }
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

/// A derived parameter: a name for an expression of the run-time parameters.
#[derive(Clone)]
pub struct Derived {
    /// Name (also the generated accessor method).
    pub name: Ident,
    /// Doc comments.
    pub docs: Vec<Attribute>,
    /// Its value, in the run-time parameters.
    pub value: Id,
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
    /// Mass properties of a moving body, if declared (massless otherwise).
    pub mass: Option<MassProperties>,
}

/// A moving body's mass properties, as expressions in parameters.
#[derive(Clone, Copy)]
pub struct MassProperties {
    /// The mass.
    pub mass: Id,
    /// The moment of inertia about the centre of mass.
    pub inertia: Id,
    /// The centre of mass in the body's frame.
    pub centre: [Id; 2],
}

/// A named output computed from the solved state.
#[derive(Clone)]
pub struct Marker {
    /// Name as declared.
    pub name: String,
    /// Doc comments.
    pub docs: Vec<Attribute>,
    /// What it tracks.
    pub kind: MarkerKind,
}

/// What a marker tracks.
#[derive(Clone, Copy)]
pub enum MarkerKind {
    /// A body-fixed point's world position.
    Point(Point),
    /// θ_b − θ_a.
    Angle(usize, usize),
}

impl MarkerKind {
    /// Suffixes of the marker's values at each level of derivatives, in layout order: a point
    /// `x`, `y` (then `x_dot`, `y_dot`, then `x_ddot`, `y_ddot`), a sensor `angle` (then
    /// `angle_dot`, `angle_ddot`).
    pub fn suffixes(&self, outputs: Outputs) -> Vec<&'static str> {
        let levels: [&[&str]; 3] = match self {
            MarkerKind::Point(_) => [&["x", "y"], &["x_dot", "y_dot"], &["x_ddot", "y_ddot"]],
            MarkerKind::Angle(..) => [&["angle"], &["angle_dot"], &["angle_ddot"]],
        };
        let count = match outputs {
            Outputs::Positions => 1,
            Outputs::Velocities => 2,
            Outputs::Accelerations | Outputs::Forces => 3,
        };
        levels
            .iter()
            .take(count)
            .flat_map(|l| l.iter().copied())
            .collect()
    }
}

/// A named applied load.
#[derive(Clone)]
pub struct Load {
    /// Name as declared.
    pub name: String,
    /// What it applies.
    pub kind: LoadKind,
}

/// The loads of the spec language; each is only its force law (see `dynamics`).
#[derive(Clone, Copy)]
pub enum LoadKind {
    /// A force at a point, in world or body axes, with components in t and parameters.
    Force {
        /// Where it acts (on a moving body).
        point: Point,
        /// Its components.
        value: [Id; 2],
        /// In the body's axes (turning with it) rather than the world's.
        local: bool,
    },
    /// A torque on a moving body, in t and parameters.
    Torque {
        /// The body.
        body: usize,
        /// Its value.
        value: Id,
    },
    /// A linear spring-damper between two points: tension `k (ℓ − L) + c ℓ̇`.
    Spring {
        /// First point.
        a: Point,
        /// Second point.
        b: Point,
        /// Stiffness k.
        stiffness: Id,
        /// Free length L.
        length: Id,
        /// Damping c.
        damping: Id,
    },
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
    /// `b`'s point (a pin) on the line through `a`'s point along `a`-fixed unit `axis`; the pin
    /// may turn (1 equation).
    Slot {
        /// Point on the slotted body.
        a: Point,
        /// The pin.
        b: Point,
        /// Unit axis in the slotted body's frame.
        axis: [Id; 2],
    },
    /// The points coincide and `θ_b − θ_a = angle` (3 equations).
    Weld {
        /// Point on the first body.
        a: Point,
        /// Point on the second body.
        b: Point,
        /// The relative angle.
        angle: Id,
    },
    /// `θ_b − θ_c = ratio (θ_a − θ_c) + phase`, c the carrier (none: the world).
    Gear {
        /// The driving gear.
        a: usize,
        /// The driven gear.
        b: usize,
        /// The carrier, if any.
        carrier: Option<usize>,
        /// The ratio.
        ratio: Id,
        /// The phase.
        phase: Id,
    },
    /// The travel of a prismatic joint (`a`'s point, `b`'s point, `a`-fixed unit `axis`) is
    /// `ratio (θ_pinion − θ_a) + phase`.
    Rack {
        /// The guide's point.
        a: Point,
        /// The rack's point.
        b: Point,
        /// Unit axis in the guide's frame.
        axis: [Id; 2],
        /// The pinion body.
        pinion: usize,
        /// Travel per radian.
        ratio: Id,
        /// Travel at zero pinion angle.
        phase: Id,
    },
    /// A driven quantity equals `value(t)`.
    Driver {
        /// The driven quantity.
        driven: Driven,
        /// The prescribed value, an expression in t and parameters.
        value: Id,
    },
}

/// A branch invariant: `product(u, v)` of two world vectors between body-fixed points keeps
/// `sign` on the declared assembly branch.
#[derive(Clone)]
pub struct Branch {
    /// Name as declared.
    pub name: String,
    /// Doc comments.
    pub docs: Vec<Attribute>,
    /// `cross` or `dot`.
    pub product: Product,
    /// The first vector, from `u[0]` to `u[1]`.
    pub u: [Point; 2],
    /// The second vector, from `v[0]` to `v[1]`.
    pub v: [Point; 2],
    /// The sign the product keeps on the declared branch.
    pub sign: Sign,
}

/// Physical dimension of a coordinate or an equation (mirrors `mechgen_runtime::Unit`, which
/// generated code names; the runtime scales by it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Unit {
    /// Radians.
    Angle,
    /// A length.
    Length,
    /// A length squared.
    Area,
}

impl Unit {
    /// The variant's name (`Angle`, `Length`, `Area`), as in `mechgen_runtime::Unit`.
    pub fn name(self) -> &'static str {
        match self {
            Unit::Angle => "Angle",
            Unit::Length => "Length",
            Unit::Area => "Area",
        }
    }
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
    /// Travel of a point along a line of another body (a prismatic joint's slider, or any
    /// line: the `slide` driver), along its unit axis.
    Travel {
        /// Point on the guiding body.
        a: Point,
        /// Point on the sliding body.
        b: Point,
        /// Unit axis in the guiding body's frame.
        axis: [Id; 2],
    },
    /// The distance between two points (a linear actuator).
    Distance(Point, Point),
}

impl ConstraintKind {
    /// Suffixes naming this constraint's equations (`pin.x`, `pin.y`, …); empty for one equation.
    pub fn equation_suffixes(&self) -> &'static [&'static str] {
        match self {
            ConstraintKind::Ground { .. } => &["x", "y", "theta"],
            ConstraintKind::Revolute { .. } => &["x", "y"],
            ConstraintKind::Prismatic { .. } => &["normal", "angle"],
            ConstraintKind::Weld { .. } => &["x", "y", "angle"],
            ConstraintKind::Distance { .. }
            | ConstraintKind::Slot { .. }
            | ConstraintKind::Gear { .. }
            | ConstraintKind::Rack { .. }
            | ConstraintKind::Driver { .. } => &[""],
        }
    }

    /// Physical dimension of each of this constraint's equations, in the order of
    /// [`equation_suffixes`](Self::equation_suffixes): point coincidences and positions are
    /// lengths, angles are angles, a prismatic joint's normal offset is a length (its axis is a
    /// unit vector), and a distance joint's `|d|² − L²` is an area.
    pub fn equation_units(&self) -> &'static [Unit] {
        match self {
            ConstraintKind::Ground { .. } => &[Unit::Length, Unit::Length, Unit::Angle],
            ConstraintKind::Revolute { .. } => &[Unit::Length, Unit::Length],
            ConstraintKind::Prismatic { .. } => &[Unit::Length, Unit::Angle],
            ConstraintKind::Distance { .. } => &[Unit::Area],
            ConstraintKind::Slot { .. } | ConstraintKind::Rack { .. } => &[Unit::Length],
            ConstraintKind::Weld { .. } => &[Unit::Length, Unit::Length, Unit::Angle],
            ConstraintKind::Gear { .. } => &[Unit::Angle],
            ConstraintKind::Driver { driven, .. } => match driven {
                Driven::Angle(_) | Driven::RelativeAngle(..) => &[Unit::Angle],
                Driven::X(_) | Driven::Y(_) | Driven::Travel { .. } | Driven::Distance(..) => {
                    &[Unit::Length]
                }
            },
        }
    }

    /// Suffixes naming the reaction each equation reports when the scene computes forces, in
    /// equation order: a ground body's load (`fx`, `fy`, `torque`), a revolute joint's force
    /// (`fx`, `fy`), a prismatic joint's `normal` and `torque`, a distance joint's `tension`,
    /// a driver's `effort`.
    pub fn reaction_suffixes(&self) -> &'static [&'static str] {
        match self {
            ConstraintKind::Ground { .. } => &["fx", "fy", "torque"],
            ConstraintKind::Revolute { .. } => &["fx", "fy"],
            ConstraintKind::Prismatic { .. } => &["normal", "torque"],
            ConstraintKind::Distance { .. } => &["tension"],
            ConstraintKind::Slot { .. } => &["normal"],
            ConstraintKind::Weld { .. } => &["fx", "fy", "torque"],
            ConstraintKind::Gear { .. } => &["torque"],
            ConstraintKind::Rack { .. } => &["force"],
            ConstraintKind::Driver { .. } => &["effort"],
        }
    }

    /// The body-fixed points this constraint places (none for ground equations, gears and
    /// angle drivers).
    pub fn points(&self) -> Vec<Point> {
        match *self {
            ConstraintKind::Ground { .. } | ConstraintKind::Gear { .. } => Vec::new(),
            ConstraintKind::Revolute { a, b }
            | ConstraintKind::Prismatic { a, b, .. }
            | ConstraintKind::Distance { a, b, .. }
            | ConstraintKind::Slot { a, b, .. }
            | ConstraintKind::Weld { a, b, .. }
            | ConstraintKind::Rack { a, b, .. } => vec![a, b],
            ConstraintKind::Driver { driven, .. } => match driven {
                Driven::Angle(_) | Driven::RelativeAngle(..) => Vec::new(),
                Driven::X(p) | Driven::Y(p) => vec![p],
                Driven::Travel { a, b, .. } | Driven::Distance(a, b) => vec![a, b],
            },
        }
    }
}

/// Names of a body's coordinates, in q order.
pub const COORDINATE_SUFFIXES: [&str; 3] = ["x", "y", "theta"];

/// Physical dimensions of a body's coordinates, in q order: x, y lengths, θ an angle.
pub const COORDINATE_UNITS: [Unit; 3] = [Unit::Length, Unit::Length, Unit::Angle];

impl Model {
    /// Number of coordinates (= number of equations, checked).
    pub fn dim(&self) -> usize {
        3 * self.bodies.len()
    }

    /// The equation (row of Φ) that holds free degree of freedom `k` at its state.
    pub fn free_equation(&self, k: usize) -> Option<usize> {
        let free = self.frees.get(k)?;
        Some(
            self.constraints[..free.constraint]
                .iter()
                .map(|c| c.kind.equation_suffixes().len())
                .sum(),
        )
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

    /// Reaction names in Φ order (`liner.fx`, …, `crank_pin.fx`, …, `crank_angle.effort`): what
    /// each equation reports when the scene computes forces.
    pub fn reaction_names(&self) -> Vec<String> {
        self.constraints
            .iter()
            .flat_map(|c| {
                c.kind
                    .reaction_suffixes()
                    .iter()
                    .map(move |s| format!("{}.{s}", c.name))
            })
            .collect()
    }

    /// Marker value names in layout order (`tip.x`, `tip.y`, `tip.x_dot`, …, `swing.angle`, …).
    pub fn marker_names(&self) -> Vec<String> {
        self.markers
            .iter()
            .flat_map(|m| {
                m.kind
                    .suffixes(self.outputs)
                    .into_iter()
                    .map(move |s| format!("{}.{s}", m.name))
            })
            .collect()
    }

    /// Physical dimension of every coordinate, in q order.
    pub fn coordinate_units(&self) -> Vec<Unit> {
        self.bodies.iter().flat_map(|_| COORDINATE_UNITS).collect()
    }

    /// Physical dimension of every equation, in Φ order.
    pub fn equation_units(&self) -> Vec<Unit> {
        self.constraints
            .iter()
            .flat_map(|c| c.kind.equation_units().iter().copied())
            .collect()
    }

    /// The scene's geometric lengths, as expressions in parameters, each once (ids are
    /// hash-consed) and in declaration order: the body-frame coordinates of every joint and
    /// driver point, every distance joint's length and every ground body's x and y. Not the
    /// guesses of moving bodies (only a starting point) nor driver values (they depend on t).
    /// Their largest magnitude is the scene's length scale.
    pub fn lengths(&self) -> Vec<Id> {
        let mut lengths = Vec::new();
        let mut seen = std::collections::HashSet::new();
        let mut add = |id: Id| {
            if seen.insert(id) {
                lengths.push(id);
            }
        };
        for body in self.bodies.iter().filter(|b| b.ground) {
            add(body.pose[0]);
            add(body.pose[1]);
        }
        for constraint in &self.constraints {
            for point in constraint.kind.points() {
                add(point.local[0]);
                add(point.local[1]);
            }
            if let ConstraintKind::Distance { length, .. } = constraint.kind {
                add(length);
            }
        }
        lengths
    }

    /// A point as the spec writes it: `rod @ (41.3, 0)`, `rod` for a reference point, and
    /// `rod @ (…)` for coordinates that depend on parameters.
    pub fn describe_point(&self, p: Point) -> String {
        let body = self
            .bodies
            .get(p.body)
            .map_or_else(|| "?".to_owned(), |b| b.name.to_string());
        match p.local.map(|id| self.arena.as_const(id)) {
            [Some(x), Some(y)] if x == 0.0 && y == 0.0 => body,
            [Some(x), Some(y)] => format!("{body} @ ({x}, {y})"),
            _ => format!("{body} @ (…)"),
        }
    }

    /// A branch invariant as the spec writes it: `dot(bearing -> liner, rod @ (41.3, 0) -> …) > 0`.
    pub fn describe_branch(&self, b: &Branch) -> String {
        let vector = |v: [Point; 2]| {
            format!(
                "{} -> {}",
                self.describe_point(v[0]),
                self.describe_point(v[1])
            )
        };
        let sign = match b.sign {
            Sign::Positive => ">",
            Sign::Negative => "<",
        };
        format!(
            "{}({}, {}) {sign} 0",
            b.product.name(),
            vector(b.u),
            vector(b.v)
        )
    }

    /// Number of drivers (the mechanism's degrees of freedom, checked).
    pub fn driver_count(&self) -> usize {
        self.constraints
            .iter()
            .filter(|c| matches!(c.kind, ConstraintKind::Driver { .. }))
            .count()
    }
}

#[cfg(test)]
mod tests {
    use super::{Outputs, Unit};
    use crate::expr::Node;

    /// Ground, revolute, prismatic, distance, weld and a driver, two markers and a branch.
    /// Constraints in equation order: the ground frame, the joints as declared, the driver.
    fn scene(outputs: &str) -> crate::Scene {
        let source = format!(
            "mechanism Kinds {{
                param r = 40;
                ground frame at (0, 0, 0);
                body crank near (0, 0, 0);
                body slider near (140, 0, 0);
                body arm near (140, 5, 0);
                joint pivot: revolute(frame, crank);
                joint guide: prismatic(frame, slider, along (1, 0));
                joint link: distance(crank @ (r, 0), slider, 100);
                joint glue: weld(slider @ (0, 5), arm);
                driver spin: angle(crank) = t;
                marker tip: arm @ (3, 4);
                marker swing: angle(crank, arm);
                branch ahead: cross(frame -> crank @ (r, 0), slider -> slider @ (0, 5)) > 0;
                {outputs}
            }}"
        );
        crate::compile(crate::Input::Text(&source), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn coordinates_are_named_and_measured_body_by_body() {
        let model = scene("").model;
        assert_eq!(model.dim(), 12);
        let names = model.coordinate_names();
        assert_eq!(names[..3], ["frame.x", "frame.y", "frame.theta"]);
        assert_eq!(names[9..], ["arm.x", "arm.y", "arm.theta"]);
        let (l, a) = (Unit::Length, Unit::Angle);
        assert_eq!(model.coordinate_units(), [l, l, a].repeat(4));
    }

    #[test]
    fn equations_are_named_and_measured_in_phi_order() {
        let model = scene("").model;
        assert_eq!(
            model.equation_names(),
            [
                "frame.x",
                "frame.y",
                "frame.theta",
                "pivot.x",
                "pivot.y",
                "guide.normal",
                "guide.angle",
                "link",
                "glue.x",
                "glue.y",
                "glue.angle",
                "spin",
            ]
        );
        let (l, a, area) = (Unit::Length, Unit::Angle, Unit::Area);
        assert_eq!(
            model.equation_units(),
            [l, l, a, l, l, l, a, area, l, l, a, a]
        );
        // One reaction per equation, named by what it reports.
        assert_eq!(
            model.reaction_names(),
            [
                "frame.fx",
                "frame.fy",
                "frame.torque",
                "pivot.fx",
                "pivot.fy",
                "guide.normal",
                "guide.torque",
                "link.tension",
                "glue.fx",
                "glue.fy",
                "glue.torque",
                "spin.effort",
            ]
        );
        assert_eq!(model.driver_count(), 1);
        // Each constraint's suffixes, units and reactions agree in number.
        for c in &model.constraints {
            let k = c.kind.equation_suffixes().len();
            assert_eq!(c.kind.equation_units().len(), k, "{}", c.name);
            assert_eq!(c.kind.reaction_suffixes().len(), k, "{}", c.name);
        }
    }

    #[test]
    fn marker_values_follow_the_outputs_marker_by_marker() {
        let positions = scene("outputs positions;").model;
        assert_eq!(positions.marker_names(), ["tip.x", "tip.y", "swing.angle"]);
        let velocities = scene("outputs positions, velocities;").model;
        assert_eq!(
            velocities.marker_names(),
            [
                "tip.x",
                "tip.y",
                "tip.x_dot",
                "tip.y_dot",
                "swing.angle",
                "swing.angle_dot"
            ]
        );
        let all = scene("").model;
        assert_eq!(all.outputs, Outputs::Accelerations);
        assert_eq!(all.marker_names().len(), 9);
        assert_eq!(all.marker_names()[4..6], ["tip.x_ddot", "tip.y_ddot"]);
        // Forces add no marker values.
        let tip = all.markers[0].kind;
        assert_eq!(
            tip.suffixes(Outputs::Forces),
            tip.suffixes(Outputs::Accelerations)
        );
    }

    #[test]
    fn outputs_are_ordered_levels_named_as_in_specs_and_the_runtime() {
        assert!(Outputs::ALL.windows(2).all(|w| w[0] < w[1]));
        for (level, name) in Outputs::ALL.into_iter().zip(Outputs::NAMES) {
            assert_eq!(level.name().to_lowercase(), name);
        }
        let units = [Unit::Angle, Unit::Length, Unit::Area].map(Unit::name);
        assert_eq!(units, ["Angle", "Length", "Area"]);
    }

    #[test]
    fn lengths_are_listed_once_in_declaration_order() {
        let model = scene("").model;
        let lengths: Vec<Node> = model
            .lengths()
            .into_iter()
            .map(|id| model.arena.node(id))
            .collect();
        // The frame's x and y (0, once), the link's point (r, 0: r new) and length, the weld's
        // point (0, 5); not the bodies' guesses, the guide's axis or the driver's value.
        let constant = |v: f64| Node::Const(f64::to_bits(v));
        assert_eq!(
            lengths,
            [
                constant(0.0),
                Node::Param(0),
                constant(100.0),
                constant(5.0)
            ]
        );
    }

    #[test]
    fn points_and_branches_are_described_as_written() {
        let model = scene("").model;
        let branch = &model.branches[0];
        // The crank's point is in a parameter: its coordinates are not written out.
        assert_eq!(
            model.describe_branch(branch),
            "cross(frame -> crank @ (…), slider -> slider @ (0, 5)) > 0"
        );
        let tip = match model.markers[0].kind {
            super::MarkerKind::Point(p) => p,
            super::MarkerKind::Angle(..) => panic!("`tip` is a point"),
        };
        assert_eq!(model.describe_point(tip), "arm @ (3, 4)");
    }
}
