//! Forward dynamics of a double pendulum (two bars, two free angles) against its Lagrange
//! equations in reduced coordinates written out by hand and integrated to about 1e-12
//! (`mechgen_tests::reference::double_pendulum`), generated and interpreted alike: the free
//! angles and rates, the centres of mass, and the constraints at every accepted step; and
//! its fixed steps against generalized-α written from the papers on the same equations.

mod dynamics;

use dynamics::{adaptive, assert_constrained, fixed, interpreted, sample, start, times};
use mechgen_runtime::nalgebra::DefaultAllocator;
use mechgen_runtime::{Dynamic, EquationsOfMotion, FreeStorage, Storage, Structured};
use mechgen_tests::reference::double_pendulum::{Bar, DoublePendulum as Reference};
use mechgen_tests::reference::generalized_alpha::GeneralizedAlpha;
use mechgen_tests::reference::ode::{self, Tolerance};
use mechgen_tests::twin;

twin! {
    DOUBLE,
    mechanism DoublePendulum {
        ground frame at (0, 0, 0);
        /// Bars along their x axes, each reference point at its centre of mass.
        body upper near (0, -60, -90deg) mass 1 inertia 3000;
        body lower near (0, -170, -90deg) mass 0.6 inertia 1800;
        joint shoulder: revolute(frame, upper @ (-60, 0));
        joint elbow: revolute(upper @ (60, 0), lower @ (-50, 0));
        free upper_angle: angle(upper) from -1.0;
        free lower_angle: angle(lower) from -0.6 speed 2;
        gravity (0, -9810);
    }
}

/// The scene as the reference sees it: centres 60 and 50 mm from the pivots, the elbow
/// 120 mm from the shoulder.
const REFERENCE: Reference = Reference {
    first: Bar {
        mass: 1.0,
        inertia: 3000.0,
        centre: 60.0,
        length: 120.0,
    },
    second: Bar {
        mass: 0.6,
        inertia: 1800.0,
        centre: 50.0,
        length: 0.0,
    },
    gravity: [0.0, -9810.0],
};

/// `θ` of the upper and lower bars in `q` (frame, upper, lower).
const THETAS: [usize; 2] = [5, 8];

/// Compares a run of `mechanism` with the reference over one second; returns the largest
/// angle and rate errors.
fn compare<M>(label: &str, mechanism: M) -> (f64, f64)
where
    M: Dynamic + EquationsOfMotion + Structured,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    let at = times(1.0, 50);
    let start_state = [-1.0, -0.6, 0.0, 2.0];
    let exact = ode::sample(
        |_, y| REFERENCE.rate(y),
        0.0,
        start_state,
        &at,
        Tolerance::REFERENCE,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let mut integrator = start(mechanism, fixed(1e-4, 0.9));
    for k in 0..2 {
        let [u, rate, _] = integrator.free_state(k);
        assert_eq!(
            [u, rate],
            [start_state[k], start_state[k + 2]],
            "{label}: free {k}"
        );
    }
    let (mut angle, mut rate) = (0.0f64, 0.0f64);
    for (s, y) in sample(&mut integrator, &at).iter().zip(&exact) {
        for k in 0..2 {
            assert!((s.q[THETAS[k]] - s.free[k][0]).abs() <= 1e-12);
            angle = angle.max((s.free[k][0] - y[k]).abs());
            rate = rate.max((s.free[k][1] - y[k + 2]).abs());
        }
        // The centres of mass are the bodies' reference points.
        let centres = REFERENCE.centres(y[0], y[1]);
        let placed = [[s.q[3], s.q[4]], [s.q[6], s.q[7]]];
        for (c, p) in centres.iter().zip(&placed) {
            let off = (c[0] - p[0]).hypot(c[1] - p[1]);
            assert!(
                off <= 170.0 * 1e-5,
                "{label}, t = {}: centre off by {off:e} mm",
                s.t
            );
        }
    }
    eprintln!(
        "{label}: double pendulum, 1 s, h = 1e-4: |θ − θ_ref| {angle:.1e} rad, |θ̇ − θ̇_ref| {rate:.1e} rad/s"
    );
    (angle, rate)
}

#[test]
fn the_double_pendulum_follows_its_lagrange_equations() {
    // Rates reach 10 rad/s. Generalized-α (ρ∞ = 0.9) on the reduced equations, emulated at
    // h = 1e-4, is off by 3.6e-7 rad and 4.1e-6 rad/s.
    for (label, errors) in [
        ("generated", compare("generated", DoublePendulum::default())),
        ("interpreted", compare("interpreted", interpreted(DOUBLE))),
    ] {
        assert!(errors.0 <= 1e-6, "{label}: angle {:e}", errors.0);
        assert!(errors.1 <= 1.5e-5, "{label}: rate {:e}", errors.1);
    }
}

#[test]
fn fixed_steps_are_generalized_alpha_on_the_lagrange_equations() {
    // Both free angles in one Newton iteration: the steps are those of
    // `reference::generalized_alpha` on the two reduced equations, to the integrator's Newton
    // tolerance (1e-10 rad; measured 1.3e-11 rad over 300 steps at ρ∞ = 1 and 0.6).
    for rho_inf in [1.0, 0.6] {
        let mut reduced = GeneralizedAlpha::new(
            |_, u: &[f64; 2], v: &[f64; 2]| {
                let r = REFERENCE.rate(&[u[0], u[1], v[0], v[1]]);
                [r[2], r[3]]
            },
            0.0,
            [-1.0, -0.6],
            [0.0, 2.0],
            rho_inf,
        );
        let mut integrator = start(DoublePendulum::default(), fixed(1e-3, rho_inf));
        let mut largest = 0.0f64;
        for n in 1..=300 {
            integrator.step().unwrap_or_else(|e| panic!("{e}"));
            reduced.step(1e-3).unwrap_or_else(|e| panic!("{e}"));
            let [u, _, _] = reduced.state();
            for (k, expected) in u.iter().enumerate() {
                let got = integrator.free_state(k)[0];
                largest = largest.max((got - expected).abs());
                assert!(
                    (got - expected).abs() <= 1e-10,
                    "ρ∞ = {rho_inf}, step {n}, free {k}: {got} vs {expected}"
                );
            }
        }
        eprintln!(
            "double pendulum, h = 1 ms, ρ∞ = {rho_inf}: {largest:.1e} rad from generalized-α"
        );
    }
}

#[test]
fn every_accepted_step_keeps_both_joints_and_both_free_angles() {
    let mut integrator = start(DoublePendulum::default(), adaptive(1e-6, 1e-9));
    assert_constrained(&integrator, &THETAS);
    while integrator.t() < 1.0 {
        integrator.step().unwrap_or_else(|e| panic!("{e}"));
        assert_constrained(&integrator, &THETAS);
    }
}

#[test]
fn the_energy_book_is_the_reference_s_energy() {
    // Kinetic plus gravity energy of the book against the reference's expression of the
    // integrator's own angles and rates (independent formulas: ½ q̇ᵀMq̇ over Cartesian
    // coordinates against T(θ, θ̇) of the Lagrangian), and no loads, springs or dampers.
    let mut integrator = start(DoublePendulum::default(), adaptive(1e-8, 1e-10));
    for s in sample(&mut integrator, &times(0.5, 10)) {
        let y = [s.free[0][0], s.free[1][0], s.free[0][1], s.free[1][1]];
        let book = s.energy.kinetic + s.energy.gravity;
        let reference = REFERENCE.energy(&y);
        assert!(
            (book - reference).abs() <= 1e-9 * reference.abs().max(1e5),
            "t = {}: book {book}, reference {reference}",
            s.t
        );
        assert_eq!(
            [s.energy.springs, s.energy.loads_work, s.energy.dissipated],
            [0.0; 3]
        );
        // No driver: what the book counts as drivers' work is that of the free equations'
        // residual efforts, zero to the Newton tolerance.
        assert!(
            s.energy.drivers_work.abs() <= 1e-9 * 1e6,
            "{}",
            s.energy.drivers_work
        );
    }
}
