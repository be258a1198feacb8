//! [`Lu`]'s API: partial-pivoting factor and solves against hand-checked systems, scaling, the
//! condition estimate against exact inverses, and the rank reveal of known dependencies.

use mechgen_runtime::{Lu, LuError};

use nalgebra::{Matrix2, Matrix3, U2, U3, Vector2, Vector3};

fn factored(m: Matrix3<f64>) -> Lu<U3> {
    let mut lu = Lu::new(U3);
    lu.factor(&m).expect("test matrix is regular");
    lu
}

#[test]
fn solves_a_hand_checked_system() {
    // 2x + y = 5, x + 3y + z = 10.5, y + 4z = 14  →  x = 1.5, y = 2, z = 3
    let m = Matrix3::new(2.0, 1.0, 0.0, 1.0, 3.0, 1.0, 0.0, 1.0, 4.0);
    let mut b = Vector3::new(5.0, 10.5, 14.0);
    factored(m).solve_in_place(&mut b).unwrap();
    assert!((b - Vector3::new(1.5, 2.0, 3.0)).amax() < 1e-15);
}

#[test]
fn pivots_past_a_zero_diagonal() {
    // A permuted identity-like system: without row exchanges the first pivot would be 0.
    let m = Matrix3::new(0.0, 1.0, 0.0, 0.0, 0.0, 2.0, 4.0, 0.0, 0.0);
    let mut b = Vector3::new(7.0, 6.0, 8.0);
    let lu = factored(m);
    lu.solve_in_place(&mut b).unwrap();
    assert_eq!(b, Vector3::new(2.0, 7.0, 3.0));
    assert_eq!(lu.rough_condition(), Some(4.0));
}

#[test]
fn reports_the_dependent_row_and_column() {
    // Row 2 = row 0 + row 1: elimination runs out of pivots in column 2.
    let m = Matrix3::new(1.0, 2.0, 3.0, 0.0, 1.0, 1.0, 1.0, 3.0, 4.0);
    let mut lu = Lu::new(U3);
    match lu.factor(&m) {
        Err(LuError::Singular { row, column, pivot }) => {
            assert_eq!((row, column), (2, 2));
            assert!(pivot < 1e-15);
        }
        other => panic!("expected a singular matrix, got {other:?}"),
    }
    assert!(!lu.is_factored());
    assert_eq!(
        lu.solve_in_place(&mut Vector3::zeros()),
        Err(LuError::NotFactored)
    );
}

#[test]
fn tolerance_is_relative_to_the_largest_entry() {
    let tiny = Matrix3::from_diagonal_element(1e-200);
    assert!(Lu::new(U3).factor(&tiny).is_ok());
    let graded = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 1e-14));
    assert!(matches!(
        Lu::new(U3).factor(&graded),
        Err(LuError::Singular { column: 2, .. })
    ));
    assert!(matches!(
        Lu::new(U3).factor(&Matrix3::zeros()),
        Err(LuError::Singular { column: 0, .. })
    ));
}

#[test]
fn names_the_remaining_row_that_depends_on_the_pivot_rows() {
    // Row 2 = row 0 / 2; row 1 is independent. After the first step both remain, and the
    // dependent one (all zero) is not the one in pivot position 1.
    let m = Matrix3::new(2.0, 1.0, 0.0, 1.0, 0.5, 1.0, 1.0, 0.5, 0.0);
    match Lu::new(U3).factor(&m) {
        Err(LuError::Singular { row, column, .. }) => assert_eq!((row, column), (2, 1)),
        other => panic!("expected a singular matrix, got {other:?}"),
    }
}

#[test]
fn rank_reveal_refuses_an_elimination_that_overflows() {
    // Finite entries whose first elimination step overflows to infinity (2 · MAX).
    let big = f64::MAX;
    let m = Matrix2::new(big, big, -big, big);
    let ones = Vector2::new(1.0, 1.0);
    let result = Lu::new(U2).reveal_rank(&ones, &ones, 1e-12, |a| a.copy_from(&m));
    assert_eq!(result, Err(LuError::NonFinite));
}

#[test]
fn rejects_non_finite_entries() {
    let m = Matrix3::from_diagonal_element(f64::NAN);
    assert_eq!(Lu::new(U3).factor(&m), Err(LuError::NonFinite));
}

#[test]
fn refactoring_reuses_the_storage() {
    let mut lu = Lu::new(U3);
    lu.factor(&Matrix3::from_diagonal_element(2.0)).unwrap();
    lu.factor_with(|m| m.fill_with_identity()).unwrap();
    let mut b = Vector3::new(1.0, 2.0, 3.0);
    lu.solve_in_place(&mut b).unwrap();
    assert_eq!(b, Vector3::new(1.0, 2.0, 3.0));
}

use nalgebra::{Matrix4, SMatrix, SVector, U4, U5, U6, Vector4};

/// max_j Σ_i |m_ij|.
fn one_norm_of<const N: usize>(m: &SMatrix<f64, N, N>) -> f64 {
    m.column_iter()
        .map(|c| c.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// A nonsymmetric, diagonally weighted 5 × 5 test matrix with small integer entries.
fn mixed5() -> SMatrix<f64, 5, 5> {
    SMatrix::from_fn(|i, j| {
        ((7 * i + 13 * j + 3) % 11) as f64 - 5.0 + if i == j { 9.0 } else { 0.0 }
    })
}

/// Checks the estimate against `exact` = κ₁: a lower bound up to rounding (`slack`), and
/// within a factor 10 of it.
fn assert_estimate_brackets(estimate: f64, exact: f64, slack: f64) {
    assert!(
        estimate <= exact * (1.0 + slack) && estimate >= exact / 10.0,
        "estimate {estimate:e} vs exact {exact:e}"
    );
}

/// Rounding slack for κ₁ computed through solves: 1e-12 plus the forward-error size 64·κ·ε.
fn slack_for(exact: f64) -> f64 {
    1e-12 + 64.0 * exact * f64::EPSILON
}

fn check_estimate_against_inverse<const N: usize>(m: SMatrix<f64, N, N>)
where
    nalgebra::Const<N>: nalgebra::DimMin<nalgebra::Const<N>, Output = nalgebra::Const<N>>,
{
    let inverse = m.try_inverse().expect("test matrix is regular");
    let exact = one_norm_of(&m) * one_norm_of(&inverse);
    let mut lu = Lu::new(nalgebra::Const::<N>);
    lu.factor(&m).unwrap();
    let estimate = lu.condition_estimate().unwrap();
    assert_estimate_brackets(estimate, exact, slack_for(exact));
}

#[test]
fn condition_estimate_brackets_the_exact_condition_number() {
    check_estimate_against_inverse(Matrix3::new(4.0, 1.0, -2.0, 1.0, 3.0, 0.5, -2.0, 0.5, 5.0));
    check_estimate_against_inverse(Matrix3::new(0.0, 2.0, 1.0, 3.0, -1.0, 0.0, 1.0, 1.0, 1.0));
    check_estimate_against_inverse(mixed5());
    check_estimate_against_inverse(mixed5().transpose());
    // Upper triangular with growing off-diagonal entries: κ grows like 2ⁿ.
    check_estimate_against_inverse(SMatrix::<f64, 5, 5>::from_fn(|i, j| match i.cmp(&j) {
        core::cmp::Ordering::Less => -1.0,
        core::cmp::Ordering::Equal => 1.0,
        core::cmp::Ordering::Greater => 0.0,
    }));
}

#[test]
fn condition_estimate_of_a_tiny_pivot_matrix() {
    // The 2 × 2 block has determinant 2⁻³⁰, so the LU and the inverse are exact:
    // A⁻¹ = [[2³⁰ + 1, −2³⁰], [−2³⁰, 2³⁰]] ⊕ [1].
    let delta = 2.0_f64.powi(-30);
    let m = Matrix3::new(1.0, 1.0, 0.0, 1.0, 1.0 + delta, 0.0, 0.0, 0.0, 1.0);
    let exact = (2.0 + delta) * (2.0_f64.powi(31) + 1.0);
    let mut lu = factored(m);
    let estimate = lu.condition_estimate().unwrap();
    assert_estimate_brackets(estimate, exact, 1e-12);
    assert!(estimate > 4e9);
}

/// Binomial coefficient, exact for the small arguments used here.
fn binomial(n: u64, k: u64) -> u64 {
    (0..k).fold(1, |c, i| c * (n - i) / (i + 1))
}

#[test]
fn condition_estimate_of_the_hilbert_matrix() {
    // 27720 = lcm(1..=11), so K = 27720·H₆ has integer entries and is stored exactly; its
    // inverse is H₆⁻¹ / 27720 with the classical integer formula for H₆⁻¹.
    const N: u64 = 6;
    let k = SMatrix::<f64, 6, 6>::from_fn(|i, j| 27720.0 / (i + j + 1) as f64);
    let hilbert_inverse = SMatrix::<f64, 6, 6>::from_fn(|i, j| {
        let (i, j) = (i as u64 + 1, j as u64 + 1);
        let magnitude = (i + j - 1)
            * binomial(N + i - 1, N - j)
            * binomial(N + j - 1, N - i)
            * binomial(i + j - 2, i - 1).pow(2);
        let sign = if (i + j) % 2 == 0 { 1.0 } else { -1.0 };
        sign * magnitude as f64
    });
    let h = k / 27720.0;
    assert!((h * hilbert_inverse - SMatrix::<f64, 6, 6>::identity()).amax() < 1e-6);
    let exact = one_norm_of(&k) * one_norm_of(&hilbert_inverse) / 27720.0;
    let mut lu = Lu::new(U6);
    lu.factor(&k).unwrap();
    let estimate = lu.condition_estimate().unwrap();
    assert_estimate_brackets(estimate, exact, slack_for(exact));
    assert!(estimate > 2e7);
}

#[test]
fn condition_estimate_is_cached_per_factorisation() {
    let mut lu = Lu::new(U3);
    assert_eq!(lu.condition_estimate(), None);
    lu.factor(&Matrix3::from_diagonal(&Vector3::new(1.0, 2.0, 8.0)))
        .unwrap();
    assert_eq!(lu.condition_estimate(), Some(8.0));
    assert_eq!(lu.condition_estimate(), Some(8.0));
    lu.factor_with(|m| m.fill_with_identity()).unwrap();
    assert_eq!(lu.condition_estimate(), Some(1.0));
    assert!(lu.factor(&Matrix3::zeros()).is_err());
    assert_eq!(lu.condition_estimate(), None);
}

#[test]
fn condition_estimate_handles_one_by_one_and_overflow() {
    let mut lu = Lu::new(nalgebra::U1);
    lu.factor(&nalgebra::Matrix1::new(-4.0)).unwrap();
    assert_eq!(lu.condition_estimate(), Some(1.0));
    // ‖A‖₁ · ‖A⁻¹‖₁ = 1e300 · 1e10 overflows (accepted only with a zero tolerance).
    let mut lu = Lu::new(U3);
    lu.set_pivot_tolerance(0.0);
    lu.factor(&Matrix3::from_diagonal(&Vector3::new(1e300, 1.0, 1e-10)))
        .unwrap();
    assert_eq!(lu.condition_estimate(), Some(f64::INFINITY));
}

/// A well-conditioned 3 × 3 matrix made badly scaled by its rows.
fn badly_scaled() -> (Matrix3<f64>, Matrix3<f64>, Vector3<f64>) {
    let well = Matrix3::new(4.0, 1.0, -2.0, 1.0, 3.0, 0.5, -2.0, 0.5, 5.0);
    let weights = Vector3::new(1e-6, 1.0, 1e4);
    (well, Matrix3::from_diagonal(&weights) * well, weights)
}

#[test]
fn scaling_undoes_bad_row_scaling_in_the_condition_estimate() {
    let (well, a, weights) = badly_scaled();
    let mut lu = Lu::new(U3);
    lu.factor(&a).unwrap();
    assert!(lu.condition_estimate().unwrap() > 1e9);

    let rows = weights.map(|w| 1.0 / w);
    lu.factor_scaled_with(&rows, &Vector3::repeat(1.0), |m| m.copy_from(&a))
        .unwrap();
    let exact = one_norm_of(&well) * one_norm_of(&well.try_inverse().unwrap());
    let estimate = lu.condition_estimate().unwrap();
    assert!(estimate < 10.0, "{estimate}");
    assert_estimate_brackets(estimate, exact, 1e-9);
    assert!(lu.rough_condition().unwrap() < 10.0);
}

#[test]
fn scaled_solves_return_the_solution_of_the_original_system() {
    let (_, a, weights) = badly_scaled();
    let (rows, cols) = (weights.map(|w| 1.0 / w), Vector3::new(0.5, 4.0, 1e3));
    let mut lu = Lu::new(U3);
    lu.factor_scaled_with(&rows, &cols, |m| m.copy_from(&a))
        .unwrap();
    let expected = Vector3::new(1.5, -2.0, 0.25);

    let mut x = a * expected;
    lu.solve_in_place(&mut x).unwrap();
    assert!((x - expected).amax() < 1e-13, "{x}");

    // Aᵀ = Bᵀ diag(1e-6, 1, 1e4) is badly scaled by its columns, which the row scaling does
    // not undo: x₀ is only good to about 1e-16 · 1e10 in the forward error, so check the
    // backward error (residual against |Aᵀ| |y|) instead.
    let c = a.transpose() * expected;
    let mut y = c;
    lu.solve_transpose_in_place(&mut y).unwrap();
    let scale = (a.transpose().abs() * y.abs()).amax();
    assert!((a.transpose() * y - c).amax() < 1e-15 * scale, "{y}");
    assert!((y - expected).amax() < 1e-6, "{y}");
}

#[test]
fn transpose_solve_matches_factoring_the_transpose() {
    let m = mixed5();
    let b = SVector::<f64, 5>::new(1.0, -2.0, 0.5, 3.0, -0.25);
    let mut lu = Lu::new(U5);
    lu.factor(&m).unwrap();
    let mut x = b;
    lu.solve_transpose_in_place(&mut x).unwrap();
    let mut transposed = Lu::new(U5);
    transposed.factor(&m.transpose()).unwrap();
    let mut expected = b;
    transposed.solve_in_place(&mut expected).unwrap();
    assert!((x - expected).amax() < 1e-14);
    assert!((m.transpose() * x - b).amax() < 1e-13);
    // A pivoting case: the permuted identity of `pivots_past_a_zero_diagonal`.
    let p = Matrix3::new(0.0, 1.0, 0.0, 0.0, 0.0, 2.0, 4.0, 0.0, 0.0);
    let mut c = Vector3::new(8.0, 7.0, 6.0);
    factored(p).solve_transpose_in_place(&mut c).unwrap();
    assert_eq!(p.transpose() * c, Vector3::new(8.0, 7.0, 6.0));
    assert_eq!(
        Lu::new(U3).solve_transpose_in_place(&mut c),
        Err(LuError::NotFactored)
    );
}

#[test]
fn pivot_tolerance_applies_to_the_scaled_matrix() {
    let graded = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 1e-14));
    let mut lu = Lu::new(U3);
    assert!(lu.factor(&graded).is_err());
    let rows = Vector3::new(1.0, 1.0, 1e14);
    lu.factor_scaled_with(&rows, &Vector3::repeat(1.0), |m| m.copy_from(&graded))
        .unwrap();
    let mut b = Vector3::new(1.0, 2.0, 3e-14);
    lu.solve_in_place(&mut b).unwrap();
    assert!((b - Vector3::new(1.0, 2.0, 3.0)).amax() < 1e-14);
    // An unscaled refactor drops the scaling again.
    lu.factor_with(|m| m.fill_with_identity()).unwrap();
    let mut b = Vector3::new(1.0, 2.0, 3.0);
    lu.solve_in_place(&mut b).unwrap();
    assert_eq!(b, Vector3::new(1.0, 2.0, 3.0));
}

#[test]
fn rejects_bad_scales_before_filling() {
    let ones = Vector3::repeat(1.0);
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, -0.0] {
        let scales = Vector3::new(1.0, bad, 1.0);
        let mut lu = Lu::new(U3);
        let mut filled = false;
        let result = lu.factor_scaled_with(&scales, &ones, |m| {
            filled = true;
            m.fill_with_identity();
        });
        assert_eq!(result, Err(LuError::NonFinite));
        assert!(!filled);
        assert_eq!(
            lu.factor_scaled_with(&ones, &scales, |m| m.fill_with_identity()),
            Err(LuError::NonFinite)
        );
        assert_eq!(
            lu.reveal_rank(&ones, &scales, 1e-12, |m| m.fill_with_identity()),
            Err(LuError::NonFinite)
        );
        assert!(!lu.is_factored());
    }
}

#[test]
fn scaled_factor_rejects_non_finite_entries_and_overflow() {
    let ones = Vector3::repeat(1.0);
    let mut lu = Lu::new(U3);
    assert_eq!(
        lu.factor_scaled_with(&ones, &ones, |m| {
            m.fill_with_identity();
            m[(1, 2)] = f64::NAN;
        }),
        Err(LuError::NonFinite)
    );
    let big = Vector3::repeat(1e10);
    assert_eq!(
        lu.factor_scaled_with(&big, &ones, |m| *m = Matrix3::from_diagonal_element(1e300)),
        Err(LuError::NonFinite)
    );
    assert!(!lu.is_factored());
}

/// Rows 0, 1, 2 generic; row 3 = row 0 + row 2.
fn one_dependent_row() -> Matrix4<f64> {
    Matrix4::new(
        2.0, -1.0, 0.5, 3.0, //
        1.0, 4.0, -2.0, 0.0, //
        0.0, 1.5, 3.0, -1.0, //
        2.0, 0.5, 3.5, 2.0,
    )
}

#[test]
fn reveals_a_row_that_is_a_sum_of_two_others() {
    let m = one_dependent_row();
    let ones = Vector4::repeat(1.0);
    let mut lu = Lu::new(U4);
    assert_eq!(lu.dependent_rows(), &[] as &[usize]);
    assert_eq!(
        lu.reveal_rank(&ones, &ones, 1e-12, |s| s.copy_from(&m)),
        Ok(3)
    );
    let dependent = lu.dependent_rows();
    assert_eq!(dependent.len(), 1);
    assert!([0, 2, 3].contains(&dependent[0]), "{dependent:?}");
    assert_eq!(lu.undetermined_columns().len(), 1);
    // The storage now holds complete-pivoting factors: no solves with it.
    assert!(!lu.is_factored());
    assert_eq!(lu.condition_estimate(), None);
    assert_eq!(
        lu.solve_in_place(&mut Vector4::zeros()),
        Err(LuError::NotFactored)
    );
    // A regular matrix has full rank and nothing to report.
    assert_eq!(
        lu.reveal_rank(&ones, &ones, 1e-12, |s| s.fill_with_identity()),
        Ok(4)
    );
    assert!(lu.dependent_rows().is_empty() && lu.undetermined_columns().is_empty());
}

#[test]
fn reveals_duplicate_rows_and_a_zero_column() {
    // Rows 1 and 4 are equal and column 2 is zero: one deficiency seen from both sides.
    let mut m = mixed5();
    m.set_row(4, &m.row(1).clone_owned());
    m.set_column(2, &SVector::zeros());
    let ones = SVector::<f64, 5>::repeat(1.0);
    let mut lu = Lu::new(U5);
    assert_eq!(
        lu.reveal_rank(&ones, &ones, 1e-12, |s| s.copy_from(&m)),
        Ok(4)
    );
    let rows = lu.dependent_rows();
    assert!(rows == [1] || rows == [4], "{rows:?}");
    assert_eq!(lu.undetermined_columns(), &[2]);

    // Also row 3 = row 0 + 2 · row 2: rank 5 − 2.
    m.set_row(3, &(m.row(0) + m.row(2) * 2.0));
    assert_eq!(
        lu.reveal_rank(&ones, &ones, 1e-12, |s| s.copy_from(&m)),
        Ok(3)
    );
    let (rows, cols) = (lu.dependent_rows(), lu.undetermined_columns());
    assert_eq!((rows.len(), cols.len()), (2, 2));
    assert!(rows.contains(&1) ^ rows.contains(&4), "{rows:?}");
    assert!(rows.iter().any(|r| [0, 2, 3].contains(r)), "{rows:?}");
    assert!(cols.contains(&2), "{cols:?}");
    assert!(rows[0] < rows[1] && cols[0] < cols[1]);
}

#[test]
fn reveals_rank_zero_and_rejects_non_finite_entries() {
    let ones = Vector3::repeat(1.0);
    let mut lu = Lu::new(U3);
    assert_eq!(lu.reveal_rank(&ones, &ones, 1e-12, |s| s.fill(0.0)), Ok(0));
    assert_eq!(lu.dependent_rows(), &[0, 1, 2]);
    assert_eq!(lu.undetermined_columns(), &[0, 1, 2]);
    assert_eq!(
        lu.reveal_rank(&ones, &ones, 1e-12, |s| s.fill(f64::NAN)),
        Err(LuError::NonFinite)
    );
    assert!(lu.dependent_rows().is_empty() && lu.undetermined_columns().is_empty());
    // A NaN tolerance only counts exact zeros as negligible.
    let graded = Matrix3::from_diagonal(&Vector3::new(1.0, 1e-200, 0.0));
    assert_eq!(
        lu.reveal_rank(&ones, &ones, f64::NAN, |s| s.copy_from(&graded)),
        Ok(2)
    );
    assert_eq!(lu.dependent_rows(), &[2]);
}

#[test]
fn scaling_decides_the_revealed_rank() {
    let regular = Matrix4::new(
        4.0, 1.0, 0.0, -1.0, //
        1.0, 5.0, 2.0, 0.0, //
        0.0, -1.0, 3.0, 1.0, //
        2.0, 0.0, 1.0, 6.0,
    );
    let weights = Vector4::new(1e8, 1e8, 1e8, 1e-2);
    let badly_scaled = Matrix4::from_diagonal(&weights) * regular;
    let (ones, inverse) = (Vector4::repeat(1.0), weights.map(|w| 1.0 / w));
    let mut lu = Lu::new(U4);
    // Unscaled, the small last equation drowns below the tolerance …
    assert_eq!(
        lu.reveal_rank(&ones, &ones, 1e-9, |s| s.copy_from(&badly_scaled)),
        Ok(3)
    );
    assert_eq!(lu.dependent_rows(), &[3]);
    // … scaled back, the matrix is regular …
    assert_eq!(
        lu.reveal_rank(&inverse, &ones, 1e-9, |s| s.copy_from(&badly_scaled)),
        Ok(4)
    );
    // … and a genuine dependency (row 3 ∝ row 0 + row 1) is still found.
    let mut dependent = regular;
    dependent.set_row(3, &(regular.row(0) + regular.row(1)));
    let badly_scaled = Matrix4::from_diagonal(&weights) * dependent;
    assert_eq!(
        lu.reveal_rank(&inverse, &ones, 1e-12, |s| s.copy_from(&badly_scaled)),
        Ok(3)
    );
    assert!([0, 1, 3].contains(&lu.dependent_rows()[0]));
}

#[cfg(feature = "alloc")]
#[test]
fn dynamic_sizes_are_checked() {
    use nalgebra::{DMatrix, DVector, Dyn};
    let mut lu = Lu::new(Dyn(3));
    let (three, two) = (DVector::repeat(3, 1.0), DVector::repeat(2, 1.0));
    let expected = Err(LuError::DimensionMismatch {
        expected: 3,
        found: 2,
    });
    assert_eq!(
        lu.factor_scaled_with(&two, &three, |m| m.fill_with_identity()),
        expected
    );
    assert_eq!(
        lu.factor_scaled_with(&three, &two, |m| m.fill_with_identity()),
        expected
    );
    assert_eq!(
        lu.reveal_rank(&three, &two, 0.0, |m| m.fill_with_identity())
            .map(|_| ()),
        expected
    );
    assert_eq!(
        lu.factor_scaled_with(&three, &three, |m| *m = DMatrix::identity(2, 2)),
        expected
    );
    lu.factor_scaled_with(&three, &three, |m| *m = DMatrix::identity(3, 3))
        .unwrap();
    assert_eq!(lu.solve_transpose_in_place(&mut two.clone()), expected);
    // 0 × 0 works throughout.
    let mut empty = Lu::new(Dyn(0));
    let none = DVector::<f64>::zeros(0);
    empty.factor_scaled_with(&none, &none, |_| ()).unwrap();
    assert_eq!(empty.condition_estimate(), Some(1.0));
    let mut b = none.clone();
    empty.solve_in_place(&mut b).unwrap();
    empty.solve_transpose_in_place(&mut b).unwrap();
    assert_eq!(empty.reveal_rank(&none, &none, 0.0, |_| ()), Ok(0));
}
