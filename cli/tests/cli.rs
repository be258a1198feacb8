//! End-to-end tests of the `mechgen` binary: each command on the example scenes, error reports
//! with positions, and bad command lines.

mod common;

use std::process::Command;

use common::{csv_rows, mechgen, scene, scratch, text};
use mechgen_runtime::{Simulation, Solver, SolverOptions, sample_time};

/// Positions of the seed at t = 0 from its closed form: piston x of the boxer piston-crank.
const SEED_PISTON_X_AT_0: f64 = 129.89921491356055;

#[test]
fn expand_prints_the_generated_mechanism() {
    let out = mechgen(&["expand", &scene("piston_crank.mech")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let code = text(&out.stdout);
    assert!(
        code.contains("impl ::mechgen_runtime::Mechanism for PistonCrank"),
        "{code}"
    );
}

#[test]
fn check_lists_coordinates_equations_and_freedom() {
    let out = mechgen(&["check", &scene("piston_crank.mech")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let report = text(&out.stdout);
    for expected in [
        "mechanism PistonCrank",
        "coordinates (15):",
        "   3  piston.x\n",
        "equations (15):",
        "  14  crank_angle\n",
        "degrees of freedom: 1 ",
        "matched by 1 driver",
        "of 225 (15 × 15)",
        "omega = 314",
    ] {
        assert!(
            report.contains(expected),
            "missing {expected:?} in\n{report}"
        );
    }
    assert!(!report.contains("operation counts"), "{report}");
}

#[test]
fn check_stats_prints_operation_counts_like_the_generated_docs() {
    let path = scene("piston_crank.mech");
    let out = mechgen(&["check", &path, "--stats"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let report = text(&out.stdout);
    assert!(report.contains("operation counts"), "{report}");
    let rows: Vec<Vec<&str>> = report
        .lines()
        .skip_while(|l| !l.contains("operation counts"))
        .skip(2)
        .map(|l| l.split_whitespace().collect())
        .collect();
    let functions: Vec<&str> = rows.iter().map(|r| r[0]).collect();
    assert_eq!(
        functions,
        ["phi", "jacobian", "phi_and_jacobian", "nu", "gamma"],
        "{report}"
    );

    // The same numbers the emitter writes into the generated doc comments.
    let expanded = text(&mechgen(&["expand", &path]).stdout);
    // The counts line follows the function's first doc line (the two may share a line).
    let doc = |what: &str| -> String {
        let mut lines = expanded
            .lines()
            .skip_while(|l| !l.contains(&format!("/// Writes {what}")));
        lines
            .by_ref()
            .take(4)
            .find_map(|l| l.split("Operations: ").nth(1))
            .unwrap_or_else(|| panic!("no operation counts documented for {what}"))
            .to_owned()
    };
    for (row, what) in rows
        .iter()
        .zip(["Φ(q, t)", "Φ_q(q, t)", "Φ and Φ_q", "ν", "γ"])
    {
        let [trig, sqrt, exp_ln, mul, add, div, neg] = [2, 3, 4, 5, 6, 7, 8].map(|i| row[i]);
        let expected = format!(
            "{trig} trig, {sqrt} sqrt, {exp_ln} exp/ln, {mul} mul, {add} add, {div} div, {neg} neg."
        );
        assert_eq!(doc(what), expected, "{what}");
    }
}

#[test]
fn solve_writes_one_row_per_sample_time() {
    let csv = scratch("seed.csv");
    let (t_end, steps) = (0.01, 8);
    let out = mechgen(&[
        "solve",
        &scene("piston_crank.mech"),
        "--t-end",
        "0.01",
        "--steps",
        "8",
        "--csv",
        csv.to_str().expect("UTF-8 path"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(out.stdout.is_empty(), "the CSV went to the file");
    let summary = text(&out.stderr);
    assert!(summary.contains("wrote 9 rows"), "{summary}");
    assert!(summary.contains("8 equal steps"), "{summary}");
    assert!(summary.contains("Newton iterations"), "{summary}");

    let written = std::fs::read_to_string(&csv).expect("CSV written");
    let lines: Vec<&str> = written.lines().collect();
    assert_eq!(lines.len(), 1 + (steps + 1));
    let header: Vec<&str> = lines[0].split(',').collect();
    assert_eq!(header.len(), 1 + 3 * 15);
    assert_eq!(header[..2], ["t", "liner.x"]);
    assert!(header.contains(&"piston.x_dot") && header.contains(&"piston.x_ddot"));
    let piston_x = header
        .iter()
        .position(|&h| h == "piston.x")
        .expect("piston.x column");

    for (k, line) in lines[1..].iter().enumerate() {
        let row: Vec<f64> = line
            .split(',')
            .map(|v| v.parse().expect("a number"))
            .collect();
        assert_eq!(row.len(), header.len());
        assert_eq!(row[0], sample_time(0.0, t_end, steps, k), "row {k}");
        assert!(row.iter().all(|v| v.is_finite()), "row {k}");
    }
    let first: f64 = lines[1]
        .split(',')
        .nth(piston_x)
        .and_then(|v| v.parse().ok())
        .unwrap_or(0.0);
    assert!((first - SEED_PISTON_X_AT_0).abs() < 1e-9, "{first}");
    let _ = std::fs::remove_file(&csv);
}

#[test]
fn solve_to_stdout_with_a_parameter_and_start_time() {
    let out = mechgen(&[
        "solve",
        &scene("four_bar.mech"),
        "--t0=0.5",
        "--t-end=1",
        "--steps=2",
        "--set",
        "omega=-3",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let csv = text(&out.stdout);
    let times: Vec<&str> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap_or(""))
        .collect();
    assert_eq!(times, ["0.5", "0.75", "1.0"]);
    // omega = -3: the crank angle is -3 t.
    let header: Vec<&str> = csv.lines().next().unwrap_or("").split(',').collect();
    let theta = header
        .iter()
        .position(|&h| h == "crank.theta")
        .expect("crank.theta");
    let last: f64 = csv
        .lines()
        .last()
        .and_then(|l| l.split(',').nth(theta)?.parse().ok())
        .unwrap_or(0.0);
    assert!((last + 3.0).abs() < 1e-9, "{last}");
}

#[test]
fn unknown_parameters_list_the_declared_ones() {
    let out = mechgen(&[
        "solve",
        &scene("piston_crank.mech"),
        "--t-end",
        "1",
        "--steps",
        "1",
        "--set",
        "speed=3",
    ]);
    // A name the scene does not declare is a bad command line.
    assert_eq!(out.status.code(), Some(2));
    let message = text(&out.stderr);
    assert!(message.contains("no parameter `speed`"), "{message}");
    assert!(message.contains("`omega` (default 314)"), "{message}");
    assert!(message.contains("Usage: mechgen solve"), "{message}");
    assert!(out.stdout.is_empty());
    let out = mechgen(&[
        "solve",
        &scene("piston_crank.mech"),
        "--at",
        "0",
        "--set",
        "omgea=2*pi",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let message = text(&out.stderr);
    assert!(message.contains("did you mean `omega`?"), "{message}");
    // A derived parameter is named as such; the parameters it is computed from can be set.
    let derived = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/derived.mech");
    let out = mechgen(&["solve", derived, "--at", "0", "--set", "c=40"]);
    assert_eq!(out.status.code(), Some(2));
    let message = text(&out.stderr);
    assert!(message.contains("`c` is a derived parameter"), "{message}");
    let out = mechgen(&["solve", derived, "--at", "0", "--set", "a=22"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let check = text(&mechgen(&["check", derived]).stdout);
    assert!(
        check.contains("derived parameters (2), computed from those above:\n  c    = 38.83"),
        "{check}"
    );
}

#[test]
fn scene_errors_are_all_reported_with_line_and_column() {
    let path = scratch("broken.mech");
    let source = "\
/// Broken on purpose.
mechanism Broken {
    ground frame at (0, 0, 0);
    body arm near (1, 0, 0);
    body arm near (2, 0, 0);
    joint pivot: revolute(frame, ghost @ (1, 0));
    driver spin: angle(arm) = t;
}
";
    std::fs::write(&path, source).expect("scene written");
    let name = path.to_str().expect("UTF-8 path");
    for command in ["check", "expand", "solve"] {
        let mut args = vec![command, name];
        if command == "solve" {
            args.extend(["--t-end", "1", "--steps", "1"]);
        }
        let out = mechgen(&args);
        assert_eq!(out.status.code(), Some(1), "{command}");
        let errors = text(&out.stderr);
        let duplicate = format!("{name}:5:10: error: duplicate name `arm`");
        let unknown = format!("{name}:6:34: error: unknown body `ghost`");
        assert!(errors.contains(&duplicate), "{command}: {errors}");
        assert!(errors.contains(&unknown), "{command}: {errors}");
        assert!(
            errors.contains("6 |     joint pivot: revolute(frame, ghost @ (1, 0));\n  |"),
            "{errors}"
        );
        assert!(
            errors.contains("\n  |                                  ^^^^^\n"),
            "{errors}"
        );
        assert!(out.stdout.is_empty(), "{command}");
    }
    let _ = std::fs::remove_file(&path);
}

/// A scene of `markers` marker statements (about 40 bytes each) after a four-line pendulum.
fn many_markers(markers: usize, last: &str) -> String {
    let mut source = "mechanism Many {\n    ground frame at (0, 0, 0);\n    \
                      body arm near (1, 0, 0);\n    joint pivot: revolute(frame, arm);\n    \
                      driver spin: angle(arm) = t;\n"
        .to_owned();
    for k in 0..markers {
        source.push_str(&format!("    marker m{k}: arm @ ({k}, 0); // no. {k}\n"));
    }
    source + last + "}\n"
}

#[test]
fn large_scenes_are_refused_before_they_are_read_and_errors_placed_in_any_chunk() {
    // 5,000 markers, about 200 kB: read in several chunks.
    let path = scratch("many.mech");
    let source = many_markers(5000, "    marker late: arm @ (1, q);\n");
    std::fs::write(&path, &source).expect("scene written");
    let name = path.to_str().expect("UTF-8 path");

    let out = mechgen(&["check", name, "--max-file-size", "1000"]);
    assert_eq!(out.status.code(), Some(1));
    let message = text(&out.stderr);
    let size = format!(
        "`{name}` is {} bytes, more than the 1000 bytes",
        source.len()
    );
    assert!(message.contains(&size), "{message}");
    assert!(
        message.contains("hint: pass `--max-file-size BYTES`"),
        "{message}"
    );

    // Statement 101 is the 97th marker, on line 102 (the header line, four statements, then
    // one marker a line).
    let out = mechgen(&["check", name, "--max-statements", "100"]);
    assert_eq!(out.status.code(), Some(1));
    let message = text(&out.stderr);
    let many = format!("{name}:102:5: error: the scene has 5005 statements, more than the 100");
    assert!(message.contains(&many), "{message}");

    // Within the limits, an error in the last chunk is placed on its line and column.
    let out = mechgen(&["check", name]);
    assert_eq!(out.status.code(), Some(1));
    let message = text(&out.stderr);
    let late = format!("{name}:5006:28: error: unknown name `q`");
    assert!(message.contains(&late), "{message}");
    assert!(
        message.contains(
            "5006 |     marker late: arm @ (1, q);\n     |                            ^\n"
        ),
        "{message}"
    );

    // Standard input is cut off at the limit.
    let mut child = Command::new(env!("CARGO_BIN_EXE_mechgen"))
        .args(["check", "-", "--max-file-size", "1000"])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("mechgen runs");
    if let Some(mut stdin) = child.stdin.take() {
        use std::io::Write as _;
        // The reader may stop early: a broken pipe is expected.
        let _ = stdin.write_all(source.as_bytes());
    }
    let out = child.wait_with_output().expect("mechgen ends");
    assert_eq!(out.status.code(), Some(1));
    let message = text(&out.stderr);
    assert!(
        message.contains("`<stdin>` is more than 1000 bytes"),
        "{message}"
    );
    let _ = std::fs::remove_file(&path);
}

/// The four-bar with one joint too many: `check` points at that joint, line and column.
#[test]
fn check_points_at_the_joint_that_over_constrains() {
    let four_bar = std::fs::read_to_string(scene("four_bar.mech")).expect("four-bar");
    let cases = [
        (
            "joint extra: distance(frame @ (80, 0), rocker @ (50, 0), 50);",
            "joint `extra` over-constrains it",
            "remove joint `extra`, or remove 1 driver, such as `crank_angle`",
        ),
        (
            "joint extra: revolute(rocker, frame @ (100, 0));",
            "joints `rocker_pivot`, `extra` over-determine body `rocker`",
            "remove joint `extra` (or `rocker_pivot`)",
        ),
    ];
    for (k, (joint, what, fix)) in cases.into_iter().enumerate() {
        let path = scratch(&format!("over_constrained_{k}.mech"));
        let source = four_bar.replace(
            "    driver crank_angle",
            &format!("    {joint}\n    driver crank_angle"),
        );
        std::fs::write(&path, &source).expect("scene written");
        let name = path.to_str().expect("UTF-8 path");
        let out = mechgen(&["check", name]);
        assert_eq!(out.status.code(), Some(1));
        let errors = text(&out.stderr);
        let line = source
            .lines()
            .position(|l| l.contains("joint extra"))
            .unwrap()
            + 1;
        assert!(
            errors.contains(&format!("{name}:{line}:11: error: ")),
            "{errors}"
        );
        assert!(errors.contains(what) && errors.contains(fix), "{errors}");
        let _ = std::fs::remove_file(&path);
    }
}

/// A spring whose ends meet, with a non-zero free length: `solve` names the spring, the
/// cause and what to do.
#[test]
fn solve_names_the_load_whose_force_is_not_finite() {
    let seed = std::fs::read_to_string(scene("piston_crank_dynamics.mech")).expect("seed");
    let source = seed.replace(
        "    joint slide:",
        "    load valve: spring(rod @ (41.3, 0), crank @ (0, 43), stiffness 20, length 35);\n    \
         joint slide:",
    );
    let path = scratch("coincident_spring.mech");
    std::fs::write(&path, &source).expect("scene written");
    let out = mechgen(&["solve", path.to_str().expect("UTF-8 path"), "--at", "0"]);
    assert_eq!(out.status.code(), Some(1));
    let errors = text(&out.stderr);
    assert!(
        errors.contains(
            "the force of spring `valve` became NaN or infinite at t = 0: its ends coincide"
        ) && errors.contains("hint: the named load is not finite at this time"),
        "{errors}"
    );
    let _ = std::fs::remove_file(&path);
}

#[test]
fn unreadable_files_say_so() {
    let out = mechgen(&["check", "no/such/scene.mech"]);
    assert_eq!(out.status.code(), Some(1));
    let message = text(&out.stderr);
    assert!(
        message.contains("cannot read `no/such/scene.mech`"),
        "{message}"
    );
    assert!(message.contains("hint: check the path"), "{message}");
}

#[test]
fn bad_command_lines_exit_2_with_a_short_usage() {
    let seed = scene("piston_crank.mech");
    for args in [
        &["frobnicate"][..],
        &["check"],
        &["check", &seed, "--verbose"],
        &["expand", &seed, "--stats"],
        &["solve", &seed, "--steps", "10"],
        &["solve", &seed, "--t-end", "soon", "--steps", "10"],
        &["solve", &seed, "--t-end", "1", "--steps", "0"],
        &[
            "solve", &seed, "--t-end", "1", "--steps", "2", "--set", "omega",
        ],
        &["solve", &seed, "--at", "0.2,0.1"],
    ] {
        let out = mechgen(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let message = text(&out.stderr);
        assert!(message.starts_with("error: "), "{args:?}: {message}");
        // The usage line or a pointer to `--help`, not the whole manual.
        assert!(message.contains("--help"), "{args:?}: {message}");
        assert!(message.lines().count() <= 8, "{args:?}: {message}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
    // No command at all: the overview, on stderr, still a usage error.
    let out = mechgen(&[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("Commands:"));
}

#[test]
fn misspelt_commands_and_flags_get_a_suggestion() {
    let seed = scene("piston_crank.mech");
    let out = mechgen(&["chek", &seed]);
    assert!(text(&out.stderr).contains("similar subcommand exists: 'check'"));
    let out = mechgen(&["check", &seed, "--stat"]);
    assert!(text(&out.stderr).contains("similar argument exists: '--stats'"));
}

#[test]
fn help_goes_to_stdout_and_succeeds_per_subcommand() {
    for (args, expected) in [
        (&["help"][..], "Commands:"),
        (&["--help"], "Commands:"),
        (&["-h"], "Commands:"),
        (&["solve", "--help"], "--diagnostics"),
        (&["help", "solve"], "t_k = T0 + k·h"),
        (&["check", "--help"], "--stats"),
        (&["--version"], "mechgen 0.1.0"),
    ] {
        let out = mechgen(args);
        assert!(out.status.success(), "{args:?}");
        let help = text(&out.stdout);
        assert!(help.contains(expected), "{args:?}: {help}");
    }
    let check = text(&mechgen(&["check", "--help"]).stdout);
    assert!(!check.contains("--t-end"), "{check}");
}

#[test]
fn completions_are_printed_for_each_shell() {
    for shell in ["bash", "zsh", "fish", "powershell", "elvish"] {
        let out = mechgen(&["completions", shell]);
        assert!(out.status.success(), "{shell}");
        assert!(text(&out.stdout).contains("solve"), "{shell}");
    }
}

#[test]
fn listed_times_are_solved_at_exactly_those_doubles() {
    let seed = scene("piston_crank.mech");
    // Times no equal-step formula produces, written in shortest round-trip form.
    let times = [
        "0.001",
        "0.0013333333333333333",
        "0.30000000000000004",
        "0.31",
    ];
    let out = mechgen(&["solve", &seed, "--at", &times.join(",")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (_, rows) = csv_rows(&out);
    let written: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
    assert_eq!(written, times);
    for (row, time) in rows.iter().zip(times) {
        let parsed: f64 = row[0].parse().unwrap();
        assert_eq!(parsed.to_bits(), time.parse::<f64>().unwrap().to_bits());
    }

    let path = scratch("times.txt");
    std::fs::write(
        &path,
        "# measured\n0.001\n\n0.0013333333333333333 # second\n",
    )
    .unwrap();
    let out = mechgen(&["solve", &seed, "--times", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (_, from_file) = csv_rows(&out);
    assert_eq!(from_file, rows[..2]);
    assert!(
        text(&out.stderr).contains("wrote 2 rows"),
        "{}",
        text(&out.stderr)
    );

    std::fs::write(&path, "0.1\nsoon\n").unwrap();
    let out = mechgen(&["solve", &seed, "--times", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains(":2: `soon`"),
        "{}",
        text(&out.stderr)
    );
    let _ = std::fs::remove_file(&path);
}

#[test]
fn diagnostics_add_per_step_columns() {
    let seed = scene("piston_crank.mech");
    let out = mechgen(&[
        "solve",
        &seed,
        "--t-end",
        "0.02",
        "--steps",
        "4",
        "--diagnostics",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (header, rows) = csv_rows(&out);
    let tail = &header[header.len() - 6..];
    assert_eq!(
        tail,
        [
            "iterations",
            "substeps",
            "evaluations",
            "fallbacks",
            "condition",
            "det_sign"
        ]
    );
    assert_eq!(rows.len(), 5);
    // The same run through the macro's generated code on the interpreter's path, the stage
    // sweep (the generated straight step verifies without applying a correction, so it counts
    // no Newton iteration): every column the same (the condition estimate to round-off, the
    // interpreter's arithmetic being ordered differently).
    let sweep = SolverOptions {
        straight_step: false,
        ..SolverOptions::default()
    };
    let solver = Solver::with_options(seed::PistonCrank::default(), sweep);
    let mut simulation = Simulation::new(solver, 0.0).unwrap_or_else(|e| panic!("{e}"));
    for (k, row) in rows.iter().enumerate() {
        if k > 0 {
            simulation
                .step_to(sample_time(0.0, 0.02, 4, k))
                .unwrap_or_else(|e| panic!("{e}"));
        }
        let state = simulation.state();
        assert_eq!(row.len(), header.len());
        let n = row.len();
        let integers: Vec<i64> = [6, 5, 4, 3, 1]
            .iter()
            .map(|back| row[n - back].parse().unwrap())
            .collect();
        let expected = [
            state.iterations as i64,
            state.substeps as i64,
            state.evaluations as i64,
            state.fallbacks as i64,
            i64::from(state.orientation),
        ];
        assert_eq!(integers, expected, "step {k}: {row:?}");
        let condition: f64 = row[n - 2].parse().unwrap();
        let relative = (condition - state.condition).abs() / state.condition;
        assert!(
            relative < 1e-12,
            "step {k}: {condition} vs {}",
            state.condition
        );
    }
}

/// The seed as the macro generates it (`examples/scenes/piston_crank.mech`, written out).
mod seed {
    mechgen_runtime::mechanism! {
        /// The seed.
        pub mechanism PistonCrank {
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
            branch piston_outboard: dot(bearing -> liner, rod @ (41.3, 0) -> rod @ (0, 102.6)) > 0;
        }
    }
}

#[test]
fn json_output_is_one_document_even_when_a_step_fails() {
    let seed = scene("piston_crank.mech");
    let out = mechgen(&[
        "solve", &seed, "--t-end", "0.01", "--steps", "2", "--format", "json",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let document: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(document["mechanism"], "PistonCrank");
    assert_eq!(document["coordinates"][3], "piston.x");
    assert_eq!(document["outputs"], "Accelerations");
    assert!(document["error"].is_null());
    let states = document["states"].as_array().unwrap();
    assert_eq!(states.len(), 3);
    assert_eq!(states[2]["t"], 0.01);
    let piston_x = states[0]["q"][3].as_f64().unwrap();
    assert!((piston_x - SEED_PISTON_X_AT_0).abs() < 1e-9, "{piston_x}");
    // The same doubles as the CSV, bit for bit.
    let csv = mechgen(&["solve", &seed, "--t-end", "0.01", "--steps", "2"]);
    let (_, rows) = csv_rows(&csv);
    for (state, row) in states.iter().zip(&rows) {
        for (j, value) in state["q"].as_array().unwrap().iter().enumerate() {
            let written: f64 = row[1 + j].parse().unwrap();
            assert_eq!(value.as_f64().unwrap().to_bits(), written.to_bits());
        }
    }
    for key in ["q_dot", "q_ddot", "iterations", "condition", "det_sign"] {
        assert!(!states[1][key].is_null(), "{key}");
    }

    // A four-bar whose links lock at t ≈ 0.18: the states before, then the error.
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/data/locked_four_bar.mech"
    );
    let out = mechgen(&[
        "solve", path, "--t-end", "0.5", "--steps", "10", "--format", "json",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let document: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let error = &document["error"];
    assert_eq!(error["step"], 4);
    // Where the links lock: a dead point (Singular) or beyond it (NoAssembly), with its time.
    let kind = error["kind"].as_object().unwrap();
    let (variant, fields) = kind.iter().next().unwrap();
    assert!(
        variant == "Singular" || variant == "NoAssembly",
        "{variant}"
    );
    let time = fields["time"].as_f64().unwrap();
    assert!((0.15..0.2).contains(&time), "{time}");
    assert!(
        error["message"]
            .as_str()
            .unwrap()
            .contains(&time.to_string())
    );
    assert_eq!(document["states"].as_array().unwrap().len(), 4);

    let out = mechgen(&["check", &seed, "--format", "json"]);
    assert!(out.status.success());
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary["degrees_of_freedom"], 1);
    assert_eq!(summary["parameters"][0]["name"], "omega");
}

#[test]
fn json_names_the_markers_and_records_a_failed_assembly() {
    let out = mechgen(&[
        "solve",
        &scene("hoeken.mech"),
        "--at",
        "0",
        "--format",
        "json",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let document: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let markers: Vec<&str> = document["markers"]
        .as_array()
        .map(|m| m.iter().filter_map(serde_json::Value::as_str).collect())
        .unwrap_or_default();
    assert_eq!(&markers[..2], ["tracer.x", "tracer.y"]);
    assert!(markers.contains(&"transmission.angle"), "{markers:?}");
    let values = document["states"][0]["markers"]
        .as_array()
        .map_or(0, Vec::len);
    assert_eq!(values, markers.len());

    // Links 10 + 20 + 20 cannot span a frame of 100: no state, the error at step 0.
    let path = scratch("apart.mech");
    std::fs::write(
        &path,
        "mechanism Apart {
            ground frame at (0, 0, 0);
            body crank near (5, 0, 0);
            body coupler near (20, 0, 0);
            body rocker near (90, 0, 0);
            joint pivot: revolute(frame, crank @ (-5, 0));
            joint pin: revolute(crank @ (5, 0), coupler @ (-10, 0));
            joint elbow: revolute(coupler @ (10, 0), rocker @ (-10, 0));
            joint rest: revolute(rocker @ (10, 0), frame @ (100, 0));
            driver spin: angle(crank) = t;
        }",
    )
    .unwrap();
    let name = path.to_str().unwrap();
    let out = mechgen(&["solve", name, "--at", "0", "--format", "json"]);
    assert_eq!(out.status.code(), Some(1));
    let document: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", text(&out.stdout)));
    assert_eq!(document["mechanism"], "Apart");
    assert_eq!(document["states"].as_array().map(Vec::len), Some(0));
    assert_eq!(document["error"]["step"], 0);
    let message = document["error"]["message"].as_str().unwrap_or_default();
    assert!(message.starts_with("cannot assemble `Apart`"), "{message}");
    assert!(text(&out.stderr).contains("cannot assemble `Apart`"));
    // CSV writes nothing.
    let out = mechgen(&["solve", name, "--at", "0"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    let _ = std::fs::remove_file(&path);
}

#[test]
fn no_negative_zeros_are_written() {
    // The seed at rest: many velocities are exactly zero, some computed as −0.
    let seed = scene("piston_crank.mech");
    for format in ["csv", "json"] {
        let out = mechgen(&[
            "solve", &seed, "--at", "0,0.001", "--set", "omega=0", "--format", format,
        ]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let written = text(&out.stdout);
        assert!(written.contains("0.0"), "{written}");
        assert!(
            !written.contains("-0.0,") && !written.contains("-0.0]"),
            "{format}: {written}"
        );
    }
}

#[test]
fn a_scene_with_forces_reports_its_reactions_in_check_csv_and_json() {
    let file = scene("piston_crank_dynamics.mech");
    let check = mechgen(&["check", &file]);
    let report = text(&check.stdout);
    assert!(check.status.success(), "{}", text(&check.stderr));
    assert!(report.contains("forces: masses on piston, rod, crank; gravity (0, -9810)"));
    assert!(report.contains("14  crank_angle.effort"), "{report}");

    let csv = mechgen(&["solve", &file, "--at", "0,0.001"]);
    let header = text(&csv.stdout);
    let header = header.lines().next().unwrap_or_default();
    assert!(
        header.ends_with(",slide.normal,slide.torque,crank_angle.effort"),
        "{header}"
    );
    assert_eq!(header.split(',').count(), 1 + 4 * 15);

    let json = mechgen(&["solve", &file, "--at", "0", "--format", "json"]);
    let document: serde_json::Value =
        serde_json::from_slice(&json.stdout).unwrap_or_else(|e| panic!("valid JSON: {e}"));
    assert_eq!(document["reactions"][6], "crank_pin.fx");
    assert_eq!(document["outputs"], "Forces");
    let reactions = document["states"][0]["reactions"]
        .as_array()
        .map_or(0, Vec::len);
    assert_eq!(reactions, 15);
    // Without forces, no reactions anywhere.
    let plain = mechgen(&[
        "solve",
        &scene("piston_crank.mech"),
        "--at",
        "0",
        "--format",
        "json",
    ]);
    assert!(!text(&plain.stdout).contains("reactions"));
}
