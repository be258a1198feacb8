//! The runtime's safeguards, each held by a test that fails when the safeguard is removed (each
//! checked by applying the removal by hand): crawl detection, the condition estimate of blocks
//! larger than 4, the jump test, and the static pivots' check; and unit scaling, whose scales a
//! solver keeps between solves, follows a change of length scale.

use mechgen_examples::scenes::PistonCrank;
use mechgen_examples::stability::SliderCrank;
use mechgen_runtime::nalgebra::{Const, DMatrix};
use mechgen_runtime::{
    Dense, Mechanism, Simulation, SolveError, Solver, SolverOptions, Unit, Vector,
};

/// The slider-crank whose rod equals its crank: a double root (toggle) at t = π/2.
fn isosceles() -> SliderCrank {
    SliderCrank {
        l: 1.0,
        ..SliderCrank::default()
    }
}

#[test]
fn newton_crawling_into_a_toggle_is_singular_with_infinite_condition() {
    // Solved directly at the toggle from states before it: Newton converges linearly into the
    // double root. Crawl detection names it after three crawling corrections, with κ = ∞ (no
    // condition is estimated at a point Newton never reached); without it, Newton would crawl
    // to the iteration cap and report the finite, merely large estimate there (~1e8–1e9).
    let toggle = core::f64::consts::FRAC_PI_2;
    let mut solver = Solver::new(isosceles());
    for before in [0.3, 0.1, 0.01, 1e-3] {
        let simulation = Simulation::new(Solver::new(isosceles()), toggle - before).unwrap();
        let error = solver.solve(toggle, &simulation.state().q).unwrap_err();
        let SolveError::Singular {
            time,
            condition,
            deficiency,
            ..
        } = error
        else {
            panic!("{before}: {error:?}");
        };
        assert_eq!((time, deficiency), (toggle, 1), "{error:?}");
        assert!(condition.is_infinite(), "from {before} before: {error:?}");
    }
}

/// κ₁ of the unit-scaled Φ_q of `m` at `q` (rows over L^unit, columns times L^unit, L the power
/// of two below the length scale, as the solver scales), from its explicit inverse.
fn exact_condition<M: Mechanism<Dim = Const<N>>, const N: usize>(
    m: &M,
    q: &Vector<Const<N>>,
    t: f64,
) -> f64 {
    let mut jacobian = mechgen_runtime::Matrix::<Const<N>>::zeros();
    m.jacobian(q, t, &mut jacobian);
    let length = 2f64.powi(m.length_scale().log2().floor() as i32);
    let power = |unit: Unit| match unit {
        Unit::Angle => 0,
        Unit::Length => 1,
        Unit::Area => 2,
    };
    let scaled = DMatrix::from_fn(N, N, |i, j| {
        let exponent = power(m.coordinate_unit(j)) - power(m.equation_unit(i));
        jacobian[(i, j)] * length.powi(exponent)
    });
    let one_norm = |a: &DMatrix<f64>| {
        a.column_iter()
            .map(|c| c.iter().map(|x| x.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    let inverse = scaled.clone().try_inverse().expect("regular");
    one_norm(&scaled) * one_norm(&inverse)
}

#[test]
fn the_condition_estimate_of_a_large_block_tracks_the_exact_condition() {
    // The dense reference solves every equation as one block (12 × 12), whose condition is
    // estimated (Hager–Higham), not computed. Approaching the toggle, κ grows like 1/distance;
    // the estimate matches it at every step, and the solution where it passes `max_condition`
    // is refused as Singular (with that finite estimate: Newton converged there).
    let toggle = core::f64::consts::FRAC_PI_2;
    let mut simulation = Simulation::new(Solver::new(Dense::new(isosceles())), 0.0).unwrap();
    let (mut checked, mut refused) = (0, false);
    for k in 1..=24 {
        let t = toggle - 0.5f64.powi(2 * k);
        match simulation.step_to(t) {
            Ok(_) => {
                let state = simulation.state();
                let exact = exact_condition(simulation.solver().mechanism(), &state.q, t);
                let estimate = state.condition;
                // Hager–Higham's estimate is a lower bound; on this block it attains κ₁.
                assert!(
                    (estimate - exact).abs() <= 1e-9 * exact,
                    "t = toggle − {:e}: estimate {estimate:e}, exact {exact:e}",
                    toggle - t
                );
                checked += 1;
            }
            Err(error) => {
                // Refused by the limit on the estimate at a converged solution: finite, above
                // `max_condition`.
                let SolveError::Singular { condition, .. } = error else {
                    panic!("{error:?}");
                };
                assert!(condition > 1e8 && condition.is_finite(), "{error:?}");
                refused = true;
                break;
            }
        }
    }
    assert!(checked >= 6 && refused, "{checked} {refused}");
}

mechgen_runtime::mechanism! {
    /// A two-link arm whose tip is driven around a circle of radius `r` about the shoulder
    /// (as in `structured.rs`): every entry of its coupled block changes sign as it turns.
    mechanism CircleArm {
        param r = 1.5;
        param w = 1.0;
        ground base at (0, 0, 0);
        body upper near (0, 0, -0.515);
        body fore near (0.870, -0.493, 0.664);
        joint shoulder: revolute(base, upper);
        joint elbow: revolute(upper @ (1, 0), fore);
        driver tip_x: x(fore @ (0.8, 0)) = r * cos(w * t);
        driver tip_y: y(fore @ (0.8, 0)) = r * sin(w * t);
        /// The elbow bends anticlockwise.
        branch elbow_up: cross(upper -> upper @ (1, 0), fore -> fore @ (0.8, 0)) > 0;
    }
}

/// The arm's exact state at time `t` (w = 1): the upper link turns at 1 rad/s, steadily.
fn arm_exact(t: f64) -> [f64; 9] {
    let (l1, l2, r) = (1.0f64, 0.8f64, 1.5f64);
    let elbow = ((r * r - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)).acos();
    let offset = (l2 * elbow.sin()).atan2(l1 + l2 * elbow.cos());
    let upper = t - offset;
    let fore = upper + elbow;
    [
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        upper,
        upper.cos() * l1,
        upper.sin() * l1,
        fore,
    ]
}

#[test]
fn a_static_pivot_is_checked_where_an_unchecked_one_gives_wrong_rates() {
    // Where the upper link stands vertical (θ = π/2 + kπ) a pivot of the block's static order
    // (chosen at the guess) is cos θ, which rounds to ~1e-16 instead of vanishing. Checked, the
    // block falls back to partial pivoting and the rates are exact (θ̇ = 1, θ̈ = 0); unchecked
    // (any non-zero pivot and any multiplier accepted), the elimination divides by the rounding
    // error and θ̇ is off by percents, though the positions still converge.
    let (l1, l2, r) = (1.0f64, 0.8f64, 1.5f64);
    let elbow = ((r * r - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)).acos();
    let offset = (l2 * elbow.sin()).atan2(l1 + l2 * elbow.cos());
    let unchecked = SolverOptions {
        static_pivot_threshold: 0.0,
        pivot_tolerance: 0.0,
        ..SolverOptions::default()
    };
    for k in [1, 3, 5, 7] {
        let t = k as f64 * core::f64::consts::FRAC_PI_2 + offset;
        let exact = Vector::<Const<9>>::from_column_slice(&arm_exact(t));
        let solve = |options| {
            Solver::with_options(CircleArm::default(), options)
                .solve(t, &exact)
                .unwrap()
        };
        let checked = solve(SolverOptions::default());
        assert!((checked.q - exact).amax() <= 1e-14, "{k}");
        assert!(
            (checked.qd()[5] - 1.0).abs() <= 1e-14,
            "{k}: {}",
            checked.qd()[5]
        );
        assert!(checked.qdd()[5].abs() <= 1e-14, "{k}: {}", checked.qdd()[5]);
        assert_eq!(checked.fallbacks, 1, "{k}");

        let wrong = solve(unchecked);
        assert!((wrong.q - exact).amax() <= 1e-14, "{k}");
        assert!((wrong.qd()[5] - 1.0).abs() > 1e-3, "{k}: {}", wrong.qd()[5]);
        assert_eq!(wrong.fallbacks, 0, "{k}");
    }
}

/// A solver keeps its blocks' unit scales between solves: switched between scaled and
/// unscaled units, it solves as a new solver with those options does, to the bit (the seed's
/// block condition differs with and without scaling, so stale scales would show).
#[test]
fn kept_unit_scales_follow_a_change_of_length_scale() {
    let seed = PistonCrank::default();
    let scaled = SolverOptions::default();
    let unscaled = SolverOptions {
        scale_units: false,
        ..scaled
    };
    let simulation = Simulation::new(Solver::with_options(seed, scaled), 0.0).expect("assembles");
    let start = simulation.state().clone();
    let mut reused = simulation.into_solver();
    let mut conditions = Vec::new();
    for (k, options) in [unscaled, scaled, unscaled, scaled].into_iter().enumerate() {
        let t = 1e-3 * (k + 1) as f64;
        reused.set_options(options);
        let mut kept = start.clone();
        reused.solve_into(t, &mut kept).expect("solves");
        let mut fresh = start.clone();
        Solver::with_options(seed, options)
            .solve_into(t, &mut fresh)
            .expect("solves");
        assert_eq!(kept.q, fresh.q, "positions at step {k}");
        assert_eq!(kept.qdd(), fresh.qdd(), "accelerations at step {k}");
        assert_eq!(
            kept.condition.to_bits(),
            fresh.condition.to_bits(),
            "step {k}"
        );
        conditions.push(kept.condition);
    }
    assert_ne!(
        conditions[0], conditions[1],
        "scaling changes the block's condition"
    );
}
