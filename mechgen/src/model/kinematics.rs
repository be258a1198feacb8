//! Kinematics: the constraint equations Φ(q, t) of a model and, by symbolic differentiation,
//! the Jacobian Φ_q (structural non-zeros only), ν = −Φ_t and γ.
//!
//! Each joint is written only as its Φ (Haug/Nikravesh planar formulation); nothing is
//! hand-derived per joint. γ comes from differentiating Φ̇ = Φ_q q̇ + Φ_t once more along the
//! motion with q̇ held as independent symbols and dropping the q̈ term:
//! γ = −(∂Φ̇/∂q · q̇ + ∂Φ̇/∂t) = −(Φ_q q̇)_q q̇ − 2 Φ_qt q̇ − Φ_tt.

use crate::expr::diff::Differentiator;
use crate::expr::{Arena, Id, Node, Var, var_index};
use crate::model::frames::{Frames, ground_poses};
use crate::model::{Branch, ConstraintKind, Model, Outputs, Product, Sign};

/// A structural non-zero of the Jacobian.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Entry {
    /// Equation (row).
    pub row: usize,
    /// Coordinate (column).
    pub col: usize,
    /// ∂Φ_row/∂q_col.
    pub value: Id,
}

/// The derived kinematic expressions of a model (ids into the model's arena).
#[derive(Debug, Clone)]
pub struct Kinematics {
    /// Φ, one expression per equation.
    pub phi: Vec<Id>,
    /// Φ_q's structural non-zeros, row-major.
    pub jacobian: Vec<Entry>,
    /// ν = −Φ_t, if the scene asked for velocities.
    pub nu: Option<Vec<Id>>,
    /// γ (reads q̇ as `Var::Qd`), if the scene asked for accelerations.
    pub gamma: Option<Vec<Id>>,
    /// The initial guess q₀ (ground poses and declared guesses), in parameters.
    pub guess: Vec<Id>,
    /// The branch invariants' values in q (and parameters), in declaration order, each signed
    /// so that it is positive on the declared branch (`< 0` invariants are negated).
    pub branches: Vec<Id>,
    /// The scene's length scale: the largest magnitude among its geometric lengths.
    pub length_scale: LengthScale,
    /// The geometry written in parameters, with the rule each value must satisfy at run time.
    pub geometry: Vec<crate::model::geometry::Check>,
    /// The mass properties and load constants written in parameters, with their rules.
    pub physics: Vec<crate::model::physics::Check>,
    /// The markers' values and rates, in layout order ([`Model::marker_names`]).
    pub markers: Vec<Id>,
}

/// The largest magnitude among a scene's geometric lengths ([`Model::lengths`]), split into what
/// is known at generation time and what depends on parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct LengthScale {
    /// The largest magnitude among the constant lengths, folded; 1 when the scene has no
    /// non-zero constant length and no parameter-dependent one (nothing to measure by).
    pub constant: f64,
    /// Lengths that depend on parameters, evaluated with the current values at run time.
    pub dependent: Vec<Id>,
}

impl LengthScale {
    /// Splits `lengths` into the folded constant maximum and the parameter-dependent rest.
    pub fn of(arena: &Arena, lengths: &[Id]) -> Self {
        let mut constant = 0.0f64;
        let mut dependent = Vec::new();
        for &id in lengths {
            if arena.any_node(id, |n| matches!(n, Node::Param(_))) {
                dependent.push(id);
            } else {
                // An unsimplified arena (naive baseline) does not fold: evaluate instead.
                let value = arena.as_const(id).unwrap_or_else(|| {
                    crate::expr::tape::eval(arena, id, &crate::expr::tape::Env::default())
                });
                constant = constant.max(value.abs());
            }
        }
        if dependent.is_empty() && constant == 0.0 {
            constant = 1.0;
        }
        LengthScale {
            constant,
            dependent,
        }
    }

    /// The scale given the values of [`dependent`](Self::dependent), in order: the same
    /// `max(|v|)` fold, in the same order, as the generated `length_scale`.
    pub fn evaluate(&self, dependent: &[f64]) -> f64 {
        dependent
            .iter()
            .fold(self.constant, |scale, v| scale.max(v.abs()))
    }
}

impl Kinematics {
    /// The non-zero outputs of each generated kinematic function, by function name: what the
    /// emitter computes (zeros are cleared, not computed) and what operation counts cover.
    pub fn function_outputs(&self, arena: &Arena) -> Vec<(&'static str, Vec<Id>)> {
        let nonzero = |ids: &[Id]| -> Vec<Id> {
            ids.iter()
                .copied()
                .filter(|&id| !arena.is_zero(id))
                .collect()
        };
        let phi = nonzero(&self.phi);
        let jacobian: Vec<Id> = self.jacobian.iter().map(|e| e.value).collect();
        let both = phi.iter().chain(&jacobian).copied().collect();
        [
            ("phi", phi),
            ("jacobian", jacobian),
            ("phi_and_jacobian", both),
        ]
        .into_iter()
        .chain(self.nu.as_deref().map(|nu| ("nu", nonzero(nu))))
        .chain(self.gamma.as_deref().map(|gamma| ("gamma", nonzero(gamma))))
        .collect()
    }
}

/// Derives Φ, Φ_q, ν and γ, adding their nodes to the model's arena.
pub fn derive(model: &mut Model) -> Kinematics {
    let phi = constraint_equations(model);
    let arena = &mut model.arena;
    let mut d = Differentiator::new();

    let mut jacobian = Vec::new();
    for (row, &phi_i) in phi.iter().enumerate() {
        for var in arena.variables(phi_i) {
            if let Var::Q(k) = var {
                let value = d.diff(arena, phi_i, var);
                if !arena.is_zero(value) {
                    let col = k as usize;
                    jacobian.push(Entry { row, col, value });
                }
            }
        }
    }

    // Time derivatives only for the outputs asked for: no work for what is left out.
    let (mut nu, mut gamma) = (None, None);
    if model.outputs >= Outputs::Velocities {
        let phi_t: Vec<Id> = phi.iter().map(|&p| d.diff(arena, p, Var::T)).collect();
        nu = Some(phi_t.iter().map(|&p| arena.neg(p)).collect());
        if model.outputs >= Outputs::Accelerations {
            gamma = Some(acceleration_rhs(arena, &mut d, &jacobian, &phi_t));
        }
    }

    let guess = model.bodies.iter().flat_map(|b| b.pose).collect();
    let branches = branch_values(model);
    let length_scale = LengthScale::of(&model.arena, &model.lengths());
    let geometry = crate::model::geometry::checks(model);
    let physics = crate::model::physics::checks(model);
    let markers = crate::model::markers::values(model);
    Kinematics {
        phi,
        jacobian,
        nu,
        gamma,
        guess,
        branches,
        length_scale,
        geometry,
        physics,
        markers,
    }
}

/// The branch invariants' signed values, built from world points like the joints (ground
/// bodies through their constant poses).
fn branch_values(model: &mut Model) -> Vec<Id> {
    let branches: Vec<Branch> = model.branches.clone();
    let poses = ground_poses(model);
    let mut f = Frames {
        arena: &mut model.arena,
        poses: &poses,
    };
    branches
        .iter()
        .map(|b| {
            let u = f.vector(b.u);
            let v = f.vector(b.v);
            let value = match b.product {
                Product::Dot => f.dot(u, v),
                Product::Cross => {
                    let (xy, yx) = (f.arena.mul(u[0], v[1]), f.arena.mul(u[1], v[0]));
                    f.arena.sub(xy, yx)
                }
            };
            match b.sign {
                Sign::Positive => value,
                Sign::Negative => f.arena.neg(value),
            }
        })
        .collect()
}

/// γ_i = −(∂Φ̇_i/∂q · q̇ + ∂Φ̇_i/∂t) with Φ̇_i = Σ_k Φ_q[i,k] q̇_k + Φ_t,i.
fn acceleration_rhs(
    arena: &mut Arena,
    d: &mut Differentiator,
    jacobian: &[Entry],
    phi_t: &[Id],
) -> Vec<Id> {
    let mut gamma = Vec::with_capacity(phi_t.len());
    for (row, &phi_t_i) in phi_t.iter().enumerate() {
        let mut phi_dot = phi_t_i;
        for e in jacobian.iter().filter(|e| e.row == row) {
            let qd = arena.var(Var::Qd(var_index(e.col)));
            let term = arena.mul(e.value, qd);
            phi_dot = arena.add(phi_dot, term);
        }
        let mut total = d.diff(arena, phi_dot, Var::T);
        for var in arena.variables(phi_dot) {
            if let Var::Q(k) = var {
                let partial = d.diff(arena, phi_dot, var);
                let qd = arena.var(Var::Qd(k));
                let term = arena.mul(partial, qd);
                total = arena.add(total, term);
            }
        }
        gamma.push(arena.neg(total));
    }
    gamma
}

/// Φ in equation order, from the model's constraints.
///
/// Ground bodies keep their coordinates and three ground equations (the system stays square
/// and in Cartesian form), but every joint and driver sees a ground body through its constant
/// pose: the solutions are the same, and ground bodies cost no trigonometry and no Jacobian
/// entries outside their own rows.
pub(crate) fn constraint_equations(model: &mut Model) -> Vec<Id> {
    let poses = ground_poses(model);
    equations_with(model, &poses)
}

/// Φ with every body through its coordinates, ground bodies included (the textbook
/// formulation, in which the joints touch the frame's coordinates): the force solve
/// differentiates it for the loads the joints put on ground bodies.
pub(crate) fn textbook_equations(model: &mut Model) -> Vec<Id> {
    let poses = vec![None; model.bodies.len()];
    equations_with(model, &poses)
}

/// Φ in equation order, each body seen through `poses` (a constant pose) or its coordinates.
fn equations_with(model: &mut Model, poses: &[Option<[Id; 3]>]) -> Vec<Id> {
    let constraints: Vec<ConstraintKind> = model.constraints.iter().map(|c| c.kind).collect();
    let mut f = Frames {
        arena: &mut model.arena,
        poses,
    };
    let mut phi = Vec::new();
    for kind in constraints {
        match kind {
            ConstraintKind::Ground { body, pose } => {
                for (k, target) in pose.into_iter().enumerate() {
                    let q = f.arena.var(Var::Q(var_index(3 * body + k)));
                    phi.push(f.arena.sub(q, target));
                }
            }
            ConstraintKind::Revolute { a, b } => {
                let (ra, rb) = (f.world_point(a), f.world_point(b));
                phi.push(f.arena.sub(ra[0], rb[0]));
                phi.push(f.arena.sub(ra[1], rb[1]));
            }
            ConstraintKind::Prismatic { a, b, axis } => {
                phi.push(f.normal_offset(a, b, axis));
                // No relative rotation, written linearly (θ_b − θ_a) rather than as the seed's
                // sin(θ_b − θ_a): same solution set near the assembly, constant Jacobian entries,
                // no trigonometry, and no spurious root at a half turn.
                let (tb, ta) = (f.pose(b.body, 2), f.pose(a.body, 2));
                phi.push(f.arena.sub(tb, ta));
            }
            ConstraintKind::Distance { a, b, length } => {
                let d = f.separation(a, b);
                let squared = f.dot(d, d);
                let l2 = f.arena.powi(length, 2);
                phi.push(f.arena.sub(squared, l2));
            }
            // The pin has no offset across the slot: the prismatic joint's normal equation alone.
            ConstraintKind::Slot { a, b, axis } => phi.push(f.normal_offset(a, b, axis)),
            ConstraintKind::Weld { a, b, angle } => {
                let (ra, rb) = (f.world_point(a), f.world_point(b));
                phi.push(f.arena.sub(ra[0], rb[0]));
                phi.push(f.arena.sub(ra[1], rb[1]));
                let (tb, ta) = (f.pose(b.body, 2), f.pose(a.body, 2));
                let relative = f.arena.sub(tb, ta);
                phi.push(f.arena.sub(relative, angle));
            }
            ConstraintKind::Gear {
                a,
                b,
                carrier,
                ratio,
                phase,
            } => {
                let [ta, tb] = [a, b].map(|body| f.relative_angle(body, carrier));
                let scaled = f.arena.mul(ratio, ta);
                let turned = f.arena.sub(tb, scaled);
                phi.push(f.arena.sub(turned, phase));
            }
            ConstraintKind::Rack {
                a,
                b,
                axis,
                pinion,
                ratio,
                phase,
            } => {
                let travel = f.travel(a, b, axis);
                let turn = f.relative_angle(pinion, Some(a.body));
                let rolled = f.arena.mul(ratio, turn);
                let offset = f.arena.sub(travel, rolled);
                phi.push(f.arena.sub(offset, phase));
            }
            ConstraintKind::Driver { driven, value } => {
                let quantity = f.driven_quantity(driven);
                phi.push(f.arena.sub(quantity, value));
            }
        }
    }
    phi
}

#[cfg(test)]
mod tests {
    use crate::expr::tape::{Env, eval};

    fn compile(source: &str) -> crate::Scene {
        crate::compile(crate::Input::Text(source), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn length_scale_folds_constants_and_keeps_parameters() {
        let scene = compile(
            "mechanism M {
                param r = 3;
                ground f at (-7, 2, 0.5);
                body a near (50, 60, 1);
                body b near (0, 0, 0);
                joint pin: revolute(f @ (1, -2), a @ (r, 0));
                joint rod: distance(a @ (-4, 0), b, 5);
                joint guide: prismatic(f, b, along (100, 0));
                driver d: angle(a) = 1000 * t;
            }",
        );
        // 7 (ground x), 4 (a point), 5 (distance); not the guesses, axes or driver values.
        let scale = &scene.kinematics.length_scale;
        assert_eq!(scale.constant, 7.0);
        assert_eq!(scale.dependent.len(), 1);
        assert_eq!(scale.evaluate(&[-9.0]), 9.0);
        assert_eq!(scale.evaluate(&[2.0]), 7.0);

        let fixed = compile(
            "mechanism M { ground f at (0, 0, 0); body a near (1, 0, 0);
               joint pin: revolute(f, a); driver d: angle(a) = t; }",
        );
        assert_eq!(fixed.kinematics.length_scale.constant, 1.0);
        assert!(fixed.kinematics.length_scale.dependent.is_empty());
    }

    #[test]
    fn branch_values_are_signed_products_of_world_vectors() {
        let scene = compile(
            "mechanism M {
                ground f at (1, 0, 0);
                body a near (0, 0, 0);
                joint pin: revolute(f, a @ (0, 0));
                driver d: angle(a) = t;
                branch left: cross(f -> a @ (2, 0), a -> a @ (0, 3)) > 0;
                branch right: dot(f -> a @ (2, 0), f @ (0, 1) -> f) < 0;
            }",
        );
        let [left, right] = [scene.kinematics.branches[0], scene.kinematics.branches[1]];
        // a at (5, 1) turned a quarter: a @ (2, 0) is at (5, 3), a @ (0, 3) at (2, 1).
        let env = Env {
            q: vec![1.0, 0.0, 0.0, 5.0, 1.0, std::f64::consts::FRAC_PI_2],
            ..Env::default()
        };
        let arena = &scene.model.arena;
        let (u, v, w) = ([4.0, 3.0], [-3.0, 0.0], [0.0, -1.0]);
        let cross = u[0] * v[1] - u[1] * v[0];
        assert!((eval(arena, left, &env) - cross).abs() < 1e-12);
        let dot = u[0] * w[0] + u[1] * w[1];
        assert!((eval(arena, right, &env) + dot).abs() < 1e-12);
    }
}
