//! The spec: what the user wrote, as parsed, with every name and value still carrying its span.
//!
//! Nothing here is resolved or validated beyond syntax; `check` turns a [`Spec`] into a model.

use proc_macro2::Span;
use syn::{Attribute, Ident, Visibility};

/// A whole `mechanism` declaration.
#[derive(Clone)]
pub struct Spec {
    /// Outer doc comments, carried onto the generated struct.
    pub docs: Vec<Attribute>,
    /// Visibility of the generated items.
    pub vis: Visibility,
    /// Name of the generated struct (UpperCamelCase).
    pub name: Ident,
    /// Run-time parameters with their defaults.
    pub params: Vec<ParamDecl>,
    /// Bodies in declaration order (this is the order of q).
    pub bodies: Vec<BodyDecl>,
    /// Joints in declaration order.
    pub joints: Vec<JointDecl>,
    /// Drivers and free degrees of freedom, in declaration order.
    pub drivers: Vec<DriverDecl>,
    /// Branch invariants in declaration order.
    pub branches: Vec<BranchDecl>,
    /// The `gravity (gx, gy);` statement, if any.
    pub gravity: Option<GravityDecl>,
    /// Applied loads (forces, torques, springs) in declaration order.
    pub loads: Vec<LoadDecl>,
    /// Markers (tracked points, angle sensors) in declaration order.
    pub markers: Vec<MarkerDecl>,
    /// Named body points (`point pin: crank @ (0, 43);`), in declaration order.
    pub points: Vec<PointDecl>,
    /// The `outputs …;` statement, if any: the listed names with their spans.
    pub outputs: Option<Vec<proc_macro2::Ident>>,
}

/// `param omega = 314.0;`
#[derive(Clone)]
pub struct ParamDecl {
    /// Doc comments, carried onto the generated field.
    pub docs: Vec<Attribute>,
    /// Name (a snake_case field of the generated struct).
    pub name: Ident,
    /// Default value (a constant expression).
    pub default: Expr,
}

/// `ground liner at (x, y, θ);` or `body piston near (x, y, θ);`
#[derive(Clone)]
pub struct BodyDecl {
    /// Doc comments, carried onto the generated accessor.
    pub docs: Vec<Attribute>,
    /// Span of the `ground` / `body` keyword.
    pub keyword: Span,
    /// Name of the body.
    pub name: Ident,
    /// True for `ground` (pose fixed by three equations), false for a moving `body`.
    pub ground: bool,
    /// Pose of a ground body, or the initial guess of a moving one.
    pub pose: [Expr; 3],
    /// Mass properties (`mass m inertia J centre (x, y)`), if declared.
    pub mass: Option<MassDecl>,
}

/// `mass 0.4 inertia 1500 centre (20, 0)` after a body's pose: its mass, its moment of inertia
/// about the centre of mass, and the centre of mass in the body's frame (each optional; the
/// centre defaults to the reference point).
#[derive(Clone)]
pub struct MassDecl {
    /// Span of the clause's first keyword.
    pub span: Span,
    /// `mass m`.
    pub mass: Option<Expr>,
    /// `inertia J`: the moment of inertia about the centre of mass.
    pub inertia: Option<Expr>,
    /// `centre (x, y)` (or `center`): body-frame coordinates of the centre of mass, with the
    /// span of the keyword.
    pub centre: Option<([Expr; 2], Span)>,
}

/// `marker NAME: body @ (x, y);` or `marker NAME: angle(a, b);`: an output computed from the
/// solved state, with its rates.
#[derive(Clone)]
pub struct MarkerDecl {
    /// Doc comments, carried onto the generated accessor.
    pub docs: Vec<Attribute>,
    /// Name of the marker (its accessor and CSV columns).
    pub name: Ident,
    /// What it tracks.
    pub kind: MarkerKind,
}

/// What a marker tracks.
#[derive(Clone)]
pub enum MarkerKind {
    /// A body-fixed point's world position.
    Point(PointRef),
    /// `angle(a, b)`: θ_b − θ_a.
    Angle(Ident, Ident),
}

/// `gravity (gx, gy);`: the acceleration of gravity in world axes.
#[derive(Clone)]
pub struct GravityDecl {
    /// Span of the `gravity` keyword.
    pub span: Span,
    /// World components.
    pub value: [Expr; 2],
}

/// `load NAME: KIND(…) [= value];`
#[derive(Clone)]
pub struct LoadDecl {
    /// Doc comments.
    pub docs: Vec<Attribute>,
    /// Name of the load.
    pub name: Ident,
    /// Span of the load kind, for diagnostics.
    pub kind_span: Span,
    /// The load.
    pub kind: LoadKind,
}

/// The applied loads of the spec language.
// A scene holds a handful of loads, parsed once at compile time: boxing the spring would only
// add indirection.
#[allow(clippy::large_enum_variant)]
#[derive(Clone)]
pub enum LoadKind {
    /// `force(point) = (fx, fy)` in world axes, or `local_force(point) = (fx, fy)` in the
    /// body's axes (turning with it).
    Force {
        /// Where it acts.
        point: PointRef,
        /// Its components, in t and parameters.
        value: [Expr; 2],
        /// Body axes (`local_force`) rather than world axes.
        local: bool,
    },
    /// `torque(body) = τ`.
    Torque {
        /// The body it turns.
        body: Ident,
        /// Its value, in t and parameters.
        value: Expr,
    },
    /// `spring(p, q, stiffness k, length L, damping c)`: a linear spring-damper between two
    /// points; each keyword argument is optional (stiffness and damping default to zero, but
    /// one of them must be given; `length` goes with `stiffness`).
    Spring {
        /// First point.
        a: PointRef,
        /// Second point.
        b: PointRef,
        /// `stiffness k`.
        stiffness: Option<Expr>,
        /// `length L`: the free length.
        length: Option<Expr>,
        /// `damping c`.
        damping: Option<Expr>,
    },
}

/// `point pin: crank @ (0, 43);`: a body point written once and used by name (`pin`) wherever a
/// point is written.
#[derive(Clone)]
pub struct PointDecl {
    /// Doc comments (documentation only: a point generates nothing).
    pub docs: Vec<Attribute>,
    /// Its name.
    pub name: Ident,
    /// The point.
    pub point: PointRef,
}

/// A body-fixed point: `rod @ (41.3, 0)`, or `rod` alone for its reference point (or a named
/// point's name, replaced by the point before checking).
#[derive(Clone)]
pub struct PointRef {
    /// The body the point is fixed to.
    pub body: Ident,
    /// Body-frame coordinates; `None` for the origin.
    pub local: Option<[Expr; 2]>,
}

/// `joint NAME: KIND(...);`
#[derive(Clone)]
pub struct JointDecl {
    /// Doc comments.
    pub docs: Vec<Attribute>,
    /// Name of the joint (names its equations, e.g. `crank_pin.x`).
    pub name: Ident,
    /// Span of the joint kind (`revolute`, …).
    pub kind_span: Span,
    /// The joint.
    pub kind: JointKind,
}

/// The joints of the library; each is only its Φ, everything else is derived.
#[derive(Clone)]
pub enum JointKind {
    /// `revolute(a @ s_a, b @ s_b)`: the two points coincide (2 equations).
    Revolute {
        /// Point on the first body.
        a: PointRef,
        /// Point on the second body.
        b: PointRef,
    },
    /// `prismatic(a @ p_a, b @ p_b, along (ux, uy))`: `b`'s point stays on the line through
    /// `a`'s point along `a`-fixed direction u, with no relative rotation (2 equations).
    Prismatic {
        /// Point on the guiding body.
        a: PointRef,
        /// Point on the sliding body.
        b: PointRef,
        /// Axis direction in the guiding body's frame.
        axis: [Expr; 2],
        /// Span of the axis, for diagnostics.
        axis_span: Span,
    },
    /// `distance(a @ s_a, b @ s_b, L)`: the points stay L apart (1 equation).
    Distance {
        /// Point on the first body.
        a: PointRef,
        /// Point on the second body.
        b: PointRef,
        /// The distance.
        length: Expr,
    },
    /// `slot(a @ p_a, b @ p_b, along (ux, uy))`: `b`'s point (a pin) stays on the line through
    /// `a`'s point along the `a`-fixed axis; the pin may turn (1 equation).
    Slot {
        /// Point on the slotted body, on the slot's line.
        a: PointRef,
        /// The pin, on the other body.
        b: PointRef,
        /// The slot's direction in the first body's frame.
        axis: [Expr; 2],
        /// Span of the axis, for diagnostics.
        axis_span: Span,
    },
    /// `weld(a @ p_a, b @ p_b[, angle θ])`: the points coincide and `θ_b − θ_a = θ`
    /// (default 0): the two bodies move as one (3 equations).
    Weld {
        /// Point on the first body.
        a: PointRef,
        /// Point on the second body.
        b: PointRef,
        /// The relative angle, if given.
        angle: Option<Expr>,
    },
    /// `gear(a, b, ratio k[, carrier c][, phase φ])`: `θ_b − θ_c = k (θ_a − θ_c) + φ`, the
    /// rotations relative to the carrier in a fixed ratio (1 equation); without a carrier,
    /// relative to the world.
    Gear {
        /// The driving gear.
        a: Ident,
        /// The driven gear.
        b: Ident,
        /// The ratio k (negative for an external pair: −z_a/z_b; positive for internal).
        ratio: Expr,
        /// The carrier both gears turn on, if any.
        carrier: Option<Ident>,
        /// The phase φ (default 0).
        phase: Option<Expr>,
    },
    /// `rack(joint, pinion, ratio r[, phase s])`: the travel of prismatic joint `joint` is
    /// `r (θ_pinion − θ_guide) + s`, the guide being the joint's first body (1 equation).
    Rack {
        /// The prismatic joint the rack slides in.
        joint: Ident,
        /// The pinion.
        pinion: Ident,
        /// Travel per radian of the pinion (its pitch radius, signed).
        ratio: Expr,
        /// The travel at zero pinion angle (default 0).
        phase: Option<Expr>,
    },
}

impl JointKind {
    /// Equations of the joint (its share of the Gruebler count).
    pub fn equations(&self) -> usize {
        match self {
            JointKind::Revolute { .. } | JointKind::Prismatic { .. } => 2,
            JointKind::Weld { .. } => 3,
            JointKind::Distance { .. }
            | JointKind::Slot { .. }
            | JointKind::Gear { .. }
            | JointKind::Rack { .. } => 1,
        }
    }

    /// The bodies the joint names (for a rack, its pinion: the prismatic joint names the
    /// others).
    pub fn bodies(&self) -> Vec<&Ident> {
        match self {
            JointKind::Revolute { a, b }
            | JointKind::Prismatic { a, b, .. }
            | JointKind::Distance { a, b, .. }
            | JointKind::Slot { a, b, .. }
            | JointKind::Weld { a, b, .. } => vec![&a.body, &b.body],
            JointKind::Gear { a, b, carrier, .. } => [a, b].into_iter().chain(carrier).collect(),
            JointKind::Rack { pinion, .. } => vec![pinion],
        }
    }
}

/// `driver NAME: KIND(...) = f(t);` or `free NAME: KIND(...) [from u0] [speed v0];`: one
/// equation holding a quantity at a value, prescribed or the integrator's state.
#[derive(Clone)]
pub struct DriverDecl {
    /// Doc comments.
    pub docs: Vec<Attribute>,
    /// Name of the driver (names its equation).
    pub name: Ident,
    /// Span of the driver kind, for diagnostics.
    pub kind_span: Span,
    /// What is driven.
    pub kind: DriverKind,
    /// The value it is held at.
    pub value: DriverValue,
}

/// The value a [`DriverDecl`] holds its quantity at.
#[derive(Clone)]
pub enum DriverValue {
    /// `= f(t)`: a prescribed function of t and parameters.
    Prescribed(Expr),
    /// `free`: a free degree of freedom, moved by the integrator under the scene's forces.
    Free {
        /// Span of the `free` keyword.
        keyword: Span,
        /// `from u0`: the initial value, in parameters (default: the value at the scene's
        /// initial guess, assembled).
        from: Option<Expr>,
        /// `speed v0`: the initial rate, in parameters (default 0).
        speed: Option<Expr>,
    },
}

impl DriverDecl {
    /// The `free` keyword's span if this declares a free degree of freedom.
    pub fn free_keyword(&self) -> Option<Span> {
        match self.value {
            DriverValue::Free { keyword, .. } => Some(keyword),
            DriverValue::Prescribed(_) => None,
        }
    }
}

/// What a driver prescribes.
#[derive(Clone)]
pub enum DriverKind {
    /// `angle(body)`: θ_body.
    Angle(Ident),
    /// `relative_angle(a, b)`: θ_b − θ_a.
    RelativeAngle(Ident, Ident),
    /// `x(point)`: global x of a body-fixed point.
    X(PointRef),
    /// `y(point)`: global y of a body-fixed point.
    Y(PointRef),
    /// `travel(joint)`: position of a prismatic joint's slider along its axis.
    Travel(Ident),
    /// `distance(a @ p, b @ q)`: the distance between two points (a linear actuator).
    Distance(PointRef, PointRef),
    /// `slide(a @ p, b @ q, along (ux, uy))`: the travel of `b`'s point along the line through
    /// `a`'s point along the `a`-fixed axis.
    Slide {
        /// Point on the guiding body.
        a: PointRef,
        /// Point on the sliding body.
        b: PointRef,
        /// The direction in the guiding body's frame.
        axis: [Expr; 2],
        /// Span of the axis, for diagnostics.
        axis_span: Span,
    },
}

impl DriverKind {
    /// The bodies the driver moves (none named directly for `travel`).
    pub fn bodies(&self) -> Vec<&Ident> {
        match self {
            DriverKind::Angle(b) => vec![b],
            DriverKind::RelativeAngle(a, b) => vec![a, b],
            DriverKind::X(p) | DriverKind::Y(p) => vec![&p.body],
            DriverKind::Distance(a, b) | DriverKind::Slide { a, b, .. } => vec![&a.body, &b.body],
            DriverKind::Travel(_) => Vec::new(),
        }
    }
}

/// `branch NAME: cross(p1 -> p2, p3 -> p4) > 0;` (or `dot(…)`, or `< 0`): a sign that tells the
/// declared assembly branch from its mirror image, which the solver refuses to leave.
#[derive(Clone)]
pub struct BranchDecl {
    /// Doc comments.
    pub docs: Vec<Attribute>,
    /// Name of the invariant (reported by the solver when a solution leaves the branch).
    pub name: Ident,
    /// `cross` or `dot`.
    pub product: Product,
    /// Span of the product's name, for diagnostics about the whole invariant.
    pub product_span: Span,
    /// The first vector, from its first point to its second (world coordinates).
    pub u: [PointRef; 2],
    /// The second vector.
    pub v: [PointRef; 2],
    /// `> 0` or `< 0`.
    pub sign: Sign,
    /// The right-hand side of the comparison as written; `check` requires the literal 0.
    pub zero: Expr,
}

/// The product of a branch invariant's two vectors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Product {
    /// `cross(u, v)` = u.x v.y − u.y v.x: the sign of the turn from u to v.
    Cross,
    /// `dot(u, v)` = u.x v.x + u.y v.y: whether u and v point the same way.
    Dot,
}

impl Product {
    /// The name used in specs (`cross`, `dot`).
    pub fn name(self) -> &'static str {
        match self {
            Product::Cross => "cross",
            Product::Dot => "dot",
        }
    }
}

/// The sign a branch invariant keeps on the declared branch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Sign {
    /// `> 0`
    Positive,
    /// `< 0`
    Negative,
}

/// An expression as written, in `t`, parameters and numbers.
#[derive(Clone)]
pub struct Expr {
    /// Where it was written.
    pub span: Span,
    /// What it is.
    pub kind: ExprKind,
}

/// The forms of [`Expr`].
#[derive(Clone)]
pub enum ExprKind {
    /// A numeric literal.
    Number(f64),
    /// `t` or a parameter name.
    Name(Ident),
    /// `-a`
    Neg(Box<Expr>),
    /// `a op b`
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// `a ^ n` with an integer literal n.
    Pow(Box<Expr>, i32),
    /// `a ^ b` with any other exponent (a real power: the base must be positive).
    RealPow(Box<Expr>, Box<Expr>),
    /// `f(a, …)`
    Call(Ident, Vec<Expr>),
    /// `(a, b, …)`: a point of a spline (`check` refuses it anywhere else).
    Tuple(Vec<Expr>),
}

/// Binary operators.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
}
