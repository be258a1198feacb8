//! Every joint and driver kind of the spec language, each in a small scene whose exact motion is
//! known in closed form, solved from generated code through the runtime solver.
//!
//! The driven value is f(t) = A sin(ω t) + B t² throughout, with exact derivatives, so velocity
//! and acceleration right-hand sides (ν, and γ including Φ_tt) are checked, not only positions.

use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{Simulation, Solver, mechanism};
use num_dual::{DualNum, second_derivative};

const A: f64 = 0.4;
const W: f64 = 3.0;
const B: f64 = 0.25;

/// f, f', f'' of the driver value shared by every scene.
fn f(t: f64) -> [f64; 3] {
    [
        A * (W * t).sin() + B * t * t,
        A * W * (W * t).cos() + 2.0 * B * t,
        -A * W * W * (W * t).sin() + 2.0 * B,
    ]
}

mechanism! {
    /// A slider on a ground rail along (1, 1), driven by its travel.
    mechanism Rail {
        param a = 0.4;
        param w = 3.0;
        param b = 0.25;
        ground frame at (1, 2, 0.3);
        body slider near (1, 2, 0.3);
        joint slide: prismatic(frame @ (0, 0), slider, along (1, 1));
        driver travel: travel(slide) = a * sin(w * t) + b * t^2;
    }
}

mechanism! {
    /// A crank driven by its angle carrying a rod driven relative to it.
    mechanism Arm {
        param a = 0.4;
        param w = 3.0;
        param b = 0.25;
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0.1);
        body rod near (2, 0, 0.1);
        joint shoulder: revolute(frame, crank);
        joint elbow: revolute(crank @ (2, 0), rod);
        driver lift: angle(crank) = 0.5 * t;
        driver bend: relative_angle(crank, rod) = a * sin(w * t) + b * t^2;
    }
}

mechanism! {
    /// A block sliding on the ground's x axis, driven through a point's x; a second block on
    /// the y axis driven through a point's y.
    mechanism Blocks {
        param a = 0.4;
        param w = 3.0;
        param b = 0.25;
        ground frame at (0, 0, 0);
        body horizontal near (0.1, 0, 0);
        body vertical near (0, 0.1, 0);
        joint rail_x: prismatic(frame, horizontal, along (1, 0));
        joint rail_y: prismatic(frame, vertical, along (0, 1));
        driver push_x: x(horizontal @ (0.5, 0)) = a * sin(w * t) + b * t^2;
        driver push_y: y(vertical @ (0, -0.5)) = a * sin(w * t) + b * t^2;
    }
}

mechanism! {
    /// A slider-crank whose connecting rod is a distance link: the crank turns by f(t), the
    /// slider follows on the ground's x axis.
    mechanism DistanceRod {
        param a = 0.4;
        param w = 3.0;
        param b = 0.25;
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body slider near (4, 0, 0);
        joint pivot: revolute(frame, crank);
        joint guide: prismatic(frame, slider, along (1, 0));
        joint rod: distance(crank @ (1, 0), slider @ (-0.5, 0), 3);
        driver spin: angle(crank) = a * sin(w * t) + b * t^2;
    }
}

/// Solves 200 steps over [0, 2] and compares q, q̇, q̈ with `exact` (each relative to its
/// largest magnitude, as everywhere in the project).
fn check<M, const N: usize>(mechanism: M, exact: impl Fn(f64) -> [[f64; N]; 3])
where
    M: mechgen_runtime::Structured<Dim = Const<N>> + mechgen_runtime::Accelerations,
{
    let mut simulation = Simulation::new(Solver::new(mechanism), 0.0).expect("assembles");
    let (mut error, mut scale) = ([0.0f64; 3], [0.0f64; 3]);
    simulation
        .run(2.0, 200, |state| {
            let reference = exact(state.t);
            for (k, solved) in [&state.q, state.qd(), state.qdd()].into_iter().enumerate() {
                for (s, r) in solved.iter().zip(reference[k]) {
                    error[k] = error[k].max((s - r).abs());
                    scale[k] = scale[k].max(r.abs());
                }
            }
        })
        .expect("solves every step");
    for k in 0..3 {
        assert!(
            error[k] <= 1e-10 * scale[k].max(1e-300),
            "quantity {k}: error {:e} at scale {:e}",
            error[k],
            scale[k]
        );
    }
}

#[test]
fn prismatic_travel_driver() {
    let u = std::f64::consts::FRAC_1_SQRT_2;
    // The rail's axis (1, 1) is in the frame's coordinates, which are rotated by 0.3.
    let (s, c) = 0.3f64.sin_cos();
    let axis = [u * (c - s), u * (s + c)];
    check(Rail::default(), |t| {
        let d = f(t);
        let body = |k: usize, base: [f64; 2]| [base[0] + axis[0] * d[k], base[1] + axis[1] * d[k]];
        let [p, v, a] = [
            body(0, [1.0, 2.0]),
            body(1, [0.0, 0.0]),
            body(2, [0.0, 0.0]),
        ];
        [
            [1.0, 2.0, 0.3, p[0], p[1], 0.3],
            [0.0, 0.0, 0.0, v[0], v[1], 0.0],
            [0.0, 0.0, 0.0, a[0], a[1], 0.0],
        ]
    });
}

#[test]
fn revolute_chain_with_absolute_and_relative_angle_drivers() {
    check(Arm::default(), |t| {
        let th1 = [0.5 * t, 0.5, 0.0];
        let g = f(t);
        let th2 = [th1[0] + g[0], th1[1] + g[1], th1[2] + g[2]];
        // The rod's reference point is the crank tip: 2 (cos θ1, sin θ1).
        let (s, c) = th1[0].sin_cos();
        let (w, dw) = (th1[1], th1[2]);
        let tip = [2.0 * c, 2.0 * s];
        let tip_d = [-2.0 * s * w, 2.0 * c * w];
        let tip_dd = [
            -2.0 * c * w * w - 2.0 * s * dw,
            -2.0 * s * w * w + 2.0 * c * dw,
        ];
        [
            [0.0, 0.0, 0.0, 0.0, 0.0, th1[0], tip[0], tip[1], th2[0]],
            [0.0, 0.0, 0.0, 0.0, 0.0, th1[1], tip_d[0], tip_d[1], th2[1]],
            [
                0.0, 0.0, 0.0, 0.0, 0.0, th1[2], tip_dd[0], tip_dd[1], th2[2],
            ],
        ]
    });
}

#[test]
fn point_coordinate_drivers() {
    check(Blocks::default(), |t| {
        let d = f(t);
        // x(horizontal @ (0.5, 0)) = f ⇒ horizontal.x = f − 0.5; likewise vertical.y = f + 0.5.
        [
            [0.0, 0.0, 0.0, d[0] - 0.5, 0.0, 0.0, 0.0, d[0] + 0.5, 0.0],
            [0.0, 0.0, 0.0, d[1], 0.0, 0.0, 0.0, d[1], 0.0],
            [0.0, 0.0, 0.0, d[2], 0.0, 0.0, 0.0, d[2], 0.0],
        ]
    });
}

#[test]
fn distance_joint_as_a_connecting_rod() {
    // Slider reference x = P_x + sqrt(L² − P_y²) + 0.5 with P = (cos f, sin f), differentiated
    // exactly with second-order dual numbers.
    fn slider_x<D: DualNum<Primitive = f64> + Copy>(t: D) -> D {
        let angle = (t * W).sin() * A + t * t * B;
        let (py, px) = (angle.sin(), angle.cos());
        px + (-(py * py) + 9.0).sqrt() + 0.5
    }
    check(DistanceRod::default(), |t| {
        let (x, xd, xdd) = second_derivative(slider_x, t);
        let th = f(t);
        [
            [0.0, 0.0, 0.0, 0.0, 0.0, th[0], x, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, th[1], xd, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, th[2], xdd, 0.0, 0.0],
        ]
    });
}
