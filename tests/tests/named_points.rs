//! Named body points (`point big_end: rod @ (41.3, 0);`): a scene that writes each point once
//! and uses it by name in joints, a marker and a branch generates exactly the code of the scene
//! with the points written out, and moves the same; its generated code is a reviewed snapshot.

use mechgen_runtime::{Simulation, Solver};
use mechgen_tests::twin;

twin! {
    NAMED,
    /// The seed piston-crank, its rod's two pins named once.
    pub mechanism Seed {
        /// Crank speed (rad/s).
        param omega = 314.0;
        ground liner at (156.8, 0, 0);
        body piston near (130, 0, 0);
        body rod near (29, 72, -2.35);
        body crank near (0, 0, 0);
        ground bearing at (0, 0, 0);
        /// The rod's big end, on the crank pin.
        point big_end: rod @ (41.3, 0);
        point small_end: rod @ (0, 102.6);
        point crank_pin_centre: crank @ (0, 43);
        joint crank_pin: revolute(big_end, crank_pin_centre);
        joint piston_pin: revolute(piston @ (-28, 0), small_end);
        joint main_bearing: revolute(crank, bearing);
        joint slide: prismatic(liner, piston, along (1, 0));
        driver crank_angle: angle(crank) = omega * t;
        marker pin_path: crank_pin_centre;
        branch piston_outboard: dot(bearing -> liner, big_end -> small_end) > 0;
    }
}

/// The same scene with its points written out (as text: it generates the same items).
const WRITTEN_OUT: &str = "
/// The seed piston-crank, its rod's two pins named once.
pub mechanism Seed {
    /// Crank speed (rad/s).
    param omega = 314.0;
    ground liner at (156.8, 0, 0);
    body piston near (130, 0, 0);
    body rod near (29, 72, -2.35);
    body crank near (0, 0, 0);
    ground bearing at (0, 0, 0);
    joint crank_pin: revolute(rod @ (41.3, 0), crank @ (0, 43));
    joint piston_pin: revolute(piston @ (-28, 0), rod @ (0, 102.6));
    joint main_bearing: revolute(crank, bearing);
    joint slide: prismatic(liner, piston, along (1, 0));
    driver crank_angle: angle(crank) = omega * t;
    marker pin_path: crank @ (0, 43);
    branch piston_outboard: dot(bearing -> liner, rod @ (41.3, 0) -> rod @ (0, 102.6)) > 0;
}
";

#[test]
fn named_points_generate_the_written_out_scene() {
    let named = mechgen::expand(mechgen::Input::Text(NAMED), &mechgen::Options::default())
        .map(mechgen::pretty)
        .unwrap_or_else(|e| panic!("{e}"));
    let written = mechgen::expand(
        mechgen::Input::Text(WRITTEN_OUT),
        &mechgen::Options::default(),
    )
    .map(mechgen::pretty)
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(named, written);
    insta::assert_snapshot!("named_points", named);
}

#[test]
fn named_points_move_as_declared() {
    let mut simulation =
        Simulation::new(Solver::new(Seed::default()), 0.0).unwrap_or_else(|e| panic!("{e}"));
    simulation
        .run(0.02, 36, |state| {
            // The marker is the crank pin: 43 from the bearing, at the crank's angle.
            let (pin, crank) = (state.pin_path(), state.crank());
            let angle = crank.theta;
            assert!((pin.x + 43.0 * angle.sin()).abs() < 1e-9, "{}", pin.x);
            assert!((pin.y - 43.0 * angle.cos()).abs() < 1e-9, "{}", pin.y);
            // The big end stays on it.
            let rod = state.rod();
            let big_end_x = rod.x + 41.3 * rod.theta.cos();
            assert!((big_end_x - pin.x).abs() < 1e-9);
        })
        .unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn misused_points_are_reported_at_their_use() {
    let errors = |extra: &str| {
        let source = NAMED.replacen(
            "driver crank_angle",
            &format!("{extra} driver crank_angle"),
            1,
        );
        match mechgen::compile(mechgen::Input::Text(&source), &mechgen::Options::default()) {
            Ok(_) => panic!("expected an error for {extra}"),
            Err(e) => e.to_string(),
        }
    };
    assert!(errors("marker m: big_end @ (1, 0);").contains("`big_end` is a named point, which takes no `@ (x, y)`: for another point of its body write `rod @ (x, y)`"));
    assert!(
        errors("load l: torque(big_end) = 1;")
            .contains("`big_end` is a named point (of `rod`), not a body")
    );
    assert!(errors("point p: shaft @ (1, 0);").contains("unknown body `shaft`"));
    assert!(errors("point rod: crank;").contains("duplicate name `rod`"));
}
