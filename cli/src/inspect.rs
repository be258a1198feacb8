//! `mechgen check`: a readable summary of a compiled scene (coordinates, equations, degrees of
//! freedom, Jacobian sparsity, length scale, parameters, branch invariants) and, with `--stats`,
//! the solve structure (stages, block sizes, fill-in) and the operation counts of the generated
//! functions.

use core::fmt::{self, Write};

use mechgen::Scene;
use mechgen::model::ConstraintKind;

/// The `check` report for a scene read from `file`.
pub fn report(scene: &Scene, file: &str, stats: bool) -> String {
    let mut out = String::new();
    // Writing to a String cannot fail.
    let _ = write_report(&mut out, scene, file, stats);
    out
}

fn write_report(out: &mut String, scene: &Scene, file: &str, stats: bool) -> fmt::Result {
    let model = &scene.model;
    let n = model.dim();
    let moving = model.bodies.iter().filter(|b| !b.ground).count();
    let ground = model.bodies.len() - moving;
    writeln!(
        out,
        "mechanism {} ({file}): {} bodies ({moving} moving, {ground} ground), {} constraints",
        model.name,
        model.bodies.len(),
        model.constraints.len()
    )?;

    let coordinates = model.coordinate_names();
    writeln!(out, "\ncoordinates ({}):", coordinates.len())?;
    numbered(out, &coordinates)?;
    let equations = model.equation_names();
    writeln!(out, "\nequations ({}):", equations.len())?;
    numbered(out, &equations)?;

    let joint_equations: usize = model
        .constraints
        .iter()
        .filter(|c| {
            matches!(
                c.kind,
                ConstraintKind::Revolute { .. }
                    | ConstraintKind::Prismatic { .. }
                    | ConstraintKind::Distance { .. }
            )
        })
        .map(|c| c.kind.equation_suffixes().len())
        .sum();
    // Signed: an inconsistent model would go negative (check rejects those, but say it right).
    let dof = 3 * moving as i64 - joint_equations as i64;
    let drivers = model.driver_count();
    let verdict = if dof == drivers as i64 {
        "matched by"
    } else {
        "but the scene has"
    };
    let plural = |k: usize| if k == 1 { "" } else { "s" };
    writeln!(
        out,
        "\ndegrees of freedom: {dof} (Gruebler: 3 × {moving} moving bod{} − {joint_equations} \
         joint equation{} = {dof}), {verdict} {drivers} driver{}",
        if moving == 1 { "y" } else { "ies" },
        plural(joint_equations),
        plural(drivers)
    )?;

    let nonzeros = scene.kinematics.jacobian.len();
    let total = n * n;
    let percent = if total == 0 {
        0.0
    } else {
        100.0 * nonzeros as f64 / total as f64
    };
    writeln!(
        out,
        "Jacobian Φ_q: {nonzeros} structural non-zeros of {total} ({n} × {n}), {percent:.1}% dense"
    )?;

    let env = mechgen::interpret::Env {
        params: model.params.iter().map(|p| p.default).collect(),
        ..Default::default()
    };
    let scale = &scene.kinematics.length_scale;
    let dependent: Vec<f64> = scale
        .dependent
        .iter()
        .map(|&id| mechgen::interpret::eval(&model.arena, id, &env))
        .collect();
    writeln!(
        out,
        "length scale: {} (largest geometric length{})",
        scale.evaluate(&dependent),
        if dependent.is_empty() {
            ""
        } else {
            ", with the parameters' defaults"
        }
    )?;

    if model.params.is_empty() {
        writeln!(out, "\nparameters: none")?;
    } else {
        writeln!(out, "\nparameters ({}):", model.params.len())?;
        let width = model.params.iter().map(|p| p.name.to_string().len()).max();
        for p in &model.params {
            let name = p.name.to_string();
            writeln!(out, "  {name:<w$} = {}", p.default, w = width.unwrap_or(0))?;
        }
    }

    if !model.branches.is_empty() {
        writeln!(out, "\nbranch invariants ({}):", model.branches.len())?;
        for b in &model.branches {
            writeln!(out, "  {}: {}", b.name, model.describe_branch(b))?;
        }
    }

    if stats {
        write_stats(out, scene)?;
    }
    Ok(())
}

fn numbered(out: &mut String, names: &[String]) -> fmt::Result {
    let width = names.len().saturating_sub(1).to_string().len();
    for (index, name) in names.iter().enumerate() {
        writeln!(out, "  {index:>width$}  {name}")?;
    }
    Ok(())
}

fn write_stats(out: &mut String, scene: &Scene) -> fmt::Result {
    writeln!(out, "\nsolve structure:")?;
    for line in mechgen::stats::structure(scene).lines() {
        writeln!(out, "  {line}")?;
    }
    writeln!(
        out,
        "\noperation counts per generated function (each shared sub-expression once):"
    )?;
    for line in mechgen::stats::table(scene).lines() {
        writeln!(out, "  {line}")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = "mechanism Pendulum {
        param l = 2;
        ground frame at (0, 0, 0);
        body rod near (1, 0, 0);
        joint pivot: revolute(frame, rod @ (-l, 0));
        driver swing: angle(rod) = sin(t);
        branch hanging: cross(frame -> rod @ (-l, 0), rod -> rod @ (1, 0)) < 0;
    }";

    #[test]
    fn reports_structure_and_counts() {
        let scene = mechgen::compile_str(SCENE).expect("compiles");
        let text = report(&scene, "p.mech", true);
        assert!(text.contains("coordinates (6):\n  0  frame.x\n"), "{text}");
        assert!(text.contains("equations (6):"), "{text}");
        assert!(
            text.contains("degrees of freedom: 1 (Gruebler: 3 × 1 moving body − 2"),
            "{text}"
        );
        assert!(text.contains("matched by 1 driver\n"), "{text}");
        assert!(text.contains("  l = 2\n"), "{text}");
        assert!(
            text.contains("length scale: 2 (largest geometric length, with the parameters'"),
            "{text}"
        );
        assert!(
            text.contains(
                "branch invariants (1):\n  hanging: cross(frame -> rod @ (…), rod -> rod @ (1, 0)) < 0\n"
            ),
            "{text}"
        );
        assert!(text.contains("function"), "{text}");
        assert!(
            text.contains("solve structure:\n  6 coordinates in 2 stages: 6 explicit (3 fixed)"),
            "{text}"
        );

        let counts = mechgen::stats::function_counts(&scene);
        let names: Vec<_> = counts.iter().map(|f| f.function).collect();
        assert_eq!(
            names,
            ["phi", "jacobian", "phi_and_jacobian", "nu", "gamma"]
        );
        let nonzeros = scene.kinematics.jacobian.len();
        assert_eq!(counts[1].outputs, nonzeros);
        assert_eq!(counts[2].outputs, counts[0].outputs + nonzeros);
        // sin θ and cos θ of the rod, shared.
        assert_eq!(counts[0].counts.trig, 3, "{:?}", counts[0]);
    }
}
