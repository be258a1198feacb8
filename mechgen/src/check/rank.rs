//! The structural rank of Φ_q: a maximum matching of equations to coordinates and the coarse
//! Dulmage–Mendelsohn decomposition into over- and under-determined parts, with the words that
//! name them in an error.

use super::plural;
use crate::expr::Var;
use crate::model::{ConstraintKind, Model};
use crate::sparse::graph::{self, UNMATCHED};

/// The structure of the Jacobian's sparsity pattern: which coordinates each equation touches
/// (ground bodies enter joints as constant poses, so only their own equations touch them), a
/// maximum matching of equations to coordinates, and from it the coarse Dulmage–Mendelsohn
/// decomposition.
///
/// A perfect matching means the Jacobian can be non-singular; otherwise it is singular at every
/// position, whatever the dimensions. Equations reachable from an unmatched equation by
/// alternating paths (equation → a coordinate it touches → the equation matched to that
/// coordinate → …) form the *over-determined* part: more equations than the coordinates they
/// touch. Coordinates reachable the same way from an unmatched coordinate form the
/// *under-determined* part.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Structure {
    /// Size of the maximum matching: the structural rank of Φ_q.
    pub rank: usize,
    /// Equations of the over-determined part, ascending.
    pub over_equations: Vec<usize>,
    /// Coordinates of the over-determined part, ascending.
    pub over_coordinates: Vec<usize>,
    /// Coordinates of the under-determined part, ascending.
    pub under_coordinates: Vec<usize>,
    /// The unmatched coordinates (free whatever the constraints do), ascending.
    pub under_free: Vec<usize>,
}

impl Structure {
    /// The structure of a model's Φ: the equations are built into the model's arena (the same
    /// hash-consed nodes `kinematics` derives from later) and each one's coordinates read off.
    pub fn of_model(model: &mut Model) -> Self {
        let rows = Self::rows_of(model);
        Self::of_pattern(&rows, model.dim())
    }

    /// The coordinates each of a model's equations touches, in Φ order.
    pub fn rows_of(model: &mut Model) -> Vec<Vec<usize>> {
        let phi = crate::model::kinematics::constraint_equations(model);
        phi.iter()
            .map(|&e| {
                model
                    .arena
                    .variables(e)
                    .into_iter()
                    .filter_map(|v| match v {
                        Var::Q(k) => Some(k as usize),
                        _ => None,
                    })
                    .collect()
            })
            .collect()
    }

    /// The structure of a pattern: `rows[i]` lists the coordinates (`< columns`) equation `i`
    /// touches.
    ///
    /// Augmenting paths from a greedy start, each search a depth-first walk with a look-ahead
    /// for a free coordinate and visit stamps: O(equations × non-zeros) at worst, near linear on
    /// the chains and trees of real mechanisms.
    pub fn of_pattern(rows: &[Vec<usize>], columns: usize) -> Self {
        let matching = graph::maximum_matching(rows, columns);
        let (row_match, col_match) = (&matching.row, &matching.column);
        let mut structure = Structure {
            rank: matching.size(),
            ..Structure::default()
        };
        // Over-determined: alternating walks from unmatched equations.
        let mut seen_row = vec![false; rows.len()];
        let mut seen_col = vec![false; columns];
        let mut queue: Vec<usize> = (0..rows.len())
            .filter(|&r| row_match[r] == UNMATCHED)
            .collect();
        for &r in &queue {
            seen_row[r] = true;
        }
        while let Some(r) = queue.pop() {
            for &c in &rows[r] {
                if !std::mem::replace(&mut seen_col[c], true) {
                    let next = col_match[c];
                    if next != UNMATCHED && !std::mem::replace(&mut seen_row[next], true) {
                        queue.push(next);
                    }
                }
            }
        }
        structure.over_equations = (0..rows.len()).filter(|&r| seen_row[r]).collect();
        structure.over_coordinates = (0..columns).filter(|&c| seen_col[c]).collect();
        // Under-determined: alternating walks from unmatched coordinates.
        let mut touching: Vec<Vec<usize>> = vec![Vec::new(); columns];
        for (r, cols) in rows.iter().enumerate() {
            for &c in cols {
                touching[c].push(r);
            }
        }
        let mut seen_row = vec![false; rows.len()];
        let mut seen_col = vec![false; columns];
        structure.under_free = (0..columns)
            .filter(|&c| col_match[c] == UNMATCHED)
            .collect();
        let mut queue = structure.under_free.clone();
        for &c in &queue {
            seen_col[c] = true;
        }
        while let Some(c) = queue.pop() {
            for &r in &touching[c] {
                if !std::mem::replace(&mut seen_row[r], true) {
                    let next = row_match[r];
                    if next != UNMATCHED && !std::mem::replace(&mut seen_col[next], true) {
                        queue.push(next);
                    }
                }
            }
        }
        structure.under_coordinates = (0..columns).filter(|&c| seen_col[c]).collect();
        structure
    }

    /// The constraints (indices into `model.constraints`) owning the over-determined equations.
    pub(super) fn over_constraints(&self, model: &Model) -> Vec<usize> {
        let mut owner = Vec::with_capacity(model.dim());
        for (k, c) in model.constraints.iter().enumerate() {
            owner.extend(std::iter::repeat_n(k, c.kind.equation_suffixes().len()));
        }
        let mut constraints: Vec<usize> = self
            .over_equations
            .iter()
            .filter_map(|&e| owner.get(e).copied())
            .collect();
        constraints.dedup();
        constraints
    }

    /// "joints `a`, `b` and driver `d`": the over-determined part's statements.
    pub(super) fn statements(&self, model: &Model) -> String {
        let mut groups: [(&str, Vec<String>); 3] = [
            ("ground bod", Vec::new()),
            ("joint", Vec::new()),
            ("driver", Vec::new()),
        ];
        for k in self.over_constraints(model) {
            let c = &model.constraints[k];
            let group = match c.kind {
                ConstraintKind::Ground { .. } => 0,
                ConstraintKind::Driver { .. } => 2,
                _ => 1,
            };
            groups[group].1.push(format!("`{}`", c.name));
        }
        let parts: Vec<String> = groups
            .iter()
            .filter(|(_, names)| !names.is_empty())
            .map(|(what, names)| {
                let what = match (*what, names.len()) {
                    ("ground bod", 1) => "ground body".to_owned(),
                    ("ground bod", _) => "ground bodies".to_owned(),
                    (what, 1) => what.to_owned(),
                    (what, _) => format!("{what}s"),
                };
                format!("{what} {}", names.join(", "))
            })
            .collect();
        match parts.as_slice() {
            [] => "no constraint".to_owned(),
            [one] => one.clone(),
            [init @ .., last] => format!("{} and {last}", init.join(", ")),
        }
    }

    /// "(7 equations for 6 coordinates)"
    pub(super) fn over_count(&self) -> String {
        format!(
            "{} equation{} for {} coordinate{}",
            self.over_equations.len(),
            plural(self.over_equations.len() as i64),
            self.over_coordinates.len(),
            plural(self.over_coordinates.len() as i64),
        )
    }

    pub(super) fn over_bodies(&self, model: &Model) -> String {
        bodies_of(model, &self.over_coordinates)
    }

    pub(super) fn under_bodies(&self, model: &Model) -> String {
        bodies_of(model, &self.under_coordinates)
    }

    pub(super) fn under_body_count(&self, model: &Model) -> usize {
        let mut bodies: Vec<usize> = self.under_coordinates.iter().map(|c| c / 3).collect();
        bodies.dedup();
        bodies.len().min(model.bodies.len())
    }
}

/// "body `a`" or "bodies `a`, `b`": the bodies owning `coordinates` (ascending).
pub(super) fn bodies_of(model: &Model, coordinates: &[usize]) -> String {
    let mut names: Vec<String> = Vec::new();
    let mut last = None;
    for &c in coordinates {
        if last != Some(c / 3) {
            last = Some(c / 3);
            if let Some(body) = model.bodies.get(c / 3) {
                names.push(format!("`{}`", body.name));
            }
        }
    }
    match names.len() {
        0 => "no body".to_owned(),
        1 => format!("body {}", names[0]),
        _ => format!("bodies {}", names.join(", ")),
    }
}
