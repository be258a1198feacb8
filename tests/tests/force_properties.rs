//! Properties of the force solve over a corpus using every joint, driver and load kind
//! (`newton_euler/corpus.rs`), in generated code, the interpreter and the dense reference:
//!
//! - a state's reactions do not depend on what the solver solved before: a fresh solver at a
//!   random time against one that solved other random times first, from the same guess;
//! - every body's Newton–Euler balance closes with the reported reactions, efforts and loads
//!   (`newton_euler`: a check built from the model and the meaning of each reaction, not from
//!   the multipliers' derivation), and every ground body's load balances what the joints and
//!   springs put on it;
//! - the three implementations agree;
//! - the issue-20 scenes against their statics by hand, whichever times are asked, and a
//!   scene's reactions do not depend on the order its bodies are declared in.
//!
//! The random times come from a fixed seed, and no failure file is written into the tree.

mod newton_euler;

use mechgen::model::{ConstraintKind, Driven, LoadKind};
use mechgen_interp::Interpreted;
use mechgen_runtime::nalgebra::{DefaultAllocator, Dim, Dyn};
use mechgen_runtime::{Dense, Forces, Simulation, Solver, State, Storage, Structured};
use newton_euler::corpus::{self, Scene};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestCaseError, TestRunner};

/// Steps of the reference motion whose states serve as guesses (each random time starts from
/// the nearest one, so Newton blocks still iterate).
const GRID: usize = 200;

/// Worst Newton–Euler residual accepted, relative to the largest force or moment in the
/// balance (measured: below 1e-13 on the corpus).
const BALANCE: f64 = 1e-11;

/// Implementations agree to this, relative to the largest reaction of the state.
const AGREEMENT: f64 = 1e-10;

fn compile(text: &str) -> mechgen::Scene {
    mechgen::compile(mechgen::Input::Text(text), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{e}"))
}

/// The positions along the scene's motion from t = 0, followed in `GRID` steps (the
/// interpreter's: any implementation would do, they are compared below).
fn reference_motion<S: Scene>() -> Vec<Vec<f64>> {
    let mechanism = Interpreted::new(&compile(S::TEXT));
    let mut simulation = Simulation::new(Solver::new(mechanism), 0.0).expect("assembles");
    let mut positions = Vec::new();
    simulation
        .run(S::T_END, GRID, |state| {
            positions.push(state.q.as_slice().to_vec())
        })
        .expect("solves");
    positions
}

/// The reference state nearest `t`.
fn guess<S: Scene>(motion: &[Vec<f64>], t: f64) -> &[f64] {
    let k = (t / S::T_END * GRID as f64).round() as usize;
    &motion[k.min(GRID)]
}

fn solve_at<M: Structured + Forces>(
    solver: &mut Solver<M>,
    t: f64,
    guess: &[f64],
) -> Result<State<M>, TestCaseError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    let mut state = State::new(solver.mechanism());
    state.q.as_mut_slice().copy_from_slice(guess);
    solver
        .solve_into(t, &mut state)
        .map_err(|e| TestCaseError::fail(format!("t = {t}: {e}")))?;
    Ok(state)
}

/// At time `t` (after solving `history` on the same solver): the state is the same as a fresh
/// solver's, to the bit, and balances every body. Returns the reactions.
fn check_at<S: Scene, M: Structured + Forces + Clone>(
    scene: &mechgen::Scene,
    mechanism: &M,
    motion: &[Vec<f64>],
    history: &[f64],
    t: f64,
) -> Result<Vec<f64>, TestCaseError>
where
    DefaultAllocator: Storage<M::Dim>,
{
    let mut fresh = Solver::new(mechanism.clone());
    let alone = solve_at(&mut fresh, t, guess::<S>(motion, t))?;
    let mut stepped = Solver::new(mechanism.clone());
    for &s in history {
        solve_at(&mut stepped, s, guess::<S>(motion, s))?;
    }
    let after = solve_at(&mut stepped, t, guess::<S>(motion, t))?;
    let (a, b) = (alone.constraint_forces(), after.constraint_forces());
    prop_assert_eq!(alone.q.as_slice(), after.q.as_slice());
    prop_assert!(
        a.as_slice() == b.as_slice(),
        "t = {t} after {history:?}: reactions {:?}, alone {:?}",
        b.as_slice(),
        a.as_slice()
    );
    let residual = newton_euler::residual(scene, mechanism, &alone);
    prop_assert!(
        residual <= BALANCE,
        "t = {t}: Newton–Euler residual {residual:e}"
    );
    Ok(a.as_slice().to_vec())
}

/// Largest difference relative to the largest magnitude of `b` (at least 1).
fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

/// The properties on one corpus scene at `cases` random (history, time) pairs.
fn properties<S: Scene + Structured + Forces>(cases: u32)
where
    DefaultAllocator: Storage<S::Dim>,
    // The interpreter's dimension, which a bound on `S::Dim` alone would hide.
    DefaultAllocator: Storage<Dyn>,
{
    let scene = compile(S::TEXT);
    let motion = reference_motion::<S>();
    let (generated, interpreted) = (S::default(), Interpreted::new(&scene));
    let dense = Dense::new(S::default());
    let config = Config {
        cases,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(20),
        ..Config::default()
    };
    let times = (
        proptest::collection::vec(0.0..=S::T_END, 1..4),
        0.0..=S::T_END,
    );
    let result = TestRunner::new(config).run(&times, |(history, t)| {
        let structured = check_at::<S, _>(&scene, &generated, &motion, &history, t)?;
        let by_interpreter = check_at::<S, _>(&scene, &interpreted, &motion, &history, t)?;
        let by_dense = check_at::<S, _>(&scene, &dense, &motion, &history, t)?;
        for (name, other) in [("interpreter", by_interpreter), ("dense", by_dense)] {
            let difference = relative_difference(&other, &structured);
            prop_assert!(
                difference <= AGREEMENT,
                "t = {t}: {name} vs generated {difference:e}"
            );
        }
        Ok(())
    });
    if let Err(e) = result {
        let name = scene.model.name.to_string();
        panic!("{name}: {e}");
    }
}

#[test]
fn force_solve_is_history_free_and_balances_every_body() {
    properties::<corpus::Sink>(64);
    properties::<corpus::Carriage>(64);
    properties::<corpus::Yoke>(64);
    properties::<corpus::GearTrain>(64);
    properties::<corpus::Actuators>(64);
    properties::<corpus::PrismaticTorque>(32);
    properties::<corpus::WeldTorque>(32);
    properties::<corpus::HeldPost>(32);
    properties::<corpus::Stacked>(64);
    properties::<corpus::StackedReversed>(64);
}

/// A constraint's kind, as the corpus must cover them (matched exhaustively, so a new kind
/// fails to compile here until the corpus has a scene with it).
fn constraint_kind(kind: &ConstraintKind) -> &'static str {
    match kind {
        ConstraintKind::Ground { .. } => "ground",
        ConstraintKind::Revolute { .. } => "revolute",
        ConstraintKind::Prismatic { .. } => "prismatic",
        ConstraintKind::Distance { .. } => "distance",
        ConstraintKind::Slot { .. } => "slot",
        ConstraintKind::Weld { .. } => "weld",
        ConstraintKind::Gear { carrier: None, .. } => "gear",
        ConstraintKind::Gear {
            carrier: Some(_), ..
        } => "gear on a carrier",
        ConstraintKind::Rack { .. } => "rack",
        ConstraintKind::Driver { driven, .. } => match driven {
            Driven::Angle(_) => "angle driver",
            Driven::RelativeAngle(..) => "relative_angle driver",
            Driven::X(_) => "x driver",
            Driven::Y(_) => "y driver",
            // `travel(joint)` and `slide(…)` are the same equation, named apart by the text.
            Driven::Travel { .. } => "travel or slide driver",
            Driven::Distance(..) => "distance driver",
        },
    }
}

/// Every joint, driver and load kind a scene uses.
fn kinds_used(model: &mechgen::Model) -> Vec<&'static str> {
    let mut kinds: Vec<&str> = model
        .constraints
        .iter()
        .map(|c| constraint_kind(&c.kind))
        .collect();
    for load in &model.loads {
        kinds.push(match load.kind {
            LoadKind::Force { local: false, .. } => "force",
            LoadKind::Force { local: true, .. } => "local_force",
            LoadKind::Torque { .. } => "torque",
            LoadKind::Spring { damping, .. } if model.arena.is_zero(damping) => "spring",
            LoadKind::Spring { stiffness, .. } if model.arena.is_zero(stiffness) => "damper",
            LoadKind::Spring { .. } => "spring-damper",
        });
    }
    let gravity = model.gravity.iter().any(|&g| !model.arena.is_zero(g));
    if gravity {
        kinds.push("gravity");
    }
    let offset =
        |m: &mechgen::model::MassProperties| m.centre.iter().any(|&c| !model.arena.is_zero(c));
    if model
        .bodies
        .iter()
        .filter_map(|b| b.mass.as_ref())
        .any(offset)
    {
        kinds.push("offset centre of mass");
    }
    kinds
}

#[test]
fn the_corpus_uses_every_joint_driver_and_load_kind() {
    let mut used: Vec<&str> = corpus::TEXTS
        .iter()
        .flat_map(|text| kinds_used(&compile(text).model))
        .collect();
    used.sort_unstable();
    used.dedup();
    let mut expected = vec![
        "ground",
        "revolute",
        "prismatic",
        "distance",
        "slot",
        "weld",
        "gear",
        "gear on a carrier",
        "rack",
        "angle driver",
        "relative_angle driver",
        "x driver",
        "y driver",
        "travel or slide driver",
        "distance driver",
        "force",
        "local_force",
        "torque",
        "spring-damper",
        "damper",
        "gravity",
        "offset centre of mass",
    ];
    expected.sort_unstable();
    assert_eq!(used, expected);
    // Both `travel` and `slide` appear in the texts.
    for driver in ["travel(", "slide("] {
        assert!(corpus::TEXTS.iter().any(|t| t.contains(driver)), "{driver}");
    }
}

#[test]
fn every_joint_and_driver_kind_carries_load_in_the_corpus() {
    // A reaction that stays zero would pass the balance with any sign: each kind must have,
    // somewhere in the corpus, every one of its reactions well away from zero along a motion.
    let mut loaded: Vec<&str> = Vec::new();
    for text in corpus::TEXTS {
        let scene = compile(text);
        let mechanism = Interpreted::new(&scene);
        let mut simulation = Simulation::new(Solver::new(mechanism), 0.0).expect("assembles");
        let mut largest = vec![0.0f64; scene.model.dim()];
        simulation
            .run(2.0, 40, |state| {
                for (m, r) in largest.iter_mut().zip(state.constraint_forces().iter()) {
                    *m = m.max(r.abs());
                }
            })
            .expect("solves");
        let scale = largest.iter().fold(0.0f64, |m, &x| m.max(x));
        let mut row = 0;
        for constraint in &scene.model.constraints {
            let rows = row..row + constraint.kind.equation_suffixes().len();
            row = rows.end;
            if largest[rows].iter().all(|&m| m > 1e-3 * scale) {
                loaded.push(constraint_kind(&constraint.kind));
            }
        }
    }
    let missing: Vec<&str> = corpus::TEXTS
        .iter()
        .flat_map(|text| {
            let model = compile(text).model;
            model
                .constraints
                .iter()
                .map(|c| constraint_kind(&c.kind))
                .collect::<Vec<_>>()
        })
        .filter(|kind| !loaded.contains(kind))
        .collect();
    assert!(missing.is_empty(), "never loaded: {missing:?}");
}

/// The named reactions of `mechanism` at each time of `times`, solved one after another by
/// one solver from the scene's initial guess.
fn named_reactions<M: Structured + Forces>(
    mechanism: M,
    times: &[f64],
    names: &[&str],
) -> Vec<Vec<f64>>
where
    DefaultAllocator: Storage<M::Dim>,
{
    let column = |m: &M, name: &str| {
        (0..m.dim().value())
            .find(|&i| m.reaction_name(i) == Some(name))
            .unwrap_or_else(|| panic!("no reaction {name}"))
    };
    let columns: Vec<usize> = names.iter().map(|n| column(&mechanism, n)).collect();
    let mut guess = State::new(&mechanism).q;
    mechanism.initial_guess(&mut guess);
    let mut solver = Solver::new(mechanism);
    times
        .iter()
        .map(|&t| {
            let state = solver
                .solve(t, &guess)
                .unwrap_or_else(|e| panic!("t = {t}: {e}"));
            columns
                .iter()
                .map(|&c| state.constraint_forces()[c])
                .collect()
        })
        .collect()
}

/// `names` at 1, 2, 3 in a row and at 3 alone equal `statics(t)`, in generated code, the
/// interpreter and the dense reference.
fn assert_statics<S: Scene + Structured + Forces>(names: &[&str], statics: impl Fn(f64) -> Vec<f64>)
where
    DefaultAllocator: Storage<S::Dim>,
    // The interpreter's dimension, which a bound on `S::Dim` alone would hide.
    DefaultAllocator: Storage<Dyn>,
{
    let scene = compile(S::TEXT);
    for times in [&[1.0, 2.0, 3.0][..], &[3.0]] {
        let solved = [
            ("generated", named_reactions(S::default(), times, names)),
            (
                "interpreter",
                named_reactions(Interpreted::new(&scene), times, names),
            ),
            (
                "dense",
                named_reactions(Dense::new(S::default()), times, names),
            ),
        ];
        for (implementation, rows) in solved {
            for (&t, row) in times.iter().zip(rows) {
                let exact = statics(t);
                for ((name, value), exact) in names.iter().zip(row).zip(exact) {
                    assert!(
                        (value - exact).abs() <= 1e-12 * exact.abs().max(1.0),
                        "{implementation}, t = {t} of {times:?}: {name} = {value}, statics {exact}"
                    );
                }
            }
        }
    }
}

#[test]
fn prismatic_torque_by_hand() {
    // The slider's joint point is at the frame's origin and its reference point 6 ahead,
    // at x = 6 + t: the push (0, 100 t) there is carried as a normal force 100 t and a moment
    // 6 · 100 t = 600 t about the joint point; the frame takes the push and its moment about
    // the origin, (6 + t) · 100 t. The travel driver has nothing to push.
    assert_statics::<corpus::PrismaticTorque>(
        &[
            "slide.normal",
            "slide.torque",
            "s.effort",
            "frame.fx",
            "frame.fy",
            "frame.torque",
        ],
        |t| {
            vec![
                100.0 * t,
                600.0 * t,
                0.0,
                0.0,
                100.0 * t,
                (6.0 + t) * 100.0 * t,
            ]
        },
    );
}

#[test]
fn weld_torque_by_hand() {
    // The bracket's reference point is at (10, 0) − (3, 4) = (7, −4): the push (100 t, 50 t)
    // there has the moment (−3)(50 t) − (−4)(100 t) = 250 t about the weld point (10, 0), and
    // 7 · 50 t + 4 · 100 t = 750 t about the frame's origin.
    assert_statics::<corpus::WeldTorque>(
        &[
            "w.fx",
            "w.fy",
            "w.torque",
            "frame.fx",
            "frame.fy",
            "frame.torque",
        ],
        |t| {
            vec![
                100.0 * t,
                50.0 * t,
                250.0 * t,
                100.0 * t,
                50.0 * t,
                750.0 * t,
            ]
        },
    );
}

#[test]
fn driver_effort_by_hand() {
    // The pin is at the origin, the push (100 t, 0) 10 above it: its moment −1000 t about the
    // pin is held by the angle driver (effort +1000 t, against the world, not the frame); the
    // pin carries the push.
    assert_statics::<corpus::HeldPost>(
        &[
            "hold.effort",
            "pin.fx",
            "pin.fy",
            "frame.fx",
            "frame.torque",
        ],
        |t| vec![1000.0 * t, 100.0 * t, 0.0, 100.0 * t, 0.0],
    );
}

#[test]
fn reactions_do_not_depend_on_the_declaration_order() {
    // The same stacked slides with the bodies declared the other way round: the coordinates
    // (and the fixed stage's order) differ, the reactions by name must not.
    let names = [
        "frame.fx",
        "frame.fy",
        "frame.torque",
        "rail.normal",
        "rail.torque",
        "lift.normal",
        "lift.torque",
        "x.effort",
        "y.effort",
    ];
    let times = [0.3, 1.1, 0.7, 2.0];
    let first = named_reactions(corpus::Stacked::default(), &times, &names);
    let second = named_reactions(corpus::StackedReversed::default(), &times, &names);
    for ((t, a), b) in times.iter().zip(&first).zip(&second) {
        assert!(
            relative_difference(a, b) <= 1e-13,
            "t = {t}: {a:?} against {b:?}"
        );
    }
}
