//! Near, at and beyond toggles: slider-cranks pushed by their slider to their dead centres, a
//! non-Grashof four-bar and an offset slider-crank driven by the crank to the limit of its
//! swing. Where the closed-form path and the Newton path (`closed_forms: false`) succeed they
//! agree (to the conditioning of the toggle) and match the exact motion; where one fails the
//! other fails with the same error; beyond the limit both fail, never with a NaN success or a
//! panic.

use core::f64::consts::FRAC_PI_2;

use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{Accelerations, Simulation, SolveError, Solver, Structured};
use mechgen_tests::toggle_times;
use proptest::prelude::*;

use super::compare::{Solved, apart, assert_same_error, assert_within, options, solve};
use super::exact::{self, Exact};
use super::scenes::{FourBar, OffsetSlider, PushedSlider};

/// How far from a toggle, relative to the scene's lengths or in radians of the drive, "near"
/// is: where both paths must succeed, the first with the two solutions far enough apart for
/// the closed form to start Newton; and where the Newton path may already fail (its pivots
/// then read the toggle's).
const NEAR: [f64; 3] = [1e-4, 1e-6, 1e-9];

/// Agreement near a toggle, where the half-angle α between the branches is about √NEAR and
/// Newton, which stops on its tolerances (1e-10), places q to about 1e-10 α and q̇, q̈ to about
/// 1e-10 / α relative (the branches differ by α in q and entirely in q̇).
const NEAR_TOLERANCE: [f64; 3] = [1e-9, 1e-5, 1e-5];

/// Agreement with the exact motion where the closed form starts Newton on the root, at the
/// first distance: q to round-off, q̇ and q̈ to ε / α² relative.
const STARTED_TOLERANCE: [f64; 3] = [1e-12, 1e-10, 1e-10];

/// Where the loop cannot close, far enough that the limit's rounding cannot matter.
const BEYOND: f64 = 1e-3;

/// Solves an instant both ways: where both succeed they agree with each other and with `want`
/// (if given), where both fail they fail alike; one failing alone fails the test. Returns
/// both solutions if they succeeded.
fn alike<M, const N: usize>(
    what: &str,
    scene: &M,
    length: f64,
    t: f64,
    guess: &[f64; N],
    want: Option<&Exact<N>>,
) -> Option<[Solved<N>; 2]>
where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    let closed = solve(scene, true, t, guess);
    let newton = solve(scene, false, t, guess);
    let (Ok(a), Ok(b)) = (closed.clone(), newton.clone()) else {
        assert_same_error(what, &closed, &newton);
        return None;
    };
    assert_within(
        &format!("{what}: closed forms vs Newton"),
        apart(scene, length, &a, &b),
        NEAR_TOLERANCE,
    );
    if let Some(want) = want {
        assert_within(
            &format!("{what}: closed forms vs exact"),
            apart(scene, length, &a, want),
            NEAR_TOLERANCE,
        );
    }
    Some([a, b])
}

/// Near a toggle, at each distance of [`NEAR`] (`at(distance)` the scene, the time and the
/// exact motion there), from `far` and from a guess as a step towards the toggle would predict
/// it (the solution at twice the distance): both paths alike, both succeeding at the first two
/// distances, and at the first the closed form starting Newton on the root (one evaluation).
fn near<M, const N: usize>(
    what: &str,
    length: f64,
    far: &[f64; N],
    at: impl Fn(f64) -> (M, f64, Exact<N>),
) where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    for (k, distance) in NEAR.into_iter().enumerate() {
        let (scene, t, want) = at(distance);
        let close = at(2.0 * distance).2.q;
        for (j, guess) in [&close, far].into_iter().enumerate() {
            let from = ["a close guess", "a far guess"][j];
            let what = format!("{what}, {distance} from the toggle, from {from}");
            let solved = alike(&what, &scene, length, t, guess, Some(&want));
            assert!(solved.is_some() || k == 2, "{what}: both paths fail");
            if let (0, 0, Some([closed, _])) = (k, j, &solved) {
                assert_eq!((closed.closed_forms, closed.evaluations), (1, 1), "{what}");
                assert_within(
                    &what,
                    apart(&scene, length, closed, &want),
                    STARTED_TOLERANCE,
                );
            }
        }
    }
}

/// Exactly at a toggle: both paths succeed and agree, or both fail with the same error.
fn at<M, const N: usize>(what: &str, scene: &M, length: f64, t: f64, guess: &[f64; N])
where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    alike(what, scene, length, t, guess, None);
}

/// Beyond the limit: both paths fail, with the same error.
fn beyond<M, const N: usize>(what: &str, scene: &M, t: f64, guess: &[f64; N])
where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    let closed: Result<Solved<N>, SolveError> = solve(scene, true, t, guess);
    let newton = solve(scene, false, t, guess);
    assert_same_error(what, &closed, &newton);
}

/// A scene driven to its `limit` (time) along the exact `motion` of one branch: [`near`] it
/// from a guess 0.05 before, [`at`] it, and [`beyond`] it, just and by [`BEYOND`].
fn to_the_limit<M, const N: usize>(
    what: &str,
    scene: &M,
    length: f64,
    limit: f64,
    motion: impl Fn(exact::Dual) -> [exact::Dual; N],
) where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    let guess = exact::at(&motion, limit - 0.05).q;
    near(what, length, &guess, |distance| {
        (
            scene.clone(),
            limit - distance,
            exact::at(&motion, limit - distance),
        )
    });
    at(&format!("{what}, at"), scene, length, limit, &guess);
    beyond(
        &format!("{what}, just beyond"),
        scene,
        limit + NEAR[2],
        &guess,
    );
    beyond(&format!("{what}, beyond"), scene, limit + BEYOND, &guess);
}

proptest! {
    // Failures are not persisted: proptest finds no crate root beside a submodule's file.
    #![proptest_config(ProptestConfig {
        cases: 24,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Lengths in whole units of a power of two, so that the dead centres r + l and l − r are
    /// exact and the loop closes there exactly (a zero discriminant, not a rounded one).
    #[test]
    fn a_slider_pushed_to_dead_centre_fails_and_succeeds_as_newton_does(
        r_units in 4_u32..16,
        extra in 2_u32..48,
        power in -6_i32..10,
        outer in any::<bool>(),
    ) {
        let unit = 2f64.powi(power);
        let (r, l) = (f64::from(r_units) * unit, f64::from(r_units + extra) * unit);
        // Towards the dead centre, from inside the range.
        let (centre, inward) = if outer { (r + l, -1.0) } else { (l - r, 1.0) };
        let length = r + l;
        let scene = |start: f64| PushedSlider { r, l, start, speed: r, ..PushedSlider::default() };
        for sign in [1.0, -1.0] {
            let what = format!("r = {r}, l = {l}, dead centre {centre}, branch {sign}");
            let far = scene(centre + inward * 0.02 * r);
            let guess = exact::at(exact::pushed_slider(&far, sign), 0.0).q;
            near(&what, length, &guess, |distance| {
                let close = scene(centre + inward * distance * length);
                let want = exact::at(exact::pushed_slider(&close, sign), 0.0);
                (close, 0.0, want)
            });
            at(&format!("{what}, at"), &scene(centre), length, 0.0, &guess);
            for (past, how) in [(NEAR[2], "just beyond"), (BEYOND, "beyond")] {
                let past = scene(centre - inward * past * length);
                beyond(&format!("{what}, {how}"), &past, 0.0, &guess);
            }
        }
    }

    /// A non-Grashof four-bar (its crank a rocker) driven to the crank angle where coupler and
    /// rocker line up.
    #[test]
    fn a_four_bar_driven_to_its_limit_fails_and_succeeds_as_newton_does(
        a in 1.5_f64..2.5,
        b in 2.7_f64..3.3,
        c in 3.2_f64..3.8,
        d in 4.5_f64..5.5,
        exponent in -2.0_f64..3.0,
    ) {
        prop_assume!(d + a > b + c + 0.3);
        let s = 10f64.powf(exponent);
        let (a, b, c, d) = (a * s, b * s, c * s, d * s);
        let scene = FourBar { a, b, c, d, omega: 1.0, phase: 0.0, ..FourBar::default() };
        let length = scene.d + scene.a;
        let limit = ((a * a + d * d - (b + c) * (b + c)) / (2.0 * a * d)).acos();
        for sign in [1.0, -1.0] {
            let what = format!("{scene:?}, limit {limit}, branch {sign}");
            to_the_limit(&what, &scene, length, limit, exact::four_bar(&scene, sign));
        }
    }

    /// An offset slider-crank whose crank is longer than rod and offset together, driven to
    /// the crank angle where the rod stands across the guide.
    #[test]
    fn an_offset_slider_driven_to_its_limit_fails_and_succeeds_as_newton_does(
        r in 1.8_f64..2.2,
        l in 0.8_f64..1.2,
        e in 0.0_f64..0.3,
        exponent in -2.0_f64..3.0,
    ) {
        let s = 10f64.powf(exponent);
        let (r, l, e) = (r * s, l * s, e * s);
        let scene = OffsetSlider { r, l, e, omega: 1.0, phase: 0.0, ..OffsetSlider::default() };
        let length = scene.r + scene.l;
        let limit = ((e + l) / r).asin();
        for side in [1.0, -1.0] {
            let what = format!("{scene:?}, limit {limit}, side {side}");
            to_the_limit(&what, &scene, length, limit, exact::offset_slider(&scene, side));
        }
    }
}

/// An offset slider-crank whose rod just reaches across the guide with the crank upright
/// (e − r = −l, sin(π/2) rounding to 1 exactly): both branches touch at a zero discriminant.
#[test]
fn an_offset_slider_exactly_at_its_touching_point_fails_as_newton_does() {
    for power in [-6, 0, 9] {
        let unit = 2f64.powi(power);
        let scene = OffsetSlider {
            r: 2.0 * unit,
            l: unit,
            e: unit,
            omega: 1.0,
            phase: FRAC_PI_2,
            ..OffsetSlider::default()
        };
        for side in [1.0, -1.0] {
            let guess = exact::at(exact::offset_slider(&scene, side), -0.05).q;
            let what = format!("unit {unit}, side {side}");
            at(&what, &scene, 3.0 * unit, 0.0, &guess);
        }
    }
}

/// Steps a `Simulation` of `scene` through `times`, closed forms on and off, towards a toggle
/// at `toggle` it cannot pass: both stop in the same step with the same error, located within
/// a step of the toggle, after the same states. (Where the crossing's bisection meets a
/// `Singular` solve it reports that midpoint: the two paths, whose midpoint solves differ in
/// the last bits, may report different midpoints of the same step.)
fn stops_alike<M, const N: usize>(what: &str, scene: &M, length: f64, toggle: f64, times: &[f64])
where
    M: Structured<Dim = Const<N>> + Accelerations + Clone,
{
    let outcome = |closed_forms: bool| {
        let solver = Solver::with_options(scene.clone(), options(closed_forms));
        let mut simulation = Simulation::new(solver, 0.0).expect("assembles at t = 0");
        let mut states = Vec::new();
        for &t in times {
            match simulation.step_to(t) {
                Ok(state) => states.push(state.q),
                Err(error) => return (states, error),
            }
        }
        panic!("{what}: stepped through the toggle at {toggle}");
    };
    let (closed, closed_error) = outcome(true);
    let (newton, newton_error) = outcome(false);
    assert_same_error(what, &Err::<(), _>(closed_error), &Err(newton_error));
    let (a, b) = (closed_error.time().unwrap(), newton_error.time().unwrap());
    let longest = times
        .windows(2)
        .map(|w| w[1] - w[0])
        .fold(times[0], f64::max);
    assert!(
        (a - toggle).abs() <= longest && (b - toggle).abs() <= longest,
        "{what}: closed forms stop at {a}, Newton at {b}, the toggle is at {toggle}"
    );
    assert_eq!(closed.len(), newton.len(), "{what}");
    for (x, y) in closed.iter().zip(&newton) {
        assert!((x - y).amax() <= 1e-12 * length, "{what}: {x} vs {y}");
    }
}

proptest! {
    // Failures are not persisted: proptest finds no crate root beside a submodule's file.
    #![proptest_config(ProptestConfig {
        cases: 16,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// The slider pushed through its outer dead centre.
    #[test]
    fn a_simulation_pushed_through_dead_centre_stops_as_newton_does(
        steps in 3_usize..40,
        fractions in prop::collection::vec(0.3_f64..1.7, 1..6),
        land in any::<bool>(),
    ) {
        let scene = PushedSlider::default();
        let dead_centre = (scene.r + scene.l - scene.start) / scene.speed;
        let times = toggle_times(dead_centre, dead_centre / steps as f64, &fractions, land);
        stops_alike("pushed slider", &scene, scene.r + scene.l, dead_centre, &times);
    }

    /// A parallelogram four-bar turned into its change point (all links in line at a crank
    /// angle of π), where its parallelogram and anti-parallelogram branches cross: a closed-form
    /// start on the merged root must not hide it.
    #[test]
    fn a_simulation_through_a_change_point_stops_as_newton_does(
        crank in 0.3_f64..3.0,
        ratio in 1.2_f64..4.0,
        omega in 0.5_f64..20.0,
        steps in 4_usize..60,
        fractions in prop::collection::vec(0.3_f64..1.7, 1..6),
        land in any::<bool>(),
    ) {
        let frame = crank * ratio;
        let scene = FourBar {
            a: crank,
            b: frame,
            c: crank,
            d: frame,
            omega,
            phase: 0.5,
            coupler_guess: 0.0,
            rocker_guess: 0.5,
        };
        let change_point = (core::f64::consts::PI - 0.5) / omega;
        let times = toggle_times(change_point, change_point / steps as f64, &fractions, land);
        stops_alike("change-point four-bar", &scene, frame + crank, change_point, &times);
    }
}
