//! The seed piston-crank: one crank revolution in 360 steps from generated code, a short table,
//! the error against the closed form, and an SVG plot (optionally every step as CSV).
//!
//! `cargo run --release --example piston_crank -- [--csv PATH] [--svg PATH]`

use mechgen_examples::closed_form;
use mechgen_examples::demo::{self, Options};
use mechgen_examples::plot::{Panel, Series};
use mechgen_examples::scenes::{PistonCrank, PistonCrankBodies};

fn main() {
    let options =
        Options::from_args("piston_crank", std::env::args().skip(1)).unwrap_or_else(|e| {
            eprintln!("error: {e}");
            std::process::exit(2)
        });
    let scene = PistonCrank::default();
    let exact = closed_form::PistonCrank::default();
    let run = demo::revolution(scene, exact.period(), 360, |t| exact.kinematics(t))
        .unwrap_or_else(|e| demo::exit_with(&e, &scene));

    println!(
        "Seed piston-crank, ω = {} rad/s, one revolution in 360 steps\n",
        scene.omega
    );
    println!(
        "{:>6} {:>14} {:>14} {:>16}",
        "crank", "piston x", "piston ẋ", "piston ẍ"
    );
    println!(
        "{:>6} {:>14} {:>14} {:>16}",
        "(deg)", "(mm)", "(mm/s)", "(mm/s²)"
    );
    for state in run.states.iter().step_by(30) {
        let piston = state.piston();
        let crank = state.crank().theta.to_degrees();
        println!(
            "{crank:>6.0} {:>14.6} {:>14.3} {:>16.1}",
            piston.x, piston.x_dot, piston.x_ddot
        );
    }
    println!();
    print!("{}", run.summary());

    let angle = |s: &mechgen_runtime::State<PistonCrank>| s.crank().theta.to_degrees();
    let series = |f: fn(&mechgen_runtime::State<PistonCrank>) -> f64| -> Vec<(f64, f64)> {
        run.states.iter().map(|s| (angle(s), f(s))).collect()
    };
    let (x, v, a) = (
        series(|s| s.piston().x),
        series(|s| s.piston().x_dot),
        series(|s| s.piston().x_ddot),
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
            y_label: "piston ẋ (mm/s)",
            series: &[Series {
                name: "",
                points: &v,
            }],
        },
        Panel {
            y_label: "piston ẍ (mm/s²)",
            series: &[Series {
                name: "",
                points: &a,
            }],
        },
    ];
    let title = "Seed piston-crank: piston motion over one crank revolution";
    run.write_outputs(&options, title, "crank angle (deg)", &panels);
}
