//! The free seed: the piston-crank with its mass properties, its crank released from rest at
//! 0.3 rad and moving under gravity alone (forward dynamics). The error-controlled integrator
//! runs the 0.5 s release; its crank angle and speed are compared with the reduced
//! one-coordinate Lagrange equation integrated here to 1e-12 (`FreeSeed`), the energy balance
//! shows what the integration loses, and the run is timed. Plot of crank angle, crank speed and
//! energy against time as SVG, optionally every output as CSV.
//!
//! `cargo run --release --example piston_crank_free -- [--csv PATH] [--svg PATH]`

use std::fmt::Write as _;
use std::time::Instant;

use mechgen_examples::demo::Options;
use mechgen_examples::free_seed::FreeSeed;
use mechgen_examples::plot::{self, Panel, Series};
use mechgen_examples::scenes::{PistonCrankFree, PistonCrankFreeBodies};
use mechgen_runtime::{Energy, Integrator, IntegratorOptions, Solver, State};

/// The release's length (s) and the spacing of the outputs (s).
const T_END: f64 = 0.5;
const OUTPUTS: usize = 100;

/// One output: the state and the energy book at its time.
struct Sample {
    state: State<PistonCrankFree>,
    energy: Energy,
}

fn main() {
    let options =
        Options::from_args("piston_crank_free", std::env::args().skip(1)).unwrap_or_else(|e| {
            eprintln!("error: {e}");
            std::process::exit(2)
        });
    let times: Vec<f64> = (0..=OUTPUTS)
        .map(|k| T_END * k as f64 / OUTPUTS as f64)
        .collect();
    let (samples, seconds, stats) = release(&times);
    let reference = FreeSeed::default().release([0.3, 0.0], &times, 1e-5);

    println!("Free seed: the crank released from rest at 0.3 rad under gravity, {T_END} s\n");
    println!(
        "{:>6} {:>12} {:>12} {:>14} {:>12}",
        "t", "crank", "crank speed", "energy total", "|Δφ| vs ref"
    );
    println!(
        "{:>6} {:>12} {:>12} {:>14} {:>12}",
        "(s)", "(rad)", "(rad/s)", "(µJ)", "(rad)"
    );
    for (s, r) in samples.iter().zip(&reference).step_by(10) {
        let crank = s.state.crank();
        println!(
            "{:>6.2} {:>12.6} {:>12.4} {:>14.6} {:>12.2e}",
            s.state.t,
            crank.theta,
            crank.theta_dot,
            s.energy.total(),
            (crank.theta - r[0]).abs()
        );
    }
    println!("\n{}", summary(&samples, &reference, seconds, &stats));

    let series = |f: &dyn Fn(&Sample) -> f64| -> Vec<(f64, f64)> {
        samples.iter().map(|s| (s.state.t, f(s))).collect()
    };
    let angle = series(&|s| s.state.crank().theta);
    let speed = series(&|s| s.state.crank().theta_dot);
    let kinetic = series(&|s| s.energy.kinetic * 1e-6);
    let potential = series(&|s| s.energy.gravity * 1e-6);
    let total = series(&|s| s.energy.total() * 1e-6);
    let panels = [
        Panel {
            y_label: "crank angle (rad)",
            series: &[Series {
                name: "",
                points: &angle,
            }],
        },
        Panel {
            y_label: "crank speed (rad/s)",
            series: &[Series {
                name: "",
                points: &speed,
            }],
        },
        Panel {
            y_label: "energy (J)",
            series: &[
                Series {
                    name: "kinetic",
                    points: &kinetic,
                },
                Series {
                    name: "gravity",
                    points: &potential,
                },
                Series {
                    name: "total",
                    points: &total,
                },
            ],
        },
    ];
    let title = "Free seed: crank released at 0.3 rad under gravity";
    if let Err(e) = write(&options, title, &panels, &samples) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

/// The release at the default (error-controlled) options, output onto each of `times`:
/// the samples, the fastest of three runs' seconds, and that run's statistics.
fn release(times: &[f64]) -> (Vec<Sample>, f64, mechgen_runtime::IntegratorStats) {
    let mut best = None;
    for _ in 0..3 {
        let start = Instant::now();
        let mut integrator = Integrator::new(
            Solver::new(PistonCrankFree::default()),
            0.0,
            IntegratorOptions::default(),
        )
        .unwrap_or_else(|e| exit_with(&e));
        let mut samples = Vec::with_capacity(times.len());
        for &t in times {
            if t > integrator.t() {
                integrator.step_to(t).unwrap_or_else(|e| exit_with(&e));
            }
            samples.push(Sample {
                state: integrator.state().clone(),
                energy: integrator.energy(),
            });
        }
        let seconds = start.elapsed().as_secs_f64();
        if best.as_ref().is_none_or(|(_, s, _)| seconds < *s) {
            best = Some((samples, seconds, integrator.stats()));
        }
    }
    best.expect("three runs")
}

/// Accuracy against the reference, energy drift and cost, in one paragraph.
fn summary(
    samples: &[Sample],
    reference: &[[f64; 2]],
    seconds: f64,
    stats: &mechgen_runtime::IntegratorStats,
) -> String {
    let worst = |f: &dyn Fn(&Sample, &[f64; 2]) -> f64| {
        samples
            .iter()
            .zip(reference)
            .map(|(s, r)| f(s, r))
            .fold(0.0f64, f64::max)
    };
    let angle = worst(&|s, r| (s.state.crank().theta - r[0]).abs());
    let speed = worst(&|s, r| (s.state.crank().theta_dot - r[1]).abs());
    let e0 = samples[0].energy.total();
    let drift = worst(&|s, _| (s.energy.total() - e0).abs()) / e0.abs().max(1e-300);
    let mut text = String::new();
    let _ = writeln!(
        text,
        "against the reduced Lagrange equation: crank angle within {angle:.1e} rad, speed within \
         {speed:.1e} rad/s; energy total drifts by {drift:.1e} relative"
    );
    let _ = write!(
        text,
        "cost: {:.2} ms for {} steps ({} rejected, {} Newton iterations), {:.2} µs per step",
        seconds * 1e3,
        stats.steps,
        stats.rejected,
        stats.iterations,
        seconds * 1e6 / stats.steps.max(1) as f64
    );
    text
}

/// The plot and, when asked, the CSV (the state's columns, then the energies).
fn write(
    options: &Options,
    title: &str,
    panels: &[Panel<'_>],
    samples: &[Sample],
) -> Result<(), String> {
    plot::write_svg(&options.svg, title, "time (s)", panels).map_err(|e| {
        format!(
            "writing the plot {}: {e}\n  hint: give a writable path with `--svg PATH`",
            options.svg.display()
        )
    })?;
    println!("plot: {}", options.svg.display());
    if let Some(path) = &options.csv {
        let mut text = String::new();
        let header = |text: &mut String| -> std::fmt::Result {
            mechgen_runtime::write_csv_header(&PistonCrankFree::default(), text)?;
            // The header ends its line; the energies go on the same line.
            text.pop();
            writeln!(text, ",kinetic,gravity,total")
        };
        let rows = |text: &mut String| -> std::fmt::Result {
            header(text)?;
            for s in samples {
                s.state.write_csv_row(text)?;
                text.pop();
                writeln!(
                    text,
                    ",{},{},{}",
                    s.energy.kinetic,
                    s.energy.gravity,
                    s.energy.total()
                )?;
            }
            Ok(())
        };
        rows(&mut text).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("writing {}: {e}", path.display()))?;
        println!("csv: {} ({} rows)", path.display(), samples.len());
    }
    Ok(())
}

/// Prints a failure in the scene's names and exits with status 1.
fn exit_with(error: &mechgen_runtime::DynamicsError) -> ! {
    let scene = PistonCrankFree::default();
    eprintln!("error: {}", error.describe(&scene));
    std::process::exit(1)
}
