//! The planned scene: the checked model with everything derived from it, which the emitter
//! renders and the interpreter runs.

use super::{kernels, motion, reactions, structure};
use crate::expr;
use crate::model::Model;
use crate::model::kinematics::Kinematics;

/// A checked model with its derived kinematics and solve structure: everything needed to emit
/// or interpret a scene.
#[derive(Clone)]
pub struct Scene {
    /// The checked model; its arena also holds the derived expressions.
    pub model: Model,
    /// Φ, Φ_q, ν, γ and the initial guess.
    pub kinematics: Kinematics,
    /// The stages of the solve: explicit assignments and Newton blocks with their static LU.
    pub plan: structure::Plan,
    /// The force solve, for a scene that computes forces: the generalised forces, the plan's
    /// stages in reverse, the reported reactions.
    pub forces: Option<reactions::Forces>,
    /// The equations of motion and energies, for a scene that needs them
    /// ([`motion::needs_motion`]).
    pub motion: Option<motion::EquationsOfMotion>,
    /// Every kernel of the plan and the force solve, as the emitter and the interpreter run them.
    pub kernels: kernels::Kernels,
    /// For a scene that computes forces, two values per load that name the load making F
    /// non-finite (`dynamics::load_witnesses`); empty otherwise.
    pub load_witnesses: Vec<expr::Id>,
}
