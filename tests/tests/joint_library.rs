//! Every joint and driver kind of the spec language (revolute, prismatic, distance, slot, weld,
//! gear, rack; angle, relative angle, x, y, travel, distance and slide drivers), each in a small
//! scene whose exact motion is known in closed form, solved from generated code through the
//! runtime solver.
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

mechanism! {
    /// A Scotch yoke: the crank's pin runs in a vertical slot of a yoke that slides on the
    /// ground's x axis; an arm welded to the yoke at an angle; a pinion meshing with the yoke
    /// as its rack.
    mechanism Yoke {
        param a = 0.4;
        param w = 3.0;
        param b = 0.25;
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body yoke near (2, 0, 0);
        body arm near (2.5, 0.5, 0.3);
        body pinion near (0, 3, -3.8);
        joint pivot: revolute(frame, crank);
        joint guide: prismatic(frame, yoke, along (1, 0));
        joint pin: slot(yoke, crank @ (2, 0), along (0, 1));
        joint fixed: weld(yoke @ (0.5, 0.5), arm, angle 0.3);
        joint axle: revolute(frame @ (0, 3), pinion);
        joint teeth: rack(guide, pinion, ratio -0.5, phase 0.1);
        driver spin: angle(crank) = a * sin(w * t) + b * t^2;
    }
}

#[test]
fn slot_weld_and_rack() {
    check(Yoke::default(), |t| {
        let th = f(t);
        // The yoke follows the pin's x: 2 cos θ; the arm rides on it at (0.5, 0.5), turned 0.3;
        // the pinion turns by (x − 0.1) / −0.5.
        let (s, c) = th[0].sin_cos();
        let x = [
            2.0 * c,
            -2.0 * s * th[1],
            -2.0 * c * th[1] * th[1] - 2.0 * s * th[2],
        ];
        let pinion = x.map(|v| v / -0.5);
        let shift = |k: usize, offset: f64| if k == 0 { offset } else { 0.0 };
        let level = |k: usize| {
            [
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                th[k],
                x[k],
                0.0,
                0.0,
                x[k] + shift(k, 0.5),
                shift(k, 0.5),
                shift(k, 0.3),
                shift(k, 0.0),
                shift(k, 3.0),
                pinion[k] + shift(k, 0.1 / 0.5),
            ]
        };
        [level(0), level(1), level(2)]
    });
}

mechanism! {
    /// A boom hinged to the ground, raised by a linear actuator between a ground point and the
    /// boom: a distance driver.
    mechanism Boom {
        param a = 0.4;
        param w = 3.0;
        param b = 0.25;
        ground frame at (0, 0, 0);
        body boom near (0, 0, 0.5);
        joint hinge: revolute(frame, boom);
        driver ram: distance(frame @ (1, -1), boom @ (2, 0)) = 2 + a * sin(w * t) + b * t^2;
    }
}

#[test]
fn distance_driver_as_a_linear_actuator() {
    // |2 (cos θ, sin θ) − (1, −1)|² = L² gives cos θ − sin θ = (6 − L²)/4, so
    // θ = acos((6 − L²) / (4√2)) − π/4 on the upper branch.
    fn angle<D: DualNum<Primitive = f64> + Copy>(t: D) -> D {
        let length = (t * W).sin() * A + t * t * B + 2.0;
        ((-(length * length) + 6.0) / (4.0 * std::f64::consts::SQRT_2)).acos()
            - std::f64::consts::FRAC_PI_4
    }
    check(Boom::default(), |t| {
        let th: (f64, f64, f64) = second_derivative(angle, t);
        let th = [th.0, th.1, th.2];
        [
            [0.0, 0.0, 0.0, 0.0, 0.0, th[0]],
            [0.0, 0.0, 0.0, 0.0, 0.0, th[1]],
            [0.0, 0.0, 0.0, 0.0, 0.0, th[2]],
        ]
    });
}

mechanism! {
    /// A cart on a rail along (1, 0.5), positioned by the x travel of one of its points
    /// measured from a ground point: a slide driver along a line the joint does not define.
    mechanism Cart {
        param a = 0.4;
        param w = 3.0;
        param b = 0.25;
        ground frame at (0, 0, 0);
        body cart near (0, 0, 0);
        joint rail: prismatic(frame, cart, along (1, 0.5));
        driver push: slide(frame @ (0, 1), cart @ (0.2, 0), along (1, 0)) = a * sin(w * t) + b * t^2;
    }
}

#[test]
fn slide_driver_along_any_line() {
    // The cart moves s along û = (1, 0.5)/|…|; the driven travel is s û_x + 0.2 = f.
    let norm = 1.25f64.sqrt();
    let u = [1.0 / norm, 0.5 / norm];
    check(Cart::default(), |t| {
        let d = f(t);
        let level = |k: usize| {
            let s = if k == 0 {
                (d[0] - 0.2) / u[0]
            } else {
                d[k] / u[0]
            };
            [0.0, 0.0, 0.0, s * u[0], s * u[1], 0.0]
        };
        [level(0), level(1), level(2)]
    });
}

mechanism! {
    /// A planetary gear set: sun (30 teeth) and ring (90) on the frame's axis, one planet (30)
    /// on the carrier; the sun and the ring driven, the carrier follows.
    mechanism Planetary {
        param a = 0.4;
        param w = 3.0;
        param b = 0.25;
        ground frame at (0, 0, 0);
        body sun near (0, 0, 0);
        body carrier near (0, 0, 0);
        body planet near (60, 0, 0);
        body ring near (0, 0, 0);
        joint sun_axle: revolute(frame, sun);
        joint carrier_axle: revolute(frame, carrier);
        joint planet_axle: revolute(carrier @ (60, 0), planet);
        joint ring_axle: revolute(frame, ring);
        joint sun_planet: gear(sun, planet, ratio -1, carrier carrier);
        joint planet_ring: gear(planet, ring, ratio 30 / 90, carrier carrier);
        driver input: angle(sun) = a * sin(w * t) + b * t^2;
        driver brake: angle(ring) = 0.2 * t;
    }
}

#[test]
fn gear_pairs_on_a_carrier() {
    // Willis: (θ_s − θ_c) / (θ_r − θ_c) = −z_r / z_s = −3, so θ_c = (θ_s + 3 θ_r) / 4; the
    // planet turns by −(θ_s − θ_c) relative to the carrier.
    check(Planetary::default(), |t| {
        let (sun, ring) = (f(t), [0.2 * t, 0.2, 0.0]);
        let level = |k: usize| {
            let carrier = (sun[k] + 3.0 * ring[k]) / 4.0;
            let planet = carrier - (sun[k] - carrier);
            let (s, c) = if k == 0 {
                carrier.sin_cos()
            } else {
                (0.0, 0.0)
            };
            // The planet's centre is the carrier's point (60, 0); its rates from the carrier's.
            let w = (sun[1] + 3.0 * ring[1]) / 4.0;
            let alpha = (sun[2] + 3.0 * ring[2]) / 4.0;
            let (sin, cos) = ((sun[0] + 3.0 * ring[0]) / 4.0).sin_cos();
            let centre = match k {
                0 => [60.0 * c, 60.0 * s],
                1 => [-60.0 * sin * w, 60.0 * cos * w],
                _ => [
                    -60.0 * cos * w * w - 60.0 * sin * alpha,
                    -60.0 * sin * w * w + 60.0 * cos * alpha,
                ],
            };
            [
                0.0, 0.0, 0.0, 0.0, 0.0, sun[k], 0.0, 0.0, carrier, centre[0], centre[1], planet,
                0.0, 0.0, ring[k],
            ]
        };
        [level(0), level(1), level(2)]
    });
}
