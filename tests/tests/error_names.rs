//! Every error a scene's public API returns names the scene's equations, coordinates, branches
//! and parameters in `Display` and in `Debug` (what `unwrap` and an error returned from `main`
//! print), for a generated scene and for the same scene interpreted: the errors carry the
//! scene's `'static` names.

use mechgen_interp::Interpreted;
use mechgen_runtime::nalgebra::DVector;
use mechgen_runtime::{
    Mechanism, Names, Quantity, Simulation, SolveError, Solver, Structured, mechanism,
};

mechanism! {
    /// A crank-rocker whose rod and frame length are parameters and whose crank angle stops
    /// being real at t = 1; `NAMED` below is the same text.
    pub mechanism Named {
        /// Frame length.
        param reach = 100.0;
        /// Coupler length.
        param rod = 120.0;
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body coupler near (40, 0, 0.6);
        body rocker near (100, 0, 1.1);
        joint crank_pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (40, 0), coupler);
        joint rocker_pin: revolute(coupler @ (rod, 0), rocker @ (80, 0));
        joint rocker_pivot: revolute(rocker, frame @ (reach, 0));
        driver crank_angle: angle(crank) = sqrt(1 - t);
        branch open_assembly: cross(coupler @ (120, 0) -> coupler, rocker @ (80, 0) -> rocker) > 0;
    }
}

mechanism! {
    /// The same crank-rocker with its branch declared the other way round: its guesses are on
    /// the wrong branch.
    pub mechanism Crossed {
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body coupler near (40, 0, 0.6);
        body rocker near (100, 0, 1.1);
        joint crank_pivot: revolute(frame, crank);
        joint crank_pin: revolute(crank @ (40, 0), coupler);
        joint rocker_pin: revolute(coupler @ (120, 0), rocker @ (80, 0));
        joint rocker_pivot: revolute(rocker, frame @ (100, 0));
        driver crank_angle: angle(crank) = t;
        branch crossed_assembly: cross(coupler @ (120, 0) -> coupler, rocker @ (80, 0) -> rocker) < 0;
    }
}

mechanism! {
    /// An arm with a moment and a spring anchored at its pivot: the spring's ends always meet.
    pub mechanism Loaded {
        /// The moment's scale.
        param moment = 1.0;
        /// The spring's free length.
        param rest = 0.0;
        gravity (0, -9.81);
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass 1 inertia 0.1;
        joint pivot: revolute(frame, arm @ (-1, 0));
        driver swing: angle(arm) = t;
        load brake: torque(arm) = 10 * moment;
        load valve: spring(frame, arm @ (-1, 0), stiffness 20, length rest);
    }
}

const LOADED: &str = "mechanism Loaded {
    param moment = 1.0;
    param rest = 0.0;
    gravity (0, -9.81);
    ground frame at (0, 0, 0);
    body arm near (1, 0, 0) mass 1 inertia 0.1;
    joint pivot: revolute(frame, arm @ (-1, 0));
    driver swing: angle(arm) = t;
    load brake: torque(arm) = 10 * moment;
    load valve: spring(frame, arm @ (-1, 0), stiffness 20, length rest);
}";

/// A force solve that meets a non-finite F names the load and the cause: an overflowing
/// moment, and a spring of non-zero free length whose ends meet.
fn load_failures<M: Structured + Clone>(loaded: M)
where
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    // Zero free length, a parameter: the spring's force is finite where its ends meet.
    if let Err(e) = Simulation::new(Solver::new(loaded.clone()), 0.0) {
        panic!("{e}");
    }
    let mut spring = loaded.clone();
    set_parameter(&mut spring, "rest", 3.0);
    let error = Simulation::new(Solver::new(spring), 0.0)
        .err()
        .unwrap()
        .error;
    assert_eq!(
        format!("{error:?}"),
        "NonFinite: the force of spring `valve` became NaN or infinite at t = 0: its ends \
         coincide, where a spring with a free length or damping has no direction (give it free \
         length 0 and no damping, or keep its ends apart)"
    );
    // The moment is declared first: it is named, whatever the spring does.
    let mut moment = loaded;
    set_parameter(&mut moment, "moment", 1e308);
    let error = Simulation::new(Solver::new(moment), 0.0)
        .err()
        .unwrap()
        .error;
    assert_named(
        &error,
        "NonFinite",
        &["the force or moment of load `brake`"],
    );
}

#[test]
fn a_non_finite_load_is_named_with_its_cause() {
    load_failures(Loaded::default());
    let scene = interpreted(LOADED);
    assert_eq!(scene.names(), &Loaded::NAMES);
    load_failures(scene);
}

const NAMED: &str = "mechanism Named {
    param reach = 100.0;
    param rod = 120.0;
    ground frame at (0, 0, 0);
    body crank near (0, 0, 0);
    body coupler near (40, 0, 0.6);
    body rocker near (100, 0, 1.1);
    joint crank_pivot: revolute(frame, crank);
    joint crank_pin: revolute(crank @ (40, 0), coupler);
    joint rocker_pin: revolute(coupler @ (rod, 0), rocker @ (80, 0));
    joint rocker_pivot: revolute(rocker, frame @ (reach, 0));
    driver crank_angle: angle(crank) = sqrt(1 - t);
    branch open_assembly: cross(coupler @ (120, 0) -> coupler, rocker @ (80, 0) -> rocker) > 0;
}";

fn interpreted(source: &str) -> Interpreted {
    Interpreted::new(
        &mechgen::compile(mechgen::Input::Text(source), &mechgen::Options::default())
            .unwrap_or_else(|e| panic!("{e}")),
    )
}

/// Display and Debug both hold every one of `names` and no bare index (`#3`); Debug leads with
/// the variant.
#[track_caller]
fn assert_named(error: &SolveError, variant: &str, names: &[&str]) {
    let (display, debug) = (error.to_string(), format!("{error:?}"));
    assert!(debug.starts_with(&format!("{variant}: ")), "{debug}");
    for text in [&display, &debug] {
        for name in names {
            assert!(text.contains(name), "`{name}` missing from: {text}");
        }
        assert!(!text.contains('#'), "a bare index in: {text}");
    }
}

/// The failures a user can reach, solved through the public API of a mechanism built from
/// [`Named`]'s text (generated or interpreted): each returned error names what failed.
fn real_failures<M: Structured + Clone>(named: M, set: fn(&mut M, &str, f64))
where
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    // Mid-run, through `step_to`: the driver's square root past t = 1.
    let mut simulation = Simulation::new(Solver::new(named.clone()), 0.0).unwrap();
    simulation.step_to(0.5).unwrap();
    let error = simulation.step_to(1.5).unwrap_err();
    assert_named(&error, "NonFinite", &["equation `crank_angle`"]);

    // A frame too long to close: `?` from `Simulation::new` into a plain `SolveError`.
    let mut far = named.clone();
    set(&mut far, "reach", 1000.0);
    let error = (|| -> Result<(), SolveError> {
        Simulation::new(Solver::new(far), 0.0)?;
        Ok(())
    })()
    .unwrap_err();
    assert_named(&error, "NoAssembly", &["cannot assemble", "equation `"]);

    // A rod beyond what double precision resolves.
    let mut huge = named;
    set(&mut huge, "rod", 1e200);
    let error = Simulation::new(Solver::new(huge), 0.0).err().unwrap().error;
    assert_named(
        &error,
        "Geometry",
        &["equation `rocker_pin.x`", "parameter `rod`"],
    );
}

fn set_parameter<M: Mechanism>(m: &mut M, name: &str, value: f64)
where
    mechgen_runtime::nalgebra::DefaultAllocator: mechgen_runtime::Storage<M::Dim>,
{
    m.set_parameter(name, value)
        .unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn a_generated_scene_names_its_failures() {
    real_failures(Named::default(), set_parameter);
    // The setter refuses NaN; a field written directly is caught by the solve.
    let nan = Named {
        reach: f64::NAN,
        ..Named::default()
    };
    let error = SolveError::from(Simulation::new(Solver::new(nan), 0.0).err().unwrap());
    assert_named(&error, "NonFinite", &["parameter `reach`"]);
    // The issue's `Error: BranchFlip { time: 0.0, branch: 0, … }`, from `main`'s `?`.
    let error = Simulation::new(Solver::new(Crossed::default()), 0.0)
        .err()
        .unwrap()
        .error;
    assert_named(
        &error,
        "BranchFlip",
        &["branch invariant `crossed_assembly`"],
    );
    assert_eq!(error.names(), &Crossed::NAMES);
}

#[test]
fn an_interpreted_scene_names_its_failures() {
    let scene = interpreted(NAMED);
    // The interpreter's tables are the generated ones, as `'static` as theirs.
    assert_eq!(scene.names(), &Named::NAMES);
    real_failures(scene.clone(), set_parameter);
    // A vector of the wrong length (only a run-time-sized scene can be handed one).
    let error = Solver::new(scene)
        .solve(0.0, &DVector::zeros(2))
        .unwrap_err();
    assert_named(&error, "DimensionMismatch", &["`Named`", "12 coordinates"]);
}

/// The failures no small scene reaches on demand (a stalled Newton iteration, a position too
/// large to resolve, a toggle), and every quantity with an index: named by each scene's tables.
#[test]
fn every_variant_names_its_indices() {
    let time = 0.25;
    let errors: [(SolveError, &str, &[&str]); 6] = [
        (
            SolveError::NoConvergence {
                time,
                iterations: 25,
                residual: 1e-3,
                equation: 7,
                names: &Names::NONE,
            },
            "NoConvergence",
            &["t = 0.25"],
        ),
        (
            SolveError::Unresolved {
                time,
                iterations: 4,
                residual: 1e-4,
                equation: 7,
                names: &Names::NONE,
            },
            "Unresolved",
            &["equation `rocker_pin.x`"],
        ),
        (
            SolveError::Singular {
                time,
                equation: 8,
                coordinate: 11,
                condition: f64::INFINITY,
                deficiency: 1,
                names: &Names::NONE,
            },
            "Singular",
            &["equation `rocker_pin.y` leaves coordinate `rocker.theta`"],
        ),
        (
            SolveError::NonFinite {
                time,
                quantity: Quantity::Branch(0),
                equation: None,
                names: &Names::NONE,
            },
            "NonFinite",
            &["branch invariant `open_assembly`"],
        ),
        (
            SolveError::BranchFlip {
                time,
                branch: 0,
                value: -1.0,
                names: &Names::NONE,
            },
            "BranchFlip",
            &["branch invariant `open_assembly`"],
        ),
        (
            SolveError::Geometry {
                time,
                equation: 9,
                parameter: 0,
                value: f64::NAN,
                requirement: mechgen_runtime::Requirement::Length,
                names: &Names::NONE,
            },
            "Geometry",
            &["equation `rocker_pivot.x`", "parameter `reach`"],
        ),
    ];
    let scene = interpreted(NAMED);
    for names in [&Named::NAMES, scene.names()] {
        for (error, variant, expected) in errors {
            assert_named(&error.named(names), variant, expected);
        }
    }
}
