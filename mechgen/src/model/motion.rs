//! The equations of motion in the form a time integrator needs: `M(q) q̈ = Q(q, q̇, t) + Φ_qᵀ λ`,
//! with the mass matrix `M`, the applied and velocity-dependent forces `Q`, and the two
//! derivatives of `Q` an implicit integrator's Newton iteration uses, the tangent stiffness
//! `K = −∂Q/∂q` and damping `C = −∂Q/∂q̇` (a stiff spring needs them exactly, not by
//! differences).
//!
//! All four come from the generalised forces of `dynamics`, `F(q, q̇, q̈, t) = Q − M q̈`, which
//! is linear in `q̈`: `M = −∂F/∂q̈` and `Q = F` at `q̈ = 0`. Each matrix is kept sparse (only
//! the structurally non-zero entries, found from the variables an expression reads) and its
//! constant entries fold: with every centre of mass at its body's reference point, `M` is the
//! constant diagonal `(m, m, J)` per body; an offset centre brings the coupling entries, and a
//! scene without springs or dampers has no `C` at all.

use std::collections::HashMap;

use crate::expr::diff::Differentiator;
use crate::expr::{Arena, Id, Var, var_index};

/// One structurally non-zero entry of a sparse matrix: (row, column, value).
pub type Entry = (usize, usize, Id);

/// The equations of motion of a scene, per coordinate.
#[derive(Debug, Clone)]
pub struct Motion {
    /// The mass matrix's non-zero entries, row-major; symmetric.
    pub mass: Vec<Entry>,
    /// `Q` per coordinate: gravity, loads, springs and dampers, and the velocity-dependent
    /// (centripetal) inertia terms.
    pub applied: Vec<Id>,
    /// `K = −∂Q/∂q`, non-zero entries, row-major.
    pub stiffness: Vec<Entry>,
    /// `C = −∂Q/∂q̇`, non-zero entries, row-major.
    pub damping: Vec<Entry>,
}

/// The equations of motion from the generalised forces `F = Q − M q̈` of `dynamics::derive`.
pub fn derive(arena: &mut Arena, generalized: &[Id]) -> Motion {
    let mut d = Differentiator::new();
    let zero_accelerations: HashMap<Var, Id> = (0..generalized.len())
        .map(|j| (Var::Qdd(var_index(j)), arena.zero()))
        .collect();
    let mut memo = HashMap::new();
    let applied: Vec<Id> = generalized
        .iter()
        .map(|&f| arena.substitute(f, &zero_accelerations, &mut memo))
        .collect();
    Motion {
        mass: negated_jacobian(arena, &mut d, generalized, |v| match v {
            Var::Qdd(j) => Some(j as usize),
            _ => None,
        }),
        stiffness: negated_jacobian(arena, &mut d, &applied, |v| match v {
            Var::Q(j) => Some(j as usize),
            _ => None,
        }),
        damping: negated_jacobian(arena, &mut d, &applied, |v| match v {
            Var::Qd(j) => Some(j as usize),
            _ => None,
        }),
        applied,
    }
}

/// The non-zero entries of `−∂f_k/∂x_j`, for the variables `x_j` that `column` numbers.
fn negated_jacobian(
    arena: &mut Arena,
    d: &mut Differentiator,
    f: &[Id],
    column: impl Fn(Var) -> Option<usize>,
) -> Vec<Entry> {
    let mut entries = Vec::new();
    for (k, &fk) in f.iter().enumerate() {
        let mut vars: Vec<(usize, Var)> = arena
            .variables(fk)
            .into_iter()
            .filter_map(|v| Some((column(v)?, v)))
            .collect();
        vars.sort_unstable_by_key(|&(j, _)| j);
        vars.dedup_by_key(|&mut (j, _)| j);
        for (j, var) in vars {
            let derivative = d.diff(arena, fk, var);
            let entry = arena.neg(derivative);
            if !arena.is_zero(entry) {
                entries.push((k, j, entry));
            }
        }
    }
    entries
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::tape::{Env, eval};

    /// The motion of `source`'s scene, with its arena.
    fn motion(source: &str) -> (Arena, Motion) {
        let scene = crate::compile(crate::Input::Text(source), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{e}"));
        let mut model = scene.model;
        let generalized = crate::model::dynamics::derive(&mut model);
        let motion = derive(&mut model.arena, &generalized);
        (model.arena, motion)
    }

    /// A sparse matrix's entries evaluated into a dense n × n array.
    fn dense(arena: &Arena, entries: &[Entry], env: &Env, n: usize) -> Vec<Vec<f64>> {
        let mut m = vec![vec![0.0; n]; n];
        for &(k, j, value) in entries {
            m[k][j] = eval(arena, value, env);
        }
        m
    }

    fn env(q: &[f64], qd: &[f64]) -> Env {
        Env {
            q: q.to_vec(),
            qd: qd.to_vec(),
            qdd: vec![0.0; q.len()],
            t: 0.3,
            params: vec![],
            free: Vec::new(),
        }
    }

    /// A free-swinging arm (its driver only makes the scene well-posed for the compiler) with
    /// its centre of mass off the reference point.
    const OFFSET_ARM: &str = "mechanism P {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass 2 inertia 0.5 centre (0.5, 0.25);
        joint pivot: revolute(frame, arm);
        driver swing: angle(arm) = t;
        gravity (0, -9.81);
    }";

    #[test]
    fn an_offset_centre_couples_translation_and_rotation() {
        let (arena, motion) = motion(OFFSET_ARM);
        let (th, thd) = (0.7_f64, 1.3_f64);
        let env = env(
            &[0.0, 0.0, 0.0, 0.2, 0.1, th],
            &[0.0, 0.0, 0.0, 0.3, -0.2, thd],
        );
        let m = dense(&arena, &motion.mass, &env, 6);
        // The centre's world offset r = A(θ) s; M = [[m, 0, −m r_y], [0, m, m r_x],
        // [−m r_y, m r_x, J + m |s|²]] (Haug, planar body with an offset centre).
        let (s, c) = th.sin_cos();
        let r = [0.5 * c - 0.25 * s, 0.5 * s + 0.25 * c];
        let expected = [
            [2.0, 0.0, -2.0 * r[1]],
            [0.0, 2.0, 2.0 * r[0]],
            [-2.0 * r[1], 2.0 * r[0], 0.5 + 2.0 * (0.25 + 0.0625)],
        ];
        for (k, row) in expected.iter().enumerate() {
            for (j, &value) in row.iter().enumerate() {
                let got = m[3 + k][3 + j];
                assert!(
                    (got - value).abs() < 1e-13,
                    "M[{k}][{j}] = {got}, not {value}"
                );
            }
        }
        assert!(
            m[..3].iter().all(|row| row.iter().all(|&v| v == 0.0)),
            "the frame has no mass"
        );
        // Q: gravity at the centre and the centripetal force m θ̇² r, with its moment.
        let q: Vec<f64> = motion
            .applied
            .iter()
            .map(|&v| eval(&arena, v, &env))
            .collect();
        let force = [2.0 * thd * thd * r[0], 2.0 * (-9.81 + thd * thd * r[1])];
        let torque = r[0] * force[1] - r[1] * force[0];
        for (got, exact) in q[3..].iter().zip([force[0], force[1], torque]) {
            assert!((got - exact).abs() < 1e-12, "{got} vs {exact}");
        }
    }

    #[test]
    fn centred_masses_give_a_constant_diagonal_mass_matrix_and_no_damping() {
        let (arena, motion) = motion(
            "mechanism C {
                ground frame at (0, 0, 0);
                body arm near (1, 0, 0) mass 2 inertia 0.5;
                body slider near (2, 0, 0) mass 3 inertia 0.25;
                joint pivot: revolute(frame, arm);
                joint rod: distance(arm @ (1, 0), slider, 1);
                joint guide: prismatic(frame, slider, along (1, 0));
                driver swing: angle(arm) = t;
                gravity (0, -9.81);
            }",
        );
        let diagonal: Vec<(usize, usize, Option<f64>)> = motion
            .mass
            .iter()
            .map(|&(k, j, v)| (k, j, arena.as_const(v)))
            .collect();
        let expected: Vec<(usize, usize, Option<f64>)> = [2.0, 2.0, 0.5, 3.0, 3.0, 0.25]
            .iter()
            .enumerate()
            .map(|(i, &m)| (3 + i, 3 + i, Some(m)))
            .collect();
        assert_eq!(diagonal, expected);
        assert!(motion.damping.is_empty() && motion.stiffness.is_empty());
    }

    /// A slider on a spring-damper anchored off its line: a nonlinear spring.
    const SPRUNG: &str = "mechanism S {
        ground frame at (0, 0, 0);
        body slider near (3, 0, 0) mass 1 inertia 0.1;
        joint guide: prismatic(frame, slider, along (1, 0));
        driver push: x(slider) = t;
        load coil: spring(frame @ (1, 0.5), slider @ (0.2, 0.1), stiffness 1e6, length 1.5, damping 2);
    }";

    #[test]
    fn the_tangent_stiffness_and_damping_are_the_derivatives_of_the_applied_forces() {
        let (arena, motion) = motion(SPRUNG);
        let (q0, qd0) = (
            [0.0, 0.0, 0.0, 2.9, -0.05, 0.3],
            [0.0, 0.0, 0.0, 1.5, 0.4, -2.0],
        );
        let applied = |q: &[f64], qd: &[f64]| -> Vec<f64> {
            let e = env(q, qd);
            motion
                .applied
                .iter()
                .map(|&v| eval(&arena, v, &e))
                .collect()
        };
        let e0 = env(&q0, &qd0);
        let stiffness = dense(&arena, &motion.stiffness, &e0, 6);
        let damping = dense(&arena, &motion.damping, &e0, 6);
        // Central differences. Q is linear in q̇ here (a damper, no offset centre), so a unit
        // step is exact but for round-off; in q a small step keeps the truncation below it.
        for j in 3..6 {
            for (matrix, of_velocity) in [(&stiffness, false), (&damping, true)] {
                let h = if of_velocity { 1.0 } else { 1e-5 };
                let (mut up, mut down) = ((q0, qd0), (q0, qd0));
                if of_velocity {
                    up.1[j] += h;
                    down.1[j] -= h;
                } else {
                    up.0[j] += h;
                    down.0[j] -= h;
                }
                let (fu, fd) = (applied(&up.0, &up.1), applied(&down.0, &down.1));
                // Round-off in the differences: a few ulps of the largest force, over h.
                let largest = fu.iter().fold(0.0_f64, |m, f| m.max(f.abs()));
                let noise = 1e-14 * largest / h;
                for k in 0..6 {
                    let difference = -(fu[k] - fd[k]) / (2.0 * h);
                    let tolerance = 1e-6 * difference.abs() + noise;
                    assert!(
                        (matrix[k][j] - difference).abs() < tolerance,
                        "{}[{k}][{j}] = {}, differences give {difference}",
                        if of_velocity { "C" } else { "K" },
                        matrix[k][j]
                    );
                }
            }
        }
        // The stiff spring dominates: K's translational block is of the order of k.
        assert!(stiffness[3][3].abs() > 1e5, "{}", stiffness[3][3]);
    }

    #[test]
    fn the_mass_matrix_is_symmetric() {
        for source in [OFFSET_ARM, SPRUNG] {
            let (arena, motion) = motion(source);
            let env = env(&[0.0, 0.0, 0.0, 0.4, -0.3, 1.1], &[0.0; 6]);
            let m = dense(&arena, &motion.mass, &env, 6);
            for (k, row) in m.iter().enumerate() {
                for (j, value) in row.iter().enumerate() {
                    assert!((value - m[j][k]).abs() < 1e-14, "M[{k}][{j}]");
                }
            }
        }
    }
}
