//! Which constraint over-constrains: among the statements of the over-determined part, those
//! whose equations the others already impose structurally, so that removing one keeps the
//! structural rank of Φ_q. The Dulmage–Mendelsohn part alone names every statement of a loop
//! with one constraint too many (a four-bar with an extra distance joint over-determines the
//! whole loop); this test singles out the ones a user can delete: the extra joint, a copy of a
//! joint, or a driver of a mechanism its joints already hold rigid.

use crate::model::{ConstraintKind, Model, Point};
use crate::sparse::graph;

/// The constraints (indices into `model.constraints`) among `candidates` whose removal keeps
/// the structural rank: all their equations are structurally redundant. `rows[e]` lists the
/// coordinates equation `e` touches; `rank` is the structural rank with every equation.
///
/// One matching per candidate, on the failure path only (a scene is reported, not compiled).
pub(super) fn removable(
    model: &Model,
    rows: &[Vec<usize>],
    rank: usize,
    candidates: &[usize],
) -> Vec<usize> {
    let mut first = Vec::with_capacity(model.constraints.len());
    let mut start = 0;
    for c in &model.constraints {
        first.push(start);
        start += c.kind.equation_suffixes().len();
    }
    candidates
        .iter()
        .copied()
        .filter(|&k| {
            let Some(&from) = first.get(k) else {
                return false;
            };
            let to = first.get(k + 1).copied().unwrap_or(rows.len());
            let kept: Vec<Vec<usize>> = rows
                .iter()
                .enumerate()
                .filter(|&(e, _)| e < from || e >= to)
                .map(|(_, r)| r.clone())
                .collect();
            graph::maximum_matching(&kept, model.dim()).size() == rank
        })
        .collect()
}

/// Revolute joints among `candidates` that pin the same two points as an earlier one (in
/// either order; the arena is hash-consed, so equal constants are the same node): `(later,
/// earlier)`. Their equations are identical, which no structural count can see when other
/// joints share the excess.
pub(super) fn repeated_pins(model: &Model, candidates: &[usize]) -> Vec<(usize, usize)> {
    let pin = |k: usize| match model.constraints.get(k)?.kind {
        ConstraintKind::Revolute { a, b } => Some([a, b]),
        _ => None,
    };
    let same = |p: Point, q: Point| p.body == q.body && p.local == q.local;
    let mut repeats = Vec::new();
    for (i, &later) in candidates.iter().enumerate() {
        let Some([a, b]) = pin(later) else { continue };
        let earlier = candidates[..i].iter().copied().find(|&k| {
            pin(k).is_some_and(|[c, d]| (same(a, c) && same(b, d)) || (same(a, d) && same(b, c)))
        });
        if let Some(earlier) = earlier {
            repeats.push((later, earlier));
        }
    }
    repeats
}
