//! The scissor lift's dimensions and its motion in closed form: the build script takes the
//! initial guesses from here, the tests their reference values.
//!
//! Stage k (from 0 at the bottom) is two links of length L crossing at their middles: `rise_k`
//! runs from its lower-left end up to the right at angle α, `fall_k` from its lower-right end up
//! to the left at π − α. A stage is w = L cos α wide and h = L sin α tall; its lower-left corner
//! is at (0, k h). Each link's reference point is its middle and its x axis runs along it, so
//! its ends are at (±L/2, 0) in its own frame.

/// Coordinates besides the 6 of each stage's two links: the ground `base`, the `slider`, the
/// `platform` and the `roller`, 3 each.
pub const EXTRA_COORDINATES: usize = 12;

/// Length of every link (m).
pub const LINK_LENGTH: f64 = 1.0;

/// Angle of the bottom link at t = 0 (rad): the default of the scene's `alpha0` parameter.
pub const ALPHA0: f64 = 0.3;

/// Rate at which the bottom link's angle grows (rad/s): the default of `omega`.
pub const OMEGA: f64 = 0.5;

/// The driven angle α(t) = α0 + ω t of every link with the defaults above.
pub fn alpha(t: f64) -> f64 {
    ALPHA0 + OMEGA * t
}

/// Width of every stage, L cos α: also the slider's and the roller's x.
pub fn stage_width(alpha: f64) -> f64 {
    LINK_LENGTH * alpha.cos()
}

/// Height of one stage, L sin α.
pub fn stage_height(alpha: f64) -> f64 {
    LINK_LENGTH * alpha.sin()
}

/// Height of the platform of an `stages`-stage lift: n L sin α.
pub fn platform_height(stages: usize, alpha: f64) -> f64 {
    // Exact for any realistic stage count (below 2^53).
    #[allow(clippy::cast_precision_loss)]
    let n = stages as f64;
    n * stage_height(alpha)
}

/// Poses (x, y, θ) of `rise_k` and `fall_k`: both centred at (w/2, (k + ½) h).
pub fn stage_poses(stage: usize, alpha: f64) -> [[f64; 3]; 2] {
    #[allow(clippy::cast_precision_loss)]
    let k = stage as f64;
    let (x, y) = (stage_width(alpha) / 2.0, (k + 0.5) * stage_height(alpha));
    [[x, y, alpha], [x, y, core::f64::consts::PI - alpha]]
}
