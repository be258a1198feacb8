//! Dynamics: the generalised applied and inertial forces `F(q, q̇, q̈, t)` on every coordinate,
//! from the scene's mass properties, gravity and loads. The constraint forces balance them,
//! `Φ_qᵀ λ = F` (the force solve, planned in `reactions`).
//!
//! Everything goes through the principle of virtual work: a force `f` at a world point `P(q)`
//! contributes `f · ∂P/∂q_k` to coordinate k (so a force at a body point also turns the body),
//! and a torque on a body contributes to its angle. Each law is written only as its force and
//! where it acts; the rest is symbolic differentiation.
//!
//! - **Inertia** (d'Alembert): `m (g − a_c)` at the centre of mass, `a_c` the second time
//!   derivative of its world position along the motion, and `−J θ̈` on the angle. With the
//!   centre at the reference point this is the constant block-diagonal `M q̈` (`m ẍ`, `m ÿ`,
//!   `J θ̈`); with an offset centre the same derivation adds the coupling and centripetal terms.
//! - **Forces** in world axes, or in the body's axes (turned by its angle).
//! - **Spring-dampers**: tension `k (ℓ − L) + c ℓ̇` along the line between the points
//!   (`ℓ` their distance), pulling them together: `−T ∂ℓ/∂q_k`.

use std::collections::HashMap;

use crate::expr::diff::Differentiator;
use crate::expr::{Arena, Func, Id, Var, var_index};
use crate::model::frames::{Frames, ground_poses};
use crate::model::{LoadKind, Model, Point};

/// The pull of the springs anchored to ground bodies on those bodies' coordinates (zero
/// elsewhere), with the frame seen through its coordinates and evaluated at its pose: part of
/// the load the mechanism puts on its frame (`reactions`).
pub fn ground_spring_loads(model: &mut Model) -> Vec<Id> {
    let n = model.dim();
    let ground: Vec<bool> = model.bodies.iter().map(|b| b.ground).collect();
    let at_rest: HashMap<Var, Id> = model
        .bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| b.ground)
        .flat_map(|(i, b)| {
            let zero = model.arena.zero();
            (0..3).flat_map(move |k| {
                let c = var_index(3 * i + k);
                [(Var::Q(c), b.pose[k]), (Var::Qd(c), zero)]
            })
        })
        .collect();
    let springs: Vec<LoadKind> = model
        .loads
        .iter()
        .map(|l| l.kind)
        .filter(|l| matches!(l, LoadKind::Spring { a, b, .. } if ground[a.body] || ground[b.body]))
        .collect();
    let zero = model.arena.zero();
    let textbook = vec![None; model.bodies.len()];
    let mut w = Work {
        frames: Frames {
            arena: &mut model.arena,
            poses: &textbook,
        },
        d: Differentiator::new(),
        forces: vec![zero; n],
    };
    for spring in springs {
        if let LoadKind::Spring {
            a,
            b,
            stiffness,
            length,
            damping,
        } = spring
        {
            w.spring(a, b, [stiffness, length, damping]);
        }
    }
    let mut memo = HashMap::new();
    (0..n)
        .map(|k| {
            if ground[k / 3] {
                w.frames.arena.substitute(w.forces[k], &at_rest, &mut memo)
            } else {
                zero
            }
        })
        .collect()
}

/// `F` per coordinate (zero for ground bodies and for massless, unloaded ones), adding its
/// nodes to the model's arena.
pub fn derive(model: &mut Model) -> Vec<Id> {
    let poses = ground_poses(model);
    let bodies: Vec<(bool, Option<crate::model::MassProperties>)> =
        model.bodies.iter().map(|b| (b.ground, b.mass)).collect();
    let loads: Vec<LoadKind> = model.loads.iter().map(|l| l.kind).collect();
    let gravity = model.gravity;
    let n = model.dim();
    let zero = model.arena.zero();
    let mut w = Work {
        frames: Frames {
            arena: &mut model.arena,
            poses: &poses,
        },
        d: Differentiator::new(),
        forces: vec![zero; n],
    };
    for (body, &(ground, mass)) in bodies.iter().enumerate() {
        if let (false, Some(mass)) = (ground, mass) {
            w.inertia(body, mass, gravity);
        }
    }
    for load in loads {
        w.load(load);
    }
    w.forces
}

/// Two values per load, for naming the load that makes F non-finite (on the failure path of
/// the force solve, `mechgen_runtime::codegen::first_load_fault`): the sum of its contributions to F,
/// finite exactly when they all are, and for a spring the squared distance between its ends
/// (its direction is undefined where they meet), 1 for other loads.
pub fn load_witnesses(model: &mut Model) -> Vec<Id> {
    let poses = ground_poses(model);
    let loads: Vec<LoadKind> = model.loads.iter().map(|l| l.kind).collect();
    let n = model.dim();
    let (zero, one) = (model.arena.zero(), model.arena.one());
    let mut w = Work {
        frames: Frames {
            arena: &mut model.arena,
            poses: &poses,
        },
        d: Differentiator::new(),
        forces: vec![zero; n],
    };
    let mut witnesses = Vec::with_capacity(2 * loads.len());
    for load in loads {
        w.forces.fill(zero);
        w.load(load);
        let sum = w
            .forces
            .iter()
            .fold(zero, |sum, &f| w.frames.arena.add(sum, f));
        let separation = match load {
            LoadKind::Spring { a, b, .. } => {
                let d = w.frames.separation(a, b);
                w.frames.dot(d, d)
            }
            _ => one,
        };
        witnesses.extend([sum, separation]);
    }
    witnesses
}

/// A force load's value in world axes (turned by its body's angle when given in the body's
/// axes) and the world point it acts at.
pub(super) fn world_force(
    frames: &mut Frames<'_>,
    point: Point,
    value: [Id; 2],
    local: bool,
) -> ([Id; 2], [Id; 2]) {
    let value = if local {
        frames.rotate(point.body, value)
    } else {
        value
    };
    (value, frames.world_point(point))
}

/// A spring-damper's line: `d = P_b − P_a` (world axes), `d · d = ℓ²` and `d · ḋ = ℓ ℓ̇`.
pub(super) struct SpringGeometry {
    pub d: [Id; 2],
    pub squared: Id,
    pub approach: Id,
}

/// The line of a spring-damper between the points `a` and `b`, its rate along the motion.
pub(super) fn spring_geometry(
    frames: &mut Frames<'_>,
    diff: &mut Differentiator,
    a: Point,
    b: Point,
) -> SpringGeometry {
    let d = frames.separation(a, b);
    let squared = frames.dot(d, d);
    let rate = d.map(|x| diff.time_derivative(frames.arena, x));
    let approach = frames.dot(d, rate);
    SpringGeometry {
        d,
        squared,
        approach,
    }
}

/// The forces gathered so far, and what builds them.
struct Work<'a> {
    frames: Frames<'a>,
    d: Differentiator,
    forces: Vec<Id>,
}

impl Work<'_> {
    fn arena(&mut self) -> &mut Arena {
        self.frames.arena
    }

    /// Adds one load's contributions.
    fn load(&mut self, load: LoadKind) {
        match load {
            LoadKind::Force {
                point,
                value,
                local,
            } => {
                let (value, at) = world_force(&mut self.frames, point, value, local);
                self.apply(value, at);
            }
            LoadKind::Torque { body, value } => self.torque(body, value),
            LoadKind::Spring {
                a,
                b,
                stiffness,
                length,
                damping,
            } => self.spring(a, b, [stiffness, length, damping]),
        }
    }

    /// `forces[k] += value`.
    fn add(&mut self, k: usize, value: Id) {
        let sum = self.frames.arena.add(self.forces[k], value);
        self.forces[k] = sum;
    }

    /// A force `f` (world axes) at the world point `at`: `f · ∂at/∂q_k` on every coordinate
    /// the point moves with.
    fn apply(&mut self, f: [Id; 2], at: [Id; 2]) {
        let mut coordinates = self.arena().variables(at[0]);
        coordinates.extend(self.arena().variables(at[1]));
        coordinates.sort_unstable();
        coordinates.dedup();
        for var in coordinates {
            let Var::Q(k) = var else { continue };
            let arena = &mut *self.frames.arena;
            let (dx, dy) = (
                self.d.diff(arena, at[0], var),
                self.d.diff(arena, at[1], var),
            );
            let (fx, fy) = (arena.mul(f[0], dx), arena.mul(f[1], dy));
            let work = arena.add(fx, fy);
            self.add(k as usize, work);
        }
    }

    /// A torque on a moving body's angle.
    fn torque(&mut self, body: usize, value: Id) {
        self.add(3 * body + 2, value);
    }

    /// Gravity and d'Alembert's inertia of a moving body: `m (g − a_c)` at its centre of mass,
    /// `−J θ̈` on its angle.
    fn inertia(&mut self, body: usize, mass: crate::model::MassProperties, gravity: [Id; 2]) {
        let centre = self.frames.world_point(Point {
            body,
            local: mass.centre,
        });
        let force = centre.map(|c| {
            let velocity = self.d.time_derivative(self.frames.arena, c);
            self.d.time_derivative(self.frames.arena, velocity)
        });
        let force = [0, 1].map(|k| {
            let arena = &mut *self.frames.arena;
            let free = arena.sub(gravity[k], force[k]);
            arena.mul(mass.mass, free)
        });
        self.apply(force, centre);
        let arena = &mut *self.frames.arena;
        let angular = arena.var(Var::Qdd(var_index(3 * body + 2)));
        let moment = arena.mul(mass.inertia, angular);
        let torque = arena.neg(moment);
        self.torque(body, torque);
    }

    /// A spring-damper between two points: tension `T = k (ℓ − L) + c ℓ̇` along `d = P_b − P_a`,
    /// pulling `a` by `T d/ℓ` and `b` by the opposite (toward each other when stretched).
    ///
    /// Written per unit length, `T/ℓ = k (1 − L/ℓ) + c (d·ḋ)/ℓ²`, so that a zero-length
    /// spring's force `k d` stays finite where its points meet, also when its length is a
    /// parameter set to 0 (`L/ℓ` is selected away, not computed as 0/0); otherwise its
    /// direction, and the force, are undefined there.
    fn spring(&mut self, a: Point, b: Point, [stiffness, length, damping]: [Id; 3]) {
        let (at_a, at_b) = (self.frames.world_point(a), self.frames.world_point(b));
        let SpringGeometry {
            d,
            squared,
            approach,
        } = spring_geometry(&mut self.frames, &mut self.d, a, b);
        let arena = &mut *self.frames.arena;
        let distance = arena.call(Func::Sqrt, squared);
        let rest = arena.mul(stiffness, length);
        let ratio = arena.div(rest, distance);
        let zero = arena.zero();
        let negative = arena.neg(rest);
        let size = arena.select(zero, rest, rest, negative);
        let shrink = arena.select(size, zero, zero, ratio);
        let elastic = arena.sub(stiffness, shrink);
        let damped = arena.mul(damping, approach);
        let viscous = arena.div(damped, squared);
        let per_length = arena.add(elastic, viscous);
        let pull = d.map(|x| arena.mul(per_length, x));
        let push = pull.map(|x| arena.neg(x));
        self.apply(pull, at_a);
        self.apply(push, at_b);
    }
}

#[cfg(test)]
mod tests {
    use crate::expr::tape::{Env, eval};

    fn forces(source: &str, env: &Env) -> Vec<f64> {
        let scene = crate::compile(crate::Input::Text(source), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{e}"));
        let mut model = scene.model;
        let forces = super::derive(&mut model);
        forces.iter().map(|&f| eval(&model.arena, f, env)).collect()
    }

    const PENDULUM: &str = "mechanism P {
        ground frame at (0, 0, 0);
        body arm near (1, 0, 0) mass 2 inertia 0.5 centre (0.5, 0.25);
        joint pivot: revolute(frame, arm);
        driver swing: angle(arm) = t;
        gravity (0, -9.81);
    }";

    #[test]
    fn inertia_and_gravity_act_at_the_centre_of_mass() {
        // arm at (0.2, 0.1), turned 0.7 rad, moving and accelerating.
        let (th, thd, thdd) = (0.7_f64, 1.3_f64, -0.4_f64);
        let (x, y) = (0.2, 0.1);
        let env = Env {
            q: vec![0.0, 0.0, 0.0, x, y, th],
            qd: vec![0.0, 0.0, 0.0, 0.3, -0.2, thd],
            qdd: vec![0.0, 0.0, 0.0, 0.05, 0.6, thdd],
            t: 0.0,
            params: vec![],
            free: Vec::new(),
        };
        let f = forces(PENDULUM, &env);
        assert_eq!(&f[..3], &[0.0; 3]);
        // The centre's world offset r = A(θ) (0.5, 0.25) and its acceleration.
        let (s, c) = th.sin_cos();
        let r = [0.5 * c - 0.25 * s, 0.5 * s + 0.25 * c];
        let a = [
            0.05 - thdd * r[1] - thd * thd * r[0],
            0.6 + thdd * r[0] - thd * thd * r[1],
        ];
        let force = [2.0 * (0.0 - a[0]), 2.0 * (-9.81 - a[1])];
        let torque = r[0] * force[1] - r[1] * force[0] - 0.5 * thdd;
        for (computed, exact) in f[3..].iter().zip([force[0], force[1], torque]) {
            assert!((computed - exact).abs() < 1e-12, "{computed} vs {exact}");
        }
    }

    #[test]
    fn springs_pull_their_points_together_with_damping() {
        let source = "mechanism S {
            ground frame at (0, 0, 0);
            body slider near (3, 0, 0);
            joint guide: prismatic(frame, slider, along (1, 0));
            driver push: x(slider) = t;
            load coil: spring(frame @ (1, 0), slider @ (0, 0), stiffness 10, length 1.5, damping 2);
            load kick: local_force(slider @ (0, 1)) = (3, 0);
            load twist: torque(slider) = 4 * t;
        }";
        // slider at x = 3 moving at 0.5, turned a quarter (its local x is world y).
        let th = core::f64::consts::FRAC_PI_2;
        let env = Env {
            q: vec![0.0, 0.0, 0.0, 3.0, 0.0, th],
            qd: vec![0.0, 0.0, 0.0, 0.5, 0.0, 0.0],
            qdd: vec![0.0; 6],
            t: 0.25,
            params: vec![],
            free: Vec::new(),
        };
        let f = forces(source, &env);
        // Stretched by 0.5 at 0.5/s: tension 10 · 0.5 + 2 · 0.5 = 6, pulling towards the frame.
        // The local force (3, 0) is (0, 3) in world axes, at the point (0, 1) whose world
        // offset is (−1, 0): a torque (−1)·3 − 0·0 = −3, plus the applied 4t = 1.
        let expected = [-6.0, 3.0, -3.0 + 1.0];
        for (computed, exact) in f[3..].iter().zip(expected) {
            assert!((computed - exact).abs() < 1e-12, "{f:?}");
        }
    }
}
