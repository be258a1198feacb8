//! Writes the report's files: `README.md` (tables, charts embedded, how it was measured),
//! one `<scene>.svg` work-precision diagram per scene, and every point as `points.csv`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

use super::chart::{self, Curve, Key, Marker};
use super::criterion;
use super::{Method, Report, ReportError, SceneReport, Setting};

/// Writes every file of `report` into `report.out` (created if missing); returns their paths.
///
/// # Errors
/// [`ReportError::Io`] or [`ReportError::Plot`].
pub fn write_all(report: &Report) -> Result<Vec<PathBuf>, ReportError> {
    let out = &report.out;
    std::fs::create_dir_all(out).map_err(|e| ReportError::Io(out.clone(), e))?;
    let mut files = Vec::new();
    for scene in &report.scenes {
        let path = out.join(format!("{}.svg", scene.slug));
        write(&path, &chart_svg(scene)?)?;
        files.push(path);
    }
    let csv = out.join("points.csv");
    write(&csv, &points_csv(report))?;
    files.push(csv);
    let readme = out.join("README.md");
    write(&readme, &markdown(report, &criterion::directory()))?;
    files.push(readme);
    Ok(files)
}

fn write(path: &Path, text: &str) -> Result<(), ReportError> {
    std::fs::write(path, text).map_err(|e| ReportError::Io(path.to_path_buf(), e))
}

/// The settings of one curve, in drawing order, with their point annotations.
fn tolerance_sweep(scene: &SceneReport) -> Vec<Setting> {
    let mut settings: Vec<Setting> = distinct_settings(scene)
        .into_iter()
        .filter(|s| s.steps == scene.reference.steps && s.predictor == scene.reference.predictor)
        .collect();
    // Loose to tight.
    settings.sort_by(|a, b| b.tolerance.total_cmp(&a.tolerance));
    settings
}

fn steps_sweep(scene: &SceneReport, predictor: bool) -> Vec<Setting> {
    let mut settings: Vec<Setting> = distinct_settings(scene)
        .into_iter()
        .filter(|s| s.tolerance == scene.reference.tolerance && s.predictor == predictor)
        .collect();
    settings.sort_by_key(|s| s.steps);
    settings
}

fn distinct_settings(scene: &SceneReport) -> Vec<Setting> {
    let mut settings: Vec<Setting> = Vec::new();
    for point in &scene.points {
        if !settings.contains(&point.setting) {
            settings.push(point.setting);
        }
    }
    settings
}

/// The work-precision diagram of a scene.
fn chart_svg(scene: &SceneReport) -> Result<String, ReportError> {
    struct Owned {
        name: &'static str,
        colour: usize,
        marker: Marker,
        dashed: bool,
        points: Vec<(f64, f64)>,
        annotations: Vec<String>,
    }
    let sweeps = [
        (tolerance_sweep(scene), Marker::Circle, false),
        (steps_sweep(scene, true), Marker::Triangle, true),
        (steps_sweep(scene, false), Marker::Cross, true),
    ];
    let mut owned = Vec::new();
    for (index, method) in Method::ALL.into_iter().enumerate() {
        for (k, (settings, marker, dashed)) in sweeps.iter().enumerate() {
            let mut points = Vec::new();
            let mut annotations = Vec::new();
            for setting in settings {
                // A failed point breaks the line (NaN is skipped by the chart).
                let point = scene
                    .measured(method, setting)
                    .map_or((f64::NAN, f64::NAN), |m| {
                        (m.seconds_per_step, m.errors.max())
                    });
                points.push(point);
                // Settings are labelled once, on the generated (reference) curves.
                annotations.push(match (method, k) {
                    (Method::Generated, 0) => format!("{:.0e}", setting.tolerance),
                    (Method::Generated, 1) => setting.steps.to_string(),
                    _ => String::new(),
                });
            }
            owned.push(Owned {
                name: if k == 0 { method.label() } else { "" },
                colour: index,
                marker: *marker,
                dashed: *dashed,
                points,
                annotations,
            });
        }
    }
    let curves: Vec<Curve<'_>> = owned
        .iter()
        .map(|o| Curve {
            name: o.name,
            colour: o.colour,
            marker: o.marker,
            dashed: o.dashed,
            points: &o.points,
            annotations: &o.annotations,
            // Steps left of their points, tolerances right: the two sweeps meet at the
            // reference point.
            annotate_left: o.marker == Marker::Triangle,
        })
        .collect();
    let r = scene.reference;
    let tolerance_key = format!(
        "Newton tolerance {} (labelled on the generated curve where room), {} steps/rev, predictor on",
        range_text(
            tolerance_sweep(scene)
                .iter()
                .map(|s| format!("{:.0e}", s.tolerance))
        ),
        r.steps
    );
    let steps_on = format!(
        "{} steps/rev (labelled likewise), tolerance {:.0e}, predictor on",
        range_text(steps_sweep(scene, true).iter().map(|s| s.steps.to_string())),
        r.tolerance
    );
    let steps_off = "the same, predictor off";
    let keys = [
        Key {
            marker: Marker::Circle,
            dashed: false,
            text: &tolerance_key,
        },
        Key {
            marker: Marker::Triangle,
            dashed: true,
            text: &steps_on,
        },
        Key {
            marker: Marker::Cross,
            dashed: true,
            text: steps_off,
        },
    ];
    let title = format!("{}: error against time per step", scene.title);
    chart::render(&title, &curves, &keys).map_err(ReportError::Plot)
}

/// `first … last` of a list of labels (or the one label).
fn range_text(labels: impl Iterator<Item = String>) -> String {
    let labels: Vec<String> = labels.collect();
    match labels.as_slice() {
        [] => String::new(),
        [one] => one.clone(),
        [first, .., last] => format!("{first} … {last}"),
    }
}

/// Every point as CSV (errors in full precision, times in seconds).
fn points_csv(report: &Report) -> String {
    let mut s = String::from(
        "scene,method,tolerance,steps_per_revolution,predictor,error,error_q,error_qd,error_qdd,\
         seconds_per_step,newton_iterations_per_step,evaluations_per_step,timed_runs,failure\n",
    );
    for scene in &report.scenes {
        for point in &scene.points {
            let st = &point.setting;
            let _ = write!(
                s,
                "{},{},{:e},{},{},",
                scene.slug,
                point.method.slug(),
                st.tolerance,
                st.steps,
                st.predictor
            );
            let _ = match &point.outcome {
                Ok(m) => writeln!(
                    s,
                    "{:e},{:e},{:e},{:e},{:e},{},{},{},",
                    m.errors.max(),
                    m.errors.q,
                    m.errors.qd,
                    m.errors.qdd,
                    m.seconds_per_step,
                    m.work.iterations,
                    m.work.evaluations,
                    m.repetitions
                ),
                // Quotes doubled so that any message stays one CSV field.
                Err(e) => writeln!(s, ",,,,,,,,\"{}\"", e.replace('"', "\"\"")),
            };
        }
    }
    s
}

/// `1.2e-15`, or `—` for a missing value.
fn sci(value: Option<f64>) -> String {
    value.map_or("—".into(), |v| format!("{v:.1e}"))
}

/// A duration in µs with sensible digits, or `—`.
fn micros(seconds: Option<f64>) -> String {
    match seconds {
        Some(s) if s.is_finite() => {
            let us = s * 1e6;
            if us.abs() >= 100.0 {
                format!("{us:.0}")
            } else if us.abs() >= 10.0 {
                format!("{us:.1}")
            } else {
                format!("{us:.2}")
            }
        }
        _ => "—".into(),
    }
}

/// A duration in ns, or `—`.
fn nanos(seconds: Option<f64>) -> String {
    match seconds {
        Some(s) if s.is_finite() => format!("{:.0}", s * 1e9),
        _ => "—".into(),
    }
}

/// The seed-style table at the reference setting, with the time split.
fn reference_table(s: &mut String, scene: &SceneReport) {
    let base = scene
        .at_reference(Method::Generated)
        .map(|m| m.seconds_per_step);
    let _ = writeln!(
        s,
        "| method | max error | q | q̇ | q̈ | µs/step | × generated | Newton it./step | \
         factorisations/step | evaluation | factorisation | solves | rates |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for method in Method::ALL {
        let Some(m) = scene.at_reference(method) else {
            let _ = writeln!(s, "| {} | failed | | | | | | | | | | | |", method.label());
            continue;
        };
        let ratio = base.map_or("—".into(), |b| format!("{:.2}", m.seconds_per_step / b));
        let _ = write!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {:.2} | {:.2} |",
            method.label(),
            sci(Some(m.errors.max())),
            sci(Some(m.errors.q)),
            sci(Some(m.errors.qd)),
            sci(Some(m.errors.qdd)),
            micros(Some(m.seconds_per_step)),
            ratio,
            m.work.iterations,
            m.work.evaluations
        );
        match scene.split(method) {
            Some(split) => {
                // Shares of the pieces' sum, not of the measured step: each piece is timed in
                // isolation (warm caches, its own batches), so the pieces need not add up to
                // the step exactly; their proportions are what the split shows.
                let parts = [
                    split.evaluation,
                    split.factorisation,
                    split.solves,
                    split.rates,
                ];
                let total: f64 = parts.iter().sum();
                for part in parts {
                    let _ = write!(
                        s,
                        " {} ({:.0} %) |",
                        micros(Some(part)),
                        100.0 * part / total
                    );
                }
                s.push('\n');
            }
            None => s.push_str(" — | — | — | — |\n"),
        }
    }
}

/// `fastest / median` of a criterion estimate, or `—`.
fn pair(estimate: Option<criterion::Estimate>, format: fn(Option<f64>) -> String) -> String {
    match estimate {
        Some(e) => format!("{} / {}", format(e.fastest), format(Some(e.seconds))),
        None => "—".into(),
    }
}

/// Per-call figures beside criterion's (when a benchmark run left them).
fn micro_table(s: &mut String, scene: &SceneReport, criterion_dir: &Path) {
    let _ = writeln!(
        s,
        "| method | Φ+Φ_q (ns) | criterion Φ+Φ_q (ns): fastest / median | block evaluation (ns) | \
         factorisation (ns) | solve (ns) | rates (ns) | step (µs) | \
         criterion step (µs): fastest / median |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for method in Method::ALL {
        let micro = scene.micro(method);
        let group = criterion::group(scene.slug, method);
        let bench = |function: &str| criterion::read(criterion_dir, &group, function);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            method.label(),
            nanos(micro.map(|m| m.phi_and_jacobian)),
            pair(bench("phi_and_jacobian"), nanos),
            nanos(micro.map(|m| m.evaluation)),
            nanos(micro.map(|m| m.factorisation)),
            nanos(micro.map(|m| m.solve)),
            nanos(micro.map(|m| m.rates)),
            micros(scene.at_reference(method).map(|m| m.seconds_per_step)),
            pair(bench("step"), micros),
        );
    }
}

/// Every point of a scene.
fn all_points_table(s: &mut String, scene: &SceneReport) {
    let _ = writeln!(
        s,
        "| method | tolerance | steps/rev | predictor | max error | q | q̇ | q̈ | µs/step | \
         × generated | Newton it./step | timed runs |\n\
         |---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for point in &scene.points {
        let st = &point.setting;
        let head = format!(
            "| {} | {:.0e} | {} | {} |",
            point.method.label(),
            st.tolerance,
            st.steps,
            if st.predictor { "on" } else { "off" }
        );
        match &point.outcome {
            Ok(m) => {
                let base = scene.measured(Method::Generated, st);
                let ratio = base.map_or("—".into(), |b| {
                    format!("{:.2}", m.seconds_per_step / b.seconds_per_step)
                });
                let _ = writeln!(
                    s,
                    "{head} {} | {} | {} | {} | {} | {ratio} | {:.2} | {} |",
                    sci(Some(m.errors.max())),
                    sci(Some(m.errors.q)),
                    sci(Some(m.errors.qd)),
                    sci(Some(m.errors.qdd)),
                    micros(Some(m.seconds_per_step)),
                    m.work.iterations,
                    m.repetitions
                );
            }
            Err(e) => {
                let _ = writeln!(
                    s,
                    "{head} failed: {} | | | | | | | |",
                    e.replace('|', "\\|")
                );
            }
        }
    }
}

/// The whole `README.md`.
fn markdown(report: &Report, criterion_dir: &Path) -> String {
    let plan = &report.plan;
    let r = plan.reference;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Accuracy against run time\n\n\
         How accurate each way of solving an example scene is, and what it costs. Generated by \
         `cargo run --release --example report{}` on {} ({}); every figure comes from runs made \
         then: rerunning changes the timings, never the errors or iteration counts.\n",
        if plan.quick { " -- --quick" } else { "" },
        date(SystemTime::now()),
        machine()
    );
    s.push_str(
        "All methods solve the same equations with the same runtime solver (`Solver`, \
         `Simulation`: Newton–Raphson, the same stopping rule, stepping and predictor); they \
         differ in how the solve is structured (the scene's plan of explicit assignments and \
         small blocks, or one dense block), in how Φ_q is obtained, and for the interpreter in \
         how everything is evaluated:\n\n",
    );
    for method in Method::ALL {
        let _ = writeln!(s, "- **{}**: {}", method.label(), method.description());
    }
    let _ = writeln!(
        s,
        "\nEach chart is a work-precision diagram: the largest error over one revolution of q, q̇ \
         and q̈ (each relative to that quantity's largest magnitude, against the closed form) \
         against the time per step (position, velocity and acceleration), both on log scales; \
         down and left is better. Circles sweep the Newton tolerance ({}) at {} steps per \
         revolution with the predictor on; triangles sweep the steps per revolution ({}) at \
         tolerance {:.0e} with the predictor on, crosses the same with it off. The tables give \
         the reference setting: tolerance {:.0e}, {} steps per revolution, predictor on.\n",
        range_text(plan.tolerances.iter().map(|t| format!("{t:.0e}"))),
        r.steps,
        range_text(plan.steps.iter().map(ToString::to_string)),
        r.tolerance,
        r.tolerance,
        r.steps
    );

    for scene in &report.scenes {
        let _ = writeln!(
            s,
            "## {} ({} coordinates)\n\n![{}: error against time per step]({}.svg)\n\n\
             At the reference setting ({}); the last four columns split the step's time (µs per \
             step, and each piece's share of their sum):\n",
            scene.title, scene.coordinates, scene.title, scene.slug, r
        );
        reference_table(&mut s, scene);
        s.push_str(
            "\nPer call, at a solved state a tenth of a revolution in. The criterion columns \
             come from the last `cargo bench -p mechgen-benches --bench kinematics` (— when it \
             has not been run), which times the same calls, and steps at the reference setting: \
             its fastest sample is the figure comparable to this report's (both keep the \
             fastest stretches); its median runs higher on a machine whose speed varies.\n\n",
        );
        micro_table(&mut s, scene, criterion_dir);
        s.push_str("\n<details><summary>Every point</summary>\n\n");
        all_points_table(&mut s, scene);
        s.push_str("\n</details>\n\n");
        if let (Some(forces), "seed") = (&report.forces, scene.slug) {
            forces_section(&mut s, forces);
        }
    }

    let _ = writeln!(
        s,
        "## Summary\n\nAt tolerance {:.0e}, {} steps per revolution, predictor on:\n\n\
         | scene | method | max error | µs/step | × generated | Newton it./step |\n\
         |---|---|---:|---:|---:|---:|",
        r.tolerance, r.steps
    );
    for scene in &report.scenes {
        let base = scene
            .at_reference(Method::Generated)
            .map(|m| m.seconds_per_step);
        for method in Method::ALL {
            match scene.at_reference(method) {
                Some(m) => {
                    let ratio =
                        base.map_or("—".into(), |b| format!("{:.2}", m.seconds_per_step / b));
                    let _ = writeln!(
                        s,
                        "| {} | {} | {} | {} | {ratio} | {:.2} |",
                        scene.title,
                        method.label(),
                        sci(Some(m.errors.max())),
                        micros(Some(m.seconds_per_step)),
                        m.work.iterations
                    );
                }
                None => {
                    let _ = writeln!(s, "| {} | {} | failed | | | |", scene.title, method.label());
                }
            }
        }
    }

    let _ = writeln!(
        s,
        "\n## How the numbers were measured\n\n\
         - **Errors**: one run per point over one revolution (assembly at t = 0 included), each \
         state compared with the closed form (`closed_form.rs`, exact derivatives by dual \
         numbers) using the measure of `accuracy.rs`.\n\
         - **Time per step**: wall time of stepping through the same revolution, assembly \
         excluded, read every {} steps: per stretch of {} steps the fastest of at least {} timed \
         run(s) (more, up to {}, while a point's runs total under {} ms) counts, and the \
         stretches are summed and divided by the steps. Taking the fastest drops interruptions \
         by the rest of the machine; taking it per stretch keeps one busy moment from spoiling \
         a long run. The timed runs go in passes over all points of a scene, so each \
         point's runs are spread over the whole sweep and a slow spell of the machine hits \
         every method alike. Errors are not computed in timed runs.\n\
         - **Newton iterations per step**: updates per step averaged over the revolution (the \
         most any block needed). **Factorisations per step**: evaluations and factorisations of \
         block Jacobians, summed over the blocks: one per update, and one more at the solution \
         unless the last correction was of round-off size (its factors then serve the velocity \
         and acceleration solves).\n\
         - **Time split**: not instrumented inside the loop (a clock read costs as much as a \
         generated Φ). Each piece is timed on its own at one solved state, in {} rounds of one \
         batch of ~{} ms, one round per pass of the timed runs (the fastest round kept, so \
         the pieces and the steps they split are measured over the same stretch of time), and \
         multiplied by the per-step counts above. For the methods solved through the scene's \
         structure (generated, interpreter): evaluation = the block kernels (Φ_b and the \
         block's Jacobian values) and explicit assignments, factorisation = copying the \
         blocks' values and running their static LUs minus the copy alone, solve = one \
         substitution per block, each averaged per block; rates = every stage's velocity and \
         acceleration kernels. For the dense methods: Φ and Φ_q (`phi_and_jacobian`), \
         copying this method's Φ_q into the LU's storage and factoring it (minus the copy \
         alone), one substitution (minus the copy restoring its right-hand side), ν and γ. \
         Evaluations and factorisations count the factorisations per step, solves about one \
         per factorisation plus two per block. The table shows each piece's share of the \
         pieces' sum: timed in isolation, the pieces need not add up to the measured step \
         (the predictor, norms, the condition estimate, finiteness checks and copies are left \
         out; warm, isolated batches can also run faster or slower than inside a step), so the \
         shares, not the remainder, are what the split tells.\n\
         - **Machine**: on a shared or virtual machine the speed can change in spells lasting \
         seconds; absolute times then move between runs by tens of percent, while the ratios \
         between methods, measured side by side, move by a few percent.\n\
         - **Points file**: [`points.csv`](points.csv) has every point in full precision.",
        super::sweep::CHUNK,
        super::sweep::CHUNK,
        plan.min_repetitions,
        plan.max_repetitions,
        plan.budget.as_millis(),
        plan.micro_batches,
        plan.micro_batch.as_secs_f64() * 1e3,
    );
    s
}

/// The seed's force solve: error against the closed-form inverse dynamics, and cost against
/// the kinematic step.
fn forces_section(s: &mut String, forces: &super::forces::ForceReport) {
    let _ = writeln!(
        s,
        "### Forces\n\n\
         The same seed with its mass properties and gravity (`piston_crank_dynamics.mech`), \
         solved for the reaction of every joint, the loads on the frame and the driving torque \
         (`Φ_qᵀ λ = F`, one more solve with the step's factors, in reverse stage order) at the \
         reference setting ({}). The error is the largest over the revolution of any reaction, \
         relative to its largest magnitude, against the closed-form Newton–Euler elimination \
         along the exact motion (`inverse_dynamics.rs`); the time is a whole step with forces, \
         against the kinematic seed's generated step timed in the same passes.\n\n\
         | method | max error of the reactions | µs/step | × kinematic step |\n\
         |---|---:|---:|---:|",
        forces.setting
    );
    for row in &forces.rows {
        match &row.error {
            Ok(error) => {
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {:.2} |",
                    row.method.label(),
                    sci(Some(*error)),
                    micros(Some(row.seconds_per_step)),
                    row.seconds_per_step / forces.kinematic
                );
            }
            Err(message) => {
                let _ = writeln!(s, "| {} | failed: {message} | | |", row.method.label());
            }
        }
    }
    let _ = writeln!(
        s,
        "| kinematic seed, generated (no forces) | | {} | 1.00 |\n",
        micros(Some(forces.kinematic))
    );
}

/// Cores, CPU model, compiler and build profile, as far as cheaply known.
fn machine() -> String {
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            info.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let rustc = std::process::Command::new(std::env::var("RUSTC").unwrap_or("rustc".into()))
        .arg("--version")
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "rustc version unknown".into());
    let profile = if cfg!(debug_assertions) {
        "debug build: timings are not representative"
    } else {
        "release build"
    };
    format!(
        "{cores} core{}, {cpu}, {}, {rustc}, {profile}",
        if cores == 1 { "" } else { "s" },
        std::env::consts::OS
    )
}

/// `YYYY-MM-DD` (UTC) of a time.
fn date(time: SystemTime) -> String {
    let days = time
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs() / 86_400) as i64;
    let (y, m, d) = civil_from_days(days);
    format!("{y:04}-{m:02}-{d:02}")
}

/// Proleptic Gregorian date of a day count since 1970-01-01 (H. Hinnant's algorithm).
fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_are_gregorian() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(19_782), (2024, 2, 29));
        assert_eq!(civil_from_days(-1), (1969, 12, 31));
    }

    #[test]
    fn formats_missing_values_as_dashes() {
        assert_eq!(sci(None), "—");
        assert_eq!(micros(Some(f64::NAN)), "—");
        assert_eq!(micros(Some(3.456e-6)), "3.46");
        assert_eq!(micros(Some(1.5e-4)), "150");
        assert_eq!(nanos(Some(8.04e-8)), "80");
        assert_eq!(
            range_text(["a".to_string(), "b".into(), "c".into()].into_iter()),
            "a … c"
        );
    }
}
