//! Hoeken's straight-line linkage: one crank revolution in 720 steps from generated code, the
//! tracer marker's path (the coupler curve) plotted, and its straightness over the half turn
//! from 90° to 270° against the closed form, beside the error and cost of the solve.
//!
//! `cargo run --release --example hoeken -- [--csv PATH] [--svg PATH]`

use mechgen_examples::closed_form::FourBar;
use mechgen_examples::demo::{self, Options};
use mechgen_examples::plot::{Panel, Series};
use mechgen_examples::scenes::{Hoeken, HoekenBodies};

fn main() {
    let options = Options::from_args("hoeken", std::env::args().skip(1)).unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(2)
    });
    let scene = Hoeken::default();
    // Hoeken's proportions: crank 1, coupler 2.5 (extended to 5), rocker 2.5, frame 2.
    let exact = FourBar {
        crank: 1.0,
        coupler: 2.5,
        rocker: 2.5,
        ground: 2.0,
        omega: scene.omega,
    };
    let run = demo::revolution(scene, exact.period(), 720, |t| exact.kinematics(t))
        .unwrap_or_else(|e| demo::exit_with(&e, &scene));

    println!("Hoeken straight-line linkage, one crank revolution in 720 steps\n");
    println!(
        "{:>6} {:>10} {:>10} {:>10} {:>10} {:>14}",
        "crank", "tracer x", "tracer y", "ẋ", "ẏ", "transmission"
    );
    for state in run.states.iter().step_by(60) {
        let p = state.tracer();
        println!(
            "{:>6.0} {:>10.5} {:>10.5} {:>10.5} {:>10.5} {:>13.1}°",
            state.crank().theta.to_degrees(),
            p.x,
            p.y,
            p.x_dot,
            p.y_dot,
            state.transmission().angle.to_degrees()
        );
    }

    // The straight run: crank from 90° to 270°.
    let straight: Vec<_> = run
        .states
        .iter()
        .filter(|s| (90.0..=270.0).contains(&s.crank().theta.to_degrees()))
        .map(|s| s.tracer())
        .collect();
    let deviation = straight
        .iter()
        .fold(0.0f64, |m, p| m.max((p.y - 4.0).abs()));
    let (low, high) = straight.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
        (lo.min(p.x), hi.max(p.x))
    });
    let speeds: Vec<f64> = straight.iter().map(|p| p.x_dot.hypot(p.y_dot)).collect();
    let mean = speeds.iter().sum::<f64>() / speeds.len() as f64;
    let spread = speeds.iter().fold(0.0f64, |m, v| m.max((v - mean).abs())) / mean;
    println!(
        "\nstraight run (crank 90°–270°): stroke {:.6}, largest deviation from y = 4 {:.6} \
         crank lengths ({:.3} % of the stroke; closed form 0.009754), speed {:.4} ± {:.1} %",
        high - low,
        deviation,
        100.0 * deviation / (high - low),
        mean,
        100.0 * spread
    );
    print!("\n{}", run.summary());

    let curve: Vec<(f64, f64)> = run
        .states
        .iter()
        .map(|s| (s.tracer().x, s.tracer().y))
        .collect();
    let line: Vec<(f64, f64)> = straight.iter().map(|p| (p.x, p.y)).collect();
    let panels = [Panel {
        y_label: "tracer y (crank lengths)",
        series: &[
            Series {
                name: "coupler curve",
                points: &curve,
            },
            Series {
                name: "crank 90°–270°",
                points: &line,
            },
        ],
    }];
    let title = "Hoeken linkage: the tracer's path over one crank revolution";
    run.write_outputs(&options, title, "tracer x (crank lengths)", &panels);
}
