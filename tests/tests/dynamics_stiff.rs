//! The stiff case: the free seed with a spring of stiffness 1e7 kg/s² between the liner and
//! the piston, at its free length at the release angle. The spring nearly locks the crank:
//! released from rest at 0.3 rad, the crank oscillates by a few µrad with the spring's period
//! (3.3 ms at the release angle, from `FreeSeed::local_frequency`), which a step of 1 ms does
//! not resolve. Against the reduced reference (`mechgen_tests::reference::seed`):
//!
//! - at a step of 1e-3 s the motion stays bounded (within a few times the reference's
//!   excursion) and the energy book gains no more than that oscillation's energy, with
//!   ρ∞ = 0.5 and ρ∞ = 0;
//! - those steps are generalized-α's on the reduced equation (written from the papers);
//! - as the step shrinks the error falls towards the reference.
//!
//! And a spring 1,000 times faster than the step: the seed whose rod is a spring of stiffness
//! 1e14 kg/s² (its piston pin in a slot along the rod, the rod's length a second free degree of
//! freedom), natural period below 6e-7 s, stepped at h = 1e-3 s: no smaller step, no blow-up,
//! the rod's stretch its static deflection, and the crank the rigid seed's (generalized-α on
//! the rigid reduced equation, at the same step), at the default Newton tolerance; and the
//! same for stiffnesses 1e10 to 1e13 with the output on a 1 ms grid.

mod dynamics;

use dynamics::{assert_constrained, fixed, start};
use mechgen_tests::reference::generalized_alpha::GeneralizedAlpha;
use mechgen_tests::reference::ode::{self, Tolerance};
use mechgen_tests::reference::seed::FreeSeed as Reference;

mechgen_runtime::mechanism! {
    mechanism StiffSeed {
        /// Free length of the spring (mm): set to its length at the release angle.
        param rest = 138.8;

        ground liner at (156.8, 0, 0);
        body piston near (130, 0, 0) mass 0.5 inertia 300;
        body rod near (29, 72, -2.35) mass 0.4 inertia 1500;
        body crank near (0, 0, 0) mass 1.2 inertia 2000;
        ground bearing at (0, 0, 0);

        joint crank_pin: revolute(rod @ (41.3, 0), crank @ (0, 43));
        joint piston_pin: revolute(piston @ (-28, 0), rod @ (0, 102.6));
        joint main_bearing: revolute(crank, bearing);
        joint slide: prismatic(liner, piston, along (1, 0));

        free crank_angle: angle(crank) from 0.3;

        /// From the liner's axis 100 mm beyond the liner to the piston.
        load coil: spring(liner @ (100, 0), piston, stiffness 1e7, length rest);

        branch piston_outboard: dot(bearing -> liner, rod @ (41.3, 0) -> rod @ (0, 102.6)) > 0;

        gravity (0, -9810);
    }
}

mechgen_runtime::mechanism! {
    mechanism ElasticRodSeed {
        /// The rod's axial stiffness (kg/s²).
        param k = 1e14;
        /// The rod's length between its pins (mm), the spring's free length.
        param rod_length = sqrt(41.3^2 + 102.6^2);

        ground liner at (156.8, 0, 0);
        body piston near (130, 0, 0) mass 0.5 inertia 300;
        body rod near (29, 72, -2.35) mass 0.4 inertia 1500;
        body crank near (0, 0, 0) mass 1.2 inertia 2000;
        ground bearing at (0, 0, 0);

        joint crank_pin: revolute(rod @ (41.3, 0), crank @ (0, 43));
        /// The piston pin slides along the rod's axis: the rod's length is free.
        joint piston_pin: slot(rod @ (0, 102.6), piston @ (-28, 0), along (41.3, -102.6));
        joint main_bearing: revolute(crank, bearing);
        joint slide: prismatic(liner, piston, along (1, 0));

        free crank_angle: angle(crank) from 0.3;
        /// How much shorter than `rod_length` the rod is.
        free shortening: slide(rod @ (0, 102.6), piston @ (-28, 0), along (41.3, -102.6)) from 0;

        /// The rod's axial stiffness, between its pins.
        load axial: spring(rod @ (41.3, 0), piston @ (-28, 0), stiffness k, length rod_length);

        branch piston_outboard: dot(bearing -> liner, rod @ (41.3, 0) -> rod @ (0, 102.6)) > 0;

        gravity (0, -9810);
    }
}

/// The crank's angle in `q`.
const CRANK_THETA: usize = 11;

/// The reference seed: the same spring, at rest at the release angle.
fn reference() -> Reference {
    Reference::with_spring(256.8, 1e7, 0.0, Reference::RELEASE)
}

/// The scene with its spring's free length the reference's.
fn scene(seed: &Reference) -> StiffSeed {
    StiffSeed {
        rest: seed.spring.expect("a spring").length,
        ..StiffSeed::default()
    }
}

/// The reference crank angle every `dt` over `(0, t_end]`.
fn exact(seed: &Reference, dt: f64, t_end: f64) -> Vec<f64> {
    let n = (t_end / dt).round() as usize;
    let at: Vec<f64> = (1..=n).map(|i| i as f64 * dt).collect();
    ode::sample(
        |_, y| seed.rate(y),
        0.0,
        [Reference::RELEASE, 0.0, 0.0],
        &at,
        Tolerance::REFERENCE,
    )
    .unwrap_or_else(|e| panic!("{e}"))
    .iter()
    .map(|y| y[0])
    .collect()
}

#[test]
fn a_millisecond_step_stays_bounded() {
    let seed = reference();
    let period = std::f64::consts::TAU / seed.local_frequency(Reference::RELEASE);
    assert!(period > 3e-3 && period < 4e-3, "{period}");
    // The reference's excursion from the release angle (a few µrad).
    let excursion = exact(&seed, 1e-3, 0.1)
        .iter()
        .map(|phi| (phi - Reference::RELEASE).abs())
        .fold(0.0, f64::max);
    assert!(excursion > 1e-6 && excursion < 1e-4, "{excursion}");
    // The energy of that oscillation: the spring's at the piston's displacement there.
    let piston = |phi: f64| seed.configuration(phi).q[3];
    let stretch = piston(Reference::RELEASE + excursion) - piston(Reference::RELEASE);
    let oscillation = 0.5 * 1e7 * stretch * stretch;
    for rho_inf in [0.5, 0.0] {
        let mut integrator = start(scene(&seed), fixed(1e-3, rho_inf));
        let total = integrator.energy().total();
        let mut largest = 0.0f64;
        for n in 1..=500 {
            integrator
                .step()
                .unwrap_or_else(|e| panic!("ρ∞ = {rho_inf}, step {n}: {e}"));
            assert_constrained(&integrator, &[CRANK_THETA]);
            let phi = integrator.free_state(0)[0];
            largest = largest.max((phi - Reference::RELEASE).abs());
            assert!(
                largest <= 3.0 * excursion,
                "ρ∞ = {rho_inf}, step {n}: {phi}"
            );
            // The unresolved oscillation gains no energy beyond its own (no blow-up).
            let gained = integrator.energy().total() - total;
            assert!(
                gained <= 2.0 * oscillation,
                "ρ∞ = {rho_inf}, step {n}: +{gained:e}"
            );
        }
        assert_eq!(integrator.stats().steps, 500);
        eprintln!(
            "stiff seed, h = 1 ms, ρ∞ = {rho_inf}: largest excursion {largest:.2e} rad \
             (reference {excursion:.2e})"
        );
    }
}

#[test]
fn a_millisecond_step_is_generalized_alpha_on_the_reduced_equation() {
    // What the bounded run above does is the method's doing: its steps are those of
    // `reference::generalized_alpha` on the reduced equation with the stiff spring, to the
    // integrator's Newton tolerance (1e-10 rad; measured: 3e-15 rad at ρ∞ = 0.5 and 0).
    let seed = reference();
    for rho_inf in [0.5, 0.0] {
        let mut reduced = GeneralizedAlpha::new(
            |_, u: &[f64; 1], v: &[f64; 1]| [seed.acceleration(u[0], v[0])],
            0.0,
            [Reference::RELEASE],
            [0.0],
            rho_inf,
        );
        let mut integrator = start(scene(&seed), fixed(1e-3, rho_inf));
        let mut largest = 0.0f64;
        for n in 1..=100 {
            integrator.step().unwrap_or_else(|e| panic!("{e}"));
            reduced.step(1e-3).unwrap_or_else(|e| panic!("{e}"));
            let (u, v) = (integrator.free_state(0)[0], reduced.state()[0][0]);
            largest = largest.max((u - v).abs());
            assert!(
                (u - v).abs() <= 1e-10,
                "ρ∞ = {rho_inf}, step {n}: {u} vs {v}"
            );
        }
        eprintln!("stiff seed, h = 1 ms, ρ∞ = {rho_inf}: {largest:.1e} rad from generalized-α");
    }
}

#[test]
fn the_stiff_seed_converges_to_the_reference_as_the_step_shrinks() {
    let seed = reference();
    let (t_end, dt) = (0.03, 1e-3);
    let exact = exact(&seed, dt, t_end);
    let excursion = exact
        .iter()
        .map(|phi| (phi - Reference::RELEASE).abs())
        .fold(0.0, f64::max);
    let errors: Vec<f64> = (0..6)
        .map(|k| {
            let h = 1e-3 / f64::from(1 << k);
            let mut integrator = start(scene(&seed), fixed(h, 0.5));
            exact
                .iter()
                .enumerate()
                .map(|(i, phi)| {
                    let t = (i + 1) as f64 * dt;
                    integrator
                        .step_to(t)
                        .unwrap_or_else(|e| panic!("h = {h}: {e}"));
                    (integrator.free_state(0)[0] - phi).abs()
                })
                .fold(0.0, f64::max)
                / excursion
        })
        .collect();
    eprintln!("stiff seed, 30 ms, h = 1 ms / 2^k: errors relative to the excursion {errors:?}");
    // The unresolved step is off by about the excursion; the resolved ones converge at
    // second order (the last halvings divide the error by at least 3).
    assert!(errors[0] <= 2.0, "{errors:?}");
    for w in errors[3..].windows(2) {
        assert!(w[1] <= w[0] / 3.0, "{errors:?}");
    }
    assert!(errors[5] <= 0.05, "{errors:?}");
}

#[test]
fn a_spring_a_thousand_times_faster_than_the_step_needs_no_smaller_step() {
    let k = ElasticRodSeed::default().k;
    // The rod's stretch moves at most the piston and the rod (0.9 kg): its period is below
    // 2π √(0.9 / k) = 6e-7 s, under a thousandth of the step.
    let h = 1e-3;
    let period = std::f64::consts::TAU * (0.9 / k).sqrt();
    assert!(1000.0 * period < h, "{period:e}");
    let seed = Reference::default();
    // The energies the motion exchanges (the rod's weight over the crank's throw).
    let scale = 0.4 * 9810.0 * 86.0;
    for (rho_inf, rigid_bound) in [(0.9, 4e-5), (0.5, 6e-5), (0.0, 2e-4)] {
        let options = fixed(h, rho_inf);
        let mut integrator = start(ElasticRodSeed::default(), options);
        let mut rigid = GeneralizedAlpha::new(
            |_, u: &[f64; 1], v: &[f64; 1]| [seed.acceleration(u[0], v[0])],
            0.0,
            [Reference::RELEASE],
            [0.0],
            rho_inf,
        );
        let exact = exact(&seed, h, 0.5);
        let total = integrator.energy().total();
        let mut largest = [0.0f64; 4];
        let mut gained = 0.0f64;
        for (n, phi) in exact.iter().enumerate() {
            let label = format!("ρ∞ = {rho_inf}, step {}", n + 1);
            integrator.step().unwrap_or_else(|e| panic!("{label}: {e}"));
            rigid.step(h).unwrap_or_else(|e| panic!("{e}"));
            assert_constrained(&integrator, &[CRANK_THETA]);
            let [u, _, _] = integrator.free_state(0);
            let stretch = integrator.free_state(1)[0].abs();
            let energy = integrator.energy().total() - total;
            largest = [
                largest[0].max((u - rigid.state()[0][0]).abs()),
                largest[1].max((u - phi).abs()),
                largest[2].max(stretch),
                largest[3].max(-energy / scale),
            ];
            // The rod's static deflection under its load (below 1e5 mN, the weights and
            // inertia forces of the rigid motion): nothing of the fast mode is excited.
            assert!(stretch <= 1e5 / k, "{label}: stretch {stretch:e} mm");
            // No blow-up: the energy stays within the method's error on the slow motion
            // (numerical damping mostly takes energy out; the resolved motion's energy error
            // also swings above the start, measured up to 1.4e-6 of the scale). The fast mode
            // holds at most ½ k (1e5 / k)² = 5e-5 µJ by the stretch bound above.
            assert!(
                energy.abs() <= 3e-4 * scale,
                "{label}: energy off by {energy:e}"
            );
            gained = gained.max(energy / scale);
        }
        // One step per millisecond: none refused, none shortened.
        assert_eq!(integrator.stats().steps, exact.len());
        assert_eq!(integrator.stats().rejected, 0);
        eprintln!(
            "elastic rod, k = {k:e}, h = 1 ms, ρ∞ = {rho_inf}: crank from the rigid \
             generalized-α {:.1e} rad, from the rigid reference {:.1e} rad, stretch up to \
             {:.1e} mm, energy lost {:.1e}, gained {gained:.1e} of m g r; {:?}",
            largest[0],
            largest[1],
            largest[2],
            largest[3],
            integrator.stats()
        );
        // The crank moves as the rigid seed's does under the same method: the stiff spring
        // acts as the constraint it stands for (measured 3e-10, 1.5e-9, 2.2e-8 rad at ρ∞ = 0.9,
        // 0.5, 0), and so within the method's own error of the exact rigid motion (measured
        // 1.3e-5, 1.9e-5, 6.9e-5 rad).
        assert!(largest[0] <= 1e-7, "ρ∞ = {rho_inf}: {:e}", largest[0]);
        assert!(
            largest[1] <= rigid_bound,
            "ρ∞ = {rho_inf}: {:e}",
            largest[1]
        );
    }
}

/// The elastic rod over four decades of stiffness (periods 50 to 6,000 times shorter than the
/// step), each ρ∞, output on a 1 ms grid (`step_to`, whose landing steps differ from h by
/// rounding, so the iteration matrix is refactored and rebuilt more often than by `step`), at
/// the default Newton tolerance: every step converges (before a rebuilt matrix's correction
/// was tried, k = 1e11 at ρ∞ = 0.9 failed at t = 0.419), and the crank follows the rigid
/// seed's generalized-α.
#[test]
fn every_stiffness_converges_on_a_millisecond_grid() {
    let seed = Reference::default();
    let h = 1e-3;
    for k in [1e10, 1e11, 1e12, 1e13] {
        for rho_inf in [0.9, 0.5, 0.0] {
            let mut integrator = start(
                ElasticRodSeed {
                    k,
                    ..Default::default()
                },
                fixed(h, rho_inf),
            );
            let mut rigid = GeneralizedAlpha::new(
                |_, u: &[f64; 1], v: &[f64; 1]| [seed.acceleration(u[0], v[0])],
                0.0,
                [Reference::RELEASE],
                [0.0],
                rho_inf,
            );
            let mut largest = 0.0f64;
            for n in 1..=500 {
                let t = n as f64 * h;
                integrator
                    .step_to(t)
                    .unwrap_or_else(|e| panic!("k = {k:e}, ρ∞ = {rho_inf}, t = {t}: {e}"));
                rigid.step(h).unwrap_or_else(|e| panic!("{e}"));
                let u = integrator.free_state(0)[0];
                largest = largest.max((u - rigid.state()[0][0]).abs());
            }
            let stats = integrator.stats();
            eprintln!(
                "k = {k:e}, ρ∞ = {rho_inf}: crank from the rigid generalized-α {largest:.1e} rad; {stats:?}"
            );
            assert_eq!((stats.steps, stats.rejected), (500, 0));
            assert!(largest <= 1e-7, "k = {k:e}, ρ∞ = {rho_inf}: {largest:e}");
        }
    }
}
