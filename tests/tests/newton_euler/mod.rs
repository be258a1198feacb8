//! Newton–Euler for one solved state of a scene, shared by the force tests: per moving body,
//! the sum of the forces on it (gravity, loads, springs, reported reactions and efforts)
//! against `m a_c`, and of their moments about the centre of mass against `J θ̈`; per ground
//! body, what the joints and springs put on it against its reported load.
//!
//! The checker is built from the scene's model (points, axes, mass properties, loads) and the
//! documented meaning of each reported reaction, with its own rigid-body kinematics: it does
//! not use the generator's derivation of F or of the multipliers, so a sign or a lever arm
//! wrong there shows as a residual here.

pub mod corpus;

use mechgen::model::{ConstraintKind, Driven, LoadKind, Point};
use mechgen_runtime::{Forces, State, Storage, nalgebra::DefaultAllocator};

/// The worst relative Newton–Euler residual of `state`, a solved state of `scene` (whose
/// parameters `mechanism` holds).
pub fn residual<M: Forces>(scene: &mechgen::Scene, mechanism: &M, state: &State<M>) -> f64
where
    DefaultAllocator: Storage<M::Dim>,
{
    let params = (0..mechanism.parameter_count())
        .map(|i| mechanism.parameter(i).unwrap_or(f64::NAN))
        .collect();
    let checker = NewtonEuler {
        scene,
        t: state.t,
        q: state.q.as_slice().to_vec(),
        qd: state.qd().as_slice().to_vec(),
        qdd: state.qdd().as_slice().to_vec(),
        params,
        sums: vec![([0.0; 2], 0.0); scene.model.bodies.len()],
        scale: (0.0, 0.0),
    };
    checker.residual(state.constraint_forces().as_slice())
}

/// The balance of every body of one state, gathered force by force. Residuals are relative to
/// the largest force and moment contributed.
struct NewtonEuler<'a> {
    scene: &'a mechgen::Scene,
    t: f64,
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    params: Vec<f64>,
    /// Per body: force, moment about its centre of mass (its reference point for ground bodies).
    sums: Vec<([f64; 2], f64)>,
    /// The largest force and moment contributed.
    scale: (f64, f64),
}

impl NewtonEuler<'_> {
    fn value(&self, id: mechgen::expr::Id) -> f64 {
        let env = mechgen::expr::tape::Env {
            q: self.q.clone(),
            qd: self.qd.clone(),
            qdd: Vec::new(),
            t: self.t,
            params: self.params.clone(),
            free: Vec::new(),
        };
        mechgen::expr::tape::eval(&self.scene.model.arena, id, &env)
    }

    fn q(&self, k: usize) -> f64 {
        self.q[k]
    }

    fn rotate(&self, body: usize, s: [f64; 2]) -> [f64; 2] {
        let (sin, cos) = self.q(3 * body + 2).sin_cos();
        [cos * s[0] - sin * s[1], sin * s[0] + cos * s[1]]
    }

    /// A body-fixed point's world position.
    fn world(&self, p: Point) -> [f64; 2] {
        let s = [self.value(p.local[0]), self.value(p.local[1])];
        let r = self.rotate(p.body, s);
        [self.q(3 * p.body) + r[0], self.q(3 * p.body + 1) + r[1]]
    }

    /// Where moments of a body are taken: its centre of mass, or its reference point.
    fn centre(&self, body: usize) -> [f64; 2] {
        let local = match self.scene.model.bodies[body].mass {
            Some(m) => [self.value(m.centre[0]), self.value(m.centre[1])],
            None => [0.0, 0.0],
        };
        let r = self.rotate(body, local);
        [self.q(3 * body) + r[0], self.q(3 * body + 1) + r[1]]
    }

    fn force(&mut self, body: usize, f: [f64; 2], at: [f64; 2]) {
        let c = self.centre(body);
        let moment = (at[0] - c[0]) * f[1] - (at[1] - c[1]) * f[0];
        let (sum, m) = &mut self.sums[body];
        sum[0] += f[0];
        sum[1] += f[1];
        *m += moment;
        self.scale.0 = self.scale.0.max(f[0].hypot(f[1]));
        self.scale.1 = self.scale.1.max(moment.abs());
    }

    fn torque(&mut self, body: usize, tau: f64) {
        self.sums[body].1 += tau;
        self.scale.1 = self.scale.1.max(tau.abs());
    }

    /// Applies every force of the scene and returns the worst relative residual.
    fn residual(mut self, reactions: &[f64]) -> f64 {
        let model = &self.scene.model;
        let mut row = 0;
        for constraint in &model.constraints {
            let r = &reactions[row..];
            match constraint.kind {
                ConstraintKind::Ground { body, .. } => {
                    // The reported load goes to the frame's balance with the opposite sign.
                    let at = [self.q(3 * body), self.q(3 * body + 1)];
                    self.force(body, [-r[0], -r[1]], at);
                    self.torque(body, -r[2]);
                }
                ConstraintKind::Revolute { a, b } => {
                    self.force(a.body, [r[0], r[1]], self.world(a));
                    self.force(b.body, [-r[0], -r[1]], self.world(b));
                }
                ConstraintKind::Prismatic { a, b, axis } => {
                    let u = [self.value(axis[0]), self.value(axis[1])];
                    let n = self.rotate(a.body, [-u[1], u[0]]);
                    let at = self.world(b);
                    self.force(a.body, [r[0] * n[0], r[0] * n[1]], at);
                    self.force(b.body, [-r[0] * n[0], -r[0] * n[1]], at);
                    self.torque(a.body, r[1]);
                    self.torque(b.body, -r[1]);
                }
                ConstraintKind::Distance { a, b, .. } => {
                    let (pa, pb) = (self.world(a), self.world(b));
                    let d = [pb[0] - pa[0], pb[1] - pa[1]];
                    let l = d[0].hypot(d[1]);
                    let f = [r[0] * d[0] / l, r[0] * d[1] / l];
                    self.force(a.body, f, pa);
                    self.force(b.body, [-f[0], -f[1]], pb);
                }
                ConstraintKind::Slot { a, b, axis } => {
                    let u = [self.value(axis[0]), self.value(axis[1])];
                    let n = self.rotate(a.body, [-u[1], u[0]]);
                    let at = self.world(b);
                    self.force(a.body, [r[0] * n[0], r[0] * n[1]], at);
                    self.force(b.body, [-r[0] * n[0], -r[0] * n[1]], at);
                }
                ConstraintKind::Weld { a, b, .. } => {
                    self.force(a.body, [r[0], r[1]], self.world(a));
                    self.force(b.body, [-r[0], -r[1]], self.world(b));
                    self.torque(a.body, r[2]);
                    self.torque(b.body, -r[2]);
                }
                ConstraintKind::Gear {
                    a,
                    b,
                    carrier,
                    ratio,
                    ..
                } => {
                    let k = self.value(ratio);
                    self.torque(b, r[0]);
                    self.torque(a, -k * r[0]);
                    if let Some(c) = carrier {
                        self.torque(c, (k - 1.0) * r[0]);
                    }
                }
                ConstraintKind::Rack {
                    a,
                    b,
                    axis,
                    pinion,
                    ratio,
                    ..
                } => {
                    let u = [self.value(axis[0]), self.value(axis[1])];
                    let u = self.rotate(a.body, u);
                    let at = self.world(b);
                    self.force(b.body, [r[0] * u[0], r[0] * u[1]], at);
                    self.force(a.body, [-r[0] * u[0], -r[0] * u[1]], at);
                    let k = self.value(ratio);
                    self.torque(pinion, -k * r[0]);
                    self.torque(a.body, k * r[0]);
                }
                ConstraintKind::Driver { driven, .. } => match driven {
                    Driven::Angle(b) => self.torque(b, r[0]),
                    Driven::RelativeAngle(a, b) => {
                        self.torque(b, r[0]);
                        self.torque(a, -r[0]);
                    }
                    Driven::X(p) => self.force(p.body, [r[0], 0.0], self.world(p)),
                    Driven::Y(p) => self.force(p.body, [0.0, r[0]], self.world(p)),
                    Driven::Travel { a, b, axis } => {
                        let u = [self.value(axis[0]), self.value(axis[1])];
                        let u = self.rotate(a.body, u);
                        let at = self.world(b);
                        self.force(b.body, [r[0] * u[0], r[0] * u[1]], at);
                        self.force(a.body, [-r[0] * u[0], -r[0] * u[1]], at);
                    }
                    Driven::Distance(a, b) => {
                        let (pa, pb) = (self.world(a), self.world(b));
                        let d = [pb[0] - pa[0], pb[1] - pa[1]];
                        let l = d[0].hypot(d[1]);
                        let u = [d[0] / l, d[1] / l];
                        self.force(b.body, [r[0] * u[0], r[0] * u[1]], pb);
                        self.force(a.body, [-r[0] * u[0], -r[0] * u[1]], pa);
                    }
                },
            }
            row += constraint.kind.equation_suffixes().len();
        }
        self.loads();
        self.inertia();
        let (force_scale, moment_scale) = self.scale;
        self.sums
            .iter()
            .map(|(f, m)| (f[0].hypot(f[1]) / force_scale).max(m.abs() / moment_scale))
            .fold(0.0, f64::max)
    }

    fn loads(&mut self) {
        let model = &self.scene.model;
        let g = [self.value(model.gravity[0]), self.value(model.gravity[1])];
        for (body, b) in model.bodies.iter().enumerate() {
            if let (Some(m), false) = (b.mass, b.ground) {
                let mass = self.value(m.mass);
                self.force(body, [mass * g[0], mass * g[1]], self.centre(body));
            }
        }
        for load in &model.loads {
            match load.kind {
                LoadKind::Force {
                    point,
                    value,
                    local,
                } => {
                    let f = [self.value(value[0]), self.value(value[1])];
                    let f = if local { self.rotate(point.body, f) } else { f };
                    self.force(point.body, f, self.world(point));
                }
                LoadKind::Torque { body, value } => self.torque(body, self.value(value)),
                LoadKind::Spring {
                    a,
                    b,
                    stiffness,
                    length,
                    damping,
                } => {
                    let (pa, pb) = (self.world(a), self.world(b));
                    let (va, vb) = (self.point_velocity(a), self.point_velocity(b));
                    let d = [pb[0] - pa[0], pb[1] - pa[1]];
                    let l = d[0].hypot(d[1]);
                    let u = [d[0] / l, d[1] / l];
                    let rate = u[0] * (vb[0] - va[0]) + u[1] * (vb[1] - va[1]);
                    let tension = self.value(stiffness) * (l - self.value(length))
                        + self.value(damping) * rate;
                    self.force(a.body, [tension * u[0], tension * u[1]], pa);
                    self.force(b.body, [-tension * u[0], -tension * u[1]], pb);
                }
            }
        }
    }

    fn point_velocity(&self, p: Point) -> [f64; 2] {
        let qd = &self.qd;
        let s = [self.value(p.local[0]), self.value(p.local[1])];
        let r = self.rotate(p.body, s);
        let w = qd[3 * p.body + 2];
        [qd[3 * p.body] - w * r[1], qd[3 * p.body + 1] + w * r[0]]
    }

    /// d'Alembert: −m a_c at the centre, −J θ̈ on the angle.
    fn inertia(&mut self) {
        let model = &self.scene.model;
        let (qd, qdd) = (self.qd.clone(), self.qdd.clone());
        for (body, b) in model.bodies.iter().enumerate() {
            let (Some(m), false) = (b.mass, b.ground) else {
                continue;
            };
            let s = [self.value(m.centre[0]), self.value(m.centre[1])];
            let r = self.rotate(body, s);
            let (w, alpha) = (qd[3 * body + 2], qdd[3 * body + 2]);
            let a = [
                qdd[3 * body] - alpha * r[1] - w * w * r[0],
                qdd[3 * body + 1] + alpha * r[0] - w * w * r[1],
            ];
            let mass = self.value(m.mass);
            self.force(body, [-mass * a[0], -mass * a[1]], self.centre(body));
            self.torque(body, -self.value(m.inertia) * alpha);
        }
    }
}
