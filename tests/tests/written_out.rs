//! The written-out closed forms (`mechgen_examples::written_out`, derivatives by hand) against
//! the dual-number closed forms (`closed_form`, derivatives by automatic differentiation of the
//! position formula): two derivations of the same kinematics, which must agree to round-off.

use mechgen_examples::closed_form::{FourBar, Kinematics, PistonCrank};

/// Largest difference over the three levels, relative to each level's largest magnitude.
fn worst<const N: usize>(hand: &([f64; N], [f64; N], [f64; N]), dual: &Kinematics<N>) -> f64 {
    [
        (&hand.0, &dual.q),
        (&hand.1, &dual.qd),
        (&hand.2, &dual.qdd),
    ]
    .into_iter()
    .map(|(a, b)| {
        let scale = b.iter().fold(1e-300_f64, |m, v| m.max(v.abs()));
        a.iter()
            .zip(b)
            .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs() / scale))
    })
    .fold(0.0, f64::max)
}

#[test]
fn the_seed_written_out_matches_its_closed_form_over_a_revolution_at_every_scale() {
    for scale in [1e-6, 1.0, 1e6] {
        for omega in [1.0, 314.0, 1e4] {
            let seed = PistonCrank {
                scale,
                omega,
                ..PistonCrank::default()
            };
            let mut out = ([0.0; 15], [0.0; 15], [0.0; 15]);
            for i in 0..720 {
                let t = seed.period() * i as f64 / 720.0;
                seed.written_out(t, &mut out);
                let error = worst(&out, &seed.kinematics(t));
                assert!(error < 1e-13, "scale {scale}, ω {omega}, t {t}: {error:e}");
            }
        }
    }
}

#[test]
fn the_four_bar_written_out_matches_its_closed_form_over_a_revolution() {
    for omega in [1.0, 10.0, 1e4] {
        let four_bar = FourBar {
            omega,
            ..FourBar::default()
        };
        let mut out = ([0.0; 12], [0.0; 12], [0.0; 12]);
        for i in 0..720 {
            let t = four_bar.period() * i as f64 / 720.0;
            four_bar.written_out(t, &mut out);
            let error = worst(&out, &four_bar.kinematics(t));
            assert!(error < 1e-13, "ω {omega}, t {t}: {error:e}");
        }
    }
}

/// The quick-return's written-out kinematics against the generated solve of its scene, with its
/// two closed-form groups (the slotted lever, the link and ram) and on Newton's path alone: an
/// independent derivation of both, to round-off, over two revolutions stepped 360 times each.
#[test]
fn the_quick_return_written_out_matches_the_solver_with_and_without_closed_forms() {
    use mechgen_examples::scenes::QuickReturn as Scene;
    use mechgen_examples::written_out::QuickReturn;
    use mechgen_runtime::{Simulation, Solver, SolverOptions};

    let hand = QuickReturn::default();
    let mut out = ([0.0; 15], [0.0; 15], [0.0; 15]);
    for closed_forms in [true, false] {
        let options = SolverOptions {
            closed_forms,
            ..SolverOptions::default()
        };
        let solver = Solver::with_options(Scene::default(), options);
        let mut simulation = Simulation::new(solver, 0.0).unwrap_or_else(|e| panic!("{e}"));
        let mut started = 0;
        for i in 1..=720 {
            let t = hand.period() * f64::from(i) / 360.0;
            let state = simulation.step_to(t).unwrap_or_else(|e| panic!("{e}"));
            hand.written_out(t, &mut out);
            let levels = [
                (state.q.as_slice(), &out.0, 220.0),
                (state.qd().as_slice(), &out.1, 220.0 * hand.omega),
                (
                    state.qdd().as_slice(),
                    &out.2,
                    220.0 * hand.omega * hand.omega,
                ),
            ];
            for (level, (solved, written, scale)) in levels.into_iter().enumerate() {
                for (k, (a, b)) in solved.iter().zip(written.iter()).enumerate() {
                    let error = (a - b).abs() / scale;
                    assert!(
                        error < 1e-12,
                        "closed forms {closed_forms}, t {t}, level {level}, q[{k}]: {a} vs {b}"
                    );
                }
            }
            started += state.closed_forms;
        }
        let expected = if closed_forms { 2 * 720 } else { 0 };
        assert_eq!(started, expected, "closed forms {closed_forms}");
    }
}
