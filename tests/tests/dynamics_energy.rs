//! The energy book of the forward dynamics (kinetic + gravity + springs − work of the loads −
//! work of the drivers + dissipated = constant):
//!
//! - an undamped pendulum (its centre of mass off its reference point) with ρ∞ = 1 keeps its
//!   energy over 1,000 periods within a documented bound, with no drift, and its book agrees
//!   with the closed-form energy of `mechgen_tests::reference::pendulum`;
//! - the free seed with a damper between piston and liner loses exactly what the damper
//!   dissipates, against the reduced reference's dissipation integral;
//! - a free pendulum on a driven crank: the driver's work balances the book.

mod dynamics;

use dynamics::{fixed, sample, start, times};
use mechgen_tests::reference::ode::{self, Tolerance};
use mechgen_tests::reference::pendulum::Pendulum as Reference;
use mechgen_tests::reference::seed::FreeSeed;
use std::f64::consts::FRAC_PI_2;

mechgen_runtime::mechanism! {
    mechanism OffsetPendulum {
        ground frame at (0, 0, 0);
        /// Reference point at the pivot, the centre of mass 150 mm out along the body's x axis.
        body arm near (0, 0, -90deg) mass 2 inertia 5000 centre (150, 0);
        joint pivot: revolute(frame, arm);
        free swing: angle(arm) from 0.5 - 90deg;
        gravity (0, -9810);
    }
}

mechgen_runtime::mechanism! {
    mechanism DampedSeed {
        /// Damping of the dashpot between liner and piston (kg/s).
        param c = 2.0;

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

        /// A dashpot from the liner's axis 100 mm beyond the liner to the piston.
        load dashpot: spring(liner @ (100, 0), piston, damping c);

        branch piston_outboard: dot(bearing -> liner, rod @ (41.3, 0) -> rod @ (0, 102.6)) > 0;

        gravity (0, -9810);
    }
}

mechgen_runtime::mechanism! {
    mechanism SwingOnACrank {
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0) mass 1 inertia 2000;
        body arm near (40, -100, -90deg) mass 0.5 inertia 800;
        joint bearing: revolute(frame, crank);
        joint hinge: revolute(crank @ (40, 0), arm @ (-100, 0));
        driver spin: angle(crank) = 10 * t;
        free swing: angle(arm) from -60deg;
        gravity (0, -9810);
    }
}

/// The offset pendulum's mass properties as the reference's.
const PENDULUM: Reference = Reference {
    mass: 2.0,
    inertia: 5000.0,
    arm: 150.0,
    gravity: 9810.0,
};

/// The bound of the undamped test: with ρ∞ = 1 (the trapezoidal rule of the average
/// acceleration) and 50 steps per period, the energy of a 0.5 rad swing oscillates by less than
/// 1e-3 of the swing's energy, and its largest excursion over the last 100 of 1,000 periods is
/// within 1.5 times that over the first 100 (no secular drift).
const UNDAMPED_BOUND: f64 = 1e-3;

#[test]
fn an_undamped_pendulum_keeps_its_energy_over_a_thousand_periods() {
    let amplitude = 0.5;
    let period = PENDULUM.period(amplitude);
    let h = period / 50.0;
    let mut integrator = start(OffsetPendulum::default(), fixed(h, 1.0));
    let swing = PENDULUM.energy(&[amplitude, 0.0]);
    let total = integrator.energy().total();
    let (mut first, mut last, mut all) = (0.0f64, 0.0f64, 0.0f64);
    let steps = 50 * 1000;
    for n in 1..=steps {
        integrator
            .step()
            .unwrap_or_else(|e| panic!("step {n}: {e}"));
        let energy = integrator.energy();
        let deviation = (energy.total() - total).abs() / swing;
        all = all.max(deviation);
        if n <= 50 * 100 {
            first = first.max(deviation);
        }
        if n > 50 * 900 {
            last = last.max(deviation);
        }
        // The book against the reference's energy of the integrator's own angle and rate
        // (zero hanging at rest; the book's gravity is zero at the pivot's height).
        if n % 500 == 0 {
            let [u, rate, _] = integrator.free_state(0);
            let closed = PENDULUM.energy(&[u + FRAC_PI_2, rate]) - 2.0 * 9810.0 * 150.0;
            let book = energy.kinetic + energy.gravity;
            assert!(
                (book - closed).abs() <= 1e-9 * swing,
                "step {n}: {book} vs {closed}"
            );
        }
    }
    assert!((integrator.t() - 1000.0 * period).abs() <= 1e-6 * period);
    eprintln!(
        "undamped pendulum, ρ∞ = 1, h = T/50, 1,000 periods: |ΔE|/E_swing ≤ {all:.1e} \
         (first 100 periods {first:.1e}, last 100 {last:.1e})"
    );
    assert!(all <= UNDAMPED_BOUND, "{all:e}");
    assert!(
        last <= 1.5 * first + 1e-12,
        "drift: first {first:e}, last {last:e}"
    );
}

#[test]
fn a_damped_seed_loses_what_its_damper_dissipates() {
    let seed = FreeSeed::with_spring(256.8, 0.0, 2.0, FreeSeed::RELEASE);
    let at = times(1.0, 50);
    let exact = ode::sample(
        |_, y| seed.rate(y),
        0.0,
        [FreeSeed::RELEASE, 0.0, 0.0],
        &at,
        Tolerance::REFERENCE,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let dissipated = exact.last().unwrap()[2];
    // It dissipates a noticeable part of the energy the swing exchanges.
    let scale = 0.4 * 9810.0 * 86.0;
    assert!(dissipated > 0.02 * scale, "{dissipated}");

    // Bounds: generalized-α (ρ∞ = 0.9) on the reduced equation, emulated at this step with
    // the trapezoidal quadrature of the damper's power, balances to 1.1e-7 and dissipates
    // within 2.2e-8 of the reference (measured here: 1.1e-7 and 9.6e-8, the latter including
    // the Newton tolerance's share over 10,000 steps).
    let mut integrator = start(DampedSeed::default(), fixed(1e-4, 0.9));
    let total = integrator.energy().total();
    let mut previous = 0.0;
    let mut largest = [0.0f64; 2];
    for (s, y) in sample(&mut integrator, &at).iter().zip(&exact) {
        let book = s.energy;
        assert!(
            book.dissipated >= previous,
            "t = {}: dissipation decreased",
            s.t
        );
        previous = book.dissipated;
        let balance = (book.total() - total).abs() / scale;
        let lost = (book.dissipated - y[2]).abs() / dissipated;
        largest = [largest[0].max(balance), largest[1].max(lost)];
        assert!(balance <= 5e-7, "t = {}: balance off by {balance:e}", s.t);
        assert!(
            lost <= 3e-7,
            "t = {}: dissipated {} vs {}",
            s.t,
            book.dissipated,
            y[2]
        );
        // A dashpot stores nothing and no load works here; without a driver, the drivers' work
        // is that of the free equation's residual effort, zero to the Newton tolerance.
        assert_eq!([book.springs, book.loads_work], [0.0; 2]);
        assert!(
            book.drivers_work.abs() <= 1e-9 * scale,
            "{}",
            book.drivers_work
        );
    }
    eprintln!(
        "damped seed, 1 s, h = 1e-4: dissipated {previous:.6e} vs reference {dissipated:.6e}; \
         balance within {:.1e}, dissipation within {:.1e} (relative)",
        largest[0], largest[1]
    );
}

#[test]
fn a_driver_s_work_balances_the_book() {
    // Bound: the reduced equation of the arm on its moving pivot, emulated with generalized-α
    // (ρ∞ = 0.9) at this step and the trapezoidal quadrature of the driver's power, balances to
    // 1.6e-7 (measured here: 1.5e-7).
    let mut integrator = start(SwingOnACrank::default(), fixed(1e-4, 0.9));
    let total = integrator.energy().total();
    // The arm's weight over the crank's and arm's lengths.
    let scale = 0.5 * 9810.0 * 140.0;
    let (mut work, mut largest) = (0.0f64, 0.0f64);
    for s in sample(&mut integrator, &times(1.0, 50)) {
        let balance = (s.energy.total() - total).abs() / scale;
        largest = largest.max(balance);
        assert!(balance <= 5e-7, "t = {}: balance off by {balance:e}", s.t);
        work = work.max(s.energy.drivers_work.abs());
    }
    eprintln!(
        "swing on a crank, 1 s, h = 1e-4: balance within {largest:.1e}, driver's work {work:.3e}"
    );
    // The driver does work on the swinging arm: the term is exercised.
    assert!(work > 1e-2 * scale, "{work}");
}
