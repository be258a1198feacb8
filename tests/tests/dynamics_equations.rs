//! The equations of motion mechgen generates, without the integrator: with a free state
//! `(u, u̇, ü)` set by hand, the kinematic solve and the force solve give the free degree of
//! freedom's effort, the residual of the equations of motion. At the reference's acceleration
//! (`mechgen_tests::reference`: reduced Lagrange equations written out by hand) it vanishes, and
//! the solved `q`, `q̇`, `q̈` are the reference's: the free seed (plain, with a stiff spring and
//! with a spring-damper) and the double pendulum, generated and interpreted.

use mechgen_runtime::nalgebra::{Const, DefaultAllocator};
use mechgen_runtime::{Dynamic, FreeStorage, Solver, State, Storage, Structured, Vector};
use mechgen_tests::reference::double_pendulum::{Bar, DoublePendulum as Chain};
use mechgen_tests::reference::seed::FreeSeed as Seed;
use mechgen_tests::twin;

twin! {
    SPRUNG_SEED,
    mechanism SprungSeed {
        /// The spring-damper between liner and piston (kg/s², mm, kg/s); none by default.
        param k = 0.0;
        param rest = 138.8;
        param c = 0.0;

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

        load coil: spring(liner @ (100, 0), piston, stiffness k, length rest, damping c);

        branch piston_outboard: dot(bearing -> liner, rod @ (41.3, 0) -> rod @ (0, 102.6)) > 0;

        gravity (0, -9810);
    }
}

twin! {
    DOUBLE,
    mechanism DoublePendulum {
        ground frame at (0, 0, 0);
        body upper near (0, -60, -90deg) mass 1 inertia 3000;
        body lower near (0, -170, -90deg) mass 0.6 inertia 1800;
        joint shoulder: revolute(frame, upper @ (-60, 0));
        joint elbow: revolute(upper @ (60, 0), lower @ (-50, 0));
        free upper_angle: angle(upper) from -1.0;
        free lower_angle: angle(lower) from -0.6;
        gravity (0, -9810);
    }
}

/// The chain of `DOUBLE` as the reference sees it.
const CHAIN: Chain = Chain {
    first: Bar {
        mass: 1.0,
        inertia: 3000.0,
        centre: 60.0,
        length: 120.0,
    },
    second: Bar {
        mass: 0.6,
        inertia: 1800.0,
        centre: 50.0,
        length: 0.0,
    },
    gravity: [0.0, -9810.0],
};

fn interpreted(text: &str) -> mechgen_interp::Interpreted {
    let scene = mechgen::compile(mechgen::Input::Text(text), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    mechgen_interp::Interpreted::new(&scene)
}

/// The kinematic and force solve of `mechanism` at t = 0 with free states `frees`, from the
/// guess `near`.
fn solve_at<M>(mut mechanism: M, frees: &[[f64; 3]], near: &[f64]) -> State<M>
where
    M: Dynamic + Structured + Clone,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    for (k, &state) in frees.iter().enumerate() {
        mechanism.set_free(k, state);
    }
    let guess =
        Vector::<M::Dim>::from_iterator_generic(mechanism.dim(), Const::<1>, near.iter().copied());
    Solver::new(mechanism)
        .solve(0.0, &guess)
        .unwrap_or_else(|e| panic!("solves at {frees:?}: {e}"))
}

/// Largest difference of two slices relative to `1 + |b|`.
fn off(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() / (1.0 + y.abs()))
        .fold(0.0, f64::max)
}

/// Reduced states of the seed, none special: a release, slow and fast turns either way.
const SEED_STATES: [(f64, f64); 5] = [
    (0.3, 0.0),
    (0.31, 2.0),
    (1.0, -5.0),
    (2.0, 10.0),
    (-2.5, 30.0),
];

/// The seed's effort and motion against the reference `seed`, for `mechanism` with its spring
/// set to the reference's.
fn check_seed<M>(label: &str, mut mechanism: M, seed: &Seed)
where
    M: Dynamic + Structured + Clone,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    if let Some(spring) = seed.spring {
        for (name, value) in [
            ("k", spring.stiffness),
            ("rest", spring.length),
            ("c", spring.damping),
        ] {
            mechanism
                .set_parameter(name, value)
                .unwrap_or_else(|e| panic!("{e}"));
        }
    }
    let row = mechanism.free_equation(0);
    assert_eq!(mechanism.reaction_name(row), Some("crank_angle.effort"));
    for (phi, rate) in SEED_STATES {
        let accel = seed.acceleration(phi, rate);
        let [q, qd, qdd] = seed.motion(phi, rate);
        let state = solve_at(mechanism.clone(), &[[phi, rate, accel]], &q);
        assert!(off(state.q.as_slice(), &q) <= 1e-10, "{label}: q at {phi}");
        assert!(
            off(state.qd().as_slice(), &qd) <= 1e-10,
            "{label}: q̇ at {phi}"
        );
        assert!(
            off(state.qdd().as_slice(), &qdd) <= 1e-9,
            "{label}: q̈ at {phi}"
        );
        // The effort against the torques in play: the generalised inertia force m(φ) φ̈ and
        // the weight of the moving parts at the crank's radius.
        let (m, _) = seed.generalised_mass(&seed.configuration(phi));
        let scale = m * accel.abs() + 2.1 * 9810.0 * 43.0;
        let effort = state.constraint_forces()[row];
        assert!(
            effort.abs() <= 1e-12 * scale,
            "{label}: effort {effort:e} at φ = {phi}, φ̇ = {rate} (scale {scale:e})"
        );
        // And it is the residual: a different acceleration needs m(φ) Δφ̈ of torque.
        let pushed = solve_at(mechanism.clone(), &[[phi, rate, accel + 1.0]], &q);
        let torque = pushed.constraint_forces()[row];
        assert!(
            (torque - m).abs() <= 1e-9 * scale,
            "{label}: {torque} vs m(φ) = {m}"
        );
    }
}

#[test]
fn the_seed_s_equation_of_motion_is_its_reduced_lagrange_equation() {
    for seed in [
        Seed::default(),
        Seed::with_spring(256.8, 1e7, 0.0, Seed::RELEASE),
        Seed::with_spring(256.8, 2e4, 3.0, 0.8),
    ] {
        check_seed("generated", SprungSeed::default(), &seed);
        check_seed("interpreted", interpreted(SPRUNG_SEED), &seed);
    }
}

/// The double pendulum's efforts and centres against the reference, for `mechanism`.
fn check_chain<M>(label: &str, mechanism: M)
where
    M: Dynamic + Structured + Clone,
    DefaultAllocator: Storage<M::Dim> + FreeStorage<M::Dim, M::Free>,
{
    let rows = [mechanism.free_equation(0), mechanism.free_equation(1)];
    for y in [
        [-1.0, -0.6, 0.0, 2.0],
        [0.3, -2.0, 4.0, -3.0],
        [2.5, 2.4, -6.0, 7.0],
    ] {
        let r = CHAIN.rate(&y);
        let [c1, c2] = CHAIN.centres(y[0], y[1]);
        let q = [0.0, 0.0, 0.0, c1[0], c1[1], y[0], c2[0], c2[1], y[1]];
        let state = solve_at(
            mechanism.clone(),
            &[[y[0], y[2], r[2]], [y[1], y[3], r[3]]],
            &q,
        );
        assert!(off(state.q.as_slice(), &q) <= 1e-10, "{label}: q at {y:?}");
        let scale = 1e6;
        for row in rows {
            let effort = state.constraint_forces()[row];
            assert!(
                effort.abs() <= 1e-12 * scale,
                "{label}: effort {effort:e} at {y:?}"
            );
        }
    }
}

#[test]
fn the_double_pendulum_s_equations_are_its_lagrange_equations() {
    check_chain("generated", DoublePendulum::default());
    check_chain("interpreted", interpreted(DOUBLE));
}
