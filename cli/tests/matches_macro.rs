//! `mechgen solve` on a scene's `.mech` file (interpreter + runtime solver) against the same
//! scene compiled by `mechanism!` (generated code + the same solver): equal to round-off, the
//! force solve's reactions included.

use mechgen_examples::scenes::{FourBar, Hoeken, PistonCrank, PistonCrankDynamics};
use mechgen_runtime::nalgebra::Const;
use mechgen_runtime::{Simulation, Solver, Structured, write_csv_header};

/// Runs the `mechgen` command line in-process (the binary's `main` is a wrapper around this).
fn cli_solve(file: &str, t_end: f64, steps: usize) -> String {
    let path = format!("{}/../examples/scenes/{file}", env!("CARGO_MANIFEST_DIR"));
    let args = [
        "solve",
        &path,
        "--t-end",
        &format!("{t_end:?}"),
        "--steps",
        &steps.to_string(),
    ];
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let status = mechgen_cli::run(args.map(Into::into), &mut out, &mut err);
    assert_eq!(status, 0, "{}", String::from_utf8_lossy(&err));
    String::from_utf8(out).expect("CSV is UTF-8")
}

/// The generated scene over the same times, written by the same CSV code.
fn macro_solve<M: Structured<Dim = Const<N>>, const N: usize>(
    mechanism: M,
    t_end: f64,
    steps: usize,
) -> String {
    let mut csv = String::new();
    write_csv_header(&mechanism, &mut csv).expect("string");
    let mut simulation = Simulation::new(Solver::new(mechanism), 0.0).expect("assembles");
    simulation
        .run(t_end, steps, |state| {
            state.write_csv_row(&mut csv).expect("string")
        })
        .expect("solves");
    csv
}

fn parse(csv: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut lines = csv.lines();
    let header = lines
        .next()
        .expect("header")
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.parse().expect("number")).collect())
        .collect();
    (header, rows)
}

/// Same header, same times to the bit, and every value equal to 1e-12 of the largest magnitude
/// of its quantity (q, q̇, q̈ or the reactions: `groups` of them) over the motion: columns that
/// are zero in exact arithmetic hold round-off noise, so a per-column scale would be
/// meaningless.
fn assert_round_off_equal(cli: &str, generated: &str, groups: usize) {
    let (cli_header, cli_rows) = parse(cli);
    let (gen_header, gen_rows) = parse(generated);
    assert_eq!(cli_header, gen_header);
    assert_eq!(cli_rows.len(), gen_rows.len());
    let n = (cli_header.len() - 1) / groups;
    let quantity = |column: usize| (column.max(1) - 1) / n;
    let mut scales = vec![0.0f64; groups];
    for row in &gen_rows {
        for (column, value) in row.iter().enumerate().skip(1) {
            scales[quantity(column)] = scales[quantity(column)].max(value.abs());
        }
    }
    for column in 0..cli_header.len() {
        let scale = if column == 0 {
            1.0
        } else {
            scales[quantity(column)]
        };
        let worst = cli_rows
            .iter()
            .zip(&gen_rows)
            .fold(0.0f64, |m, (a, b)| m.max((a[column] - b[column]).abs()));
        if column == 0 {
            assert_eq!(worst, 0.0, "sample times differ");
        }
        assert!(
            worst <= 1e-12 * scale,
            "{}: differs by {worst:e} at scale {scale:e}",
            cli_header[column]
        );
    }
}

#[test]
fn seed_cli_matches_generated_code() {
    let period = 2.0 * std::f64::consts::PI / 314.0;
    let cli = cli_solve("piston_crank.mech", period, 360);
    let generated = macro_solve(PistonCrank::default(), period, 360);
    assert_round_off_equal(&cli, &generated, 3);
}

#[test]
fn seed_forces_cli_matches_generated_code() {
    let period = 2.0 * std::f64::consts::PI / 314.0;
    let cli = cli_solve("piston_crank_dynamics.mech", period, 360);
    let generated = macro_solve(PistonCrankDynamics::default(), period, 360);
    assert!(
        cli.lines()
            .next()
            .is_some_and(|h| h.ends_with("crank_angle.effort"))
    );
    assert_round_off_equal(&cli, &generated, 4);
}

#[test]
fn four_bar_cli_matches_generated_code() {
    let period = 2.0 * std::f64::consts::PI / 10.0;
    let cli = cli_solve("four_bar.mech", period, 180);
    let generated = macro_solve(FourBar::default(), period, 180);
    assert_round_off_equal(&cli, &generated, 3);
}

#[test]
fn hoeken_markers_cli_matches_generated_code() {
    // Markers follow the kinematics: the tracer's position and rates, then the transmission
    // angle's. Lengths are crank lengths (O(1)), so each column is held to 1e-12 of its
    // largest magnitude or of 1.
    let period = 2.0 * std::f64::consts::PI;
    let cli = cli_solve("hoeken.mech", period, 120);
    let generated = macro_solve(Hoeken::default(), period, 120);
    let (cli_header, cli_rows) = parse(&cli);
    let (gen_header, gen_rows) = parse(&generated);
    assert_eq!(cli_header, gen_header);
    let markers = [
        "tracer.x",
        "tracer.y",
        "tracer.x_dot",
        "tracer.y_dot",
        "tracer.x_ddot",
        "tracer.y_ddot",
        "transmission.angle",
        "transmission.angle_dot",
        "transmission.angle_ddot",
    ];
    assert_eq!(cli_header[cli_header.len() - markers.len()..], markers);
    for (column, name) in cli_header.iter().enumerate() {
        let scale = gen_rows.iter().fold(1.0f64, |m, r| m.max(r[column].abs()));
        let worst = cli_rows
            .iter()
            .zip(&gen_rows)
            .fold(0.0f64, |m, (a, b)| m.max((a[column] - b[column]).abs()));
        assert!(worst <= 1e-12 * scale, "{name}: differs by {worst:e}");
    }
}
