//! Body frames as joints, drivers, markers and loads see them: a moving body through its
//! coordinates q, a ground body through its constant pose, and the world points, vectors,
//! offsets and driven quantities built on them. Kinematics, markers and dynamics all write
//! their expressions through it.

use crate::expr::{Arena, Id, Var, var_index};
use crate::model::{Driven, Model, Point};

/// The pose of each ground body (`None` for moving bodies): how joints see the frame.
pub(crate) fn ground_poses(model: &Model) -> Vec<Option<[Id; 3]>> {
    model
        .bodies
        .iter()
        .map(|b| b.ground.then_some(b.pose))
        .collect()
}

/// Body frames as joints see them: a moving body through its coordinates, a ground body
/// through its constant pose.
pub(crate) struct Frames<'a> {
    pub(crate) arena: &'a mut Arena,
    /// The pose of each ground body; `None` for moving bodies.
    pub(crate) poses: &'a [Option<[Id; 3]>],
}

impl Frames<'_> {
    /// Coordinate `k` (0 x, 1 y, 2 θ) of `body`: q for a moving body, the pose for a ground one.
    pub(crate) fn pose(&mut self, body: usize, k: usize) -> Id {
        match self.poses.get(body).copied().flatten() {
            Some(pose) => pose[k],
            None => self.arena.var(Var::Q(var_index(3 * body + k))),
        }
    }

    /// A(θ_body) v
    pub(crate) fn rotate(&mut self, body: usize, v: [Id; 2]) -> [Id; 2] {
        let theta = self.pose(body, 2);
        let a = &mut *self.arena;
        let (c, s) = (a.cos(theta), a.sin(theta));
        let (cx, sy) = (a.mul(c, v[0]), a.mul(s, v[1]));
        let (sx, cy) = (a.mul(s, v[0]), a.mul(c, v[1]));
        [a.sub(cx, sy), a.add(sx, cy)]
    }

    /// r_body + A(θ_body) s
    pub(crate) fn world_point(&mut self, p: Point) -> [Id; 2] {
        let offset = self.rotate(p.body, p.local);
        let (x, y) = (self.pose(p.body, 0), self.pose(p.body, 1));
        [self.arena.add(x, offset[0]), self.arena.add(y, offset[1])]
    }

    /// World vector from `from`'s point to `to`'s point.
    pub(crate) fn separation(&mut self, from: Point, to: Point) -> [Id; 2] {
        let (rf, rt) = (self.world_point(from), self.world_point(to));
        [self.arena.sub(rt[0], rf[0]), self.arena.sub(rt[1], rf[1])]
    }

    /// The world vector from `points[0]` to `points[1]`; between two points of one body it is
    /// that body's rotation of their difference (the body's position cancels exactly).
    pub(crate) fn vector(&mut self, points: [Point; 2]) -> [Id; 2] {
        let [from, to] = points;
        if from.body == to.body {
            let d = [0, 1].map(|k| self.arena.sub(to.local[k], from.local[k]));
            self.rotate(from.body, d)
        } else {
            self.separation(from, to)
        }
    }

    /// u · v
    pub(crate) fn dot(&mut self, u: [Id; 2], v: [Id; 2]) -> Id {
        let (x, y) = (self.arena.mul(u[0], v[0]), self.arena.mul(u[1], v[1]));
        self.arena.add(x, y)
    }

    /// b's point's offset from the line through a's point along a-fixed unit `axis`, along the
    /// normal n = A_a R u (R a quarter turn anticlockwise).
    pub(crate) fn normal_offset(&mut self, a: Point, b: Point, axis: [Id; 2]) -> Id {
        let neg_uy = self.arena.neg(axis[1]);
        let normal = self.rotate(a.body, [neg_uy, axis[0]]);
        let offset = self.separation(a, b);
        self.dot(normal, offset)
    }

    /// b's point's travel along the line through a's point along a-fixed unit `axis`.
    pub(crate) fn travel(&mut self, a: Point, b: Point, axis: [Id; 2]) -> Id {
        let u = self.rotate(a.body, axis);
        let d = self.separation(a, b);
        self.dot(u, d)
    }

    /// θ_body − θ_reference (θ_body alone without a reference).
    pub(crate) fn relative_angle(&mut self, body: usize, reference: Option<usize>) -> Id {
        let angle = self.pose(body, 2);
        match reference {
            Some(reference) => {
                let base = self.pose(reference, 2);
                self.arena.sub(angle, base)
            }
            None => angle,
        }
    }

    pub(crate) fn driven_quantity(&mut self, driven: Driven) -> Id {
        match driven {
            Driven::Angle(body) => self.pose(body, 2),
            Driven::RelativeAngle(from, to) => {
                let (tt, tf) = (self.pose(to, 2), self.pose(from, 2));
                self.arena.sub(tt, tf)
            }
            Driven::X(p) => self.world_point(p)[0],
            Driven::Y(p) => self.world_point(p)[1],
            Driven::Travel { a, b, axis } => self.travel(a, b, axis),
            Driven::Distance(a, b) => {
                let d = self.separation(a, b);
                let squared = self.dot(d, d);
                self.arena.call(crate::expr::Func::Sqrt, squared)
            }
        }
    }
}
