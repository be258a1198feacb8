//! A planetary gear set with its ring fixed: the sun driven at ω, the carrier's speed against
//! Willis' formula, and the hypocycloid a tooth of the planet rolls out, plotted.
//!
//! `cargo run --release --example planetary -- [--csv PATH] [--svg PATH]`

use mechgen_examples::demo::Options;
use mechgen_examples::plot::{self, Panel, Series};
use mechgen_examples::scenes::{Planetary, PlanetaryBodies};
use mechgen_runtime::{Simulation, Solver, State};

/// Teeth of the sun, planet and ring.
const TEETH: (f64, f64, f64) = (24.0, 24.0, 72.0);

fn main() {
    let options = Options::from_args("planetary", std::env::args().skip(1)).unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(2)
    });
    let scene = Planetary::default();
    // One turn of the carrier: four of the sun.
    let (z_sun, z_planet, z_ring) = TEETH;
    let willis = z_sun / (z_sun + z_ring);
    let period = std::f64::consts::TAU / (scene.omega * willis);
    let mut states: Vec<State<Planetary>> = Vec::new();
    let mut simulation = Simulation::new(Solver::new(scene), 0.0).unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(1)
    });
    if let Err(e) = simulation.run(period, 720, |state| states.push(state.clone())) {
        eprintln!("error: {}", e.describe(&scene));
        std::process::exit(1);
    }

    let ratio = |s: &State<Planetary>| s.carrier().theta_dot / s.sun().theta_dot;
    let worst = states
        .iter()
        .fold(0.0f64, |m, s| m.max((ratio(s) - willis).abs() / willis));
    let planet = willis - z_sun / z_planet * (1.0 - willis);
    println!(
        "Planetary gear set, ring fixed: sun {z_sun}, planet {z_planet}, ring {z_ring} teeth, \
         sun at {} rad/s\n",
        scene.omega
    );
    println!(
        "carrier / sun speed: {:.15} (Willis: z_s / (z_s + z_r) = {willis}), largest relative \
         difference over one carrier turn {worst:.1e}",
        ratio(&states[0])
    );
    println!(
        "planet / sun speed:  {:.15} (Willis: {planet})",
        states[0].planet().theta_dot / scene.omega
    );

    let tooth: Vec<(f64, f64)> = states.iter().map(|s| (s.tooth().x, s.tooth().y)).collect();
    let panels = [Panel {
        y_label: "y (mm)",
        series: &[Series {
            name: "tooth on the planet's pitch circle",
            points: &tooth,
        }],
    }];
    let title = "Planetary gear set: a planet tooth over one carrier turn (a hypocycloid)";
    match plot::write_svg(&options.svg, title, "x (mm)", &panels) {
        Ok(()) => println!("plot: {}", options.svg.display()),
        Err(e) => {
            eprintln!("error: writing the plot {}: {e}", options.svg.display());
            std::process::exit(1);
        }
    }
    if let Some(path) = &options.csv {
        let mut text = String::new();
        let written = mechgen_runtime::write_csv_header(&Planetary::default(), &mut text)
            .and_then(|()| states.iter().try_for_each(|s| s.write_csv_row(&mut text)));
        match written
            .map_err(|e| e.to_string())
            .and_then(|()| std::fs::write(path, text).map_err(|e| e.to_string()))
        {
            Ok(()) => println!("csv: {} ({} rows)", path.display(), states.len()),
            Err(e) => {
                eprintln!("error: writing {}: {e}", path.display());
                std::process::exit(1);
            }
        }
    }
}
