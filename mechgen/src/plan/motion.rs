//! The equations of motion as the integrator calls them (`mechgen_runtime::EquationsOfMotion`),
//! planned once for a scene that needs them: the products `M v`, `K v` and `C v` written out
//! over the matrices' structural non-zeros (constants folded, so centred masses give
//! `out[k] = m v[k]`), and the energy terms. Both consumers render these lists as they are.
//!
//! The vector `v` of a product is read through the q̈ variables: `M v` is the inertia term
//! `M q̈` itself, and neither `M` (a function of q) nor `K` and `C` (of q, q̇ and t, at q̈ = 0)
//! reads q̈, so the products need no variable of their own.

use crate::expr::{Arena, Id, Var, var_index};
use crate::model::energy::{self, Energy};
use crate::model::motion::{self, Entry, Motion};
use crate::model::{Model, Outputs};

/// What a scene's `EquationsOfMotion` implementation computes.
#[derive(Debug, Clone)]
pub struct EquationsOfMotion {
    /// The sparse `M`, `Q`, `K` and `C` (`model::motion`).
    pub motion: Motion,
    /// `(M v)_k` per coordinate, `v` read as q̈.
    pub mass_times: Vec<Id>,
    /// `(K v)_k`, `v` read as q̈; `None` when `Q` does not depend on q (no kernel).
    pub stiffness_times: Option<Vec<Id>>,
    /// `(C v)_k`, `v` read as q̈; `None` when `Q` does not depend on q̇ (no kernel).
    pub damping_times: Option<Vec<Id>>,
    /// The potentials and powers.
    pub energy: Energy,
}

/// Whether a scene carries its equations of motion: a scene that computes forces, when it
/// declares free degrees of freedom (the integrator needs them) or when `asked`
/// (`CodegenOptions::equations_of_motion`: M, K and C of a prescribed motion).
pub fn needs_motion(model: &Model, asked: bool) -> bool {
    model.outputs >= Outputs::Forces && (asked || !model.frees.is_empty())
}

/// The equations of motion of `model`, from its generalised forces `F = Q − M q̈`.
pub fn plan(model: &mut Model, generalized: &[Id]) -> EquationsOfMotion {
    let motion = motion::derive(&mut model.arena, generalized);
    let energy = energy::derive(model);
    let n = model.dim();
    let arena = &mut model.arena;
    let product = |arena: &mut Arena, entries: &[Entry]| {
        (!entries.is_empty()).then(|| times(arena, entries, n))
    };
    EquationsOfMotion {
        mass_times: times(arena, &motion.mass, n),
        stiffness_times: product(arena, &motion.stiffness),
        damping_times: product(arena, &motion.damping),
        motion,
        energy,
    }
}

/// `(A v)_k = Σ_j A_kj v_j` over `entries`, with `v_j` the variable q̈_j.
fn times(arena: &mut Arena, entries: &[Entry], n: usize) -> Vec<Id> {
    let mut out = vec![arena.zero(); n];
    for &(k, j, value) in entries {
        let v = arena.var(Var::Qdd(var_index(j)));
        let term = arena.mul(value, v);
        out[k] = arena.add(out[k], term);
    }
    out
}

#[cfg(test)]
mod tests {
    use crate::expr::Node;

    fn plan(source: &str) -> (crate::Model, super::EquationsOfMotion) {
        let mut options = crate::Options::default();
        options.codegen.equations_of_motion = true;
        let scene =
            crate::compile(crate::Input::Text(source), &options).unwrap_or_else(|e| panic!("{e}"));
        let motion = scene
            .motion
            .expect("a force scene with the option has its motion");
        (scene.model, motion)
    }

    #[test]
    fn centred_masses_multiply_by_their_constant_mass() {
        let (model, eom) = plan(
            "mechanism C {
                ground frame at (0, 0, 0);
                body arm near (1, 0, 0) mass 2 inertia 0.5;
                joint pivot: revolute(frame, arm);
                driver swing: angle(arm) = t;
                gravity (0, -9.81);
            }",
        );
        let arena = &model.arena;
        assert!(eom.mass_times[..3].iter().all(|&v| arena.is_zero(v)));
        for (k, m) in [(3, 2.0), (4, 2.0), (5, 0.5)] {
            let Node::Mul(a, b) = arena.node(eom.mass_times[k]) else {
                panic!("(M v)_{k} is not one product");
            };
            let (constant, var) = if arena.as_const(a).is_some() {
                (a, b)
            } else {
                (b, a)
            };
            assert_eq!(arena.as_const(constant), Some(m));
            assert_eq!(arena.node(var), Node::Var(crate::expr::Var::Qdd(k as u32)));
        }
        // Gravity at the reference point does not turn with the body: no K, no C.
        assert!(eom.stiffness_times.is_none() && eom.damping_times.is_none());
    }

    #[test]
    fn only_scenes_that_ask_carry_their_motion() {
        let source = "mechanism C {
            ground frame at (0, 0, 0);
            body arm near (1, 0, 0) mass 2 inertia 0.5;
            joint pivot: revolute(frame, arm);
            driver swing: angle(arm) = t;
        }";
        let default = crate::compile(crate::Input::Text(source), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(default.motion.is_none());
        let kinematic = source.replace(
            "driver swing",
            "outputs positions, velocities, accelerations;\n driver swing",
        );
        let mut options = crate::Options::default();
        options.codegen.equations_of_motion = true;
        let scene = crate::compile(crate::Input::Text(&kinematic), &options)
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(scene.motion.is_none(), "no forces, no equations of motion");
    }
}
