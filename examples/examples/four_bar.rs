//! A crank-rocker four-bar: one crank revolution in 360 steps from generated code, a short
//! table, the error against the closed form, and an SVG plot (optionally every step as CSV).
//!
//! `cargo run --release --example four_bar -- [--csv PATH] [--svg PATH]`

use mechgen_examples::closed_form;
use mechgen_examples::demo::{self, Options};
use mechgen_examples::plot::{Panel, Series};
use mechgen_examples::scenes::{FourBar, FourBarBodies};
use mechgen_runtime::State;

fn main() {
    let options = Options::from_args("four_bar", std::env::args().skip(1)).unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(2)
    });
    let scene = FourBar::default();
    let exact = closed_form::FourBar::default();
    let run = demo::revolution(scene, exact.period(), 360, |t| exact.kinematics(t))
        .unwrap_or_else(|e| demo::exit_with(&e, &scene));

    println!(
        "Crank-rocker four-bar, ω = {} rad/s, one revolution in 360 steps\n",
        scene.omega
    );
    println!(
        "{:>6} {:>12} {:>14} {:>16}",
        "crank", "rocker θ", "rocker θ̇", "rocker θ̈"
    );
    println!(
        "{:>6} {:>12} {:>14} {:>16}",
        "(deg)", "(deg)", "(rad/s)", "(rad/s²)"
    );
    for state in run.states.iter().step_by(30) {
        let rocker = state.rocker();
        println!(
            "{:>6.0} {:>12.6} {:>14.6} {:>16.4}",
            state.crank().theta.to_degrees(),
            rocker.theta.to_degrees(),
            rocker.theta_dot,
            rocker.theta_ddot
        );
    }
    println!();
    print!("{}", run.summary());

    let series = |f: fn(&State<FourBar>) -> f64| -> Vec<(f64, f64)> {
        run.states
            .iter()
            .map(|s| (s.crank().theta.to_degrees(), f(s)))
            .collect()
    };
    let (th, w, a) = (
        series(|s| s.rocker().theta.to_degrees()),
        series(|s| s.rocker().theta_dot),
        series(|s| s.rocker().theta_ddot),
    );
    let panels = [
        Panel {
            y_label: "rocker θ (deg)",
            series: &[Series {
                name: "",
                points: &th,
            }],
        },
        Panel {
            y_label: "rocker θ̇ (rad/s)",
            series: &[Series {
                name: "",
                points: &w,
            }],
        },
        Panel {
            y_label: "rocker θ̈ (rad/s²)",
            series: &[Series {
                name: "",
                points: &a,
            }],
        },
    ];
    let title = "Crank-rocker four-bar: rocker motion over one crank revolution";
    run.write_outputs(&options, title, "crank angle (deg)", &panels);
}
