//! `--set` of a mass, inertia, spring constant or gear ratio that breaks the rule a constant
//! obeys at compile time is refused (exit status 1) with the error naming the parameter and
//! the body or load. The typed errors behind it, in generated code, the interpreter and the
//! dense reference, are tested on the same scene in `tests/tests/physics_checks.rs`.

/// A slider-crank with a gear on the crank and a spring on the slider, its physics in
/// parameters.
const LOADED: &str = r"
mechanism Loaded {
    param m = 2;
    param j = 0.01;
    param k = 500;
    param c = 4;
    param free = 0.2;
    param ratio = 2;
    param arm = 0.03;
    ground frame at (0, 0, 0);
    body crank near (0, 0, 0.2) mass m inertia j centre (arm, 0);
    body slider near (0.33, 0, 0) mass 0.7 inertia 0.001;
    body wheel near (0, 0, 0) mass 1 inertia 0.1;
    joint pivot: revolute(frame, crank);
    joint axle: revolute(frame, wheel);
    joint mesh: gear(crank, wheel, ratio ratio);
    joint guide: prismatic(frame, slider, along (1, 0));
    joint rod: distance(crank @ (0.1, 0), slider, 0.25);
    driver spin: angle(crank) = 0.2 + 20 * t;
    gravity (0, -9.81);
    load coil: spring(frame @ (0.6, 0.1), slider, stiffness k, length free, damping c);
    outputs positions, velocities, accelerations, forces;
}";

/// (parameter, value, its subject's name in the message).
const BAD: [(&str, f64, &str); 7] = [
    ("m", -1.0, "body `crank`"),
    ("j", -10.0, "body `crank`"),
    ("arm", 1e101, "body `crank`"),
    ("k", -20.0, "load `coil`"),
    ("c", -1.0, "load `coil`"),
    ("free", -0.1, "load `coil`"),
    ("ratio", 0.0, "`mesh`"),
];

#[test]
fn the_cli_refuses_bad_physics_from_set() {
    let dir = std::env::temp_dir().join(format!("mechgen-physics-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("loaded.mech");
    std::fs::write(&path, LOADED).unwrap();
    for (parameter, value, named) in BAD {
        let set = format!("{parameter}={value}");
        let args = [
            "solve",
            path.to_str().unwrap(),
            "--at",
            "0,0.1",
            "--set",
            &set,
        ];
        let (mut out, mut err) = (Vec::new(), Vec::new());
        let code = mechgen_cli::run(args.iter().map(|a| a.into()), &mut out, &mut err);
        let err = String::from_utf8_lossy(&err);
        assert_eq!(code, 1, "{set}: {err}");
        assert!(
            err.contains(named) && err.contains(&format!("`{parameter}`")),
            "{err}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
