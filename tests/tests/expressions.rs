//! The expression language's functions and motion laws, each driving a dial's angle, against
//! exact values and derivatives written here: `atan2`, `asin`, `acos`, real powers, degrees and
//! `pi`, the kinks of `abs`, `min` and `max` (with their documented one-sided derivatives), the
//! cycloidal and 3-4-5 polynomial rise laws, and the natural cubic spline (through its knots,
//! C² continuous, straight beyond its ends).

use mechgen_runtime::{Simulation, Solver, mechanism};
use num_dual::{DualNum, second_derivative};

mechanism! {
    /// Dials on the frame, each turned by one expression of t.
    mechanism Dials {
        ground frame at (0, 0, 0);
        body arc near (0, 0, 0.5);
        body sine near (0, 0, 0);
        body cosine near (0, 0, 1.5);
        body power near (0, 0, 1);
        body degrees near (0, 0, 0.5);
        body kinks near (0, 0, 1);
        body cams near (0, 0, 0);
        body curve near (0, 0, 0);
        joint a1: revolute(frame, arc);
        joint a2: revolute(frame, sine);
        joint a3: revolute(frame, cosine);
        joint a4: revolute(frame, power);
        joint a5: revolute(frame, degrees);
        joint a6: revolute(frame, kinks);
        joint a7: revolute(frame, cams);
        joint a8: revolute(frame, curve);
        driver d1: angle(arc) = atan2(1 + t, 2 - t);
        driver d2: angle(sine) = asin(0.5 * sin(3 * t));
        driver d3: angle(cosine) = acos(0.3 * t);
        driver d4: angle(power) = (1 + t)^1.5;
        driver d5: angle(degrees) = 30deg + deg(10) * t + pi / 4 * t^2;
        driver d6: angle(kinks) = abs(t - 1) + min(t, 1.5 - t) + max(0.5 * t, 2 * t - 1);
        driver d7: angle(cams) = cycloidal(t / 1.5) + poly345(t - 0.5);
        driver d8: angle(curve) = spline(t, (0, 0), (0.5, 1), (1, 0.5), (1.5, 0.8));
    }
}

/// Value and first two derivatives.
type Rates = [f64; 3];

fn dual(f: impl Fn(num_dual::Dual2_64) -> num_dual::Dual2_64, t: f64) -> Rates {
    let (v, d, dd) = second_derivative(f, t);
    [v, d, dd]
}

/// `abs(x)` with slope +1 at 0, `min`/`max` following their first argument on a tie.
fn kinks(t: f64) -> Rates {
    let abs = if t - 1.0 >= 0.0 {
        [t - 1.0, 1.0]
    } else {
        [1.0 - t, -1.0]
    };
    let min = if t <= 1.5 - t {
        [t, 1.0]
    } else {
        [1.5 - t, -1.0]
    };
    let max = if 2.0 * t - 1.0 <= 0.5 * t {
        [0.5 * t, 0.5]
    } else {
        [2.0 * t - 1.0, 2.0]
    };
    [abs[0] + min[0] + max[0], abs[1] + min[1] + max[1], 0.0]
}

/// A rise law on u = (t − start)/span, held at 0 before and 1 after.
fn rise(t: f64, start: f64, span: f64, law: fn(f64) -> Rates) -> Rates {
    let u = (t - start) / span;
    if u <= 0.0 {
        [0.0; 3]
    } else if u <= 1.0 {
        let [v, d, dd] = law(u);
        [v, d / span, dd / (span * span)]
    } else {
        [1.0, 0.0, 0.0]
    }
}

fn cycloidal(u: f64) -> Rates {
    let w = std::f64::consts::TAU;
    [
        u - (w * u).sin() / w,
        1.0 - (w * u).cos(),
        w * (w * u).sin(),
    ]
}

fn poly345(u: f64) -> Rates {
    [
        u.powi(3) * (10.0 - 15.0 * u + 6.0 * u * u),
        30.0 * u * u * (1.0 - u).powi(2),
        60.0 * u * (1.0 - u) * (1.0 - 2.0 * u),
    ]
}

/// The natural cubic spline through (0, 0), (0.5, 1), (1, 0.5), (1.5, 0.8): with equal spacing
/// h the second derivatives at the inner knots solve M₀ + 4M₁ + M₂ = 6/h² Δ²y₁ and
/// M₁ + 4M₂ + M₃ = 6/h² Δ²y₂ with M₀ = M₃ = 0. Beyond the last knot it goes on straight.
fn spline(t: f64) -> Rates {
    const X: [f64; 4] = [0.0, 0.5, 1.0, 1.5];
    const Y: [f64; 4] = [0.0, 1.0, 0.5, 0.8];
    let h = 0.5;
    let r = [1, 2].map(|i| 6.0 / (h * h) * (Y[i + 1] - 2.0 * Y[i] + Y[i - 1]));
    let m1 = (4.0 * r[0] - r[1]) / 15.0;
    let m2 = (4.0 * r[1] - r[0]) / 15.0;
    let m = [0.0, m1, m2, 0.0];
    let piece = |i: usize, x: f64| -> Rates {
        let (a, b) = (X[i + 1] - x, x - X[i]);
        let (ca, cb) = (Y[i] / h - m[i] * h / 6.0, Y[i + 1] / h - m[i + 1] * h / 6.0);
        [
            m[i] * a.powi(3) / (6.0 * h) + m[i + 1] * b.powi(3) / (6.0 * h) + ca * a + cb * b,
            -m[i] * a * a / (2.0 * h) + m[i + 1] * b * b / (2.0 * h) - ca + cb,
            m[i] * a / h + m[i + 1] * b / h,
        ]
    };
    if t > X[3] {
        let [v, d, _] = piece(2, X[3]);
        return [v + d * (t - X[3]), d, 0.0];
    }
    let i = X.windows(2).position(|w| t <= w[1]).unwrap_or(2);
    piece(i, t)
}

/// Each dial's exact angle and rates at t.
fn exact(t: f64) -> [Rates; 8] {
    [
        // atan2(y, x) with y = 1 + t, x = 2 − t: θ' = 3 / (x² + y²) (through x = 0 at t = 2).
        {
            let r2 = (1.0 + t).powi(2) + (2.0 - t).powi(2);
            [
                (1.0 + t).atan2(2.0 - t),
                3.0 / r2,
                -3.0 * (4.0 * t - 2.0) / (r2 * r2),
            ]
        },
        dual(|t| ((t * 3.0).sin() * 0.5).asin(), t),
        dual(|t| (t * 0.3).acos(), t),
        dual(|t| (t + 1.0).powf(1.5), t),
        dual(
            |t| t * t * std::f64::consts::FRAC_PI_4 + t * 10f64.to_radians() + 30f64.to_radians(),
            t,
        ),
        kinks(t),
        {
            let (a, b) = (rise(t, 0.0, 1.5, cycloidal), rise(t, 0.5, 1.0, poly345));
            [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
        },
        spline(t),
    ]
}

#[test]
fn every_function_and_law_matches_its_exact_value_and_rates() {
    let mut simulation = Simulation::new(Solver::new(Dials::default()), 0.0).expect("assembles");
    simulation
        .run(2.0, 200, |state| {
            let reference = exact(state.t);
            for (dial, r) in reference.iter().enumerate() {
                let k = 3 * (dial + 1) + 2;
                let solved = [state.q[k], state.qd()[k], state.qdd()[k]];
                for level in 0..3 {
                    let error = (solved[level] - r[level]).abs() / r[level].abs().max(1.0);
                    assert!(
                        error <= 1e-10,
                        "dial {} at t = {}: level {level} {} vs {}",
                        dial + 1,
                        state.t,
                        solved[level],
                        r[level]
                    );
                }
            }
        })
        .expect("solves every step");
}

#[test]
fn the_spline_is_twice_continuously_differentiable_through_its_knots() {
    let mut solver = Solver::new(Dials::default());
    let mut state = solver
        .solve(0.0, &Default::default())
        .expect("assembles at t = 0");
    let curve = 3 * 8 + 2;
    let mut at = |t: f64| {
        solver.solve_into(t, &mut state).expect("solves");
        [state.q[curve], state.qd()[curve], state.qdd()[curve]]
    };
    // Through its knots, with natural (zero-curvature) ends.
    for (x, y) in [(0.0, 0.0), (0.5, 1.0), (1.0, 0.5), (1.5, 0.8)] {
        assert!((at(x)[0] - y).abs() <= 1e-14, "knot ({x}, {y})");
    }
    assert!(at(0.0)[2].abs() <= 1e-12 && at(1.5)[2].abs() <= 1e-12);
    // Value, slope and curvature agree on both sides of each inner knot (to the step's order).
    let e = 1e-9;
    for x in [0.5, 1.0] {
        let (left, right) = (at(x - e), at(x + e));
        for level in 0..3 {
            assert!(
                (left[level] - right[level]).abs() <= 1e-6,
                "jump in derivative {level} at {x}: {} vs {}",
                left[level],
                right[level]
            );
        }
    }
    // Beyond the last knot: straight, with the end slope.
    let (end, beyond) = (at(1.5), at(1.9));
    assert!((beyond[0] - (end[0] + 0.4 * end[1])).abs() <= 1e-12);
    assert!(beyond[2] == 0.0 && (beyond[1] - end[1]).abs() <= 1e-12);
}

/// The hand-written rates of the piecewise references agree with their differences (dual
/// numbers differentiate the others).
#[test]
fn the_exact_rates_are_consistent_with_differences() {
    fn check(f: impl Fn(f64) -> Rates, t: f64) {
        let h = 1e-5;
        let [v, d, dd] = f(t);
        let (plus, minus) = (f(t + h), f(t - h));
        assert!(((plus[0] - minus[0]) / (2.0 * h) - d).abs() < 1e-6 * d.abs().max(1.0));
        assert!(((plus[1] - minus[1]) / (2.0 * h) - dd).abs() < 1e-5 * dd.abs().max(1.0));
        assert!(v.is_finite());
    }
    for t in [0.3, 0.8, 1.2, 1.7] {
        check(|t| rise(t, 0.0, 1.5, cycloidal), t);
        check(|t| rise(t, 0.5, 1.0, poly345), t);
        check(spline, t);
    }
}
