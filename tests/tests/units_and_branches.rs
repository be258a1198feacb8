//! The scene metadata the solver scales and guards by — coordinate and equation units, the
//! length scale and the branch invariants — is the same in generated code (`mechanism!`) and in
//! the interpreter (`.mech` files through `Interpreted`), and the example scenes' declared
//! branches hold along their whole motion.

use mechgen_examples::scenes::{FourBar, OffsetSlider, PistonCrank};
use mechgen_interp::Interpreted;
use mechgen_runtime::nalgebra::{Const, DVector};
use mechgen_runtime::{Mechanism, Simulation, Solver, Structured, Unit, Vector};
use mechgen_tests::example_scene as interpreted;

/// Units, length scale and branch names agree, past the ends too.
fn assert_same_metadata<M: Mechanism<Dim = Const<N>>, const N: usize>(
    generated: &M,
    interpreted: &Interpreted,
) {
    for i in 0..N + 2 {
        assert_eq!(
            generated.coordinate_unit(i),
            interpreted.coordinate_unit(i),
            "{i}"
        );
        assert_eq!(
            generated.equation_unit(i),
            interpreted.equation_unit(i),
            "{i}"
        );
    }
    assert_eq!(generated.coordinate_unit(N), Unit::Angle);
    assert_eq!(generated.length_scale(), interpreted.length_scale());
    assert_eq!(generated.branch_count(), interpreted.branch_count());
    for i in 0..generated.branch_count() + 2 {
        assert_eq!(generated.branch_name(i), interpreted.branch_name(i), "{i}");
    }
}

/// The branch values along one period, from generated code, checked against the interpreter
/// and returned.
fn branch_values_along_motion<M: Structured<Dim = Const<N>> + Clone, const N: usize>(
    generated: M,
    interpreted: &Interpreted,
    period: f64,
) -> Vec<f64> {
    let mut values = Vec::new();
    let scene = generated.clone();
    let mut simulation = Simulation::new(Solver::new(generated), 0.0).expect("assembles");
    simulation
        .run(period, 120, |state| {
            let q: &Vector<Const<N>> = &state.q;
            let dynamic = DVector::from_column_slice(q.as_slice());
            for b in 0..scene.branch_count() {
                let (value, reference) = (
                    scene.branch_value(b, q),
                    interpreted.branch_value(b, &dynamic),
                );
                assert!(
                    (value - reference).abs() <= 1e-12 * reference.abs(),
                    "{value} vs {reference}"
                );
                values.push(value);
            }
        })
        .expect("solves");
    assert!(
        scene
            .branch_value(scene.branch_count(), &Vector::<Const<N>>::zeros())
            .is_nan()
    );
    values
}

#[test]
fn seed_metadata_and_branch() {
    let (generated, interpreted) = (PistonCrank::default(), interpreted("piston_crank.mech"));
    assert_same_metadata(&generated, &interpreted);
    assert_eq!(generated.length_scale(), 156.8);
    assert_eq!(generated.equation_unit(14), Unit::Angle);
    assert_eq!(generated.branch_name(0), Some("piston_outboard"));
    let period = 2.0 * std::f64::consts::PI / 314.0;
    let values = branch_values_along_motion(generated, &interpreted, period);
    assert!(values.iter().all(|&v| v > 0.0), "{values:?}");
}

#[test]
fn four_bar_metadata_and_branch() {
    let (generated, interpreted) = (FourBar::default(), interpreted("four_bar.mech"));
    assert_same_metadata(&generated, &interpreted);
    assert_eq!(generated.length_scale(), 120.0);
    let period = 2.0 * std::f64::consts::PI / 10.0;
    let values = branch_values_along_motion(generated, &interpreted, period);
    assert!(values.iter().all(|&v| v > 0.0), "{values:?}");
}

#[test]
fn parameter_dependent_length_scale() {
    let (mut generated, mut interpreted) =
        (OffsetSlider::default(), interpreted("offset_slider.mech"));
    assert_same_metadata(&generated, &interpreted);
    assert_eq!(generated.length_scale(), 80.0);
    assert_eq!(generated.branch_count(), 0);
    generated.set_parameter("offset", -250.0).expect("declared");
    interpreted
        .set_parameter("offset", -250.0)
        .expect("declared");
    assert_eq!(generated.length_scale(), 250.0);
    assert_eq!(interpreted.length_scale(), 250.0);
}
