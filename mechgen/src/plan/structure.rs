//! The solve structure: which equations decide which coordinates, and in what order — the plan
//! that both the emitter (as specialised code) and the interpreter (as data) follow.
//!
//! 1. **Fixed coordinates.** An equation affine in a single unknown coordinate with a constant
//!    coefficient, whose value does not depend on q or t (a ground pose, a pin on a fixed point
//!    at a body's reference point, a prismatic joint's angle to a fixed body), fixes that
//!    coordinate. Its value is substituted into every other equation, which may reveal more;
//!    this repeats until nothing changes. Ground bodies and what they pin cost nothing after.
//! 2. **Block-triangular order** of the rest: a maximum matching of equations to coordinates
//!    (`graph`), then the strongly connected components of the matched graph (Tarjan), in
//!    dependency order. Each component's equations read only its own and earlier coordinates.
//! 3. **Explicit assignments.** A one-equation component affine in its coordinate with a
//!    constant coefficient `a` (a driver `θ = f(t)`, a pin on a point already placed) is
//!    assigned in closed form: `q_c = −g/a`, `g` the equation with `q_c = 0`. Its velocity and
//!    acceleration follow from the same row of Φ_q q̇ = ν and Φ_q q̈ = γ.
//! 4. **Newton blocks** for every other component, each with a static LU (`factor`) whose pivot
//!    order is chosen here at the scene's initial guess, and the right-hand sides of its
//!    velocity and acceleration solves: `ν_b − Φ_q[b, earlier] q̇_earlier`, and the same with γ
//!    and q̈. A block whose loop closes by an intersection (a dyad) also gets its solution
//!    in closed form ([`closed`]), which starts its Newton iteration.
//!
//! Rates that turn out constant (a ground body's zero velocity, a driver's ω) are substituted
//! forward as well, so the generated code does no work for them.

use std::collections::HashMap;

use crate::expr::diff::Differentiator;
use crate::expr::tape::{Inputs, Tape};
use crate::expr::{Arena, Id, Var, var_index};
use crate::model::kinematics::Kinematics;
use crate::model::{Model, Outputs};
use crate::plan::closed::{self, ClosedForm};
use crate::sparse::factor::{self, Factorization};
use crate::sparse::graph;

/// Static factorisations with more updates than this are not emitted as straight-line code
/// (rustc's time grows quickly with a function's size); such a block is factored with partial
/// pivoting at run time.
pub const MAX_STATIC_UPDATES: usize = 20_000;

/// The stages of a scene's solve, in order.
#[derive(Debug, Clone)]
pub struct Plan {
    /// Stages in solve order; every coordinate belongs to exactly one.
    pub stages: Vec<Stage>,
    /// For each stage, the earlier stages whose coordinates it reads, ascending (a singular
    /// stage leaves the coordinates of every stage downstream of it undetermined too).
    pub reads: Vec<Vec<usize>>,
}

/// One stage of the solve.
#[derive(Debug, Clone)]
pub enum Stage {
    /// Coordinates assigned in closed form, in order: each position reads only coordinates
    /// assigned before it (earlier in the stage, or in earlier stages). The fixed stage's
    /// positions are constants and are listed by coordinate; through Φ_q its equations may
    /// still touch each other's coordinates in any order.
    Explicit(Vec<Assignment>),
    /// Equations solved together by Newton's method.
    Block(Block),
}

/// A coordinate assigned in closed form by one equation.
#[derive(Debug, Clone)]
pub struct Assignment {
    /// The equation (global index).
    pub equation: usize,
    /// The coordinate it assigns (global index).
    pub coordinate: usize,
    /// q_c in earlier coordinates, t and parameters.
    pub position: Id,
    /// q̇_c in earlier coordinates and velocities, if the scene computes velocities.
    pub velocity: Option<Id>,
    /// q̈_c (also reading earlier accelerations, `Var::Qdd`), if it computes accelerations.
    pub acceleration: Option<Id>,
}

/// Equations solved together, rows and columns in pivot order.
#[derive(Debug, Clone)]
pub struct Block {
    /// Global equation indices, in the block's row (pivot) order.
    pub equations: Vec<usize>,
    /// Global coordinate indices, in the block's column (pivot) order.
    pub coordinates: Vec<usize>,
    /// Each equation's value (fixed coordinates substituted), in row order.
    pub residuals: Vec<Id>,
    /// `(row, column, ∂Φ/∂q)` of each Jacobian entry, in slot order: column-major.
    pub entries: Vec<(usize, usize, Id)>,
    /// The static LU, unless too large to emit.
    pub factorization: Option<Factorization>,
    /// `ν_b − Φ_q[b, earlier] q̇_earlier`, in row order, if the scene computes velocities.
    pub velocity_rhs: Option<Vec<Id>>,
    /// `γ_b − Φ_q[b, earlier] q̈_earlier`, in row order, if it computes accelerations.
    pub acceleration_rhs: Option<Vec<Id>>,
    /// Its solution in closed form, if its loop closes by an intersection ([`closed`]).
    pub closed: Option<Box<ClosedForm>>,
}

impl Block {
    /// Length of the block's value array: entries, then fill-in.
    pub fn slots(&self) -> usize {
        self.factorization
            .as_ref()
            .map_or(self.entries.len(), |f| f.slots)
    }
}

impl Plan {
    /// Size of the largest block (at least 1: sizes the runtime's workspace).
    pub fn largest_block(&self) -> usize {
        self.blocks()
            .map(|b| b.equations.len())
            .max()
            .unwrap_or(0)
            .max(1)
    }

    /// Most value slots of a block (at least 1).
    pub fn largest_slots(&self) -> usize {
        self.blocks().map(Block::slots).max().unwrap_or(0).max(1)
    }

    /// The Newton blocks, in order.
    pub fn blocks(&self) -> impl Iterator<Item = &Block> {
        self.stages.iter().filter_map(|s| match s {
            Stage::Block(b) => Some(b),
            Stage::Explicit(_) => None,
        })
    }

    /// The explicit assignments, in order.
    pub fn assignments(&self) -> impl Iterator<Item = &Assignment> {
        self.stages.iter().flat_map(|s| match s {
            Stage::Explicit(a) => a.as_slice(),
            Stage::Block(_) => &[],
        })
    }
}

/// Derives the plan of a checked scene, adding its expressions to the model's arena. The naive
/// baseline (an unsimplified arena, which cannot recognise constants) gets [`single_block`].
pub fn plan(model: &mut Model, kin: &Kinematics) -> Plan {
    if !model.arena.simplifies() {
        return single_block(kin);
    }
    let outputs = model.outputs;
    let params: Vec<f64> = model.params.iter().map(|p| p.default).collect();
    let mut cx = Planner {
        arena: &mut model.arena,
        kin,
        d: Differentiator::new(),
        rows: jacobian_rows(kin, kin.phi.len()),
        map: HashMap::new(),
        local: HashMap::new(),
        outputs,
        params,
        sample: Vec::new(),
    };
    let n = kin.phi.len();
    cx.sample = cx.evaluate(&kin.guess, &vec![0.0; n]);
    let mut phi = kin.phi.clone();
    let mut known = vec![false; n];
    let mut done = vec![false; n];
    let mut stages = Vec::new();
    let fixed = cx.fix(&mut phi, &mut known, &mut done);
    if !fixed.is_empty() {
        stages.push(Stage::Explicit(fixed));
    }
    // The fixed coordinates stay a stage of their own; later consecutive assignments merge
    // into one explicit stage, each reading the earlier ones of its stage by substitution.
    let first_free = stages.len();
    for component in cx.components(&phi, &known, &done) {
        let open = stages.len() > first_free && matches!(stages.last(), Some(Stage::Explicit(_)));
        if !open {
            cx.local.clear();
        }
        match (cx.stage(&phi, component), stages.last_mut()) {
            (Stage::Explicit(more), Some(Stage::Explicit(previous))) if open => {
                previous.extend(more);
            }
            (stage, _) => stages.push(stage),
        }
    }
    let reads = reads(cx.arena, &stages, n);
    Plan { stages, reads }
}

/// The earlier stages each stage reads (through its positions or residuals: rates read the
/// same stages).
fn reads(arena: &Arena, stages: &[Stage], n: usize) -> Vec<Vec<usize>> {
    let mut stage_of = vec![0; n];
    for (s, stage) in stages.iter().enumerate() {
        for c in stage_coordinates(stage) {
            stage_of[c] = s;
        }
    }
    stages
        .iter()
        .enumerate()
        .map(|(s, stage)| {
            let expressions: Vec<Id> = match stage {
                Stage::Explicit(assignments) => assignments.iter().map(|a| a.position).collect(),
                Stage::Block(block) => block.residuals.clone(),
            };
            let mut read: Vec<usize> = expressions
                .iter()
                .flat_map(|&e| arena.variables(e))
                .filter_map(|v| match v {
                    Var::Q(k) => Some(stage_of[k as usize]),
                    _ => None,
                })
                .filter(|&r| r != s)
                .collect();
            read.sort_unstable();
            read.dedup();
            read
        })
        .collect()
}

/// The coordinates a stage determines.
pub fn stage_coordinates(stage: &Stage) -> Vec<usize> {
    match stage {
        Stage::Explicit(assignments) => assignments.iter().map(|a| a.coordinate).collect(),
        Stage::Block(block) => block.coordinates.clone(),
    }
}

/// The plan without structure: every equation in one block, factored with partial pivoting at
/// run time (what the runtime did before scenes carried their structure).
pub fn single_block(kin: &Kinematics) -> Plan {
    let n = kin.phi.len();
    let mut entries: Vec<(usize, usize, Id)> = kin
        .jacobian
        .iter()
        .map(|e| (e.row, e.col, e.value))
        .collect();
    entries.sort_by_key(|&(r, c, _)| (c, r));
    Plan {
        stages: vec![Stage::Block(Block {
            equations: (0..n).collect(),
            coordinates: (0..n).collect(),
            residuals: kin.phi.clone(),
            entries,
            factorization: None,
            velocity_rhs: kin.nu.clone(),
            acceleration_rhs: kin.gamma.clone(),
            closed: None,
        })],
        reads: vec![Vec::new()],
    }
}

/// Each row of Φ_q as (coordinate, ∂Φ/∂q) pairs.
fn jacobian_rows(kin: &Kinematics, n: usize) -> Vec<Vec<(usize, Id)>> {
    let mut rows = vec![Vec::new(); n];
    for e in &kin.jacobian {
        rows[e.row].push((e.col, e.value));
    }
    rows
}

/// One structured component of the remaining system: equations and their matched coordinates.
struct Component {
    equations: Vec<usize>,
    coordinates: Vec<usize>,
}

struct Planner<'a> {
    arena: &'a mut Arena,
    kin: &'a Kinematics,
    d: Differentiator,
    /// Rows of the (unsubstituted) Jacobian.
    rows: Vec<Vec<(usize, Id)>>,
    /// Substitutions applied to every expression of the plan: fixed coordinates by their
    /// values, and constant rates (`Var::Qd`, `Var::Qdd`) by theirs.
    map: HashMap<Var, Id>,
    /// The explicit stage being built: its coordinates' positions, velocities and accelerations
    /// by variable, substituted into the later assignments of the stage (which its kernels
    /// evaluate before writing anything back).
    local: HashMap<Var, Id>,
    outputs: Outputs,
    params: Vec<f64>,
    /// A representative configuration for choosing pivots: the initial guess, with explicit
    /// coordinates assigned at t = 0.
    sample: Vec<f64>,
}

impl Planner<'_> {
    /// Step 1: fixed coordinates, until substituting them reveals no more.
    fn fix(&mut self, phi: &mut [Id], known: &mut [bool], done: &mut [bool]) -> Vec<Assignment> {
        let mut fixed = Vec::new();
        loop {
            let start = fixed.len();
            for i in 0..phi.len() {
                if done[i] {
                    continue;
                }
                let Some(c) = self.single_unknown(phi[i], known) else {
                    continue;
                };
                let Some((value, _)) = self.explicit_value(phi[i], c) else {
                    continue;
                };
                if !self.arena.is_invariant(value) {
                    continue;
                }
                known[c] = true;
                done[i] = true;
                self.map.insert(Var::Q(var_index(c)), value);
                let zero = self.arena.zero();
                self.map.insert(Var::Qd(var_index(c)), zero);
                self.map.insert(Var::Qdd(var_index(c)), zero);
                let rates = self.outputs >= Outputs::Velocities;
                let accelerations = self.outputs >= Outputs::Accelerations;
                fixed.push(Assignment {
                    equation: i,
                    coordinate: c,
                    position: value,
                    velocity: rates.then_some(zero),
                    acceleration: accelerations.then_some(zero),
                });
                self.sample[c] = self.evaluate(&[value], &self.sample.clone())[0];
            }
            if fixed.len() == start {
                break;
            }
            let mut memo = HashMap::new();
            for (i, e) in phi.iter_mut().enumerate() {
                if !done[i] {
                    *e = self.arena.substitute(*e, &self.map, &mut memo);
                }
            }
        }
        // Fixed positions are constants, so any order serves the forward sweep: by coordinate
        // reads best. The force solve does not rely on it (it resolves the stage's
        // multipliers in their own dependency order, `reactions`).
        fixed.sort_by_key(|a| a.coordinate);
        fixed
    }

    /// The only coordinate of `e` not yet known, if there is exactly one.
    fn single_unknown(&self, e: Id, known: &[bool]) -> Option<usize> {
        let mut unknown = self.unknowns(e, known);
        (unknown.len() == 1).then(|| unknown.remove(0))
    }

    fn unknowns(&self, e: Id, known: &[bool]) -> Vec<usize> {
        self.arena
            .variables(e)
            .into_iter()
            .filter_map(|v| match v {
                Var::Q(k) if !known[k as usize] => Some(k as usize),
                _ => None,
            })
            .collect()
    }

    /// `(q_c = −g/a, a)` if `e = a·q_c + g` with a constant non-zero `a`.
    fn explicit_value(&mut self, e: Id, c: usize) -> Option<(Id, f64)> {
        let slope = self.d.diff(self.arena, e, Var::Q(var_index(c)));
        let a = self.arena.as_const(slope)?;
        if a == 0.0 || !a.is_finite() {
            return None;
        }
        let zero = HashMap::from([(Var::Q(var_index(c)), self.arena.zero())]);
        let g = self.arena.substitute(e, &zero, &mut HashMap::new());
        Some((self.divide(g, -a), a))
    }

    /// `e / a` for a constant `a`, exactly `e` or `−e` for ±1.
    fn divide(&mut self, e: Id, a: f64) -> Id {
        if a == 1.0 {
            e
        } else if a == -1.0 {
            self.arena.neg(e)
        } else {
            let a = self.arena.constant(a);
            self.arena.div(e, a)
        }
    }

    /// Step 2: the remaining system's components in dependency order (one component of
    /// everything if its structure is singular: the run time's diagnosis then names the
    /// equations).
    fn components(&self, phi: &[Id], known: &[bool], done: &[bool]) -> Vec<Component> {
        let equations: Vec<usize> = (0..phi.len()).filter(|&i| !done[i]).collect();
        let coordinates: Vec<usize> = (0..known.len()).filter(|&c| !known[c]).collect();
        let mut local = vec![usize::MAX; known.len()];
        for (l, &c) in coordinates.iter().enumerate() {
            local[c] = l;
        }
        let pattern: Vec<Vec<usize>> = equations
            .iter()
            .map(|&i| {
                self.unknowns(phi[i], known)
                    .into_iter()
                    .map(|c| local[c])
                    .collect()
            })
            .collect();
        let matching = graph::maximum_matching(&pattern, coordinates.len());
        if !matching.is_perfect() {
            return vec![Component {
                equations,
                coordinates,
            }];
        }
        // Equation r depends on the equation matched to each other coordinate it reads.
        let successors: Vec<Vec<usize>> = pattern
            .iter()
            .enumerate()
            .map(|(r, cols)| {
                cols.iter()
                    .filter(|&&c| c != matching.row[r])
                    .map(|&c| matching.column[c])
                    .collect()
            })
            .collect();
        graph::strongly_connected_components(equations.len(), |r| &successors[r])
            .into_iter()
            .map(|rows| Component {
                coordinates: rows.iter().map(|&r| coordinates[matching.row[r]]).collect(),
                equations: rows.iter().map(|&r| equations[r]).collect(),
            })
            .collect()
    }

    /// Steps 3 and 4: a component as an explicit assignment or a Newton block.
    fn stage(&mut self, phi: &[Id], component: Component) -> Stage {
        if let ([i], [c]) = (&component.equations[..], &component.coordinates[..])
            && let Some((position, a)) = self.explicit_value(phi[*i], *c)
        {
            return Stage::Explicit(vec![self.assignment(*i, *c, position, a)]);
        }
        Stage::Block(self.block(phi, component))
    }

    /// The assignment of `q_c` by equation `i` (coefficient `a` of `q_c` in it), with its rates.
    fn assignment(&mut self, i: usize, c: usize, position: Id, a: f64) -> Assignment {
        let known = self.sample.clone();
        self.sample[c] = self.evaluate(&[position], &known)[0];
        let position = self.within_stage(Var::Q(var_index(c)), position);
        let velocity = (self.outputs >= Outputs::Velocities).then(|| {
            let nu = self.kin.nu.as_ref().map_or(self.arena.zero(), |nu| nu[i]);
            let rhs = self.rate_rhs(nu, i, &[c], Var::Qd);
            let value = self.divide(rhs, a);
            let value = self.forward(Var::Qd(var_index(c)), value);
            self.within_stage(Var::Qd(var_index(c)), value)
        });
        let acceleration = (self.outputs >= Outputs::Accelerations).then(|| {
            let gamma = self.kin.gamma.as_ref().map_or(self.arena.zero(), |g| g[i]);
            let rhs = self.rate_rhs(gamma, i, &[c], Var::Qdd);
            let value = self.divide(rhs, a);
            let value = self.forward(Var::Qdd(var_index(c)), value);
            self.within_stage(Var::Qdd(var_index(c)), value)
        });
        Assignment {
            equation: i,
            coordinate: c,
            position,
            velocity,
            acceleration,
        }
    }

    /// `value` with the stage's earlier assignments of its own level substituted (positions
    /// into positions, velocities into velocities, …), then remembered as `var`'s.
    fn within_stage(&mut self, var: Var, value: Id) -> Id {
        let same_level = |v: &Var| {
            matches!(
                (v, var),
                (Var::Q(_), Var::Q(_)) | (Var::Qd(_), Var::Qd(_)) | (Var::Qdd(_), Var::Qdd(_))
            )
        };
        let level: HashMap<Var, Id> = self
            .local
            .iter()
            .filter(|(v, _)| same_level(v))
            .map(|(&v, &e)| (v, e))
            .collect();
        let value = self.arena.substitute(value, &level, &mut HashMap::new());
        self.local.insert(var, value);
        value
    }

    /// `value` with the plan's substitutions; remembered as `var`'s value if it is constant.
    fn forward(&mut self, var: Var, value: Id) -> Id {
        let value = self.arena.substitute(value, &self.map, &mut HashMap::new());
        if self.arena.is_invariant(value) {
            self.map.insert(var, value);
        }
        value
    }

    /// `base_i − Σ_{k ∉ own} Φ_q[i, k] · rate(k)`, substituted: a rate right-hand side of row
    /// `i` with the rates of earlier stages moved over.
    fn rate_rhs(&mut self, base: Id, i: usize, own: &[usize], rate: fn(u32) -> Var) -> Id {
        let mut rhs = base;
        for (k, value) in self.rows[i].clone() {
            if own.contains(&k) {
                continue;
            }
            let r = self.arena.var(rate(var_index(k)));
            let term = self.arena.mul(value, r);
            rhs = self.arena.sub(rhs, term);
        }
        self.arena.substitute(rhs, &self.map, &mut HashMap::new())
    }

    fn block(&mut self, phi: &[Id], component: Component) -> Block {
        let Component {
            equations,
            coordinates,
        } = component;
        let n = equations.len();
        // Entries in the component's natural local order.
        let mut natural = Vec::new();
        for (r, &i) in equations.iter().enumerate() {
            for (col, &c) in coordinates.iter().enumerate() {
                let value = self.d.diff(self.arena, phi[i], Var::Q(var_index(c)));
                if !self.arena.is_zero(value) {
                    natural.push((r, col, value));
                }
            }
        }
        let values: Vec<Id> = natural.iter().map(|e| e.2).collect();
        let sample = self.evaluate(&values, &self.sample.clone());
        let constant: Vec<bool> = values
            .iter()
            .map(|&v| self.arena.as_const(v).is_some())
            .collect();
        let pattern: Vec<(usize, usize)> = natural.iter().map(|e| (e.0, e.1)).collect();
        let (pivot_rows, pivot_columns) = factor::order(n, &pattern, &sample, &constant);
        let (row_rank, column_rank) = (ranks(&pivot_rows), ranks(&pivot_columns));
        let mut entries: Vec<(usize, usize, Id)> = natural
            .iter()
            .map(|&(r, c, v)| (row_rank[r], column_rank[c], v))
            .collect();
        entries.sort_by_key(|&(r, c, _)| (c, r));
        let equations: Vec<usize> = pivot_rows.iter().map(|&r| equations[r]).collect();
        let coordinates: Vec<usize> = pivot_columns.iter().map(|&c| coordinates[c]).collect();
        let positions: Vec<(usize, usize)> = entries.iter().map(|&(r, c, _)| (r, c)).collect();
        let factorization =
            Some(Factorization::new(n, &positions)).filter(|f| f.updates() <= MAX_STATIC_UPDATES);
        let residuals: Vec<Id> = equations.iter().map(|&i| phi[i]).collect();
        let velocity_rhs = (self.outputs >= Outputs::Velocities).then(|| {
            equations
                .iter()
                .map(|&i| {
                    let nu = self.kin.nu.as_ref().map_or(self.arena.zero(), |nu| nu[i]);
                    self.rate_rhs(nu, i, &coordinates, Var::Qd)
                })
                .collect()
        });
        let acceleration_rhs = (self.outputs >= Outputs::Accelerations).then(|| {
            equations
                .iter()
                .map(|&i| {
                    let gamma = self.kin.gamma.as_ref().map_or(self.arena.zero(), |g| g[i]);
                    self.rate_rhs(gamma, i, &coordinates, Var::Qdd)
                })
                .collect()
        });
        let closed = closed::recognize(self.arena, &coordinates, &residuals).map(Box::new);
        Block {
            equations,
            coordinates,
            residuals,
            entries,
            factorization,
            velocity_rhs,
            acceleration_rhs,
            closed,
        }
    }

    /// `roots` at positions `q`, t = 0 and the default parameters (NaN where undefined).
    fn evaluate(&self, roots: &[Id], q: &[f64]) -> Vec<f64> {
        let tape = Tape::new(self.arena, roots);
        let mut out = vec![0.0; roots.len()];
        let inputs = Inputs {
            q,
            qd: &[],
            qdd: &[],
            trig: &[],
            lambda: &[],
            t: 0.0,
            params: &self.params,
            free: &[],
        };
        tape.eval(inputs, &mut tape.scratch(), &mut out);
        out
    }
}

/// `ranks[p[k]] = k` for a permutation `p`.
fn ranks(permutation: &[usize]) -> Vec<usize> {
    let mut ranks = vec![0; permutation.len()];
    for (k, &p) in permutation.iter().enumerate() {
        ranks[p] = k;
    }
    ranks
}

#[cfg(test)]
mod tests {
    use super::{Block, Stage, stage_coordinates};
    use crate::expr::tape::{Env, eval};
    use crate::expr::{Arena, Func, Id, Node, Var};
    use crate::plan::trig::Phase;

    fn compile(source: &str) -> crate::Scene {
        crate::compile(crate::Input::Text(source), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{e}"))
    }

    /// A crank-rocker. Coordinates: frame 0–2, crank 3–5, coupler 6–8, rocker 9–11 (x, y, θ).
    /// Equations: frame 0–2, crank_pivot 3–4, crank_pin 5–6, rocker_pin 7–8, rocker_pivot
    /// 9–10, crank_angle 11.
    fn four_bar(coupler_angle: f64, rocker_angle: f64) -> String {
        format!(
            "mechanism FourBar {{
                ground frame at (0, 0, 0);
                body crank near (0, 0, 0);
                body coupler near (40, 0, {coupler_angle});
                body rocker near (100, 0, {rocker_angle});
                joint crank_pivot: revolute(frame, crank);
                joint crank_pin: revolute(crank @ (40, 0), coupler);
                joint rocker_pin: revolute(coupler @ (120, 0), rocker @ (80, 0));
                joint rocker_pivot: revolute(rocker, frame @ (100, 0));
                driver crank_angle: angle(crank) = 10 * t;
            }}"
        )
    }

    /// A slider-crank whose rod's angle alone is a block. Coordinates: frame 0–2, crank 3–5,
    /// rod 6–8, slider 9–11. Equations: frame 0–2, pivot 3–4, crank_pin 5–6, wrist 7–8,
    /// guide 9–10 (normal, angle), spin 11.
    fn slider_crank(extra: &str) -> String {
        format!(
            "mechanism SliderCrank {{
                ground frame at (0, 0, 0);
                body crank near (0, 0, 0);
                body rod near (40, 0, -0.2);
                body slider near (140, 0, 0);
                joint pivot: revolute(frame, crank);
                joint crank_pin: revolute(crank @ (40, 0), rod);
                joint wrist: revolute(rod @ (100, 0), slider);
                joint guide: prismatic(frame, slider, along (1, 0));
                driver spin: angle(crank) = 10 * t;
                {extra}
            }}"
        )
    }

    /// (equation, coordinate) of each assignment of an explicit stage, in order.
    fn pairs(stage: &Stage) -> Vec<(usize, usize)> {
        match stage {
            Stage::Explicit(assignments) => assignments
                .iter()
                .map(|a| (a.equation, a.coordinate))
                .collect(),
            Stage::Block(_) => panic!("a block where an explicit stage was expected"),
        }
    }

    fn block(stage: &Stage) -> &Block {
        match stage {
            Stage::Block(block) => block,
            Stage::Explicit(_) => panic!("an explicit stage where a block was expected"),
        }
    }

    /// The node `f(q_k)`, which the scene must hold.
    fn trig_of(arena: &Arena, f: Func, k: u32) -> Id {
        let q = arena
            .find(Node::Var(Var::Q(k)))
            .expect("the scene reads q_k");
        arena
            .find(Node::Call(f, q))
            .expect("the scene reads f(q_k)")
    }

    /// q with the four-bar's fixed coordinates at their values (the rest as given).
    fn four_bar_state(crank: f64, coupler: [f64; 3], rocker: f64) -> Vec<f64> {
        let [x, y, theta] = coupler;
        vec![
            0.0, 0.0, 0.0, 0.0, 0.0, crank, x, y, theta, 100.0, 0.0, rocker,
        ]
    }

    #[test]
    fn a_four_bar_is_fixed_then_explicit_then_one_block() {
        let scene = compile(&four_bar(0.6, 1.1));
        let plan = &scene.plan;
        assert_eq!(plan.stages.len(), 3);
        // The frame and both pivots are constants, listed by coordinate.
        assert_eq!(
            pairs(&plan.stages[0]),
            [(0, 0), (1, 1), (2, 2), (3, 3), (4, 4), (9, 9), (10, 10)]
        );
        // The driven crank angle, then the crank pin placing the coupler: one explicit stage.
        assert_eq!(pairs(&plan.stages[1]), [(11, 5), (5, 6), (6, 7)]);
        // The rocker pin closes the loop: both angles at once.
        let b = block(&plan.stages[2]);
        let (mut equations, mut coordinates) = (b.equations.clone(), b.coordinates.clone());
        equations.sort_unstable();
        coordinates.sort_unstable();
        assert_eq!((equations, coordinates), (vec![7, 8], vec![8, 11]));
        assert_eq!(plan.blocks().count(), 1);
        assert_eq!(plan.assignments().count(), 10);
        assert_eq!((plan.largest_block(), plan.largest_slots()), (2, 4));
        // Every coordinate is solved by exactly one stage.
        let mut solved: Vec<usize> = plan.stages.iter().flat_map(stage_coordinates).collect();
        solved.sort_unstable();
        assert_eq!(solved, (0..12).collect::<Vec<_>>());
        // The fixed values are substituted: only the block reads an earlier stage (the coupler's
        // x and y, from stage 1).
        assert_eq!(plan.reads, [vec![], vec![], vec![1]]);
    }

    #[test]
    fn explicit_assignments_are_closed_forms_of_earlier_values() {
        let scene = compile(&four_bar(0.6, 1.1));
        let arena = &scene.model.arena;
        let Stage::Explicit(fixed) = &scene.plan.stages[0] else {
            panic!("the fixed stage comes first")
        };
        for a in fixed {
            let expected = if a.coordinate == 9 { 100.0 } else { 0.0 };
            assert_eq!(
                arena.as_const(a.position),
                Some(expected),
                "{}",
                a.coordinate
            );
            assert!(arena.is_zero(a.velocity.expect("velocities")));
            assert!(arena.is_zero(a.acceleration.expect("accelerations")));
        }
        let Stage::Explicit(stage) = &scene.plan.stages[1] else {
            panic!("the crank and the coupler's pin are explicit")
        };
        // Each position reads only t: the crank's angle, assigned earlier in the stage, is
        // substituted into the coupler's.
        for a in stage {
            assert_eq!(arena.variables(a.position), [Var::T], "{}", a.coordinate);
        }
        // At t = 0.1 the crank is at 1 rad turning at 10 rad/s: the coupler's reference point
        // is the crank pin, 40 (cos, sin) of it.
        let angle = 1.0_f64;
        let env = Env {
            q: four_bar_state(angle, [0.0; 3], 0.0),
            qd: vec![0.0; 12],
            qdd: vec![0.0; 12],
            t: 0.1,
            params: Vec::new(),
            free: Vec::new(),
        };
        let (s, c) = angle.sin_cos();
        let expected = [
            [angle, 10.0, 0.0],
            [40.0 * c, -400.0 * s, -4000.0 * c],
            [40.0 * s, 400.0 * c, -4000.0 * s],
        ];
        for (a, expected) in stage.iter().zip(expected) {
            let rates = [a.velocity, a.acceleration].map(|r| r.expect("rates"));
            let values = [a.position, rates[0], rates[1]].map(|id| eval(arena, id, &env));
            for (value, expected) in values.into_iter().zip(expected) {
                assert!((value - expected).abs() < 1e-9, "{value} ≠ {expected}");
            }
        }
    }

    #[test]
    fn a_block_is_the_scenes_rows_and_columns_in_pivot_order() {
        let scene = compile(&four_bar(0.6, 1.1));
        let b = block(&scene.plan.stages[2]);
        let arena = &scene.model.arena;
        let env = Env {
            q: four_bar_state(0.3, [40.0 * 0.3_f64.cos(), 40.0 * 0.3_f64.sin(), 0.5], 1.2),
            ..Env::default()
        };
        for (r, &i) in b.equations.iter().enumerate() {
            let (residual, textbook) = (b.residuals[r], scene.kinematics.phi[i]);
            assert!((eval(arena, residual, &env) - eval(arena, textbook, &env)).abs() < 1e-12);
        }
        // Dense 2 × 2, column-major, each entry Φ_q at its (equation, coordinate).
        let positions: Vec<(usize, usize)> = b.entries.iter().map(|e| (e.0, e.1)).collect();
        assert_eq!(positions, [(0, 0), (1, 0), (0, 1), (1, 1)]);
        for &(r, c, value) in &b.entries {
            let (row, col) = (b.equations[r], b.coordinates[c]);
            let textbook = scene.kinematics.jacobian.iter();
            let textbook = textbook
                .filter(|e| (e.row, e.col) == (row, col))
                .map(|e| e.value)
                .next()
                .expect("a structural non-zero of Φ_q");
            let (planned, textbook) = (eval(arena, value, &env), eval(arena, textbook, &env));
            assert!((planned - textbook).abs() < 1e-12, "({row}, {col})");
        }
        let lu = b.factorization.as_ref().expect("a static LU");
        assert_eq!((lu.n, lu.entries, lu.slots), (2, 4, 4));
    }

    #[test]
    fn the_pivot_order_follows_the_initial_guess() {
        // ∂(rocker_pin)/∂(θ_coupler, θ_rocker) = 120 (−sin, cos) θc and 80 (sin, −cos) θr, up to
        // sign. At (0.6, 1.1) the largest of each column relative to its column are y/θc and
        // x/θr, and the first row wins: x pivots on the rocker. At (1.5, 0.2) they are x/θc and
        // y/θr: x pivots on the coupler.
        for ((coupler, rocker), first) in [((0.6, 1.1), 11), ((1.5, 0.2), 8)] {
            let scene = compile(&four_bar(coupler, rocker));
            let b = block(&scene.plan.stages[2]);
            assert_eq!(b.equations, [7, 8], "rows: rocker_pin.x, then .y");
            let second = if first == 11 { 8 } else { 11 };
            assert_eq!(
                b.coordinates,
                [first, second],
                "guess ({coupler}, {rocker})"
            );
        }
    }

    #[test]
    fn a_slider_crank_caches_the_angles_read_after_their_stage() {
        let scene = compile(&slider_crank(""));
        let plan = &scene.plan;
        // Fixed (frame, crank pivot, slider's y and θ), explicit (crank, rod pin), the rod's
        // angle alone (wrist.y is not affine in it), then the slider's x.
        assert_eq!(
            pairs(&plan.stages[0]),
            [(0, 0), (1, 1), (2, 2), (3, 3), (4, 4), (9, 10), (10, 11)]
        );
        assert_eq!(pairs(&plan.stages[1]), [(11, 5), (5, 6), (6, 7)]);
        let b = block(&plan.stages[2]);
        assert_eq!((&b.equations[..], &b.coordinates[..]), (&[8][..], &[8][..]));
        assert_eq!(pairs(&plan.stages[3]), [(7, 9)]);
        assert_eq!(plan.reads, [vec![], vec![], vec![1], vec![1, 2]]);
        // The crank's sine (its stage's rates) and the rod's cosine (the slider's position):
        // slots of two, filled by the angle's stage.
        let trig = &scene.kernels.trig;
        assert_eq!(trig.angles, [5, 8]);
        assert_eq!(trig.filled_by, [1, 2]);
        assert_eq!(
            (trig.len(), trig.fills(2).collect::<Vec<_>>()),
            (4, vec![1])
        );
        let arena = &scene.model.arena;
        for (m, &k) in trig.angles.iter().enumerate() {
            let k = k as u32;
            let (sin, cos) = (trig_of(arena, Func::Sin, k), trig_of(arena, Func::Cos, k));
            assert_eq!(trig.nodes[m], (sin, cos));
            assert_eq!((trig.slot[&sin], trig.slot[&cos]), (2 * m, 2 * m + 1));
        }
    }

    #[test]
    fn a_kernel_reads_the_cache_once_its_angle_is_solved() {
        let scene = compile(&slider_crank(""));
        let (plan, arena, trig) = (&scene.plan, &scene.model.arena, &scene.kernels.trig);
        let sin_rod = trig_of(arena, Func::Sin, 8);
        let b = block(&plan.stages[2]);
        // The block's residual reads sin θ_rod while solving for it: computed, not cached.
        let residual = &b.residuals;
        assert!(trig.reads(arena, residual, 2, Phase::Positions).is_empty());
        let after = trig.reads(arena, residual, 2, Phase::After);
        assert_eq!(after.into_iter().collect::<Vec<_>>(), [(sin_rod, 2)]);
        let last = trig.reads(arena, residual, 2, Phase::Final);
        assert_eq!(last.into_iter().collect::<Vec<_>>(), [(sin_rod, 2)]);
        // The slider's x, a stage later, reads the rod's cosine from the cache.
        let Stage::Explicit(slider) = &plan.stages[3] else {
            panic!("the slider's x is explicit")
        };
        let cos_rod = trig_of(arena, Func::Cos, 8);
        let position = trig.reads(arena, &[slider[0].position], 3, Phase::Positions);
        assert_eq!(position.into_iter().collect::<Vec<_>>(), [(cos_rod, 3)]);
    }

    #[test]
    fn only_what_a_scene_computes_is_cached() {
        // Positions only: no rates read the crank's sine; the slider still reads the rod's cosine.
        let positions = compile(&slider_crank("outputs positions;"));
        assert_eq!(positions.kernels.trig.angles, [8]);
        assert_eq!(positions.kernels.trig.filled_by, [2]);
        // A marker on the crank, evaluated after the sweep, reads the crank's angle too.
        let marker = compile(&slider_crank(
            "outputs positions; marker tip: crank @ (40, 0);",
        ));
        assert_eq!(marker.kernels.trig.angles, [5, 8]);
        assert_eq!(marker.kernels.trig.filled_by, [1, 2]);
    }

    #[test]
    fn fixing_repeats_until_substitution_reveals_nothing_more() {
        // The weld's x and y read the arm's angle through its point (−2, 0): they fix the arm's
        // x and y only once its angle is fixed, on the second pass. Listed by coordinate.
        let scene = compile(
            "mechanism Welded {
                ground frame at (0, 0, 0);
                body arm near (3, 0, 0);
                joint glue: weld(frame @ (1, 0), arm @ (-2, 0));
            }",
        );
        let plan = &scene.plan;
        assert_eq!(plan.stages.len(), 1);
        let pairs = pairs(&plan.stages[0]);
        assert_eq!(pairs, [(0, 0), (1, 1), (2, 2), (3, 3), (4, 4), (5, 5)]);
        let arena = &scene.model.arena;
        let positions: Vec<Option<f64>> = plan
            .assignments()
            .map(|a| arena.as_const(a.position))
            .collect();
        assert_eq!(positions, [0.0, 0.0, 0.0, 3.0, 0.0, 0.0].map(Some));
    }

    #[test]
    fn the_naive_baseline_is_one_block_of_everything() {
        let options = crate::Options {
            codegen: crate::CodegenOptions {
                naive: true,
                ..crate::CodegenOptions::default()
            },
            ..crate::Options::default()
        };
        let scene = crate::compile(crate::Input::Text(&four_bar(0.6, 1.1)), &options)
            .unwrap_or_else(|e| panic!("{e}"));
        let plan = &scene.plan;
        assert_eq!(plan.stages.len(), 1);
        let b = block(&plan.stages[0]);
        assert_eq!(b.equations, (0..12).collect::<Vec<_>>());
        assert_eq!(b.coordinates, (0..12).collect::<Vec<_>>());
        assert!(b.factorization.is_none());
        assert_eq!(b.slots(), scene.kinematics.jacobian.len());
        // Column-major, as the runtime's partial-pivoting factorisation reads them.
        assert!(
            b.entries
                .windows(2)
                .all(|w| (w[0].1, w[0].0) < (w[1].1, w[1].0))
        );
        assert_eq!(plan.reads, [Vec::<usize>::new()]);
        assert!(scene.kernels.trig.is_empty());
        assert_eq!(plan.largest_block(), 12);
    }
}
