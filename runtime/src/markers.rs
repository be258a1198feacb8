//! Named views of a solved state's markers: what a scene's generated accessors return for a
//! tracked point (`marker tip: coupler @ (x, y);`) and for an angle sensor
//! (`marker swing: angle(a, b);`), at the level of derivatives the scene computes.

/// A tracked point's world position.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointPosition {
    /// World x.
    pub x: f64,
    /// World y.
    pub y: f64,
}

/// A tracked point's world position and velocity.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointVelocity {
    /// World x.
    pub x: f64,
    /// World y.
    pub y: f64,
    /// ẋ.
    pub x_dot: f64,
    /// ẏ.
    pub y_dot: f64,
}

/// A tracked point's world position, velocity and acceleration.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointState {
    /// World x.
    pub x: f64,
    /// World y.
    pub y: f64,
    /// ẋ.
    pub x_dot: f64,
    /// ẏ.
    pub y_dot: f64,
    /// ẍ.
    pub x_ddot: f64,
    /// ÿ.
    pub y_ddot: f64,
}

/// An angle sensor's reading `θ_b − θ_a` (radians).
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnglePosition {
    /// The angle.
    pub angle: f64,
}

/// An angle sensor's reading and its rate.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleVelocity {
    /// The angle.
    pub angle: f64,
    /// Its rate.
    pub angle_dot: f64,
}

/// An angle sensor's reading and its first two rates.
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleState {
    /// The angle.
    pub angle: f64,
    /// Its rate.
    pub angle_dot: f64,
    /// Its second rate.
    pub angle_ddot: f64,
}
