//! The equations of motion (`EquationsOfMotion`), generated (`build.rs`, with
//! `CodegenOptions::equations_of_motion`) and interpreted, on `tests/data/swing_motion.mech`:
//! an offset centre of mass, a spring-damper, gravity, a follower force and a torque.
//!
//! Held to independent references: `M v` to the generalised forces' change with q̈ (exact: F
//! is linear in q̈), `K v` and `C v` to central differences of F (q̈ = 0) in q and q̇, the
//! energies to hand formulas; generated code to the interpreter (to the round-off between
//! libm's and std's sines), and split functions to whole ones (bit for bit).

use mechgen_runtime::nalgebra::{Const, DefaultAllocator};
use mechgen_runtime::{EnergyTerms, EquationsOfMotion, Storage, Vector};
use proptest::prelude::*;

// Only the equations of motion and the generalised forces are exercised.
#[allow(dead_code)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/swing_motion.rs"));
}

// The same with every function split into parts of at most 12 operations.
#[allow(dead_code)]
mod split {
    include!(concat!(env!("OUT_DIR"), "/swing_motion_split.rs"));
}

use generated::SwingMotion;

const SCENE: &str = include_str!("../data/swing_motion.mech");

/// Nine coordinates: the frame, the arm, the slider.
const N: usize = 9;

fn options() -> mechgen::Options {
    mechgen::Options {
        codegen: mechgen::CodegenOptions {
            equations_of_motion: true,
            ..Default::default()
        },
        ..Default::default()
    }
}

fn interpreted(source: &str) -> mechgen_interp::Interpreted {
    let scene = mechgen::compile(mechgen::Input::Text(source), &options())
        .unwrap_or_else(|e| panic!("{e}"));
    mechgen_interp::Interpreted::new(&scene)
}

fn vector<M: EquationsOfMotion>(m: &M, values: &[f64]) -> Vector<M::Dim>
where
    DefaultAllocator: Storage<M::Dim>,
{
    Vector::<M::Dim>::from_iterator_generic(m.dim(), Const::<1>, values.iter().copied())
}

/// A state of the scene: (q, q̇, v, t), the frame at rest at its pose.
type Sample = (Vec<f64>, Vec<f64>, Vec<f64>, f64);

fn sample() -> impl Strategy<Value = Sample> {
    let moving = || proptest::collection::vec(-2.0..2.0f64, N - 3);
    (
        moving(),
        moving(),
        proptest::collection::vec(-1.0..1.0f64, N),
        0.0..1.0f64,
    )
        .prop_map(|(q, qd, v, t)| {
            let at_rest = |x: Vec<f64>| [vec![0.0; 3], x].concat();
            (at_rest(q), at_rest(qd), v, t)
        })
}

/// `F(q, q̇, q̈, t)` as a plain vector.
fn forces<M: EquationsOfMotion>(m: &M, q: &[f64], qd: &[f64], qdd: &[f64], t: f64) -> Vec<f64>
where
    DefaultAllocator: Storage<M::Dim>,
{
    let mut out = vector(m, &[0.0; N]);
    let (q, qd, qdd) = (vector(m, q), vector(m, qd), vector(m, qdd));
    m.generalized_forces(&q, &qd, &qdd, t, &mut out);
    out.as_slice().to_vec()
}

/// `M v`, `K v` and `C v` (`None` where the scene has no such kernel) at a sample.
type Products = (Vec<f64>, Option<Vec<f64>>, Option<Vec<f64>>);

fn products<M: EquationsOfMotion>(m: &M, (q, qd, v, t): &Sample) -> Products
where
    DefaultAllocator: Storage<M::Dim>,
{
    let unset = vec![f64::NAN; q.len()];
    let (q, qd, v) = (vector(m, q), vector(m, qd), vector(m, v));
    let mut mass = vector(m, &unset);
    m.mass_times(&q, &v, &mut mass);
    let mut stiffness = vector(m, &unset);
    let has_k = m.stiffness_times(&q, &qd, *t, &v, &mut stiffness);
    let mut damping = vector(m, &unset);
    let has_c = m.damping_times(&q, &qd, *t, &v, &mut damping);
    (
        mass.as_slice().to_vec(),
        has_k.then(|| stiffness.as_slice().to_vec()),
        has_c.then(|| damping.as_slice().to_vec()),
    )
}

/// `|a − b| ≤ tolerance` component by component.
fn close(what: &str, a: &[f64], b: &[f64], tolerance: f64) -> Result<(), TestCaseError> {
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        prop_assert!(
            (x - y).abs() <= tolerance,
            "{what}[{k}]: {x} vs {y} (tolerance {tolerance})\n{a:?}\n{b:?}"
        );
    }
    Ok(())
}

fn largest(values: &[f64]) -> f64 {
    values.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// `−(F(x + h v) − F(x − h v)) / 2h` along q (`velocity` false) or q̇, at q̈ = 0.
fn difference<M: EquationsOfMotion>(m: &M, s: &Sample, h: f64, velocity: bool) -> Vec<f64>
where
    DefaultAllocator: Storage<M::Dim>,
{
    let (q, qd, v, t) = s;
    let step = |x: &[f64], sign: f64| -> Vec<f64> {
        x.iter().zip(v).map(|(x, v)| x + sign * h * v).collect()
    };
    let at = |sign: f64| {
        if velocity {
            forces(m, q, &step(qd, sign), &[0.0; N], *t)
        } else {
            forces(m, &step(q, sign), qd, &[0.0; N], *t)
        }
    };
    let (up, down) = (at(1.0), at(-1.0));
    up.iter()
        .zip(&down)
        .map(|(u, d)| -(u - d) / (2.0 * h))
        .collect()
}

/// The products held to F for one implementation.
fn check_products<M: EquationsOfMotion>(m: &M, s: &Sample) -> Result<(), TestCaseError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    let (q, qd, v, t) = s;
    let (mass, stiffness, damping) = products(m, s);
    // F = Q − M q̈ exactly, so M v = F(q̈ = 0) − F(q̈ = v) but for round-off.
    let (rest, moving) = (forces(m, q, qd, &[0.0; N], *t), forces(m, q, qd, v, *t));
    let by_forces: Vec<f64> = rest.iter().zip(&moving).map(|(a, b)| a - b).collect();
    let scale = 1.0 + largest(&rest) + largest(&moving);
    close("M v", &mass, &by_forces, 1e-13 * scale)?;
    // In q̇, F is quadratic (centripetal) plus linear (the damper): a unit step is exact
    // but for round-off. In q a small step keeps the truncation below the tolerance.
    let stiffness = stiffness.expect("gravity on an offset centre and a spring: K ≠ 0");
    let by_q = difference(m, s, 1e-5, false);
    close("K v", &stiffness, &by_q, 1e-6 * (1.0 + largest(&by_q)))?;
    let damping = damping.expect("a damper and an offset centre: C ≠ 0");
    let by_qd = difference(m, s, 1.0, true);
    close(
        "C v",
        &damping,
        &by_qd,
        1e-12 * (1.0 + largest(&by_qd) + scale),
    )
}

/// The energies of the swing scene by hand (its source: gravity (0, −9.81), the arm's centre
/// at (0.5, 0.25) with mass 2, the slider's mass 3 at its reference point; the coil from
/// the frame at (3, 0.5) to the slider at (0, 0.1), k = 50, L = 1, c = 2; the force (0, 3 + t)
/// in the arm's axes at its (1, 0); the torque 2t on the slider).
fn energies_by_hand((q, qd, _, t): &Sample) -> EnergyTerms {
    let ([_, ya, ta], [xs, ys, ts]) = ([q[3], q[4], q[5]], [q[6], q[7], q[8]]);
    let ([xad, yad, tad], [xsd, ysd, tsd]) = ([qd[3], qd[4], qd[5]], [qd[6], qd[7], qd[8]]);
    let ((sa, ca), (ss, cs)) = (ta.sin_cos(), ts.sin_cos());
    let centre_y = ya + 0.5 * sa + 0.25 * ca;
    let gravity = 9.81 * (2.0 * centre_y + 3.0 * ys);
    let d = [xs - 0.1 * ss - 3.0, ys + 0.1 * cs - 0.5];
    let dd = [xsd - 0.1 * cs * tsd, ysd - 0.1 * ss * tsd];
    let length = d[0].hypot(d[1]);
    let rate = (d[0] * dd[0] + d[1] * dd[1]) / length;
    let force = [-(3.0 + t) * sa, (3.0 + t) * ca];
    let velocity = [xad - tad * sa, yad + tad * ca];
    EnergyTerms {
        gravity,
        springs: 25.0 * (length - 1.0).powi(2),
        loads: force[0] * velocity[0] + force[1] * velocity[1] + 2.0 * t * tsd,
        dampers: 2.0 * rate * rate,
    }
}

fn energies<M: EquationsOfMotion>(m: &M, (q, qd, _, t): &Sample) -> EnergyTerms
where
    DefaultAllocator: Storage<M::Dim>,
{
    m.energy_terms(&vector(m, q), &vector(m, qd), *t)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn the_products_are_the_derivatives_of_the_generalized_forces(s in sample()) {
        check_products(&SwingMotion::default(), &s)?;
        check_products(&interpreted(SCENE), &s)?;
    }

    #[test]
    fn the_energies_match_the_hand_formulas(s in sample()) {
        let exact = energies_by_hand(&s);
        let got = energies(&SwingMotion::default(), &s);
        let pairs = [
            (got.gravity, exact.gravity),
            (got.springs, exact.springs),
            (got.loads, exact.loads),
            (got.dampers, exact.dampers),
        ];
        for (got, exact) in pairs {
            prop_assert!((got - exact).abs() <= 1e-12 * (1.0 + exact.abs()), "{got} vs {exact}");
        }
        prop_assert!(got.dampers >= 0.0);
    }

    #[test]
    fn generated_and_interpreted_agree(s in sample()) {
        let (generated, interpreted) = (SwingMotion::default(), interpreted(SCENE));
        let ((gm, gk, gc), (im, ik, ic)) = (products(&generated, &s), products(&interpreted, &s));
        prop_assert_eq!((gk.is_some(), gc.is_some()), (ik.is_some(), ic.is_some()));
        let (ge, ie) = (energies(&generated, &s), energies(&interpreted, &s));
        // Parts of a split body compute exactly what the whole one does.
        let parts = split::SwingMotion::default();
        prop_assert_eq!(products(&parts, &s), (gm.clone(), gk.clone(), gc.clone()));
        prop_assert_eq!(energies(&parts, &s), ge);
        let terms = |e: EnergyTerms| vec![e.gravity, e.springs, e.loads, e.dampers];
        for (what, a, b) in [
            ("M v", gm, im),
            ("K v", gk.unwrap_or_default(), ik.unwrap_or_default()),
            ("C v", gc.unwrap_or_default(), ic.unwrap_or_default()),
            ("energies", terms(ge), terms(ie)),
        ] {
            for (x, y) in a.iter().zip(&b) {
                prop_assert!(round_off(*x, *y), "{what}: generated {a:?}, interpreted {b:?}");
            }
        }
    }
}

#[test]
fn the_split_kernels_are_split() {
    let code = include_str!(concat!(env!("OUT_DIR"), "/swing_motion_split.rs"));
    for part in [
        "mass_times_part1",
        "stiffness_times_part1",
        "damping_times_part1",
        "energy_terms_part1",
    ] {
        assert!(code.contains(part), "{part}");
    }
}

/// Equal but for the round-off that separates libm's elementary functions (generated code)
/// from std's (the interpreter).
fn round_off(x: f64, y: f64) -> bool {
    (x - y).abs() <= 1e-13 * x.abs().max(1.0)
}

/// Which of `stiffness_times` and `damping_times` a scene's generated code and its
/// interpreter have.
fn kernels(body: &str) -> [(bool, bool); 2] {
    let source = format!(
        "mechanism K {{
            ground frame at (0, 0, 0);
            body arm near (1, 0, 0) {body};
            joint pivot: revolute(frame, arm);
            driver swing: angle(arm) = t;
        }}"
    );
    let code = mechgen::expand(mechgen::Input::Text(&source), &options())
        .unwrap_or_else(|e| panic!("{e}"))
        .to_string();
    let emitted = (
        code.contains("fn stiffness_times"),
        code.contains("fn damping_times"),
    );
    let m = interpreted(&source);
    let (_, stiffness, damping) = products(&m, &(vec![0.3; 6], vec![0.2; 6], vec![1.0; 6], 0.5));
    [emitted, (stiffness.is_some(), damping.is_some())]
}

#[test]
fn only_the_tangent_matrices_a_scene_has_are_emitted() {
    assert!(
        mechgen::expand(mechgen::Input::Text(SCENE), &options())
            .unwrap_or_else(|e| panic!("{e}"))
            .to_string()
            .contains("fn stiffness_times")
    );
    // A centred mass under gravity and a torque in t: Q does not move with the state.
    let centred = "mass 2 inertia 0.5; gravity (0, -9.81); load twist: torque(arm) = t";
    // Gravity on an offset centre turns with the arm (K), whose centripetal force grows
    // with its rate (C).
    let offset = "mass 2 inertia 0.5 centre (0.5, 0); gravity (0, -9.81)";
    // A spring to the frame stiffens; without a damper it does not damp.
    let sprung = "mass 2 inertia 0.5; load coil: spring(frame @ (0, 1), arm @ (1, 0), stiffness 5, length 1)";
    // A damper alone damps, and its direction turns with the arm (K).
    let damped = "mass 2 inertia 0.5; load coil: spring(frame @ (0, 1), arm @ (1, 0), stiffness 0, length 1, damping 3)";
    for (body, expected) in [
        (centred, (false, false)),
        (offset, (true, true)),
        (sprung, (true, false)),
        (damped, (true, true)),
    ] {
        assert_eq!(kernels(body), [expected; 2], "{body}");
    }
}

#[test]
fn the_default_options_emit_no_equations_of_motion() {
    let code = mechgen::expand(mechgen::Input::Text(SCENE), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .to_string();
    assert!(!code.contains("EquationsOfMotion"));
    // The interpreter of such a scene answers NaN and "no kernel", never stale numbers.
    let scene = mechgen::compile(mechgen::Input::Text(SCENE), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let m = mechgen_interp::Interpreted::new(&scene);
    let (mass, stiffness, damping) = products(&m, &(vec![0.1; N], vec![0.2; N], vec![1.0; N], 0.3));
    assert!(mass.iter().all(|v| v.is_nan()) && stiffness.is_none() && damping.is_none());
    let e = energies(&m, &(vec![0.1; N], vec![0.2; N], vec![], 0.3));
    assert!(
        [e.gravity, e.springs, e.loads, e.dampers]
            .iter()
            .all(|v| v.is_nan())
    );
}

#[test]
fn generated_code() {
    let code = mechgen::expand(mechgen::Input::Text(SCENE), &options())
        .map(mechgen::pretty)
        .unwrap_or_else(|e| panic!("{e}"));
    // The equations of motion are emitted last: the snapshot is that impl.
    let start = code
        .find("impl ::mechgen_runtime::EquationsOfMotion for SwingMotion")
        .expect("the scene has its equations of motion");
    insta::assert_snapshot!("swing_motion", &code[start..]);
}
