//! `Dense`: any mechanism as one block of every equation, its kernels the mechanism's textbook
//! functions, checked against the pendulum's hand-computed Φ, Φ_q, ν and γ.

mod common;

use common::pendulum::Pendulum;
use mechgen_runtime::codegen::{Block, Pattern, Stage};
use mechgen_runtime::nalgebra::Vector3;
use mechgen_runtime::{Dense, Structured};

fn close(computed: &[f64], expected: &[f64]) {
    assert_eq!(computed.len(), expected.len());
    for (c, e) in computed.iter().zip(expected) {
        assert!(
            (c - e).abs() <= 1e-15 * e.abs().max(1.0),
            "{computed:?} vs {expected:?}"
        );
    }
}

#[test]
fn one_block_holds_every_equation_without_static_pivots() {
    let dense = Dense::new(Pendulum::default());
    assert_eq!(dense.stage_count(), 1);
    let expected = Block {
        equations: &[0, 1, 2],
        coordinates: &[0, 1, 2],
        pattern: Pattern::Dense,
        slots: 9,
        pivots: &[],
        reads: &[],
    };
    assert_eq!(dense.stage(0), Some(Stage::Block(expected)));
    assert_eq!(dense.stage(1), None);
}

#[test]
fn the_block_kernels_are_the_textbook_functions() {
    let pendulum = Pendulum {
        a: 3.0,
        omega: 1.25,
        ..Pendulum::default()
    };
    let dense = Dense::new(pendulum);
    let (q, qd, t) = (
        Vector3::new(1.0, 0.5, 0.3),
        Vector3::new(-0.2, 0.4, 0.7),
        0.2,
    );
    let (a, w, (s, c)) = (3.0, 1.25, (0.3_f64.sin(), 0.3_f64.cos()));
    let (mut phi, mut values) = ([0.0; 3], [0.0; 9]);
    dense.block_jacobian(0, &q, &[], t, &mut phi, &mut values);
    // Φ = (x − a cos θ, y − a sin θ, θ − ω t), and Φ_q column by column.
    close(&phi, &[1.0 - a * c, 0.5 - a * s, 0.3 - w * t]);
    close(&values, &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, a * s, -a * c, 1.0]);
    let mut rhs = [f64::NAN; 3];
    dense.velocity_rhs(0, &q, &[], &qd, t, &mut rhs);
    close(&rhs, &[0.0, 0.0, w]);
    dense.acceleration_rhs(0, &q, &[], &qd, &qd, t, &mut rhs);
    let w2 = 0.7 * 0.7;
    close(&rhs, &[-a * c * w2, -a * s * w2, 0.0]);
}
