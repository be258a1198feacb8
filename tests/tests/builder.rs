//! Scenes assembled with `mechgen::builder`: the seed rebuilt in code generates exactly the code
//! of its `.mech` file, and scissor lifts of several sizes (the `mechgen-scissor` example's
//! scene, built here without its build script) solve to their closed form through the
//! interpreter and the runtime solver.

// The scissor crate's scene and geometry, compiled into this test (the scene finds the
// geometry at `crate::geometry`).
#[allow(dead_code)]
#[path = "../../examples/scissor/src/geometry.rs"]
mod geometry;
#[path = "../../examples/scissor/scene.rs"]
mod scene;

use mechgen::CodegenOptions;
use mechgen::builder::{Product, SceneBuilder, Sign};
use mechgen_interp::Interpreted;
use mechgen_runtime::{Mechanism, Solver};

#[test]
fn the_seed_built_in_code_generates_the_same_code_as_its_file() {
    let mut seed = SceneBuilder::new("PistonCrank");
    seed.doc(
        "Piston-crank of a boxer engine: the seed mechanism (5 bodies, 15 coordinates, mm, rad, s).",
    )
    .doc("")
    .doc("The crank turns at `omega`; the connecting rod drives the piston along the liner's x axis.");
    seed.param("omega", 314.0).item_doc("Crank speed (rad/s).");
    seed.ground("liner", [156.8, 0.0, 0.0])
        .item_doc("Cylinder liner (fixed).");
    seed.body("piston", [130.0, 0.0, 0.0])
        .item_doc("Piston, sliding in the liner.");
    seed.body("rod", [29.0, 72.0, -2.35])
        .item_doc("Connecting rod.");
    seed.body("crank", [0.0, 0.0, 0.0]).item_doc("Crank shaft.");
    seed.ground("bearing", [0.0, 0.0, 0.0])
        .item_doc("Crank bearing (fixed).");
    seed.revolute("crank_pin", ("rod", [41.3, 0.0]), ("crank", [0.0, 43.0]));
    seed.revolute(
        "piston_pin",
        ("piston", [-28.0, 0.0]),
        ("rod", [0.0, 102.6]),
    );
    seed.revolute("main_bearing", "crank", "bearing");
    seed.prismatic("slide", "liner", "piston", [1.0, 0.0]);
    seed.driver_angle("crank_angle", "crank", "omega * t");
    seed.branch(
        "piston_outboard",
        Product::Dot,
        ("bearing", "liner"),
        (("rod", [41.3, 0.0]), ("rod", [0.0, 102.6])),
        Sign::Positive,
    )
    .item_doc(
        "The piston stays on the liner's side of the crank pin: the rod, from crank pin to piston",
    )
    .item_doc("pin, points along the cylinder axis (bearing to liner).");

    let options = CodegenOptions::default();
    let built = seed.expand(&options).unwrap_or_else(|e| panic!("{e}"));
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/scenes/piston_crank.mech"
    );
    let file = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let from_file = mechgen::expand(
        mechgen::Input::Text(&file),
        &mechgen::Options {
            codegen: options,
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(built.to_string(), from_file.to_string());
}

#[test]
fn scissor_lifts_of_several_sizes_rise_as_n_l_sin_alpha() {
    for stages in [1, 2, 3, 7] {
        let text = scene::scissor_lift(stages)
            .build()
            .unwrap_or_else(|e| panic!("{e}"));
        let compiled = mechgen::compile(mechgen::Input::Text(&text), &mechgen::Options::default())
            .unwrap_or_else(|e| panic!("{e}\n{text}"));
        let lift = Interpreted::new(&compiled);
        assert_eq!(lift.len(), 6 * stages + geometry::EXTRA_COORDINATES);
        let platform = 2 * stages + 2;
        assert_eq!(lift.coordinate_name(3 * platform + 1), Some("platform.y"));
        let mut guess =
            mechgen_runtime::Vector::<mechgen_runtime::nalgebra::Dyn>::zeros(lift.len());
        lift.initial_guess(&mut guess);
        let mut solver = Solver::new(lift);
        for t in [0.0, 0.4, 1.1, 2.0] {
            let state = solver
                .solve(t, &guess)
                .unwrap_or_else(|e| panic!("{stages} stages, t = {t}: {e:?}"));
            let alpha = geometry::alpha(t);
            let expected = geometry::platform_height(stages, alpha);
            let y = state.q[3 * platform + 1];
            assert!(
                (y - expected).abs() <= 1e-10 * expected,
                "{stages} stages, t = {t}: platform at {y}, closed form {expected}"
            );
            // The slider keeps the bottom stage's width.
            assert!((state.q[3] - geometry::stage_width(alpha)).abs() <= 1e-10);
            guess.copy_from(&state.q);
        }
    }
}

#[test]
fn an_extra_driver_on_a_built_scene_is_reported_by_the_checker() {
    let mut lift = scene::scissor_lift(3);
    // A second driver on a one-degree-of-freedom scene.
    lift.driver_travel("push", "rail", "0.9");
    let errors = lift
        .expand(&CodegenOptions::default())
        .expect_err("an error")
        .to_string();
    assert!(
        errors.contains("1 degree of freedom but 2 drivers"),
        "{errors}"
    );
}
