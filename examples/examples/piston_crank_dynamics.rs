//! The seed piston-crank with its mass properties and gravity: one crank revolution in 360
//! steps, the driving torque and the crank-pin force beside the piston's motion, their errors
//! against the closed-form inverse dynamics, and what the force solve costs next to the
//! kinematic step (both timed in this run). Plot as SVG, optionally every step as CSV (its
//! force columns in the scene's units: kg·mm/s² = mN, kg·mm²/s² = µN·m).
//!
//! `cargo run --release --example piston_crank_dynamics -- [--csv PATH] [--svg PATH]`

use mechgen_examples::closed_form;
use mechgen_examples::demo::{self, Options};
use mechgen_examples::inverse_dynamics::{MassProperties, seed_reactions};
use mechgen_examples::plot::{Panel, Series};
use mechgen_examples::scenes::{
    PistonCrank, PistonCrankDynamics, PistonCrankDynamicsBodies, PistonCrankDynamicsForces,
};
use mechgen_runtime::State;

/// Scene units to SI for printing: kg·mm/s² → N, kg·mm²/s² → N·m.
const NEWTON: f64 = 1e-3;
const NEWTON_METRE: f64 = 1e-6;

fn main() {
    let options = Options::from_args("piston_crank_dynamics", std::env::args().skip(1))
        .unwrap_or_else(|e| {
            eprintln!("error: {e}");
            std::process::exit(2)
        });
    let scene = PistonCrankDynamics::default();
    let exact = closed_form::PistonCrank::default();
    let mass = MassProperties::default();
    let run = demo::revolution(scene, exact.period(), 360, |t| exact.kinematics(t))
        .unwrap_or_else(|e| demo::exit_with(&e, &scene));
    // The kinematic seed in the same run: what the force solve adds to a step.
    let kinematic = demo::revolution(PistonCrank::default(), exact.period(), 360, |t| {
        exact.kinematics(t)
    })
    .unwrap_or_else(|e| demo::exit_with(&e, &PistonCrank::default()));

    println!(
        "Seed piston-crank with masses and gravity, ω = {} rad/s, one revolution in 360 steps\n",
        scene.omega
    );
    println!(
        "{:>6} {:>12} {:>14} {:>14} {:>14}",
        "crank", "piston ẍ", "torque", "crank pin fx", "crank pin fy"
    );
    println!(
        "{:>6} {:>12} {:>14} {:>14} {:>14}",
        "(deg)", "(m/s²)", "(N·m)", "(N)", "(N)"
    );
    for state in run.states.iter().step_by(30) {
        let pin = state.reactions().crank_pin;
        println!(
            "{:>6.0} {:>12.1} {:>14.4} {:>14.2} {:>14.2}",
            state.crank().theta.to_degrees(),
            state.piston().x_ddot * 1e-3,
            state.efforts().crank_angle * NEWTON_METRE,
            pin.fx * NEWTON,
            pin.fy * NEWTON
        );
    }
    println!();
    print!("{}", run.summary());
    println!("{}", force_error(&run.states, &exact, &mass));
    println!(
        "force solve: {:.2} µs per step with forces against {:.2} µs for the kinematic seed \
         ({:.2}×, same run)",
        run.seconds_per_step * 1e6,
        kinematic.seconds_per_step * 1e6,
        run.seconds_per_step / kinematic.seconds_per_step
    );

    let angle = |s: &State<PistonCrankDynamics>| s.crank().theta.to_degrees();
    let series = |f: fn(&State<PistonCrankDynamics>) -> f64| -> Vec<(f64, f64)> {
        run.states.iter().map(|s| (angle(s), f(s))).collect()
    };
    let (x, a) = (
        series(|s| s.piston().x),
        series(|s| s.piston().x_ddot * 1e-3),
    );
    let torque = series(|s| s.efforts().crank_angle * NEWTON_METRE);
    let (fx, fy) = (
        series(|s| s.reactions().crank_pin.fx * NEWTON),
        series(|s| s.reactions().crank_pin.fy * NEWTON),
    );
    let panels = [
        Panel {
            y_label: "piston x (mm)",
            series: &[Series {
                name: "",
                points: &x,
            }],
        },
        Panel {
            y_label: "piston ẍ (m/s²)",
            series: &[Series {
                name: "",
                points: &a,
            }],
        },
        Panel {
            y_label: "driving torque (N·m)",
            series: &[Series {
                name: "",
                points: &torque,
            }],
        },
        Panel {
            y_label: "crank-pin force on the rod (N)",
            series: &[
                Series {
                    name: "fx",
                    points: &fx,
                },
                Series {
                    name: "fy",
                    points: &fy,
                },
            ],
        },
    ];
    let title = "Seed piston-crank: driving torque and crank-pin force over one revolution";
    run.write_outputs(&options, title, "crank angle (deg)", &panels);
}

/// The largest error of every reaction against the closed-form inverse dynamics, relative to
/// that reaction's largest magnitude over the revolution.
fn force_error(
    states: &[State<PistonCrankDynamics>],
    exact: &closed_form::PistonCrank,
    mass: &MassProperties,
) -> String {
    let reference: Vec<[f64; 15]> = states
        .iter()
        .map(|s| seed_reactions(exact, mass, &exact.kinematics(s.t)).in_equation_order())
        .collect();
    let worst = (0..15)
        .map(|k| {
            let scale = reference.iter().fold(1.0f64, |m, r| m.max(r[k].abs()));
            let error = states.iter().zip(&reference).fold(0.0f64, |m, (s, r)| {
                m.max((s.constraint_forces()[k] - r[k]).abs())
            });
            error / scale
        })
        .fold(0.0, f64::max);
    format!("max error of the reactions and driving torque vs closed form: {worst:.2e}")
}
