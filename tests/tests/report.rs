//! The accuracy-against-run-time report (`mechgen_examples::report`) on its quick plan: it writes
//! its files, and the errors it lists agree with what the closed form allows (exact Jacobians
//! reach round-off, finite differences do not beat them, nothing is non-finite).

use std::path::PathBuf;

use mechgen_examples::report::{self, Method, Options};

/// A fresh directory under the system's temporary directory.
fn temp_dir() -> PathBuf {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    std::env::temp_dir().join(format!("mechgen-report-{}-{nanos}", std::process::id()))
}

#[test]
fn quick_report_writes_files_consistent_with_the_closed_form() {
    let out = temp_dir();
    let options = Options {
        out: out.clone(),
        quick: true,
        scenes: Vec::new(),
    };
    let (mut calls, mut last) = (0, (0, 0));
    let report = report::run(&options, &mut |p| {
        calls += 1;
        last = (p.done, p.total);
    })
    .expect("report written");
    assert!(
        calls > 1 && last.0 == last.1 && last.1 > 0,
        "{calls} {last:?}"
    );

    // The files, with the seed's chart embedded in the Markdown.
    let readme = std::fs::read_to_string(out.join("README.md")).expect("README.md");
    for slug in ["seed", "four_bar"] {
        let svg = std::fs::read_to_string(out.join(format!("{slug}.svg"))).expect("chart");
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("error against time per step"));
        assert!(
            readme.contains(&format!("({slug}.svg)")),
            "{slug} not embedded"
        );
    }
    for method in Method::ALL {
        assert!(readme.contains(method.label()), "{method} missing");
    }
    assert!(readme.contains("## Summary") && readme.contains("How the numbers were measured"));
    // The seed's force solve: every method against the closed-form inverse dynamics.
    assert!(readme.contains("### Forces"));
    let forces = report
        .forces
        .as_ref()
        .expect("the seed ran, with its forces");
    assert_eq!(forces.rows.len(), 3);
    for row in &forces.rows {
        let error = row.error.as_ref().unwrap_or_else(|e| panic!("{e}"));
        assert!(*error <= 1e-10, "{}: {error:e}", row.method);
        assert!(row.seconds_per_step.is_finite() && row.seconds_per_step > 0.0);
    }
    assert!(forces.kinematic.is_finite() && forces.kinematic > 0.0);

    // The measurements behind them.
    assert_eq!(report.scenes.len(), 2);
    for scene in &report.scenes {
        let settings = report.plan.settings();
        assert_eq!(scene.points.len(), settings.len() * Method::ALL.len());
        for point in &scene.points {
            let m = point
                .outcome
                .as_ref()
                .unwrap_or_else(|e| panic!("{} {:?}: {e}", scene.slug, point.setting));
            let e = &m.errors;
            assert!(
                e.q.is_finite() && e.qd.is_finite() && e.qdd.is_finite(),
                "{} {:?} {:?}",
                scene.slug,
                point.method,
                point.setting
            );
            assert!(m.seconds_per_step.is_finite() && m.seconds_per_step > 0.0);
            // Every step evaluates its block (the straight step verifies its closed form
            // without applying a Newton update; the sweep applies at least one).
            assert!(m.work.evaluations >= 1.0, "every step evaluates its block");
            // One factorisation per update per block, at most one more at the solution.
            assert!(
                m.work.evaluations >= m.work.iterations,
                "{} {:?}: {:?}",
                scene.slug,
                point.method,
                m.work
            );
        }
        // Exact Jacobians reach round-off at the tight (reference) tolerance.
        for method in [Method::Generated, Method::AutoDiff, Method::Interpreted] {
            let error = scene.at_reference(method).expect("ran").errors.max();
            assert!(error <= 1e-10, "{} {method}: {error:e}", scene.slug);
        }
        // Finite differences never beat the analytic Jacobian at the same setting (at loose
        // tolerances both errors are the same Newton truncation, equal to a few digits: only a
        // clear win would be wrong), and forward differences lose about half the digits in q̇
        // and q̈.
        for setting in &settings {
            let analytic = scene.measured(Method::Generated, setting).expect("ran");
            for method in [Method::ForwardDifference, Method::CentralDifference] {
                let fd = scene.measured(method, setting).expect("ran");
                assert!(
                    fd.errors.max() >= analytic.errors.max() * (1.0 - 1e-3),
                    "{} {method} {setting}: {:e} < {:e}",
                    scene.slug,
                    fd.errors.max(),
                    analytic.errors.max()
                );
            }
        }
        let forward = scene.at_reference(Method::ForwardDifference).expect("ran");
        assert!(forward.errors.max() > 1e-10, "{:e}", forward.errors.max());
        // The time split of the tables was measured.
        assert!(Method::ALL.iter().all(|&m| scene.split(m).is_some()));
    }

    // The CSV lists the same points, and its analytic rows at tolerance 1e-12 are accurate.
    let csv = std::fs::read_to_string(out.join("points.csv")).expect("points.csv");
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let points: usize = report.scenes.iter().map(|s| s.points.len()).sum();
    assert_eq!(rows.len(), points);
    let tight: Vec<f64> = rows
        .iter()
        .filter(|r| r[1] == "generated" && r[2].parse::<f64>().ok() == Some(1e-12))
        .map(|r| r[5].parse().expect("error is a number"))
        .collect();
    assert!(!tight.is_empty());
    assert!(tight.iter().all(|&e| e <= 1e-10), "{tight:?}");

    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn options_reject_unknown_arguments_and_scenes() {
    let parse = |args: &[&str]| Options::from_args(args.iter().map(ToString::to_string));
    let options = parse(&["--quick", "--scene", "seed", "--out", "x"]).expect("valid");
    assert!(options.quick);
    assert_eq!(options.scenes, vec!["seed".to_string()]);
    assert_eq!(options.out, PathBuf::from("x"));
    assert!(parse(&["--scene", "nope"]).is_err());
    assert!(parse(&["--out"]).is_err());
    assert!(parse(&["--bogus"]).is_err());
}
