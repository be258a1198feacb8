//! Closed-form groups (issue 23) against closed forms written in the test and against the
//! Newton path (`SolverOptions::closed_forms: false`): each group kind over random geometry,
//! drives, times and guesses on both assembly branches; near, at and beyond toggles (the same
//! answers and the same errors as the Newton path); a class III group that stays a Newton block
//! beside a closed-form dyad; whole runs of `Simulation`, closed forms on and off; and the
//! interpreter's closed-form starts against the generated code's.

#[path = "closed_forms/compare.rs"]
mod compare;
#[path = "closed_forms/exact.rs"]
mod exact;
#[path = "closed_forms/scenes.rs"]
mod scenes;
#[path = "closed_forms/toggles.rs"]
mod toggles;

use core::f64::consts::{PI, TAU};

use mechgen::plan::closed::ClosedKind;
use mechgen::plan::structure::Block;
use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{Accelerations, Mechanism, Structured, Vector};
use proptest::prelude::*;

use compare::{
    Solved, apart, assert_same_turns, assert_within, guess_near, run, run_interpreted, solve,
};
use exact::Exact;
use scenes::{
    COLLAR, Collar, FOUR_BAR, FourBar, OFFSET_SLIDER, OffsetSlider, PISTON_CRANK, PUSHED_SLIDER,
    PistonCrank, PushedSlider, SIX_BAR, SixBar,
};

/// Agreement to round-off: q in scene lengths and radians, q̇ and q̈ relative to their largest
/// magnitude.
const ROUND_OFF: [f64; 3] = [1e-12; 3];

/// How far (in radians and scene lengths) a guess lies from the solution it should lead to,
/// besides whole turns of its angles.
const SPREAD: f64 = 0.1;

/// Solves one instant of a scene with one block from `guess`, with closed forms on and off: both
/// land on `want` (the branch the guess is near) to round-off, the closed-form path starting
/// its block on the root (one evaluation of the block verifies it), the Newton path not.
fn check_instant<M, const N: usize>(
    what: &str,
    scene: &M,
    length: f64,
    t: f64,
    guess: &[f64; N],
    want: &Exact<N>,
) where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    let closed = solve(scene, true, t, guess).unwrap_or_else(|e| panic!("{what}, t = {t}: {e}"));
    let newton = solve(scene, false, t, guess).unwrap_or_else(|e| panic!("{what}, t = {t}: {e}"));
    assert_eq!(
        (closed.closed_forms, closed.evaluations),
        (1, 1),
        "{what}, t = {t}"
    );
    assert_eq!(newton.closed_forms, 0, "{what}, t = {t}");
    let what = format!("{what}, t = {t}");
    assert_within(
        &format!("{what}, closed forms vs exact"),
        apart(scene, length, &closed, want),
        ROUND_OFF,
    );
    assert_within(
        &format!("{what}, closed forms vs Newton"),
        apart(scene, length, &closed, &newton),
        ROUND_OFF,
    );
    assert_same_turns(&what, scene, &closed.q, &newton.q);
}

/// The closed-form kind of each block of a scene's plan, in solve order (`None`: a Newton
/// block), with the block's coordinates.
fn block_kinds(text: &str) -> Vec<(Option<ClosedKind>, Vec<usize>)> {
    let scene = mechgen::compile(mechgen::Input::Text(text), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    scene
        .plan
        .blocks()
        .map(|b: &Block| (b.closed.as_ref().map(|c| c.kind), b.coordinates.clone()))
        .collect()
}

/// Sorted, to compare a block's coordinates (in pivot order) as a set.
fn sorted(mut coordinates: Vec<usize>) -> Vec<usize> {
    coordinates.sort_unstable();
    coordinates
}

#[test]
fn each_scene_plans_its_group_as_its_closed_form_kind() {
    let cases: [(&str, &str, ClosedKind, Vec<usize>); 5] = [
        (
            "four-bar",
            FOUR_BAR,
            ClosedKind::CircleCircle,
            vec![FourBar::COUPLER_THETA, FourBar::ROCKER_THETA],
        ),
        (
            "offset slider-crank",
            OFFSET_SLIDER,
            ClosedKind::CircleLine,
            vec![OffsetSlider::ROD_THETA],
        ),
        (
            "piston-crank",
            PISTON_CRANK,
            ClosedKind::CircleLine,
            vec![PistonCrank::ROD_Y, PistonCrank::ROD_THETA],
        ),
        ("collar", COLLAR, ClosedKind::Linear, vec![Collar::COLLAR_Y]),
        (
            "pushed slider-crank",
            PUSHED_SLIDER,
            ClosedKind::CircleCircle,
            vec![PushedSlider::CRANK_THETA, PushedSlider::ROD_THETA],
        ),
    ];
    for (what, text, kind, coordinates) in cases {
        let blocks = block_kinds(text);
        assert_eq!(blocks.len(), 1, "{what}: {blocks:?}");
        assert_eq!(blocks[0].0, Some(kind), "{what}");
        assert_eq!(sorted(blocks[0].1.clone()), sorted(coordinates), "{what}");
    }
}

/// Link lengths of a crank-rocker whose dyad stays clear of its toggles: the distance from
/// the crank pin to the rocker pivot, d − a to d + a over a turn, keeps a margin from |b − c|
/// and b + c (the crank then turns fully: Grashof, the crank the shortest link).
fn crank_rocker(a: f64, b: f64, c: f64, d: f64) -> bool {
    let margin = 0.15 * (b + c);
    d + a < b + c - margin && d - a > (b - c).abs() + margin
}

/// 10^`exponent`: the scene's size.
fn size(exponent: f64) -> f64 {
    10f64.powf(exponent)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn four_bar_is_the_circle_circle_intersection_on_both_branches(
        a in 0.5_f64..1.2,
        b in 2.5_f64..5.0,
        c in 2.5_f64..5.0,
        d in 2.5_f64..5.0,
        exponent in -2.0_f64..3.0,
        omega in 0.5_f64..50.0,
        phase in -PI..PI,
        times in prop::collection::vec(0.0_f64..1.0, 3),
        moves in prop::collection::vec(-1.0_f64..1.0, 12),
        turns in -50_i32..50,
    ) {
        prop_assume!(crank_rocker(a, b, c, d));
        let s = size(exponent);
        let (a, b, c, d) = (a * s, b * s, c * s, d * s);
        let scene = FourBar { a, b, c, d, omega, phase, ..FourBar::default() };
        let length = scene.b.max(scene.c).max(scene.d);
        for sign in [1.0, -1.0] {
            let motion = exact::four_bar(&scene, sign);
            for &fraction in &times {
                let t = fraction * TAU / omega;
                let want = exact::at(&motion, t);
                let guess = guess_near(&scene, length, &want.q, (&moves, SPREAD), turns);
                let what = format!("four-bar {scene:?}, branch {sign}");
                check_instant(&what, &scene, length, t, &guess, &want);
            }
        }
    }

    #[test]
    fn offset_slider_is_the_circle_line_intersection_on_both_sides(
        r in 0.5_f64..1.5,
        l in 2.5_f64..5.0,
        e in -1.0_f64..1.0,
        exponent in -2.0_f64..3.0,
        omega in 0.5_f64..50.0,
        phase in -PI..PI,
        times in prop::collection::vec(0.0_f64..1.0, 3),
        moves in prop::collection::vec(-1.0_f64..1.0, 12),
        turns in -50_i32..50,
    ) {
        prop_assume!(e.abs() + r < 0.8 * l);
        let s = size(exponent);
        let (r, l, e) = (r * s, l * s, e * s);
        let scene = OffsetSlider { r, l, e, omega, phase, ..OffsetSlider::default() };
        let length = scene.l;
        for side in [1.0, -1.0] {
            let motion = exact::offset_slider(&scene, side);
            for &fraction in &times {
                let t = fraction * TAU / omega;
                let want = exact::at(&motion, t);
                let guess = guess_near(&scene, length, &want.q, (&moves, SPREAD), turns);
                let what = format!("offset slider {scene:?}, side {side}");
                check_instant(&what, &scene, length, t, &guess, &want);
            }
        }
    }

    #[test]
    fn piston_crank_is_the_circle_line_intersection_on_both_sides(
        radius in 20.0_f64..50.0,
        rod_pin in -50.0_f64..50.0,
        rod_length in 90.0_f64..150.0,
        pin in -30.0_f64..30.0,
        offset in -20.0_f64..20.0,
        exponent in -3.0_f64..2.0,
        omega in 1.0_f64..400.0,
        phase in -PI..PI,
        times in prop::collection::vec(0.0_f64..1.0, 3),
        moves in prop::collection::vec(-1.0_f64..1.0, 15),
        turns in -50_i32..50,
    ) {
        let s = size(exponent);
        let scene = PistonCrank {
            radius: radius * s,
            rod_pin: rod_pin * s,
            rod_length: rod_length * s,
            pin: pin * s,
            offset: offset * s,
            omega,
            phase,
            ..PistonCrank::default()
        };
        let length = scene.rod_pin.hypot(scene.rod_length);
        for side in [1.0, -1.0] {
            let motion = exact::piston_crank(&scene, side);
            for &fraction in &times {
                let t = fraction * TAU / omega;
                let want = exact::at(&motion, t);
                let guess = guess_near(&scene, length, &want.q, (&moves, SPREAD), turns);
                let what = format!("piston-crank {scene:?}, side {side}");
                check_instant(&what, &scene, length, t, &guess, &want);
            }
        }
    }

    #[test]
    fn collar_is_the_linear_solution(
        phase in -0.5_f64..0.5,
        swing in 0.0_f64..0.5,
        omega in 0.5_f64..20.0,
        reach in -3.0_f64..3.0,
        stroke in 0.0_f64..1.0,
        nu in 0.5_f64..20.0,
        exponent in -2.0_f64..3.0,
        times in prop::collection::vec(0.0_f64..1.0, 3),
        moves in prop::collection::vec(-1.0_f64..1.0, 9),
        turns in -50_i32..50,
    ) {
        let s = size(exponent);
        let (reach, stroke) = (reach * s, stroke * s);
        let scene = Collar { size: 4.0 * s, phase, swing, omega, reach, stroke, nu };
        let length = scene.size;
        let motion = exact::collar(&scene);
        for &fraction in &times {
            let t = fraction * TAU / omega;
            let want = exact::at(&motion, t);
            let guess = guess_near(&scene, length, &want.q, (&moves, SPREAD), turns);
            check_instant(&format!("collar {scene:?}"), &scene, length, t, &guess, &want);
        }
    }

    #[test]
    fn pushed_slider_is_the_circle_circle_intersection_on_both_branches(
        r in 0.5_f64..1.5,
        l in 2.0_f64..5.0,
        position in 0.15_f64..0.85,
        speed in -1.0_f64..1.0,
        exponent in -2.0_f64..3.0,
        moves in prop::collection::vec(-1.0_f64..1.0, 12),
        turns in -50_i32..50,
    ) {
        let s = size(exponent);
        // Between the dead centres l − r and l + r, clear of both.
        let start = (l - r + 2.0 * r * position) * s;
        let (r, l, speed) = (r * s, l * s, speed * s);
        let scene = PushedSlider { r, l, start, speed, ..PushedSlider::default() };
        let length = scene.l + scene.r;
        for sign in [1.0, -1.0] {
            let want = exact::at(exact::pushed_slider(&scene, sign), 0.0);
            let guess = guess_near(&scene, length, &want.q, (&moves, SPREAD / 3.0), turns);
            let what = format!("pushed slider {scene:?}, branch {sign}");
            check_instant(&what, &scene, length, 0.0, &guess, &want);
        }
    }
}

/// The class III group of the six-bar: its three binary links' angles and the ternary link's
/// pose.
const CLASS_III: [usize; 6] = [
    SixBar::LINK1_THETA,
    SixBar::LINK2_THETA,
    SixBar::LINK3_THETA,
    SixBar::TERNARY_X,
    SixBar::TERNARY_Y,
    SixBar::TERNARY_THETA,
];

#[test]
fn the_class_three_group_stays_a_newton_block_beside_a_closed_form_dyad() {
    let blocks = block_kinds(SIX_BAR);
    assert_eq!(blocks.len(), 2, "{blocks:?}");
    assert_eq!(blocks[0].0, None, "the class III group has no closed form");
    assert_eq!(sorted(blocks[0].1.clone()), sorted(CLASS_III.to_vec()));
    assert_eq!(blocks[1].0, Some(ClosedKind::CircleCircle), "the dyad");
    assert_eq!(
        sorted(blocks[1].1.clone()),
        sorted(vec![SixBar::ARM_THETA, SixBar::LEVER_THETA])
    );
}

/// The largest |Φ| of a scene at `q`, in scene lengths.
fn residual<M: Mechanism<Dim = Const<N>>, const N: usize>(
    scene: &M,
    length: f64,
    q: &[f64; N],
    t: f64,
) -> f64 {
    let mut phi = Vector::<Const<N>>::zeros();
    scene.phi(&Vector::<Const<N>>::from_column_slice(q), t, &mut phi);
    phi.amax() / length
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    #[test]
    fn the_six_bar_closes_its_loops_as_the_newton_path_does(
        omega in 0.5_f64..20.0,
        times in prop::collection::vec(0.0_f64..1.0, 4),
    ) {
        let scene = SixBar { omega, ..SixBar::default() };
        let length = 10.0;
        // Guesses from a run: the closed forms' answers at random instants, from the state
        // of the run before them.
        let steps = 48;
        let period = TAU / omega;
        let states = run(&scene, true, period, steps);
        for &fraction in &times {
            let k = (fraction * steps as f64) as usize;
            let t = period * (k + 1) as f64 / steps as f64;
            let closed = solve(&scene, true, t, &states[k].q).unwrap();
            let newton = solve(&scene, false, t, &states[k].q).unwrap();
            prop_assert_eq!(closed.closed_forms, 1, "the dyad alone, t = {}", t);
            prop_assert_eq!(newton.closed_forms, 0);
            let what = format!("six-bar, t = {t}");
            assert_within(&what, apart(&scene, length, &closed, &newton), ROUND_OFF);
            let phi = residual(&scene, length, &closed.q, t);
            prop_assert!(phi <= 1e-13, "Φ = {:e} scene lengths at t = {}", phi, t);
        }
    }
}

/// A run over `period` of a scene with one closed-form block, with closed forms on and off: the
/// same states to round-off, the closed-form path starting that block from its closed form at
/// every step and the Newton path never; each state of the run checked by `check`.
fn runs_agree<M, const N: usize>(
    what: &str,
    scene: &M,
    length: f64,
    period: f64,
    check: impl Fn(f64, &Solved<N>),
) where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    let steps = 90;
    let closed = run(scene, true, period, steps);
    let newton = run(scene, false, period, steps);
    for (k, (on, off)) in closed.iter().zip(&newton).enumerate() {
        let t = period * k as f64 / steps as f64;
        assert_eq!(on.closed_forms, 1, "{what}, step {k}");
        assert_eq!(off.closed_forms, 0, "{what}, step {k}");
        assert_within(
            &format!("{what}, step {k}"),
            apart(scene, length, on, off),
            ROUND_OFF,
        );
        check(t, on);
    }
}

/// [`runs_agree`] for a scene whose one block is its only one, each state also against the
/// exact motion and started on the root (one evaluation of the block verifies it).
fn runs_agree_with_exact<M, const N: usize>(
    what: &str,
    scene: &M,
    length: f64,
    period: f64,
    motion: impl Fn(exact::Dual) -> [exact::Dual; N],
) where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    runs_agree(what, scene, length, period, |t, state| {
        assert_eq!(state.evaluations, 1, "{what}, t = {t}");
        assert_within(
            &format!("{what}, t = {t}"),
            apart(scene, length, state, &exact::at(&motion, t)),
            ROUND_OFF,
        );
    });
}

/// Each scene assembled near each branch (its `near` guesses set from the exact motion, then
/// moved off it) and run over a turn of its drive.
#[test]
fn simulations_agree_with_closed_forms_on_and_off_on_both_branches() {
    for sign in [1.0, -1.0] {
        let mut scene = FourBar::default();
        let start = exact::at(exact::four_bar(&scene, sign), 0.0).q;
        scene.coupler_guess = start[FourBar::COUPLER_THETA] + 0.1;
        scene.rocker_guess = start[FourBar::ROCKER_THETA] - 0.1;
        let period = TAU / scene.omega;
        runs_agree_with_exact(
            &format!("four-bar, branch {sign}"),
            &scene,
            120.0,
            period,
            exact::four_bar(&scene, sign),
        );

        let mut scene = OffsetSlider::default();
        let start = exact::at(exact::offset_slider(&scene, sign), 0.0).q;
        scene.rod_guess = start[OffsetSlider::ROD_THETA] + 0.1;
        runs_agree_with_exact(
            &format!("offset slider, side {sign}"),
            &scene,
            80.0,
            TAU / scene.omega,
            exact::offset_slider(&scene, sign),
        );

        let mut scene = PistonCrank::default();
        let start = exact::at(exact::piston_crank(&scene, sign), 0.0).q;
        scene.rod_y_guess = start[PistonCrank::ROD_Y] + 2.0;
        scene.rod_guess = start[PistonCrank::ROD_THETA] - 0.1;
        runs_agree_with_exact(
            &format!("piston-crank, side {sign}"),
            &scene,
            scene.rod_pin.hypot(scene.rod_length),
            TAU / scene.omega,
            exact::piston_crank(&scene, sign),
        );
    }
    let scene = Collar::default();
    runs_agree_with_exact(
        "collar",
        &scene,
        4.0,
        TAU / scene.omega,
        exact::collar(&scene),
    );
    let scene = SixBar::default();
    runs_agree("six-bar", &scene, 10.0, TAU / scene.omega, |t, state| {
        let phi = residual(&scene, 10.0, &state.q, t);
        assert!(
            phi <= 1e-13,
            "six-bar: Φ = {phi:e} scene lengths at t = {t}"
        );
    });
}

/// A run of the generated scene and of the interpreter running its text, closed forms on: the
/// same closed-form starts and the same states.
fn interpreted_agrees<M, const N: usize>(
    what: &str,
    scene: &M,
    text: &str,
    length: f64,
    period: f64,
) where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    let generated = run(scene, true, period, 60);
    let interpreted = run_interpreted::<N>(text, true, period, 60);
    for (k, (g, i)) in generated.iter().zip(&interpreted).enumerate() {
        assert_eq!(g.closed_forms, i.closed_forms, "{what}, step {k}");
        assert_within(
            &format!("{what}, step {k}"),
            apart(scene, length, i, g),
            ROUND_OFF,
        );
    }
}

/// The interpreter follows the same plan, closed forms included, over a turn of each scene.
#[test]
fn the_interpreter_starts_from_the_same_closed_forms() {
    let four_bar = FourBar::default();
    interpreted_agrees("four-bar", &four_bar, FOUR_BAR, 120.0, TAU / four_bar.omega);
    let slider = OffsetSlider::default();
    interpreted_agrees(
        "offset slider",
        &slider,
        OFFSET_SLIDER,
        80.0,
        TAU / slider.omega,
    );
    let seed = PistonCrank::default();
    interpreted_agrees("piston-crank", &seed, PISTON_CRANK, 102.6, TAU / seed.omega);
    let collar = Collar::default();
    interpreted_agrees("collar", &collar, COLLAR, 4.0, TAU / collar.omega);
    let six_bar = SixBar::default();
    interpreted_agrees("six-bar", &six_bar, SIX_BAR, 10.0, TAU / six_bar.omega);
}
