//! What to try when the kinematic solve fails, by the kind of [`SolveError`]: at the start
//! (the `near` guesses, the dimensions) and along a motion (the steps, the drivers).

use mechgen_runtime::{Quantity, SolveError};

const GEOMETRY_HINT: &str = "change the named parameter with `--set NAME=VALUE` (its default is in the scene; \
     `mechgen check FILE` lists the parameters)";

const LOAD_HINT: &str = "the named load is not finite at this time: check its expression and the \
     parameters it reads (with `--set NAME=VALUE`); a spring with a free length or damping needs \
     its ends apart";

/// What to try when the scene cannot be assembled at the start.
pub(crate) fn assembly_hint(error: &SolveError) -> &'static str {
    match error {
        SolveError::NoConvergence { .. } => {
            "no solution found from these guesses (the residual was still decreasing): move \
             the `near (x, y, angle)` guesses of the bodies in the named equation's joint \
             closer to an assembled pose"
        }
        SolveError::Singular { .. } => {
            "the named equation is redundant or conflicts with others at this pose: check the \
             joints, or move the `near` guesses away from a dead-centre position"
        }
        SolveError::NoAssembly { .. } => {
            "the residual above is a minimum no direction reduces (a guess with links in line \
             is left along its free direction, so the guesses' shape is not the cause): the \
             joints cannot all close with these dimensions; check the lengths, the parameters \
             and the drivers' values at the start time"
        }
        SolveError::BranchFlip { .. } => {
            "the guesses lead to another assembly branch than the scene's `branch` declares: \
             move the `near` guesses towards the declared branch"
        }
        SolveError::Unresolved { .. } => {
            "a coordinate is too large to resolve: give `near` angles within a turn and \
             positions near the scene's size, and check parameters that set huge values"
        }
        SolveError::Geometry { .. } | SolveError::Physics { .. } => GEOMETRY_HINT,
        SolveError::Unreachable { .. } => {
            "start the run nearer t = 0 (`--t0`), or write the drivers so that the motion of \
             interest starts near t = 0"
        }
        SolveError::NonFinite {
            quantity: Quantity::LoadValue(_) | Quantity::SpringEnds(_),
            ..
        } => LOAD_HINT,
        _ => "check the parameter values and the `near` guesses for divisions by zero",
    }
}

/// What to try when a step of the motion fails.
pub(crate) fn step_hint(error: &SolveError) -> &'static str {
    match error {
        SolveError::NoConvergence { .. } => {
            "the mechanism may stop being able to assemble here (a joint cannot close), or the \
             time step is too large: try more `--steps`"
        }
        SolveError::Singular { .. } => {
            "the mechanism reaches a singular position (dead centre or a locked joint): check \
             the dimensions, or end the run before this time"
        }
        SolveError::NoAssembly { .. } => {
            "the mechanism cannot close here (a driver beyond the reachable range?): check the \
             dimensions and the drivers, or end the run before this time"
        }
        SolveError::BranchFlip { .. } => {
            "the motion would leave the declared assembly branch (through a singular position, \
             or the steps are too coarse even after sub-stepping): try more `--steps`"
        }
        SolveError::Unresolved { .. } => {
            "a coordinate has grown too large to resolve (a driven angle after very many \
             turns?): start the run at a smaller time, or drive the angle with a periodic law"
        }
        SolveError::Geometry { .. } | SolveError::Physics { .. } => GEOMETRY_HINT,
        SolveError::NonFinite {
            quantity: Quantity::LoadValue(_) | Quantity::SpringEnds(_),
            ..
        } => LOAD_HINT,
        _ => "a value became NaN or infinite: check the parameter values and the time range",
    }
}
