//! What a scene does not need is not generated: checked on the expanded tokens of the example
//! scenes, and by solving the positions-only scene against its closed form.

use mechgen_examples::scenes::{OffsetSlider, OffsetSliderBodies};
use mechgen_runtime::{Mechanism, Outputs, Simulation, Solver};

fn scene_source(file: &str) -> String {
    let path = format!("{}/../examples/scenes/{file}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn expanded(file: &str) -> String {
    let tokens: proc_macro2::TokenStream = scene_source(file).parse().expect("lexes");
    mechgen::expand(mechgen::Input::Tokens(tokens), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{file}: {e}"))
        .to_string()
}

/// Identifiers of the token stream outside string literals (doc comments), for exact-word
/// searches.
fn words(code: &str) -> Vec<String> {
    let mut outside = String::new();
    let mut in_string = false;
    let mut escaped = false;
    for c in code.chars() {
        match (in_string, escaped, c) {
            (true, false, '\\') => escaped = true,
            (true, false, '"') | (false, _, '"') => in_string = !in_string,
            (true, _, _) => escaped = false,
            (false, _, c) => outside.push(c),
        }
    }
    outside
        .split(|c: char| !(c.is_alphanumeric() || c == '_'))
        .filter(|w| !w.is_empty())
        .map(str::to_owned)
        .collect()
}

#[test]
fn a_positions_only_scene_has_no_velocity_or_acceleration_code() {
    let code = expanded("offset_slider.mech");
    let words = words(&code);
    for absent in [
        "Velocities",
        "Accelerations",
        "nu",
        "gamma",
        "qd",
        "qdd",
        "solve_velocities",
        "x_dot",
        "x_ddot",
    ] {
        assert!(!words.iter().any(|w| w == absent), "`{absent}` generated");
    }
    assert!(words.iter().any(|w| w == "phi_and_jacobian"));
}

#[test]
fn a_time_free_scene_reads_no_time() {
    // The driver is a parameter: Φ has no `t` and nothing reads it (`_t` arguments only).
    let code = expanded("offset_slider.mech");
    assert!(!words(&code).iter().any(|w| w == "t"), "`t` read");
}

#[test]
fn the_full_scenes_keep_every_output() {
    let words = words(&expanded("piston_crank.mech"));
    for present in ["Velocities", "Accelerations", "nu", "gamma"] {
        assert!(words.iter().any(|w| w == present), "`{present}` missing");
    }
}

/// The force solve's items, which only a scene that computes forces gets.
const FORCE_ITEMS: [&str; 10] = [
    "Forces",
    "generalized_forces",
    "reactions",
    "reaction_name",
    "REACTIONS",
    "assign_multipliers",
    "force_rhs",
    "lambda",
    "PistonCrankForces",
    "constraint_forces",
];

#[test]
fn a_scene_without_masses_or_loads_has_no_force_code() {
    let words = words(&expanded("piston_crank.mech"));
    for absent in FORCE_ITEMS {
        assert!(!words.iter().any(|w| w == absent), "`{absent}` generated");
    }
    // Its workspace has no force storage: the type is the one without the sixth size.
    let code = expanded("piston_crank.mech").replace(' ', "");
    assert!(
        code.contains("Buffers<2,4,4,15,4>"),
        "workspace type changed"
    );
}

#[test]
fn masses_without_the_forces_output_generate_no_force_code() {
    let source = scene_source("piston_crank_dynamics.mech").replace(
        "gravity (0, -9810);",
        "gravity (0, -9810);\n    outputs positions, velocities, accelerations;",
    );
    let tokens: proc_macro2::TokenStream = source.parse().expect("lexes");
    let code = mechgen::expand(mechgen::Input::Tokens(tokens), &mechgen::Options::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let words = words(&code.to_string());
    for absent in FORCE_ITEMS {
        assert!(!words.iter().any(|w| w == absent), "`{absent}` generated");
    }
    // Declared masses default to the forces output.
    let words = self::words(&expanded("piston_crank_dynamics.mech"));
    for present in [
        "Forces",
        "generalized_forces",
        "force_rhs",
        "assign_multipliers",
    ] {
        assert!(words.iter().any(|w| w == present), "`{present}` missing");
    }
}

#[test]
fn ground_bodies_contribute_no_trigonometry() {
    // The seed's grounds are `liner` and `bearing`: no sin/cos of their angles anywhere.
    let code = expanded("piston_crank.mech");
    for ground in ["liner_theta", "bearing_theta"] {
        for f in ["sin", "cos"] {
            let name = format!("{f}_{ground}");
            assert!(!words(&code).contains(&name), "{name} computed");
        }
    }
}

#[test]
fn each_angle_has_at_most_one_sin_and_cos_per_function() {
    let code = expanded("piston_crank.mech");
    // Every function body sits between `fn name (` and the next `fn `.
    for body in code.split(" fn ").skip(1) {
        let words = words(body);
        for angle in ["piston_theta", "rod_theta", "crank_theta"] {
            for f in ["sin", "cos"] {
                let name = format!("{f}_{angle}");
                let bindings = words
                    .windows(2)
                    .filter(|w| w[0] == "let" && w[1].starts_with(&name))
                    .count();
                assert!(
                    bindings <= 1,
                    "{name} bound {bindings} times in `fn {}`",
                    &body[..40.min(body.len())]
                );
            }
        }
    }
}

#[test]
fn no_identically_zero_jacobian_entry_is_stored() {
    for file in ["piston_crank.mech", "four_bar.mech", "offset_slider.mech"] {
        let scene = mechgen::compile(
            mechgen::Input::Text(&scene_source(file)),
            &mechgen::Options::default(),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        for entry in &scene.kinematics.jacobian {
            assert!(
                !scene.model.arena.is_zero(entry.value),
                "{file}: zero at {entry:?}"
            );
        }
    }
}

#[test]
fn positions_only_scene_solves_to_its_closed_form() {
    let mut simulation =
        Simulation::new(Solver::new(OffsetSlider::default()), 0.0).expect("assembles");
    assert_eq!(simulation.state().outputs(), Outputs::Positions);
    for k in 0..=72 {
        let angle = f64::from(k) * std::f64::consts::TAU / 72.0;
        simulation
            .solver_mut()
            .mechanism_mut()
            .set_parameter("crank_angle", angle)
            .expect("declared");
        let state = simulation.step_to(f64::from(k)).expect("solves");
        // Crank pin P = 30 (cos a, sin a); slider pin on y = 12 at 80 from P, +x branch.
        let (px, py) = (30.0 * angle.cos(), 30.0 * angle.sin());
        let x = px + (80.0f64 * 80.0 - (12.0 - py) * (12.0 - py)).sqrt();
        let slider = state.slider();
        assert!(
            (slider.x - x).abs() <= 1e-10 * 110.0,
            "angle {angle}: {} vs {x}",
            slider.x
        );
        assert!((slider.y - 12.0).abs() <= 1e-10 * 110.0);
    }
}
