//! The energies of a scene with masses and the powers of its loads and dampers, as
//! expressions of `(q, q̇, t)`: what the integrator's energy bookkeeping reads
//! (`mechgen_runtime::EnergyTerms`), so that a user (and the tests) can see conservation.
//!
//! - **Gravity**: `V_g = −Σ m g · c` over the moving bodies with mass, `c` the world position
//!   of the centre of mass;
//! - **Springs**: `V_s = Σ ½ k (ℓ − L)²`;
//! - **Loads**: their power `Σ f · ṗ + τ θ̇` (forces at their world points, in world axes);
//! - **Dampers**: the power they dissipate, `Σ c ℓ̇² ≥ 0`.
//!
//! Each term is written from the same force laws as the generalised forces of `dynamics`
//! (its points, spring lines and rates), so `−dV/dt` is exactly the power of the
//! conservative part of `Q`, and the loads' and dampers' powers are those of the forces `Q`
//! holds.

use crate::expr::diff::Differentiator;
use crate::expr::{Arena, Func, Id};
use crate::model::dynamics::{SpringGeometry, spring_geometry, world_force};
use crate::model::frames::{Frames, ground_poses};
use crate::model::{LoadKind, Model, Point};

/// The four terms, in the order of `EnergyTerms`' fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Energy {
    /// Potential energy of gravity.
    pub gravity: Id,
    /// Potential energy of the springs.
    pub springs: Id,
    /// Power of the loads on the motion.
    pub loads: Id,
    /// Power dissipated by the dampers.
    pub dampers: Id,
}

impl Energy {
    /// `[gravity, springs, loads, dampers]`.
    pub fn terms(&self) -> [Id; 4] {
        [self.gravity, self.springs, self.loads, self.dampers]
    }
}

/// The energy terms of `model`, adding their nodes to its arena.
pub fn derive(model: &mut Model) -> Energy {
    let poses = ground_poses(model);
    let centres: Vec<(usize, Id, [Id; 2])> = (model.bodies.iter().enumerate())
        .filter(|(_, b)| !b.ground)
        .filter_map(|(i, b)| b.mass.map(|m| (i, m.mass, m.centre)))
        .collect();
    let loads: Vec<LoadKind> = model.loads.iter().map(|l| l.kind).collect();
    let gravity = model.gravity;
    let zero = model.arena.zero();
    let mut frames = Frames {
        arena: &mut model.arena,
        poses: &poses,
    };
    let mut diff = Differentiator::new();
    let mut energy = Energy {
        gravity: zero,
        springs: zero,
        loads: zero,
        dampers: zero,
    };
    for (body, mass, local) in centres {
        let centre = frames.world_point(Point { body, local });
        let height = frames.dot(gravity, centre);
        let arena = &mut *frames.arena;
        let work = arena.mul(mass, height);
        energy.gravity = arena.sub(energy.gravity, work);
    }
    for load in loads {
        add_load(&mut energy, &mut frames, &mut diff, load);
    }
    energy
}

/// Adds `load`'s power (a force or torque) or its stored energy and dissipation (a
/// spring-damper) to `energy`.
fn add_load(
    energy: &mut Energy,
    frames: &mut Frames<'_>,
    diff: &mut Differentiator,
    load: LoadKind,
) {
    match load {
        LoadKind::Force {
            point,
            value,
            local,
        } => {
            let (force, at) = world_force(frames, point, value, local);
            let velocity = at.map(|x| diff.time_derivative(frames.arena, x));
            let power = frames.dot(force, velocity);
            energy.loads = frames.arena.add(energy.loads, power);
        }
        LoadKind::Torque { body, value } => {
            let angle = frames.pose(body, 2);
            let rate = diff.time_derivative(frames.arena, angle);
            let arena = &mut *frames.arena;
            let power = arena.mul(value, rate);
            energy.loads = arena.add(energy.loads, power);
        }
        LoadKind::Spring {
            a,
            b,
            stiffness,
            length,
            damping,
        } => {
            let line = spring_geometry(frames, diff, a, b);
            let arena = &mut *frames.arena;
            let stored = spring_energy(arena, &line, stiffness, length);
            energy.springs = arena.add(energy.springs, stored);
            let dissipated = damper_power(arena, &line, damping);
            energy.dampers = arena.add(energy.dampers, dissipated);
        }
    }
}

/// `½ k (ℓ − L)²`, `ℓ = √(d · d)`.
fn spring_energy(arena: &mut Arena, line: &SpringGeometry, stiffness: Id, length: Id) -> Id {
    let distance = arena.call(Func::Sqrt, line.squared);
    let stretch = arena.sub(distance, length);
    let squared = arena.mul(stretch, stretch);
    let half = arena.constant(0.5);
    let half_k = arena.mul(half, stiffness);
    arena.mul(half_k, squared)
}

/// `c ℓ̇² = c (d · ḋ)² / (d · d)` (undefined where the points meet, as the damper's force is).
fn damper_power(arena: &mut Arena, line: &SpringGeometry, damping: Id) -> Id {
    let approach = arena.mul(line.approach, line.approach);
    let rate = arena.div(approach, line.squared);
    arena.mul(damping, rate)
}

#[cfg(test)]
mod tests {
    use crate::expr::tape::{Env, eval};
    use crate::expr::{Arena, Id};

    /// The model of `source` with its energy terms and generalised forces.
    fn derive(source: &str) -> (Arena, super::Energy, Vec<Id>) {
        let scene = crate::compile(crate::Input::Text(source), &crate::Options::default())
            .unwrap_or_else(|e| panic!("{e}"));
        let mut model = scene.model;
        let energy = super::derive(&mut model);
        let forces = crate::model::dynamics::derive(&mut model);
        (model.arena, energy, forces)
    }

    fn env(q: &[f64], qd: &[f64], t: f64) -> Env {
        Env {
            q: q.to_vec(),
            qd: qd.to_vec(),
            qdd: vec![0.0; q.len()],
            t,
            params: vec![],
            free: Vec::new(),
        }
    }

    /// A deterministic pseudo-random number in [−1, 1) (xorshift), for the random states.
    fn random(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// Two bodies with offset centres under gravity, three springs (one between the moving
    /// bodies, one to the frame, one zero-length): the drivers only make the scene well-posed.
    const CONSERVATIVE: &str = "mechanism C {
        ground frame at (0.5, -0.25, 0.3);
        body arm near (1, 0, 0) mass 2 inertia 0.5 centre (0.5, 0.25);
        body block near (2, 1, 0) mass 3 inertia 0.2 centre (-0.1, 0.3);
        joint pivot: revolute(frame, arm);
        joint hinge: revolute(arm @ (1, 0), block);
        driver swing: angle(arm) = t;
        driver bend: relative_angle(arm, block) = t;
        gravity (0.4, -9.81);
        load coil: spring(arm @ (0.2, 0.3), block @ (0.5, -0.4), stiffness 40, length 0.7);
        load tie: spring(frame @ (1, 0.5), block @ (0.1, 0.1), stiffness 15, length 1.2);
        load rubber: spring(frame @ (0, 2), arm @ (0.3, 0), stiffness 3, length 0);
    }";

    #[test]
    fn the_potentials_fall_at_the_power_of_the_conservative_forces() {
        // At q̇ = 0 and q̈ = 0, F holds exactly gravity and the springs' elastic pull (virtual
        // work, `dynamics`); the potentials' rate along any q̇ is minus their power, checked by
        // central differences of V along q̇ (independent of the symbolic derivative).
        let (arena, energy, forces) = derive(CONSERVATIVE);
        let potential = |q: &[f64]| {
            let e = env(q, &[0.0; 9], 0.0);
            eval(&arena, energy.gravity, &e) + eval(&arena, energy.springs, &e)
        };
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        for _ in 0..20 {
            let mut q = [0.5, -0.25, 0.3, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
            let mut qd = [0.0; 9];
            for k in 3..9 {
                q[k] = 2.0 * random(&mut seed);
                qd[k] = random(&mut seed);
            }
            let e = env(&q, &[0.0; 9], 0.0);
            let power: f64 = (forces.iter().zip(&qd))
                .map(|(&f, v)| eval(&arena, f, &e) * v)
                .sum();
            let h = 1e-6;
            let along =
                |s: f64| -> Vec<f64> { q.iter().zip(&qd).map(|(x, v)| x + s * v).collect() };
            let rate = (potential(&along(h)) - potential(&along(-h))) / (2.0 * h);
            assert!(
                (rate + power).abs() < 1e-7 * (1.0 + power.abs()),
                "dV/dt = {rate}, conservative power {power}"
            );
        }
    }

    #[test]
    fn gravity_and_springs_match_their_hand_formulas() {
        let (arena, energy, _) = derive(CONSERVATIVE);
        let (x, y, th) = (0.3, -0.2, 0.8_f64);
        let q = [0.5, -0.25, 0.3, x, y, th, 1.1, 0.4, -0.6];
        let e = env(&q, &[0.0; 9], 0.0);
        let turn = |th: f64, p: [f64; 2]| {
            let (s, c) = th.sin_cos();
            [c * p[0] - s * p[1], s * p[0] + c * p[1]]
        };
        let at = |body: [f64; 3], p: [f64; 2]| {
            let r = turn(body[2], p);
            [body[0] + r[0], body[1] + r[1]]
        };
        let (frame, arm, block) = ([0.5, -0.25, 0.3], [x, y, th], [1.1, 0.4, -0.6]);
        let (ca, cb) = (at(arm, [0.5, 0.25]), at(block, [-0.1, 0.3]));
        let gravity = -(2.0 * (0.4 * ca[0] - 9.81 * ca[1]) + 3.0 * (0.4 * cb[0] - 9.81 * cb[1]));
        let stored = |k: f64, rest: f64, p: [f64; 2], q: [f64; 2]| {
            0.5 * k * ((q[0] - p[0]).hypot(q[1] - p[1]) - rest).powi(2)
        };
        let springs = stored(40.0, 0.7, at(arm, [0.2, 0.3]), at(block, [0.5, -0.4]))
            + stored(15.0, 1.2, at(frame, [1.0, 0.5]), at(block, [0.1, 0.1]))
            + stored(3.0, 0.0, at(frame, [0.0, 2.0]), at(arm, [0.3, 0.0]));
        for (got, exact) in [
            (eval(&arena, energy.gravity, &e), gravity),
            (eval(&arena, energy.springs, &e), springs),
        ] {
            assert!(
                (got - exact).abs() < 1e-12 * (1.0 + exact.abs()),
                "{got} vs {exact}"
            );
        }
    }

    /// A slider with a spring-damper anchored off its line (ℓ̇ ≠ ẋ), a body-axes force and a
    /// torque; no gravity and a centred mass, so that `Q` at q̈ = 0 is loads, springs and
    /// dampers only.
    const DISSIPATIVE: &str = "mechanism D {
        ground frame at (0, 0, 0);
        body slider near (3, 0, 0) mass 1 inertia 0.1;
        joint guide: prismatic(frame, slider, along (1, 0));
        driver push: x(slider) = t;
        load coil: spring(frame @ (1, 0.5), slider @ (0.2, 0.1), stiffness 10, length 1.5, damping 2);
        load kick: local_force(slider @ (0, 1)) = (3, 1 + t);
        load twist: torque(slider) = 4 * t;
    }";

    #[test]
    fn loads_and_dampers_deliver_the_power_of_their_forces() {
        let (arena, energy, forces) = derive(DISSIPATIVE);
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        for _ in 0..20 {
            let (mut q, mut qd) = ([0.0; 6], [0.0; 6]);
            for k in 3..6 {
                q[k] = 3.0 * random(&mut seed);
                qd[k] = 2.0 * random(&mut seed);
            }
            let t = random(&mut seed);
            let e = env(&q, &qd, t);
            let (dampers, loads) = (
                eval(&arena, energy.dampers, &e),
                eval(&arena, energy.loads, &e),
            );
            // By hand: the force A(θ) (3, 1 + t) at the point r + A(θ) (0, 1), whose velocity
            // is ṙ + θ̇ (−cos θ, −sin θ); the torque 4t at θ̇; the damper's 2 ℓ̇².
            let ([x, y, th], [xd, yd, thd]) = ([q[3], q[4], q[5]], [qd[3], qd[4], qd[5]]);
            let (s, c) = th.sin_cos();
            let force = [3.0 * c - (1.0 + t) * s, 3.0 * s + (1.0 + t) * c];
            let velocity = [xd - thd * c, yd - thd * s];
            let by_hand = force[0] * velocity[0] + force[1] * velocity[1] + 4.0 * t * thd;
            let d = [x + 0.2 * c - 0.1 * s - 1.0, y + 0.2 * s + 0.1 * c - 0.5];
            let dd = [
                xd - thd * (0.2 * s + 0.1 * c),
                yd + thd * (0.2 * c - 0.1 * s),
            ];
            let rate = (d[0] * dd[0] + d[1] * dd[1]) / d[0].hypot(d[1]);
            assert!(
                (loads - by_hand).abs() < 1e-12 * (1.0 + by_hand.abs()),
                "{loads} vs {by_hand}"
            );
            assert!(
                dampers >= 0.0 && (dampers - 2.0 * rate * rate).abs() < 1e-12 * (1.0 + dampers)
            );
            // Q's whole power (q̈ = 0, a centred mass, no gravity) is the loads', the springs'
            // (−dV_s/dt, central differences along q̇) and the dampers' (dissipated).
            let total: f64 = (forces.iter().zip(&qd))
                .map(|(&f, v)| eval(&arena, f, &e) * v)
                .sum();
            let h = 1e-6;
            let along =
                |s: f64| -> Vec<f64> { q.iter().zip(&qd).map(|(x, v)| x + s * v).collect() };
            let stored = |q: &[f64]| eval(&arena, energy.springs, &env(q, &qd, t));
            let springs = -(stored(&along(h)) - stored(&along(-h))) / (2.0 * h);
            assert!(
                (total - (loads + springs - dampers)).abs() < 1e-7 * (1.0 + total.abs()),
                "Q·q̇ = {total}, loads {loads} + springs {springs} − dampers {dampers}"
            );
        }
    }
}
