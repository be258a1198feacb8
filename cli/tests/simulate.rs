//! End-to-end tests of `mechgen simulate`: a free pendulum through the CSV against its
//! closed forms (the harmonic solution, the energies, the pivot force), outputs at exactly the
//! requested times, the JSON document, and what is refused (a scene without free degrees of
//! freedom, bad flags, a start that cannot assemble, a motion that fails part-way).

mod common;

use common::{csv_rows, mechgen, scene, scratch, text};
use mechgen_runtime::sample_time;

/// A pendulum hanging from the origin: its centre of mass `L` = 100 mm below the pivot, mass
/// `M` = 2 kg, inertia `J` = 2000 kg·mm² about the centre, swinging under gravity 9810 mm/s²
/// from `theta0` rad at rest (`swing` = the arm's angle, 0 hanging straight down).
const PENDULUM: &str = "
mechanism Pendulum {
    param theta0 = 0.01;
    ground frame at (0, 0, 0);
    body arm near (0, -100, 0) mass 2 inertia 2000;
    joint pivot: revolute(frame, arm @ (0, 100));
    free swing: angle(arm) from theta0;
    gravity (0, -9810);
}";

const M: f64 = 2.0;
const J: f64 = 2000.0;
const L: f64 = 100.0;
const G: f64 = 9810.0;

/// Small-amplitude angular frequency, √(M g L / (J + M L²)).
fn omega() -> f64 {
    (M * G * L / (J + M * L * L)).sqrt()
}

/// The pendulum written to a scratch file, its `theta0` replaced.
fn pendulum(name: &str, theta0: f64) -> String {
    let path = scratch(name);
    let source = PENDULUM.replace("theta0 = 0.01", &format!("theta0 = {theta0}"));
    std::fs::write(&path, source).expect("scene written");
    path.to_str().expect("UTF-8 path").to_owned()
}

/// The named columns of a CSV run, as numbers: one vector per row, in the order of `names`.
fn table(header: &[String], rows: &[Vec<String>], names: &[&str]) -> Vec<Vec<f64>> {
    let at: Vec<usize> = names
        .iter()
        .map(|name| {
            header
                .iter()
                .position(|h| h == name)
                .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
        })
        .collect();
    rows.iter()
        .map(|row| {
            at.iter()
                .map(|&j| row[j].parse().expect("a number"))
                .collect()
        })
        .collect()
}

#[test]
fn a_small_swing_follows_the_harmonic_solution() {
    let theta0 = 0.01;
    let path = pendulum("harmonic.mech", theta0);
    let out = mechgen(&[
        "simulate", &path, "--t-end", "1", "--steps", "20", "--rtol", "1e-6", "--atol", "1e-9",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (header, rows) = csv_rows(&out);
    assert_eq!(rows.len(), 21);
    let names = [
        "t",
        "swing.value",
        "swing.rate",
        "arm.theta",
        "arm.theta_dot",
    ];
    let w = omega();
    // The sine's nonlinearity shifts the frequency by θ0²/16 (6e-6 relative): 6e-7 rad of
    // error after 1 s, well inside the bound.
    for row in table(&header, &rows, &names) {
        let [t, value, rate, theta, theta_dot] = row[..] else {
            panic!("five columns");
        };
        let (angle, speed) = (theta0 * (w * t).cos(), -theta0 * w * (w * t).sin());
        assert!(
            (value - angle).abs() < 2e-4 * theta0,
            "t = {t}: {value} vs {angle}"
        );
        assert!(
            (rate - speed).abs() < 2e-4 * theta0 * w,
            "t = {t}: {rate} vs {speed}"
        );
        // The free coordinate is the arm's angle: its equation holds at every output.
        assert!((theta - value).abs() < 1e-12, "t = {t}");
        assert!((theta_dot - rate).abs() < 1e-12, "t = {t}");
    }
    let summary = text(&out.stderr);
    assert!(summary.contains("wrote 21 rows"), "{summary}");
    assert!(
        summary.contains("integrator steps") && summary.contains("rejected"),
        "{summary}"
    );
}

#[test]
fn outputs_are_at_exactly_the_requested_times() {
    let theta0 = 0.01;
    let path = pendulum("times.mech", theta0);
    let listed = [
        "0.0",
        "0.001",
        "0.0013333333333333333",
        "0.30000000000000004",
        "0.31",
    ];
    // Error-controlled and fixed steps (1 ms, which does not divide the listed times) alike.
    for stepping in [&[][..], &["--step", "1e-3"][..]] {
        let mut args = vec!["simulate", path.as_str(), "--at"];
        let at = listed.join(",");
        args.push(&at);
        args.extend_from_slice(stepping);
        let out = mechgen(&args);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let (header, rows) = csv_rows(&out);
        let written: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
        assert_eq!(written, listed, "{stepping:?}");
        // Stepped onto each time, not relabelled: the angle there is the solution's.
        for row in table(&header, &rows, &["t", "swing.value"]) {
            let angle = theta0 * (omega() * row[0]).cos();
            assert!(
                (row[1] - angle).abs() < 1e-3 * theta0,
                "{stepping:?} t = {}",
                row[0]
            );
        }
    }
    let out = mechgen(&[
        "simulate", &path, "--t-end", "0.7", "--steps", "7", "--step", "0.03",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (_, rows) = csv_rows(&out);
    for (k, row) in rows.iter().enumerate() {
        let t: f64 = row[0].parse().unwrap();
        assert_eq!(
            t.to_bits(),
            sample_time(0.0, 0.7, 7, k).to_bits(),
            "row {k}"
        );
    }
}

#[test]
fn energies_match_their_closed_forms_and_the_total_is_kept() {
    // A large swing, undamped integrator: kinetic + gravity stays constant to O(h²).
    let theta0 = 1.0;
    let path = pendulum("energy.mech", theta0);
    let out = mechgen(&[
        "simulate",
        &path,
        "--t-end",
        "2",
        "--steps",
        "200",
        "--step",
        "1e-3",
        "--rho-inf",
        "1",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (header, rows) = csv_rows(&out);
    let names = [
        "arm.theta",
        "swing.rate",
        "energy.kinetic",
        "energy.gravity",
        "energy.springs",
        "energy.loads_work",
        "energy.drivers_work",
        "energy.dissipated",
        "energy.total",
    ];
    let scale = M * G * L * (1.0 - theta0.cos()); // the largest kinetic energy
    let table = table(&header, &rows, &names);
    let total0 = table[0][8];
    for (k, row) in table.iter().enumerate() {
        let [
            theta,
            rate,
            kinetic,
            gravity,
            springs,
            loads,
            drivers,
            dissipated,
            total,
        ] = row[..]
        else {
            panic!("nine columns");
        };
        let expected = 0.5 * (J + M * L * L) * rate * rate;
        assert!(
            (kinetic - expected).abs() < 1e-9 * scale,
            "row {k}: {kinetic} vs {expected}"
        );
        let expected = -M * G * L * theta.cos();
        assert!(
            (gravity - expected).abs() < 1e-9 * scale,
            "row {k}: {gravity} vs {expected}"
        );
        assert_eq!([springs, loads, dissipated], [0.0; 3], "row {k}: none here");
        // No driver either: what is left is the work of the free equation's residual effort
        // (zero to the Newton tolerance; measured about 5e-12 of the scale).
        assert!(
            drivers.abs() < 1e-10 * scale,
            "row {k}: drivers' work {drivers}"
        );
        let sum = kinetic + gravity;
        assert!(
            (total - sum).abs() < 1e-9 * scale,
            "row {k}: the total is their sum"
        );
        // (ωh)² / 12 ≈ 7e-6: the trapezoidal rule's energy error on this pendulum.
        assert!(
            (total - total0).abs() < 1e-4 * scale,
            "row {k}: {total} vs {total0}"
        );
    }
}

#[test]
fn a_damper_dissipates_what_the_motion_loses() {
    // A 0.3 rad swing against a spring-damper to the side of the pivot.
    let source = PENDULUM.replace("theta0 = 0.01", "theta0 = 0.3").replace(
        "    gravity",
        "    load coil: spring(frame @ (100, 0), arm, stiffness 50, length 100, damping 2);\n    \
             gravity",
    );
    let path = scratch("damped.mech");
    std::fs::write(&path, source).expect("scene written");
    let path = path.to_str().expect("UTF-8 path");
    let out = mechgen(&[
        "simulate", path, "--t-end", "2", "--steps", "40", "--rtol", "1e-10",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (header, rows) = csv_rows(&out);
    let names = [
        "energy.kinetic",
        "energy.gravity",
        "energy.springs",
        "energy.dissipated",
        "energy.total",
    ];
    let table = table(&header, &rows, &names);
    let (first, last) = (&table[0], &table[table.len() - 1]);
    // Energy went into the damper, and the balance counts it.
    assert!(last[3] > 0.0, "dissipated {}", last[3]);
    assert!(
        table.windows(2).all(|w| w[1][3] >= w[0][3]),
        "dissipation never decreases"
    );
    let lost = first[..3].iter().sum::<f64>() - last[..3].iter().sum::<f64>();
    // The dissipation is a quadrature of the damper's power over each step: O(h²).
    assert!(
        (lost - last[3]).abs() < 1e-3 * lost,
        "lost {lost}, dissipated {}",
        last[3]
    );
    assert!((last[4] - first[4]).abs() < 1e-3 * lost);
}

#[test]
fn the_pivot_carries_the_pendulum() {
    // Newton on the arm: the force it exerts on the frame is M g − M a_c, with a_c from the
    // reduced equation (J + M L²) θ̈ = −M g L sin θ.
    let path = pendulum("pivot.mech", 0.5);
    let out = mechgen(&[
        "simulate", &path, "--t-end", "0.5", "--steps", "10", "--rtol", "1e-10",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (header, rows) = csv_rows(&out);
    let names = [
        "arm.theta",
        "arm.theta_dot",
        "pivot.fx",
        "pivot.fy",
        "swing.effort",
    ];
    for (k, row) in table(&header, &rows, &names).iter().enumerate() {
        let [theta, rate, pivot_fx, pivot_fy, effort] = row[..] else {
            panic!("five columns");
        };
        let accel = -M * G * L * theta.sin() / (J + M * L * L);
        // Centre of mass (L sin θ, −L cos θ).
        let ax = L * (accel * theta.cos() - rate * rate * theta.sin());
        let ay = L * (accel * theta.sin() + rate * rate * theta.cos());
        let (fx, fy) = (-M * ax, -M * G - M * ay);
        let scale = M * G;
        assert!(
            (pivot_fx - fx).abs() < 1e-6 * scale,
            "row {k}: fx {pivot_fx} vs {fx}"
        );
        assert!(
            (pivot_fy - fy).abs() < 1e-6 * scale,
            "row {k}: fy {pivot_fy} vs {fy}"
        );
        // A free coordinate needs no effort: that is its equation of motion.
        assert!(effort.abs() < 1e-6 * scale * L, "row {k}: effort {effort}");
    }
}

#[test]
fn json_is_one_document_with_energies_free_states_and_totals() {
    let path = pendulum("json.mech", 0.01);
    let args = ["simulate", path.as_str(), "--t-end", "0.5", "--steps", "5"];
    let out = mechgen(&[&args[..], &["--format", "json"]].concat());
    assert!(out.status.success(), "{}", text(&out.stderr));
    let document: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", text(&out.stdout)));
    assert_eq!(document["mechanism"], "Pendulum");
    assert_eq!(document["outputs"], "Forces");
    assert_eq!(document["energy"][0], "energy.kinetic");
    assert_eq!(document["energy"][6], "energy.total");
    assert_eq!(
        document["free"],
        serde_json::json!(["swing.value", "swing.rate"])
    );
    assert!(document["error"].is_null());
    let stats = &document["stats"];
    let steps = stats["steps"].as_u64().expect("steps");
    assert!(steps >= 5, "at least one step per output: {steps}");
    for key in ["rejected", "iterations", "factorizations"] {
        assert!(stats[key].is_u64(), "{key}: {stats}");
    }
    let states = document["states"].as_array().expect("states");
    assert_eq!(states.len(), 6);
    assert_eq!(states[5]["t"], 0.5);
    // The same doubles as the CSV of the same run, bit for bit.
    let csv = mechgen(&args);
    let (header, rows) = csv_rows(&csv);
    let first_energy = header.iter().position(|h| h == "energy.kinetic").unwrap();
    for (state, row) in states.iter().zip(&rows) {
        let energy = state["energy"].as_array().expect("energies");
        let free = state["free"].as_array().expect("free states");
        assert_eq!((energy.len(), free.len()), (7, 2));
        let values = energy.iter().chain(free).map(|v| v.as_f64().unwrap());
        for (j, value) in values.enumerate() {
            let written: f64 = row[first_energy + j].parse().unwrap();
            assert_eq!(
                value.to_bits(),
                written.to_bits(),
                "column {}",
                header[first_energy + j]
            );
        }
    }
}

#[test]
fn a_scene_without_free_degrees_of_freedom_is_refused() {
    let out = mechgen(&[
        "simulate",
        &scene("piston_crank_dynamics.mech"),
        "--at",
        "0,0.01",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let message = text(&out.stderr);
    for expected in [
        "`PistonCrankDynamics` has no free degrees of freedom",
        "free NAME: angle(body);",
        "use `mechgen solve`",
        "Usage: mechgen simulate",
    ] {
        assert!(message.contains(expected), "{expected:?} in {message}");
    }
    assert!(out.stdout.is_empty());
}

#[test]
fn bad_flags_exit_2_and_say_what_to_give() {
    let path = pendulum("flags.mech", 0.01);
    let run = |flags: &[&str]| {
        let out = mechgen(
            &[
                &["simulate", path.as_str(), "--t-end", "1", "--steps", "2"],
                flags,
            ]
            .concat(),
        );
        assert_eq!(
            out.status.code(),
            Some(2),
            "{flags:?}: {}",
            text(&out.stderr)
        );
        assert!(out.stdout.is_empty());
        text(&out.stderr)
    };
    assert!(run(&["--rtol", "0"]).contains("not positive"));
    assert!(run(&["--rtol", "2"]).contains("below 1"));
    assert!(run(&["--atol", "-1"]).contains("not positive"));
    assert!(run(&["--step", "0"]).contains("not positive"));
    assert!(run(&["--rho-inf", "1.1"]).contains("outside [0, 1]"));
    assert!(run(&["--step", "1e-3", "--rtol", "1e-6"]).contains("cannot be used with"));
    assert!(run(&["--diagnostics"]).contains("unexpected argument"));
    let endless = run(&["--step", "1e-12"]);
    assert!(
        endless.contains("1.0e12 steps") && endless.contains("leave out `--step`"),
        "{endless}"
    );
    let set = run(&["--set", "theta=1"]);
    assert!(
        set.contains("did you mean `theta0`?") && set.contains("Usage: mechgen simulate"),
        "{set}"
    );
}

#[test]
fn a_start_that_cannot_assemble_leaves_the_csv_file_alone() {
    // The tip of a 200 mm pendulum cannot reach 500 mm below the pivot.
    let source = PENDULUM.replace(
        "free swing: angle(arm) from theta0;",
        "free reach: y(arm @ (0, -100)) from -500;",
    );
    let path = scratch("unreachable.mech");
    std::fs::write(&path, source).expect("scene written");
    let path = path.to_str().expect("UTF-8 path");
    let csv = scratch("unreachable.csv");
    std::fs::write(&csv, "kept\n").unwrap();
    let out = mechgen(&[
        "simulate",
        path,
        "--at",
        "0,0.1",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let message = text(&out.stderr);
    assert!(
        message.contains("cannot start the simulation of `Pendulum` at t = 0"),
        "{message}"
    );
    assert!(message.contains("hint: "), "{message}");
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), "kept\n");
    // JSON records the failure at step 0, with no states.
    let out = mechgen(&["simulate", path, "--at", "0,0.1", "--format", "json"]);
    assert_eq!(out.status.code(), Some(1));
    let document: serde_json::Value = serde_json::from_slice(&out.stdout).expect("a document");
    assert_eq!(document["states"].as_array().map(Vec::len), Some(0));
    assert_eq!(document["error"]["step"], 0);
    let _ = std::fs::remove_file(&csv);
}

#[test]
fn a_motion_that_fails_part_way_ends_its_document_with_the_error() {
    // The torque is NaN after t = 0.25 (and negligible before).
    let source = PENDULUM.replace(
        "    gravity",
        "    load push: torque(arm) = sqrt(0.25 - t);\n    gravity",
    );
    let path = scratch("nan_torque.mech");
    std::fs::write(&path, source).expect("scene written");
    let path = path.to_str().expect("UTF-8 path");
    let out = mechgen(&[
        "simulate",
        path,
        "--at",
        "0,0.1,0.2,0.3",
        "--format",
        "json",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let message = text(&out.stderr);
    assert!(
        message.contains("simulation failed at output 3 of 3"),
        "{message}"
    );
    assert!(
        message.contains("note: wrote 3 rows to stdout"),
        "{message}"
    );
    let document: serde_json::Value = serde_json::from_slice(&out.stdout).expect("a document");
    assert_eq!(document["states"].as_array().map(Vec::len), Some(3));
    assert_eq!(document["error"]["step"], 3);
    assert!(!document["error"]["kind"].is_null());
    assert!(document["stats"]["steps"].as_u64().is_some_and(|s| s > 0));
}
