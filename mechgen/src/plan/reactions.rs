//! The force solve's structure: `Φ_qᵀ λ = F` along the kinematic plan, in reverse, and the
//! reactions reported from the multipliers λ.
//!
//! The plan orders Φ_q block lower triangular: a stage's equations read only its own and
//! earlier coordinates. So a stage's coordinates are touched only by its own equations and by
//! later stages', and in reverse stage order each stage's multipliers follow from what the
//! later ones left of the generalised force on its coordinates:
//!
//! - an explicit assignment (equation e assigns coordinate c with constant coefficient a) gives
//!   `λ_e = (F_c − Σ_{i ≠ e} Φ_q[i, c] λ_i) / a` in closed form; assignments of one stage that
//!   read each other are resolved in their dependency order (found here from the expressions,
//!   not assumed from the stage's order) and substituted, so each expression reads only later
//!   stages' multipliers;
//! - a block's right-hand side is `r_c = F_c − Σ_{i later} Φ_q[i, c] λ_i` per coordinate, and
//!   the runtime solves `Φ_q[b, b]ᵀ λ_b = r` with the block's static LU.
//!
//! Fixed coordinates and constant rates are substituted, so the frame, a driven crank's
//! constant speed and the like cost nothing. The plan asserts that no stage's kernel reads a
//! multiplier the reverse sweep has not computed yet: one that did would read whatever an
//! earlier solve left in the buffer, and a reaction would depend on which times were solved
//! before.
//!
//! The reported reaction of each equation is then a simple function of λ: a revolute joint's
//! force on its first body is `−λ`, a prismatic joint's normal force and torque `λ`, a
//! distance joint's tension `2 L λ`, a driver's effort `−λ`, and a ground body's load is what the textbook formulation's multiplier would be,
//! `−Σ_i ∂Φ_i/∂q_ground λ_i` (the joints seen through the frame's coordinates), plus the pull
//! of the springs anchored to it.

use std::collections::HashMap;

use crate::expr::diff::Differentiator;
use crate::expr::{Arena, Id, Var, var_index};
use crate::model::kinematics::Kinematics;
use crate::model::{ConstraintKind, Model};
use crate::plan::structure::{Plan, Stage};

/// A scene's force solve: the generalised forces, the reverse stages and the reported
/// reactions (ids into the model's arena).
#[derive(Debug, Clone)]
pub struct Forces {
    /// `F(q, q̇, q̈, t)` per coordinate (`dynamics`), unsubstituted: the textbook
    /// `generalized_forces` and the dense reference's right-hand side.
    pub generalized: Vec<Id>,
    /// Per stage of the plan, at the same index (the runtime walks them in reverse).
    pub stages: Vec<ForceStage>,
    /// Per equation, its reported reaction, in the multipliers (`Var::Lambda`), q, q̇ (a
    /// damper's pull on the frame) and the parameters.
    pub reactions: Vec<Id>,
}

/// What the force solve computes for one stage.
#[derive(Debug, Clone)]
pub enum ForceStage {
    /// The multiplier of each assignment's equation, in the stage's assignment order, reading
    /// only later stages' multipliers.
    Explicit(Vec<Id>),
    /// The block's force right-hand side, in its local column order.
    Block(Vec<Id>),
}

impl Forces {
    /// The non-zero outputs of the textbook force functions, by name (for operation counts).
    pub fn function_outputs(&self, arena: &Arena) -> Vec<(&'static str, Vec<Id>)> {
        let nonzero = |ids: &[Id]| -> Vec<Id> {
            ids.iter().copied().filter(|&i| !arena.is_zero(i)).collect()
        };
        vec![
            ("generalized_forces", nonzero(&self.generalized)),
            ("reactions", nonzero(&self.reactions)),
        ]
    }
}

/// Plans the force solve of a scene whose generalised forces are `generalized`, adding its
/// expressions to the model's arena.
pub fn plan(model: &mut Model, kin: &Kinematics, plan: &Plan, generalized: Vec<Id>) -> Forces {
    let reactions = reported(model, kin);
    let n = kin.phi.len();
    let mut columns: Vec<Vec<(usize, Id)>> = vec![Vec::new(); n];
    for e in &kin.jacobian {
        columns[e.col].push((e.row, e.value));
    }
    let known = known_values(&model.arena, plan);
    let mut cx = Transpose {
        arena: &mut model.arena,
        known,
        memo: HashMap::new(),
        columns,
        generalized: &generalized,
    };
    let stages: Vec<ForceStage> = plan
        .stages
        .iter()
        .map(|stage| match stage {
            Stage::Explicit(assignments) => {
                let pairs: Vec<(usize, usize)> = assignments
                    .iter()
                    .map(|a| (a.equation, a.coordinate))
                    .collect();
                ForceStage::Explicit(cx.explicit(&pairs))
            }
            Stage::Block(block) => ForceStage::Block(
                block
                    .coordinates
                    .iter()
                    .map(|&c| cx.remainder(c, &block.equations))
                    .collect(),
            ),
        })
        .collect();
    assert_reads_later_stages(&model.arena, plan, &stages, n);
    Forces {
        generalized,
        stages,
        reactions,
    }
}

/// What the plan knows to be constant: fixed positions, and rates that turned out constant
/// (the same substitutions the plan made in its own expressions).
fn known_values(arena: &Arena, plan: &Plan) -> HashMap<Var, Id> {
    let mut known = HashMap::new();
    for a in plan.assignments() {
        let c = var_index(a.coordinate);
        let values = [
            (Var::Q(c), Some(a.position)),
            (Var::Qd(c), a.velocity),
            (Var::Qdd(c), a.acceleration),
        ];
        for (var, value) in values {
            if let Some(value) = value.filter(|&v| arena.is_invariant(v)) {
                known.insert(var, value);
            }
        }
    }
    known
}

/// The reverse sweep's expressions, built over one arena.
struct Transpose<'a> {
    arena: &'a mut Arena,
    /// Constant positions and rates, substituted everywhere.
    known: HashMap<Var, Id>,
    memo: HashMap<Id, Id>,
    /// Each coordinate's Jacobian column: (equation, ∂Φ/∂q) pairs.
    columns: Vec<Vec<(usize, Id)>>,
    generalized: &'a [Id],
}

impl Transpose<'_> {
    /// `e` with the known values substituted.
    fn known(&mut self, e: Id) -> Id {
        self.arena.substitute(e, &self.known, &mut self.memo)
    }

    /// `F_c − Σ Φ_q[i, c] λ_i` over the equations touching coordinate `c` except `own`.
    fn remainder(&mut self, c: usize, own: &[usize]) -> Id {
        let mut rest = self.known(self.generalized[c]);
        for (i, value) in self.columns[c].clone() {
            if own.contains(&i) {
                continue;
            }
            let value = self.known(value);
            let lambda = self.arena.var(Var::Lambda(var_index(i)));
            let term = self.arena.mul(value, lambda);
            rest = self.arena.sub(rest, term);
        }
        rest
    }

    /// The multipliers of an explicit stage's (equation, coordinate) assignments, each divided
    /// by its coefficient and with the stage's own multipliers substituted, in the stage's
    /// assignment order.
    ///
    /// Assignment (e, c) reads the multipliers of the stage's other equations that touch c:
    /// those that read c in the forward sweep. They are resolved first ([`resolution_order`],
    /// over the entries that survive the known values) and substituted, so every expression
    /// reads only later stages' multipliers, whatever order the stage lists its assignments in.
    fn explicit(&mut self, assignments: &[(usize, usize)]) -> Vec<Id> {
        let own: HashMap<Var, usize> = assignments
            .iter()
            .enumerate()
            .map(|(k, &(e, _))| (Var::Lambda(var_index(e)), k))
            .collect();
        let raw: Vec<Id> = assignments
            .iter()
            .map(|&(e, c)| {
                let rest = self.remainder(c, &[e]);
                let coefficient = self.columns[c]
                    .iter()
                    .find(|(i, _)| *i == e)
                    .map(|&(_, v)| v)
                    .expect("the plan assigns a coordinate through an equation that touches it");
                let coefficient = self.known(coefficient);
                divide(self.arena, rest, coefficient)
            })
            .collect();
        let reads: Vec<Vec<usize>> = raw
            .iter()
            .map(|&r| {
                let vars = self.arena.variables(r);
                vars.iter().filter_map(|v| own.get(v).copied()).collect()
            })
            .collect();
        let order = resolution_order(&reads).unwrap_or_else(|| {
            panic!(
                "internal error: the multipliers of the explicit stage {assignments:?} read \
                 each other in a cycle (the forward sweep's order does not transpose)"
            )
        });
        let mut resolved: HashMap<Var, Id> = HashMap::new();
        let mut values = vec![self.arena.zero(); assignments.len()];
        for k in order {
            let value = self
                .arena
                .substitute(raw[k], &resolved, &mut HashMap::new());
            resolved.insert(Var::Lambda(var_index(assignments[k].0)), value);
            values[k] = value;
        }
        values
    }
}

/// An order in which to resolve a stage's multipliers: `reads[k]` lists the assignments whose
/// multipliers assignment k's expression reads, and each comes before k. Among those ready, the
/// last in the stage goes first (the reverse of the forward sweep, when that is an order).
/// `None` if they read each other in a cycle.
fn resolution_order(reads: &[Vec<usize>]) -> Option<Vec<usize>> {
    let n = reads.len();
    let mut waiting: Vec<usize> = reads
        .iter()
        .enumerate()
        .map(|(k, r)| r.iter().filter(|&&i| i != k).count())
        .collect();
    let mut readers = vec![Vec::new(); n];
    for (k, r) in reads.iter().enumerate() {
        for &i in r.iter().filter(|&&i| i != k) {
            readers[i].push(k);
        }
    }
    let mut ready: std::collections::BinaryHeap<usize> =
        (0..n).filter(|&k| waiting[k] == 0).collect();
    let mut order = Vec::with_capacity(n);
    while let Some(k) = ready.pop() {
        order.push(k);
        for &reader in &readers[k] {
            waiting[reader] -= 1;
            if waiting[reader] == 0 {
                ready.push(reader);
            }
        }
    }
    (order.len() == n).then_some(order)
}

/// Asserts what the reverse sweep relies on: every stage's kernel reads only the multipliers
/// of later stages' equations, which the sweep has written before it runs. A violation is a
/// bug in the plan or in this module, and would make a reaction depend on which times were
/// solved before (the buffer still holding an earlier solve's multiplier).
fn assert_reads_later_stages(arena: &Arena, plan: &Plan, stages: &[ForceStage], n: usize) {
    let mut stage_of = vec![usize::MAX; n];
    for (s, stage) in plan.stages.iter().enumerate() {
        let equations: Vec<usize> = match stage {
            Stage::Explicit(assignments) => assignments.iter().map(|a| a.equation).collect(),
            Stage::Block(block) => block.equations.clone(),
        };
        for e in equations {
            stage_of[e] = s;
        }
    }
    for (s, stage) in stages.iter().enumerate() {
        let (ForceStage::Explicit(values) | ForceStage::Block(values)) = stage;
        for &value in values {
            for var in arena.variables(value) {
                if let Var::Lambda(i) = var {
                    let i = i as usize;
                    assert!(
                        stage_of[i] > s && stage_of[i] != usize::MAX,
                        "internal error: the force solve's stage {s} reads the multiplier of \
                         equation {i} (stage {}) before the reverse sweep computes it",
                        stage_of[i]
                    );
                }
            }
        }
    }
}

/// `e / a`, exactly `e` or `−e` for a coefficient of ±1.
fn divide(arena: &mut Arena, e: Id, a: Id) -> Id {
    match arena.as_const(a) {
        Some(1.0) => e,
        Some(-1.0) => arena.neg(e),
        _ => arena.div(e, a),
    }
}

/// The reported reaction of every equation, from its multiplier (and, for a ground body's
/// load, the multipliers of the joints that touch it).
fn reported(model: &mut Model, kin: &Kinematics) -> Vec<Id> {
    let kinds: Vec<ConstraintKind> = model.constraints.iter().map(|c| c.kind).collect();
    let loads = ground_loads(model, kin.phi.len());
    let arena = &mut model.arena;
    let mut reactions = Vec::with_capacity(kin.phi.len());
    for kind in kinds {
        let first = reactions.len();
        let lambda = |arena: &mut Arena, k: usize| arena.var(Var::Lambda(var_index(first + k)));
        match kind {
            ConstraintKind::Ground { body, .. } => {
                reactions.extend((0..3).map(|k| loads[3 * body + k]));
            }
            // The force on the first body: −λ; and a driver's effort, −λ along its coordinate.
            ConstraintKind::Revolute { .. }
            | ConstraintKind::Gear { .. }
            | ConstraintKind::Rack { .. }
            | ConstraintKind::Driver { .. } => {
                for k in 0..kind.equation_suffixes().len() {
                    let l = lambda(arena, k);
                    reactions.push(arena.neg(l));
                }
            }
            ConstraintKind::Prismatic { .. } | ConstraintKind::Slot { .. } => {
                reactions.extend((0..kind.equation_suffixes().len()).map(|k| lambda(arena, k)));
            }
            // The force on the first body at the point, −λ, and its torque, +λ (θ_b − θ_a).
            ConstraintKind::Weld { .. } => {
                for k in 0..2 {
                    let l = lambda(arena, k);
                    reactions.push(arena.neg(l));
                }
                reactions.push(lambda(arena, 2));
            }
            ConstraintKind::Distance { length, .. } => {
                // Φ = |d|² − L²: the force on the first body is 2 λ d, along d with length L.
                let l = lambda(arena, 0);
                let two = arena.constant(2.0);
                let twice = arena.mul(two, length);
                reactions.push(arena.mul(twice, l));
            }
        }
    }
    reactions
}

/// The load on each ground body's coordinates (zero for moving ones): with the joints written
/// through the frame's coordinates, `−Σ_i ∂Φ_i/∂q_k λ_i` at the frame's pose, plus the pull of
/// the springs anchored to it.
fn ground_loads(model: &mut Model, n: usize) -> Vec<Id> {
    let mut loads = crate::model::dynamics::ground_spring_loads(model);
    debug_assert_eq!(loads.len(), n);
    let ground: Vec<(usize, [Id; 3])> = model
        .bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| b.ground)
        .map(|(i, b)| (i, b.pose))
        .collect();
    if ground.is_empty() {
        return loads;
    }
    let textbook = crate::model::kinematics::textbook_equations(model);
    // Ground equations touch only their own body, and their multipliers are not loads.
    let ground_rows: Vec<bool> = model
        .constraints
        .iter()
        .flat_map(|c| {
            let ground = matches!(c.kind, ConstraintKind::Ground { .. });
            std::iter::repeat_n(ground, c.kind.equation_suffixes().len())
        })
        .collect();
    let arena = &mut model.arena;
    let pose: HashMap<Var, Id> = ground
        .iter()
        .flat_map(|&(body, pose)| (0..3).map(move |k| (Var::Q(var_index(3 * body + k)), pose[k])))
        .collect();
    let mut memo = HashMap::new();
    let mut d = Differentiator::new();
    for (i, &phi) in textbook.iter().enumerate() {
        if ground_rows[i] {
            continue;
        }
        for var in arena.variables(phi) {
            let Var::Q(k) = var else { continue };
            let k = k as usize;
            if !pose.contains_key(&var) {
                continue;
            }
            let partial = d.diff(arena, phi, var);
            let partial = arena.substitute(partial, &pose, &mut memo);
            let lambda = arena.var(Var::Lambda(var_index(i)));
            let term = arena.mul(partial, lambda);
            loads[k] = arena.sub(loads[k], term);
        }
    }
    loads
}

#[cfg(test)]
mod tests {
    use super::{ForceStage, assert_reads_later_stages, resolution_order};
    use crate::expr::tape::{Inputs, Tape};
    use crate::expr::{Arena, Id, Var, var_index};
    use crate::plan::structure::Stage;

    fn compile(source: &str) -> crate::Scene {
        crate::compile(crate::Input::Text(source), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{e}"))
    }

    /// `id` at positions `q` and multipliers `lambda` (at rest, t = 0, default parameters).
    fn value(arena: &Arena, id: Id, q: &[f64], lambda: &[f64]) -> f64 {
        let tape = Tape::new(arena, &[id]);
        let rest = vec![0.0; q.len()];
        let inputs = Inputs {
            q,
            qd: &rest,
            qdd: &rest,
            trig: &[],
            lambda,
            t: 0.0,
            params: &[],
            free: &[],
        };
        let mut out = [0.0];
        tape.eval(inputs, &mut tape.scratch(), &mut out);
        out[0]
    }

    /// The multipliers at `q` by the reverse sweep: stages from last to first, an explicit
    /// stage's values evaluated, a 1 × 1 block's right-hand side divided by its entry. A
    /// multiplier not computed yet is NaN, so reading one shows.
    fn multipliers(scene: &crate::Scene, q: &[f64]) -> Vec<f64> {
        let forces = scene.forces.as_ref().expect("the scene computes forces");
        let arena = &scene.model.arena;
        assert_eq!(forces.stages.len(), scene.plan.stages.len());
        let mut lambda = vec![f64::NAN; q.len()];
        for (stage, force) in scene.plan.stages.iter().zip(&forces.stages).rev() {
            match (stage, force) {
                (Stage::Explicit(assignments), ForceStage::Explicit(values)) => {
                    assert_eq!(assignments.len(), values.len());
                    let values: Vec<f64> = values
                        .iter()
                        .map(|&v| value(arena, v, q, &lambda))
                        .collect();
                    for (a, v) in assignments.iter().zip(values) {
                        lambda[a.equation] = v;
                    }
                }
                (Stage::Block(block), ForceStage::Block(rhs)) => {
                    assert_eq!(block.entries.len(), 1, "these scenes' blocks are 1 × 1");
                    let pivot = value(arena, block.entries[0].2, q, &lambda);
                    lambda[block.equations[0]] = value(arena, rhs[0], q, &lambda) / pivot;
                }
                _ => panic!("a force stage of another kind than its plan stage"),
            }
        }
        lambda
    }

    /// A static crank and slider joined by a distance link, the slider pushed back. Coordinates:
    /// frame 0–2, crank 3–5, slider 6–8. Equations: frame 0–2, pivot 3–4, link 5, guide 6–7
    /// (normal, angle), spin 8.
    const CRANK_AND_LINK: &str = "mechanism CrankAndLink {
        ground frame at (0, 0, 0);
        body crank near (0, 0, 0);
        body slider near (140, 0, 0);
        joint pivot: revolute(frame, crank);
        joint link: distance(crank @ (40, 0), slider, 100);
        joint guide: prismatic(frame, slider, along (1, 0));
        driver spin: angle(crank) = t;
        load push: force(slider) = (-100, 0);
    }";

    #[test]
    fn the_reverse_sweep_gives_the_effort_of_virtual_work() {
        let scene = compile(CRANK_AND_LINK);
        // Fixed, the crank's angle, the slider's x alone (the link is not affine in it).
        let kinds: Vec<bool> = (scene.plan.stages.iter())
            .map(|s| matches!(s, Stage::Block(_)))
            .collect();
        assert_eq!(kinds, [false, false, true]);
        // At θ = 1 the slider is at x = r cos θ + √(L² − r² sin² θ); massless, at rest, the
        // driver's torque τ balances the push: τ δθ + F δx = 0, τ = 100 dx/dθ.
        let (r, l, theta) = (40.0_f64, 100.0_f64, 1.0_f64);
        let (s, c) = theta.sin_cos();
        let root = (l * l - r * r * s * s).sqrt();
        let x = r * c + root;
        let dx = -r * s - r * r * s * c / root;
        let q = [0.0, 0.0, 0.0, 0.0, 0.0, theta, x, 0.0, 0.0];
        let lambda = multipliers(&scene, &q);
        let forces = scene.forces.as_ref().expect("forces");
        let effort = value(&scene.model.arena, forces.reactions[8], &q, &lambda);
        assert!(
            (effort - 100.0 * dx).abs() < 1e-9,
            "{effort} ≠ {}",
            100.0 * dx
        );
        // The link pushes the slider with 100 along x: its tension 2 L λ is −100 / cos of the
        // link's angle to the guide.
        let tension = value(&scene.model.arena, forces.reactions[5], &q, &lambda);
        let cos_link = (x - r * c) / l;
        assert!((tension + 100.0 / cos_link).abs() < 1e-9, "{tension}");
    }

    #[test]
    fn each_joint_reports_its_multiplier_by_its_convention() {
        let scene = compile(CRANK_AND_LINK);
        let forces = scene.forces.as_ref().expect("forces");
        let q = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 130.0, 0.0, 0.0];
        let lambda: Vec<f64> = (1..=9).map(f64::from).collect();
        let reported: Vec<f64> = forces.reactions[3..]
            .iter()
            .map(|&id| value(&scene.model.arena, id, &q, &lambda))
            .collect();
        // A revolute's force on its first body −λ, a distance joint's tension 2 L λ, a
        // prismatic joint's normal and torque λ, a driver's effort −λ.
        assert_eq!(reported, [-4.0, -5.0, 1200.0, 7.0, 8.0, -9.0]);
        assert_eq!(
            scene.model.reaction_names()[3..],
            [
                "pivot.fx",
                "pivot.fy",
                "link.tension",
                "guide.normal",
                "guide.torque",
                "spin.effort"
            ]
        );
    }

    #[test]
    fn a_welds_fixed_stage_resolves_its_multipliers_in_dependency_order() {
        // The arm is welded at its point (−2, 0) to the frame's (1, 0), pushed up by 10 at its
        // point (2, 0), world (5, 0). One fixed stage, listed by coordinate: frame (0–2), then
        // glue.x, glue.y, glue.angle (3–5). The angle's multiplier reads glue.y's (the weld
        // point is off the arm's reference point, Φ_q[glue.y, θ_arm] = ±2): glue.y's must be
        // resolved first, although the reverse of the stage's order would take the angle first.
        let scene = compile(
            "mechanism Welded {
                ground frame at (0, 0, 0);
                body arm near (3, 0, 0);
                joint glue: weld(frame @ (1, 0), arm @ (-2, 0));
                load push: force(arm @ (2, 0)) = (0, 10);
            }",
        );
        let forces = scene.forces.as_ref().expect("forces");
        let arena = &scene.model.arena;
        let [ForceStage::Explicit(values)] = &forces.stages[..] else {
            panic!("one explicit stage")
        };
        // No value reads a multiplier: the stage's own are substituted, and none come later.
        for &v in values {
            let lambdas = arena.variables(v);
            assert!(
                !lambdas.iter().any(|v| matches!(v, Var::Lambda(_))),
                "{lambdas:?}"
            );
        }
        let q = [0.0, 0.0, 0.0, 3.0, 0.0, 0.0];
        let lambda = multipliers(&scene, &q);
        // The joints read the frame's pose as constants: its own rows carry nothing.
        assert_eq!([lambda[0], lambda[1], lambda[2]], [0.0; 3]);
        // The weld's torque: the load's moment about the weld point (4 × 10), not about the
        // arm's reference point (2 × 10, the angle's expression without glue.y's multiplier).
        assert_eq!(lambda[5], 40.0);
        // Reported: the frame's load (the push, and its moment 5 × 10 about the frame's
        // origin), and the weld's force and torque on the frame.
        let reported: Vec<f64> = (forces.reactions.iter())
            .map(|&id| value(arena, id, &q, &lambda))
            .collect();
        assert_eq!(reported, [0.0, 10.0, 50.0, 0.0, 10.0, 40.0]);
    }

    /// Issue 20's first scene: its fixed stage holds the prismatic joint's two equations.
    const PRISMATIC_TORQUE: &str = "mechanism PrismaticTorque {
        ground frame at (0, 0, 0);
        body slider near (6, 0, 0);
        joint slide: prismatic(frame, slider @ (-6, 0), along (1, 0));
        driver s: travel(slide) = t;
        load push: force(slider) = (0, 100 * t);
    }";

    /// The scene's force stages with the first multiplier of stage `s` made to read the
    /// multiplier of `equation`, checked.
    fn check_with_read(s: usize, equation: impl Fn(&[Stage]) -> usize) {
        let mut scene = crate::compile(
            crate::Input::Text(PRISMATIC_TORQUE),
            &crate::Options::default(),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let mut stages = scene.forces.expect("computes forces").stages;
        let n = scene.kinematics.phi.len();
        let read = equation(&scene.plan.stages);
        let lambda = scene.model.arena.var(Var::Lambda(var_index(read)));
        let (ForceStage::Explicit(values) | ForceStage::Block(values)) = &mut stages[s];
        values[0] = scene.model.arena.add(values[0], lambda);
        assert_reads_later_stages(&scene.model.arena, &scene.plan, &stages, n);
    }

    fn first_equation(stage: &Stage) -> usize {
        match stage {
            Stage::Explicit(assignments) => assignments[0].equation,
            Stage::Block(block) => block.equations[0],
        }
    }

    #[test]
    fn the_planned_stages_read_only_later_multipliers() {
        let scene = crate::compile(
            crate::Input::Text(PRISMATIC_TORQUE),
            &crate::Options::default(),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let stages = scene.forces.expect("computes forces").stages;
        assert!(stages.len() >= 2, "a fixed stage and the driver's");
        let n = scene.kinematics.phi.len();
        assert_reads_later_stages(&scene.model.arena, &scene.plan, &stages, n);
    }

    #[test]
    #[should_panic(expected = "before the reverse sweep computes it")]
    fn a_kernel_reading_its_own_stage_multiplier_is_refused() {
        check_with_read(0, |stages| first_equation(&stages[0]));
    }

    #[test]
    #[should_panic(expected = "before the reverse sweep computes it")]
    fn a_kernel_reading_an_earlier_stage_multiplier_is_refused() {
        check_with_read(1, |stages| first_equation(&stages[0]));
    }

    #[test]
    fn multipliers_resolve_after_those_they_read() {
        // 0 reads 2, 2 reads 1: 1, 2, 0 whatever the stage's order.
        assert_eq!(
            resolution_order(&[vec![2], vec![], vec![1]]),
            Some(vec![1, 2, 0])
        );
        // Independent ones go in reverse stage order; reading itself is no dependency.
        assert_eq!(
            resolution_order(&[vec![0], vec![], vec![]]),
            Some(vec![2, 1, 0])
        );
        // The fixed stage of a prismatic joint: the angle's multiplier (1) reads the normal's (0).
        assert_eq!(resolution_order(&[vec![], vec![0]]), Some(vec![0, 1]));
        assert_eq!(resolution_order(&[vec![1], vec![0]]), None);
    }
}
