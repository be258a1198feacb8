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
