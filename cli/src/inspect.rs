//! `mechgen check`: a readable summary of a compiled scene (coordinates, equations, degrees of
//! freedom, Jacobian sparsity, length scale, parameters, branch invariants, and what produces
//! the forces and which reactions a scene with forces reports) and, with `--stats`,
//! the solve structure (stages, block sizes, fill-in) and the operation counts of the generated
//! functions.

use core::fmt::{self, Write};

use mechgen::Scene;
use mechgen::expr::tape::Env;
use mechgen::model::{ConstraintKind, Model};
use serde::Serialize;

/// What `check` reports about a scene, rendered as text ([`report`]) or JSON ([`json`]; the
/// schema is this structure, field for field).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// The mechanism's name.
    pub mechanism: String,
    /// Where it was read from.
    pub file: String,
    /// Moving bodies.
    pub moving_bodies: usize,
    /// Ground (fixed) bodies.
    pub ground_bodies: usize,
    /// Joints, drivers and ground constraints.
    pub constraints: usize,
    /// Coordinate names in q order (`piston.x`).
    pub coordinates: Vec<String>,
    /// Equation names in Φ order (`crank_pin.x`).
    pub equations: Vec<String>,
    /// Degrees of freedom by Gruebler's count: 3 × moving bodies − joint equations.
    pub degrees_of_freedom: i64,
    /// Joint equations in that count.
    pub joint_equations: usize,
    /// Drivers (equal to the degrees of freedom in a valid scene).
    pub drivers: usize,
    /// Structural non-zeros of Φ_q.
    pub jacobian_nonzeros: usize,
    /// The scene's length scale, with the parameters' defaults.
    pub length_scale: f64,
    /// Parameters with their defaults, in declaration order.
    pub parameters: Vec<Parameter>,
    /// Derived parameters (computed from the others), with their values at the defaults.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub derived_parameters: Vec<Parameter>,
    /// Branch invariants as written.
    pub branches: Vec<Branch>,
    /// For a scene that computes forces: what produces them and the reactions it reports.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub forces: Option<ForceSummary>,
}

/// What produces a scene's forces, and what it reports.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ForceSummary {
    /// Moving bodies with mass properties.
    pub bodies_with_mass: Vec<String>,
    /// Gravity in world axes, with the parameters' defaults.
    pub gravity: [f64; 2],
    /// Loads by name.
    pub loads: Vec<String>,
    /// The reaction each equation reports, in Φ order (`crank_pin.fx`, …).
    pub reactions: Vec<String>,
}

/// A parameter and its default.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Parameter {
    /// Its name.
    pub name: String,
    /// Its default value.
    pub default: f64,
}

/// A branch invariant.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Branch {
    /// Its name.
    pub name: String,
    /// The invariant, as the spec writes it.
    pub invariant: String,
}

/// The facts `check` reports about `scene`, read from `file`.
pub fn summary(scene: &Scene, file: &str) -> Summary {
    let model = &scene.model;
    let moving = model.bodies.iter().filter(|b| !b.ground).count();
    let joint_equations = joint_equations(model);
    let env = Env {
        params: model.params.iter().map(|p| p.default).collect(),
        ..Default::default()
    };
    Summary {
        mechanism: model.name.to_string(),
        file: file.to_owned(),
        moving_bodies: moving,
        ground_bodies: model.bodies.len() - moving,
        constraints: model.constraints.len(),
        coordinates: model.coordinate_names(),
        equations: model.equation_names(),
        // Signed: an inconsistent model would go negative (check rejects those).
        degrees_of_freedom: 3 * moving as i64 - joint_equations as i64,
        joint_equations,
        drivers: model.driver_count(),
        jacobian_nonzeros: scene.kinematics.jacobian.len(),
        length_scale: length_scale(scene, &env),
        parameters: model
            .params
            .iter()
            .map(|p| Parameter {
                name: p.name.to_string(),
                default: p.default + 0.0,
            })
            .collect(),
        derived_parameters: model
            .derived
            .iter()
            .map(|d| Parameter {
                name: d.name.to_string(),
                default: mechgen::expr::tape::eval(&model.arena, d.value, &env) + 0.0,
            })
            .collect(),
        branches: model
            .branches
            .iter()
            .map(|b| Branch {
                name: b.name.clone(),
                invariant: model.describe_branch(b),
            })
            .collect(),
        forces: scene.forces.as_ref().map(|_| force_summary(model, &env)),
    }
}

/// Equations of the joints (drivers and the ground's fixing excluded): the Gruebler count's.
fn joint_equations(model: &Model) -> usize {
    model
        .constraints
        .iter()
        .filter(|c| {
            !matches!(
                c.kind,
                ConstraintKind::Ground { .. } | ConstraintKind::Driver { .. }
            )
        })
        .map(|c| c.kind.equation_suffixes().len())
        .sum()
}

/// The scene's length scale with the parameters' defaults in `env`.
fn length_scale(scene: &Scene, env: &Env) -> f64 {
    let scale = &scene.kinematics.length_scale;
    let dependent: Vec<f64> = scale
        .dependent
        .iter()
        .map(|&id| mechgen::expr::tape::eval(&scene.model.arena, id, env))
        .collect();
    scale.evaluate(&dependent)
}

/// What produces the forces of a scene that computes them, with the parameters' defaults in
/// `env`.
fn force_summary(model: &Model, env: &Env) -> ForceSummary {
    ForceSummary {
        bodies_with_mass: model
            .bodies
            .iter()
            .filter(|b| b.mass.is_some())
            .map(|b| b.name.to_string())
            .collect(),
        // `+ 0.0`: no `-0` in the report (a gravity `(0, -9810)` folds its x to −0).
        gravity: model
            .gravity
            .map(|g| mechgen::expr::tape::eval(&model.arena, g, env) + 0.0),
        loads: model.loads.iter().map(|l| l.name.clone()).collect(),
        reactions: model.reaction_names(),
    }
}

/// The [`Summary`] as pretty-printed JSON.
pub fn json(scene: &Scene, file: &str) -> String {
    // Plain data (strings, numbers, vectors) always serialises.
    serde_json::to_string_pretty(&summary(scene, file)).unwrap_or_default() + "\n"
}

/// The `check` report for a scene read from `file`.
pub fn report(scene: &Scene, file: &str, stats: bool) -> String {
    let mut out = String::new();
    // Writing to a String cannot fail.
    let _ = write_report(&mut out, scene, &summary(scene, file), stats);
    out
}

fn write_report(out: &mut String, scene: &Scene, s: &Summary, stats: bool) -> fmt::Result {
    writeln!(
        out,
        "mechanism {} ({}): {} bodies ({} moving, {} ground), {} constraints",
        s.mechanism,
        s.file,
        s.moving_bodies + s.ground_bodies,
        s.moving_bodies,
        s.ground_bodies,
        s.constraints
    )?;
    writeln!(out, "\ncoordinates ({}):", s.coordinates.len())?;
    numbered(out, &s.coordinates)?;
    writeln!(out, "\nequations ({}):", s.equations.len())?;
    numbered(out, &s.equations)?;
    write_mobility(out, scene, s)?;
    write_parameters(out, s)?;
    if !s.branches.is_empty() {
        writeln!(out, "\nbranch invariants ({}):", s.branches.len())?;
        for b in &s.branches {
            writeln!(out, "  {}: {}", b.name, b.invariant)?;
        }
    }
    if let Some(f) = &s.forces {
        write_forces(out, f)?;
    }
    if stats {
        write_stats(out, scene)?;
    }
    Ok(())
}

/// Degrees of freedom against drivers, the Jacobian's sparsity and the length scale.
fn write_mobility(out: &mut String, scene: &Scene, s: &Summary) -> fmt::Result {
    let moving = s.moving_bodies;
    let (dof, joint_equations, drivers) = (s.degrees_of_freedom, s.joint_equations, s.drivers);
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

    let n = s.coordinates.len();
    let (nonzeros, total) = (s.jacobian_nonzeros, n * n);
    let percent = if total == 0 {
        0.0
    } else {
        100.0 * nonzeros as f64 / total as f64
    };
    writeln!(
        out,
        "Jacobian Φ_q: {nonzeros} structural non-zeros of {total} ({n} × {n}), {percent:.1}% dense"
    )?;
    writeln!(
        out,
        "length scale: {} (largest geometric length{})",
        s.length_scale,
        if scene.kinematics.length_scale.dependent.is_empty() {
            ""
        } else {
            ", with the parameters' defaults"
        }
    )
}

/// The parameters with their defaults, then the derived ones with their values.
fn write_parameters(out: &mut String, s: &Summary) -> fmt::Result {
    if s.parameters.is_empty() {
        writeln!(out, "\nparameters: none")?;
    } else {
        writeln!(out, "\nparameters ({}):", s.parameters.len())?;
        aligned(out, &s.parameters)?;
    }
    if !s.derived_parameters.is_empty() {
        writeln!(
            out,
            "derived parameters ({}), computed from those above:",
            s.derived_parameters.len()
        )?;
        aligned(out, &s.derived_parameters)?;
    }
    Ok(())
}

/// `  name = value`, one per line, the `=` aligned.
fn aligned(out: &mut String, parameters: &[Parameter]) -> fmt::Result {
    let width = parameters.iter().map(|p| p.name.len()).max();
    for p in parameters {
        writeln!(
            out,
            "  {:<w$} = {}",
            p.name,
            p.default,
            w = width.unwrap_or(0)
        )?;
    }
    Ok(())
}

/// What produces the forces, and the reactions reported.
fn write_forces(out: &mut String, f: &ForceSummary) -> fmt::Result {
    let list = |names: &[String]| {
        if names.is_empty() {
            "none".to_owned()
        } else {
            names.join(", ")
        }
    };
    writeln!(
        out,
        "\nforces: masses on {}; gravity ({}, {}); loads: {}",
        list(&f.bodies_with_mass),
        f.gravity[0],
        f.gravity[1],
        list(&f.loads)
    )?;
    writeln!(out, "reactions ({}):", f.reactions.len())?;
    numbered(out, &f.reactions)
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
    for line in mechgen::plan::stats::structure(scene).lines() {
        writeln!(out, "  {line}")?;
    }
    writeln!(
        out,
        "\noperation counts per generated function (each shared sub-expression once):"
    )?;
    for line in mechgen::plan::stats::table(scene).lines() {
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
        let scene = mechgen::compile(mechgen::Input::Text(SCENE), &mechgen::Options::default())
            .expect("compiles");
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

        let counts = mechgen::plan::stats::function_counts(&scene);
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

    #[test]
    fn json_holds_the_same_facts() {
        let scene = mechgen::compile(mechgen::Input::Text(SCENE), &mechgen::Options::default())
            .expect("compiles");
        let value: serde_json::Value = serde_json::from_str(&json(&scene, "p.mech")).unwrap();
        assert_eq!(value["mechanism"], "Pendulum");
        assert_eq!(value["coordinates"][0], "frame.x");
        assert_eq!(value["equations"].as_array().map(Vec::len), Some(6));
        assert_eq!(value["degrees_of_freedom"], 1);
        assert_eq!(value["drivers"], 1);
        assert_eq!(value["parameters"][0]["name"], "l");
        assert_eq!(value["parameters"][0]["default"], 2.0);
        assert_eq!(value["length_scale"], 2.0);
        assert_eq!(value["branches"][0]["name"], "hanging");
    }
}
