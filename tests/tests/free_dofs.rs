//! Free degrees of freedom (`free NAME: KIND(…) from u0 speed v0;`): with the state `(u, u̇, ü)`
//! set by hand, the ordinary kinematic solve gives `q`, `q̇`, `q̈` and the efforts, checked
//! against the closed forms written out here:
//!
//! - a pendulum (`x = a cos u`, `y = a sin u`, `θ = u`, rates by hand), and its free
//!   equation's effort against the reduced Lagrange equation `(J + m a²) ü + m g a cos u = τ`
//!   (zero on a motion that obeys it);
//! - a free pendulum on a driven crank (a rheonomic driver and a free degree of freedom in one
//!   scene);
//! - the pendulum at random free states (a property test);
//! - generated against interpreted for the same free state; the `Dynamic` contract (names,
//!   equations, declared initial state at the current parameters, state reads and writes);
//! - a snapshot of the code generated for the pendulum.

use mechgen_interp::Interpreted;
use mechgen_runtime::{Dynamic, Mechanism, Solver, State, Structured, mechanism};
use proptest::prelude::*;

/// The pendulum, as text (interpreted, snapshot) and as the macro below (generated).
const PENDULUM: &str = "
    /// A pendulum swinging freely about a ground pivot.
    pub mechanism FreePendulum {
        /// Distance from the pivot to the centre of mass.
        param a = 0.8;
        ground frame at (0, 0, 0);
        body arm near (0.6, 0.5, 0.7) mass 1.5 inertia 0.02;
        joint pivot: revolute(frame, arm @ (-a, 0));
        free swing: angle(arm) from 0.3 speed 0.5 * a;
        gravity (0, -9.81);
    }";

mechanism! {
    /// A pendulum swinging freely about a ground pivot.
    pub mechanism FreePendulum {
        /// Distance from the pivot to the centre of mass.
        param a = 0.8;
        ground frame at (0, 0, 0);
        body arm near (0.6, 0.5, 0.7) mass 1.5 inertia 0.02;
        joint pivot: revolute(frame, arm @ (-a, 0));
        free swing: angle(arm) from 0.3 speed 0.5 * a;
        gravity (0, -9.81);
    }
}

mechanism! {
    /// A pendulum hanging from a crank driven at a constant speed.
    pub mechanism CrankPendulum {
        /// Crank speed.
        param omega = 3.0;
        ground frame at (0, 0, 0);
        body crank near (0.1, 0, 0) mass 0.5 inertia 0.01;
        body arm near (0.5, 0.4, 0.9) mass 1.0 inertia 0.03;
        joint hub: revolute(frame, crank);
        joint elbow: revolute(crank @ (0.2, 0), arm @ (-0.5, 0));
        driver spin: angle(crank) = omega * t;
        free swing: relative_angle(crank, arm);
        gravity (0, -9.81);
    }
}

const A: f64 = 0.8;
const MASS: f64 = 1.5;
const INERTIA: f64 = 0.02;
const G: f64 = 9.81;

fn interpreted(source: &str) -> Interpreted {
    let scene = mechgen::compile(mechgen::Input::Text(source), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    Interpreted::new(&scene)
}

/// Free states to solve at: value, rate and acceleration, none of them special.
const STATES: [[f64; 3]; 4] = [
    [0.3, 0.0, 0.0],
    [-1.1, 2.5, -7.0],
    [2.4, -0.7, 3.3],
    [4.0, 11.0, 0.25],
];

/// Solves `mechanism` with free state `state` from the guess `near`.
fn solve_at<M: Structured + Dynamic>(
    mut mechanism: M,
    state: [f64; 3],
    t: f64,
    near: &[f64],
) -> State<M>
where
    mechgen_runtime::nalgebra::DefaultAllocator:
        mechgen_runtime::Storage<M::Dim> + mechgen_runtime::FreeStorage<M::Dim, M::Free>,
{
    mechanism.set_free(0, state);
    let guess = mechgen_runtime::Vector::<M::Dim>::from_iterator_generic(
        mechanism.dim(),
        mechgen_runtime::nalgebra::Const::<1>,
        near.iter().copied(),
    );
    Solver::new(mechanism)
        .solve(t, &guess)
        .unwrap_or_else(|e| panic!("solves at {state:?}: {e}"))
}

fn assert_close(what: &str, got: &[f64], exact: &[f64], tolerance: f64) {
    for (k, (g, e)) in got.iter().zip(exact).enumerate() {
        assert!(
            (g - e).abs() <= tolerance * (1.0 + e.abs()),
            "{what}[{k}]: {g} against {e} (all: {got:?} against {exact:?})"
        );
    }
}

/// The pendulum's q, q̇, q̈ (frame, then arm) at `[u, u̇, ü]`, by hand: the arm's point
/// `(−a, 0)` is at the origin, so its reference point is at `a (cos u, sin u)`.
fn pendulum_closed_form([u, ud, udd]: [f64; 3]) -> [[f64; 6]; 3] {
    let (s, c) = u.sin_cos();
    [
        [0.0, 0.0, 0.0, A * c, A * s, u],
        [0.0, 0.0, 0.0, -A * s * ud, A * c * ud, ud],
        [
            0.0,
            0.0,
            0.0,
            -A * c * ud * ud - A * s * udd,
            -A * s * ud * ud + A * c * udd,
            udd,
        ],
    ]
}

/// A guess on the branch of `u` (the solve converges to the nearest assembly).
fn pendulum_guess(u: f64) -> [f64; 6] {
    [
        0.0,
        0.0,
        0.0,
        A * u.cos() + 0.05,
        A * u.sin() - 0.05,
        u + 0.1,
    ]
}

#[test]
fn the_pendulum_solve_follows_the_free_state_as_the_closed_form() {
    for state in STATES {
        let [q, qd, qdd] = pendulum_closed_form(state);
        let solved = solve_at(
            FreePendulum::default(),
            state,
            0.7,
            &pendulum_guess(state[0]),
        );
        assert_close("q", solved.q.as_slice(), &q, 1e-10);
        assert_close("q̇", solved.qd().as_slice(), &qd, 1e-10);
        assert_close("q̈", solved.qdd().as_slice(), &qdd, 1e-9);
    }
}

#[test]
fn the_free_effort_is_the_reduced_equation_of_motion() {
    // The driver's torque on the arm, τ = (J + m a²) ü + m g a cos u (Lagrange's equation in
    // u, the arm's centre of mass at its reference point): zero when ü obeys the equation of
    // motion, so a free state on a solved motion has no effort.
    let m = FreePendulum::default();
    let row = m.free_equation(0);
    assert_eq!(m.reaction_name(row), Some("swing.effort"));
    let mut states = STATES.to_vec();
    let u = 0.9;
    states.push([u, 1.2, -MASS * G * A * u.cos() / (INERTIA + MASS * A * A)]);
    for state in states {
        let [u, _, udd] = state;
        let solved = solve_at(FreePendulum::default(), state, 0.0, &pendulum_guess(u));
        let torque = (INERTIA + MASS * A * A) * udd + MASS * G * A * u.cos();
        let effort = solved.constraint_forces()[row];
        assert!(
            (effort - torque).abs() <= 1e-9 * (1.0 + torque.abs()),
            "effort {effort} against the torque {torque} at {state:?}"
        );
    }
}

#[test]
fn a_driven_crank_and_a_free_pendulum_mix_in_one_scene() {
    // φ = ω t drives the crank (length r); the arm (point (−l, 0) on the crank's tip) turns
    // u relative to it: θ = φ + u, the arm's reference point at r e(φ) + l e(θ).
    let (omega, r, l, t) = (3.0, 0.2, 0.5, 0.4);
    let m = CrankPendulum::default();
    assert_eq!(m.free_name(0), Some("swing"));
    assert_eq!(
        CrankPendulum::EQUATIONS[m.free_equation(0)],
        "swing",
        "the free equation's row"
    );
    for [u, ud, udd] in STATES {
        let phi = omega * t;
        let (theta, thetad, thetadd) = (phi + u, omega + ud, udd);
        let (sp, cp, st, ct) = (phi.sin(), phi.cos(), theta.sin(), theta.cos());
        let q = [
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            phi,
            r * cp + l * ct,
            r * sp + l * st,
            theta,
        ];
        let qd = [
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            omega,
            -r * sp * omega - l * st * thetad,
            r * cp * omega + l * ct * thetad,
            thetad,
        ];
        let qdd = [
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            -r * cp * omega * omega - l * ct * thetad * thetad - l * st * thetadd,
            -r * sp * omega * omega - l * st * thetad * thetad + l * ct * thetadd,
            thetadd,
        ];
        let near: Vec<f64> = q.iter().map(|v| v + 0.03).collect();
        let solved = solve_at(CrankPendulum::default(), [u, ud, udd], t, &near);
        assert_close("q", solved.q.as_slice(), &q, 1e-10);
        assert_close("q̇", solved.qd().as_slice(), &qd, 1e-10);
        assert_close("q̈", solved.qdd().as_slice(), &qdd, 1e-9);
    }
}

proptest! {
    // A fixed seed: every run checks the same states, nothing written into the tree.
    #![proptest_config(ProptestConfig {
        cases: 100,
        failure_persistence: None,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x5EED_F4EE),
        ..ProptestConfig::default()
    })]

    /// Any free state, solved from a guess near it, gives the pendulum's closed form.
    #[test]
    fn any_free_state_solves_to_the_closed_form(
        u in -3.1f64..3.1,
        ud in -20.0f64..20.0,
        udd in -100.0f64..100.0,
        t in 0.0f64..10.0,
    ) {
        let [q, qd, qdd] = pendulum_closed_form([u, ud, udd]);
        let solved = solve_at(FreePendulum::default(), [u, ud, udd], t, &pendulum_guess(u));
        assert_close("q", solved.q.as_slice(), &q, 1e-10);
        assert_close("q̇", solved.qd().as_slice(), &qd, 1e-10);
        assert_close("q̈", solved.qdd().as_slice(), &qdd, 1e-9);
    }
}

#[test]
fn generated_and_interpreted_agree_for_the_same_free_state() {
    for state in STATES {
        let near = pendulum_guess(state[0]);
        let generated = solve_at(FreePendulum::default(), state, 0.2, &near);
        let interpreted = solve_at(interpreted(PENDULUM), state, 0.2, &near);
        let pairs = [
            (generated.q.as_slice(), interpreted.q.as_slice()),
            (generated.qd().as_slice(), interpreted.qd().as_slice()),
            (generated.qdd().as_slice(), interpreted.qdd().as_slice()),
            (
                generated.constraint_forces().as_slice(),
                interpreted.constraint_forces().as_slice(),
            ),
        ];
        for (g, i) in pairs {
            assert_close("generated against interpreted", g, i, 1e-12);
        }
    }
}

/// The `Dynamic` contract, for any implementation of the pendulum.
fn holds_the_dynamic_contract<M: Dynamic + Mechanism>(mut m: M)
where
    mechgen_runtime::nalgebra::DefaultAllocator:
        mechgen_runtime::Storage<M::Dim> + mechgen_runtime::FreeStorage<M::Dim, M::Free>,
{
    use mechgen_runtime::nalgebra::Dim;
    assert_eq!(m.free().value(), 1);
    assert_eq!((m.free_name(0), m.free_name(1)), (Some("swing"), None));
    assert_eq!(m.equation_name(m.free_equation(0)), Some("swing"));
    assert_eq!(m.free_equation(1), usize::MAX);
    // Declared: `from 0.3 speed 0.5 * a`, read at the current parameters.
    assert_eq!(m.free_initial(0), (Some(0.3), 0.5 * A));
    assert!(m.set_parameter("a", 2.0).is_ok());
    assert_eq!(m.free_initial(0), (Some(0.3), 1.0));
    assert_eq!(m.free_initial(1), (None, 0.0));
    // The state starts at the declared one (at the default parameters), at rest.
    assert_eq!(m.free_state(0), [0.3, 0.5 * A, 0.0]);
    m.set_free(0, [1.0, 2.0, 3.0]);
    m.set_free(1, [9.0; 3]);
    assert_eq!(m.free_state(0), [1.0, 2.0, 3.0]);
    assert!(m.free_state(1).iter().all(|v| v.is_nan()));
}

#[test]
fn generated_and_interpreted_keep_the_dynamic_contract() {
    holds_the_dynamic_contract(FreePendulum::default());
    holds_the_dynamic_contract(interpreted(PENDULUM));
    // The generated state is a plain field.
    assert_eq!(FreePendulum::default().free, [[0.3, 0.5 * A, 0.0]]);
}

#[test]
fn an_undeclared_initial_value_is_left_to_assembly() {
    let source = PENDULUM.replace("from 0.3 speed 0.5 * a", "");
    let m = interpreted(&source);
    assert_eq!(m.free_initial(0), (None, 0.0));
    assert_eq!(m.free_state(0), [0.0; 3]);
}

#[test]
fn generated_code_for_the_free_pendulum() {
    let code = mechgen::expand(mechgen::Input::Text(PENDULUM), &mechgen::Options::default())
        .map(mechgen::pretty)
        .unwrap_or_else(|e| panic!("{e}"));
    let mut settings = insta::Settings::clone_current();
    settings.set_omit_expression(true);
    settings.bind(|| insta::assert_snapshot!("free_pendulum", code));
}
