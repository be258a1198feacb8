//! The force solve (inverse dynamics) against physics it must obey:
//!
//! - the seed's reactions against its closed-form Newton–Euler elimination
//!   (`mechgen_examples::inverse_dynamics`), generated and dense-reference solves alike;
//! - the driver's power against the rate of change of kinetic and potential energy along the
//!   closed-form motion;
//! - Newton–Euler for every body of scenes using every joint, driver and load kind
//!   (`newton_euler/corpus.rs`), generated and interpreted: gravity, loads, springs and the
//!   reported reactions balance `m a_c` and `J θ̈` (a checker built from the scene's model,
//!   independent of the generator's force derivation: `newton_euler`);
//! - a slider-crank with offset centres of mass against its closed-form inverse dynamics,
//!   written out here;
//! - a spring-damper on a slider against hand-derived forces;
//! - non-finite loads reported as typed errors.

mod newton_euler;

use mechgen_examples::closed_form::PistonCrank as SeedMotion;
use mechgen_examples::inverse_dynamics::{MassProperties, seed_reactions};
use mechgen_examples::scenes::{PistonCrankDynamics, PistonCrankDynamicsForces};
use mechgen_interp::Interpreted;
use mechgen_runtime::nalgebra::DVector;
use mechgen_runtime::{
    Dense, Forces, Quantity, Simulation, SolveError, Solver, SolverOptions, State, Structured,
    mechanism,
};
use newton_euler::corpus::{Actuators, Carriage, GearTrain, Scene, Sink, Yoke};
use num_dual::{Dual2_64, DualNum, second_derivative};

fn read_scene(file: &str) -> String {
    let path = format!("{}/../examples/scenes/{file}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// Largest difference of each column of `a` and `b` relative to the column's largest magnitude
/// in `b` (over all rows), the largest over all columns; a column smaller than `floor`
/// throughout is measured against `floor`.
fn relative_error(a: &[Vec<f64>], b: &[Vec<f64>], floor: f64) -> f64 {
    let columns = b.first().map_or(0, Vec::len);
    (0..columns)
        .map(|c| {
            let scale = b
                .iter()
                .fold(0.0f64, |m, row| m.max(row[c].abs()))
                .max(floor);
            let worst = a
                .iter()
                .zip(b)
                .fold(0.0f64, |m, (x, y)| m.max((x[c] - y[c]).abs()));
            worst / scale
        })
        .fold(0.0, f64::max)
}

/// Every state of one revolution of the seed with masses, in `steps` steps.
fn seed_states<M: Structured>(mechanism: M, steps: usize) -> Vec<State<M>>
where
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    let period = SeedMotion::default().period();
    let mut simulation = Simulation::new(Solver::new(mechanism), 0.0).expect("assembles");
    let mut states = Vec::new();
    simulation
        .run(period, steps, |state| states.push(state.clone()))
        .expect("solves");
    states
}

#[test]
fn seed_reactions_match_the_closed_form_inverse_dynamics() {
    let (seed, mass) = (SeedMotion::default(), MassProperties::default());
    let states = seed_states(PistonCrankDynamics::default(), 360);
    let exact: Vec<Vec<f64>> = states
        .iter()
        .map(|s| seed_reactions(&seed, &mass, &seed.kinematics(s.t)).in_equation_order())
        .map(|r| r.to_vec())
        .collect();
    let solved: Vec<Vec<f64>> = states
        .iter()
        .map(|s| s.constraint_forces().as_slice().to_vec())
        .collect();
    let error = relative_error(&solved, &exact, 1.0);
    assert!(error <= 1e-10, "generated: {error:e}");
    // Measured: ~1e-15 (the kinematics are exact to round-off, the rest is one solve).
    eprintln!("seed reactions, generated vs closed form: {error:.1e}");

    // The named accessors read the same values.
    let state = &states[40];
    let (reactions, efforts) = (state.reactions(), state.efforts());
    let r = state.constraint_forces();
    assert_eq!(
        reactions.crank_pin.fx,
        r[PistonCrankDynamics::EQUATIONS.len() - 9]
    );
    assert_eq!(efforts.crank_angle, r[14]);
    assert_eq!(
        (reactions.slide.normal, reactions.slide.torque),
        (r[12], r[13])
    );
    assert_eq!(reactions.liner.fy, r[1]);
    assert_eq!(PistonCrankDynamics::REACTIONS[6], "crank_pin.fx");

    // Without static pivots no block's factors are archived: the force solve factors each
    // block again with partial pivoting, to the same answer.
    let options = SolverOptions {
        static_pivots: false,
        ..SolverOptions::default()
    };
    let period = SeedMotion::default().period();
    let mut refactored = Simulation::new(
        Solver::with_options(PistonCrankDynamics::default(), options),
        0.0,
    )
    .expect("assembles");
    let mut again = Vec::new();
    refactored
        .run(period, 360, |s| {
            again.push(s.constraint_forces().as_slice().to_vec())
        })
        .expect("solves");
    let error = relative_error(&again, &solved, 1.0);
    assert!(error <= 1e-13, "archived vs refactored: {error:e}");

    // The dense reference (one block, the textbook F, a transposed LU) agrees.
    let dense = seed_states(Dense::new(PistonCrankDynamics::default()), 360);
    let reference: Vec<Vec<f64>> = dense
        .iter()
        .map(|s| s.constraint_forces().as_slice().to_vec())
        .collect();
    let error = relative_error(&solved, &reference, 1.0);
    assert!(error <= 1e-12, "structured vs dense: {error:e}");
}

/// The seed's kinetic and potential energy rates along the closed-form motion equal the
/// driver's power: effort · θ̇ = dT/dt + dV/dt, with T = Σ ½ m |v|² + ½ J ω² and
/// V = −Σ m g · r (centres of mass at the reference points).
#[test]
fn driver_power_balances_the_energy_rate() {
    let (seed, mass) = (SeedMotion::default(), MassProperties::default());
    let states = seed_states(PistonCrankDynamics::default(), 360);
    let bodies = [(3, mass.piston), (6, mass.rod), (9, mass.crank)];
    let (mut worst, mut largest) = (0.0f64, 0.0f64);
    for state in &states {
        let k = seed.kinematics(state.t);
        let energy_rate: f64 = bodies
            .iter()
            .map(|&(i, (m, j))| {
                let (v, a) = ([k.qd[i], k.qd[i + 1]], [k.qdd[i], k.qdd[i + 1]]);
                let kinetic = m * (v[0] * a[0] + v[1] * a[1]) + j * k.qd[i + 2] * k.qdd[i + 2];
                let potential = -m * (mass.gravity[0] * v[0] + mass.gravity[1] * v[1]);
                kinetic + potential
            })
            .sum();
        let power = state.efforts().crank_angle * k.qd[11];
        worst = worst.max((power - energy_rate).abs());
        largest = largest.max(energy_rate.abs());
    }
    assert!(worst <= 1e-10 * largest, "{worst:e} of {largest:e}");
}

/// Steps `mechanism` (an implementation of `scene`) and checks Newton–Euler at every state.
fn newton_euler_along<M: Structured + Forces>(
    scene: &mechgen::Scene,
    mechanism: M,
    t_end: f64,
    steps: usize,
) -> f64
where
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    let mut simulation = Simulation::new(Solver::new(mechanism), 0.0).expect("assembles");
    let mut states = Vec::new();
    simulation
        .run(t_end, steps, |state| states.push(state.clone()))
        .expect("solves");
    let mechanism = simulation.solver().mechanism();
    states
        .iter()
        .map(|state| newton_euler::residual(scene, mechanism, state))
        .fold(0.0, f64::max)
}

/// Steps a `.mech` scene with the interpreter and checks Newton–Euler at every state.
fn assert_newton_euler(source: &str, t_end: f64, steps: usize) {
    let scene = mechgen::compile(mechgen::Input::Text(source), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let worst = newton_euler_along(&scene, Interpreted::new(&scene), t_end, steps);
    assert!(worst <= 1e-10, "Newton–Euler residual {worst:e}");
}

#[test]
fn newton_euler_balances_every_body_of_the_seed() {
    let period = SeedMotion::default().period();
    assert_newton_euler(&read_scene("piston_crank_dynamics.mech"), period, 90);
}

/// A corpus scene, interpreted and generated, along its motion.
fn assert_newton_euler_both<S: Scene + Structured + Forces>(steps: usize)
where
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<S::Dim>,
{
    let scene = mechgen::compile(mechgen::Input::Text(S::TEXT), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let name = scene.model.name.to_string();
    let worst = newton_euler_along(&scene, S::default(), S::T_END, steps);
    assert!(
        worst <= 1e-10,
        "{name} (generated): Newton–Euler residual {worst:e}"
    );
    assert_newton_euler(S::TEXT, S::T_END, steps);
}

#[test]
fn newton_euler_balances_every_joint_driver_and_load_kind() {
    // Revolute, distance, prismatic; relative_angle drivers; forces, a torque, a spring-damper.
    assert_newton_euler_both::<Sink>(60);
    // Travel and x drivers, a damper.
    assert_newton_euler_both::<Carriage>(60);
    // Slot, weld, rack; an angle driver.
    assert_newton_euler_both::<Yoke>(60);
    // Gears with and without a carrier; a y driver.
    assert_newton_euler_both::<GearTrain>(60);
    // Distance and slide drivers.
    assert_newton_euler_both::<Actuators>(60);
}

/// The reactions along `steps` steps of a simulation to `t_end`, as rows.
fn reaction_rows<M: Structured + Forces>(mechanism: M, t_end: f64, steps: usize) -> Vec<Vec<f64>>
where
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    let mut simulation = Simulation::new(Solver::new(mechanism), 0.0).expect("assembles");
    let mut rows = Vec::new();
    simulation
        .run(t_end, steps, |state| {
            rows.push(state.constraint_forces().as_slice().to_vec());
        })
        .expect("solves");
    rows
}

#[test]
fn generated_force_solve_matches_the_interpreter_across_blocks() {
    // Carriage solves in two blocks, so its force solve walks the archive of the first
    // block's factors; Sink has every joint kind.
    let interpreted = |text: &str| {
        Interpreted::new(
            &mechgen::compile(mechgen::Input::Text(text), &mechgen::Options::default())
                .unwrap_or_else(|e| panic!("{e}")),
        )
    };
    let error = relative_error(
        &reaction_rows(Sink::default(), 2.0, 60),
        &reaction_rows(interpreted(Sink::TEXT), 2.0, 60),
        1.0,
    );
    assert!(
        error <= 1e-11,
        "Sink: generated vs interpreted reactions {error:e}"
    );
    let error = relative_error(
        &reaction_rows(Carriage::default(), 3.0, 60),
        &reaction_rows(interpreted(Carriage::TEXT), 3.0, 60),
        1.0,
    );
    assert!(
        error <= 1e-11,
        "Carriage: generated vs interpreted reactions {error:e}"
    );
    let blocks = |stages: usize| {
        (0..stages)
            .filter(|&s| {
                matches!(
                    Carriage::default().stage(s),
                    Some(mechgen_runtime::codegen::Stage::Block(_))
                )
            })
            .count()
    };
    assert!(
        blocks(Carriage::default().stage_count()) >= 2,
        "Carriage has one block only"
    );
}

mechanism! {
    /// An in-line slider-crank whose centres of mass are off the reference points (m, kg, s).
    mechanism OffsetSliderCrank {
        param omega = 40.0;
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0.3) mass 2 inertia 0.01 centre (0.03, 0.01);
        body rod near (0.05, 0.03, -0.1) mass 1 inertia 0.02 centre (0.12, -0.005);
        body slider near (0.3, 0, 0) mass 0.7 inertia 0.001 centre (0.01, 0.02);
        joint pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (0.1, 0), rod);
        joint wrist: revolute(rod @ (0.25, 0), slider);
        joint guide: prismatic(frame, slider, along (1, 0));
        driver spin: angle(crank) = 0.3 + omega * t;
        gravity (0, -9.81);
        load gas: force(slider) = (-200 * (1 + sin(omega * t)), 0);
    }
}

/// The offset slider-crank's motion for a crank angle (dual numbers give its rates), with the
/// rod's reference point at the crank pin and the slider ahead of it.
fn slider_crank_positions<D: DualNum<Primitive = f64> + Copy>(theta: D) -> [D; 9] {
    let (r, l) = (0.1, 0.25);
    let (s, c) = theta.sin_cos();
    let pin = [c * r, s * r];
    let rod = (-pin[1] / l).asin();
    let slider = pin[0] + rod.cos() * l;
    let zero = theta * 0.0;
    [zero, zero, theta, pin[0], pin[1], rod, slider, zero, zero]
}

/// Closed-form inverse dynamics of the offset slider-crank, eliminated from the slider to the
/// crank. Returns the reported reactions: the force on the crank from the rod at the crank pin
/// `P`, the force on the rod from the slider at the wrist `W`, the guide's normal force `N` and
/// torque `T` on the frame, and the driving torque `τ`.
fn slider_crank_forces(t: f64) -> ([f64; 2], [f64; 2], [f64; 2], f64) {
    let omega = 40.0;
    let angle = |t: Dual2_64| slider_crank_positions(t * omega + 0.3);
    let k: [(f64, f64, f64); 9] = second_derivative(angle, t);
    let (q, qd, qdd) = (k.map(|x| x.0), k.map(|x| x.1), k.map(|x| x.2));
    let g = [0.0, -9.81];
    let rot = |th: f64, s: [f64; 2]| {
        let (sin, cos) = th.sin_cos();
        [cos * s[0] - sin * s[1], sin * s[0] + cos * s[1]]
    };
    let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
    // Body i (crank 0, rod 3, slider 6): the centre's world offset c = A s and its
    // acceleration a_c = r̈ + θ̈ × c − θ̇² c.
    let centre = |i: usize, s: [f64; 2]| {
        let c = rot(q[i + 2], s);
        let (w, alpha) = (qd[i + 2], qdd[i + 2]);
        let a = [
            qdd[i] - alpha * c[1] - w * w * c[0],
            qdd[i + 1] + alpha * c[0] - w * w * c[1],
        ];
        (c, a, alpha)
    };
    let neg = |v: [f64; 2]| [-v[0], -v[1]];
    let (m1, j1) = (2.0, 0.01);
    let (m2, j2) = (1.0, 0.02);
    let (m3, j3) = (0.7, 0.001);
    let (c1, a1, alpha1) = centre(0, [0.03, 0.01]);
    let (c2, a2, alpha2) = centre(3, [0.12, -0.005]);
    let (c3, a3, alpha3) = centre(6, [0.01, 0.02]);
    let gas = [-200.0 * (1.0 + (omega * t).sin()), 0.0];
    // Slider: −W at the wrist, −N ŷ and the gas force at its reference point, −T.
    let wx = gas[0] + m3 * (g[0] - a3[0]);
    // Rod: −P at the crank pin (its reference point), W at the wrist: x and y give P from W;
    // its moment balance about the centre then gives W's y component.
    let px = wx + m2 * (g[0] - a2[0]);
    let lift = m2 * (g[1] - a2[1]);
    let wrist = rot(q[5], [0.25, 0.0]);
    let arm = [wrist[0] - c2[0], wrist[1] - c2[1]];
    let wy = (j2 * alpha2 - c2[0] * lift + c2[1] * px + arm[1] * wx) / wrist[0];
    let (p, w) = ([px, wy + lift], [wx, wy]);
    let normal = -wy + m3 * (g[1] - a3[1]);
    let torque =
        cross(neg(c3), neg(w)) + cross(neg(c3), [0.0, -normal]) + cross(neg(c3), gas) - j3 * alpha3;
    // Crank: P at its pin, the pivot's force F at its reference point, τ.
    let pivot = [m1 * (a1[0] - g[0]) - p[0], m1 * (a1[1] - g[1]) - p[1]];
    let pin = rot(q[2], [0.1, 0.0]);
    let tau = j1 * alpha1 - cross([pin[0] - c1[0], pin[1] - c1[1]], p) - cross(neg(c1), pivot);
    (p, w, [normal, torque], tau)
}

#[test]
fn offset_slider_crank_matches_its_closed_form_inverse_dynamics() {
    let mut simulation =
        Simulation::new(Solver::new(OffsetSliderCrank::default()), 0.0).expect("assembles");
    let period = std::f64::consts::TAU / 40.0;
    let (mut worst, mut scale) = (0.0f64, 0.0f64);
    simulation
        .run(period, 120, |state| {
            let (crank_pin, wrist, guide, tau) = slider_crank_forces(state.t);
            let (r, e) = (state.reactions(), state.efforts());
            let pairs = [
                (r.crank_pin.fx, crank_pin[0]),
                (r.crank_pin.fy, crank_pin[1]),
                (r.wrist.fx, wrist[0]),
                (r.wrist.fy, wrist[1]),
                (r.guide.normal, guide[0]),
                (r.guide.torque, guide[1]),
                (e.spin, tau),
            ];
            for (solved, exact) in pairs {
                worst = worst.max((solved - exact).abs());
                scale = scale.max(exact.abs());
            }
        })
        .expect("solves");
    assert!(worst <= 1e-10 * scale, "{worst:e} of {scale:e}");
}

mechanism! {
    /// A slider on a horizontal guide, pushed through a spring-damper from the frame by an x
    /// driver, under gravity (m, kg, s).
    mechanism SprungSlider {
        ground frame at (0, 0, 0);
        body slider near (1, 0, 0) mass 3 inertia 0.2;
        joint guide: prismatic(frame, slider, along (1, 0));
        driver stroke: x(slider) = 1 + 0.2 * sin(7 * t);
        gravity (0, -9.81);
        load coil: spring(frame, slider, stiffness 500, length 0.8, damping 4);
    }
}

#[test]
fn spring_damper_forces_match_hand_derivation() {
    let mut simulation =
        Simulation::new(Solver::new(SprungSlider::default()), 0.0).expect("assembles");
    simulation
        .run(1.0, 50, |state| {
            let t = state.t;
            let (x, v, a) = (
                1.0 + 0.2 * (7.0 * t).sin(),
                1.4 * (7.0 * t).cos(),
                -9.8 * (7.0 * t).sin(),
            );
            // m ẍ = effort − k (x − L) − c ẋ; the guide carries the weight.
            let effort = 3.0 * a + 500.0 * (x - 0.8) + 4.0 * v;
            let (r, e) = (state.reactions(), state.efforts());
            assert!(
                (e.stroke - effort).abs() <= 1e-10 * 300.0,
                "{} vs {effort}",
                e.stroke
            );
            assert!((r.guide.normal - 3.0 * -9.81).abs() <= 1e-12);
            assert!(r.guide.torque.abs() <= 1e-12);
            assert!((r.frame.fy - 3.0 * -9.81).abs() <= 1e-12);
            // The spring pulls the frame toward the slider; the x driver pushes against the
            // world, not the frame.
            let tension = 500.0 * (x - 0.8) + 4.0 * v;
            assert!(
                (r.frame.fx - tension).abs() <= 1e-10 * 300.0,
                "{} vs {tension}",
                r.frame.fx
            );
        })
        .expect("solves");
}

#[test]
fn non_finite_loads_are_typed_errors_naming_the_forces() {
    // A force that becomes NaN past t = 1, and a spring of non-zero free length whose ends
    // meet (its direction, and so its force, is undefined there).
    let scene = |load: &str| {
        let source = format!(
            "mechanism M {{
                ground frame at (0, 0, 0);
                body slider near (1, 0, 0) mass 1;
                joint guide: prismatic(frame, slider, along (1, 0));
                driver stroke: x(slider) = 1 - t;
                {load}
            }}"
        );
        Interpreted::new(
            &mechgen::compile(mechgen::Input::Text(&source), &mechgen::Options::default())
                .unwrap_or_else(|e| panic!("{e}")),
        )
    };
    for (load, time, named) in [
        (
            "load push: force(slider) = (sqrt(1 - t), 0);",
            1.5,
            Quantity::LoadValue(0),
        ),
        (
            "load coil: spring(frame, slider, stiffness 1, length 0.5);",
            1.0,
            Quantity::SpringEnds(0),
        ),
    ] {
        let mut solver = Solver::new(scene(load));
        let guess = DVector::from_vec(vec![0.0, 0.0, 0.0, 1.0 - time, 0.0, 0.0]);
        match solver.solve(time, &guess) {
            Err(SolveError::NonFinite {
                quantity, time: t, ..
            }) if quantity == named => assert_eq!(t, time),
            other => panic!("{load}: expected a non-finite load, got {other:?}"),
        }
    }
}

#[test]
fn a_zero_length_spring_stays_finite_where_its_ends_meet() {
    // Its force, k d, is defined everywhere: through the meeting point at t = 1 the driver
    // holds it, never a NaN.
    let source = "mechanism M {
        ground frame at (0, 0, 0);
        body slider near (1, 0, 0) mass 1;
        joint guide: prismatic(frame, slider, along (1, 0));
        driver stroke: x(slider) = 1 - t;
        load coil: spring(frame, slider, stiffness 3, length 0);
    }";
    let mut solver = Solver::new(Interpreted::new(
        &mechgen::compile(mechgen::Input::Text(source), &mechgen::Options::default())
            .unwrap_or_else(|e| panic!("{e}")),
    ));
    for time in [0.5, 1.0, 1.5] {
        let guess = DVector::from_vec(vec![0.0, 0.0, 0.0, 1.0 - time, 0.0, 0.0]);
        let state = solver
            .solve(time, &guess)
            .unwrap_or_else(|e| panic!("t = {time}: {e}"));
        // The slider moves at constant speed: the driver balances the spring, 3 (1 − t) toward
        // the frame, so its effort along x is +3 (1 − t) (`x = 1 − t`: Φ = x − (1 − t)).
        let effort = state.constraint_forces()[5];
        assert!(
            (effort - 3.0 * (1.0 - time)).abs() < 1e-12,
            "t = {time}: effort {effort}"
        );
    }
}

#[test]
fn force_kernels_read_their_angles_from_the_trig_cache() {
    // Only the force solve needs the crank's sine and cosine (the force's lever arm and the
    // centre's acceleration): the cache is planned for it too, so the stage that solves the
    // angle fills it and no force kernel calls `sincos` again.
    let source = "mechanism LoadedCrank {
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0) mass 1 inertia 0.5 centre (0.5, 0.1);
        joint pivot: revolute(frame, crank);
        driver spin: angle(crank) = 3 * t;
        load push: force(crank @ (1, 0)) = (0, 2);
    }";
    let scene = mechgen::compile(mechgen::Input::Text(source), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let code = mechgen::emit::emit(&scene).to_string();
    let mut kernels = 0;
    // Every function body sits between `fn name (` and the next `fn `.
    for body in code.split(" fn ").skip(1) {
        let name = body.split_whitespace().next().unwrap_or_default();
        if name.ends_with("_multipliers") || name.ends_with("_force_rhs") {
            kernels += 1;
            assert!(
                !body.contains("sincos"),
                "`fn {name}` computes a sine: {body}"
            );
            assert!(
                body.contains("trig"),
                "`fn {name}` reads no cached angle: {body}"
            );
        }
    }
    assert!(kernels > 0, "no force kernel in {code}");
}
