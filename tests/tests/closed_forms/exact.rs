//! The test scenes' motions, derived here from their geometry (circle–circle and circle–line
//! intersections written out, independently of the generator's closed forms), as functions of
//! t over second-order dual numbers: q, q̇ and q̈ exactly, to round-off. Each returns the
//! coordinates in the scene's order (bodies as declared, x, y, θ each).

use core::f64::consts::PI;

use num_dual::{Dual2_64, DualNum, second_derivative};

use super::scenes::{Collar, FourBar, OffsetSlider, PistonCrank, PushedSlider};

/// The dual numbers the motions are written in.
pub type Dual = Dual2_64;
type D = Dual;

/// q, q̇, q̈ at one instant.
pub struct Exact<const N: usize> {
    pub q: [f64; N],
    pub qd: [f64; N],
    pub qdd: [f64; N],
}

/// Differentiates a motion `q(t)` twice at `t`.
pub fn at<const N: usize>(motion: impl Fn(D) -> [D; N], t: f64) -> Exact<N> {
    let parts: [(f64, f64, f64); N] = second_derivative(motion, t);
    Exact {
        q: parts.map(|p| p.0),
        qd: parts.map(|p| p.1),
        qdd: parts.map(|p| p.2),
    }
}

fn c(x: f64) -> D {
    D::from(x)
}

/// The angle of the vector (x, y), with exact derivatives wherever the vector is not zero:
/// `atan` of whichever ratio is bounded, turned by the multiple of π that puts it on
/// `atan2`'s value.
fn angle(y: D, x: D) -> D {
    let raw = if x.re.abs() >= y.re.abs() {
        (y / x).atan()
    } else {
        c(PI / 2.0) - (x / y).atan()
    };
    let turn = ((y.re.atan2(x.re) - raw.re) / PI).round() * PI;
    raw + turn
}

/// The point at distance `r1` from `p1` and `r2` from `p2`, left of p1 → p2 for `sign` +1
/// and right of it for −1: along the centre line at `x` from `p1`, off it by `h`, where
/// r1² − x² = h² = r2² − (ρ − x)².
fn circle_circle(p1: [D; 2], r1: f64, p2: [D; 2], r2: f64, sign: f64) -> [D; 2] {
    let (dx, dy) = (p2[0] - p1[0], p2[1] - p1[1]);
    let rho = (dx * dx + dy * dy).sqrt();
    let x = (rho * rho + r1 * r1 - r2 * r2) / (rho * 2.0);
    let h = (c(r1 * r1) - x * x).sqrt() * sign;
    let (ux, uy) = (dx / rho, dy / rho);
    [p1[0] + ux * x - uy * h, p1[1] + uy * x + ux * h]
}

/// The four-bar on the branch whose rocker pin lies left (`sign` +1) or right (−1) of the
/// line from the crank pin to the rocker pivot.
pub fn four_bar(s: &FourBar, sign: f64) -> impl Fn(D) -> [D; 12] + '_ {
    move |t| {
        let crank = t * s.omega + s.phase;
        let (sin, cos) = crank.sin_cos();
        let pin = [cos * s.a, sin * s.a];
        let pivot = [c(s.d), c(0.0)];
        let elbow = circle_circle(pin, s.b, pivot, s.c, sign);
        let coupler = angle(elbow[1] - pin[1], elbow[0] - pin[0]);
        let rocker = angle(elbow[1], elbow[0] - s.d);
        let z = c(0.0);
        [
            z, z, z, z, z, crank, pin[0], pin[1], coupler, pivot[0], z, rocker,
        ]
    }
}

/// The offset slider-crank with its slider right (`side` +1) or left (−1) of the crank pin:
/// the rod's sine is fixed by the guide's height, its cosine's sign by the side.
pub fn offset_slider(s: &OffsetSlider, side: f64) -> impl Fn(D) -> [D; 12] + '_ {
    move |t| {
        let crank = t * s.omega + s.phase;
        let (sin, cos) = crank.sin_cos();
        let pin = [cos * s.r, sin * s.r];
        let rise = (c(s.e) - pin[1]) / s.l;
        let run = (c(1.0) - rise * rise).sqrt() * side;
        let rod = angle(rise, run);
        let z = c(0.0);
        [
            z,
            z,
            z,
            z,
            z,
            crank,
            pin[0],
            pin[1],
            rod,
            pin[0] + run * s.l,
            c(s.e),
            z,
        ]
    }
}

/// The parametrised seed with its piston right (`side` +1) or left (−1) of the crank pin: the
/// piston pin is where the circle of the rod's pin distance about the crank pin meets the
/// liner's axis; the rod's angle is that chord's less its direction in the rod's frame.
pub fn piston_crank(s: &PistonCrank, side: f64) -> impl Fn(D) -> [D; 15] + '_ {
    move |t| {
        let crank = t * s.omega + s.phase;
        let (sin, cos) = crank.sin_cos();
        let pin = [-sin * s.radius, cos * s.radius];
        let chord = s.rod_pin.hypot(s.rod_length);
        let rise = c(s.offset) - pin[1];
        let run = (c(chord * chord) - rise * rise).sqrt() * side;
        let rod = angle(rise, run) - s.rod_length.atan2(-s.rod_pin);
        let (rod_sin, rod_cos) = rod.sin_cos();
        let z = c(0.0);
        [
            z,
            c(s.offset),
            z,
            pin[0] + run + s.pin,
            c(s.offset),
            z,
            pin[0] - rod_cos * s.rod_pin,
            pin[1] - rod_sin * s.rod_pin,
            rod,
            z,
            z,
            crank,
            z,
            z,
            z,
        ]
    }
}

/// The collar: on the arm's line through the pivot, at the driven x, so y = x tan θ.
pub fn collar(s: &Collar) -> impl Fn(D) -> [D; 9] + '_ {
    move |t| {
        let arm = (t * s.omega).sin() * s.swing + s.phase;
        let x = (t * s.nu).sin() * s.stroke + s.reach;
        let z = c(0.0);
        [z, z, z, z, z, arm, x, x * arm.tan(), arm]
    }
}

/// The slider-crank pushed by its slider, the crank pin above (`sign` +1) or below (−1) the
/// guide: the crank pin is where the crank's circle about the pivot meets the rod's about the
/// wrist pin.
pub fn pushed_slider(s: &PushedSlider, sign: f64) -> impl Fn(D) -> [D; 12] + '_ {
    move |t| {
        let x = t * s.speed + s.start;
        let z = c(0.0);
        // Right of the line from the wrist pin to the pivot is above the guide.
        let pin = circle_circle([x, z], s.l, [z, z], s.r, -sign);
        let crank = angle(pin[1], pin[0]);
        let rod = angle(-pin[1], x - pin[0]);
        [z, z, z, z, z, crank, x, z, rod, x, z, z]
    }
}
