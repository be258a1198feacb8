//! Property tests over random states: the generated Jacobian against central differences of
//! the generated Φ, and generated code against the interpreter on the same IR (Φ, Φ_q, ν, γ).

use mechgen_cli::Interpreted;
use mechgen_examples::scenes::{FourBar, PistonCrank};
use mechgen_runtime::nalgebra::{DMatrix, DVector, Dyn};
use mechgen_runtime::{Accelerations, Matrix, Mechanism, Vector};
use proptest::prelude::*;

fn interpreted(file: &str) -> Interpreted {
    let path = format!("{}/../examples/scenes/{file}", env!("CARGO_MANIFEST_DIR"));
    let source = std::fs::read_to_string(&path).expect("scene file");
    let scene = mechgen::compile_str(&source).unwrap_or_else(|e| panic!("{path}: {e}"));
    Interpreted::new(&scene)
}

/// Random states: positions within a few hundred mm, any angle, fast velocities, any time.
fn states(n: usize) -> impl Strategy<Value = (Vec<f64>, Vec<f64>, f64)> {
    let coordinate = prop_oneof![-300.0..300.0f64, -7.0..7.0f64];
    (
        proptest::collection::vec(coordinate, n),
        proptest::collection::vec(-1e3..1e3f64, n),
        0.0..0.1f64,
    )
}

/// max |J − J_fd| over the matrix, relative to max(1, |J|max): central differences have
/// truncation error O(h²) and round-off O(ε/h), so ~1e-6 relative is the right tolerance.
fn jacobian_matches_differences<M>(mechanism: &M, q: &[f64], t: f64) -> Result<(), TestCaseError>
where
    M: Mechanism,
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    let dim = mechanism.dim();
    let n = q.len();
    let mut qv = Vector::<M::Dim>::zeros_generic(dim, mechgen_runtime::nalgebra::Const::<1>);
    qv.as_mut_slice().copy_from_slice(q);
    let mut analytic = Matrix::<M::Dim>::zeros_generic(dim, dim);
    mechanism.jacobian(&qv, t, &mut analytic);
    let mut plus = Vector::<M::Dim>::zeros_generic(dim, mechgen_runtime::nalgebra::Const::<1>);
    let mut minus = plus.clone();
    let mut worst: f64 = 0.0;
    for k in 0..n {
        let h = 1e-6 * q[k].abs().max(1.0);
        let mut shifted = qv.clone();
        shifted[k] += h;
        mechanism.phi(&shifted, t, &mut plus);
        shifted[k] -= 2.0 * h;
        mechanism.phi(&shifted, t, &mut minus);
        for i in 0..n {
            let fd = (plus[i] - minus[i]) / (2.0 * h);
            worst = worst.max((fd - analytic[(i, k)]).abs());
        }
    }
    let scale = analytic.amax().max(1.0);
    prop_assert!(worst <= 1e-6 * scale, "worst {worst} at scale {scale}");
    Ok(())
}

/// Generated and interpreted Φ, Φ_q, ν, γ agree to round-off (relative 1e-12 of each output's
/// largest entry; the two evaluate the same DAG, differing only in libm vs std functions).
fn agree<M>(
    generated: &M,
    interpreted: &Interpreted,
    q: &[f64],
    qd: &[f64],
    t: f64,
) -> Result<(), TestCaseError>
where
    M: Accelerations,
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    let dim = generated.dim();
    let n = q.len();
    let col = mechgen_runtime::nalgebra::Const::<1>;
    let mut gq = Vector::<M::Dim>::zeros_generic(dim, col);
    gq.as_mut_slice().copy_from_slice(q);
    let mut gqd = gq.clone();
    gqd.as_mut_slice().copy_from_slice(qd);
    let (iq, iqd) = (
        DVector::from_column_slice(q),
        DVector::from_column_slice(qd),
    );

    let mut gv = Vector::<M::Dim>::zeros_generic(dim, col);
    let mut iv = DVector::zeros(n);
    let mut gm = Matrix::<M::Dim>::zeros_generic(dim, dim);
    let mut im = DMatrix::zeros(n, n);
    let close = |a: &[f64], b: &[f64], what: &str| -> Result<(), TestCaseError> {
        let scale = a.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        let diff = a
            .iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        prop_assert!(
            diff <= 1e-12 * scale,
            "{what}: differ by {diff} at scale {scale}"
        );
        Ok(())
    };

    generated.phi(&gq, t, &mut gv);
    interpreted.phi(&iq, t, &mut iv);
    close(gv.as_slice(), iv.as_slice(), "phi")?;
    generated.jacobian(&gq, t, &mut gm);
    interpreted.jacobian(&iq, t, &mut im);
    close(gm.as_slice(), im.as_slice(), "jacobian")?;
    let mut gm2 = gm.clone();
    let mut gv2 = gv.clone();
    generated.phi_and_jacobian(&gq, t, &mut gv2, &mut gm2);
    prop_assert_eq!(&gv2, &gv, "phi_and_jacobian's phi");
    prop_assert_eq!(&gm2, &gm, "phi_and_jacobian's jacobian");
    let mut im2 = im.clone();
    let mut iv2 = iv.clone();
    interpreted.phi_and_jacobian(&iq, t, &mut iv2, &mut im2);
    close(
        gv2.as_slice(),
        iv2.as_slice(),
        "interpreted phi_and_jacobian",
    )?;
    close(
        gm2.as_slice(),
        im2.as_slice(),
        "interpreted phi_and_jacobian",
    )?;
    generated.nu(&gq, t, &mut gv);
    interpreted.nu(&iq, t, &mut iv);
    close(gv.as_slice(), iv.as_slice(), "nu")?;
    generated.gamma(&gq, &gqd, t, &mut gv);
    interpreted.gamma(&iq, &iqd, t, &mut iv);
    close(gv.as_slice(), iv.as_slice(), "gamma")?;
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn seed_jacobian_matches_central_differences((q, _, t) in states(15)) {
        jacobian_matches_differences(&PistonCrank::default(), &q, t)?;
    }

    #[test]
    fn four_bar_jacobian_matches_central_differences((q, _, t) in states(12)) {
        jacobian_matches_differences(&FourBar::default(), &q, t)?;
    }

    #[test]
    fn interpreted_jacobian_matches_central_differences((q, _, t) in states(15)) {
        let scene = interpreted("piston_crank.mech");
        prop_assert_eq!(scene.dim(), Dyn(15));
        jacobian_matches_differences(&scene, &q, t)?;
    }

    #[test]
    fn seed_generated_and_interpreted_agree((q, qd, t) in states(15)) {
        agree(&PistonCrank::default(), &interpreted("piston_crank.mech"), &q, &qd, t)?;
    }

    #[test]
    fn four_bar_generated_and_interpreted_agree((q, qd, t) in states(12)) {
        agree(&FourBar::default(), &interpreted("four_bar.mech"), &q, &qd, t)?;
    }
}
