//! Named views of a solved state's forces: the values a scene's generated `reactions()`
//! accessor returns for each joint and ground body (drivers' efforts are plain numbers).
//!
//! Every value is in the scene's own consistent units: with lengths in mm, masses in kg and
//! time in s, forces are in kg·mm/s² (mN) and torques in kg·mm²/s² (µN·m). Nothing is converted.

/// The reaction of a revolute joint `revolute(a @ …, b @ …)`: the force, in world axes, that
/// body `b` exerts on body `a` at the joint point. Body `b` receives the opposite.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RevoluteReaction {
    /// World x component of the force on `a`.
    pub fx: f64,
    /// World y component of the force on `a`.
    pub fy: f64,
}

/// The reaction of a prismatic joint `prismatic(a @ …, b @ …, along u)`: what body `b` exerts
/// on body `a`. Body `b` receives the opposite.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrismaticReaction {
    /// The normal force on `a`, along the joint's normal (its axis turned a quarter turn
    /// anticlockwise with `a`), acting at `b`'s point.
    pub normal: f64,
    /// The torque on `a` that keeps the two from rotating relative to each other (besides the
    /// moment of the normal force).
    pub torque: f64,
}

/// The reaction of a distance joint: its tension, positive when it pulls the two points
/// together (a rod in compression has a negative tension).
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistanceReaction {
    /// Tension along the line between the points.
    pub tension: f64,
}

/// The load the mechanism puts on a ground body through its joints, its drivers and the
/// springs anchored to it: what its mounting must resist.
///
/// A driver of a body's `angle` or of a point's world `x` or `y` pushes against the world, not
/// against any ground body: its effort is in no ground load (so the ground loads and those
/// drivers' efforts together balance the mechanism's weight and loads).
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundLoad {
    /// World x component of the force on the ground body.
    pub fx: f64,
    /// World y component of the force on the ground body.
    pub fy: f64,
    /// Torque on the ground body about its reference point.
    pub torque: f64,
}

/// The reaction of a pin-in-slot joint `slot(a @ …, b @ …, along u)`: what the pin (on `b`)
/// exerts on the slotted body `a`. The pin receives the opposite.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlotReaction {
    /// The normal force on `a`, along the slot's normal (its axis turned a quarter turn
    /// anticlockwise with `a`), acting at the pin.
    pub normal: f64,
}

/// The reaction of a weld `weld(a @ …, b @ …)`: the force (world axes) and torque `b` exerts on
/// `a` at the weld point. `b` receives the opposite.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeldReaction {
    /// World x component of the force on `a`.
    pub fx: f64,
    /// World y component of the force on `a`.
    pub fy: f64,
    /// Torque on `a`.
    pub torque: f64,
}

/// The reaction of a gear pair `gear(a, b, ratio k, carrier c)`: the torque the mesh applies to
/// the driven gear `b`. The driving gear `a` receives `−k` times it, the carrier the rest.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GearReaction {
    /// Torque on `b`.
    pub torque: f64,
}

/// The reaction of a rack and pinion `rack(slide, pinion, ratio r)`: the force along the axis
/// that the pinion applies to the rack (the prismatic joint's slider). The pinion receives the
/// torque `−r` times it, the guide the rest.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RackReaction {
    /// Force on the rack along the joint's axis.
    pub force: f64,
}
