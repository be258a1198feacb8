//! The library's example scenes against their textbook answers:
//!
//! - Hoeken's straight-line linkage: the tracer marker's position, velocity and acceleration
//!   against the closed-form four-bar, and the straightness of its path over the half turn
//!   from 90° to 270° against the closed form's deviation (0.00975 crank lengths, 0.24 % of
//!   the 4-crank-length stroke);
//! - the planetary gear set: the carrier's and the planet's speeds against Willis' formula,
//!   and the planet's tooth marker against the hypocycloid it rolls out.

use mechgen_examples::closed_form::FourBar;
use mechgen_examples::scenes::{Hoeken, HoekenBodies, Planetary, PlanetaryBodies};
use mechgen_runtime::{Simulation, Solver};
use num_dual::{DualNum, second_derivative};

/// Hoeken's proportions as a four-bar: crank 1, coupler 2.5, rocker 2.5, frame 2.
fn hoeken_four_bar() -> FourBar {
    FourBar {
        crank: 1.0,
        coupler: 2.5,
        rocker: 2.5,
        ground: 2.0,
        omega: Hoeken::default().omega,
    }
}

/// The tracer, on the coupler's line at twice the rocker pin's distance from the crank pin:
/// P = 2B − A.
fn tracer<D: DualNum<Primitive = f64> + Copy>(t: D) -> [D; 2] {
    let linkage = hoeken_four_bar();
    let (sin, cos) = (t * linkage.omega).sin_cos();
    let (bx, by) = linkage.pin_b_generic(t);
    [bx * 2.0 - cos, by * 2.0 - sin]
}

/// The largest distance of the tracer from the line y = 4 over the crank's half turn from 90°
/// to 270°, in the closed form sampled every 0.01°.
fn closed_form_deviation() -> f64 {
    (0..=18_000)
        .map(|i| {
            let t = (90.0 + i as f64 * 0.01).to_radians() / hoeken_four_bar().omega;
            (tracer(t)[1] - 4.0).abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn hoeken_tracer_matches_the_closed_form_and_runs_straight() {
    let period = hoeken_four_bar().period();
    let mut simulation = Simulation::new(Solver::new(Hoeken::default()), 0.0).expect("assembles");
    let (mut error, mut deviation) = ([0.0f64; 3], 0.0f64);
    let mut straight = Vec::new();
    simulation
        .run(period, 720, |state| {
            let p = state.tracer();
            let [x, y] = [0, 1].map(|k| second_derivative(|t| tracer(t)[k], state.t));
            let solved = [[p.x, p.y], [p.x_dot, p.y_dot], [p.x_ddot, p.y_ddot]];
            let exact = [[x.0, y.0], [x.1, y.1], [x.2, y.2]];
            for level in 0..3 {
                for k in 0..2 {
                    error[level] = error[level].max((solved[level][k] - exact[level][k]).abs());
                }
            }
            let crank = state.crank().theta.to_degrees();
            if (90.0..=270.0).contains(&crank) {
                deviation = deviation.max((p.y - 4.0).abs());
                straight.push(p.x);
            }
        })
        .expect("solves the revolution");
    // Lengths are crank lengths and ω = 1: position, velocity and acceleration are all O(1).
    for (level, e) in error.iter().enumerate() {
        assert!(*e <= 1e-10, "tracer level {level}: error {e:e}");
    }
    // The sampled path can only miss the closed form's peak deviation by its curvature over
    // half a step (0.25° of crank): far below 1e-5.
    let reference = closed_form_deviation();
    assert!(
        (reference - 0.009_753_7).abs() < 1e-6,
        "closed form {reference}"
    );
    assert!(
        deviation <= reference && reference - deviation < 1e-5,
        "straightness {deviation} vs closed form {reference}"
    );
    // The straight run covers the stroke of 4 crank lengths: 0.24 % deviation.
    let stroke = straight.iter().fold(f64::MIN, |m, &x| m.max(x))
        - straight.iter().fold(f64::MAX, |m, &x| m.min(x));
    assert!((stroke - 4.0).abs() < 1e-9, "stroke {stroke}");
    assert!(deviation / stroke < 0.0025);
}

#[test]
fn hoeken_transmission_angle_is_the_rocker_angle_less_the_coupler_angle() {
    let mut simulation = Simulation::new(Solver::new(Hoeken::default()), 0.0).expect("assembles");
    simulation
        .run(6.0, 60, |state| {
            let (coupler, rocker, m) = (state.coupler(), state.rocker(), state.transmission());
            assert!((m.angle - (rocker.theta - coupler.theta)).abs() <= 1e-14);
            assert!((m.angle_dot - (rocker.theta_dot - coupler.theta_dot)).abs() <= 1e-13);
            assert!((m.angle_ddot - (rocker.theta_ddot - coupler.theta_ddot)).abs() <= 1e-12);
        })
        .expect("solves");
}

#[test]
fn planetary_speeds_follow_willis() {
    // Willis, ring fixed: (ω_s − ω_c) / (0 − ω_c) = −z_r / z_s, so ω_c = ω_s z_s / (z_s + z_r);
    // the planet, meshing externally with the sun, turns at ω_c − (z_s / z_p)(ω_s − ω_c).
    let (z_sun, z_planet, z_ring) = (24.0, 24.0, 72.0);
    let omega = Planetary::default().omega;
    let carrier = omega * z_sun / (z_sun + z_ring);
    let planet = carrier - z_sun / z_planet * (omega - carrier);
    let mut simulation =
        Simulation::new(Solver::new(Planetary::default()), 0.0).expect("assembles");
    simulation
        .run(1.0, 100, |state| {
            let t = state.t;
            assert!((state.carrier().theta_dot - carrier).abs() <= 1e-12 * omega);
            assert!((state.planet().theta_dot - planet).abs() <= 1e-12 * omega);
            assert!((state.output().angle - carrier * t).abs() <= 1e-12);
            assert!((state.output().angle_dot - carrier).abs() <= 1e-12 * omega);
            // The tooth: the planet's centre on the carrier at 48, plus 24 along its angle.
            let (centre, spin) = (carrier * t, planet * t);
            let exact = [
                48.0 * centre.cos() + 24.0 * spin.cos(),
                48.0 * centre.sin() + 24.0 * spin.sin(),
            ];
            let tooth = state.tooth();
            assert!((tooth.x - exact[0]).abs() <= 1e-10 && (tooth.y - exact[1]).abs() <= 1e-10);
            let speed = [
                -48.0 * carrier * centre.sin() - 24.0 * planet * spin.sin(),
                48.0 * carrier * centre.cos() + 24.0 * planet * spin.cos(),
            ];
            assert!(
                (tooth.x_dot - speed[0]).abs() <= 1e-9 && (tooth.y_dot - speed[1]).abs() <= 1e-9
            );
        })
        .expect("solves");
    // Willis' ratio is rolling without slip: the planet's pitch point against the ring
    // (radius 72) is at rest, 48 ω_c + 24 ω_p = 0.
    assert!((48.0 * carrier + 24.0 * planet).abs() <= 1e-12);
}
