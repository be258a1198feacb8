//! Kinematics: the constraint equations Φ(q, t) of a model and, by symbolic differentiation,
//! the Jacobian Φ_q (structural non-zeros only), ν = −Φ_t and γ.
//!
//! Each joint is written only as its Φ (Haug/Nikravesh planar formulation); nothing is
//! hand-derived per joint. γ comes from differentiating Φ̇ = Φ_q q̇ + Φ_t once more along the
//! motion with q̇ held as independent symbols and dropping the q̈ term:
//! γ = −(∂Φ̇/∂q · q̇ + ∂Φ̇/∂t) = −(Φ_q q̇)_q q̇ − 2 Φ_qt q̇ − Φ_tt.

use crate::diff::Differentiator;
use crate::expr::{Arena, Id, Var};
use crate::model::{ConstraintKind, Driven, Model, Point};

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
    /// ν = −Φ_t.
    pub nu: Vec<Id>,
    /// γ (reads q̇ as `Var::Qd`).
    pub gamma: Vec<Id>,
    /// The initial guess q₀ (ground poses and declared guesses), in parameters.
    pub guess: Vec<Id>,
}

impl Kinematics {
    /// The non-zero outputs of each generated kinematic function, by function name: what the
    /// emitter computes (zeros are cleared, not computed) and what operation counts cover.
    pub fn function_outputs(&self, arena: &Arena) -> [(&'static str, Vec<Id>); 5] {
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
            ("nu", nonzero(&self.nu)),
            ("gamma", nonzero(&self.gamma)),
        ]
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

    let phi_t: Vec<Id> = phi.iter().map(|&p| d.diff(arena, p, Var::T)).collect();
    let nu = phi_t.iter().map(|&p| arena.neg(p)).collect();

    let mut gamma = Vec::with_capacity(phi.len());
    for (row, &phi_t_i) in phi_t.iter().enumerate() {
        // Φ̇_i = Σ_k Φ_q[i,k] q̇_k + Φ_t,i
        let mut phi_dot = phi_t_i;
        for e in jacobian.iter().filter(|e| e.row == row) {
            let qd = arena.var(Var::Qd(col_u32(e.col)));
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

    let guess = model.bodies.iter().flat_map(|b| b.pose).collect();
    Kinematics {
        phi,
        jacobian,
        nu,
        gamma,
        guess,
    }
}

fn col_u32(col: usize) -> u32 {
    u32::try_from(col).unwrap_or(u32::MAX)
}

/// Φ in equation order, from the model's constraints.
fn constraint_equations(model: &mut Model) -> Vec<Id> {
    let constraints: Vec<ConstraintKind> = model.constraints.iter().map(|c| c.kind).collect();
    let a = &mut model.arena;
    let mut phi = Vec::new();
    for kind in constraints {
        match kind {
            ConstraintKind::Ground { body, pose } => {
                for (k, target) in pose.into_iter().enumerate() {
                    let q = coord(a, body, k);
                    phi.push(a.sub(q, target));
                }
            }
            ConstraintKind::Revolute { a: pa, b: pb } => {
                let ra = world_point(a, pa);
                let rb = world_point(a, pb);
                phi.push(a.sub(ra[0], rb[0]));
                phi.push(a.sub(ra[1], rb[1]));
            }
            ConstraintKind::Prismatic { a: pa, b: pb, axis } => {
                // Normal n = A_a R u (R a quarter turn): b's point has no offset across the axis.
                let neg_uy = a.neg(axis[1]);
                let normal = rotate(a, pa.body, [neg_uy, axis[0]]);
                let offset = separation(a, pa, pb);
                phi.push(dot(a, normal, offset));
                // No relative rotation, written linearly (θ_b − θ_a) rather than as the seed's
                // sin(θ_b − θ_a): same solution set near the assembly, constant Jacobian entries,
                // no trigonometry, and no spurious root at a half turn.
                let (tb, ta) = (coord(a, pb.body, 2), coord(a, pa.body, 2));
                phi.push(a.sub(tb, ta));
            }
            ConstraintKind::Distance {
                a: pa,
                b: pb,
                length,
            } => {
                let d = separation(a, pa, pb);
                let squared = dot(a, d, d);
                let l2 = a.powi(length, 2);
                phi.push(a.sub(squared, l2));
            }
            ConstraintKind::Driver { driven, value } => {
                let quantity = driven_quantity(a, driven);
                phi.push(a.sub(quantity, value));
            }
        }
    }
    phi
}

fn driven_quantity(a: &mut Arena, driven: Driven) -> Id {
    match driven {
        Driven::Angle(body) => coord(a, body, 2),
        Driven::RelativeAngle(from, to) => {
            let (tt, tf) = (coord(a, to, 2), coord(a, from, 2));
            a.sub(tt, tf)
        }
        Driven::X(p) => world_point(a, p)[0],
        Driven::Y(p) => world_point(a, p)[1],
        Driven::Travel { a: pa, b: pb, axis } => {
            let u = rotate(a, pa.body, axis);
            let d = separation(a, pa, pb);
            dot(a, u, d)
        }
    }
}

/// q index of coordinate `k` (0 x, 1 y, 2 θ) of `body`.
fn coord(a: &mut Arena, body: usize, k: usize) -> Id {
    a.var(Var::Q(col_u32(3 * body + k)))
}

/// A(θ_body) v
fn rotate(a: &mut Arena, body: usize, v: [Id; 2]) -> [Id; 2] {
    let theta = coord(a, body, 2);
    let (c, s) = (a.cos(theta), a.sin(theta));
    let (cx, sy) = (a.mul(c, v[0]), a.mul(s, v[1]));
    let (sx, cy) = (a.mul(s, v[0]), a.mul(c, v[1]));
    [a.sub(cx, sy), a.add(sx, cy)]
}

/// r_body + A(θ_body) s
fn world_point(a: &mut Arena, p: Point) -> [Id; 2] {
    let offset = rotate(a, p.body, p.local);
    let (x, y) = (coord(a, p.body, 0), coord(a, p.body, 1));
    [a.add(x, offset[0]), a.add(y, offset[1])]
}

/// World vector from `from`'s point to `to`'s point.
fn separation(a: &mut Arena, from: Point, to: Point) -> [Id; 2] {
    let (rf, rt) = (world_point(a, from), world_point(a, to));
    [a.sub(rt[0], rf[0]), a.sub(rt[1], rf[1])]
}

fn dot(a: &mut Arena, u: [Id; 2], v: [Id; 2]) -> Id {
    let (x, y) = (a.mul(u[0], v[0]), a.mul(u[1], v[1]));
    a.add(x, y)
}
