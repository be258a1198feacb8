//! Branch invariants: the sign of a dot or cross product of two vectors between points, which
//! tells the assembly branches apart.

use super::Checker;
use crate::expr::{Id, Node};
use crate::model::{Branch, Point};
use crate::syntax::spec::{BranchDecl, ExprKind};

impl Checker {
    /// A branch invariant: known bodies, points without `t`, the literal 0 on the right, no
    /// vector from a point to itself, and at least one vector that can turn.
    pub(super) fn branch(&mut self, decl: &BranchDecl) -> Option<Branch> {
        if !matches!(decl.zero.kind, ExprKind::Number(v) if v == 0.0) {
            self.errors.push(
                decl.zero.span,
                format!(
                    "compare the branch invariant with `0`: only its sign tells the branches \
                     apart; write `{}(…) > 0` or `{}(…) < 0`",
                    decl.product.name(),
                    decl.product.name()
                ),
            );
        }
        let [u0, u1, v0, v1] =
            [&decl.u[0], &decl.u[1], &decl.v[0], &decl.v[1]].map(|p| self.point(p));
        let (u, v) = ([u0?, u1?], [v0?, v1?]);
        let mut valid = true;
        for (points, refs) in [(u, &decl.u), (v, &decl.v)] {
            if self.same_point(points[0], points[1]) {
                self.errors.push(
                    refs[1].body.span(),
                    format!(
                        "this vector goes from a point of `{}` to the same point, so it has no \
                         direction; give two different points",
                        refs[0].body
                    ),
                );
                valid = false;
            }
        }
        let fixed = |points: [Point; 2]| points.iter().all(|p| self.ground[p.body]);
        if valid && fixed(u) && fixed(v) {
            self.errors.push(
                decl.product_span,
                "both vectors join points of ground bodies, so this invariant never changes; \
                 use points on moving bodies",
            );
            valid = false;
        }
        valid.then(|| Branch {
            name: decl.name.to_string(),
            docs: decl.docs.clone(),
            product: decl.product,
            u,
            v,
            sign: decl.sign,
        })
    }

    /// True if two points are structurally the same: one body, equal body-frame coordinates
    /// (the same node, or the same constant in an arena that does not fold).
    pub(super) fn same_point(&self, a: Point, b: Point) -> bool {
        let constant = |id: Id| {
            let arena = &self.arena;
            arena.as_const(id).or_else(|| {
                (!arena.any_node(id, |n| matches!(n, Node::Var(_) | Node::Param(_))))
                    .then(|| crate::expr::tape::eval(arena, id, &crate::expr::tape::Env::default()))
            })
        };
        a.body == b.body
            && (0..2).all(|k| {
                a.local[k] == b.local[k]
                    || matches!((constant(a.local[k]), constant(b.local[k])), (Some(x), Some(y)) if x == y)
            })
    }
}
