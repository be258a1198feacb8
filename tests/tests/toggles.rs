//! Singular crossings are caught wherever they happen: slider-cranks whose rod equals the crank
//! and four-bars at a Grashof change point, stepped with random step sizes (one of them landing
//! exactly on the toggle time), report `Singular` within one step of the toggle and never
//! return a finite state at it or past it, with or without a declared branch. Mechanisms that
//! pass near a toggle without reaching it still solve, on both sides of it; those that cannot
//! reach it lock up with `Singular` or `NoAssembly`, never with advice about step sizes.

use mechgen_examples::closed_form;
use mechgen_examples::stability::SliderCrank;
use mechgen_runtime::{
    Mechanism, Simulation, SolveError, Solver, State, Structured, Unit, mechanism,
    nalgebra::DefaultAllocator,
};
use mechgen_tests::toggle_times;
use proptest::prelude::*;

mechanism! {
    /// An in-line slider-crank without a branch invariant: nothing tells the solver which
    /// branch to keep, so only the crossing check stands between it and a silent switch.
    pub mechanism FreeSliderCrank {
        /// Crank radius.
        param r = 1.0;
        /// Rod length.
        param l = 1.0;
        /// Crank speed (rad/s).
        param omega = 1.0;

        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body rod near (r, 0, 0);
        body slider near (r + l, 0, 0);

        joint pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (r, 0), rod);
        joint wrist_pin: revolute(rod @ (l, 0), slider);
        joint slide: prismatic(frame, slider, along (1, 0));

        driver turn: angle(crank) = omega * t;
    }
}

mechanism! {
    /// A four-bar at a Grashof change point (frame + coupler = crank + rocker): a
    /// parallelogram, whose links all line up at crank angles 0 and π, where the parallelogram
    /// and anti-parallelogram branches cross.
    pub mechanism ChangePointFourBar {
        /// Crank and rocker length.
        param crank_length = 1.0;
        /// Frame and coupler length.
        param frame_length = 2.0;
        /// Crank speed (rad/s).
        param omega = 1.0;
        /// Crank angle at t = 0.
        param phase = 0.5;

        ground frame at (0, 0, 0);
        body crank near (0, 0, 0.5);
        body coupler near (0.88, 0.48, 0);
        body rocker near (frame_length, 0, 0.5);

        joint pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (crank_length, 0), coupler);
        joint rocker_pin: revolute(coupler @ (frame_length, 0), rocker @ (crank_length, 0));
        joint rocker_pivot: revolute(rocker, frame @ (frame_length, 0));

        driver turn: angle(crank) = omega * t + phase;
    }
}

/// Steps from the assembled start through `times`, returning the states solved and the error
/// that ended the run, if any.
fn run<M: Structured + Clone>(scene: M, times: &[f64]) -> (Vec<f64>, Option<SolveError>)
where
    DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    let mut simulation = Simulation::new(Solver::new(scene), 0.0).expect("assembles at t = 0");
    let mut solved = vec![0.0];
    for &t in times {
        match simulation.step_to(t) {
            Ok(state) => {
                assert!(state.q.iter().all(|x| x.is_finite()));
                solved.push(state.t);
            }
            Err(error) => return (solved, Some(error)),
        }
    }
    (solved, None)
}

/// The run ended with `Singular` within one step of the toggle, and no state was returned at
/// the toggle or past it.
fn assert_caught(toggle: f64, times: &[f64], solved: &[f64], error: Option<SolveError>) {
    let error = error.unwrap_or_else(|| panic!("stepped through the toggle at {toggle}"));
    let SolveError::Singular { time, .. } = error else {
        panic!("expected Singular near {toggle}, got {error:?}");
    };
    let longest = times
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(times[0], f64::max);
    assert!(
        (time - toggle).abs() <= longest,
        "Singular at {time}, toggle at {toggle}"
    );
    let last = *solved.last().unwrap();
    // A state within the Newton resolution of the toggle (√ε of the motion) is at it.
    assert!(
        last < toggle - 1e-7 * toggle,
        "a state was returned at t = {last}, toggle at {toggle}"
    );
}

fn slider_crank_toggle(omega: f64) -> f64 {
    core::f64::consts::FRAC_PI_2 / omega
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn rod_equal_to_crank_reports_the_toggle_with_or_without_a_branch(
        r in 0.2_f64..5.0,
        omega in 0.5_f64..20.0,
        per_quarter in 3_usize..60,
        fractions in prop::collection::vec(0.3_f64..1.7, 1..8),
        land in any::<bool>(),
    ) {
        let toggle = slider_crank_toggle(omega);
        let times = toggle_times(toggle, toggle / per_quarter as f64, &fractions, land);
        let (solved, error) = run(SliderCrank { r, l: r, omega }, &times);
        assert_caught(toggle, &times, &solved, error);
        let (solved, error) = run(FreeSliderCrank { r, l: r, omega }, &times);
        assert_caught(toggle, &times, &solved, error);
    }

    #[test]
    fn change_point_four_bar_reports_its_change_point(
        crank in 0.3_f64..3.0,
        ratio in 1.2_f64..4.0,
        omega in 0.5_f64..20.0,
        per_half in 4_usize..60,
        fractions in prop::collection::vec(0.3_f64..1.7, 1..8),
        land in any::<bool>(),
    ) {
        // From crank angle 0.5 to the line-up at π.
        let toggle = (core::f64::consts::PI - 0.5) / omega;
        let times = toggle_times(toggle, toggle / per_half as f64, &fractions, land);
        let scene = ChangePointFourBar {
            crank_length: crank,
            frame_length: crank * ratio,
            omega,
            phase: 0.5,
        };
        let (solved, error) = run(scene, &times);
        assert_caught(toggle, &times, &solved, error);
    }

    #[test]
    fn rod_slightly_longer_than_the_crank_passes_near_the_toggle(
        r in 0.2_f64..5.0,
        excess in -6.0_f64..-2.0,
        per_quarter in 6_usize..40,
        fractions in prop::collection::vec(0.5_f64..1.5, 1..6),
        land in any::<bool>(),
    ) {
        // l = r (1 + 10^excess): the rod is never perpendicular to the slide, but within
        // √(2·10^excess) rad of it at the near-toggle (crank at π/2). Samples on both sides
        // of it, and exactly at it when `land`.
        let l = r * (1.0 + 10_f64.powf(excess));
        let near = slider_crank_toggle(1.0);
        let times = toggle_times(near, near / per_quarter as f64, &fractions, land);
        let exact = closed_form::SliderCrank { crank: r, rod: l, omega: 1.0 };
        let mut simulation =
            Simulation::new(Solver::new(SliderCrank { r, l, ..SliderCrank::default() }), 0.0)
                .unwrap();
        for &t in &times {
            let state = simulation
                .step_to(t)
                .unwrap_or_else(|e| panic!("l = {l}, r = {r}, t = {t}: {e:?}"));
            // Angles compare modulo whole turns: a coarse step past the near-toggle, where the
            // rod's angular acceleration is ~1/√(l − r), may leave the rod angle unwrapped by
            // 2π (the same pose). Lengths compare as they are.
            let q = exact.kinematics(t).q;
            for (k, (a, b)) in state.q.iter().zip(q.iter()).enumerate() {
                let d = a - b;
                let error = match SliderCrank::default().coordinate_unit(k) {
                    Unit::Angle => (d - core::f64::consts::TAU * (d / core::f64::consts::TAU).round()).abs(),
                    _ => d.abs(),
                };
                prop_assert!(error <= 1e-8 * r, "t = {t}, q[{k}]: error {error:e}");
            }
        }
    }

    #[test]
    fn rod_slightly_shorter_than_the_crank_locks_up_before_the_toggle(
        r in 0.2_f64..5.0,
        deficit in -6.0_f64..-2.0,
        per_quarter in 3_usize..40,
        fractions in prop::collection::vec(0.5_f64..1.5, 1..6),
    ) {
        // l = r (1 − 10^deficit): the crank cannot pass the angle where r sin θ = l.
        let l = r * (1.0 - 10_f64.powf(deficit));
        // The samples run up to the dead point, then one lands in the range the crank cannot
        // reach (a step over the whole range can still land on its far side: see the module
        // docs of `crossing`).
        let limit = (l / r).asin();
        let mut times = toggle_times(limit, limit / per_quarter as f64, &fractions, false);
        times.retain(|&t| t < limit);
        times.push(core::f64::consts::FRAC_PI_2);
        let scene = SliderCrank { r, l, ..SliderCrank::default() };
        let (solved, error) = run(scene, &times);
        let error = error.expect("cannot pass its dead point");
        prop_assert!(
            matches!(error, SolveError::Singular { .. } | SolveError::NoAssembly { .. }),
            "{error:?}"
        );
        prop_assert!(*solved.last().unwrap() <= limit, "{solved:?}");
    }
}

/// The crossing is found even when every sample avoids the toggle by a wide margin.
#[test]
fn a_step_straddling_the_toggle_is_bisected_to_it() {
    let toggle = slider_crank_toggle(1.0);
    let times = [0.5, toggle + 0.4];
    let scene = FreeSliderCrank::default();
    let mut simulation = Simulation::new(Solver::new(scene), 0.0).unwrap();
    simulation.step_to(times[0]).unwrap();
    let before: State<FreeSliderCrank> = simulation.state().clone();
    let error = simulation.step_to(times[1]).unwrap_err();
    let SolveError::Singular { time, .. } = error else {
        panic!("{error:?}");
    };
    assert!((time - toggle).abs() <= 1e-6, "{time} vs {toggle}");
    assert_eq!(simulation.state().t, before.t);
    let described = simulation.solver().describe(&error).to_string();
    assert!(
        described.contains("slider.x") || described.contains("rod"),
        "{described}"
    );
}
