//! The solve's trig cache: which angles' sines and cosines are computed once, right after the
//! stage that solves the angle, and read by every kernel that runs after that; and the rule
//! ([`Phase::ready`]) of which slots a kernel finds filled. The kernel list
//! ([`super::kernels`]) plans it from the kernels themselves.

use std::collections::HashMap;

use super::structure::{Stage, stage_coordinates};
use crate::expr::tape::topological_order;
use crate::expr::{Arena, Func, Id, Node, Var, var_index};

/// The solve's trig cache: the sine and cosine of each angle a later kernel needs, computed once
/// (one `sincos`) right after the stage that determines the angle, and read from the cache by
/// every kernel that runs after that (later stages, and the stage's own rates). Without it, a
/// seed step computed sin and cos of the rod angle in six kernels.
#[derive(Debug, Clone, Default)]
pub struct TrigCache {
    /// Slot `m` holds the sine (at `2m`) and cosine (at `2m + 1`) of coordinate `angles[m]`.
    pub angles: Vec<usize>,
    /// The nodes `sin q_k` and `cos q_k` of each slot.
    pub nodes: Vec<(Id, Id)>,
    /// The stage that fills each slot.
    pub filled_by: Vec<usize>,
    /// The slot of each cached node (`sin q_k` at `2m`, `cos q_k` at `2m + 1`).
    pub slot: HashMap<Id, usize>,
}

/// When a kernel of a stage runs: before the stage's positions are known (explicit positions,
/// a block's Newton iteration), after (its rates, its trig fill), or after the whole forward
/// sweep (the force solve, in reverse).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Computing the stage's positions.
    Positions,
    /// After the stage's positions are known.
    After,
    /// After every stage's positions are known: the whole cache is filled.
    Final,
}

impl Phase {
    /// Whether a kernel of stage `stage` running in this phase finds filled a slot that stage
    /// `filled_by` fills: before its own positions only earlier stages' slots, after them its
    /// own too, after the sweep every slot.
    pub fn ready(self, filled_by: usize, stage: usize) -> bool {
        match self {
            Phase::Positions => filled_by < stage,
            Phase::After => filled_by <= stage,
            Phase::Final => true,
        }
    }
}

impl TrigCache {
    /// Length of the cache buffer.
    pub fn len(&self) -> usize {
        2 * self.angles.len()
    }

    /// True without cached angles.
    pub fn is_empty(&self) -> bool {
        self.angles.is_empty()
    }

    /// The slots stage `stage` fills.
    pub fn fills(&self, stage: usize) -> impl Iterator<Item = usize> + '_ {
        (0..self.angles.len()).filter(move |&m| self.filled_by[m] == stage)
    }

    /// The cached nodes among those reachable from `roots` that a kernel of `stage` running in
    /// `phase` reads from the cache, with their position in the buffer.
    pub fn reads(
        &self,
        arena: &Arena,
        roots: &[Id],
        stage: usize,
        phase: Phase,
    ) -> HashMap<Id, usize> {
        topological_order(arena, roots)
            .into_iter()
            .filter_map(|id| {
                let &i = self.slot.get(&id)?;
                phase.ready(self.filled_by[i / 2], stage).then_some((id, i))
            })
            .collect()
    }
}

/// The angles worth caching for `kernels` (stage, phase, roots) over the `stages` of a plan of
/// `n` coordinates: those whose sine or cosine a kernel reads after the angle's stage is
/// solved. Adds the sine and cosine nodes a slot needs to the arena.
pub fn plan<'k>(
    arena: &mut Arena,
    stages: &[Stage],
    n: usize,
    kernels: impl IntoIterator<Item = (usize, Phase, &'k [Id])>,
) -> TrigCache {
    let mut stage_of = vec![0; n];
    for (s, stage) in stages.iter().enumerate() {
        for c in stage_coordinates(stage) {
            stage_of[c] = s;
        }
    }
    let mut wanted = vec![false; n];
    for (s, phase, roots) in kernels {
        for id in topological_order(arena, roots) {
            if let Node::Call(Func::Sin | Func::Cos, a) = arena.node(id)
                && let Node::Var(Var::Q(k)) = arena.node(a)
            {
                let k = k as usize;
                wanted[k] |= phase.ready(stage_of[k], s);
            }
        }
    }
    let angles: Vec<usize> = (0..n).filter(|&k| wanted[k]).collect();
    let nodes: Vec<(Id, Id)> = angles
        .iter()
        .map(|&k| {
            let q = arena.var(Var::Q(var_index(k)));
            (arena.sin(q), arena.cos(q))
        })
        .collect();
    let filled_by = angles.iter().map(|&k| stage_of[k]).collect();
    let slot = nodes
        .iter()
        .enumerate()
        .flat_map(|(m, &(sin, cos))| [(sin, 2 * m), (cos, 2 * m + 1)])
        .collect();
    TrigCache {
        angles,
        nodes,
        filled_by,
        slot,
    }
}
